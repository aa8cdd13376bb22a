// Growth inside lobes (§5): the paper's rules (V_A, cluster split, stop rule, signed
// distance), the subtree library, and trees grown in generated lobes.
#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <set>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include "core/errors.h"
#include "growth/grow.h"
#include "growth/mesh_raycast.h"
#include "growth/radii.h"
#include "growth/skeleton.h"
#include "growth/species.h"
#include "growth/subtree_library.h"
#include "tests/support/shapes.h"
#include "tests/support/tree_checks.h"

namespace lobe {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

using test::ellipsoid;

glm::vec3 dir_from(double azimuth_deg, double elevation_deg)
{
    const double a = azimuth_deg * kDeg, e = elevation_deg * kDeg;
    return glm::vec3(glm::dvec3(std::cos(e) * std::cos(a), std::sin(e), std::cos(e) * std::sin(a)));
}

GrowthLobe growth_lobe(std::int64_t id, TriangleMesh mesh)
{
    GrowthLobe l;
    l.id = id;
    l.mesh = std::move(mesh);
    return l;
}

// Length of grown branch segments whose midpoint lies outside every lobe, over all grown length.
double outside_fraction(const TreeGraph& tree, const std::vector<GrowthLobe>& lobes)
{
    std::vector<TriangleMesh> meshes;
    for (const GrowthLobe& l : lobes) meshes.push_back(l.mesh);
    return test::outside_share(tree, meshes);
}

TEST(Growth, GrowthVectorIsTheFormulaToOneMicro)
{
    const glm::dvec3 vc = glm::normalize(glm::dvec3(0.3, 0.5, -0.8));
    const glm::dvec3 vd = glm::normalize(glm::dvec3(-0.1, 0.9, 0.2));
    const glm::dvec3 va = growth_vector(vc, vd, 0.8, -0.3);
    const glm::dvec3 expected(vc.x + 0.8 * vd.x, vc.y + 0.8 * vd.y + 0.3, vc.z + 0.8 * vd.z);
    EXPECT_NEAR(va.x, expected.x, 1e-6);
    EXPECT_NEAR(va.y, expected.y, 1e-6);
    EXPECT_NEAR(va.z, expected.z, 1e-6);
    // Gravity with β < 0 lifts the growth direction.
    EXPECT_GT(growth_vector(glm::dvec3(1, 0, 0), glm::dvec3(1, 0, 0), 0.8, -0.3).y, 0.29);
}

TEST(Growth, ClusterOf100By40DegreesWithSplitAngle30SplitsInto8Pieces)
{
    std::vector<glm::vec3> dirs;
    for (double a = 0; a <= 100.0 + 1e-9; a += 5.0)
        for (double e = -20; e <= 20.0 + 1e-9; e += 5.0) dirs.push_back(dir_from(a + 37.0, e));
    const ClusterSpan span = cluster_span(dirs);
    EXPECT_NEAR(span.horizontal_deg, 100.0, 1e-3);
    EXPECT_NEAR(span.vertical_deg, 40.0, 1e-3);
    int gh = 0, gv = 0;
    const auto pieces = split_cluster(dirs, 30.0, &gh, &gv);
    EXPECT_EQ(gh, 4);
    EXPECT_EQ(gv, 2);
    EXPECT_EQ(pieces.size(), 8u);
    std::size_t total = 0;
    for (const auto& p : pieces) total += p.size();
    EXPECT_EQ(total, dirs.size()); // every attractor in exactly one piece
    // Smaller t: denser branching.
    EXPECT_GT(split_cluster(dirs, 15.0).size(), 8u);
}

TEST(Growth, ClusterWithinTheSplitAngleStaysOnePieceAcrossTheAzimuthSeam)
{
    std::vector<glm::vec3> dirs;
    for (double a = 170; a <= 195; a += 5) dirs.push_back(dir_from(a, 10.0)); // crosses ±180°
    // Measured about the cluster's own mean direction there is no seam: 25° of azimuth at 10°
    // of elevation is 25° × cos 10° of arc.
    const ClusterSpan span = cluster_span(dirs);
    EXPECT_NEAR(span.horizontal_deg, 25.0 * std::cos(10.0 * kDeg), 0.05);
    EXPECT_EQ(split_cluster(dirs, 30.0).size(), 1u);
}

TEST(Growth, ClusterDirectionWeightsDistantAttractorsMoreAsSection52Says)
{
    const glm::vec3 node(0.0f);
    // d_i·V_i: the attractor 1 m away pulls ten times harder than the one 10 cm away.
    const glm::dvec3 v = cluster_direction(node, {glm::vec3(0.1f, 0, 0), glm::vec3(0, 0, 1.0f)});
    EXPECT_NEAR(glm::length(v), 1.0, 1e-9);
    EXPECT_NEAR(v.z / v.x, 10.0, 1e-4);
    // Σ d_i·V_i / Σ d_i, normalised, for three attractors at other distances.
    const std::vector<glm::vec3> a = {glm::vec3(0.3f, 0.1f, 0), glm::vec3(-0.05f, 0.4f, 0.2f), glm::vec3(0, 0, -0.7f)};
    glm::dvec3 expected(0.0);
    for (const glm::vec3& p : a) {
        const glm::dvec3 d(p);
        expected += glm::length(d) * (d / glm::length(d));
    }
    expected = glm::normalize(expected);
    const glm::dvec3 got = cluster_direction(node, a);
    EXPECT_NEAR(got.x, expected.x, 1e-6);
    EXPECT_NEAR(got.y, expected.y, 1e-6);
    EXPECT_NEAR(got.z, expected.z, 1e-6);
    // Degenerate clusters: one attractor, attractors cancelling out on a line: finite.
    EXPECT_NEAR(cluster_direction(node, {glm::vec3(0, 0, 0.2f)}).z, 1.0, 1e-9);
    const glm::dvec3 line = cluster_direction(node, {glm::vec3(-0.2f, 0, 0), glm::vec3(0.2f, 0, 0)});
    EXPECT_TRUE(std::isfinite(line.x) && std::isfinite(line.y) && std::isfinite(line.z));
}

// Directions filling a cone of half-angle `half_deg` about `axis` (rings of 72).
std::vector<glm::vec3> cone(const glm::dvec3& axis, double half_deg)
{
    const glm::dvec3 a = glm::normalize(axis);
    const glm::dvec3 ref = std::fabs(a.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 0, 1);
    const glm::dvec3 u = glm::normalize(glm::cross(a, ref)), w = glm::cross(a, u);
    std::vector<glm::vec3> out{glm::vec3(a)};
    for (double r = half_deg / 6; r <= half_deg + 1e-9; r += half_deg / 6)
        for (int k = 0; k < 72; ++k) {
            const double phi = k * 5.0 * kDeg;
            out.emplace_back(std::cos(r * kDeg) * a + std::sin(r * kDeg) * (std::cos(phi) * u + std::sin(phi) * w));
        }
    return out;
}

TEST(Growth, ConeSplitsIntoTheSamePiecesPointingUpSidewaysOrDown)
{
    // No pole: spans are measured about the cluster's mean direction (§5.2, Fig. 7c).
    for (const glm::dvec3 axis : {glm::dvec3(0, 1, 0), glm::dvec3(1, 0, 0), glm::dvec3(0, 0, -1), glm::dvec3(0, -1, 0),
                                  glm::dvec3(0.3, 0.9, -0.2), glm::dvec3(-0.5, -0.5, 0.7)}) {
        // A 20° cone (10° half-angle): one piece with t = 30°.
        const ClusterSpan narrow = cluster_span(cone(axis, 10.0));
        EXPECT_NEAR(narrow.horizontal_deg, 20.0, 0.5) << axis.x << " " << axis.y << " " << axis.z;
        EXPECT_NEAR(narrow.vertical_deg, 20.0, 0.5);
        EXPECT_EQ(split_cluster(cone(axis, 10.0), 30.0).size(), 1u);
        // A 50° cone: 2 × 2 pieces of about the same size, whichever way it points.
        int gh = 0, gv = 0;
        const std::vector<glm::vec3> wide = cone(axis, 25.0);
        const auto pieces = split_cluster(wide, 30.0, &gh, &gv);
        EXPECT_EQ(gh, 2);
        EXPECT_EQ(gv, 2);
        ASSERT_EQ(pieces.size(), 4u);
        for (const auto& p : pieces) {
            EXPECT_GT(p.size(), wide.size() / 6);
            EXPECT_LT(p.size(), wide.size() / 3);
        }
    }
}

TEST(Growth, SignedDistanceAlongIsPositiveInsideAndEnteringNegativeWhenMissing)
{
    const TriangleMesh sphere = ellipsoid(glm::dvec3(0, 1, 0), glm::dvec3(0.2), 4);
    const MeshRaycaster ray(sphere);
    // Inside: distance to where the ray leaves (the radius from the centre).
    EXPECT_NEAR(ray.signed_distance_along(glm::vec3(0, 1, 0), glm::vec3(1, 0, 0)), 0.2, 0.002);
    EXPECT_TRUE(ray.inside(glm::vec3(0, 1, 0)));
    // Below the lobe, pointing up: it enters and keeps growing through it (to the far side).
    EXPECT_NEAR(ray.signed_distance_along(glm::vec3(0, 0.5f, 0), glm::vec3(0, 1, 0)), 0.5 + 0.2, 0.002);
    EXPECT_FALSE(ray.inside(glm::vec3(0, 0.5f, 0)));
    // Below the lobe, pointing away: negative, minus the distance to the lobe.
    const float away = ray.signed_distance_along(glm::vec3(0, 0.5f, 0), glm::vec3(0, -1, 0));
    EXPECT_LT(away, 0.0f);
    EXPECT_NEAR(away, -0.3, 0.01);
}

TEST(Growth, ShippedSubtreesAreUnitLengthAndParentsPrecedeChildren)
{
    const SubtreeLibrary& lib = default_subtree_library();
    ASSERT_GE(lib.subtrees.size(), 5u);
    std::set<std::string> names;
    for (const Subtree& s : lib.subtrees) {
        names.insert(s.name);
        float extent = 0.0f;
        for (const glm::vec3& v : s.nodes) extent = std::max(extent, glm::length(v));
        EXPECT_NEAR(extent, 1.0f, 1e-6f) << s.name;
        EXPECT_EQ(s.parents[0], -1);
        for (std::size_t i = 1; i < s.parents.size(); ++i) EXPECT_LT(s.parents[i], static_cast<int>(i));
    }
    EXPECT_EQ(names.size(), lib.subtrees.size());
}

TEST(Growth, SubtreeLibraryRefusesMalformedFiles)
{
    EXPECT_THROW(parse_subtree_library("{", "x.json"), InvalidInput);
    EXPECT_THROW(parse_subtree_library(R"({"format":7,"version":1,"subtrees":[]})", "x"), InvalidInput);
    EXPECT_THROW(parse_subtree_library(R"({"format":{"a":1},"version":1,"subtrees":[]})", "x"), InvalidInput);
    EXPECT_THROW(parse_subtree_library("[1,2]", "x"), InvalidInput);
    EXPECT_THROW(parse_subtree_library(R"({"format":"lobesketch-subtrees","version":2,"subtrees":[]})", "x"),
                 InvalidInput);
    EXPECT_THROW(parse_subtree_library(
                     R"({"format":"lobesketch-subtrees","version":1,"subtrees":[{"name":"a","nodes":[[0,0,0],[0,1,0]],"parents":[-1,5]}]})",
                     "x"),
                 InvalidInput);
    EXPECT_THROW(parse_subtree_library(
                     R"({"format":"lobesketch-subtrees","version":1,"subtrees":[{"name":"a","nodes":[[0,0,0],[0,0,0]],"parents":[-1,0]}]})",
                     "x"),
                 InvalidInput);
    try {
        parse_subtree_library(R"({"format":"lobesketch-subtrees","version":1,"subtrees":[{"name":"a","nodes":[[0,0,0],[0,1,0]],"parents":[-1,0]},{"name":"a","nodes":[[0,0,0],[0,1,0]],"parents":[-1,0]}]})",
                              "lib.json");
        FAIL();
    } catch (const InvalidInput& e) {
        EXPECT_NE(std::string(e.what()).find("duplicate name"), std::string::npos);
    }
}

TEST(Growth, SkeletonMainBranchIsTheStrokeWithTheLowestPointRootedAtItsLowerEnd)
{
    // A side branch drawn first, from its tip inwards; the trunk drawn top-down.
    const std::vector<std::vector<glm::vec3>> strokes = {
        {{0.3f, 1.3f, 0}, {0.15f, 1.2f, 0}, {0.02f, 1.1f, 0}},
        {{0, 1.4f, 0}, {0, 1.2f, 0}, {0, 1.0f, 0}, {0, 0.8f, 0}},
    };
    const Skeleton s = build_skeleton(strokes, {});
    ASSERT_FALSE(s.graph.empty());
    EXPECT_TRUE(s.from_strokes);
    EXPECT_EQ(s.graph.nodes[0].kind, TreeNodeKind::Root);
    EXPECT_NEAR(s.graph.nodes[0].position.y, 0.8f, 1e-6f);
    for (std::size_t i = 1; i < s.graph.nodes.size(); ++i) {
        EXPECT_GE(s.graph.nodes[i].parent, 0);
        EXPECT_LT(s.graph.nodes[i].parent, static_cast<int>(i));
        EXPECT_GE(s.graph.nodes[i].position.y, s.graph.nodes[0].position.y);
    }
    // The side branch joins near (0, 1.1): its first node's parent is a trunk node close by.
    bool joined = false;
    for (const TreeNode& n : s.graph.nodes)
        if (glm::distance(n.position, glm::vec3(0.02f, 1.1f, 0)) < 1e-4f)
            joined = glm::distance(s.graph.nodes[static_cast<std::size_t>(n.parent)].position, glm::vec3(0, 1.1f, 0)) < 0.03f;
    EXPECT_TRUE(joined);
}

TEST(Growth, DefaultTrunkRisesFromTheGroundBelowTheLobesAndReachesIntoEach)
{
    const std::vector<TriangleMesh> lobes = {ellipsoid({-0.25, 1.4, 0}, {0.15, 0.12, 0.15}),
                                             ellipsoid({0.25, 1.45, 0.05}, {0.14, 0.13, 0.14})};
    const Skeleton s = build_skeleton({}, lobes);
    ASSERT_FALSE(s.graph.empty());
    EXPECT_FALSE(s.from_strokes);
    const glm::vec3 root = s.graph.nodes[0].position;
    EXPECT_LT(root.y, 1.4f - 0.12f); // below the lowest lobe
    EXPECT_NEAR(root.x, 0.0f, 0.05f); // under the middle of the two
    for (const TriangleMesh& l : lobes) {
        const MeshRaycaster r(l);
        bool reached = false;
        for (const TreeNode& n : s.graph.nodes) reached = reached || r.inside(n.position);
        EXPECT_TRUE(reached);
    }
}

TEST(Growth, LobeThatNoTrunkStrokeReachesGetsALimbAndAMessage)
{
    const std::vector<std::vector<glm::vec3>> strokes = {{{0, 0.9f, 0}, {0, 1.1f, 0}, {0, 1.3f, 0}}};
    const std::vector<TriangleMesh> lobes = {ellipsoid({0.0, 1.45, 0}, {0.15, 0.15, 0.15}),
                                             ellipsoid({0.8, 1.2, 0.0}, {0.12, 0.12, 0.12})};
    const Skeleton s = build_skeleton(strokes, lobes);
    ASSERT_EQ(s.messages.size(), 1u);
    EXPECT_NE(s.messages[0].find("lobe 2"), std::string::npos);
    int owned = 0;
    for (int o : s.owner) owned += o == 1;
    EXPECT_GT(owned, 10);
}

class GrowInLobes : public ::testing::Test {
protected:
    std::vector<GrowthLobe> lobes{growth_lobe(7, ellipsoid({0.0, 1.4, 0.0}, {0.17, 0.14, 0.16}))};
    std::vector<std::vector<glm::vec3>> trunk{{{0, 1.0f, 0}, {0.003f, 1.1f, -0.002f}, {-0.002f, 1.2f, 0.001f}, {0, 1.3f, 0}}};
    GrowthSettings settings;
};

TEST_F(GrowInLobes, OneConnectedTreeRootedAtTheTrunkBaseWithTipsAtTheSurface)
{
    const GrowthResult r = grow_tree(trunk, lobes, settings, default_subtree_library(), 1);
    ASSERT_GT(r.tree.size(), r.skeleton_nodes + 100);
    EXPECT_EQ(r.tree.nodes[0].kind, TreeNodeKind::Root);
    EXPECT_NEAR(r.tree.nodes[0].position.y, 1.0f, 1e-6f);
    for (std::size_t i = 1; i < r.tree.size(); ++i) {
        const TreeNode& n = r.tree.nodes[i];
        ASSERT_GE(n.parent, 0);
        ASSERT_LT(n.parent, static_cast<int>(i));
        ASSERT_TRUE(std::isfinite(n.position.x) && std::isfinite(n.position.y) && std::isfinite(n.position.z));
        if (n.kind == TreeNodeKind::Grown) {
            EXPECT_GE(n.subtree_id, 0); // every grown node records its library subtree
            EXPECT_LT(n.subtree_id, static_cast<int>(default_subtree_library().subtrees.size()));
            EXPECT_EQ(n.lobe, 0);
        }
    }
    ASSERT_EQ(r.lobes.size(), 1u);
    // Tips reach the surface: a branch tip within 4 cm of 90 % of the lobe's vertices.
    EXPECT_GE(test::tip_reach_share(r.tree, {lobes[0].mesh}), 0.9);
    EXPECT_LE(outside_fraction(r.tree, lobes), 0.02);
    EXPECT_FALSE(r.lobes[0].iteration_cap);
    EXPECT_FALSE(r.lobes[0].node_cap);
}

TEST_F(GrowInLobes, SameSeedSameTreeAndAnotherSeedAnotherTree)
{
    const GrowthResult a = grow_tree(trunk, lobes, settings, default_subtree_library(), 5);
    const GrowthResult b = grow_tree(trunk, lobes, settings, default_subtree_library(), 5);
    const GrowthResult c = grow_tree(trunk, lobes, settings, default_subtree_library(), 6);
    ASSERT_EQ(a.tree.size(), b.tree.size());
    for (std::size_t i = 0; i < a.tree.size(); ++i) {
        ASSERT_EQ(a.tree.nodes[i].position, b.tree.nodes[i].position);
        ASSERT_EQ(a.tree.nodes[i].parent, b.tree.nodes[i].parent);
    }
    bool differs = a.tree.size() != c.tree.size();
    for (std::size_t i = 0; !differs && i < a.tree.size(); ++i) differs = a.tree.nodes[i].position != c.tree.nodes[i].position;
    EXPECT_TRUE(differs);
}

TEST_F(GrowInLobes, FirstIterationPiecesSpanAtMostTheSplitAngleAndSmallerAnglesMakeMore)
{
    // The first iteration's clusters depend only on the skeleton: the same for every t.
    auto pieces_of = [&](double t, std::size_t* count) {
        lobes[0].split_angle_deg = t;
        const GrowthResult r = grow_tree(trunk, lobes, settings, default_subtree_library(), 1);
        // Every attractor not reached before the first iteration is in one piece.
        EXPECT_LE(r.first_clusters.size(), lobes[0].mesh.positions.size());
        EXPECT_GE(r.first_clusters.size(), lobes[0].mesh.positions.size() * 98 / 100);
        std::map<int, std::vector<glm::vec3>> by_piece;
        std::map<int, int> node_of;
        for (const ClusteredAttractor& a : r.first_clusters) {
            const glm::vec3 d = a.position - r.tree.nodes[static_cast<std::size_t>(a.node)].position;
            by_piece[a.piece].push_back(glm::normalize(d));
            node_of[a.piece] = a.node;
        }
        double widest = 0.0;
        for (const auto& [piece, dirs] : by_piece) {
            const ClusterSpan span = cluster_span(dirs);
            widest = std::max({widest, span.horizontal_deg, span.vertical_deg});
        }
        *count = by_piece.size();
        return widest;
    };
    std::size_t coarse = 0, fine = 0;
    const double widest_coarse = pieces_of(45.0, &coarse), widest_fine = pieces_of(15.0, &fine);
    // Each piece spans about t at most (measured in its own frame, so a little more at most).
    EXPECT_LE(widest_coarse, 1.3 * 45.0);
    EXPECT_LE(widest_fine, 1.3 * 15.0);
    // A third of the angle: many more pieces (⌈θ/t⌉² per large cluster).
    EXPECT_GE(fine, 4 * coarse) << coarse << " pieces at 45°, " << fine << " at 15°";
}

TEST_F(GrowInLobes, TheStopRuleNotAttractorRemovalDecidesWhereGrowthEnds)
{
    const GrowthResult r = grow_tree(trunk, lobes, settings, default_subtree_library(), 1);
    const LobeGrowthStats& st = r.lobes[0];
    EXPECT_EQ(st.reached + st.stopped + st.left, st.attractors);
    EXPECT_GE(st.stop_share(), 0.8) << st.stopped << " stopped, " << st.reached << " reached of " << st.attractors;
    // Shrinking the kill distance to 2 mm leaves the tree nearly as it was.
    GrowthSettings tiny_kill = settings;
    tiny_kill.kill_distance_m = 0.002;
    const GrowthResult k = grow_tree(trunk, lobes, tiny_kill, default_subtree_library(), 1);
    EXPECT_NEAR(static_cast<double>(k.tree.size()), static_cast<double>(r.tree.size()), 0.15 * static_cast<double>(r.tree.size()));
    // A larger stop distance ends growth farther from the surface, with fewer nodes.
    auto tip_gap = [&](const GrowthResult& g) { // median distance from a grown tip to the nearest lobe vertex
        const auto children = tree_children(g.tree);
        std::vector<double> gaps;
        for (std::size_t i = g.skeleton_nodes; i < g.tree.size(); ++i) {
            if (!children[i].empty()) continue;
            double best = 1e9;
            for (const glm::vec3& v : lobes[0].mesh.positions) best = std::min(best, static_cast<double>(glm::distance(v, g.tree.nodes[i].position)));
            gaps.push_back(best);
        }
        std::sort(gaps.begin(), gaps.end());
        return gaps.empty() ? 0.0 : gaps[gaps.size() / 2];
    };
    GrowthSettings far = settings;
    far.stop_distance_m = 0.06;
    const GrowthResult f = grow_tree(trunk, lobes, far, default_subtree_library(), 1);
    EXPECT_LT(f.tree.size(), r.tree.size());
    EXPECT_GT(tip_gap(f), tip_gap(r) + 0.01);
    EXPECT_LT(tip_gap(r), settings.stop_distance_m + 0.02); // tips end near the surface
}

TEST_F(GrowInLobes, SubtreeLengthIsProportionalToTheDistanceToTheSurface)
{
    // A ball centred on the trunk's top node: every direction from it meets the surface at
    // the radius, so the first subtrees it grows reach growth_ratio × radius from it.
    const glm::vec3 top(0, 1.3f, 0);
    lobes[0].mesh = ellipsoid({0.0, 1.3, 0.0}, glm::dvec3(0.2), 4);
    const GrowthResult r = grow_tree(trunk, lobes, settings, default_subtree_library(), 1);
    std::size_t top_index = 0;
    for (std::size_t i = 0; i < r.skeleton_nodes; ++i)
        if (glm::distance(r.tree.nodes[i].position, top) < 1e-4f) top_index = i;
    ASSERT_GT(top_index, 0u);
    // Each subtree the top node grew: its first segment is the library subtree's first
    // segment (the root has one child in every shipped subtree) scaled by the subtree's length.
    const SubtreeLibrary& lib = default_subtree_library();
    std::size_t measured = 0;
    for (std::size_t i = r.skeleton_nodes; i < r.tree.size(); ++i) {
        const TreeNode& n = r.tree.nodes[i];
        if (n.parent != static_cast<int>(top_index)) continue;
        const Subtree& st = lib.subtrees[static_cast<std::size_t>(n.subtree_id)];
        ASSERT_EQ(st.parents[1], 0);
        const double length = glm::distance(n.position, top) / glm::length(st.nodes[1]);
        EXPECT_NEAR(length, settings.growth_ratio * 0.2, 0.006) << st.name;
        ++measured;
    }
    EXPECT_GE(measured, 4u);
}

TEST_F(GrowInLobes, CapsStopGrowthWithAMessage)
{
    settings.max_nodes = 100;
    const GrowthResult r = grow_tree(trunk, lobes, settings, default_subtree_library(), 1);
    EXPECT_TRUE(r.lobes[0].node_cap);
    EXPECT_LE(r.lobes[0].nodes, 100u + kMaxSubtreeNodes);
    bool said = false;
    for (const std::string& m : r.messages) said = said || m.find("node cap") != std::string::npos;
    EXPECT_TRUE(said);
    settings.max_nodes = 500000;
    settings.max_iterations = 2;
    const GrowthResult q = grow_tree(trunk, lobes, settings, default_subtree_library(), 1);
    EXPECT_TRUE(q.lobes[0].iteration_cap);
}

TEST_F(GrowInLobes, PipeRadiiNeverIncreaseFromRootToTip)
{
    GrowthResult r = grow_tree(trunk, lobes, settings, default_subtree_library(), 1);
    assign_pipe_radii(r.tree, 2.0, 0.0012);
    const auto children = tree_children(r.tree);
    for (std::size_t i = 1; i < r.tree.size(); ++i) {
        const TreeNode& n = r.tree.nodes[i];
        EXPECT_LE(n.radius, r.tree.nodes[static_cast<std::size_t>(n.parent)].radius);
        if (children[i].empty()) {
            EXPECT_FLOAT_EQ(n.radius, 0.0012f);
        }
    }
    // r_parent² = Σ r_child² at a fork.
    for (std::size_t i = 0; i < r.tree.size(); ++i)
        if (children[i].size() >= 2) {
            double sum = 0.0;
            for (int c : children[i]) sum += std::pow(r.tree.nodes[static_cast<std::size_t>(c)].radius, 2.0);
            EXPECT_NEAR(std::pow(r.tree.nodes[i].radius, 2.0), sum, 1e-6 * sum);
            break;
        }
    EXPECT_GT(r.tree.nodes[0].radius, 0.01f);
}

TEST_F(GrowInLobes, LeaderRadiiTaperWithoutStepsAlongTheTrunkIntoTheLobe)
{
    GrowthResult r = grow_tree(trunk, lobes, settings, default_subtree_library(), 1);
    EXPECT_TRUE(r.leader_radii);
    assign_leader_radii(r.tree, 2.0, 0.0012);
    EXPECT_TRUE(test::radii_non_increasing(r.tree));
    EXPECT_GE(test::leader_share(r.tree), 0.98);
    const auto children = tree_children(r.tree);
    for (std::size_t i = 0; i < r.tree.size(); ++i)
        if (children[i].empty()) {
            EXPECT_FLOAT_EQ(r.tree.nodes[i].radius, 0.0012f);
        }
    // Along the sketched trunk the radius falls by at most a few percent per node (2 cm), and
    // the thickest subtree it grows into starts at the trunk's radius less its taper.
    for (std::size_t i = 1; i < r.skeleton_nodes; ++i) {
        const float parent = r.tree.nodes[static_cast<std::size_t>(r.tree.nodes[i].parent)].radius;
        EXPECT_GE(r.tree.nodes[i].radius, 0.9f * parent) << i;
    }
    const std::size_t last = r.skeleton_nodes - 1;
    float thickest = 0.0f;
    for (int c : children[last]) thickest = std::max(thickest, r.tree.nodes[static_cast<std::size_t>(c)].radius);
    EXPECT_GE(thickest, 0.7f * r.tree.nodes[last].radius);
}

TEST(Growth, DefaultTrunkTapersWithoutSteps)
{
    const std::vector<GrowthLobe> lobes = {growth_lobe(1, ellipsoid({-0.25, 1.4, 0}, {0.15, 0.12, 0.15})),
                                           growth_lobe(2, ellipsoid({0.25, 1.45, 0.05}, {0.14, 0.13, 0.14}))};
    GrowthResult r = grow_tree({}, lobes, GrowthSettings{}, default_subtree_library(), 1);
    assign_leader_radii(r.tree, 2.0, 0.0012);
    // Along the trunk's axis (from the root, always the thickest child, through the fork and
    // into a lobe) the radius falls at a steady rate per metre: no step where the trunk forks
    // or enters a lobe (the plain pipe model kept it constant, then dropped it at once).
    const auto children = tree_children(r.tree);
    std::vector<double> slopes;
    for (std::size_t i = 0; i < r.skeleton_nodes;) {
        std::size_t next = i;
        float thickest = -1.0f;
        for (int c : children[i])
            if (static_cast<std::size_t>(c) < r.skeleton_nodes && r.tree.nodes[static_cast<std::size_t>(c)].radius > thickest) {
                thickest = r.tree.nodes[static_cast<std::size_t>(c)].radius;
                next = static_cast<std::size_t>(c);
            }
        if (next == i) break;
        const double len = glm::distance(r.tree.nodes[i].position, r.tree.nodes[next].position);
        slopes.push_back((r.tree.nodes[i].radius - r.tree.nodes[next].radius) / len);
        i = next;
    }
    ASSERT_GT(slopes.size(), 10u);
    const auto [lo, hi] = std::minmax_element(slopes.begin(), slopes.end());
    EXPECT_GT(*lo, 0.0);
    EXPECT_LE(*hi, 1.5 * *lo) << "taper per metre from " << *lo << " to " << *hi;
    EXPECT_TRUE(test::radii_non_increasing(r.tree));
}

TEST(Growth, EditingOneLobeLeavesTheBranchesOfTheOthersBitIdentical)
{
    const std::vector<std::vector<glm::vec3>> trunk = {{{0, 0.9f, 0}, {0, 1.1f, 0}, {0, 1.25f, 0}},
                                                       {{0, 1.2f, 0}, {-0.2f, 1.35f, 0}},
                                                       {{0, 1.2f, 0}, {0.25f, 1.4f, 0}}};
    std::vector<GrowthLobe> lobes = {growth_lobe(1, ellipsoid({-0.25, 1.4, 0}, {0.15, 0.12, 0.15})),
                                     growth_lobe(2, ellipsoid({0.25, 1.45, 0.0}, {0.14, 0.13, 0.14}))};
    const GrowthSettings settings;
    const GrowthResult before = grow_tree(trunk, lobes, settings, default_subtree_library(), 3);
    lobes[1].mesh = ellipsoid({0.27, 1.47, 0.02}, {0.16, 0.15, 0.15}); // the second lobe moved and grew
    const GrowthResult after = grow_tree(trunk, lobes, settings, default_subtree_library(), 3);
    auto of_lobe = [](const GrowthResult& r, int lobe) {
        std::vector<TreeNode> out;
        for (const TreeNode& n : r.tree.nodes)
            if (n.lobe == lobe) out.push_back(n);
        return out;
    };
    const auto a = of_lobe(before, 0), b = of_lobe(after, 0);
    ASSERT_GT(a.size(), 50u);
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
        ASSERT_EQ(a[i].position, b[i].position);
        ASSERT_EQ(a[i].subtree_id, b[i].subtree_id);
    }
    EXPECT_NE(of_lobe(before, 1).size() == of_lobe(after, 1).size() &&
                  of_lobe(before, 1).back().position == of_lobe(after, 1).back().position,
              true);
}

TEST(Growth, BadLobesAndStrokesGiveATreeOrNothingButNeverNaN)
{
    const GrowthSettings settings;
    const SubtreeLibrary& lib = default_subtree_library();
    // No lobes, no strokes.
    EXPECT_TRUE(grow_tree({}, {}, settings, lib, 1).tree.empty());
    // An empty lobe mesh and a NaN stroke point.
    const float nan = std::numeric_limits<float>::quiet_NaN();
    GrowthResult r = grow_tree({{{0, 1, 0}, {nan, 1.1f, 0}, {0, 1.2f, 0}}}, {growth_lobe(1, TriangleMesh{})}, settings, lib, 1);
    for (const TreeNode& n : r.tree.nodes) EXPECT_TRUE(std::isfinite(n.position.y));
    // A tiny lobe (2 cm), an enormous one (20 m across) and one far from the trunk.
    TriangleMesh huge = ellipsoid({0, 1.2, 0}, glm::dvec3(1.0), 3);
    for (glm::vec3& p : huge.positions) p *= 10.0f;
    r = grow_tree({{{0, 1, 0}, {0, 1.3f, 0}}},
                  {growth_lobe(1, ellipsoid({0, 1.3, 0}, glm::dvec3(0.02), 2)), growth_lobe(2, huge),
                   growth_lobe(3, ellipsoid({5, 1, 5}, glm::dvec3(0.2), 3))},
                  settings, lib, 1);
    ASSERT_EQ(r.lobes.size(), 3u);
    EXPECT_GT(r.lobes[2].nodes, 0u); // the far lobe is reached through a limb
    assign_pipe_radii(r.tree);
    for (const TreeNode& n : r.tree.nodes) {
        ASSERT_TRUE(std::isfinite(n.position.x) && std::isfinite(n.position.y) && std::isfinite(n.position.z));
        ASSERT_TRUE(std::isfinite(n.radius));
    }
    EXPECT_LE(r.tree.size(), static_cast<std::size_t>(3 * settings.max_nodes + 20000));
}

TEST(Growth, TrunkStrokeCrossingTheSkeletonJoinsAtItsNearestPointAndGrowsBothWays)
{
    // §5.1: the side stroke passes 5 cm from the trunk in its middle; both its halves grow
    // from the joint there (joined by an end, one half would run through the other).
    const std::vector<std::vector<glm::vec3>> strokes = {
        {{0, 0.8f, 0}, {0, 1.0f, 0}, {0, 1.2f, 0}, {0, 1.4f, 0}},
        {{-0.3f, 1.2f, 0.05f}, {0.0f, 1.2f, 0.05f}, {0.35f, 1.2f, 0.05f}},
    };
    const Skeleton s = build_skeleton(strokes, {});
    auto nearest = [&](const glm::vec3& p) {
        std::size_t best = 0;
        for (std::size_t i = 0; i < s.graph.nodes.size(); ++i)
            if (glm::distance(s.graph.nodes[i].position, p) < glm::distance(s.graph.nodes[best].position, p)) best = i;
        return best;
    };
    const std::size_t left = nearest({-0.3f, 1.2f, 0.05f}), right = nearest({0.35f, 1.2f, 0.05f});
    auto ancestors = [&](std::size_t i) {
        std::set<std::size_t> up;
        for (int p = s.graph.nodes[i].parent; p >= 0; p = s.graph.nodes[static_cast<std::size_t>(p)].parent)
            up.insert(static_cast<std::size_t>(p));
        return up;
    };
    EXPECT_FALSE(ancestors(right).count(left));
    EXPECT_FALSE(ancestors(left).count(right));
    // Both reach the trunk through the joint at the trunk's node nearest the stroke.
    const std::size_t joint_trunk = nearest({0, 1.2f, 0});
    EXPECT_TRUE(ancestors(left).count(joint_trunk));
    EXPECT_TRUE(ancestors(right).count(joint_trunk));
    for (std::size_t i : {left, right})
        for (std::size_t a : ancestors(i)) EXPECT_GE(s.graph.nodes[a].position.y, 0.8f);
}

TEST(Growth, OverlappingLobesAreClusteredAsOneTree)
{
    // Attractors go to their nearest node of the whole tree: where two lobes overlap, nodes
    // grown for one take the other's attractors and grow into it.
    const std::vector<std::vector<glm::vec3>> trunk{{{-0.1f, 0.9f, 0}, {-0.1f, 1.1f, 0}, {-0.1f, 1.3f, 0}}};
    const std::vector<GrowthLobe> lobes = {growth_lobe(1, ellipsoid({-0.1, 1.4, 0}, {0.18, 0.14, 0.15})),
                                           growth_lobe(2, ellipsoid({0.12, 1.42, 0.0}, {0.18, 0.14, 0.15}))};
    const GrowthResult r = grow_tree(trunk, lobes, GrowthSettings{}, default_subtree_library(), 1);
    std::size_t crossed = 0;
    for (std::size_t i = r.skeleton_nodes; i < r.tree.size(); ++i) {
        const TreeNode& n = r.tree.nodes[i];
        const TreeNode& p = r.tree.nodes[static_cast<std::size_t>(n.parent)];
        if (n.lobe == 1 && p.kind == TreeNodeKind::Grown && p.lobe == 0) ++crossed;
    }
    EXPECT_GT(crossed, 0u);
    std::vector<TriangleMesh> meshes{lobes[0].mesh, lobes[1].mesh};
    EXPECT_GE(test::tip_reach_share(r.tree, meshes), 0.9);
}

TEST(Growth, DifferentTrunkStrokesChangeTheBranchingInTheSameLobe)
{
    // Fig. 11: one lobe, a straight trunk to its centre or a trunk bending in from the left:
    // the attractors cluster around other nodes, so the branching differs.
    const std::vector<GrowthLobe> lobes = {growth_lobe(1, ellipsoid({0.0, 1.4, 0.0}, {0.2, 0.15, 0.18}))};
    const std::vector<std::vector<glm::vec3>> straight{{{0, 0.8f, 0}, {0, 1.1f, 0}, {0, 1.4f, 0}}};
    const std::vector<std::vector<glm::vec3>> bent{{{0, 0.8f, 0}, {-0.1f, 1.1f, 0}, {-0.12f, 1.3f, 0}, {0.05f, 1.45f, 0}},
                                                   {{-0.1f, 1.1f, 0}, {0.1f, 1.3f, 0.05f}}};
    const GrowthResult a = grow_tree(straight, lobes, GrowthSettings{}, default_subtree_library(), 1);
    const GrowthResult b = grow_tree(bent, lobes, GrowthSettings{}, default_subtree_library(), 1);
    ASSERT_EQ(a.first_clusters.size(), b.first_clusters.size());
    std::size_t moved = 0;
    for (std::size_t i = 0; i < a.first_clusters.size(); ++i) {
        const glm::vec3 na = a.tree.nodes[static_cast<std::size_t>(a.first_clusters[i].node)].position;
        const glm::vec3 nb = b.tree.nodes[static_cast<std::size_t>(b.first_clusters[i].node)].position;
        if (glm::distance(na, nb) > 0.05f) ++moved;
    }
    EXPECT_GE(static_cast<double>(moved) / static_cast<double>(a.first_clusters.size()), 0.3);
    // Both fill the lobe.
    EXPECT_GE(test::tip_reach_share(a.tree, {lobes[0].mesh}), 0.9);
    EXPECT_GE(test::tip_reach_share(b.tree, {lobes[0].mesh}), 0.9);
}

TEST(Growth, UnreachableLobesFarStrokesAndDegenerateClustersGiveOneLineMessagesAndAFiniteTree)
{
    const SubtreeLibrary& lib = default_subtree_library();
    TriangleMesh line; // "a lobe" whose vertices lie on a line
    for (int i = 0; i < 20; ++i) line.positions.emplace_back(0.5f + 0.01f * static_cast<float>(i), 1.3f, 0.0f);
    for (int i = 0; i + 2 < 20; ++i) line.triangles.push_back({i, i + 1, i + 2});
    TriangleMesh point; // one attractor
    point.positions.emplace_back(-0.4f, 1.2f, 0.1f);
    const std::vector<GrowthLobe> lobes = {growth_lobe(1, ellipsoid({0.0, 1.4, 0.0}, {0.17, 0.14, 0.16})),
                                           growth_lobe(2, line), growth_lobe(3, point)};
    const std::vector<std::vector<glm::vec3>> trunk{{{0, 1.0f, 0}, {0, 1.3f, 0}}, {{3.0f, 0.5f, 3.0f}, {3.0f, 0.9f, 3.0f}}};
    GrowthResult r = grow_tree(trunk, lobes, GrowthSettings{}, lib, 1);
    ASSERT_EQ(r.lobes.size(), 3u);
    EXPECT_GT(r.lobes[0].nodes, 100u); // the good lobe grows
    bool far_said = false;
    for (const std::string& m : r.messages) {
        EXPECT_EQ(m.find('\n'), std::string::npos) << m;
        far_said = far_said || m.find("trunk stroke 2 is more than") != std::string::npos;
    }
    EXPECT_TRUE(far_said);
    assign_leader_radii(r.tree);
    for (const TreeNode& n : r.tree.nodes) {
        ASSERT_TRUE(std::isfinite(n.position.x) && std::isfinite(n.position.y) && std::isfinite(n.position.z));
        ASSERT_TRUE(std::isfinite(n.radius) && n.radius > 0.0f);
    }
    EXPECT_TRUE(test::radii_non_increasing(r.tree));
    // A lobe nothing can grow into says so.
    const std::vector<GrowthLobe> only_line = {growth_lobe(1, line)};
    const GrowthResult q = grow_tree({{{0, 1.0f, 0}, {0, 1.3f, 0}}}, only_line, GrowthSettings{}, lib, 1);
    bool said = false;
    for (const std::string& m : q.messages) said = said || m.find("lobe 1: no branch could grow into it") != std::string::npos;
    EXPECT_TRUE(said) << q.lobes[0].nodes << " nodes grew";
    EXPECT_EQ(q.lobes[0].nodes, 0u);
}

TEST(Species, ShippedPresetsParseAndVisiblyDiffer)
{
    const std::vector<std::string> names = species_names();
    ASSERT_GE(names.size(), 3u);
    std::set<std::string> shapes;
    std::set<double> leaf_lengths, bark;
    for (const std::string& n : names) {
        Settings s;
        apply_species(s, load_species(n));
        EXPECT_EQ(s.growth.species, n);
        shapes.insert(s.leaves.shape);
        leaf_lengths.insert(s.leaves.length_m);
        bark.insert(s.branches.bark_color[0]);
        EXPECT_NO_THROW(subtree_weights(default_subtree_library(), s.growth.subtree_weights));
    }
    EXPECT_GE(shapes.size(), 3u);
    EXPECT_GE(leaf_lengths.size(), 3u);
    EXPECT_GE(bark.size(), 3u);
}

TEST(Species, BadPresetsAreRefusedWithOneLineAndSettingsUnchanged)
{
    try {
        load_species("baobab");
        FAIL();
    } catch (const InvalidInput& e) {
        EXPECT_NE(std::string(e.what()).find("known: "), std::string::npos);
    }
    EXPECT_THROW(parse_species(R"({"format":"lobesketch-species","version":1,"name":"x","leaves":{"colour":[1,0,0]}})", "x.json"),
                 InvalidInput);
    EXPECT_THROW(parse_species(R"({"format":"lobesketch-species","version":1,"name":"x","growth":{"split_angle_deg":"wide"}})", "x.json"),
                 InvalidInput);
    EXPECT_THROW(parse_species(R"({"format":"lobesketch-species","version":1,"name":"x","growth":{"split_angle_deg":1}})", "x.json"),
                 InvalidInput);
    Settings s;
    SpeciesPreset bad;
    bad.name = "bad";
    bad.settings.values.leaves.per_node = 1000;
    bad.settings.mark("leaves.per_node");
    EXPECT_THROW(apply_species(s, bad), InvalidInput);
    EXPECT_EQ(s.leaves.per_node, LeafSettings{}.per_node);
    EXPECT_EQ(s.growth.species, "broadleaf");
}

} // namespace
} // namespace lobe
