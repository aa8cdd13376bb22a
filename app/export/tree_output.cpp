#include "app/export/tree_output.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <sstream>

#include "app/export/export_gltf.h"
#include "app/export/export_obj.h"
#include "core/errors.h"
#include "growth/bark_texture.h"
#include "growth/branch_geometry.h"
#include "growth/leaf_lod.h"
#include "app/session/edit_ops.h"
#include "app/session/stage_options.h"

namespace lobe {

LobeLeafOverrides document_lobe_leaves(const Document& doc, const BuiltTree& tree)
{
    LobeLeafOverrides out(tree.lobes.size());
    bool any = false;
    for (std::size_t i = 0; i < tree.lobes.size(); ++i)
        for (const LobeRecord& r : doc.lobes) {
            if (r.id != tree.lobes[i].lobe_id) continue;
            out[i] = {r.leaf_length_m, r.leaves_per_node, r.seed};
            any = any || r.leaf_length_m || r.leaves_per_node || r.seed;
        }
    if (!any) out.clear();
    return out;
}

TreeGeometry document_tree_geometry(const Document& doc, const BuiltTree& tree)
{
    // At real scale the rings follow the scaled curves: as far apart, relative to the tree, as
    // at the size it was sketched (at most 1 m), so the branch mesh does not grow with the height.
    BranchSettings branches = branch_geometry_options(doc.settings);
    if (tree.scale > 1.0) branches.ring_spacing_m = std::min(1.0, branches.ring_spacing_m * tree.scale);
    return build_tree_geometry(tree.growth.tree, branches, leaf_options(doc.settings), doc.seed,
                               doc.settings.growth.species, document_lobe_leaves(doc, tree),
                               tree.growth.leaves ? &*tree.growth.leaves : nullptr);
}

std::size_t lod_triangles(const TreeLod& lod) { return lod.branches.triangle_count() + lod.leaves.triangle_count(); }

std::string lod_triangle_summary(const TreeGeometry& geometry)
{
    std::string out;
    for (std::size_t i = 0; i < geometry.lods.size(); ++i)
        out += (i ? ", LOD" : "LOD") + std::to_string(i) + " " + std::to_string(lod_triangles(geometry.lods[i]));
    return out;
}

std::vector<std::string> write_tree_file(const std::string& path, const Document& doc, const BuiltTree& tree,
                     const TreeGeometry& geometry, const ExportOptions& options)
{
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    // Textures at another size: the same procedural pictures made again.
    TreeGeometry resized;
    const TreeGeometry* drawn = &geometry;
    if (options.texture_size > 0 && options.texture_size != geometry.bark_texture.width) {
        if (options.texture_size < 16 || options.texture_size > 2048)
            throw InvalidInput("export: texture size " + std::to_string(options.texture_size) + " is not in [16, 2048]");
        resized = geometry;
        resized.leaf_texture = make_leaf_atlas(make_leaf_texture(doc.settings.leaves.shape, options.texture_size));
        resized.bark_texture = make_bark_texture(options.texture_size);
        drawn = &resized;
    }
    ExportScene scene;
    scene.name = std::filesystem::path(path).stem().string();
    if (scene.name.empty()) scene.name = "tree";
    scene.tree = drawn;
    if (!tree.growth.tree.empty()) scene.base = tree.growth.tree.nodes[0].position;
    if (options.include_lobes)
        for (const BuiltLobe& l : tree.lobes) {
            scene.lobes.push_back(l.mesh);
            scene.lobe_ids.push_back(l.lobe_id);
        }
    if (options.include_strokes) {
        scene.strokes = effective_strokes(doc);
        const glm::dvec3 base(scene.base);
        if (tree.scale != 1.0) // the strokes as the tree was scaled (apply_real_scale)
            for (Stroke& s : scene.strokes)
                for (StrokePoint& p : s.points) p.position = glm::vec3(base + (glm::dvec3(p.position) - base) * tree.scale);
    }
    if (ext == ".glb") {
        write_glb(path, scene, options);
        return {path};
    }
    if (ext == ".obj") return write_obj(path, scene, options);
    throw InvalidInput(path + ": the tree is written as .glb (glTF binary) or .obj (with .mtl and a PNG)");
}

std::string wrote_line(const std::vector<std::string>& files)
{
    if (files.empty()) return "wrote nothing";
    std::string out = "wrote " + files[0];
    for (std::size_t i = 1; i < files.size(); ++i) out += (i == 1 ? " (" : ", ") + files[i];
    return files.size() > 1 ? out + ")" : out;
}

std::vector<int> parse_lod_list(const std::string& text, int lod_count, bool billboard)
{
    if (text.empty() || text == "all") return {};
    std::vector<int> out;
    std::stringstream ss(text);
    std::string item;
    while (std::getline(ss, item, ',')) {
        if (item.empty() || item.size() > 2 || !std::all_of(item.begin(), item.end(), [](unsigned char c) { return std::isdigit(c); }))
            throw InvalidInput("--lod: expected \"all\" or LOD indices such as 0 or 0,2 (got '" + text + "')");
        const int lod = std::stoi(item);
        if (lod >= lod_count + (billboard ? 1 : 0))
            throw InvalidInput("--lod: LOD " + item + " does not exist (the tree has LOD0 to LOD" +
                               std::to_string(lod_count - 1) + "; settings.branches.lod_count" +
                               (billboard ? ", and the billboard LOD" + std::to_string(lod_count) : std::string()) + ")");
        if (std::find(out.begin(), out.end(), lod) != out.end()) throw InvalidInput("--lod: LOD " + item + " given twice");
        out.push_back(lod);
    }
    return out;
}

} // namespace lobe
