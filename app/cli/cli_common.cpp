#include "app/session/session_file.h"
#include "app/cli/cli_common.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "app/session/edit_hooks.h"
#include "app/session/session_builder.h"
#include "core/atomic_file.h"
#include "core/document.h"
#include "core/errors.h"
#include "core/settings_json.h"
#include "core/settings_table.h"
#include "growth/grower.h"
#include "growth/lsystem/lsystem_grower.h"
#include "growth/selforg/selforg_grower.h"
#include "growth/species.h"
#include "input/pipeline.h"
#include "input/recording_format.h"
#include "app/session/stage_options.h"
#include "meshing/mesh_io.h"

namespace lobe::cli {

namespace {
bool g_quiet = false;
}

void set_quiet(bool quiet) { g_quiet = quiet; }
void warn(const std::string& line) { std::cerr << "lobesketch: warning: " << line << '\n'; }
void error(const std::string& line) { std::cerr << "lobesketch: error: " << line << '\n'; }
void progress(const std::string& line)
{
    if (!g_quiet) std::cerr << line << '\n';
}

CLI::Validator finite_range(double lo, double hi)
{
    return CLI::Validator(
        [lo, hi](std::string& text) {
            double v = 0.0;
            std::size_t used = 0;
            try {
                v = std::stod(text, &used);
            } catch (const std::exception&) {
                used = 0;
            }
            if (used != text.size() || !std::isfinite(v) || v < lo || v > hi) {
                std::ostringstream range;
                range << lo << " to " << hi;
                return "expected a number from " + range.str() + " (got '" + text + "')";
            }
            return std::string();
        },
        "", "finite range");
}

CLI::Validator species_check()
{
    return CLI::Validator(
        [](std::string& text) {
            if (lower_extension(text) == ".json") return std::string(); // a preset file: read later
            const std::vector<std::string> known = species_names();
            if (std::find(known.begin(), known.end(), text) != known.end()) return std::string();
            std::string list;
            for (const std::string& n : known) list += n + ", ";
            return "unknown species '" + text + "' (known: " + list + "or a preset .json file)";
        },
        "", "species");
}

CLI::Validator seed_check()
{
    return CLI::Validator(
        [](std::string& text) {
            const bool digits = !text.empty() && text.size() <= 20 &&
                                std::all_of(text.begin(), text.end(), [](unsigned char c) { return std::isdigit(c); });
            if (!digits || (text.size() == 20 && text > "18446744073709551615"))
                return "a seed is a whole number from 0 to 18446744073709551615 (got '" + text + "')";
            return std::string();
        },
        "", "seed");
}

CLI::Validator output_extension(std::vector<std::string> extensions, std::string what)
{
    return CLI::Validator(
        [extensions, what](std::string& text) {
            const std::string ext = lower_extension(text);
            if (std::find(extensions.begin(), extensions.end(), ext) != extensions.end()) return std::string();
            return text + ": " + what;
        },
        "", "output extension");
}

void require_output_folder(const std::string& path)
{
    const std::filesystem::path folder = std::filesystem::path(path).parent_path();
    if (folder.empty()) return;
    std::error_code ec;
    if (std::filesystem::is_directory(folder, ec)) return;
    if (std::filesystem::exists(folder, ec))
        throw FileError(path, "'" + folder.string() + "' is not a folder");
    throw FileError(path, "the folder '" + folder.string() + "' does not exist");
}

bool is_session_file(const std::string& path)
{
    std::ifstream in{path, std::ios::binary};
    char c = 0;
    while (in.get(c) && std::isspace(static_cast<unsigned char>(c))) {
    }
    if (!in || c != '{') return false;
    try {
        const nlohmann::json j = nlohmann::json::parse(read_file_limited(path, 256u << 20), nullptr, false);
        return j.is_object() && j.contains("format") && j["format"] == "lobesketch-session";
    } catch (const std::exception&) {
        return false;
    }
}

bool is_recording_file(const std::string& path)
{
    std::ifstream in{path, std::ios::binary};
    std::string head(64, '\0');
    in.read(head.data(), static_cast<std::streamsize>(head.size()));
    head.resize(static_cast<std::size_t>(in.gcount()));
    if (head.rfind("\xEF\xBB\xBF", 0) == 0) head.erase(0, 3); // a UTF-8 BOM before the text form
    namespace rf = recording_format;
    const std::string binary(reinterpret_cast<const char*>(rf::kMagic.data()), rf::kMagic.size());
    return head.rfind(binary, 0) == 0 || head.rfind(std::string(rf::kTextMagic), 0) == 0;
}

void check_input_kind(const std::string& path, const std::string& command, const std::string& takes,
                      bool takes_session, bool takes_mesh)
{
    const std::string ext = lower_extension(path);
    std::string kind;
    if (ext == ".glb" || ext == ".gltf") kind = "a glTF file (an exported tree)";
    else if (ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".bmp" || ext == ".tga" || ext == ".webp")
        kind = "a picture";
    else if (ext == ".mtl") kind = "an OBJ material file";
    else if (ext == ".fbx" || ext == ".stl" || ext == ".dae" || ext == ".3ds" || ext == ".blend")
        kind = "a model in a format lobesketch does not read";
    else if (ext == ".l" || ext == ".v") kind = "an L-system file (grow it with 'lobesketch lsystem FILE.l')";
    else if (!takes_session && ext == ".json")
        kind = is_session_file(path) ? "a Lobesketch session document" : "a JSON file";
    else if (!takes_mesh && is_mesh_file(path)) kind = "a mesh";
    else if (ext == ".obj") {
        // An OBJ this program exported is a whole tree, not a lobe to grow one in.
        std::ifstream in{path, std::ios::binary};
        std::string first;
        std::getline(in, first);
        if (first.rfind("# Lobesketch: ", 0) == 0 && first.find("origin at the trunk base") != std::string::npos)
            kind = "a tree exported by lobesketch (a mesh input is the lobe a tree grows in)";
    }
    if (kind.empty()) return;
    throw UsageError(path + ": " + kind + " is not an input " + command + " takes (" + takes + ")");
}

void warn_mesh_only_option(const std::string& input, const std::string& option)
{
    if (is_mesh_file(input)) return;
    warn(option + " applies only to a mesh input (.obj/.ply/.off); ignored for " + input);
}

void print_report(const std::string& path, const ReadReport& report)
{
    for (const std::string& p : report.problems) warn(path + ": " + p);
    if (report.frames_dropped > 0)
        warn(path + ": dropped " + std::to_string(report.frames_dropped) + " frame(s), kept " +
             std::to_string(report.frames_read));
}

Recording load_recording_verbose(const std::string& path)
{
    ReadReport report;
    Recording rec;
    try {
        rec = read_recording(path, &report);
    } catch (const FileError& e) {
        // Captures of other programs are a common mix-up: say which command converts them.
        std::string head;
        if (std::ifstream in{path, std::ios::binary}) {
            head.resize(16);
            in.read(head.data(), 16);
            head.resize(static_cast<std::size_t>(in.gcount()));
        }
        const std::string what = e.what();
        if (head.rfind("{", 0) == 0 && what.find("magic") != std::string::npos && is_session_file(path))
            throw Error(path + ": a Lobesketch session document, not a recording (grow, export, render and lobes "
                               "take sessions; 'lobesketch info' shows one)");
        if (head.rfind("glTF", 0) == 0 && what.find("magic") != std::string::npos)
            throw Error(path + ": a glTF binary (an exported tree), not a recording");
        if (head.rfind("\x89PNG", 0) == 0 && what.find("magic") != std::string::npos)
            throw Error(path + ": a PNG picture, not a recording");
        if (head.rfind("{", 0) == 0 && what.find("magic") != std::string::npos)
            throw Error(what + " (a Leap Motion JSON capture? convert it with 'lobesketch import-leap')");
        if (head.rfind("var ", 0) == 0 && what.find("magic") != std::string::npos)
            throw Error(what + " (a WebXR capture? convert it with 'lobesketch import-webxr')");
        throw;
    }
    print_report(path, report);
    return rec;
}

Settings load_settings_file(const std::string& path)
{
    const std::string text = read_file_limited(path, 16u << 20);
    nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
    if (j.is_discarded()) throw FileError(path, "not valid JSON");
    try {
        // Accept a bare settings object or a whole session document's "settings".
        if (j.is_object() && j.contains("format") && j.contains("settings")) return settings_from_json(j["settings"]);
        return settings_from_json(j);
    } catch (const InvalidInput& e) {
        throw FileError(path, e.what());
    }
}

namespace {

/// A CLI11 check of one setting's value on the command line: the settings table's parse and
/// range, its message naming the setting.
CLI::Validator setting_value_check(const SettingInfo& info)
{
    return CLI::Validator(
        [&info](std::string& text) {
            try {
                Settings scratch;
                set_setting_text(scratch, info, text);
                return std::string();
            } catch (const InvalidInput& e) {
                return std::string(e.what());
            }
        },
        info.allowed(), info.key);
}

/// The help of an option that sets one setting: its key and doc line.
std::string setting_help(const SettingInfo& info) { return "Sets " + info.key + ": " + info.doc; }

/// "KEY=VALUE" applied to `overlay`. \throw InvalidInput
void add_assignment(SettingsOverlay& overlay, const std::string& assignment)
{
    const std::size_t eq = assignment.find('=');
    if (eq == std::string::npos || eq == 0)
        throw InvalidInput("expected KEY=VALUE (e.g. growth.split_angle_deg=25), not '" + assignment + "'");
    overlay.set_text(assignment.substr(0, eq), assignment.substr(eq + 1));
}

} // namespace

void add_radius_options(CLI::App* cmd, TreeInputOptions& o);

void add_tree_input_options(CLI::App* cmd, TreeInputOptions& o)
{
    const SettingInfo& split = *find_setting("growth.split_angle_deg");
    const SettingInfo& spacing = *find_setting("lobes.edge_length_m");
    cmd->add_option("--settings", o.settings, "Settings JSON (a settings object or a session document)");
    cmd->add_option("--species", o.species,
                    "Species preset: broadleaf, conifer, willow, birch, or a preset .json file (with the "
                    "self-organizing grower also its growth preset)")
        ->check(species_check());
    std::vector<std::string> names;
    for (const Grower* g : growers()) names.emplace_back(g->name());
    cmd->add_option("--grower", o.grower, "Growth model: " + grower_names() + " (default: the session's, else " +
                                              std::string(kDefaultGrowerName) + ")")
        ->check(CLI::IsMember(names));
    cmd->add_option("--lsystem", o.lsystem,
                    "L-system file (cpfg's .l, with NAME.v beside it) for the lsystem grower; implies --grower lsystem");
    cmd->add_option("--set", o.set,
                    "Sets one setting (repeatable): growth.split_angle_deg=25, leaves.color=0.2,0.4,0.1. Applied "
                    "after --settings and --species, in the order given, before --split-angle and "
                    "--attractor-spacing; `lobesketch settings` lists the keys")
        ->type_name("KEY=VALUE")
        ->allow_extra_args(false)
        ->check(CLI::Validator(
            [](std::string& text) {
                try {
                    SettingsOverlay scratch;
                    add_assignment(scratch, text);
                    return std::string();
                } catch (const InvalidInput& e) {
                    return std::string(e.what());
                }
            },
            "", "setting assignment"));
    cmd->add_option("--seed", o.seed, "Seed of every random choice of growth (default: the session's)")->check(seed_check());
    cmd->add_option("--environment", o.environment,
                    "Self-organizing grower: what buds perceive, markers (space colonization) or shadow")
        ->check(CLI::IsMember({"markers", "shadow"}));
    cmd->add_option("--bud-fate", o.bud_fate, "Self-organizing grower: borchert-honda or priority")
        ->check(CLI::IsMember({"borchert-honda", "priority"}));
    cmd->add_option("--iterations", o.iterations, "Self-organizing grower: growth iterations (1 to 500)")
        ->check(CLI::Range(std::int64_t{1}, std::int64_t{500}));
    cmd->add_option("--split-angle", o.split_angle, setting_help(split))->check(setting_value_check(split));
    cmd->add_option("--attractor-spacing", o.spacing, setting_help(spacing))->check(setting_value_check(spacing));
    add_radius_options(cmd, o);
}

void add_radius_options(CLI::App* cmd, TreeInputOptions& o)
{
    const SettingInfo& exponent = *find_setting("branches.pipe_exponent");
    const SettingInfo& tip = *find_setting("branches.tip_radius_m");
    cmd->add_option("--pipe-exponent", o.pipe_exponent,
                    setting_help(exponent) + "; given, it is used at real scale too (branches.dbh_ratio=0)")->check(setting_value_check(exponent));
    cmd->add_option("--tip-radius", o.tip_radius, setting_help(tip) + " (metres)")->check(setting_value_check(tip));
}

SettingsOverlay setting_assignments(const std::vector<std::string>& assignments)
{
    SettingsOverlay overlay;
    for (const std::string& a : assignments) add_assignment(overlay, a);
    return overlay;
}

void apply_tree_input_options(Settings& s, const TreeInputOptions& o)
{
    if (!o.species.empty()) {
        const Settings before = s;
        apply_species(s, load_species(o.species));
        if (!o.settings.empty()) {
            // The species is applied after the settings file: say which of the file's values it replaced.
            std::vector<std::string> changed;
            for (const SettingInfo& info : settings_table())
                if (setting_text(before, info) != setting_text(s, info)) changed.push_back(info.key);
            if (!changed.empty()) {
                std::string keys;
                for (std::size_t i = 0; i < changed.size() && i < 5; ++i) keys += (i ? ", " : "") + changed[i];
                if (changed.size() > 5) keys += ", …";
                warn("--species " + o.species + " replaces " + std::to_string(changed.size()) + " setting(s) of --settings " +
                     o.settings + " (" + keys + "): the species wins; --set applies after both");
            }
        }
    }
    setting_assignments(o.set).apply_to(s);
    if (o.split_angle) s.growth.split_angle_deg = *o.split_angle;
    if (o.spacing) s.lobes.edge_length_m = *o.spacing;
    if (o.pipe_exponent) {
        s.branches.pipe_exponent = *o.pipe_exponent;
        s.branches.dbh_ratio = 0.0; // the exponent given, not one fitted to the trunk
    }
    if (o.tip_radius) s.branches.tip_radius_m = *o.tip_radius;
    if (o.height && *o.height > 0.0) s.growth.height_m = *o.height;
    validate_settings(s);
}

std::string lower_extension(const std::string& path)
{
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return ext;
}

std::string timestamp()
{
    const std::time_t now = std::time(nullptr);
    std::tm tm{};
    localtime_r(&now, &tm);
    char buf[32];
    std::strftime(buf, sizeof buf, "%Y%m%d-%H%M%S", &tm);
    return buf;
}

std::string beside(const std::string& session, const std::string& suffix)
{
    const std::filesystem::path p(session);
    return (p.parent_path() / (p.stem().string() + suffix)).string();
}

Document replay_into_document(const std::string& path, Document doc, std::size_t* drags)
{
    const Recording rec = load_recording_verbose(path);
    const double duration = rec.frames.empty() ? 0.0 : rec.frames.back().time - rec.frames.front().time;
    progress("replaying " + std::to_string(rec.frames.size()) + " frames (" + std::to_string(duration).substr(0, 6) +
             " s) of " + path);
    const InputResult result = run_input_pipeline(rec, input_options(doc.settings));
    for (const std::string& m : result.messages) warn(path + ": " + m);
    if (drags) *drags = result.drags.size();
    doc.source_recording = std::filesystem::absolute(path).lexically_normal().string();
    EditHooks hooks = meshing_edit_hooks(edit_apply_options(doc.settings));
    // Meshes imported during the session lie beside the recording (import_mesh_path).
    hooks.import_model = [path](int n) {
        const std::string file = import_mesh_path(path, n);
        return std::make_shared<const LobeModel>(
            LobeModel{std::filesystem::path(file).filename().string(), read_mesh(file)});
    };
    const EditPickOptions pick = edit_pick_options(doc.settings);
    SessionBuilder builder(std::move(doc), pick, std::move(hooks));
    builder.apply(result.actions);
    for (const std::string& m : builder.messages()) warn(path + ": " + m);
    return builder.take_document();
}

bool is_mesh_file(const std::string& path)
{
    const std::string ext = lower_extension(path);
    return ext == ".obj" || ext == ".ply" || ext == ".off";
}

void apply_document_options(Document& doc, const TreeInputOptions& o)
{
    if (o.seed) doc.seed = *o.seed;
    const char* only_selforg = o.environment ? "--environment" : o.bud_fate ? "--bud-fate" : o.iterations ? "--iterations" : nullptr;
    const std::string selforg(self_organizing_grower().name());
    if (!o.lsystem.empty()) {
        if (!o.grower.empty() && o.grower != lsystem::kGrowerName)
            throw UsageError("--lsystem: an L-system file grows with --grower " + std::string(lsystem::kGrowerName) +
                               ", not " + o.grower);
        if (only_selforg)
            throw UsageError(std::string(only_selforg) + " is only valid with --grower " + selforg + " (the grower is " +
                               std::string(lsystem::kGrowerName) + ")");
        GrowerChoice choice = lsystem_file_choice(o.lsystem);
        if (o.height) choice.params["height_m"] = *o.height;
        set_scene_grower(doc, std::move(choice));
        return;
    }
    GrowerChoice choice;
    if (!o.grower.empty()) {
        choice.name = o.grower;
        if (const Grower* g = find_grower(o.grower)) choice.version = g->version();
    } else {
        choice = scene_grower(doc);
    }
    if (only_selforg && choice.name != selforg)
        throw UsageError(std::string(only_selforg) + " is only valid with --grower " + selforg + " (the grower is " +
                           choice.name + ")");
    if (choice.name == selforg) {
        if (o.environment) choice.params["environment"] = *o.environment;
        if (o.bud_fate) choice.params["bud_fate"] = *o.bud_fate;
        if (o.iterations) choice.params["iterations"] = *o.iterations;
        const std::vector<std::string> presets = selforg_species_list();
        if (std::find(presets.begin(), presets.end(), o.species) != presets.end()) choice.params["species"] = o.species;
    }
    if (!o.grower.empty() || choice != scene_grower(doc)) set_scene_grower(doc, std::move(choice));
}

GrownInput grow_input_tree(const std::string& input, const TreeInputOptions& o,
                           const std::function<void(const Document&)>& before_growing)
{
    GrownInput out;
    Document& doc = out.doc;
    if (!o.settings.empty()) doc.settings = load_settings_file(o.settings);
    const std::string ext = lower_extension(input);
    if (ext == ".json") {
        doc = load_session(input);
        if (!o.settings.empty()) doc.settings = load_settings_file(o.settings);
    }
    apply_tree_input_options(doc.settings, o);
    apply_document_options(doc, o);
    if (before_growing && (ext == ".json" || is_mesh_file(input))) before_growing(doc);
    if (is_mesh_file(input)) {
        const BuiltLobe lobe = model_lobe(input, doc.settings, o.mesh_size);
        LobeRecord rec;
        rec.id = 1;
        rec.model = std::make_shared<const LobeModel>(LobeModel{input, lobe.mesh});
        doc.lobes.push_back(std::move(rec));
        out.tree = grow_document_tree(doc, {lobe});
        apply_real_scale(doc, out.tree);
        return out;
    }
    if (ext != ".json") doc = replay_into_document(input, std::move(doc));
    out.tree = build_document_tree(doc);
    apply_real_scale(doc, out.tree);
    return out;
}

nlohmann::json wood_json(const WoodEstimate& e)
{
    return nlohmann::json{{"wood_volume_m3", e.wood_volume_m3},
                          {"dry_biomass_kg", e.dry_biomass_kg},
                          {"carbon_kg", e.carbon_kg},
                          {"co2_kg", e.co2_kg},
                          {"density_kg_m3", e.density_kg_m3}};
}

} // namespace lobe::cli
