#include "growth/real_scale.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "core/errors.h"
#include "growth/radii.h"
#include "growth/species_form.h"

namespace lobe {

namespace {

constexpr int kMostLeavesPerShoot = 64;
// The golden angle (137.5077°), as constants: no trigonometry whose last bit could differ.
constexpr double kGoldenCos = -0.73736887807831974, kGoldenSin = 0.67549029426152364;

/// Length of the shoot of tip `tip`: the distance to its parent (0 for the root).
double shoot_length(const TreeGraph& graph, int tip)
{
    const TreeNode& n = graph.nodes[static_cast<std::size_t>(tip)];
    if (n.parent < 0) return 0.0;
    return glm::distance(glm::dvec3(n.position), glm::dvec3(graph.nodes[static_cast<std::size_t>(n.parent)].position));
}

int spread_count(double length, int count, double spacing)
{
    if (!(spacing > 0.0) || count <= 0 || !(length > count * spacing)) return count;
    return std::min(kMostLeavesPerShoot, std::max(count, static_cast<int>(std::floor(length / spacing))));
}

/// `v` turned about the unit `axis` by the angle of (c, s).
glm::dvec3 turn(const glm::dvec3& v, const glm::dvec3& axis, double c, double s)
{
    return v * c + glm::cross(axis, v) * s + axis * (glm::dot(axis, v) * (1.0 - c));
}

} // namespace

double graph_height(const TreeGraph& graph)
{
    double top = 0.0;
    if (graph.nodes.empty()) return top;
    const double root = graph.nodes[0].position.y;
    for (const TreeNode& n : graph.nodes) top = std::max(top, double(n.position.y) - root);
    return top;
}

void scale_tree_structure(TreeGraph& graph, double factor)
{
    if (!std::isfinite(factor) || !(factor > 0.0)) throw InvalidInput("real scale: the scale factor must be a positive number");
    if (graph.nodes.empty()) return;
    const glm::dvec3 root(graph.nodes[0].position);
    for (TreeNode& n : graph.nodes) n.position = glm::vec3(root + (glm::dvec3(n.position) - root) * factor);
}

void spread_leaves_along_shoots(LeafCloud& cloud, const TreeGraph& graph, const LeafSettings& leaves)
{
    if (!(leaves.spacing_m > 0.0) || cloud.leaves.empty()) return;
    std::vector<LeafCloud::Leaf> out;
    out.reserve(cloud.leaves.size());
    std::size_t i = 0;
    while (i < cloud.leaves.size()) {
        // One tip's leaves: consecutive, by rank.
        std::size_t end = i;
        while (end < cloud.leaves.size() && cloud.leaves[end].node == cloud.leaves[i].node) ++end;
        const int tip = cloud.leaves[i].node;
        const int k = static_cast<int>(end - i);
        const double length = shoot_length(graph, tip);
        const int count = spread_count(length, k, leaves.spacing_m);
        if (count == k) {
            out.insert(out.end(), cloud.leaves.begin() + static_cast<std::ptrdiff_t>(i),
                       cloud.leaves.begin() + static_cast<std::ptrdiff_t>(end));
            i = end;
            continue;
        }
        const TreeNode& node = graph.nodes[static_cast<std::size_t>(tip)];
        const glm::dvec3 shoot =
            glm::normalize(glm::dvec3(node.position) - glm::dvec3(graph.nodes[static_cast<std::size_t>(node.parent)].position));
        double c = 1.0, s = 0.0;
        for (int j = 0; j < count; ++j) {
            LeafCloud::Leaf leaf = cloud.leaves[i + static_cast<std::size_t>(j % k)];
            leaf.base = glm::vec3(glm::dvec3(node.position) - shoot * (length * j / count));
            leaf.axis = glm::vec3(glm::normalize(turn(glm::dvec3(leaf.axis), shoot, c, s)));
            leaf.across = glm::vec3(glm::normalize(turn(glm::dvec3(leaf.across), shoot, c, s)));
            leaf.rank = j;
            leaf.per_node = count;
            out.push_back(leaf);
            const double c2 = c * kGoldenCos - s * kGoldenSin;
            s = s * kGoldenCos + c * kGoldenSin;
            c = c2;
        }
        i = end;
    }
    cloud.leaves = std::move(out);
}

double fit_pipe_exponent(TreeGraph& graph, double tip_radius_m, double dbh_ratio, bool leader)
{
    const auto assign = [&](double e) {
        if (leader) assign_leader_radii(graph, e, tip_radius_m);
        else assign_pipe_radii(graph, e, tip_radius_m);
    };
    const std::vector<std::vector<int>> children = tree_children(graph);
    const double target = dbh_ratio * graph_height(graph);
    double lo = 1.0, hi = 4.0;
    for (int i = 0; i < 40; ++i) {
        const double mid = 0.5 * (lo + hi);
        assign(mid);
        (trunk_dbh(graph, children) > target ? lo : hi) = mid; // too thick: a larger exponent
    }
    const double e = 0.5 * (lo + hi);
    assign(e);
    return e;
}

double spread_leaf_count(const TreeGraph& graph, const LeafSettings& leaves, int most)
{
    double total = 0.0;
    if (most <= 0) return total;
    for (const int tip : leaf_tip_nodes(graph)) total += spread_count(shoot_length(graph, tip), most, leaves.spacing_m);
    return total;
}

} // namespace lobe
