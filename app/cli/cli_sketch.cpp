// `lobesketch sketch REC`: the VR app without a headset. A recording's hand frames go through
// the live VrSession one by one (panel, scene grab, pipeline, document, recording, autosave,
// regrowth), as `lobesketch vr` feeds it tracked hands. For benchmarks of the live session and
// for the crash-safety tests (docs/crash-safety.md).
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "app/cli/cli.h"
#include "app/cli/cli_common.h"
#include "app/vr/sketch_run.h"
#include "core/document.h"
#include "core/errors.h"

namespace lobe::cli {

void add_sketch_command(CLI::App& app, int& exit_code)
{
    auto* cmd = app.add_subcommand(
        "sketch", "Feed a recording's hand frames through the live VR session (the VR app without a headset)");
    struct Args {
        std::string rec, session, autosave, record, settings;
        std::uint64_t seed = 1;
        bool realtime = false, events = false, inline_regrowth = false;
    };
    auto a = std::make_shared<Args>();
    cmd->add_option("REC", a->rec, "Recording whose hand frames are the tracked hands")->required();
    cmd->add_option("--session,-o,--out", a->session,
                    "Session file written (atomically) when the recording ends (--out as in the other commands)");
    cmd->add_option("--autosave", a->autosave, "Autosave written after every change of the document");
    cmd->add_option("--record", a->record, "The session's own recording, written as it goes");
    cmd->add_flag("--realtime", a->realtime, "Feed each frame at its time (default: as fast as the session runs)");
    cmd->add_flag("--events-from-recording", a->events,
                  "Apply REC's event track (keys, settings) at its times, as if the panel had been pressed; "
                  "leave it off for a recording made by the VR app, whose panel presses its hands make again");
    cmd->add_flag("--inline-regrowth", a->inline_regrowth,
                  "Regrow on the frame thread after every change (default: off it, as live)");
    cmd->add_option("--settings", a->settings, "Settings JSON the session starts with");
    cmd->add_option("--seed", a->seed, "The session's seed")->capture_default_str()->check(seed_check());
    cmd->callback([a, &exit_code] {
        const Recording rec = load_recording_verbose(a->rec);
        Document doc;
        doc.seed = a->seed;
        if (!a->settings.empty()) doc.settings = load_settings_file(a->settings);

        SketchRunOptions o;
        o.session_path = a->session;
        o.autosave_path = a->autosave;
        o.record_path = a->record;
        o.realtime = a->realtime;
        o.events_from_recording = a->events;
        o.background_regrowth = !a->inline_regrowth;
        const SketchRunResult run = run_sketch(rec, std::move(doc), o, [](const std::string& m) { progress(m); });
        const Document& out = run.document;
        progress(frame_time_summary(run));
        progress(std::to_string(out.strokes.size()) + " strokes, " + std::to_string(out.lobes.size()) +
                 " lobe group(s), " + std::to_string(out.edits.size()) + " edit(s)" +
                 (a->session.empty() ? std::string() : "; saved " + a->session));
        exit_code = kExitOk;
    });
}

} // namespace lobe::cli
