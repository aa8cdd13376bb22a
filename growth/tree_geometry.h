#pragma once
/// \file tree_geometry.h
/// Renderable and exportable geometry of a tree: branch and leaf meshes per level of detail,
/// plus the leaf texture. Plain data; made by growth/branch_geometry.h and growth/leaves.h,
/// consumed by the exporters (app/export/export_gltf.h, app/export/export_obj.h) and the renderer.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace lobe {

/// A triangle mesh with per-vertex normals and texture coordinates.
struct SurfaceGeometry {
    std::vector<glm::vec3> positions;                  ///< #V positions, metres
    std::vector<glm::vec3> normals;                    ///< #V unit normals
    std::vector<glm::vec2> uvs;                        ///< #V texture coordinates
    std::vector<std::array<std::uint32_t, 3>> triangles; ///< #F, counter-clockwise seen from the front

    std::size_t vertex_count() const { return positions.size(); }
    std::size_t triangle_count() const { return triangles.size(); }
    bool empty() const { return triangles.empty(); }
};

/// An 8-bit RGBA image, rows top to bottom.
struct RgbaImage {
    int width = 0;
    int height = 0;
    std::vector<std::uint8_t> pixels; ///< width × height × 4
};

/// One level of detail.
struct TreeLod {
    SurfaceGeometry branches; ///< bark: u around the branch (mirrored 0 → 1 → 0), v along it in half circumferences
    SurfaceGeometry leaves;   ///< quads (two triangles each), uv over the leaf texture; render two-sided
};

struct TreeGeometry {
    std::vector<TreeLod> lods; ///< LOD0 (finest) first
    RgbaImage leaf_texture;    ///< alpha-tested (alpha 0 outside the leaves): the leaf atlas, one leaf left, a spray right (growth/leaf_lod.h)
    RgbaImage bark_texture;    ///< tiles (REPEAT) over the bark UVs; multiplied by bark_color; may be empty
    std::array<float, 3> bark_color{0.36f, 0.25f, 0.17f}; ///< linear RGB
    std::array<float, 3> leaf_color{0.20f, 0.42f, 0.12f}; ///< linear RGB (multiplies the texture)
    std::string species;       ///< preset name, for material names
};

} // namespace lobe
