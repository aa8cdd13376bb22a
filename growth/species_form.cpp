#include "growth/species_form.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

namespace lobe {

namespace {
constexpr double kHalfPi = 1.57079632679489661923;
constexpr double kDeg = 57.295779513082320877; // degrees per radian
} // namespace

std::vector<glm::vec3> default_leader_points(const glm::vec3& from, float crown_bottom_y, float crown_top_y,
                                             double whorl_spacing, double spacing_m)
{
    std::vector<glm::vec3> pts;
    const float crown = std::max(crown_top_y - crown_bottom_y, 0.0f);
    const float top = crown_bottom_y + 0.95f * crown;
    if (!(top > from.y) || !(spacing_m > 0.0)) return pts;
    const double step = whorl_spacing > 0.0 ? whorl_spacing * double(crown) : spacing_m;
    const int pieces = std::clamp(static_cast<int>(std::ceil(double(top - from.y) / std::max(step, 1e-4))), 1, 2000);
    for (int i = 1; i <= pieces; ++i)
        pts.emplace_back(from.x, from.y + (top - from.y) * static_cast<float>(i) / static_cast<float>(pieces), from.z);
    return pts;
}

void apply_species_form(TreeGraph& graph, std::size_t skeleton_nodes, const GrowthSettings& settings)
{
    const double droop = std::clamp(settings.droop, 0.0, 1.0), hang = std::clamp(settings.hang, 0.0, 1.0);
    if ((droop == 0.0 && hang == 0.0) || graph.nodes.size() <= skeleton_nodes) return;
    const std::size_t n = graph.nodes.size();
    // Each grown node's lateral (the skeleton node it grew from) and path length from it.
    std::vector<int> base(n, -1);
    std::vector<double> dist(n, 0.0), longest(n, 0.0);
    for (std::size_t i = skeleton_nodes; i < n; ++i) {
        const int p = graph.nodes[i].parent;
        if (p < 0) continue;
        const double seg = glm::distance(glm::dvec3(graph.nodes[i].position),
                                         glm::dvec3(graph.nodes[static_cast<std::size_t>(p)].position));
        if (static_cast<std::size_t>(p) < skeleton_nodes) {
            base[i] = p;
            dist[i] = seg;
        } else {
            base[i] = base[static_cast<std::size_t>(p)];
            dist[i] = dist[static_cast<std::size_t>(p)] + seg;
        }
        if (base[i] >= 0) longest[static_cast<std::size_t>(base[i])] = std::max(longest[static_cast<std::size_t>(base[i])], dist[i]);
    }
    std::vector<glm::dvec3> moved(n);
    for (std::size_t i = 0; i < n; ++i) moved[i] = glm::dvec3(graph.nodes[i].position);
    for (std::size_t i = skeleton_nodes; i < n; ++i) {
        const int p = graph.nodes[i].parent;
        if (p < 0 || base[i] < 0) continue;
        const glm::dvec3 from(graph.nodes[static_cast<std::size_t>(p)].position);
        const glm::dvec3 d = glm::dvec3(graph.nodes[i].position) - from;
        const double len = glm::length(d);
        const double total = longest[static_cast<std::size_t>(base[i])];
        if (len < 1e-9 || !(total > 0.0)) {
            moved[i] = moved[static_cast<std::size_t>(p)] + d;
            continue;
        }
        const glm::dvec3 u = d / len;
        glm::dvec3 h(u.x, 0.0, u.z);
        if (glm::length(h) < 1e-6) {
            // A vertical segment: it bends away from the lateral's base (or along +X).
            const glm::dvec3 out = glm::dvec3(graph.nodes[i].position) -
                                   glm::dvec3(graph.nodes[static_cast<std::size_t>(base[i])].position);
            h = glm::dvec3(out.x, 0.0, out.z);
            if (glm::length(h) < 1e-6) h = glm::dvec3(1.0, 0.0, 0.0);
        }
        h = glm::normalize(h);
        const double t = std::clamp(dist[i] / total, 0.0, 1.0);
        const double w = 1.0 - (1.0 - droop * t) * (1.0 - hang * std::clamp(1.5 * (t - 1.0 / 3.0), 0.0, 1.0));
        const double e = std::asin(std::clamp(u.y, -1.0, 1.0));
        const double bent = e - w * (e + kHalfPi);
        moved[i] = moved[static_cast<std::size_t>(p)] + len * (std::cos(bent) * h + glm::dvec3(0.0, std::sin(bent), 0.0));
    }
    for (std::size_t i = skeleton_nodes; i < n; ++i) graph.nodes[i].position = glm::vec3(moved[i]);
}

double quantile(const std::vector<double>& sorted, double q)
{
    if (sorted.empty()) return 0.0;
    const double pos = std::clamp(q, 0.0, 1.0) * static_cast<double>(sorted.size() - 1);
    return sorted[static_cast<std::size_t>(std::lround(pos))];
}

double trunk_dbh(const TreeGraph& graph, const std::vector<std::vector<int>>& children)
{
    if (graph.nodes.empty()) return 0.0;
    const double root = graph.nodes[0].position.y;
    double height = 0.0;
    for (const TreeNode& n : graph.nodes) height = std::max(height, double(n.position.y) - root);
    // Along the trunk: from the root, always into the thickest child (lowest index on ties).
    const double breast = height >= 8.0 ? 1.3 : 0.1625 * height;
    std::size_t at = 0;
    double dbh = 2.0 * graph.nodes[0].radius;
    for (;;) {
        const std::vector<int>& kids = children[at];
        if (kids.empty()) break;
        int next = kids[0];
        for (int c : kids)
            if (graph.nodes[static_cast<std::size_t>(c)].radius > graph.nodes[static_cast<std::size_t>(next)].radius) next = c;
        const TreeNode& a = graph.nodes[at];
        const TreeNode& b = graph.nodes[static_cast<std::size_t>(next)];
        const double ya = a.position.y - root, yb = b.position.y - root;
        if (yb >= breast && ya <= breast) {
            const double f = yb > ya ? (breast - ya) / (yb - ya) : 0.0;
            return 2.0 * (a.radius + f * (b.radius - a.radius));
        }
        dbh = 2.0 * b.radius;
        at = static_cast<std::size_t>(next);
    }
    return dbh;
}

TreeFormStats tree_form_stats(const TreeGraph& graph)
{
    TreeFormStats st;
    if (graph.nodes.empty()) return st;
    const std::vector<std::vector<int>> children = tree_children(graph);
    const glm::dvec3 root(graph.nodes[0].position);
    auto seg = [&](std::size_t i) {
        const int p = graph.nodes[i].parent;
        return p < 0 ? glm::dvec3(0.0) : glm::dvec3(graph.nodes[i].position) - glm::dvec3(graph.nodes[static_cast<std::size_t>(p)].position);
    };
    std::size_t tips = 0, drooping = 0;
    for (std::size_t i = 0; i < graph.nodes.size(); ++i) {
        st.height_m = std::max(st.height_m, double(graph.nodes[i].position.y) - root.y);
        const glm::dvec3 in = seg(i);
        if (children[i].size() >= 2 && glm::length(in) > 1e-9)
            for (int c : children[i]) {
                const glm::dvec3 out = seg(static_cast<std::size_t>(c));
                if (glm::length(out) < 1e-9) continue;
                const double cosa = std::clamp(glm::dot(glm::normalize(in), glm::normalize(out)), -1.0, 1.0);
                st.branch_angles_deg.push_back(std::acos(cosa) * kDeg);
            }
        if (children[i].empty() && graph.nodes[i].kind == TreeNodeKind::Grown) {
            const glm::dvec3 d = seg(i);
            if (glm::length(d) < 1e-9) continue;
            const double elev = std::asin(std::clamp(glm::normalize(d).y, -1.0, 1.0)) * kDeg;
            st.tip_elevations_deg.push_back(elev);
            ++tips;
            if (elev < 0.0) ++drooping;
        }
    }
    std::sort(st.branch_angles_deg.begin(), st.branch_angles_deg.end());
    std::sort(st.tip_elevations_deg.begin(), st.tip_elevations_deg.end());
    st.drooping_tip_share = tips ? double(drooping) / double(tips) : 0.0;
    st.dbh_m = trunk_dbh(graph, children);
    return st;
}

} // namespace lobe
