// Growth inside lobes (§5): the paper's rules (V_A, cluster split, stop rule, signed
// distance), the subtree library, and trees grown in generated lobes.
#include <cmath>
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
    std::vector<MeshRaycaster> rays;
    for (const GrowthLobe& l : lobes) rays.emplace_back(l.mesh);
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
    const ClusterSpan span = cluster_span(dirs);
    EXPECT_NEAR(span.horizontal_deg, 25.0, 1e-3);
    EXPECT_EQ(split_cluster(dirs, 30.0).size(), 1u);
}

TEST(Growth, ClusterDirectionWeightsNearAttractorsMore)
{
    const glm::vec3 node(0.0f);
    const glm::dvec3 v = cluster_direction(node, {glm::vec3(0.1f, 0, 0), glm::vec3(0, 0, 1.0f)});
    EXPECT_NEAR(glm::length(v), 1.0, 1e-9);
    EXPECT_GT(v.x, 5 * v.z); // weights 1/0.1 against 1/1
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

TEST_F(GrowInLobes, OneConnectedTreeRootedAtTheTrunkBaseReachingNinetyPercentOfAttractors)
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
    EXPECT_GE(r.lobes[0].coverage(), 0.9) << r.lobes[0].reached << " of " << r.lobes[0].attractors;
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

TEST_F(GrowInLobes, SmallerSplitAngleGivesDenserBranching)
{
    settings.split_angle_deg = 45;
    lobes[0].split_angle_deg = 45;
    const GrowthResult coarse = grow_tree(trunk, lobes, settings, default_subtree_library(), 1);
    lobes[0].split_angle_deg = 15;
    const GrowthResult fine = grow_tree(trunk, lobes, settings, default_subtree_library(), 1);
    EXPECT_GT(fine.lobes[0].subtrees, coarse.lobes[0].subtrees);
}

TEST_F(GrowInLobes, StopRuleDropsTheAttractorsOfNodesNearTheSurface)
{
    // A stop distance larger than the lobe: nothing grows, every attractor leaves as stopped.
    settings.stop_distance_m = 0.45;
    const GrowthResult r = grow_tree(trunk, lobes, settings, default_subtree_library(), 1);
    EXPECT_EQ(r.lobes[0].nodes, 0u);
    EXPECT_EQ(r.lobes[0].reached + r.lobes[0].stopped, r.lobes[0].attractors);
    EXPECT_GT(r.lobes[0].stopped, 0u);
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
