#pragma once
/// \file leaves.h
/// Leaves (§5, "leaves are added at the tips of the branches"): alpha-tested textured quads at
/// the tip nodes of a tree graph, and the procedural leaf textures they use.
///
/// Leaf quads: a quad's base edge is centred on its tip node, its axis follows the branch
/// direction turned by a random angle of at most deviation_deg, and it is rolled by a random
/// angle about that axis. Texture coordinates: u = 0 … 1 across the leaf, v = 1 at the base
/// and 0 at the leaf's tip (image rows run top to bottom, glTF's convention, so the leaf in
/// the texture points up). Random choices come from a stream keyed by (seed, node.lobe,
/// ordinal of the node among the nodes of its lobe), so editing one lobe leaves the leaves of
/// every other lobe bit-identical.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "core/settings.h"
#include "core/tree.h"
#include "growth/tree_geometry.h"

namespace lobe {

/// A procedural leaf texture, size × size: the leaf's blade (alpha 255) on alpha 0, its stalk
/// at the bottom centre and its tip at the top centre, a light midrib and side veins and a
/// soft mottling. The colours are light (near white, slightly green) because the material's
/// leaf colour multiplies them. Deterministic.
/// \param shape "ovate" (pointed, widest below the middle), "round" or "needle" (narrow).
/// \throw InvalidInput for another shape or a size outside [8, 4096].
RgbaImage make_leaf_texture(const std::string& shape, int size = 128);

/// How a level of detail thins the leaves.
struct LeafLodOptions {
    /// Share of the LOD0 leaves kept, in (0, 1]. Each tip keeps ⌊per_node · keep + r⌋ of its
    /// LOD0 leaves (r a random number of the tip's stream, so the expected total is exact and
    /// tips keep a leaf in proportion), and every kept leaf's area is scaled by 1 / keep, so
    /// the total leaf area stays about the same.
    double keep_fraction = 1.0;
};

/// Tip nodes that carry leaves: nodes without children that are neither the root nor on the
/// skeleton (TreeNodeKind::Grown).
std::vector<int> leaf_tip_nodes(const TreeGraph& graph);

/// Leaf quads at the tips of `graph`: leaves.per_node quads per tip at LOD0 (fewer, larger
/// ones at keep_fraction < 1; those are the first of the tip's LOD0 leaves, scaled), each of
/// length_m × width_m. Four vertices per quad (no vertex shared between quads), normals the
/// quad's face normal (render two-sided). A tip whose parent is at the same position takes
/// the direction of the nearest ancestor that is not; if none, +Y.
/// Same as emit_leaf_quads(make_leaf_cloud(graph, leaves, seed), lod, out, quad_nodes).
/// \param quad_nodes when not null, receives the tip node of each quad.
/// \throw InvalidInput when keep_fraction is not in (0, 1].
SurfaceGeometry build_leaf_quads(const TreeGraph& graph, const LeafSettings& leaves, std::uint64_t seed,
                                 const LeafLodOptions& lod = {}, std::vector<int>* quad_nodes = nullptr);

/// One lobe's own leaves: what it sets replaces the tree's LeafSettings and seed for the tips
/// grown in that lobe (the session's per-lobe overrides, LobeRecord).
struct LobeLeafOverride {
    std::optional<double> length_m;    ///< leaf length; the width keeps the tree's width/length ratio
    std::optional<int> per_node;       ///< leaves per tip, ≥ 0
    std::optional<std::uint64_t> seed; ///< keys the lobe's leaf streams instead of the tree's seed
};
/// Per lobe, indexed by TreeNode::lobe (the lobe's index in growth order); lobes past its end
/// use the tree's settings.
using LobeLeafOverrides = std::vector<LobeLeafOverride>;

/// The random placement of every LOD0 leaf, drawn once and shared by all levels of detail.
struct LeafCloud {
    struct Leaf {
        glm::vec3 base{0.0f};   ///< the tip node's position: the middle of the quad's base edge
        glm::vec3 axis{0.0f};   ///< unit, from the base to the leaf's tip
        glm::vec3 across{0.0f}; ///< unit, normal to axis: the base edge's direction
        int node = 0;           ///< the tip node
        int rank = 0;           ///< 0 … per_node − 1 among the leaves of its tip
        int per_node = 0;       ///< leaves of its tip at LOD0 (the tree's, or its lobe's override)
        float keep_offset = 0;  ///< the tip's r in ⌊per_node · keep + r⌋, in [0, 1)
        double length_m = 0;    ///< LOD0 size (the tree's, or its lobe's override)
        double width_m = 0;
    };
    std::vector<Leaf> leaves; ///< tips in node order, each tip's leaves by rank
    int per_node = 0;         ///< the tree's leaves per tip
};

/// Draws the LOD0 leaves of `graph` (see build_leaf_quads). A lobe with an entry in
/// `per_lobe` takes its leaf length, count and seed from there.
/// \throw InvalidInput when an override's length is not in (0, 1] m or its count not in [0, 64].
LeafCloud make_leaf_cloud(const TreeGraph& graph, const LeafSettings& leaves, std::uint64_t seed,
                          const LobeLeafOverrides& per_lobe = {});

/// A leaf a grower placed itself (an L-system's surfaces, growth/lsystem/turtle.h) instead
/// of the leaves at the tips.
struct PlacedLeaf {
    glm::vec3 base{0.0f};   ///< metres, stage space: the middle of the leaf's base edge
    glm::vec3 axis{0.0f, 1.0f, 0.0f};   ///< unit, from the base to the leaf's tip
    glm::vec3 across{1.0f, 0.0f, 0.0f}; ///< unit, normal to axis: the base edge's direction
    float length_m = 0.0f;  ///< > 0
    float width_m = 0.0f;   ///< > 0
    int node = 0;           ///< the tree node it grew from (reported as the quad's node)
};

/// The LOD0 leaves of `placed`, one per placement in order: each is its own "tip" of one leaf
/// (per_node 1), its keep offset drawn from a stream keyed by (seed, its index), so coarser
/// LODs keep each leaf with probability keep_fraction (emit_leaf_quads) and every LOD thins
/// the same leaves whatever else changed.
/// \throw InvalidInput for a leaf with a non-finite position or direction, or a size not > 0.
LeafCloud make_placed_leaf_cloud(const std::vector<PlacedLeaf>& placed, std::uint64_t seed);

/// Number of quads emit_leaf_quads writes for `keep_fraction`.
std::size_t count_leaf_quads(const LeafCloud& cloud, double keep_fraction);

/// Writes the quads of `cloud` at `lod` into `out`, replacing its content but reusing its
/// storage. Sizes are each leaf's (LeafCloud::Leaf::length_m, width_m), their area scaled by
/// 1 / keep_fraction.
/// \throw InvalidInput when keep_fraction is not in (0, 1].
void emit_leaf_quads(const LeafCloud& cloud, const LeafLodOptions& lod, SurfaceGeometry& out,
                     std::vector<int>* quad_nodes = nullptr);

/// Share of the LOD0 leaves kept at level `lod`: 0.5^lod.
double leaf_lod_keep_fraction(int lod);

} // namespace lobe
