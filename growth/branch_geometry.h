#pragma once
/// \file branch_geometry.h
/// Branch geometry of a tree graph (§5, "the tree is rendered with generalised cylinders"):
/// the graph is cut into branch chains, each chain's curve is smoothed and swept by a
/// generalised cylinder with rotation-minimising (parallel-transport) frames, and the whole
/// tree is built at several levels of detail (LOD) together with its leaves
/// (growth/leaves.h). docs/tree-geometry.md states the conventions and the LOD rules.
///
/// Bark texture coordinates: u goes around the branch mirrored, 0 → 1 → 0 (u = 1 − |1 − 2j/n|
/// at the j-th of n ring vertices), so the seam is welded and no vertex is duplicated; the
/// bark texture must tile (REPEAT) and is seen mirrored on the back half. v is the arc length
/// along the branch measured in half circumferences (v = ∫ ds / (π r)), so one texture tile
/// covers the same distance around and along the bark: the texture is not stretched.

#include <cstdint>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "core/settings.h"
#include "core/tree.h"
#include "growth/leaves.h"
#include "growth/tree_geometry.h"

namespace lobe {

/// A branch: a path through the graph from its base to a tip. At each fork the child whose
/// radius is largest (ties: the lowest index) continues the chain; every other child starts
/// a chain of its own whose first point is the fork node. A TreeNodeKind::Detached node
/// (core/tree.h: reached without drawing) never continues its parent's chain: it starts a
/// chain of its own, with no parent chain, as the root does.
struct BranchChain {
    std::vector<int> nodes; ///< node indices, base to tip; for a chain that starts at a fork, nodes[0] is the fork (parent) node
    int parent_chain = -1;  ///< chain holding nodes[0] as an interior point; -1 for the chain from the root and those from Detached nodes
    int fork_index = -1;    ///< index of nodes[0] in the parent chain's `nodes`; -1 for the root chain
    int sibling_ordinal = 0; ///< 1-based rank among the chains starting at the same fork (the continuing child is rank 0)
    int sibling_count = 1;   ///< number of children of the fork node
};

/// Cuts `graph` into branch chains. Chains come in topological order: a chain's parent
/// chain precedes it. Chains with fewer than two nodes (a lone root, a Detached node no drawn
/// branch leaves) are not returned, except the root's (chains[0]) when only Detached nodes
/// leave the root: it is then one node and draws nothing.
/// \pre the graph's parents precede their children (TreeGraph).
std::vector<BranchChain> decompose_branch_chains(const TreeGraph& graph);

/// A chain's centre line after smoothing.
struct BranchCurve {
    std::vector<glm::vec3> points; ///< #P ≥ 2 centre-line points, metres
    std::vector<float> radii;      ///< #P radii at the points, metres
    int parent = -1;               ///< index of the parent curve; -1 for the root curve
    float fork_arc_m = 0.0f;       ///< arc length along the parent curve where this curve starts
    float phase = 0.0f;            ///< angle of the first vertex of every ring, as a fraction of one radial segment, in [0, 1)
};

/// Smooths every chain's curve with `iterations` passes of Laplacian smoothing
/// (p_i ← ½ p_i + ¼ (p_{i−1} + p_{i+1})) that keep the end points. A chain that starts at a
/// fork starts at the smoothed position of the fork node on its parent's curve, so the child
/// starts inside its parent. Radii are the nodes' radii (a chain's first point has the radius
/// of its first child node, not the fork's).
/// \pre `chains` from decompose_branch_chains(graph).
std::vector<BranchCurve> smooth_branch_curves(const TreeGraph& graph, const std::vector<BranchChain>& chains,
                                              int iterations);

/// Resolution of one branch mesh.
struct BranchMeshOptions {
    int radial_segments = BranchSettings{}.radial_segments;  ///< vertices around each ring (3 to 1024)
    double ring_spacing_m = BranchSettings{}.ring_spacing_m; ///< largest distance between rings along a curve (> 0)
    /// A curve point is skipped (no ring on it) only while the curve turns there by less than
    /// this angle; larger turns always get a ring.
    double max_turn_deg = 10.0;
    /// Curves whose base radius (or any ancestor's) is below this are dropped with all their
    /// descendants: twig pruning for coarse LODs. The root curve is always kept.
    double min_radius_m = 0.0;
};

/// One ring of a swept branch, for tests and for callers that attach things to branches.
struct BranchRing {
    glm::vec3 centre{0.0f};  ///< on the curve
    glm::vec3 tangent{0.0f}; ///< unit; the ring lies in the plane through `centre` normal to it
    float radius = 0.0f;     ///< distance of the ring's vertices from `centre`
    float arc_m = 0.0f;      ///< arc length from the curve's first point
    std::uint32_t first_vertex = 0; ///< the ring's vertices are first_vertex … first_vertex + radial_segments − 1
    int curve = 0;           ///< index into the curves passed to build_branch_mesh
};

/// Rings of one curve at the given spacing: always at the first and last point, at curve
/// points where the curve turns by more than max_turn_deg, and elsewhere as few as keep
/// consecutive rings at most ring_spacing_m apart. Exposed for budget computations: a kept
/// curve with R rings costs 2·n·(R − 1) + n triangles (tube and tip cone), plus n for the
/// base cap of the root curve.
/// \throw InvalidInput when radial_segments is outside [3, 1024] or ring_spacing_m ≤ 0.
std::size_t count_branch_rings(const BranchCurve& curve, const BranchMeshOptions& options);

/// Sweeps a generalised cylinder along each kept curve: rings of radial_segments welded
/// vertices, consecutive rings joined by quads (two triangles each), frames transported
/// along the curve by the double-reflection rotation-minimising frame of Wang et al. (2008)
/// so the cylinder does not twist. Each tip ends in a cone (apex one tip radius beyond the
/// last point); the root curve's base is closed by a flat fan. A child curve's frame starts
/// from its parent's at the fork, turned by the curve's phase so no two rings meeting at a
/// fork share a vertex position. Radii below 10 µm are raised to 10 µm.
/// \param rings when not null, receives every ring of every kept curve.
/// \throw InvalidInput when radial_segments is outside [3, 1024] or ring_spacing_m ≤ 0.
SurfaceGeometry build_branch_mesh(const std::vector<BranchCurve>& curves, const BranchMeshOptions& options,
                                  std::vector<BranchRing>* rings = nullptr);

/// A copy of `graph` in which nodes closer than `tolerance_m` to their parent are merged into
/// it, and siblings closer than `tolerance_m` to each other are merged into the first of them
/// (their children move to it; the kept node gets the larger radius). Keeps the root.
/// \param old_to_new when not null, receives each old node's index in the result.
/// \throw InvalidInput when a parent does not precede its child or a position or radius is
/// not finite.
TreeGraph merge_coincident_nodes(const TreeGraph& graph, float tolerance_m = 1e-5f,
                                 std::vector<int>* old_to_new = nullptr);

/// A copy of `graph` without the twigs thinner than `min_radius_m`: every chain (see
/// decompose_branch_chains) whose first child node is thinner is removed with its whole
/// subtree. The chain from the root is always kept.
/// \param old_to_new when not null, receives each old node's index in the result, or −1.
TreeGraph prune_twigs(const TreeGraph& graph, float min_radius_m, std::vector<int>* old_to_new = nullptr);

/// Resolution of level of detail `lod` for `branches`: LOD0 is the settings themselves; each
/// further level multiplies the radial segments by 0.7 (rounded, at least 3: 8, 6, 4, 3, …),
/// doubles the ring spacing and allows 1.75 × the turn angle between rings (10°, 17.5°, …,
/// at most 60°). Twig pruning is chosen by
/// build_tree_geometry to meet the triangle budgets.
BranchMeshOptions branch_lod_options(const BranchSettings& branches, int lod);

/// Share of LOD0's triangles (branches + leaves) that LOD `lod` may use: 1, 0.27, 0.072, then
/// × 0.3 per further level (10 % below the 30 % and 8 % that LOD1 and LOD2 must stay under).
double lod_triangle_budget(int lod);

/// Most triangles LOD0 of a tree may have (branches and leaves), estimated from its rings and
/// leaves before any mesh is built; a larger tree is refused (docs/limits.md).
inline constexpr std::size_t kMaxTreeTriangles = 50000000;

/// Builds the tree's branch and leaf geometry at branches.lod_count levels of detail, the
/// leaf texture of leaves.shape, and the colours. LOD0 uses the settings as they are. Coarser
/// LODs come from the same smoothed skeleton with the coarser resolution of
/// branch_lod_options, the thinnest twigs pruned (the largest set of chains, thickest first,
/// that fits the budget lod_triangle_budget × LOD0's triangles), and the leaves merged into
/// cluster cards (growth/leaf_lod.h: leaf_lod_keep_fraction × LOD0's leaves, fewer when the
/// leaves alone would take more than 80 % of a LOD's budget), each card no larger than the
/// leaves it stands for, so the foliage keeps its silhouette. The leaf texture is the leaf
/// atlas (make_leaf_atlas): LOD0's leaves use its left half, the cards its right half.
/// Deterministic: the same inputs give the same bytes.
/// \throw InvalidInput on an invalid graph (see merge_coincident_nodes), lod_count outside
/// [1, 6], radial_segments outside [3, 1024], ring_spacing_m ≤ 0, an unknown leaf shape, a
/// lobe override make_leaf_cloud refuses, or a LOD0 beyond kMaxTreeTriangles.
/// `lobe_leaves`: per-lobe leaf length, count and seed (make_leaf_cloud).
/// `placed_leaves` (when not null): the leaves a grower placed itself (GrowthResult::leaves),
/// drawn instead of the leaves at the tips (make_placed_leaf_cloud); `leaves` then gives only
/// the texture's shape and the colour, `lobe_leaves` is not used.
TreeGeometry build_tree_geometry(const TreeGraph& graph, const BranchSettings& branches, const LeafSettings& leaves,
                                 std::uint64_t seed, const std::string& species = {},
                                 const LobeLeafOverrides& lobe_leaves = {},
                                 const std::vector<PlacedLeaf>* placed_leaves = nullptr);

/// build_tree_geometry into an existing TreeGeometry, reusing the storage of its meshes: a
/// caller that regrows the tree often (the editor, while the person sketches) keeps two
/// TreeGeometry values, draws one and rebuilds into the other, and after the first build no
/// memory is allocated for the meshes. `out` is left unchanged when this throws.
/// \throw InvalidInput as build_tree_geometry.
void build_tree_geometry_into(TreeGeometry& out, const TreeGraph& graph, const BranchSettings& branches,
                              const LeafSettings& leaves, std::uint64_t seed, const std::string& species = {},
                              const LobeLeafOverrides& lobe_leaves = {},
                              const std::vector<PlacedLeaf>* placed_leaves = nullptr);

} // namespace lobe
