#include "app/cli/cli_export_options.h"

#include <string>

namespace lobe::cli {

namespace {

/// A power of two in [lo, hi], or 0 when `zero` allows it.
CLI::Validator power_of_two(int lo, int hi, bool zero)
{
    return CLI::Validator(
        [=](std::string& text) {
            std::size_t used = 0;
            long v = -1;
            try {
                v = std::stol(text, &used);
            } catch (const std::exception&) {
                used = 0;
            }
            const bool ok = used == text.size() && ((zero && v == 0) || (v >= lo && v <= hi && (v & (v - 1)) == 0));
            if (ok) return std::string();
            return "expected " + std::string(zero ? "0 or " : "") + "a power of two from " + std::to_string(lo) + " to " +
                   std::to_string(hi) + " (got '" + text + "')";
        },
        "PIXELS", "power of two");
}

} // namespace

void add_tree_file_options(CLI::App* cmd, TreeFileArgs& a)
{
    cmd->add_option("--billboard", a.billboard,
                    "Texture size of the billboard level written after the coarsest LOD (crossed cards with the tree "
                    "baked in; 0: none)")
        ->capture_default_str()
        ->check(power_of_two(16, 4096, true));
    cmd->add_option("--texture-size", a.texture_size, "Leaf and bark texture size in pixels (default 128)")
        ->check(power_of_two(16, 2048, false));
    cmd->add_flag("--bark-normal-map", a.bark_normal_map, "Also write a normal map of the bark (derived from its texture)");
    cmd->add_flag("--optimize", a.optimize,
                  "Reorder each mesh for the vertex cache, overdraw and vertex fetch (meshoptimizer)");
    cmd->add_flag("--quantize", a.quantize,
                  "Quantize the .glb's meshes (KHR_mesh_quantization) without compressing them: for importers "
                  "without EXT_meshopt_compression such as Blender 3.4; implies --optimize");
    cmd->add_flag("--compress", a.compress,
                  "Quantize (KHR_mesh_quantization) and compress (EXT_meshopt_compression) the .glb's meshes; implies "
                  "--optimize. Viewers need both extensions");
}

void apply_tree_file_options(const TreeFileArgs& a, ExportOptions& into)
{
    into.billboard_size = a.billboard;
    into.texture_size = a.texture_size;
    into.bark_normal_map = a.bark_normal_map;
    into.optimize = a.optimize || a.compress || a.quantize;
    into.compress = a.compress;
    into.quantize = a.quantize && !a.compress;
}

} // namespace lobe::cli
