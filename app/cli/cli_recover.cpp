// `lobesketch recover AUTOSAVE [--recording REC] [--out SESSION.json]`: the newest good
// autosave of a live session, plus what its recording holds beyond it (docs/crash-safety.md).
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "app/live/live_session.h"
#include "app/session/session_file.h"
#include "app/cli/cli.h"
#include "app/cli/cli_common.h"
#include "app/session/edit_hooks.h"
#include "app/session/stage_options.h"
#include "core/atomic_file.h"
#include "core/document.h"
#include "core/errors.h"
#include "growth/lsystem/sketch.h"
#include "input/pipeline.h"
#include "input/recording.h"
#include "app/session/session_builder.h"
#include "meshing/mesh_io.h"

namespace lobe::cli {

namespace {

/// The recovered session's default name: "DIR/NAME.recovered.json" for "DIR/NAME.json".
std::string default_recovered_path(const std::string& autosave)
{
    std::filesystem::path p(autosave);
    if (lower_extension(autosave) == ".json") p.replace_extension();
    return p.string() + ".recovered.json";
}

/// The newest autosave that loads: AUTOSAVE, else its previous generation (AUTOSAVE.1).
/// \throw FileError naming both when neither loads.
Document load_newest_autosave(const std::string& autosave, std::string& used)
{
    std::string first_problem;
    try {
        used = autosave;
        return load_session(autosave);
    } catch (const FileError& e) {
        first_problem = e.what();
    }
    const std::string previous = previous_autosave_path(autosave);
    std::error_code ec;
    if (!std::filesystem::exists(previous, ec))
        throw FileError(autosave, "no good autosave (" + first_problem + "; no previous generation " + previous + ")");
    warn(first_problem + "; using the previous generation " + previous);
    try {
        used = previous;
        return load_session(previous);
    } catch (const FileError& e) {
        throw FileError(autosave, "no good autosave (" + first_problem + "; " + e.what() + ")");
    }
}

bool same_point(const StrokePoint& a, const StrokePoint& b)
{
    return glm::all(glm::lessThanEqual(glm::abs(a.position - b.position), glm::vec3(1e-6f)));
}

/// A stroke of `doc` that is `s` as drawn: same kind, same points at the ends. (Edits are
/// operations, so a document keeps its strokes as drawn.)
bool document_has_stroke(const Document& doc, const Stroke& s)
{
    if (s.points.empty()) return false;
    for (const Stroke& d : doc.strokes)
        if (d.kind == s.kind && d.points.size() == s.points.size() && same_point(d.points.front(), s.points.front()) &&
            same_point(d.points.back(), s.points.back()))
            return true;
    return false;
}

bool same_file(const std::string& a, const std::string& b)
{
    std::error_code ec;
    return std::filesystem::equivalent(a, b, ec) && !ec;
}

/// The text of the L-system sketch autosaved beside `autosave` (lsystem_sketch_path), when
/// there is one and it reads as a sketch; a damaged one is a warning and none.
std::optional<std::string> autosaved_lsystem_sketch(const std::string& autosave)
{
    const std::string path = lsystem_sketch_path(autosave);
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) return std::nullopt;
    try {
        std::string text = read_file_limited(path, lsystem::kMaxSketchFileBytes);
        (void)lsystem::parse_sketch(text, path);
        return text;
    } catch (const Error& e) {
        warn(std::string(e.what()) + "; the session is recovered without its L-system sketch");
        return std::nullopt;
    }
}

} // namespace

void add_recover_command(CLI::App& app, int& exit_code)
{
    auto* cmd = app.add_subcommand(
        "recover", "Restore a session after a crash: its newest good autosave plus the rest of its recording");
    struct Args {
        std::string autosave, recording, out;
        bool force = false;
    };
    auto a = std::make_shared<Args>();
    cmd->add_option("AUTOSAVE", a->autosave,
                    "The session's autosave (when it does not load, its previous generation AUTOSAVE.1 is used)")
        ->required();
    cmd->add_option("--recording", a->recording, "The session's recording (default: the autosave's source_recording)");
    cmd->add_option("-o,--out", a->out, "Where to write the recovered session (default: NAME.recovered.json beside AUTOSAVE NAME.json)");
    cmd->add_flag("--force", a->force, "Replace the --out file if it exists");
    cmd->callback([a, &exit_code] {
        const std::string out = a->out.empty() ? default_recovered_path(a->autosave) : a->out;
        std::error_code ec;
        if (same_file(out, a->autosave) || same_file(out, previous_autosave_path(a->autosave)) ||
            (!a->recording.empty() && same_file(out, a->recording)))
            throw FileError(out, "is the autosave or the recording: choose another --out");
        if (std::filesystem::exists(out, ec) && !a->force)
            throw FileError(out, "exists: choose another --out, or add --force to replace it");
        // The L-system sketch autosaved beside the autosave goes beside the recovered session.
        const std::optional<std::string> sketch = autosaved_lsystem_sketch(a->autosave);
        const std::string sketch_out = lsystem_sketch_path(out);
        if (sketch && std::filesystem::exists(sketch_out, ec) && !a->force)
            throw FileError(sketch_out, "exists: choose another --out, or add --force to replace it");

        std::string used;
        Document doc = load_newest_autosave(a->autosave, used);
        if (!doc.recording_frames)
            throw FileError(used, "does not say how much of its recording it holds (no recording_frames): "
                                  "not an autosave of a recorded live session");
        const std::uint64_t saved_frames = *doc.recording_frames;
        const std::size_t saved_strokes = doc.strokes.size();

        if (doc.recording_finished) {
            progress(used + " holds all of its recording: nothing to replay");
        } else {
            const std::string rec_path = a->recording.empty() ? doc.source_recording : a->recording;
            if (rec_path.empty())
                throw FileError(used, "names no recording (source_recording is empty): give --recording");
            if (same_file(out, rec_path)) throw FileError(out, "is the recording: choose another --out");
            const Recording rec = load_recording_verbose(rec_path);
            if (rec.frames.size() < saved_frames)
                throw FileError(rec_path, "has " + std::to_string(rec.frames.size()) + " frames, fewer than the " +
                                              std::to_string(saved_frames) + " that " + used +
                                              " holds: not that session's recording, or its end was lost "
                                              "(the autosave itself is intact)");

            // The pipeline runs over the whole recording, as the live session did, so that its
            // state (filters, gestures, the pen, the tool) is exact where the autosave stopped.
            // Actions of the first saved_frames frames are in the autosave already.
            InputPipeline pipe(input_options(doc.settings));
            std::vector<InputAction> tail;
            std::vector<Stroke> saved_prefix; ///< strokes completed within the saved frames
            std::size_t e = 0;
            for (std::size_t i = 0; i < rec.frames.size(); ++i) {
                const HandFrame& f = rec.frames[i];
                while (e < rec.events.size() && rec.events[e].time <= f.time) pipe.push_event(rec.events[e++]);
                pipe.push_frame(f);
                for (InputAction& act : pipe.take_actions()) {
                    if (i >= saved_frames) tail.push_back(std::move(act));
                    else if (act.type == InputAction::Type::StrokeCompleted) saved_prefix.push_back(std::move(act.stroke));
                }
            }
            // The end of the recording (events after its last frame, a stroke cut short by the
            // crash) as replay takes it.
            while (e < rec.events.size()) pipe.push_event(rec.events[e++]);
            pipe.finish();
            for (InputAction& act : pipe.take_actions()) tail.push_back(std::move(act));

            // A recording of another session: none of the strokes it had made by then is there.
            if (!saved_prefix.empty() && !doc.strokes.empty()) {
                bool any = false;
                for (const Stroke& s : saved_prefix) any = any || document_has_stroke(doc, s);
                if (!any)
                    throw FileError(rec_path, "does not match " + used + ": none of the " +
                                                  std::to_string(saved_prefix.size()) + " strokes of its first " +
                                                  std::to_string(saved_frames) + " frames is in the autosave");
            }

            EditHooks hooks = meshing_edit_hooks(edit_apply_options(doc.settings));
            // Meshes imported during the session lie beside the recording (import_mesh_path).
            hooks.import_model = [rec_path](int n) {
                const std::string file = import_mesh_path(rec_path, n);
                return std::make_shared<const LobeModel>(
                    LobeModel{std::filesystem::path(file).filename().string(), read_mesh(file)});
            };
            const EditPickOptions pick = edit_pick_options(doc.settings);
            SessionBuilder builder(std::move(doc), pick, std::move(hooks));
            std::size_t changes = 0;
            for (const InputAction& act : tail) {
                if (act.type == InputAction::Type::StrokeDiscarded) warn(rec_path + ": stroke discarded: " + act.message);
                if (builder.apply(act)) ++changes;
            }
            for (const std::string& m : builder.messages()) warn(rec_path + ": " + m);
            doc = builder.take_document();
            doc.source_recording = std::filesystem::absolute(rec_path).lexically_normal().string();
            doc.recording_frames = rec.frames.size();
            doc.recording_finished = true;
            progress("replayed the last " + std::to_string(rec.frames.size() - saved_frames) + " of " +
                     std::to_string(rec.frames.size()) + " frames of " + rec_path + ": " + std::to_string(changes) +
                     " change(s), " + std::to_string(tail.size()) + " action(s)");
        }
        save_document(out, doc);
        if (sketch) {
            write_file_atomic(sketch_out, *sketch);
            progress("recovered the L-system sketch into " + sketch_out);
        }
        progress("recovered " + std::to_string(doc.strokes.size()) + " strokes (" + std::to_string(saved_strokes) +
                 " in " + used + "), " + std::to_string(doc.lobes.size()) + " lobe group(s), " +
                 std::to_string(doc.edits.size()) + " edit(s) into " + out);
        exit_code = kExitOk;
    });
}

} // namespace lobe::cli
