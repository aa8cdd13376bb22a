#pragma once
/// \file grow.h
/// Lobe-guided growth (Zhang et al., §5.2, Fig. 7–8). The lobe vertices are attractors. Each
/// iteration assigns every live attractor to its nearest node of the whole tree; nodes with
/// attractors are active; an active node's attractors of one lobe form a cluster, split by its
/// angular spans (measured about the cluster's mean direction) into pieces, and each piece
/// grows one library subtree along V_A = V_cluster + α·V_default + β·V_gravity, scaled to the
/// signed distance from the node to the lobe surface along V_A. A piece whose distance is below
/// the stop threshold stops and its attractors leave the next iteration: the stop rule decides
/// where growth ends. An attractor within a small fraction of its node's subtree scale is
/// reached and removed (space colonization's kill distance, scaled). docs/growth.md.
///
/// One rule is per lobe: once the skeleton enters a lobe, only nodes inside that lobe take its
/// attractors (branches grow through a lobe, not around its thin parts from outside). Random
/// streams are keyed by (seed, lobe id, a key hashed from the node's ancestry), so editing one
/// lobe leaves the branches grown in the others bit-identical.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "core/mesh.h"
#include "core/settings.h"
#include "core/tree.h"
#include "growth/leaves.h"
#include "growth/skeleton.h"
#include "growth/subtree_library.h"

namespace lobe {

class MeshRaycaster;

/// One lobe to grow in.
struct GrowthLobe {
    std::int64_t id = 0;    ///< the lobe's id: keys its random streams
    TriangleMesh mesh;      ///< closed, outward, stage space; its vertices are the attractors
    double split_angle_deg = GrowthSettings{}.split_angle_deg; ///< t for this lobe (the tree's, or the lobe's override)
    std::vector<double> subtree_weights; ///< per library subtree (subtree_weights()); empty = all equal
    std::optional<std::uint64_t> seed;  ///< keys this lobe's random streams instead of the tree's seed
};

struct LobeGrowthStats {
    std::size_t attractors = 0;
    std::size_t reached = 0;  ///< removed: came within a node's reach (its scaled kill distance)
    std::size_t stopped = 0;  ///< left with a piece the stop rule stopped (too close to the surface)
    std::size_t left = 0;     ///< left with a node that could grow no more towards them
    std::size_t nodes = 0;    ///< nodes grown in this lobe
    std::size_t subtrees = 0; ///< subtrees grown
    int iterations = 0;
    bool iteration_cap = false;
    bool node_cap = false;
    /// Share of the attractors removed by reach; stop_share() those the stop rule ended.
    double coverage() const { return attractors ? static_cast<double>(reached) / static_cast<double>(attractors) : 1.0; }
    double stop_share() const { return attractors ? static_cast<double>(stopped) / static_cast<double>(attractors) : 0.0; }
};

/// An attractor of the first iteration's clusters (Fig. 7b–c): the node it belongs to, its
/// lobe (index) and the piece of the node's cluster it fell in (numbered across the tree).
struct ClusteredAttractor {
    glm::vec3 position{0.0f};
    int node = 0;
    int lobe = 0;
    int piece = 0;
};

struct GrowthResult {
    TreeGraph tree; ///< skeleton nodes first, then each lobe's grown nodes in lobe order; radii unset
    std::size_t skeleton_nodes = 0;
    std::vector<LobeGrowthStats> lobes;
    std::vector<std::string> messages; ///< one line each (skeleton messages, caps hit)
    /// The grower set every node's radius itself (an L-system's widths): the pipe model
    /// (growth/radii.h) is not applied. False: radii are left to the caller.
    bool radii_set = false;
    /// Leaves the grower placed itself (an L-system's surfaces), drawn instead of the leaves
    /// at the tips; nullopt: leaves at the tips (growth/leaves.h). An empty list: no leaves.
    std::optional<std::vector<PlacedLeaf>> leaves;
    /// Radii by the pipe model with a leader at each branching (assign_leader_radii,
    /// radii.h) rather than the plain pipe model; the subtree grower sets it.
    bool leader_radii = false;
    /// The first iteration's clusters and pieces (subtree grower; empty for the others).
    std::vector<ClusteredAttractor> first_clusters;
};

/// Most nodes a single piece's cluster split may make (⌈θh/t⌉ × ⌈θv/t⌉ is capped to this).
inline constexpr int kMaxPiecesPerNode = 256;
/// A node grows at most this many times (once per iteration it is active in).
inline constexpr int kMaxGrowthsPerNode = 4;
/// Most nodes of a whole tree (skeleton and every lobe's growth): GrowthSettings::max_nodes
/// caps each lobe, this caps their sum, so memory stays bounded however many lobes a session
/// holds. A lobe grows at most the nodes left under it; lobes after the cap is reached are
/// not grown, each with a message (docs/limits.md).
inline constexpr std::size_t kMaxTreeNodes = 5000000;

/// V_A = V_cluster + α·V_default + β·(0, −1, 0), unnormalised (§5.2).
glm::dvec3 growth_vector(const glm::dvec3& v_cluster, const glm::dvec3& v_default, double alpha, double beta);

/// Angular spans of a cluster of unit directions, in a frame around the cluster's mean
/// direction (no pole near it, whichever way it points): θh the smallest arc of longitudes
/// about an axis perpendicular to the mean (leaning to +Y) that holds them all, θv the range
/// of latitudes from the plane of the mean and that axis's normal; degrees. A cluster whose
/// directions nearly cancel out (|mean| ≤ 0.1) is measured about +Y.
struct ClusterSpan {
    double horizontal_deg = 0.0;
    double vertical_deg = 0.0;
};
ClusterSpan cluster_span(const std::vector<glm::vec3>& unit_dirs);

/// Splits a cluster into ⌈θh/t⌉ × ⌈θv/t⌉ pieces by longitude and latitude (§5.2; one piece
/// when neither span exceeds t = `split_angle_deg`, degrees; at most kMaxPiecesPerNode).
/// Returns the non-empty pieces as indices into `unit_dirs`, in bin order; `grid_h` and
/// `grid_v` (when given) receive the number of bins horizontally and vertically.
std::vector<std::vector<int>> split_cluster(const std::vector<glm::vec3>& unit_dirs, double split_angle_deg,
                                            int* grid_h = nullptr, int* grid_v = nullptr);

/// V_cluster (§5.2): Σ d_i·V_i / Σ d_i, V_i the unit vector from `node` to attractor i and d_i
/// its distance (distant attractors pull harder, "towards bulgy and distant regions"),
/// normalised; +Y when they cancel out.
glm::dvec3 cluster_direction(const glm::vec3& node, const std::vector<glm::vec3>& attractors);

/// The whole tree: skeleton from the trunk strokes (or the default trunk), then growth in
/// every lobe at once, one graph rooted at the trunk base: skeleton nodes first, then the
/// grown nodes in the order they grew. Radii are left to assign_leader_radii (radii.h).
/// `max_tree_nodes` caps the whole tree (kMaxTreeNodes; tests lower it); max_nodes × the
/// number of lobes caps the grown nodes. A lobe nothing grows into gets a one-line message.
/// \throw InvalidInput when there is a lobe to grow and the library has no subtree.
GrowthResult grow_tree(const std::vector<std::vector<glm::vec3>>& trunk_strokes, const std::vector<GrowthLobe>& lobes,
                       const GrowthSettings& settings, const SubtreeLibrary& library, std::uint64_t seed,
                       std::size_t max_tree_nodes = kMaxTreeNodes);

} // namespace lobe
