// `lobesketch sketch REC`: the VR app without a headset. A recording's hand frames go through
// the live VrSession one by one (panel, scene grab, pipeline, document, recording, autosave,
// regrowth), as `lobesketch vr` feeds it tracked hands. For benchmarks of the live session and
// for the crash-safety tests (docs/crash-safety.md).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>

#include "app/cli.h"
#include "app/cli_common.h"
#include "app/vr_session.h"
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
    cmd->add_option("--session", a->session, "Session file written (atomically) when the recording ends");
    cmd->add_option("--autosave", a->autosave, "Autosave written after every change of the document");
    cmd->add_option("--record", a->record, "The session's own recording, written as it goes");
    cmd->add_flag("--realtime", a->realtime, "Feed each frame at its time (default: as fast as the session runs)");
    cmd->add_flag("--events-from-recording", a->events,
                  "Apply REC's event track (keys, settings) at its times, as if the panel had been pressed; "
                  "leave it off for a recording made by the VR app, whose panel presses its hands make again");
    cmd->add_flag("--inline-regrowth", a->inline_regrowth,
                  "Regrow on the frame thread after every change (default: off it, as live)");
    cmd->add_option("--settings", a->settings, "Settings JSON the session starts with");
    cmd->add_option("--seed", a->seed, "The session's seed")->capture_default_str();
    cmd->callback([a, &exit_code] {
        const Recording rec = load_recording_verbose(a->rec);
        Document doc;
        doc.seed = a->seed;
        if (!a->settings.empty()) doc.settings = load_settings_file(a->settings);

        // The session counts time from the first frame.
        const double t0 = rec.frames.front().time;
        VrOptions o;
        o.session_path = a->session;
        o.autosave_path = a->autosave;
        o.record_path = a->record;
        o.background_regrowth = !a->inline_regrowth;
        o.runtime_name = "sketch";
        o.device_name = rec.header.device;
        o.nominal_rate_hz = rec.header.nominal_rate_hz;
        if (a->events) {
            o.events = rec.events;
            for (InputEvent& e : o.events) e.time = std::max(0.0, e.time - t0);
        }
        VrSession session(std::move(doc), std::move(o));

        using Clock = std::chrono::steady_clock;
        const Clock::time_point start = Clock::now();
        std::vector<double> frame_ms;
        frame_ms.reserve(rec.frames.size());
        std::string last_message;
        double time = 0.0;
        for (const HandFrame& input : rec.frames) {
            HandFrame f = input;
            f.time = input.time - t0;
            time = f.time;
            if (a->realtime) std::this_thread::sleep_until(start + std::chrono::duration<double>(f.time));
            const Clock::time_point before = Clock::now();
            session.frame(f);
            frame_ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - before).count());
            if (session.status().last_message != last_message) {
                last_message = session.status().last_message;
                if (!last_message.empty()) progress(last_message);
            }
            if (session.quit_requested()) break;
        }
        session.finish(time + 1e-3);
        const double total_s = std::chrono::duration<double>(Clock::now() - start).count();

        std::vector<double> sorted = frame_ms;
        std::sort(sorted.begin(), sorted.end());
        auto quantile = [&](double q) {
            return sorted.empty() ? 0.0 : sorted[std::min(sorted.size() - 1, static_cast<std::size_t>(q * double(sorted.size())))];
        };
        double sum = 0.0;
        for (double ms : frame_ms) sum += ms;
        const Document& out = session.document();
        char line[256];
        std::snprintf(line, sizeof line, "%zu frames in %.2f s; frame %.2f ms mean, %.2f ms p99, %.2f ms max",
                      frame_ms.size(), total_s, frame_ms.empty() ? 0.0 : sum / double(frame_ms.size()), quantile(0.99),
                      sorted.empty() ? 0.0 : sorted.back());
        progress(line);
        progress(std::to_string(out.strokes.size()) + " strokes, " + std::to_string(out.lobes.size()) +
                 " lobe group(s), " + std::to_string(out.edits.size()) + " edit(s)" +
                 (a->session.empty() ? std::string() : "; saved " + a->session));
        exit_code = kExitOk;
    });
}

} // namespace lobe::cli
