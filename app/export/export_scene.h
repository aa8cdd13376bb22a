#pragma once
/// \file export_scene.h
/// What the exporters (app/export/export_gltf.h, app/export/export_obj.h) write, and the preparation they
/// share: checking the input, choosing LODs, moving the trunk base to the origin and scaling
/// to a target height. Units stay metres, +Y up, right-handed (the glTF frame): nothing is
/// converted. The layout of the written files is described in docs/export.md.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "core/mesh.h"
#include "core/stroke.h"
#include "growth/tree_geometry.h"

namespace lobe {

/// A tree and, optionally, the sketch it grew from.
struct ExportScene {
    std::string name = "tree";          ///< prefix of every node/object name; non-empty, printable
    const TreeGeometry* tree = nullptr; ///< required; not owned
    glm::vec3 base{0.0f};               ///< trunk base on the ground (metres): becomes the origin
    std::vector<TriangleMesh> lobes;    ///< optional, written as `lobe_<id>`
    std::vector<std::int64_t> lobe_ids; ///< the lobes' ids (LobeRecord::id), one per lobe; empty: ids 1, 2, …
    std::vector<Stroke> strokes;        ///< optional, written as `stroke_<id>` line strips
};

struct ExportOptions {
    /// > 0: scale uniformly (about the base) so the tallest vertex of LOD0 (branches and
    /// leaves) lies this many metres above the base; every written LOD gets that scale.
    /// 0: keep the size.
    double target_height_m = 0.0;
    /// Indices of the LODs to write (any order, no repeats); empty = all (the billboard too).
    std::vector<int> lods;
    /// > 0: add a billboard level after the tree's finest-to-coarsest LODs (LOD n for a tree
    /// of n LODs; app/export/billboard.h) baked from LOD0 into a texture of this many pixels a
    /// side (a power of two, 16 to 4096). `lods` may then name n. 0: none.
    int billboard_size = 0;
    /// > 0: the leaf and bark textures are made at this size (app/export/tree_output.h;
    /// the exporters themselves write the textures the tree has). 0: the tree's.
    int texture_size = 0;
    /// Also write a tangent-space normal map of the bark, derived from its texture's
    /// brightness (bark_normal_map): glTF normalTexture, OBJ map_Bump.
    bool bark_normal_map = false;
    /// Reorder every tree mesh for the post-transform vertex cache, then (the opaque bark
    /// only) for overdraw, then for vertex fetch (meshoptimizer; same triangles, other order).
    bool optimize = false;
    /// .glb only (the OBJ ignores it): quantized vertex data (KHR_mesh_quantization) and
    /// meshopt-compressed buffer views (EXT_meshopt_compression), both required extensions.
    bool compress = false;
    /// .glb only: quantized vertex data (KHR_mesh_quantization, required) without meshopt
    /// compression: smaller, and read by importers without EXT_meshopt_compression (Blender).
    bool quantize = false;
    bool include_lobes = false;   ///< write ExportScene::lobes
    bool include_strokes = false; ///< write ExportScene::strokes (those with two points or more)
};

/// One non-empty mesh of one LOD, in export space.
struct ExportPart {
    enum class Kind { Branches, Leaves, Billboard };
    std::string name; ///< `<scene name>_branches_LOD<k>`, `<scene name>_leaves_LOD<k>` or `<scene name>_billboard_LOD<n>`
    Kind kind = Kind::Branches;
    int lod = 0;               ///< index into TreeGeometry::lods; the billboard: TreeGeometry::lods.size()
    SurfaceGeometry geometry;  ///< base subtracted, scaled; normals renormalised
    /// Per-vertex tangents (xyz along +u, w the handedness: bitangent = cross(normal, xyz) · w,
    /// along +v) for the bark normal map; empty unless PreparedExport::bark_normal_map is set
    /// and this is a branches part.
    std::vector<glm::vec4> tangents;
};

/// A lobe in export space (positions only: flat shaded).
struct ExportLobe {
    std::string name; ///< `lobe_<id>`
    std::vector<glm::vec3> positions;
    std::vector<std::array<std::uint32_t, 3>> triangles;
};

/// A stroke in export space.
struct ExportPolyline {
    std::string name; ///< `stroke_<id>`
    std::vector<glm::vec3> points;
};

/// Everything an exporter writes, already checked and transformed.
struct PreparedExport {
    std::string name;
    std::vector<ExportPart> parts;      ///< by LOD ascending, branches before leaves; empty meshes left out
    std::vector<ExportLobe> lobes;      ///< empty unless include_lobes
    std::vector<ExportPolyline> strokes; ///< empty unless include_strokes
    const RgbaImage* leaf_texture = nullptr; ///< null when the tree has no texture (width or height 0)
    const RgbaImage* bark_texture = nullptr; ///< null when the tree has no bark texture
    RgbaImage billboard_texture;             ///< the billboard's baked picture; empty without a billboard part
    RgbaImage bark_normal_map;               ///< with ExportOptions::bark_normal_map and a bark texture; else empty
    std::array<float, 3> bark_color{};
    std::array<float, 3> leaf_color{};
    std::string species;
    float scale = 1.0f; ///< the uniform scale applied after subtracting the base
    bool has_leaves() const;
    bool has_branches() const;
    bool has_billboard() const;
};

/// Height of the tallest vertex of LOD0 (the tree itself; coarser LODs' larger leaves may
/// reach a little higher) above `base`, so that exporting any subset of LODs scales exactly
/// like exporting all of them: a target height h scales by h / tree_height. −∞ with no LOD.
double tree_height(const TreeGeometry& tree, const glm::vec3& base);

/// Checks `scene` and `options` and transforms the geometry: x' = (x − base) · scale.
/// \throw InvalidInput (one line) for a missing tree, a bad name, an unknown or repeated LOD
/// index, a non-finite or negative target height, a tree with no height to scale, array
/// sizes that disagree, non-finite positions/normals/uvs, zero normals, out-of-range or
/// negative triangle indices, or a leaf texture whose pixel count does not match its size.
PreparedExport prepare_export(const ExportScene& scene, const ExportOptions& options);

/// Reads a PNG or JPEG picture (a reference photo) as RGBA8, scaled down (box filter) so that
/// neither side exceeds `max_side`. Untrusted: files over 64 MB or pictures over 16384 pixels
/// a side are refused before decoding.
/// \throw FileError (one line naming the file) when it cannot be read or decoded.
RgbaImage read_picture_file(const std::string& path, int max_side = 1024);

/// `image` (sRGB-encoded colours) multiplied by the linear colour `rgb`, as a glTF
/// baseColorFactor multiplies a baseColorTexture: decoded to linear, multiplied, encoded back
/// to sRGB, rounded; alpha kept. Baked into the OBJ's PNGs, which have no factor.
RgbaImage tinted_texture(const RgbaImage& image, const std::array<float, 3>& rgb);

/// A tangent-space normal map (RGB = (n + 1) / 2, +Z out of the surface, alpha 255) of the
/// brightness of `image` taken as a height field that tiles (wraps at the edges): dark
/// furrows lie deep. `strength` scales the slopes (1: one texture side of height per unit of
/// brightness … times the side in pixels / 32). Deterministic.
RgbaImage normal_map_from_height(const RgbaImage& image, double strength = 2.0);

/// sRGB-encoded byte to linear, and a linear value in [0, 1] back to an sRGB byte (rounded).
double srgb_to_linear(std::uint8_t v);
std::uint8_t linear_to_srgb(double v);

/// PNG encoding of an RGBA8 image (stb_image_write, deterministic: same pixels, same bytes).
/// \throw InvalidInput for an empty image or a pixel count that does not match.
std::vector<std::uint8_t> encode_png(const RgbaImage& image);

} // namespace lobe
