#pragma once
/// \file render_scene.h
/// What `lobesketch render` shows, as a RenderScene (app/render/renderer.h): a grown tree at one
/// level of detail, its lobes and its strokes, from the pipeline's own data or from a .glb
/// the program exported (docs/rendering.md).

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "app/render/renderer.h"
#include "core/mesh.h"
#include "core/stroke.h"
#include "growth/grow.h"
#include "growth/tree_geometry.h"

namespace lobe {

/// Which parts are drawn (`--show tree,leaves,lobes,strokes`).
struct RenderContent {
    bool tree = true;     ///< branches (bark)
    bool leaves = true;
    bool lobes = false;   ///< translucent lobe meshes
    bool strokes = false; ///< the sketch's strokes as tubes
    bool clusters = false; ///< the first growth iteration's attractor clusters and pieces (Fig. 7)
    int lod = 0;          ///< level of detail of the tree
};

/// FNV-1a over `bytes` bytes: the content hashes that scene items' versions are made of.
std::uint64_t bytes_hash(const void* data, std::size_t bytes);

/// Parses a comma-separated `--show` list of tree, leaves, lobes, strokes, clusters.
/// \throw InvalidInput naming an unknown or empty item.
RenderContent parse_show_list(const std::string& text);

/// Colours of the sketch parts (linear RGBA), those of the glTF export (docs/export.md).
inline constexpr std::array<float, 4> kLobeColor{0.45f, 0.75f, 0.35f, 0.25f};
inline constexpr std::array<float, 4> kStrokeColor{1.0f, 0.55f, 0.1f, 1.0f};

/// A tube of `sides` sides and radius `radius_m` along a polyline (capped by nothing: a
/// stroke's ends are open). Fewer than two distinct points give an empty mesh.
SurfaceGeometry polyline_tube(const std::vector<glm::vec3>& points, float radius_m = 0.003f, int sides = 6);

/// A lobe mesh with area-weighted vertex normals, ready to draw.
/// \throw InvalidInput for a triangle index outside the mesh's vertices.
SurfaceGeometry lobe_surface(const TriangleMesh& mesh);

/// The scene of a grown tree: `geometry`'s LOD `content.lod` (branches and/or leaves), the
/// lobes and strokes when asked, the ground at `ground_y`. Every item's version is a hash of
/// its data, so an unchanged mesh keeps its GPU buffers across set_scene calls.
/// \throw InvalidInput when the LOD does not exist.
RenderScene tree_render_scene(const TreeGeometry& geometry, const std::vector<TriangleMesh>& lobes,
                              const std::vector<Stroke>& strokes, float ground_y, const RenderContent& content);

/// Adds the first growth iteration's clusters (§5.2, Fig. 7b–c) to `scene`: each attractor a
/// small octahedron coloured by the piece of its node's cluster it fell in (twelve colours,
/// neighbouring pieces differ), and a tube from the node to each piece's centre in its colour.
/// `tree` is the grown tree the clusters' node indices refer to. Nothing for an empty list.
void add_cluster_items(RenderScene& scene, const std::vector<ClusteredAttractor>& clusters, const TreeGraph& tree);

/// Replaces the mesh of the item tree_render_scene made for lobe `index` (a lobe being
/// deformed live); false when `scene` has no such item. \throw InvalidInput as lobe_surface.
bool replace_lobe_item(RenderScene& scene, std::size_t index, const TriangleMesh& mesh);

/// Replaces the tube of the item tree_render_scene made for `stroke` (found by its id) with
/// one through the stroke's points as given (a lobe's stroke while the lobe is moved, turned
/// or scaled live); false when `scene` has no such item.
bool replace_stroke_item(RenderScene& scene, const Stroke& stroke);

/// The scene of a .glb written by Lobesketch (nodes `<name>_branches_LOD<k>`,
/// `<name>_leaves_LOD<k>`, `lobe_<id>`, `stroke_<id>`; docs/export.md): its origin is the trunk
/// base, so the ground is at y = 0.
/// \throw FileError when the file cannot be read or has no mesh of LOD `content.lod`.
RenderScene glb_render_scene(const std::string& path, const RenderContent& content);

/// The share of pixels of `picture` that differ from `background` (same size) by more than
/// `threshold` in any channel; `mask` (optional) gets 1 for those pixels, 0 elsewhere.
/// \throw InvalidInput when the two pictures differ in size.
double coverage(const RgbaImage& picture, const RgbaImage& background, int threshold = 24,
                std::vector<std::uint8_t>* mask = nullptr);

} // namespace lobe
