#pragma once
/// \file leaf_lod.h
/// Leaves of the coarser levels of detail: the LOD0 leaves merged into cluster cards instead
/// of fewer leaves blown up. A cluster card stands for the leaves of one cell of an octree
/// over the crown; it lies in the plane of their mean direction and spans exactly the box of
/// their corners in that plane, so no card reaches past the leaves it replaces (a lone leaf
/// keeps its own quad). Cards are textured from the right half of the leaf atlas
/// (make_leaf_atlas), a picture of a spray of leaves; LOD0's leaves use its left half.

#include <cstddef>

#include "growth/leaves.h"
#include "growth/tree_geometry.h"

namespace lobe {

/// The leaf atlas of a tree: 2·n × n pixels for an n × n `leaf` picture (make_leaf_texture):
/// the leaf itself on the left half, on the right half a spray of eleven copies of it fanning
/// from the bottom centre (turned by up to ±83°, sizes 50 % to 100 % of the cell), composited
/// by alpha. Colours outside the leaves are kept (alpha 0) as in the leaf picture, so
/// filtering does not darken the edges. Deterministic.
/// \throw InvalidInput when `leaf` is not square, is empty, or its pixel count is wrong.
RgbaImage make_leaf_atlas(const RgbaImage& leaf);

/// Maps the texture coordinates of LOD0 leaf quads (u in [0, 1] over one leaf) to the atlas's
/// left half: u ← u / 2.
void use_single_leaf_half(SurfaceGeometry& leaves);

/// Writes at most `max_cards` leaf cards for `cloud` into `out` (replacing its content):
/// the leaves are grouped by the finest octree level over their centres (bounding cube of all
/// leaf centres, Morton order) that gives no more than `max_cards` groups, and then, in Morton
/// order, groups are split into their cells one level finer while the total stays within
/// max_cards. Each group becomes one quad (4 vertices, 2 triangles, normal the card's face
/// normal) over the box of its leaves' corners, in the plane spanned by their mean axis and
/// the first leaf's base edge, shrunk about its middle until its corners lie in the
/// axis-aligned box of those leaves' corners (a card never reaches past its leaves); a group
/// of one leaf gets that leaf's own rectangle. Every card shows the spray (uv u in [0.5, 1]),
/// so all cards share one texture rectangle and can be drawn instanced. With max_cards ≥ the
/// number of leaves this is every leaf as at LOD0, on the single-leaf half. No card when
/// max_cards is 0.
/// Deterministic (no floating-point sums whose order depends on anything but the cloud).
void emit_leaf_cluster_cards(const LeafCloud& cloud, std::size_t max_cards, SurfaceGeometry& out);

} // namespace lobe
