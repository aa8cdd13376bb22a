// `lobesketch vr [SESSION]`: sketching with tracked hands in a headset through OpenXR
// (docs/vr.md). XrHost (app/vr/vr_xr.h) runs the runtime, the frames and the eyes; VrSession
// (app/vr/vr_session.h) everything else.
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <set>

#include <CLI/CLI.hpp>

#include "app/session/session_file.h"
#include "app/cli/cli.h"
#include "app/cli/cli_common.h"
#include "app/cli/outputs.h"
#include "app/render/renderer.h"
#include "app/export/skeleton_json.h"
#include "app/export/tree_output.h"
#include "app/vr/vr_session.h"
#include "app/vr/vr_xr.h"
#include "core/errors.h"
#include "input/tools.h"

namespace lobe::cli {

namespace {

namespace fs = std::filesystem;

std::string status_line(const VrSession& s, const XrFrameStats& f)
{
    const VrStatus& st = s.status();
    char head[128];
    std::snprintf(head, sizeof head, "vr: %.1f s, %llu frames (%.1f ms/frame), %s", f.time,
                  static_cast<unsigned long long>(f.frames), f.frame_ms, f.state);
    std::string line = head;
    line += ", " + (st.label.empty() ? std::string(tool_name(st.tool)) : st.label);
    line += ", " + std::to_string(st.strokes) + " strokes, " + std::to_string(st.lobes) + " lobes, " +
            std::to_string(st.edits) + " edits";
    line += std::string(", hands ") + (st.hands_tracked[0] ? "L" : "-") + (st.hands_tracked[1] ? "R" : "-");
    if (st.regrowing) line += ", regrowing";
    if (!st.last_message.empty()) line += ": " + st.last_message;
    return line;
}

/// What `replay --out DIR` writes, from the document the session ended with.
void write_outputs(const std::string& dir, Document doc, const std::string& source)
{
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec) throw FileError(dir, "cannot create output folder: " + ec.message());
    write_strokes_json(dir + "/strokes.json", doc.strokes, source);
    save_document(dir + "/session.json", doc);
    std::vector<std::string> warnings;
    std::vector<BuiltLobe> lobes;
    const std::size_t lobe_files = write_document_lobes(doc, dir, warnings, &lobes);
    for (const std::string& w : warnings) warn(source + ": " + w);
    save_document(dir + "/session.json", doc);
    bool tree_written = false;
    if (!lobes.empty()) {
        const BuiltTree tree = grow_document_tree(doc, std::move(lobes));
        for (const std::string& w : tree.warnings) warn(source + ": " + w);
        const TreeGeometry geometry = document_tree_geometry(doc, tree);
        write_tree_file(dir + "/tree.glb", doc, tree, geometry, ExportOptions{});
        write_skeleton_json(dir + "/tree.json", tree);
        tree_written = true;
        progress("grew a tree of " + std::to_string(tree.growth.tree.size()) + " nodes (triangles " +
                 lod_triangle_summary(geometry) + ")");
    }
    progress("wrote " + dir + "/strokes.json, " + dir + "/session.json, " + std::to_string(lobe_files) +
             " lobe mesh(es) in " + dir + "/lobes" + (tree_written ? ", " + dir + "/tree.glb and " + dir + "/tree.json" : ""));
}

} // namespace

void add_vr_command(CLI::App& app, int& exit_code)
{
    auto* cmd = app.add_subcommand("vr", "Sketch lobes and trunks with your fingers in a headset (OpenXR hand tracking)");
    struct Args {
        std::string session, record, autosave, export_path, events, photo, out;
        int max_view_size = 0, samples = 4;
        double reconnect_seconds = 10.0;
        bool sync_regrowth = false;
    };
    auto a = std::make_shared<Args>();
    cmd->add_option("SESSION", a->session, "Session document (.json) to open; written when the session ends");
    cmd->add_option("--record", a->record, "The session's recording (default: SESSION_STEM.<time>.lrec beside it)");
    cmd->add_option("--autosave", a->autosave, "Autosave file (default: SESSION_STEM.autosave.json beside it)");
    cmd->add_option("--export", a->export_path, "Where Export writes the tree (default: SESSION_STEM.glb)");
    cmd->add_option("--events", a->events,
                    "Apply the event track of this recording at its times (replaying it through the replay runtime, "
                    "which cannot carry events)");
    cmd->add_option("--photo", a->photo, "A reference picture (PNG or JPEG) to place in the scene");
    cmd->add_option("--max-view-size", a->max_view_size, "Cap each side of an eye's image, in pixels (0: the runtime's size)")
        ->check(CLI::Range(0, 16384));
    cmd->add_option("--reconnect-seconds", a->reconnect_seconds,
                    "After the headset goes away, how long to wait for it to come back (0: end at once)")
        ->check(finite_range(0.0, 3600.0))
        ->capture_default_str();
    cmd->add_option("--samples", a->samples, "Multisampling: 1, 2, 4 or 8 samples per pixel")
        ->check(CLI::IsMember({1, 2, 4, 8}))
        ->capture_default_str();
    cmd->add_flag("--sync-regrowth", a->sync_regrowth,
                  "Rebuild lobes and the tree on the frame thread (every frame shows the current tree; for replays)");
    cmd->add_option("-o,--out", a->out,
                    "After the session, write what `replay --out` writes here: strokes.json, session.json, lobes, tree.glb, tree.json");
    cmd->callback([a, &exit_code] {
        const std::string session = a->session.empty() ? "lobesketch-" + timestamp() + ".json" : a->session;
        VrOptions options;
        options.session_path = session;
        options.autosave_path = a->autosave.empty() ? beside(session, ".autosave.json") : a->autosave;
        options.record_path = a->record.empty() ? beside(session, "." + timestamp() + ".lrec") : a->record;
        options.export_path = a->export_path.empty() ? beside(session, ".glb") : a->export_path;
        options.photo_path = a->photo;
        options.background_regrowth = !a->sync_regrowth;

        Document doc;
        std::error_code ec;
        if (fs::exists(session, ec)) {
            try {
                doc = load_session(session);
            } catch (const Error& e) {
                throw Error(std::string(e.what()) + "; nothing was changed. Its autosave, if any, is " +
                            options.autosave_path);
            }
            // The L-system sketch saved beside it, if any (docs/lsystem-sketch.md).
            options.lsystem_sketch_file = lsystem_sketch_path(session);
        }
        if (!a->events.empty()) {
            const Recording rec = load_recording_verbose(a->events);
            // VrOptions::events count from the recording's first frame, as frame times do.
            const double t0 = rec.frames.empty() ? 0.0 : rec.frames.front().time;
            for (InputEvent e : rec.events) {
                e.time -= t0;
                options.events.push_back(e);
            }
            for (const HandFrame& f : rec.frames) options.clock.push_back(f.time - t0);
            options.nominal_rate_hz = rec.header.nominal_rate_hz;
            progress("vr: " + std::to_string(options.events.size()) + " event(s) of " + a->events +
                     " will be applied at their times");
        }

        XrHostOptions ho;
        ho.max_view_size = a->max_view_size;
        ho.reconnect_seconds = a->reconnect_seconds;
        ho.samples = a->samples;
        ho.message = [](const std::string& line) { warn(line); };
        ho.status = [](const VrSession& s, const XrFrameStats& f) { progress(status_line(s, f)); };
        XrHost host(ho);
        options.runtime_name = host.runtime_name();
        options.device_name = host.system_name();
        progress("vr: " + host.runtime_name() + ", " + host.system_name() + ", drawing on " +
                 host.renderer().device_name() + "; session " + options.session_path + ", recording " +
                 options.record_path);

        VrSession vs(std::move(doc), options);
        XrRunResult result;
        try {
            result = host.run(vs);
        } catch (...) {
            // Whatever broke, what was made is kept: the stroke being drawn, the recording, the session.
            try {
                vs.finish(host.last_time());
            } catch (const std::exception& e) {
                warn(std::string("vr: while saving after the failure: ") + e.what());
            }
            throw;
        }
        vs.finish(result.last_time);

        std::set<std::string> shown; // each warning once
        for (const std::string& m : vs.messages())
            if (m.rfind("saved ", 0) != 0 && m.rfind("exported ", 0) != 0 && shown.insert(m).second) warn(m);
        if (result.end == XrRunResult::End::Lost)
            warn(result.message + "; the session is saved in " + options.session_path + ", the recording in " +
                 options.record_path);
        else
            progress(result.message);
        const Document& out = vs.document();
        progress("vr: " + std::to_string(result.frames) + " frames (" + std::to_string(result.rendered) + " drawn), " +
                 std::to_string(out.strokes.size()) + " strokes, " + std::to_string(out.lobes.size()) + " lobes, " +
                 std::to_string(out.edits.size()) + " edits; session " + options.session_path + ", recording " +
                 options.record_path);
        if (!a->out.empty()) write_outputs(a->out, out, options.record_path);
        exit_code = kExitOk;
    });
}

} // namespace lobe::cli
