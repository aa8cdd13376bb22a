#include "app/cli/cli.h"

#include <algorithm>
#include <iostream>
#include <string>
#include <vector>

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

namespace {

/// Edits (insert, delete, replace) between two short words.
std::size_t edit_distance(const std::string& a, const std::string& b)
{
    std::vector<std::size_t> row(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i) {
        std::size_t diagonal = row[0];
        row[0] = i;
        for (std::size_t j = 1; j <= b.size(); ++j) {
            const std::size_t above = row[j];
            row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
            diagonal = above;
        }
    }
    return row[b.size()];
}

/// The first argument that is not an option of the program itself (they are all flags) names
/// the subcommand: when it names none, one line saying so and listing them, else empty.
std::string unknown_command(CLI::App& app, int argc, char** argv)
{
    std::vector<std::string> names;
    for (const CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) names.push_back(sub->get_name());
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        if (arg.empty() || arg[0] == '-') continue;
        if (std::find(names.begin(), names.end(), arg) != names.end()) return {};
        std::string list, closest;
        std::size_t best = 3; // a suggestion only within two edits
        for (const std::string& n : names) {
            list += (list.empty() ? "" : ", ") + n;
            const std::size_t d = edit_distance(arg, n);
            if (d < best) {
                best = d;
                closest = n;
            }
        }
        return "unknown command '" + arg + "'" + (closest.empty() ? "" : " (did you mean '" + closest + "'?)") +
               "; the commands are " + list;
    }
    return {};
}

} // namespace

int run_cli(int argc, char** argv)
{
    CLI::App app{"Lobesketch: sketch trees in mid-air with your fingers.\n"
                 "Replays hand-tracking recordings into strokes, lobes and trees."};
    app.require_subcommand(1);
    bool quiet = false;
    app.add_flag("-q,--quiet", quiet, "Print no progress lines");
    app.set_version_flag("--version", std::string("lobesketch ") + "0.1.0");
    // -q (and --help, --version) also after the subcommand: options a subcommand does not know
    // go to the program's (subcommands made after this inherit it).
    app.fallthrough();
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
    if (const std::string unknown = unknown_command(app, argc, argv); !unknown.empty()) {
        cli::error(unknown);
        return kExitUsage;
    }
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        if (e.get_exit_code() == 0) return app.exit(e) == 0 ? kExitOk : kExitUsage; // --help, --version
        // One line, as every other error: what is wrong and where the help is.
        std::string command = "lobesketch";
        for (const CLI::App* sub : app.get_subcommands()) command += " " + sub->get_name();
        cli::error(one_line_message(e.what()) + " (see '" + command + " --help')");
        return kExitUsage;
    } catch (const cli::UsageError& e) {
        cli::error(e.what());
        return kExitUsage;
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
