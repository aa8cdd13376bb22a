// `lobesketch replay REC --out DIR`: the whole pipeline from a recording.
#include <filesystem>
#include <iostream>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "app/cli/cli.h"
#include "app/cli/cli_common.h"
#include "app/cli/cli_export_options.h"
#include "app/cli/outputs.h"
#include "app/export/skeleton_json.h"
#include "app/export/tree_output.h"
#include "app/live/lsystem_sketch_mode.h"
#include "core/atomic_file.h"
#include "core/errors.h"

namespace lobe::cli {

void add_replay_command(CLI::App& app, int& exit_code)
{
    auto* cmd = app.add_subcommand("replay", "Replay a recording through the pipeline and write its results");
    struct Args {
        std::string rec, out, settings, species;
        std::uint64_t seed = 1;
        double height = 0.0;
        TreeInputOptions radii;
        TreeFileArgs file;
    };
    auto a = std::make_shared<Args>();
    cmd->add_option("REC", a->rec, "Recording (binary or text form)")->required();
    cmd->add_option("-o,--out", a->out,
                    "Output folder (created): strokes.json, session.json, lobes/lobe_N.ply, tree.glb, tree.json")
        ->required();
    cmd->add_option("--settings", a->settings, "Settings JSON (a settings object or a session document)");
    cmd->add_option("--seed", a->seed, "Seed of every random choice downstream")->capture_default_str()->check(seed_check());
    cmd->add_option("--species", a->species,
                    "Species preset applied after --settings, as in grow: broadleaf, conifer, willow, birch, or a preset "
                    ".json file")
        ->check(species_check());
    cmd->add_option("--height", a->height,
                    "Real scale for tree.glb, as grow does: the structure at this height in metres, leaves and twigs at "
                    "the species' sizes (stored in session.json as settings.growth.height_m; 0: as sketched)")
        ->check(finite_range(0.0, 1000.0));
    add_radius_options(cmd, a->radii);
    add_tree_file_options(cmd, a->file);
    cmd->callback([a, &exit_code] {
        check_input_kind(a->rec, "replay", "a recording; grow, export, render and lobes take session documents and meshes",
                         false, false);
        Document doc;
        doc.seed = a->seed;
        if (!a->settings.empty()) doc.settings = load_settings_file(a->settings);
        if (!a->species.empty()) {
            TreeInputOptions species;
            species.settings = a->settings;
            species.species = a->species;
            apply_tree_input_options(doc.settings, species);
        }
        if (a->radii.pipe_exponent) {
            doc.settings.branches.pipe_exponent = *a->radii.pipe_exponent;
            doc.settings.branches.dbh_ratio = 0.0;
        }
        if (a->radii.tip_radius) doc.settings.branches.tip_radius_m = *a->radii.tip_radius;
        if (a->height > 0.0) doc.settings.growth.height_m = a->height;
        std::size_t drags = 0;
        Document out_doc = replay_into_document(a->rec, std::move(doc), &drags);

        std::error_code ec;
        std::filesystem::create_directories(a->out, ec);
        if (ec) throw FileError(a->out, "cannot create output folder: " + ec.message());
        write_strokes_json(a->out + "/strokes.json", out_doc.strokes, a->rec);
        // The session first (every stroke is safe even if meshing fails), then the lobes, then
        // the session again with their files.
        save_document(a->out + "/session.json", out_doc);
        std::vector<std::string> warnings;
        std::vector<BuiltLobe> lobes;
        const std::size_t lobe_files = write_document_lobes(out_doc, a->out, warnings, &lobes);
        for (const std::string& w : warnings) warn(a->rec + ": " + w);
        save_document(a->out + "/session.json", out_doc);
        // Then the tree grown in those lobes (docs/growth.md, docs/export.md).
        bool tree_written = false;
        if (!lobes.empty()) {
            BuiltTree tree = grow_document_tree(out_doc, std::move(lobes));
            apply_real_scale(out_doc, tree);
            for (const std::string& w : tree.warnings) warn(a->rec + ": " + w);
            const TreeGeometry geometry = document_tree_geometry(out_doc, tree);
            ExportOptions options;
            apply_tree_file_options(a->file, options);
            write_tree_file(a->out + "/tree.glb", out_doc, tree, geometry, options);
            write_skeleton_json(a->out + "/tree.json", tree); // the tree graph, as grow --skeleton-out
            tree_written = true;
            progress("grew a tree of " + std::to_string(tree.growth.tree.size()) + " nodes (triangles " +
                     lod_triangle_summary(geometry) + ")");
        }
        std::size_t lobe_strokes = 0, trunk_strokes = 0;
        for (const Stroke& s : out_doc.strokes) (s.kind == StrokeKind::Lobe ? lobe_strokes : trunk_strokes)++;
        progress("derived " + std::to_string(out_doc.strokes.size()) + " strokes (" + std::to_string(lobe_strokes) +
                 " lobe, " + std::to_string(trunk_strokes) + " trunk) in " + std::to_string(out_doc.lobes.size()) +
                 " lobe group(s), " + std::to_string(out_doc.edits.size()) + " edit(s) from " +
                 std::to_string(drags) + " drag(s)");
        progress("wrote " + a->out + "/strokes.json, " + a->out + "/session.json, " + std::to_string(lobe_files) +
                 " lobe mesh(es) in " + a->out + "/lobes" +
                 (tree_written ? ", " + a->out + "/tree.glb and " + a->out + "/tree.json" : ""));
        // The L-system sketch mode's sketch (docs/lsystem-sketch.md), when the recording made one.
        const LSystemSketchMode sketch_mode = replay_lsystem_sketch(read_recording(a->rec));
        const bool sketched = sketch_mode.sketch().trunk.size() >= 2;
        if (sketched) {
            write_file_atomic(a->out + "/lsystem-sketch.json", lsystem::sketch_json(sketch_mode.sketch_file()) + "\n");
            progress("wrote " + a->out + "/lsystem-sketch.json (the L-system sketch: lobesketch lsystem --sketch grows it)");
        }
        if (out_doc.strokes.empty() && drags == 0 && out_doc.lobes.empty() && !sketched) {
            error(a->rec + ": no strokes in this recording");
            exit_code = kExitFailure;
            return;
        }
        exit_code = kExitOk;
    });
}

} // namespace lobe::cli
