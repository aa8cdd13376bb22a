#pragma once
/// \file cli_common.h
/// Shared helpers of the CLI subcommands: messages, settings files, recording input.

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "app/session/tree_pipeline.h"
#include "core/document.h"
#include "core/errors.h"
#include "core/settings.h"
#include "core/settings_json.h" // the commands that write settings as JSON (settings_json)
#include "core/settings_table.h"
#include "growth/wood.h"
#include "input/recording.h"

namespace CLI {
class App;
class Validator;
}

namespace lobe::cli {

void warn(const std::string& line);  ///< "lobesketch: warning: …" on stderr
void error(const std::string& line); ///< "lobesketch: error: …" on stderr
void progress(const std::string& line); ///< a progress line on stderr (suppressed by --quiet)
void set_quiet(bool quiet);

/// A bad command line found after CLI11 has parsed it (an input of a kind the command does
/// not take, options that cannot go together), before any work: printed as one line, exit 2
/// (kExitUsage). An InvalidInput, so code that checks options without the CLI still catches it.
class UsageError : public InvalidInput {
public:
    using InvalidInput::InvalidInput;
};

/// A CLI11 check of a number: finite and in [lo, hi] (CLI::Range lets "nan" through).
CLI::Validator finite_range(double lo, double hi);
/// A CLI11 check of --species: a shipped preset's name, or a .json file (read later).
CLI::Validator species_check();
/// A CLI11 check of a seed: a whole number 0 to 2^64-1 ("-1" would wrap to 2^64-1).
CLI::Validator seed_check();
/// A CLI11 check of an output file's extension: one of `extensions` (lower case, with the
/// dot); `what` says what is written ("the tree is written as .glb or .obj").
CLI::Validator output_extension(std::vector<std::string> extensions, std::string what);

/// \throw FileError when the folder `path` would be written in does not exist (checked before
/// the work, so a typo in --out does not cost a whole growth).
void require_output_folder(const std::string& path);

/// Refuses, as a bad command line, an input whose extension says it is not one `command`
/// takes (a .glb, a picture, an L-system file, a session where a recording is wanted, …),
/// naming what it takes. `takes` lists them ("a recording, a session document (.json) or a
/// mesh (.obj/.ply/.off)"). Recordings may have any extension, so unknown ones pass.
/// \throw UsageError
void check_input_kind(const std::string& path, const std::string& command, const std::string& takes,
                      bool takes_session, bool takes_mesh);

/// True when `path` holds a Lobesketch session document (a JSON object whose "format" is
/// "lobesketch-session"), whatever its extension.
bool is_session_file(const std::string& path);
/// True when `path` starts as a Lobesketch recording does (binary or text form).
bool is_recording_file(const std::string& path);

/// Warns (one line) when an option that applies only to a mesh input was given for another
/// input: `option` ("--size") was set on the command line, `input` is not a mesh.
void warn_mesh_only_option(const std::string& input, const std::string& option);

/// Prints the reader's report as warnings, one line each, naming the file.
void print_report(const std::string& path, const ReadReport& report);

/// Reads a recording and prints what had to be dropped. \throw FileError
Recording load_recording_verbose(const std::string& path);

/// Loads a settings JSON file (the "settings" object of a session document).
/// \throw FileError naming the file and the bad key.
Settings load_settings_file(const std::string& path);

/// The options that say how a tree is grown from an input (`grow`, `export`, `render`).
struct TreeInputOptions {
    std::string settings; ///< settings JSON file (empty: none)
    std::string species;  ///< preset name or .json file (empty: the settings')
    std::string grower;   ///< growth model (growth/grower.h; empty: the session's)
    std::vector<std::string> set; ///< `--set KEY=VALUE`, in the order given
    std::optional<std::uint64_t> seed;
    std::optional<double> split_angle, spacing;
    double mesh_size = 1.5; ///< a mesh input's largest side (metres)
    std::string lsystem;    ///< `--lsystem FILE.l`: the lsystem grower with that file (empty: none)
    /// The tree's height in metres: settings.growth.height_m (real scale, apply_real_scale),
    /// and an L-system tree grown without lobes is this tall.
    std::optional<double> height;
    std::optional<double> pipe_exponent, tip_radius; ///< settings.branches.pipe_exponent, tip_radius_m
    /// The self-organizing grower's parameters (growth/selforg/selforg_grower.h); only with
    /// that grower. `--species` also sets its `species` when it names one of its presets.
    std::optional<std::string> environment, bud_fate;
    std::optional<std::int64_t> iterations;
};

/// Registers --settings, --species, --grower, --lsystem, --set, --seed, --split-angle,
/// --attractor-spacing, --pipe-exponent, --tip-radius, and the self-organizing grower's --environment, --bud-fate and
/// --iterations. The help and range checks of --set, --split-angle and
/// --attractor-spacing come from the settings table: a bad value is a bad command line (exit
/// 2) naming the setting.
void add_tree_input_options(CLI::App* cmd, TreeInputOptions& o);
/// Registers --pipe-exponent and --tip-radius alone (replay, which takes no other tree
/// input options).
void add_radius_options(CLI::App* cmd, TreeInputOptions& o);

/// `--set` assignments ("growth.split_angle_deg=25"), in order, as an overlay.
/// \throw InvalidInput naming the key (unknown, a value of the wrong form or out of range).
SettingsOverlay setting_assignments(const std::vector<std::string>& assignments);

/// Applies the options to `s` in this order, which is a contract (docs/settings.md): the
/// settings file is the caller's (it replaces the settings first), then the species preset,
/// then each `--set` in the order given, then --split-angle, --attractor-spacing,
/// --pipe-exponent, --tip-radius and --height (growth.height_m, when > 0); then the
/// result is validated (settings that contradict each other are refused here). --seed sets
/// the document's seed, not a setting. \throw InvalidInput
void apply_tree_input_options(Settings& s, const TreeInputOptions& o);

/// Applies the options that are the document's rather than its settings': --seed and
/// --grower (the scene's tree grows with that grower and its default parameters, or those
/// --environment, --bud-fate, --iterations and --species give the self-organizing grower;
/// without --grower they change the session's self-organizing grower); --lsystem FILE.l
/// makes it the lsystem grower with that file (lsystem_file_choice).
/// \throw FileError for an unreadable --lsystem file; UsageError (a bad command line) when
/// --grower names another grower than lsystem beside --lsystem, or (one line) for a
/// self-organizing option with another grower.
void apply_document_options(Document& doc, const TreeInputOptions& o);

/// The local time as "YYYYMMDD-HHMMSS", for default file names.
std::string timestamp();
/// A wood estimate as the report and `info --json` write it (docs/wood-and-co2.md):
/// wood_volume_m3, dry_biomass_kg, carbon_kg, co2_kg, density_kg_m3.
nlohmann::json wood_json(const WoodEstimate& e);

/// "tree.json" → "tree<suffix>" beside it.
std::string beside(const std::string& session, const std::string& suffix);

/// Replays the recording at `path` into `doc` (its settings and seed are used): the input
/// pipeline, then the session builder with the meshing edit hooks, as `replay` does. Warnings
/// of both go to stderr naming the file; `drags` (when given) receives the number of drags.
/// \throw FileError for an unreadable recording.
Document replay_into_document(const std::string& path, Document doc, std::size_t* drags = nullptr);

/// Lower-case extension of `path` (".json").
std::string lower_extension(const std::string& path);
/// An .obj, .ply or .off file.
bool is_mesh_file(const std::string& path);

/// A document and its grown tree.
struct GrownInput {
    Document doc;
    BuiltTree tree;
};

/// Grows the tree of `input`: a session document (.json), a mesh (.obj/.ply/.off, one lobe
/// of `mesh_size`) or a recording (run through the input pipeline and the session builder,
/// warnings printed naming the file), with the options applied. `before_growing` (when given)
/// sees the document of a session or mesh input once its settings are final, before the
/// tree is grown (a recording's events may still change them as it is replayed).
/// \throw FileError, InvalidInput
GrownInput grow_input_tree(const std::string& input, const TreeInputOptions& o,
                           const std::function<void(const Document&)>& before_growing = {});

/// The lsystem grower's choice for the L-system file `path`: its text as `source`, the path
/// as `source_name`, the view file beside it (NAME.v) as `view` when there is one.
/// \throw FileError when a file cannot be read or is larger than lsystem::kMaxFileBytes.
GrowerChoice lsystem_file_choice(const std::string& path);

/// An L-system file's tree, and what else its growth gives.
struct LSystemGrown {
    GrownInput grown;
    std::string word;        ///< the derived word as text (lsystem::to_string)
    std::size_t modules = 0; ///< its modules
    double grow_ms = 0.0;    ///< derivation and turtle, milliseconds
};

/// Grows the L-system file `path` (`lsystem`, `render FILE.l`): alone, or in the lobes of the
/// session `lobes_session` (its trunk strokes, settings and seed); --settings, --set, --seed
/// and --height of `o` applied. The reader's and the turtle's warnings go to stderr, one line
/// each. \throw FileError, InvalidInput (a malformed file: one line naming file, line and column)
LSystemGrown grow_lsystem_file(const std::string& path, const std::string& lobes_session, std::optional<int> steps,
                               const TreeInputOptions& o);

// Subcommand registration; each sets `exit_code` when it runs.
void add_info_command(CLI::App& app, int& exit_code);
void add_replay_command(CLI::App& app, int& exit_code);
void add_import_commands(CLI::App& app, int& exit_code);
void add_synth_command(CLI::App& app, int& exit_code);
void add_lobes_command(CLI::App& app, int& exit_code);
void add_grow_command(CLI::App& app, int& exit_code);
void add_export_command(CLI::App& app, int& exit_code);
void add_render_command(CLI::App& app, int& exit_code);
void add_desktop_command(CLI::App& app, int& exit_code);
void add_lsystem_command(CLI::App& app, int& exit_code);

} // namespace lobe::cli
