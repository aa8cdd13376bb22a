// `lobesketch desktop [SESSION]`: the sketching app in a window (docs/desktop.md). Here: the
// command line, which session to open (or recover) and where its files go; the window and its
// frame loop are app/desktop/desktop_window.h, the app itself app/desktop/desktop_session.h.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <set>

#include <CLI/CLI.hpp>

#include "app/session/session_file.h"
#include "app/cli/cli.h"
#include "app/cli/cli_common.h"
#include "app/desktop/desktop_script.h"
#include "app/desktop/desktop_session.h"
#include "app/desktop/desktop_window.h"
#include "app/export/export_scene.h"
#include "app/render/renderer.h"
#include "core/atomic_file.h"
#include "core/errors.h"

namespace lobe::cli {

namespace fs = std::filesystem;

void add_desktop_command(CLI::App& app, int& exit_code)
{
    auto* cmd = app.add_subcommand("desktop", "Sketch lobes and trunks with the mouse in a window and grow the tree");
    struct Args {
        std::string session, record, autosave, export_path, size = "1280x800", script, script_log, screenshot;
        bool recover = false, software = false;
        int frames = 0, samples = 4, lod = -1;
    };
    auto a = std::make_shared<Args>();
    cmd->add_option("SESSION", a->session, "Session document (.json) to open; created on the first save when missing");
    cmd->add_option("--record", a->record, "The session's recording (default: SESSION_STEM.<time>.lrec beside it)");
    cmd->add_option("--autosave", a->autosave, "Autosave file (default: SESSION_STEM.autosave.json beside it)");
    cmd->add_option("--export", a->export_path, "Where Export writes the tree (default: SESSION_STEM.glb)");
    cmd->add_option("--size", a->size, "Window size WxH")->capture_default_str();
    cmd->add_option("--script", a->script, "Drive the window with scripted mouse and key input (docs/desktop.md)");
    cmd->add_option("--script-log", a->script_log, "With --script: JSON lines describing the document at each `mark`");
    cmd->add_option("--screenshot", a->screenshot, "Write the last frame as PNG when the window closes");
    cmd->add_option("--frames", a->frames, "Close the window after this many frames (0: when closed)");
    cmd->add_flag("--recover", a->recover, "Open SESSION's autosave (after a crash or when SESSION is damaged)");
    cmd->add_flag("--software", a->software, "Render on the CPU (lavapipe) even when a GPU is present");
    cmd->add_option("--lod", a->lod, "Draw the tree at this level of detail (default: finest that keeps frames under 40 ms)")
        ->check(CLI::Range(0, 7));
    cmd->add_option("--samples", a->samples, "Multisampling: 1, 2, 4 or 8 samples per pixel")
        ->check(CLI::IsMember({1, 2, 4, 8}))
        ->capture_default_str();
    cmd->callback([a, &exit_code] {
        int width = 0, height = 0;
        {
            char x = 0, rest = 0;
            if (std::sscanf(a->size.c_str(), "%d%c%d%c", &width, &x, &height, &rest) != 3 || (x != 'x' && x != 'X') ||
                width < 64 || height < 64 || width > 8192 || height > 8192)
                throw CLI::ValidationError("--size", "expected WxH with sides in 64..8192, got '" + a->size + "'");
        }
        // Where the session, its autosave, recording and export live.
        const std::string session = a->session.empty() ? "lobesketch-" + timestamp() + ".json" : a->session;
        const std::string autosave = a->autosave.empty() ? beside(session, ".autosave.json") : a->autosave;
        DesktopOptions options;
        options.session_path = session;
        options.autosave_path = autosave;
        options.record_path = a->record.empty() ? beside(session, "." + timestamp() + ".lrec") : a->record;
        options.export_path = a->export_path.empty() ? beside(session, ".glb") : a->export_path;
        options.background_regrowth = a->script.empty();

        Document doc;
        std::error_code ec;
        if (a->recover) {
            if (!fs::exists(autosave, ec)) throw FileError(autosave, "there is no autosave to recover");
            doc = load_session(autosave);
            // The damaged or older session file stays as it is: saves go beside it.
            if (fs::exists(session, ec)) options.session_path = beside(session, ".recovered.json");
            progress("recovered " + autosave + "; Save writes " + options.session_path);
            options.lsystem_sketch_file = lsystem_sketch_path(autosave); // the autosave's, if any
        } else if (fs::exists(session, ec)) {
            try {
                doc = load_session(session);
            } catch (const Error& e) {
                std::string offer = fs::exists(autosave, ec)
                                        ? " The autosave " + autosave + " holds your last work: open it with "
                                              "`lobesketch desktop " + session + " --recover`."
                                        : "";
                throw Error(std::string(e.what()) + "; nothing was changed." + offer);
            }
            // The L-system sketch saved beside it, if any (docs/lsystem-sketch.md).
            options.lsystem_sketch_file = lsystem_sketch_path(session);
            // Work after the last save (a crash, a killed program) is in a newer autosave.
            std::error_code e1, e2;
            const auto saved_at = fs::last_write_time(session, e1), autosaved_at = fs::last_write_time(autosave, e2);
            try {
                if (!e1 && !e2 && autosaved_at > saved_at &&
                    read_file_limited(autosave, kMaxDocumentBytes) != read_file_limited(session, kMaxDocumentBytes))
                    warn(autosave + " is newer than " + session + " and differs: to continue from it, run "
                         "`lobesketch desktop " + session + " --recover`");
            } catch (const Error&) {
                // An unreadable autosave offers nothing; the session opened.
            }
        }

        std::vector<ScriptStep> script;
        if (!a->script.empty()) script = parse_desktop_script(read_file_limited(a->script, 16u << 20), a->script);
        std::unique_ptr<std::ofstream> log;
        if (!a->script_log.empty()) {
            log = std::make_unique<std::ofstream>(a->script_log, std::ios::trunc);
            if (!*log) throw FileError(a->script_log, "cannot write the script log");
        }

        DesktopWindowOptions wo;
        wo.width = width;
        wo.height = height;
        wo.title = "Lobesketch - " + fs::path(session).filename().string();
        wo.software = a->software;
        wo.samples = a->samples;
        wo.lod = a->lod;
        wo.frames = a->frames;
        wo.script = std::move(script);
        if (log) wo.mark = [&log](const std::string& line) { *log << line << "\n" << std::flush; };
        DesktopWindow window(std::move(wo));
        progress("desktop: " + window.renderer().device_name() + ", session " + options.session_path + ", recording " +
                 options.record_path);

        DesktopSession ds(std::move(doc), options);
        const DesktopRunResult run = window.run(ds, fs::path(options.session_path).filename().string());
        ds.finish(0.0);
        if (!a->screenshot.empty()) {
            const std::vector<std::uint8_t> png = encode_png(window.renderer().last_frame());
            write_file_atomic(a->screenshot, std::string_view(reinterpret_cast<const char*>(png.data()), png.size()));
        }
        std::set<std::string> shown; // each warning once
        for (const std::string& m : ds.messages())
            if (m.rfind("saved ", 0) != 0 && m.rfind("exported ", 0) != 0 && shown.insert(m).second) warn(m);
        char timing[160];
        std::snprintf(timing, sizeof timing, "%zu frames, median %.2f ms input+session (scene included), %.1f ms to present",
                      run.frames, run.median_session_ms, run.median_present_ms);
        progress("desktop: " + std::to_string(ds.document().strokes.size()) + " strokes, " +
                 std::to_string(ds.document().lobes.size()) + " lobes; " + timing + "; autosave " + options.autosave_path);
        exit_code = kExitOk;
    });
}

} // namespace lobe::cli
