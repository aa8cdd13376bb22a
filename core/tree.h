#pragma once
/// \file tree.h
/// The generic tree graph every growth model outputs (§5): nodes with parents, radii and the
/// library subtree each came from. Geometry (growth/branch_geometry.h) and export work on
/// this graph alone, so other growth models can be added without touching them.

#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

namespace lobe {

/// Where a node came from.
enum class TreeNodeKind : std::uint8_t {
    Root = 0,     ///< nodes[0]: the trunk base, on the ground
    Skeleton = 1, ///< on a sketched trunk stroke, or on the default trunk
    Grown = 2,    ///< grown by rule inside a lobe
    /// Reached from its parent without a branch between them (an L-system's turtle moving
    /// without drawing, `f` or `g`): it starts a branch of its own, as the root does, and
    /// nothing is drawn from its parent to it. Its parent is where the move began, so the
    /// graph stays one tree (radii, pruning and order work as for any node).
    Detached = 3,
};

struct TreeNode {
    glm::vec3 position{0.0f}; ///< metres, stage space
    int parent = -1;          ///< index into TreeGraph::nodes, smaller than this node's; -1 for the root only
    float radius = 0.0f;      ///< branch radius at this node, metres (pipe model, growth/radii.h)
    int subtree_id = -1;      ///< index of the library subtree this node came from; -1 for root and skeleton
    int lobe = -1;            ///< index of the lobe whose growth made it; -1 for root and skeleton
    TreeNodeKind kind = TreeNodeKind::Grown;
};

/// A tree: nodes[0] is the root; every other node's parent comes before it, so one pass
/// from the back visits children before parents (used to accumulate radii from the tips).
struct TreeGraph {
    std::vector<TreeNode> nodes;

    bool empty() const { return nodes.empty(); }
    std::size_t size() const { return nodes.size(); }
};

/// Children of every node, in node order. \pre graph's parents precede their children.
std::vector<std::vector<int>> tree_children(const TreeGraph& graph);

} // namespace lobe
