#include "tests/support/tree_checks.h"

#include <cmath>

#include <glm/geometric.hpp>
#include <nanoflann.hpp>

#include "growth/mesh_raycast.h"

namespace lobe::test {

namespace {

struct Points {
    std::vector<glm::vec3> pts;
    std::size_t kdtree_get_point_count() const { return pts.size(); }
    float kdtree_get_pt(std::size_t i, std::size_t d) const { return pts[i][static_cast<int>(d)]; }
    template <class B>
    bool kdtree_get_bbox(B&) const { return false; }
};
using Index = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, Points>, Points, 3, std::uint32_t>;

} // namespace

double tip_reach_share(const TreeGraph& tree, const std::vector<TriangleMesh>& lobes, double within_m)
{
    std::vector<int> children(tree.nodes.size(), 0);
    for (const TreeNode& n : tree.nodes)
        if (n.parent >= 0) ++children[static_cast<std::size_t>(n.parent)];
    Points tips;
    for (std::size_t i = 0; i < tree.nodes.size(); ++i)
        if (children[i] == 0) tips.pts.push_back(tree.nodes[i].position);
    std::size_t total = 0, near = 0;
    if (tips.pts.empty()) return 0.0;
    Index index(3, tips, nanoflann::KDTreeSingleIndexAdaptorParams(10));
    const float r2 = static_cast<float>(within_m * within_m);
    for (const TriangleMesh& m : lobes)
        for (const glm::vec3& v : m.positions) {
            std::uint32_t i = 0;
            float d2 = 0.0f;
            index.knnSearch(&v.x, 1, &i, &d2);
            ++total;
            if (d2 <= r2) ++near;
        }
    return total ? static_cast<double>(near) / static_cast<double>(total) : 1.0;
}

double outside_share(const TreeGraph& tree, const std::vector<TriangleMesh>& lobes)
{
    std::vector<MeshRaycaster> rays;
    for (const TriangleMesh& l : lobes) rays.emplace_back(l);
    double out = 0.0, total = 0.0;
    for (const TreeNode& n : tree.nodes) {
        if (n.kind != TreeNodeKind::Grown) continue;
        const glm::vec3 a = tree.nodes[static_cast<std::size_t>(n.parent)].position;
        const double len = glm::distance(a, n.position);
        const glm::vec3 mid = 0.5f * (a + n.position);
        bool in = false;
        for (const MeshRaycaster& r : rays) in = in || r.inside(mid);
        total += len;
        if (!in) out += len;
    }
    return total > 0.0 ? out / total : 0.0;
}

double leader_share(const TreeGraph& tree, double ratio)
{
    std::vector<float> thickest(tree.nodes.size(), -1.0f);
    for (const TreeNode& n : tree.nodes)
        if (n.parent >= 0) {
            float& t = thickest[static_cast<std::size_t>(n.parent)];
            t = std::max(t, n.radius);
        }
    std::size_t with_children = 0, led = 0;
    for (std::size_t i = 0; i < tree.nodes.size(); ++i) {
        if (thickest[i] < 0.0f) continue;
        ++with_children;
        if (thickest[i] >= static_cast<float>(ratio) * tree.nodes[i].radius) ++led;
    }
    return with_children ? static_cast<double>(led) / static_cast<double>(with_children) : 1.0;
}

bool radii_non_increasing(const TreeGraph& tree)
{
    for (const TreeNode& n : tree.nodes) {
        if (!std::isfinite(n.radius) || !(n.radius > 0.0f)) return false;
        if (n.parent >= 0 && n.radius > tree.nodes[static_cast<std::size_t>(n.parent)].radius) return false;
    }
    return true;
}

} // namespace lobe::test
