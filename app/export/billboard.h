#pragma once
/// \file billboard.h
/// The billboard level of an exported tree: crossed cards with the tree baked into their
/// texture (colour and alpha), for an engine's farthest LOD. Baked on the CPU by rasterising
/// the finest LOD (no GPU, no window; same input, same bytes).
///
/// Cards: three vertical cards through the trunk axis (the export's Y axis) at 0°, 60° and
/// 120° about it, each spanning the tree's extent across it and from its lowest to its
/// highest vertex, and one horizontal card at half the crown's height spanning the tree seen
/// from above: 4 quads, 8 triangles, render double-sided with alpha testing. Texture: 2 × 2
/// cells of size/2 pixels, cell k for card k (rows top to bottom: cells 0 1 / 2 3). Each
/// cell holds the tree seen orthographically along its card's normal: bark and leaves with
/// their textures and colours (sRGB-encoded, linear colours multiplied as glTF does), shaded
/// lightly by a fixed sun so the volume reads, 2 × 2 supersampled; alpha is the coverage,
/// and the colour of transparent texels is spread from their covered neighbours so
/// filtering does not darken the outline.

#include <array>

#include "growth/tree_geometry.h"

namespace lobe {

struct BillboardInput {
    const SurfaceGeometry* branches = nullptr; ///< finest LOD, export space (metres, base at the origin); may be empty
    const SurfaceGeometry* leaves = nullptr;   ///< idem
    const RgbaImage* bark_texture = nullptr;   ///< null: bark_color alone
    const RgbaImage* leaf_texture = nullptr;   ///< null: leaf_color alone, no cut-out
    std::array<float, 3> bark_color{};         ///< linear RGB
    std::array<float, 3> leaf_color{};         ///< linear RGB
};

struct Billboard {
    SurfaceGeometry cards; ///< 16 vertices, 8 triangles; uv over `texture`
    RgbaImage texture;     ///< size × size
};

/// Bakes the billboard of `in` at `size` × `size` pixels.
/// \throw InvalidInput when size is not a power of two in [16, 4096], or the tree has no
/// vertex (nothing to see).
Billboard bake_billboard(const BillboardInput& in, int size);

} // namespace lobe
