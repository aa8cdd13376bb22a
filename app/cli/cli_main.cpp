#include "app/cli/cli.h"

#include <iostream>

#include <CLI/CLI.hpp>

#include "app/cli/cli_common.h"
#include "core/errors.h"

namespace lobe {

namespace cli {
// Crash safety (docs/crash-safety.md): app/cli/cli_recover.cpp.
void add_recover_command(CLI::App& app, int& exit_code);
// The live VR session fed from a recording: app/cli/cli_sketch.cpp.
void add_sketch_command(CLI::App& app, int& exit_code);
// Sketching in a headset (docs/vr.md): app/cli/cli_vr.cpp.
void add_vr_command(CLI::App& app, int& exit_code);
// The settings table (docs/settings.md): app/cli/cli_settings.cpp.
void add_settings_command(CLI::App& app, int& exit_code);
} // namespace cli

int run_cli(int argc, char** argv)
{
    CLI::App app{"Lobesketch: sketch trees in mid-air with your fingers.\n"
                 "Replays hand-tracking recordings into strokes, lobes and trees."};
    app.require_subcommand(1);
    bool quiet = false;
    app.add_flag("-q,--quiet", quiet, "Print no progress lines");
    app.set_version_flag("--version", std::string("lobesketch ") + "0.1.0");
    int exit_code = kExitOk;
    cli::add_info_command(app, exit_code);
    cli::add_replay_command(app, exit_code);
    cli::add_import_commands(app, exit_code);
    cli::add_synth_command(app, exit_code);
    cli::add_lobes_command(app, exit_code);
    cli::add_grow_command(app, exit_code);
    cli::add_export_command(app, exit_code);
    cli::add_render_command(app, exit_code);
    cli::add_lsystem_command(app, exit_code);
    cli::add_desktop_command(app, exit_code);
    cli::add_vr_command(app, exit_code);
    cli::add_recover_command(app, exit_code);
    cli::add_sketch_command(app, exit_code);
    cli::add_settings_command(app, exit_code);
    app.parse_complete_callback([&] { cli::set_quiet(quiet); });
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        int code = app.exit(e);
        return code == 0 ? kExitOk : kExitUsage;
    } catch (const Error& e) {
        cli::error(e.what());
        return kExitFailure;
    } catch (const std::bad_alloc&) {
        cli::error("out of memory");
        return kExitFailure;
    } catch (const std::exception& e) {
        cli::error(std::string("unexpected failure: ") + e.what());
        return kExitFailure;
    }
    return exit_code;
}

} // namespace lobe
