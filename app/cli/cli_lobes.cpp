// `lobesketch lobes INPUT --out DIR`: lobe meshes from a recording, a session or a mesh.
#include <algorithm>
#include <cctype>
#include <cstddef>
#include <filesystem>
#include <memory>

#include <CLI/CLI.hpp>

#include "app/session/session_file.h"
#include "app/cli/cli.h"
#include "app/cli/cli_common.h"
#include "app/cli/outputs.h"
#include "app/session/stage_options.h"
#include "core/errors.h"
#include "meshing/mesh_io.h"
#include "meshing/mesh_quality.h"
#include "meshing/model_import.h"

namespace lobe::cli {

void add_lobes_command(CLI::App& app, int& exit_code)
{
    auto* cmd = app.add_subcommand(
        "lobes", "Build lobe meshes from a recording, a session document (.json) or a mesh (.obj, .ply, .off)");
    struct Args {
        std::string input, out, settings;
        double size_m = 1.5;
        std::size_t simplify_above = LobeFromModelOptions{}.simplify_above_triangles;
    };
    auto a = std::make_shared<Args>();
    cmd->add_option("INPUT", a->input, "Recording, session document or mesh")->required();
    cmd->add_option("-o,--out", a->out, "Output folder (created): lobes/lobe_N.ply and session.json")->required();
    cmd->add_option("--settings", a->settings, "Settings JSON (a settings object or a session document)");
    cmd->add_option("--size,--mesh-size", a->size_m, "A mesh input is scaled so its bounding box's largest side is this (metres)")
        ->capture_default_str()
        ->check(finite_range(0.01, 100.0));
    cmd->add_option("--simplify-above", a->simplify_above,
                    "A mesh of more triangles than this is simplified in cubes of a fifth of the spacing before "
                    "repair (0: never)")
        ->capture_default_str();
    cmd->callback([a, cmd, &exit_code] {
        check_input_kind(a->input, "lobes", "a recording, a session document (.json) or a mesh (.obj/.ply/.off)", true,
                         true);
        if (cmd->get_option("--size")->count() > 0) warn_mesh_only_option(a->input, "--size");
        const std::string ext = lower_extension(a->input);
        std::error_code ec;
        std::filesystem::create_directories(a->out, ec);
        if (ec) throw FileError(a->out, "cannot create output folder: " + ec.message());
        Document doc;
        const bool is_mesh = ext == ".obj" || ext == ".ply" || ext == ".off";
        if (is_mesh) {
            // A mesh becomes one lobe: repaired, scaled, remeshed (docs/lobes-from-models.md).
            if (!a->settings.empty()) doc.settings = load_settings_file(a->settings);
            LobeFromModelOptions options = model_import_options(doc.settings, a->size_m);
            options.simplify_above_triangles = a->simplify_above;
            RepairReport report;
            const TriangleMesh mesh = lobe_from_model(a->input, options, &report);
            if (!report.notes.empty()) {
                std::string done;
                for (const std::string& n : report.notes) done += (done.empty() ? "" : "; ") + n;
                progress(a->input + ": repaired: " + done);
            }
            std::filesystem::create_directories(a->out + "/lobes", ec);
            if (ec) throw FileError(a->out + "/lobes", "cannot create folder: " + ec.message());
            write_ply(a->out + "/lobes/lobe_1.ply", mesh);
            if (const std::size_t removed = remove_stale_lobe_files(a->out + "/lobes", {"lobe_1.ply"}); removed > 0)
                warn(a->input + ": removed " + std::to_string(removed) + " lobe mesh(es) of an earlier run from " + a->out +
                     "/lobes");
            // The session holds the lobe itself, so it opens, regrows and exports without the file.
            LobeRecord rec = LobeRecord::of_strokes(1, {}, "lobes/lobe_1.ply");
            rec.model = std::make_shared<const LobeModel>(
                LobeModel{std::filesystem::path(a->input).filename().string(), mesh});
            doc.lobes.push_back(std::move(rec));
            save_document(a->out + "/session.json", doc);
            const MeshQuality q = measure_quality(mesh);
            progress("wrote " + a->out + "/lobes/lobe_1.ply (" + std::to_string(q.vertices) + " vertices, " +
                     std::to_string(q.triangles) + " triangles) and " + a->out + "/session.json");
            exit_code = kExitOk;
            return;
        }
        if (ext == ".json") {
            doc = load_session(a->input);
            if (!a->settings.empty()) doc.settings = load_settings_file(a->settings);
        } else {
            if (!a->settings.empty()) doc.settings = load_settings_file(a->settings);
            doc = replay_into_document(a->input, std::move(doc));
        }
        std::vector<std::string> warnings;
        const std::size_t written = write_document_lobes(doc, a->out, warnings);
        for (const std::string& w : warnings) warn(a->input + ": " + w);
        save_document(a->out + "/session.json", doc);
        progress("wrote " + std::to_string(written) + " lobe mesh(es) in " + a->out + "/lobes and " + a->out +
                 "/session.json");
        if (written == 0) {
            error(a->input + ": no lobe could be built");
            exit_code = kExitFailure;
            return;
        }
        exit_code = kExitOk;
    });
}

} // namespace lobe::cli
