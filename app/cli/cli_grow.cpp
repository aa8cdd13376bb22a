// `lobesketch grow INPUT --out tree.glb` and `lobesketch export SESSION --out FILE`: a tree
// from a recording, a session or a mesh, written as glTF binary or OBJ.
#include <chrono>
#include <memory>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "app/session/session_file.h"
#include "app/cli/cli.h"
#include "app/cli/cli_common.h"
#include "app/cli/cli_export_options.h"
#include "app/export/tree_output.h"
#include "app/export/export_scene.h"
#include "app/export/skeleton_json.h"
#include "app/session/tree_pipeline.h"
#include "core/atomic_file.h"
#include "core/errors.h"
#include "growth/wood.h"

namespace lobe::cli {

namespace {

struct TreeArgs {
    TreeInputOptions in;
    std::string input, out, lod, report, skeleton_out; // lod empty: the format's default
    bool lobes = false, strokes = false;
    TreeFileArgs file;
};

void add_tree_options(CLI::App* cmd, TreeArgs& a)
{
    add_tree_input_options(cmd, a.in);
    cmd->add_option("--lod", a.lod,
                    "LODs to write: all, or indices such as 0 or 0,2 (default: all in a .glb, LOD0 in an .obj; "
                    "an .obj holds one LOD, the others go to NAME_LODk.obj)")
        ->check(CLI::Validator(
            [](std::string& text) {
                // The form here; whether each LOD exists is known once the settings are.
                try {
                    parse_lod_list(text, 100);
                    return std::string();
                } catch (const InvalidInput& e) {
                    std::string why = e.what();
                    if (why.rfind("--lod: ", 0) == 0) why.erase(0, 7); // CLI11 names the option itself
                    return why;
                }
            },
            "LIST", "LOD list"));
    cmd->add_option("--height", a.in.height,
                    "Real scale: the tree's structure is scaled to this height in metres, its leaves and twigs keep "
                    "the species' sizes (settings.growth.height_m; 0 or none: the session's, else as sketched)")
        ->check(finite_range(0.0, 1000.0));
    add_tree_file_options(cmd, a.file);
    cmd->add_flag("--lobes", a.lobes, "Also write the lobes as extra nodes");
    cmd->add_flag("--strokes", a.strokes, "Also write the strokes as extra nodes");
    cmd->add_option("--report", a.report,
                    "Write the tree's wood volume, dry biomass, carbon and CO2 as JSON (docs/wood-and-co2.md)");
    cmd->add_option("--skeleton-out", a.skeleton_out,
                    "Also write the tree graph as JSON: nodes with parents, positions, radii, lobes (docs/growth.md)");
}

/// The wood report as JSON: the tree as grown, and scaled to --height when given.
std::string wood_report(const TreeArgs& a, const Document& doc, const BuiltTree& tree, const TreeGeometry& geometry)
{
    const double density = basic_wood_density(doc.settings.growth.species);
    nlohmann::json j = wood_json(estimate_wood(tree.growth.tree, density));
    j["species"] = doc.settings.growth.species;
    (void)a;
    (void)geometry;
    if (tree.scale != 1.0) {
        // The tree is at real scale (apply_real_scale): the figures above are of the tree as
        // written, repeated under at_height with its height and the scale applied.
        nlohmann::json at = wood_json(estimate_wood(tree.growth.tree, density));
        at["height_m"] = doc.settings.growth.height_m;
        at["scale"] = tree.scale;
        j["at_height"] = std::move(at);
    }
    return j.dump(2) + "\n";
}

void report_and_write(const TreeArgs& a, const Document& doc, const BuiltTree& tree, const std::string& input,
                      int& exit_code)
{
    for (const std::string& w : tree.warnings) warn(input + ": " + w);
    if (tree.growth.tree.size() <= tree.growth.skeleton_nodes) {
        error(input + ": no tree could be grown (no lobe could be built)");
        exit_code = kExitFailure;
        return;
    }
    const auto t0 = std::chrono::steady_clock::now();
    const TreeGeometry geometry = document_tree_geometry(doc, tree);
    const double geometry_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    ExportOptions options;
    options.lods = parse_lod_list(a.lod, static_cast<int>(geometry.lods.size()), a.file.billboard > 0);
    if (a.lod.empty() && lower_extension(a.out) == ".obj") options.lods = {0}; // one LOD per OBJ
    apply_tree_file_options(a.file, options);
    options.include_lobes = a.lobes;
    options.include_strokes = a.strokes;
    const std::vector<std::string> written = write_tree_file(a.out, doc, tree, geometry, options);
    if (!a.report.empty()) {
        write_file_atomic(a.report, wood_report(a, doc, tree, geometry));
        progress("wrote " + a.report);
    }
    if (!a.skeleton_out.empty()) {
        write_skeleton_json(a.skeleton_out, tree);
        progress("wrote " + a.skeleton_out);
    }
    std::size_t attractors = 0, reached = 0, stopped = 0;
    for (const LobeGrowthStats& l : tree.growth.lobes) {
        attractors += l.attractors;
        reached += l.reached;
        stopped += l.stopped;
    }
    if (attractors > 0)
        progress("grew " + std::to_string(tree.growth.tree.size()) + " nodes in " + std::to_string(tree.lobes.size()) +
                 " lobe(s); of " + std::to_string(attractors) + " attractors " + std::to_string(stopped) +
                 " ended by the stop rule, " + std::to_string(reached) + " reached");
    else
        progress("grew " + std::to_string(tree.growth.tree.size()) + " nodes (" + std::to_string(tree.lobes.size()) +
                 " lobe(s))");
    progress("geometry in " + std::to_string(static_cast<int>(geometry_ms)) + " ms, triangles " + lod_triangle_summary(geometry));
    progress(wrote_line(written));
    exit_code = kExitOk;
}

/// --out's extension, checked when the command line is parsed.
CLI::Validator tree_file_check()
{
    return output_extension({".glb", ".obj"}, "the tree is written as .glb (glTF binary) or .obj (with .mtl and a PNG)");
}

/// Every file the command writes goes into a folder that exists (before the tree is grown).
void require_outputs_folders(const TreeArgs& a)
{
    require_output_folder(a.out);
    if (!a.report.empty()) require_output_folder(a.report);
    if (!a.skeleton_out.empty()) require_output_folder(a.skeleton_out);
}

} // namespace

void add_grow_command(CLI::App& app, int& exit_code)
{
    auto* cmd = app.add_subcommand(
        "grow", "Grow a tree from a recording, a session document (.json) or a mesh (.obj, .ply, .off) and export it");
    auto a = std::make_shared<TreeArgs>();
    cmd->add_option("INPUT", a->input, "Recording, session document or mesh")->required();
    cmd->add_option("-o,--out", a->out, "Output file: tree.glb (glTF binary) or tree.obj (with .mtl and PNG)")
        ->required()
        ->check(tree_file_check());
    add_tree_options(cmd, *a);
    cmd->add_option("--size,--mesh-size", a->in.mesh_size, "A mesh input is scaled so its bounding box's largest side is this (metres)")
        ->capture_default_str()
        ->check(finite_range(0.01, 100.0));
    cmd->callback([a, cmd, &exit_code] {
        check_input_kind(a->input, "grow", "a recording, a session document (.json) or a mesh (.obj/.ply/.off)", true,
                         true);
        if (cmd->get_option("--size")->count() > 0) warn_mesh_only_option(a->input, "--size");
        require_outputs_folders(*a);
        // The LODs asked for exist: known before growing for a session or a mesh.
        const GrownInput grown = grow_input_tree(a->input, a->in, [a](const Document& doc) {
            parse_lod_list(a->lod, doc.settings.branches.lod_count, a->file.billboard > 0);
        });
        report_and_write(*a, grown.doc, grown.tree, a->input, exit_code);
    });
}

void add_export_command(CLI::App& app, int& exit_code)
{
    auto* cmd = app.add_subcommand("export", "Export the tree of a session document as .glb or .obj");
    auto a = std::make_shared<TreeArgs>();
    cmd->add_option("SESSION", a->input, "Session document (.json)")->required();
    cmd->add_option("-o,--out", a->out, "Output file: tree.glb (glTF binary) or tree.obj (with .mtl and PNG)")
        ->required()
        ->check(tree_file_check());
    add_tree_options(cmd, *a);
    cmd->callback([a, &exit_code] {
        if (lower_extension(a->input) != ".json" && !is_session_file(a->input)) {
            std::string kind = "this file";
            if (is_mesh_file(a->input)) kind = "a mesh";
            else if (is_recording_file(a->input)) kind = "a recording";
            throw UsageError(a->input + ": export wants a session document (.json), and " + kind +
                             " is not one; grow takes recordings, sessions and meshes (lobesketch grow " + a->input +
                             " --out " + a->out + ")");
        }
        require_outputs_folders(*a);
        Document doc = load_session(a->input);
        if (!a->in.settings.empty()) doc.settings = load_settings_file(a->in.settings);
        apply_tree_input_options(doc.settings, a->in);
        apply_document_options(doc, a->in);
        parse_lod_list(a->lod, doc.settings.branches.lod_count, a->file.billboard > 0); // the LODs asked for exist, before growing
        BuiltTree tree = build_document_tree(doc);
        apply_real_scale(doc, tree);
        report_and_write(*a, doc, tree, a->input, exit_code);
    });
}

} // namespace lobe::cli
