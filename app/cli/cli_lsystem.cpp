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
#include "app/export/tree_output.h"
#include "app/session/session_file.h"
#include "app/session/tree_pipeline.h"
#include "core/atomic_file.h"
#include "core/errors.h"
#include "growth/lsystem/lsystem_grower.h"
#include "growth/lsystem/presets.h"

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

LSystemGrown grow_lsystem_file(const std::string& path, const std::string& lobes_session, std::optional<int> steps,
                               const TreeInputOptions& o)
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
    GrowerChoice choice = lsystem_file_choice(path);
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

void add_lsystem_command(CLI::App& app, int& exit_code)
{
    auto* cmd = app.add_subcommand(
        "lsystem", "Grow a tree from an L-system file (cpfg's .l, with the .v beside it) and export it as .glb or .obj");
    struct Args {
        TreeInputOptions in;
        std::string file, out, lobes, string_out, skeleton_out;
        std::optional<int> steps;
    };
    auto a = std::make_shared<Args>();
    cmd->add_option("FILE", a->file, "L-system file (.l; NAME.v beside it is its view file), or a shipped preset's name (docs/lsystems.md)")->required();
    cmd->add_option("-o,--out", a->out, "Output file: tree.glb (glTF binary) or tree.obj (with .mtl and PNG)")
        ->required()
        ->check(output_extension({".glb", ".obj"},
                                 "the tree is written as .glb (glTF binary) or .obj (with .mtl and a PNG)"));
    cmd->add_option("--steps", a->steps, "Derivation steps (default: the file's derivation length)")
        ->check(CLI::Range(0, lsystem::kMaxDerivationLength));
    cmd->add_option("--seed", a->in.seed, "Seed of the stochastic productions and ran() (default 1)")->check(seed_check());
    cmd->add_option("--lobes", a->lobes,
                    "Grow in the lobes of this session document (.json): from its trunk base, with its settings");
    cmd->add_option("--string-out", a->string_out, "Also write the derived word, one line");
    cmd->add_option("--skeleton-out", a->skeleton_out, "Also write the tree graph as JSON (docs/growth.md)");
    cmd->add_option("--height", a->in.height, "A tree grown without lobes is scaled to this height in metres (default 3)")
        ->check(finite_range(0.01, 100.0));
    cmd->add_option("--settings", a->in.settings, "Settings JSON (a settings object or a session document)");
    cmd->callback([a, &exit_code] {
        for (const std::string* path : {&a->out, &a->string_out, &a->skeleton_out})
            if (!path->empty()) require_output_folder(*path);
        const LSystemGrown g = grow_lsystem_file(a->file, a->lobes, a->steps, a->in);
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
            error(a->file + ": the L-system drew no branch (its word has no F or G to draw)");
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
