// `lobesketch lsystem FILE.l --out tree.glb`: a tree from an L-system in cpfg's language
// (growth/lsystem/, docs/lsystem-turtle.md), alone or in the lobes of a session; and the L-system
// file input of `render FILE.l` and `grow --lsystem FILE.l`.
#include <chrono>
#include <filesystem>
#include <memory>
#include <optional>

#include <CLI/CLI.hpp>

#include "app/cli/cli.h"
#include "app/cli/cli_common.h"
#include "app/export/skeleton_json.h"
#include "app/live/lsystem_sketch_mode.h"
#include "app/export/tree_output.h"
#include "app/session/session_file.h"
#include "app/session/tree_pipeline.h"
#include "core/atomic_file.h"
#include "core/errors.h"
#include "growth/lsystem/lsystem_grower.h"
#include "growth/lsystem/presets.h"
#include "growth/lsystem/sketch.h"

namespace lobe::cli {

GrowerChoice lsystem_file_choice(const std::string& path)
{
    GrowerChoice choice;
    choice.name = lsystem::kGrowerName;
    choice.version = lsystem_grower().version();
    std::error_code exists_ec;
    if (!std::filesystem::exists(path, exists_ec)) {
        // A shipped preset's name where no file of that name is (docs/lsystems.md).
        if (lsystem::find_preset(path)) {
            choice.params["preset"] = path;
            return choice;
        }
        throw FileError(path, "no such file, nor a shipped L-system preset (" + lsystem::preset_names_text() + ")");
    }
    choice.params["source"] = read_file_limited(path, lsystem::kMaxFileBytes);
    choice.params["source_name"] = path;
    std::filesystem::path view(path);
    view.replace_extension(".v");
    std::error_code ec;
    if (std::filesystem::is_regular_file(view, ec)) choice.params["view"] = read_file_limited(view.string(), lsystem::kMaxFileBytes);
    return choice;
}

namespace {

/// Grows the lsystem grower's `choice` (named `path` in messages) as grow_lsystem_file says.
LSystemGrown grow_lsystem_choice(GrowerChoice choice, const std::string& path, const std::string& lobes_session,
                                 std::optional<int> steps, const TreeInputOptions& o)
{
    LSystemGrown out;
    Document& doc = out.grown.doc;
    if (!lobes_session.empty()) doc = load_session(lobes_session);
    if (!o.settings.empty()) doc.settings = load_settings_file(o.settings);
    apply_tree_input_options(doc.settings, o);
    if (o.seed) doc.seed = *o.seed;
    if (!o.grower.empty() && o.grower != lsystem::kGrowerName)
        warn(path + ": an L-system file grows with the " + std::string(lsystem::kGrowerName) + " grower; --grower " + o.grower +
             " does not apply");
    if (steps) choice.params["steps"] = std::int64_t{*steps};
    if (o.height) choice.params["height_m"] = *o.height;
    set_scene_grower(doc, std::move(choice));

    BuiltTree& tree = out.grown.tree;
    if (!lobes_session.empty()) {
        std::vector<std::string> warnings;
        tree.lobes = build_document_lobes(doc, &warnings);
        for (const std::string& w : warnings) warn(lobes_session + ": " + w);
    }
    const auto t0 = std::chrono::steady_clock::now();
    lsystem::LSystemRun run = lsystem::run_lsystem(document_grower_input(doc, tree.lobes));
    out.grow_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    out.modules = run.word.size();
    out.word = lsystem::to_string(run.system, run.word);
    tree.growth = std::move(run.growth);
    // The reader's and the turtle's messages, one line each as they are (they name the file).
    for (const std::string& m : tree.growth.messages) warn(m);
    tree.growth.messages.clear();
    finish_grown_tree(doc, tree);
    return out;
}

/// The lsystem grower's choice for a sketch file: the rules derived from it (sketch.h) at
/// `growth` (0: the sketch's iterations), named `rules_name` in messages.
GrowerChoice sketch_choice(const std::string& path, double growth, const std::string& rules_name, const std::string& sketch_out,
                           lsystem::SketchRules& rules)
{
    lsystem::Sketch sketch;
    if (is_recording_file(path)) {
        // A recording of the live L-system sketch mode: the sketch as its replay leaves it,
        // shown at the growth it was left at.
        const LSystemSketchMode mode = replay_lsystem_sketch(load_recording_verbose(path));
        for (const std::string& m : mode.messages()) progress(path + ": " + m);
        if (mode.sketch().trunk.size() < 2)
            throw InvalidInput(path + ": the recording sketches no L-system trunk (P turns the L-system sketch mode on)");
        sketch = mode.sketch_file();
        if (growth <= 0.0) growth = mode.growth();
    } else {
        sketch = lsystem::parse_sketch(read_file_limited(path, lsystem::kMaxSketchFileBytes), path);
    }
    if (!sketch_out.empty()) {
        write_file_atomic(sketch_out, lsystem::sketch_json(sketch) + "\n");
        progress("wrote " + sketch_out);
    }
    lsystem::SketchRulesOptions ro;
    ro.growth = growth;
    rules = lsystem::sketch_rules(sketch, ro);
    return lsystem::sketch_grower_choice(rules, rules_name);
}

std::string view_path_of(const std::string& rules_path)
{
    std::filesystem::path v(rules_path);
    v.replace_extension(".v");
    return v.string();
}

} // namespace

LSystemGrown grow_lsystem_file(const std::string& path, const std::string& lobes_session, std::optional<int> steps,
                               const TreeInputOptions& o)
{
    return grow_lsystem_choice(lsystem_file_choice(path), path, lobes_session, steps, o);
}

void add_lsystem_command(CLI::App& app, int& exit_code)
{
    auto* cmd = app.add_subcommand(
        "lsystem", "Grow a tree from an L-system file (cpfg's .l, with the .v beside it) or from a sketch (--sketch), "
                   "and export it as .glb or .obj");
    struct Args {
        TreeInputOptions in;
        std::string file, out, lobes, string_out, skeleton_out, sketch, rules_out, sketch_out;
        std::optional<int> steps;
        std::optional<double> growth;
    };
    auto a = std::make_shared<Args>();
    auto* file_opt = cmd->add_option(
        "FILE", a->file, "L-system file (.l; NAME.v beside it is its view file), or a shipped preset's name (docs/lsystems.md)");
    auto* sketch_opt = cmd->add_option("--sketch", a->sketch,
                                       "Grow the parametric 2L-system derived from this sketch file, or from the L-system sketch "
                                       "a recording (.lrec) replays to, instead (docs/lsystem-sketch.md)")
                           ->excludes(file_opt);
    cmd->add_option("--rules-out", a->rules_out, "With --sketch: also write the derived rules as RULES.l and its view RULES.v")
        ->needs(sketch_opt)
        ->check(output_extension({".l"}, "the rules are written as a cpfg .l file"));
    cmd->add_option("--sketch-out", a->sketch_out, "With --sketch: also write the sketch as a sketch file (.json)")
        ->needs(sketch_opt);
    cmd->add_option("--growth", a->growth,
                    "With --sketch: the growth value in iterations, fractional between two (default: the sketch's iterations)")
        ->needs(sketch_opt)
        ->check(finite_range(0.01, lsystem::kMaxSketchIterations));
    cmd->add_option("-o,--out", a->out, "Output file: tree.glb (glTF binary) or tree.obj (with .mtl and PNG)")
        ->required()
        ->check(output_extension({".glb", ".obj"},
                                 "the tree is written as .glb (glTF binary) or .obj (with .mtl and a PNG)"));
    cmd->add_option("--steps", a->steps, "Derivation steps (default: the file's derivation length)")
        ->check(CLI::Range(0, lsystem::kMaxDerivationLength))
        ->excludes(sketch_opt);
    cmd->add_option("--seed", a->in.seed, "Seed of the stochastic productions and ran() (default 1)")->check(seed_check());
    cmd->add_option("--lobes", a->lobes,
                    "Grow in the lobes of this session document (.json): from its trunk base, with its settings")
        ->excludes(sketch_opt);
    cmd->add_option("--string-out", a->string_out, "Also write the derived word, one line");
    cmd->add_option("--skeleton-out", a->skeleton_out, "Also write the tree graph as JSON (docs/growth.md)");
    cmd->add_option("--height", a->in.height, "A tree grown without lobes is scaled to this height in metres (default 3)")
        ->check(finite_range(0.01, 100.0))
        ->excludes(sketch_opt);
    cmd->add_option("--settings", a->in.settings, "Settings JSON (a settings object or a session document)");
    cmd->callback([a, &exit_code] {
        if (a->file.empty() && a->sketch.empty()) throw CLI::RequiredError("FILE or --sketch");
        for (const std::string* path : {&a->out, &a->string_out, &a->skeleton_out, &a->rules_out, &a->sketch_out})
            if (!path->empty()) require_output_folder(*path);
        LSystemGrown g;
        if (a->sketch.empty()) {
            g = grow_lsystem_file(a->file, a->lobes, a->steps, a->in);
        } else {
            lsystem::SketchRules rules;
            const std::string rules_name = a->rules_out.empty() ? a->sketch + ".l" : a->rules_out;
            GrowerChoice choice = sketch_choice(a->sketch, a->growth.value_or(0.0), rules_name, a->sketch_out, rules);
            progress("derived " + std::to_string(rules.trunk_sections) + " trunk blueprints and " +
                     std::to_string(rules.branches.size()) + " branch type(s); growth " + std::to_string(rules.growth));
            if (!a->rules_out.empty()) {
                write_file_atomic(a->rules_out, rules.lsystem);
                write_file_atomic(view_path_of(a->rules_out), rules.view);
                progress("wrote " + a->rules_out + " and " + view_path_of(a->rules_out));
            }
            g = grow_lsystem_choice(std::move(choice), a->sketch, "", std::nullopt, a->in);
        }
        const std::string& input = a->sketch.empty() ? a->file : a->sketch;
        const BuiltTree& tree = g.grown.tree;
        progress("derived " + std::to_string(g.modules) + " modules and drew " + std::to_string(tree.growth.tree.size()) +
                 " nodes and " + std::to_string(tree.growth.leaves ? tree.growth.leaves->size() : 0) + " leaves in " +
                 std::to_string(static_cast<int>(g.grow_ms)) + " ms");
        if (!a->string_out.empty()) {
            write_file_atomic(a->string_out, g.word + "\n");
            progress("wrote " + a->string_out);
        }
        if (!a->skeleton_out.empty()) {
            write_skeleton_json(a->skeleton_out, tree);
            progress("wrote " + a->skeleton_out);
        }
        if (tree.growth.tree.size() <= tree.growth.skeleton_nodes) {
            error(input + ": the L-system drew no branch (its word has no F or G to draw)");
            exit_code = kExitFailure;
            return;
        }
        const TreeGeometry geometry = document_tree_geometry(g.grown.doc, tree);
        ExportOptions options;
        if (lower_extension(a->out) == ".obj") options.lods = {0}; // one LOD per OBJ, as grow writes
        const std::vector<std::string> written = write_tree_file(a->out, g.grown.doc, tree, geometry, options);
        progress("triangles " + lod_triangle_summary(geometry));
        progress(wrote_line(written));
        exit_code = kExitOk;
    });
}

} // namespace lobe::cli
