// Branch geometry: chains, smoothing, the generalised-cylinder sweep and the LODs
// (growth/branch_geometry.h).
#include <gtest/gtest.h>

#include <map>
#include <set>

#include "core/errors.h"
#include "growth/branch_geometry.h"
#include "growth/leaves.h"
#include "tests/support/geometry_checks.h"
#include "tests/support/tree_fixtures.h"

using namespace lobe;
using namespace lobe::test;

namespace {

/// Root at the origin and one grown node `length` above it.
TreeGraph two_node_tree(float length = 1.0f, float radius = 0.02f)
{
    TreeGraph g;
    TreeNode root;
    root.kind = TreeNodeKind::Root;
    root.radius = radius;
    g.nodes.push_back(root);
    TreeNode tip;
    tip.position = {0.0f, length, 0.0f};
    tip.parent = 0;
    tip.radius = radius;
    tip.lobe = 0;
    g.nodes.push_back(tip);
    return g;
}

/// A small tree with nodes on top of their parents and coincident siblings.
TreeGraph coincident_node_tree()
{
    TreeGraph g;
    auto add = [&](glm::vec3 p, int parent, TreeNodeKind kind = TreeNodeKind::Grown) {
        TreeNode n;
        n.position = p;
        n.parent = parent;
        n.kind = kind;
        n.lobe = parent < 0 ? -1 : 0;
        g.nodes.push_back(n);
        return static_cast<int>(g.nodes.size()) - 1;
    };
    const int root = add({0, 0, 0}, -1, TreeNodeKind::Root);
    const int same_as_root = add({0, 0, 0}, root); // zero-length segment
    const int a = add({0, 0.3f, 0}, same_as_root);
    const int a2 = add({0, 0.3f, 0}, a);           // again on top of its parent
    const int b = add({0.1f, 0.5f, 0}, a2);
    add({0.1f, 0.5f, 0}, a2);                      // coincident sibling of b
    add({0.2f, 0.7f, 0}, b);
    add({-0.1f, 0.55f, 0.05f}, a);
    add({-0.1f, 0.55f, 0.05f}, a);                 // coincident twin tips
    assign_pipe_radii(g, 2.0, 0.0012);
    return g;
}

BranchSettings default_branches() { return BranchSettings{}; }
LeafSettings default_leaves() { return LeafSettings{}; }

std::size_t lod_triangles(const TreeLod& lod) { return lod.branches.triangle_count() + lod.leaves.triangle_count(); }

/// Distance from p to the polyline.
double distance_to_polyline(const glm::vec3& p, const std::vector<glm::vec3>& line)
{
    double best = 1e30;
    for (std::size_t i = 0; i + 1 < line.size(); ++i) {
        const glm::dvec3 a(line[i]), b(line[i + 1]), q(p);
        const glm::dvec3 ab = b - a;
        const double t = std::clamp(glm::dot(q - a, ab) / std::max(1e-30, glm::dot(ab, ab)), 0.0, 1.0);
        best = std::min(best, glm::length(a + t * ab - q));
    }
    return best;
}

} // namespace

TEST(BranchGeometry, ChainsCoverEveryEdgeOnceAndContinueTheThickestChild)
{
    const TreeGraph g = binary_test_tree();
    const auto chains = decompose_branch_chains(g);
    const auto children = tree_children(g);
    std::size_t forks = 0;
    for (const auto& c : children)
        if (!c.empty()) forks += c.size() - 1;
    EXPECT_EQ(chains.size(), 1 + forks);
    std::vector<int> covered(g.size(), 0);
    for (std::size_t c = 0; c < chains.size(); ++c) {
        const BranchChain& ch = chains[c];
        ASSERT_GE(ch.nodes.size(), 2u);
        EXPECT_LT(ch.parent_chain, static_cast<int>(c)) << "a chain's parent precedes it";
        for (std::size_t k = 1; k < ch.nodes.size(); ++k) {
            ++covered[static_cast<std::size_t>(ch.nodes[k])];
            EXPECT_EQ(g.nodes[static_cast<std::size_t>(ch.nodes[k])].parent, ch.nodes[k - 1]);
        }
        if (ch.parent_chain >= 0) {
            EXPECT_EQ(chains[static_cast<std::size_t>(ch.parent_chain)].nodes[static_cast<std::size_t>(ch.fork_index)], ch.nodes[0]);
        }
        // Inside a chain, each step goes to the thickest child.
        for (std::size_t k = 0; k + 1 < ch.nodes.size(); ++k) {
            if (k == 0 && ch.parent_chain >= 0) continue;
            float thickest = 0.0f;
            for (int child : children[static_cast<std::size_t>(ch.nodes[k])])
                thickest = std::max(thickest, g.nodes[static_cast<std::size_t>(child)].radius);
            EXPECT_EQ(g.nodes[static_cast<std::size_t>(ch.nodes[k + 1])].radius, thickest);
        }
        EXPECT_TRUE(children[static_cast<std::size_t>(ch.nodes.back())].empty()) << "chains end at tips";
    }
    for (std::size_t i = 1; i < g.size(); ++i) EXPECT_EQ(covered[i], 1) << "node " << i;
}

TEST(BranchGeometry, SmoothingKeepsEndPointsAndChildCurvesStartOnTheirParentCurve)
{
    const TreeGraph g = binary_test_tree();
    const auto chains = decompose_branch_chains(g);
    const auto curves = smooth_branch_curves(g, chains, 4);
    ASSERT_EQ(curves.size(), chains.size());
    for (std::size_t c = 0; c < curves.size(); ++c) {
        const BranchCurve& cu = curves[c];
        const BranchChain& ch = chains[c];
        EXPECT_EQ(cu.points.back(), g.nodes[static_cast<std::size_t>(ch.nodes.back())].position);
        if (ch.parent_chain < 0) {
            EXPECT_EQ(cu.points.front(), g.nodes[0].position);
        } else {
            const BranchCurve& parent = curves[static_cast<std::size_t>(ch.parent_chain)];
            EXPECT_EQ(cu.points.front(), parent.points[static_cast<std::size_t>(ch.fork_index)]);
            EXPECT_EQ(cu.radii.front(), g.nodes[static_cast<std::size_t>(ch.nodes[1])].radius);
            EXPECT_GE(cu.phase, 0.0f);
            EXPECT_LT(cu.phase, 1.0f);
        }
    }
}

TEST(BranchGeometry, MeshesOfEveryLodHaveNoNaNAndUnitNormals)
{
    const TreeGeometry geo = build_tree_geometry(binary_test_tree(), default_branches(), default_leaves(), 3);
    ASSERT_EQ(geo.lods.size(), 3u);
    for (const TreeLod& lod : geo.lods) {
        for (const SurfaceGeometry* s : {&lod.branches, &lod.leaves}) {
            EXPECT_FALSE(s->empty());
            EXPECT_TRUE(indices_valid(*s));
            EXPECT_TRUE(all_finite(*s));
            EXPECT_LT(worst_normal_length_error(*s), 1e-5);
        }
    }
}

TEST(BranchGeometry, EveryTriangleHasNonZeroArea)
{
    const TreeGeometry geo = build_tree_geometry(binary_test_tree(), default_branches(), default_leaves(), 3);
    for (const TreeLod& lod : geo.lods) EXPECT_GT(smallest_triangle_area(lod.branches), 1e-12);
}

TEST(BranchGeometry, NoTwoVerticesShareAPositionSoJointsAndSeamsAreWelded)
{
    const TreeGeometry geo = build_tree_geometry(binary_test_tree(), default_branches(), default_leaves(), 3);
    for (const TreeLod& lod : geo.lods) EXPECT_EQ(coincident_vertex_pairs(lod.branches, 1e-7), 0u);
    // Also with odd and minimal radial resolution, and with pure chains of equal radii.
    for (int n : {3, 5, 8}) {
        BranchSettings b;
        b.radial_segments = n;
        b.lod_count = 1;
        EXPECT_EQ(coincident_vertex_pairs(build_tree_geometry(binary_test_tree(2), b, default_leaves(), 1).lods[0].branches), 0u)
            << n << " segments";
    }
}

TEST(BranchGeometry, TubesAreClosedAndTrianglesFaceOutwards)
{
    // One straight branch: base fan + tube + tip cone is a closed surface, each edge used
    // once in each direction.
    const auto g = two_node_tree(0.3f);
    const SurfaceGeometry s = build_branch_mesh(smooth_branch_curves(g, decompose_branch_chains(g), 0), BranchMeshOptions{});
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
    for (const auto& t : s.triangles)
        for (int e = 0; e < 3; ++e) ++directed[{t[static_cast<std::size_t>(e)], t[static_cast<std::size_t>((e + 1) % 3)]}];
    for (const auto& [edge, count] : directed) {
        EXPECT_EQ(count, 1);
        EXPECT_EQ(directed.count({edge.second, edge.first}), 1u) << "edge without its opposite: a hole";
    }
    // Face normals agree with the vertex normals (counter-clockwise seen from outside).
    const TreeGeometry geo = build_tree_geometry(binary_test_tree(), default_branches(), default_leaves(), 3);
    for (const TreeLod& lod : geo.lods) {
        std::size_t inward = 0;
        for (const auto& t : lod.branches.triangles) {
            const auto& P = lod.branches.positions;
            const glm::vec3 fn = glm::cross(P[t[1]] - P[t[0]], P[t[2]] - P[t[0]]);
            const glm::vec3 vn = lod.branches.normals[t[0]] + lod.branches.normals[t[1]] + lod.branches.normals[t[2]];
            if (glm::dot(fn, vn) <= 0.0f) ++inward;
        }
        EXPECT_EQ(inward, 0u);
    }
}

TEST(BranchGeometry, TriangleAndVertexCountsMatchTheResolutionFormula)
{
    // A straight 1 m branch: ⌈1 / 0.015⌉ + 1 = 68 rings of 8 vertices, a base centre and an apex;
    // 2·8·67 tube triangles, 8 in the base fan and 8 in the tip cone.
    const auto g = two_node_tree(1.0f);
    const TreeGeometry geo = build_tree_geometry(g, default_branches(), default_leaves(), 1);
    const SurfaceGeometry& s = geo.lods[0].branches;
    EXPECT_EQ(s.vertex_count(), 68u * 8u + 2u);
    EXPECT_EQ(s.triangle_count(), 2u * 8u * 67u + 8u + 8u);

    // The binary tree: per kept curve 2n(R − 1) + n, plus n for the root's base.
    const TreeGraph tree = binary_test_tree();
    const auto curves = smooth_branch_curves(tree, decompose_branch_chains(tree), 2);
    for (int n : {3, 8, 12}) {
        BranchMeshOptions o;
        o.radial_segments = n;
        std::vector<BranchRing> rings;
        const SurfaceGeometry m = build_branch_mesh(curves, o, &rings);
        std::size_t expected = static_cast<std::size_t>(n), vertices = 1;
        std::map<int, std::size_t> per_curve;
        for (const BranchRing& r : rings) ++per_curve[r.curve];
        EXPECT_EQ(per_curve.size(), curves.size());
        for (const auto& [c, count] : per_curve) {
            EXPECT_EQ(count, count_branch_rings(curves[static_cast<std::size_t>(c)], o));
            expected += 2 * static_cast<std::size_t>(n) * (count - 1) + static_cast<std::size_t>(n);
            vertices += count * static_cast<std::size_t>(n) + 1;
        }
        EXPECT_EQ(m.triangle_count(), expected) << n;
        EXPECT_EQ(m.vertex_count(), vertices) << n;
    }
}

TEST(BranchGeometry, RingVerticesLieAtTheRingRadiusAroundTheCurveAndRingsAreAtMostRingSpacingApart)
{
    const TreeGraph tree = binary_test_tree();
    for (int smoothing : {0, 2}) {
        const auto chains = decompose_branch_chains(tree);
        const auto curves = smooth_branch_curves(tree, chains, smoothing);
        BranchMeshOptions o;
        std::vector<BranchRing> rings;
        const SurfaceGeometry m = build_branch_mesh(curves, o, &rings);
        std::size_t at_nodes = 0;
        for (std::size_t i = 0; i < rings.size(); ++i) {
            const BranchRing& r = rings[i];
            const BranchCurve& cu = curves[static_cast<std::size_t>(r.curve)];
            EXPECT_LT(distance_to_polyline(r.centre, cu.points), 1e-5) << "ring centre on the curve";
            for (int j = 0; j < o.radial_segments; ++j) {
                const glm::vec3 d = m.positions[r.first_vertex + static_cast<std::uint32_t>(j)] - r.centre;
                EXPECT_NEAR(glm::length(d), r.radius, 1e-6 + 1e-4 * r.radius);
                EXPECT_NEAR(glm::dot(d, r.tangent), 0.0f, 1e-6 + 1e-4 * r.radius) << "ring normal to the curve";
            }
            // The ring's radius interpolates the radii of the curve points it lies between.
            const float lo = *std::min_element(cu.radii.begin(), cu.radii.end());
            const float hi = *std::max_element(cu.radii.begin(), cu.radii.end());
            EXPECT_GE(r.radius, lo * (1 - 1e-6f));
            EXPECT_LE(r.radius, hi * (1 + 1e-6f));
            for (std::size_t k = 0; k < cu.points.size(); ++k)
                if (glm::length(cu.points[k] - r.centre) < 1e-7f) {
                    EXPECT_FLOAT_EQ(r.radius, cu.radii[k]) << "a ring on a node has the node's radius";
                    ++at_nodes;
                }
            if (i + 1 < rings.size() && rings[i + 1].curve == r.curve) {
                EXPECT_LE(glm::length(rings[i + 1].centre - r.centre), o.ring_spacing_m * (1 + 1e-5));
            }
        }
        EXPECT_GT(at_nodes, curves.size() * 2);
    }
}

TEST(BranchGeometry, FramesDoNotTwistAlongABentBranch)
{
    // A planar S-shaped branch: parallel transport keeps every ring's first vertex direction
    // (relative to the centre) in the bending plane's normal... here: the plane z = 0 is the
    // bending plane, so the frame normal that starts along ±z stays along ±z.
    TreeGraph g = two_node_tree(0.1f);
    g.nodes.pop_back();
    for (int i = 1; i <= 20; ++i) {
        TreeNode n;
        n.position = {0.05f * std::sin(static_cast<float>(i) * 0.4f), 0.05f * static_cast<float>(i), 0.0f};
        n.parent = i - 1;
        n.radius = 0.01f;
        g.nodes.push_back(n);
    }
    g.nodes[0].radius = 0.01f;
    const auto curves = smooth_branch_curves(g, decompose_branch_chains(g), 0);
    std::vector<BranchRing> rings;
    const SurfaceGeometry m = build_branch_mesh(curves, BranchMeshOptions{}, &rings);
    // Find the ring vertex of ring 0 that points along z; the same index must point along z on
    // every ring.
    int zj = -1;
    for (int j = 0; j < 8; ++j)
        if (std::abs(glm::normalize(m.positions[rings[0].first_vertex + static_cast<std::uint32_t>(j)] - rings[0].centre).z) > 0.999f) zj = j;
    if (zj < 0) { // frame does not start along z: check the angle to z is the same on every ring
        const float z0 = glm::normalize(m.positions[rings[0].first_vertex] - rings[0].centre).z;
        for (const BranchRing& r : rings) EXPECT_NEAR(glm::normalize(m.positions[r.first_vertex] - r.centre).z, z0, 1e-4f);
    } else {
        for (const BranchRing& r : rings)
            EXPECT_GT(std::abs(glm::normalize(m.positions[r.first_vertex + static_cast<std::uint32_t>(zj)] - r.centre).z), 0.999f);
    }
}

TEST(BranchGeometry, BarkUvIsMirroredAroundAndUnstretchedAlong)
{
    const float r = 0.02f;
    const auto g = two_node_tree(0.5f, r);
    const auto curves = smooth_branch_curves(g, decompose_branch_chains(g), 0);
    std::vector<BranchRing> rings;
    BranchMeshOptions o;
    o.radial_segments = 8;
    const SurfaceGeometry m = build_branch_mesh(curves, o, &rings);
    for (std::size_t k = 0; k < rings.size(); ++k) {
        for (std::uint32_t j = 0; j < 8; ++j) {
            const glm::vec2 uv = m.uvs[rings[k].first_vertex + j];
            EXPECT_FLOAT_EQ(uv.x, 1.0f - std::abs(1.0f - 2.0f * static_cast<float>(j) / 8.0f));
            // v in half circumferences: one texture tile is as long as it is wide on the bark.
            EXPECT_NEAR(uv.y, rings[k].arc_m / (3.14159265f * r), 1e-4f);
        }
    }
    // u is continuous around: neighbours differ by 2/n, including across the welded seam.
    for (std::uint32_t j = 0; j < 8; ++j)
        EXPECT_NEAR(std::abs(m.uvs[rings[0].first_vertex + j].x - m.uvs[rings[0].first_vertex + (j + 1) % 8].x), 0.25f, 1e-6f);
}

TEST(BranchGeometry, LodBudgetsHoldAndCoarserLodsPruneTwigsButKeepTheTrunk)
{
    BranchSettings b;
    b.lod_count = 6;
    const TreeGraph tree = binary_test_tree();
    const TreeGeometry geo = build_tree_geometry(tree, b, default_leaves(), 3);
    ASSERT_EQ(geo.lods.size(), 6u);
    const double t0 = static_cast<double>(lod_triangles(geo.lods[0]));
    EXPECT_LE(static_cast<double>(lod_triangles(geo.lods[1])), 0.30 * t0);
    EXPECT_LE(static_cast<double>(lod_triangles(geo.lods[2])), 0.08 * t0);
    for (std::size_t k = 1; k < geo.lods.size(); ++k) {
        EXPECT_LT(lod_triangles(geo.lods[k]), lod_triangles(geo.lods[k - 1])) << "LOD" << k;
        EXPECT_LE(static_cast<double>(lod_triangles(geo.lods[k])), lod_triangle_budget(static_cast<int>(k)) * t0 + 1e-9);
        EXPECT_FALSE(geo.lods[k].branches.empty());
    }
    // The trunk's base and the top of the tree's main axis are still there at LOD2.
    const Bounds b0 = bounds_of(geo.lods[0].branches), b2 = bounds_of(geo.lods[2].branches);
    EXPECT_NEAR(b2.lo.y, b0.lo.y, 1e-6);
    EXPECT_GT(b2.extent().y, 0.7 * b0.extent().y);
    // LOD2 has dropped twigs: fewer tip cones than LOD0 would at its resolution.
    const auto curves = smooth_branch_curves(tree, decompose_branch_chains(tree), b.smoothing_iterations);
    const BranchMeshOptions o2 = branch_lod_options(b, 2);
    const SurfaceGeometry unpruned = build_branch_mesh(curves, o2);
    EXPECT_LT(geo.lods[2].branches.triangle_count(), unpruned.triangle_count());
}

TEST(BranchGeometry, LodOptionsGetCoarser)
{
    const BranchSettings b;
    const BranchMeshOptions o0 = branch_lod_options(b, 0), o1 = branch_lod_options(b, 1), o2 = branch_lod_options(b, 2);
    EXPECT_EQ(o0.radial_segments, b.radial_segments);
    EXPECT_DOUBLE_EQ(o0.ring_spacing_m, b.ring_spacing_m);
    EXPECT_EQ(o1.radial_segments, 6);
    EXPECT_EQ(o2.radial_segments, 4);
    EXPECT_EQ(branch_lod_options(b, 3).radial_segments, 3);
    EXPECT_GT(o1.ring_spacing_m, o0.ring_spacing_m);
    EXPECT_GT(o2.ring_spacing_m, o1.ring_spacing_m);
    EXPECT_LE(lod_triangle_budget(1), 0.30);
    EXPECT_LE(lod_triangle_budget(2), 0.08);
}

TEST(BranchGeometry, LodCountFollowsTheSettings)
{
    const TreeGraph tree = binary_test_tree();
    for (int n = 1; n <= 6; ++n) {
        BranchSettings b;
        b.lod_count = n;
        EXPECT_EQ(build_tree_geometry(tree, b, default_leaves(), 1).lods.size(), static_cast<std::size_t>(n));
    }
    BranchSettings bad;
    bad.lod_count = 0;
    EXPECT_THROW(build_tree_geometry(tree, bad, default_leaves(), 1), InvalidInput);
    bad.lod_count = 7;
    EXPECT_THROW(build_tree_geometry(tree, bad, default_leaves(), 1), InvalidInput);
}

TEST(BranchGeometry, ZeroLengthSegmentsAndCoincidentNodesGiveValidGeometry)
{
    const TreeGraph g = coincident_node_tree();
    TreeGeometry geo;
    ASSERT_NO_THROW(geo = build_tree_geometry(g, default_branches(), default_leaves(), 5));
    for (const TreeLod& lod : geo.lods) {
        for (const SurfaceGeometry* s : {&lod.branches, &lod.leaves}) {
            EXPECT_TRUE(indices_valid(*s));
            EXPECT_TRUE(all_finite(*s));
            EXPECT_LT(worst_normal_length_error(*s), 1e-5);
            if (!s->empty()) {
                EXPECT_GT(smallest_triangle_area(*s), 1e-12);
            }
        }
        EXPECT_EQ(coincident_vertex_pairs(lod.branches), 0u);
    }
    EXPECT_FALSE(geo.lods[0].branches.empty());

    // Merging: 9 nodes, two on top of their parents and two coincident siblings.
    std::vector<int> map;
    const TreeGraph merged = merge_coincident_nodes(g, 1e-5f, &map);
    EXPECT_EQ(merged.size(), 5u);
    EXPECT_EQ(map[1], 0);
    EXPECT_EQ(map[3], map[2]);
    EXPECT_EQ(map[5], map[4]);
    EXPECT_EQ(map[8], map[7]);
    for (std::size_t i = 1; i < merged.size(); ++i) EXPECT_LT(merged.nodes[i].parent, static_cast<int>(i));

    // A tree whose every node sits at the origin.
    TreeGraph flat;
    for (int i = 0; i < 4; ++i) {
        TreeNode n;
        n.parent = i - 1;
        n.radius = 0.01f;
        n.kind = i == 0 ? TreeNodeKind::Root : TreeNodeKind::Grown;
        flat.nodes.push_back(n);
    }
    ASSERT_NO_THROW(geo = build_tree_geometry(flat, default_branches(), default_leaves(), 5));
    for (const TreeLod& lod : geo.lods) {
        EXPECT_TRUE(lod.branches.empty());
        EXPECT_TRUE(all_finite(lod.leaves));
        EXPECT_EQ(coincident_vertex_pairs(lod.leaves), 0u);
    }
}

TEST(BranchGeometry, EmptyAndSingleNodeGraphsGiveEmptyGeometry)
{
    TreeGraph empty;
    TreeGeometry geo;
    ASSERT_NO_THROW(geo = build_tree_geometry(empty, default_branches(), default_leaves(), 1));
    ASSERT_EQ(geo.lods.size(), 3u);
    for (const TreeLod& lod : geo.lods) {
        EXPECT_TRUE(lod.branches.empty());
        EXPECT_TRUE(lod.leaves.empty());
    }
    TreeGraph single;
    single.nodes.push_back(TreeNode{});
    single.nodes[0].kind = TreeNodeKind::Root;
    ASSERT_NO_THROW(geo = build_tree_geometry(single, default_branches(), default_leaves(), 1));
    for (const TreeLod& lod : geo.lods) {
        EXPECT_TRUE(lod.branches.empty());
        EXPECT_TRUE(lod.leaves.empty());
    }
    EXPECT_GT(geo.leaf_texture.width, 0);
}

TEST(BranchGeometry, InvalidGraphsAndOptionsThrowInvalidInput)
{
    TreeGraph g = two_node_tree();
    g.nodes[1].parent = 1;
    EXPECT_THROW(build_tree_geometry(g, default_branches(), default_leaves(), 1), InvalidInput);
    g = two_node_tree();
    g.nodes[1].position.x = std::nanf("");
    EXPECT_THROW(build_tree_geometry(g, default_branches(), default_leaves(), 1), InvalidInput);
    g = two_node_tree();
    BranchSettings b;
    b.radial_segments = 2;
    EXPECT_THROW(build_tree_geometry(g, b, default_leaves(), 1), InvalidInput);
    b = BranchSettings{};
    b.ring_spacing_m = 0.0;
    EXPECT_THROW(build_tree_geometry(g, b, default_leaves(), 1), InvalidInput);
    LeafSettings l;
    l.shape = "fern";
    EXPECT_THROW(build_tree_geometry(g, default_branches(), l, 1), InvalidInput);
}

TEST(BranchGeometry, SameInputsGiveIdenticalBytes)
{
    const TreeGraph tree = binary_test_tree();
    const TreeGeometry a = build_tree_geometry(tree, default_branches(), default_leaves(), 11, "birch");
    const TreeGeometry b = build_tree_geometry(tree, default_branches(), default_leaves(), 11, "birch");
    ASSERT_EQ(a.lods.size(), b.lods.size());
    for (std::size_t k = 0; k < a.lods.size(); ++k) {
        EXPECT_TRUE(same_bytes(a.lods[k].branches, b.lods[k].branches));
        EXPECT_TRUE(same_bytes(a.lods[k].leaves, b.lods[k].leaves));
    }
    EXPECT_EQ(a.leaf_texture.pixels, b.leaf_texture.pixels);
    EXPECT_EQ(a.species, "birch");
}

TEST(BranchGeometry, ColoursComeFromTheSettings)
{
    BranchSettings b;
    b.bark_color[0] = 0.7;
    LeafSettings l;
    l.color[2] = 0.5;
    const TreeGeometry geo = build_tree_geometry(two_node_tree(), b, l, 1);
    EXPECT_FLOAT_EQ(geo.bark_color[0], 0.7f);
    EXPECT_FLOAT_EQ(geo.leaf_color[2], 0.5f);
}

TEST(BranchGeometry, PruneTwigsRemovesThinChainsWithTheirSubtreesAndKeepsTheMainAxis)
{
    const TreeGraph tree = binary_test_tree();
    const float threshold = 0.004f;
    std::vector<int> map;
    const TreeGraph pruned = prune_twigs(tree, threshold, &map);
    EXPECT_LT(pruned.size(), tree.size());
    EXPECT_GT(pruned.size(), 1u);
    for (std::size_t i = 1; i < pruned.size(); ++i) {
        EXPECT_GE(pruned.nodes[i].parent, 0);
        EXPECT_LT(pruned.nodes[i].parent, static_cast<int>(i));
    }
    // Every chain that remains starts at least as thick as the threshold (or is the main axis).
    const auto chains = decompose_branch_chains(pruned);
    for (std::size_t c = 1; c < chains.size(); ++c)
        EXPECT_GE(pruned.nodes[static_cast<std::size_t>(chains[c].nodes[1])].radius, threshold);
    // A removed node's children are removed too.
    for (std::size_t i = 1; i < tree.size(); ++i)
        if (map[static_cast<std::size_t>(tree.nodes[i].parent)] < 0) {
            EXPECT_LT(map[i], 0);
        }
    // Nothing pruned below the tip radius.
    EXPECT_EQ(prune_twigs(tree, 0.0f).size(), tree.size());
}

TEST(BranchGeometry, RebuildingIntoKeptStorageGivesTheSameBytesAndLeavesItUnchangedOnError)
{
    TreeShape deeper;
    deeper.depth = 9;
    const TreeGraph big = make_fixture_tree(deeper), small = binary_test_tree(2);
    TreeGeometry kept;
    // Small into empty storage (appended), big into small (grows), small into big (in place).
    build_tree_geometry_into(kept, small, default_branches(), default_leaves(), 4);
    build_tree_geometry_into(kept, big, default_branches(), default_leaves(), 4);
    const TreeGeometry fresh_big = build_tree_geometry(big, default_branches(), default_leaves(), 4);
    for (std::size_t k = 0; k < kept.lods.size(); ++k) EXPECT_TRUE(same_bytes(kept.lods[k].branches, fresh_big.lods[k].branches));
    build_tree_geometry_into(kept, small, default_branches(), default_leaves(), 4, "willow");
    const TreeGeometry fresh = build_tree_geometry(small, default_branches(), default_leaves(), 4, "willow");
    ASSERT_EQ(kept.lods.size(), fresh.lods.size());
    for (std::size_t k = 0; k < kept.lods.size(); ++k) {
        EXPECT_TRUE(same_bytes(kept.lods[k].branches, fresh.lods[k].branches));
        EXPECT_TRUE(same_bytes(kept.lods[k].leaves, fresh.lods[k].leaves));
    }
    EXPECT_EQ(kept.species, "willow");
    TreeGraph bad = small;
    bad.nodes[5].parent = 900;
    EXPECT_THROW(build_tree_geometry_into(kept, bad, default_branches(), default_leaves(), 4, "birch"), InvalidInput);
    EXPECT_EQ(kept.species, "willow");
    EXPECT_TRUE(same_bytes(kept.lods[0].branches, fresh.lods[0].branches));
}
