#pragma once
/// \file cli_common.h
/// Shared helpers of the CLI subcommands: messages, settings files, recording input.

#include <string>

#include "core/document.h"
#include "core/settings.h"
#include "input/recording.h"

namespace CLI {
class App;
}

namespace lobe::cli {

void warn(const std::string& line);  ///< "lobesketch: warning: …" on stderr
void error(const std::string& line); ///< "lobesketch: error: …" on stderr
void progress(const std::string& line); ///< a progress line on stderr (suppressed by --quiet)
void set_quiet(bool quiet);

/// Prints the reader's report as warnings, one line each, naming the file.
void print_report(const std::string& path, const ReadReport& report);

/// Reads a recording and prints what had to be dropped. \throw FileError
Recording load_recording_verbose(const std::string& path);

/// Replays the recording at `path` into `doc` (its settings and seed are used): the input
/// pipeline, then the session builder with the meshing edit hooks, as `replay` does. Warnings
/// of both go to stderr naming the file; `drags` (when given) receives the number of drags.
/// \throw FileError for an unreadable recording.
Document replay_into_document(const std::string& path, Document doc, std::size_t* drags = nullptr);

/// The file name's extension, lower case, with its dot (".obj"); empty when it has none.
std::string lower_extension(const std::string& path);

/// Loads a settings JSON file (the "settings" object of a session document).
/// \throw FileError naming the file and the bad key.
Settings load_settings_file(const std::string& path);

// Subcommand registration; each sets `exit_code` when it runs.
void add_info_command(CLI::App& app, int& exit_code);
void add_replay_command(CLI::App& app, int& exit_code);
void add_import_commands(CLI::App& app, int& exit_code);
void add_synth_command(CLI::App& app, int& exit_code);
void add_lobes_command(CLI::App& app, int& exit_code);
void add_grow_command(CLI::App& app, int& exit_code);
void add_export_command(CLI::App& app, int& exit_code);

} // namespace lobe::cli
