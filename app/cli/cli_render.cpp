// `lobesketch render INPUT --out tree.png`: pictures of a tree (docs/rendering.md).
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>

#include <CLI/CLI.hpp>

#include "app/cli/cli.h"
#include "app/cli/cli_common.h"
#include "app/render/render_scene.h"
#include "app/render/renderer.h"
#include "app/export/tree_output.h"
#include "core/atomic_file.h"
#include "core/errors.h"
#include "app/session/edit_ops.h"

namespace lobe::cli {

namespace {

constexpr int kMinSide = 16, kMaxSide = 8192;

/// Parses "WxH" with both sides in kMinSide..kMaxSide; false (sizes untouched) otherwise.
bool parse_size(const std::string& text, int& width, int& height)
{
    int w = 0, h = 0;
    char x = 0, rest = 0;
    if (std::sscanf(text.c_str(), "%d%c%d%c", &w, &x, &h, &rest) != 3 || (x != 'x' && x != 'X')) return false;
    if (w < kMinSide || h < kMinSide || w > kMaxSide || h > kMaxSide) return false;
    width = w;
    height = h;
    return true;
}

std::string frame_path(const std::string& out, int frame)
{
    const std::filesystem::path p(out);
    char number[16];
    std::snprintf(number, sizeof number, "_%03d", frame);
    return (p.parent_path() / (p.stem().string() + number + p.extension().string())).string();
}

} // namespace

void add_render_command(CLI::App& app, int& exit_code)
{
    auto* cmd = app.add_subcommand(
        "render", "Draw pictures (PNG) of the tree of a recording, a session document (.json), a mesh, an L-system "
        "file (.l) or a .glb");
    struct Args {
        TreeInputOptions in;
        std::string input, out, view = "front", size = "1280x720", show = "tree,leaves";
        int lod = 0, frames = 12;
        bool software = false;
    };
    auto a = std::make_shared<Args>();
    cmd->add_option("INPUT", a->input,
                    "Recording, session document (.json), mesh (.obj/.ply/.off), L-system (.l) or a .glb made by lobesketch")
        ->required();
    cmd->add_option("-o,--out", a->out, "Picture (.png); with --view orbit, OUT_000.png, OUT_001.png, …")
        ->required()
        ->check(output_extension({".png"}, "pictures are written as .png"));
    cmd->add_option("--view", a->view, "front (looks along -Z), side (along -X), top (down -Y) or orbit (a turntable)")
        ->capture_default_str()
        ->check(CLI::IsMember({"front", "side", "top", "orbit"}));
    cmd->add_option("--frames", a->frames, "Frames of the orbit turntable")->capture_default_str()->check(CLI::Range(1, 360));
    cmd->add_option("--size", a->size, "Picture size WxH in pixels, each side 16 to 8192")
        ->capture_default_str()
        ->check(CLI::Validator(
            [](std::string& s) {
                int w = 0, h = 0;
                return parse_size(s, w, h) ? std::string() : "expected WxH with each side 16 to 8192 (got '" + s + "')";
            },
            "WxH"));
    cmd->add_option("--show", a->show, "What to draw, comma-separated: tree, leaves, lobes, strokes, clusters (the first growth "
                    "iteration's attractor clusters, each piece in its own colour)")
        ->capture_default_str()
        ->check(CLI::Validator(
            [](std::string& s) {
                try {
                    parse_show_list(s);
                    return std::string();
                } catch (const InvalidInput& e) {
                    std::string why = e.what();
                    if (why.rfind("--show: ", 0) == 0) why.erase(0, 8); // CLI11 names the option itself
                    return why;
                }
            },
            "LIST"));
    cmd->add_option("--lod", a->lod, "Level of detail of the tree (0: finest)")->capture_default_str()->check(CLI::Range(0, 9));
    add_tree_input_options(cmd, a->in);
    cmd->add_option("--height", a->in.height,
                    "Real scale: the tree's structure at this height in metres, leaves and twigs at the species' sizes "
                    "(settings.growth.height_m)")
        ->check(finite_range(0.0, 1000.0));
    cmd->add_option("--mesh-size", a->in.mesh_size, "A mesh input is scaled so its bounding box's largest side is this (metres)")
        ->capture_default_str()
        ->check(finite_range(0.01, 100.0));
    cmd->add_flag("--software", a->software, "Render on the CPU (lavapipe) even when a GPU is present");
    cmd->callback([a, cmd, &exit_code] {
        int width = 0, height = 0;
        parse_size(a->size, width, height);
        RenderContent content = parse_show_list(a->show);
        content.lod = a->lod;
        const std::string input_ext = lower_extension(a->input);
        if (input_ext != ".glb" && input_ext != ".l")
            check_input_kind(a->input, "render",
                             "a recording, a session document (.json), a mesh (.obj/.ply/.off), an L-system file (.l) "
                             "or a .glb made by lobesketch",
                             true, true);
        if (cmd->get_option("--frames")->count() > 0 && a->view != "orbit")
            warn("--frames applies only to --view orbit; one picture is drawn for --view " + a->view);
        if (cmd->get_option("--mesh-size")->count() > 0 && input_ext != ".glb" && input_ext != ".l")
            warn_mesh_only_option(a->input, "--mesh-size");

        RenderScene scene;
        if (lower_extension(a->input) == ".glb") {
            if (!a->in.settings.empty() || !a->in.species.empty() || !a->in.grower.empty() || !a->in.set.empty() ||
                a->in.seed || a->in.split_angle || a->in.spacing)
                warn(a->input + ": a .glb holds a grown tree; --settings, --species, --grower, --set, --seed, "
                                "--split-angle and --attractor-spacing do not apply");
            if (content.clusters) warn(a->input + ": --show clusters: a .glb holds no attractor clusters");
            scene = glb_render_scene(a->input, content);
        } else {
            // An L-system file grows alone (its messages printed as it grows); anything else
            // as grow does.
            const bool lsystem_file = lower_extension(a->input) == ".l";
            const GrownInput grown =
                lsystem_file ? grow_lsystem_file(a->input, "", std::nullopt, a->in).grown : grow_input_tree(a->input, a->in);
            for (const std::string& w : grown.tree.warnings) warn(a->input + ": " + w);
            const BuiltTree& tree = grown.tree;
            if (tree.growth.tree.size() <= tree.growth.skeleton_nodes) {
                error(a->input + ": no tree could be grown (no lobe could be built)");
                exit_code = kExitFailure;
                return;
            }
            const TreeGeometry geometry = document_tree_geometry(grown.doc, tree);
            std::vector<TriangleMesh> lobes;
            if (content.lobes)
                for (const BuiltLobe& l : tree.lobes) lobes.push_back(l.mesh);
            std::vector<Stroke> strokes;
            if (content.strokes) strokes = effective_strokes(grown.doc);
            scene = tree_render_scene(geometry, lobes, strokes, tree.growth.tree.nodes[0].position.y, content);
            if (content.clusters) {
                if (tree.growth.first_clusters.empty())
                    warn(a->input + ": --show clusters: this grower has no attractor clusters (the subtrees grower has)");
                add_cluster_items(scene, tree.growth.first_clusters, tree.growth.tree);
            }
        }
        if (scene.items.empty()) {
            error(a->input + ": nothing to draw for --show " + a->show);
            exit_code = kExitFailure;
            return;
        }

        RendererOptions options;
        options.prefer_software = a->software;
        Renderer renderer(options);
        renderer.set_scene(scene);
        const Bounds bounds = scene_bounds(scene);
        const float aspect = float(width) / float(height);
        std::vector<std::pair<std::string, ViewAngles>> pictures;
        if (a->view == "orbit")
            for (int i = 0; i < a->frames; ++i)
                pictures.emplace_back(frame_path(a->out, i), ViewAngles{360.0f * float(i) / float(a->frames), 15.0f});
        else
            pictures.emplace_back(a->out, a->view == "side" ? side_view() : a->view == "top" ? top_view() : front_view());
        const std::filesystem::path folder = std::filesystem::path(a->out).parent_path();
        if (!folder.empty()) {
            std::error_code ec;
            std::filesystem::create_directories(folder, ec);
            if (ec) throw FileError(folder.string(), "cannot create the output folder: " + ec.message());
        }
        const auto t0 = std::chrono::steady_clock::now();
        for (const auto& [path, view] : pictures) {
            const RgbaImage image = renderer.render(frame_view(bounds, view, aspect), width, height);
            const std::vector<std::uint8_t> png = encode_png(image);
            write_file_atomic(path, std::string_view(reinterpret_cast<const char*>(png.data()), png.size()));
        }
        const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        progress("rendered " + std::to_string(pictures.size()) + " picture(s) of " + std::to_string(width) + "x" +
                 std::to_string(height) + " on " + renderer.device_name() + (renderer.is_software() ? " (CPU)" : "") +
                 " in " + std::to_string(static_cast<int>(ms)) + " ms");
        progress("wrote " + (pictures.size() == 1 ? a->out : frame_path(a->out, 0) + " … " + pictures.back().first));
        exit_code = kExitOk;
    });
}

} // namespace lobe::cli
