#pragma once
// Procedural tree graphs for the geometry tests and benchmarks: a trunk of skeleton nodes and
// branches that fork level by level with jittered directions, radii by the pipe model.
// Nodes are made breadth first, so the nodes of the lobes (one per first-level branch,
// alternating 0, 1, 0, …) are interleaved in the node order.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <deque>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "core/random.h"
#include "core/tree.h"
#include "growth/radii.h"

namespace lobe::test {

struct TreeShape {
    int depth = 8;                   ///< fork levels above the trunk
    double triple_fork_share = 0.0;  ///< share of forks with three children instead of two
    int nodes_per_branch = 3;        ///< nodes along each branch (at least)
    double max_node_spacing_m = 0.0; ///< when > 0, long branches get more nodes, at most this far apart
    double trunk_height_m = 1.2;
    double trunk_node_spacing_m = 0.02;
    double first_branch_m = 0.6;     ///< length of a first-level branch
    double length_ratio = 0.78;      ///< length of a branch / its parent's
    double fork_angle_deg = 32.0;
    double jitter_deg = 12.0;
    std::uint64_t seed = 1;
};

/// Deterministic uniform numbers in [0, 1) (core/random.h).
struct FixtureRng {
    SplitMix64 stream;
    double next() { return stream.uniform(); }
};

inline glm::dvec3 rotate_about(const glm::dvec3& v, const glm::dvec3& axis, double angle)
{
    const glm::dvec3 k = glm::normalize(axis);
    return v * std::cos(angle) + glm::cross(k, v) * std::sin(angle) + k * glm::dot(k, v) * (1.0 - std::cos(angle));
}

inline TreeGraph make_fixture_tree(const TreeShape& shape)
{
    constexpr double deg = 3.14159265358979323846 / 180.0;
    FixtureRng rng{SplitMix64(shape.seed)};
    TreeGraph g;
    TreeNode root;
    root.kind = TreeNodeKind::Root;
    g.nodes.push_back(root);
    const int trunk_nodes = std::max(1, static_cast<int>(std::lround(shape.trunk_height_m / shape.trunk_node_spacing_m)));
    for (int i = 1; i <= trunk_nodes; ++i) {
        TreeNode n;
        n.position = glm::vec3(0.0f, static_cast<float>(shape.trunk_height_m * i / trunk_nodes), 0.0f);
        n.parent = i - 1;
        n.kind = TreeNodeKind::Skeleton;
        g.nodes.push_back(n);
    }
    struct Pending {
        int parent;
        glm::dvec3 dir;
        double length;
        int level;
        int lobe;
    };
    std::deque<Pending> queue;
    const int top = static_cast<int>(g.nodes.size()) - 1;
    auto push_children = [&](int parent, const glm::dvec3& dir, double length, int level, int lobe) {
        const int count = rng.next() < shape.triple_fork_share ? 3 : 2;
        const double turn0 = rng.next() * 6.283185307179586;
        glm::dvec3 side = glm::cross(dir, glm::dvec3(0.3, 0.1, 0.9));
        if (glm::length(side) < 1e-6) side = glm::cross(dir, glm::dvec3(1, 0, 0));
        side = glm::normalize(side);
        for (int c = 0; c < count; ++c) {
            const glm::dvec3 axis = rotate_about(side, dir, turn0 + 6.283185307179586 * c / count);
            const double angle = (c == 0 ? 0.35 : 1.0) * shape.fork_angle_deg * deg + (rng.next() - 0.5) * 2.0 * shape.jitter_deg * deg;
            glm::dvec3 d = glm::normalize(rotate_about(dir, axis, angle) + glm::dvec3(0.0, 0.15, 0.0));
            queue.push_back({parent, d, length, level, lobe < 0 ? c % 2 : lobe});
        }
    };
    push_children(top, glm::dvec3(0, 1, 0), shape.first_branch_m, 1, -1);
    while (!queue.empty()) {
        const Pending b = queue.front();
        queue.pop_front();
        int parent = b.parent;
        glm::dvec3 pos(g.nodes[static_cast<std::size_t>(parent)].position);
        glm::dvec3 dir = b.dir;
        int nodes = shape.nodes_per_branch;
        if (shape.max_node_spacing_m > 0.0) nodes = std::max(nodes, static_cast<int>(std::ceil(b.length / shape.max_node_spacing_m)));
        const double step = b.length / nodes;
        for (int k = 0; k < nodes; ++k) {
            // A little bend along the branch.
            dir = glm::normalize(dir + glm::dvec3(rng.next() - 0.5, rng.next() - 0.5, rng.next() - 0.5) * 0.15);
            pos += dir * step;
            TreeNode n;
            n.position = glm::vec3(pos);
            n.parent = parent;
            n.lobe = b.lobe;
            n.subtree_id = 0;
            n.kind = TreeNodeKind::Grown;
            parent = static_cast<int>(g.nodes.size());
            g.nodes.push_back(n);
        }
        if (b.level < shape.depth) push_children(parent, dir, b.length * shape.length_ratio, b.level + 1, b.lobe);
    }
    assign_pipe_radii(g, 2.0, 0.0012);
    return g;
}

/// The depth-8 binary test tree (256 tips, 1,591 nodes).
inline TreeGraph binary_test_tree(std::uint64_t seed = 1)
{
    TreeShape s;
    s.seed = seed;
    return make_fixture_tree(s);
}

/// A tree the size of the largest scene's: 29,737 nodes and 5,264 tips.
inline TreeGraph large_test_tree()
{
    TreeShape s;
    s.depth = 11;
    s.triple_fork_share = 0.22;
    s.nodes_per_branch = 3;
    s.max_node_spacing_m = 0.05;
    s.first_branch_m = 0.9;
    s.length_ratio = 0.76;
    s.seed = 7;
    return make_fixture_tree(s);
}

} // namespace lobe::test
