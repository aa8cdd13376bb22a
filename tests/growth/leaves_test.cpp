// Leaf quads, their levels of detail and the procedural leaf textures (growth/leaves.h).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <map>

#include "core/errors.h"
#include "growth/branch_geometry.h"
#include "growth/leaf_lod.h"
#include "growth/leaves.h"
#include "tests/support/geometry_checks.h"
#include "tests/support/tree_fixtures.h"

using namespace lobe;
using namespace lobe::test;

namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

/// Quad q's four corners (base −, base +, tip +, tip −).
struct Quad {
    glm::dvec3 c[4];
    glm::dvec3 base_centre() const { return 0.5 * (c[0] + c[1]); }
    glm::dvec3 centre() const { return 0.25 * (c[0] + c[1] + c[2] + c[3]); }
    glm::dvec3 axis() const { return glm::normalize(0.5 * (c[2] + c[3]) - base_centre()); }
    double length() const { return glm::length(0.5 * (c[2] + c[3]) - base_centre()); }
    double width() const { return glm::length(c[1] - c[0]); }
};

Quad quad(const SurfaceGeometry& s, std::size_t q)
{
    Quad out;
    for (std::size_t k = 0; k < 4; ++k) out.c[k] = glm::dvec3(s.positions[4 * q + k]);
    return out;
}

std::size_t grown_tips(const TreeGraph& g)
{
    const auto children = tree_children(g);
    std::size_t n = 0;
    for (std::size_t i = 1; i < g.size(); ++i)
        if (children[i].empty() && g.nodes[i].kind == TreeNodeKind::Grown) ++n;
    return n;
}

/// Copy of `g` without the nodes for which drop(i) is true (they must be tips), with move(i)
/// added to the others' positions, and with a new tip child right after each node for which
/// sprout(i) is true (so every later node's index shifts).
template <class Drop, class Move, class Sprout>
TreeGraph edited(const TreeGraph& g, Drop drop, Move move, Sprout sprout)
{
    TreeGraph out;
    std::vector<int> map(g.size(), -1);
    for (std::size_t i = 0; i < g.size(); ++i) {
        if (drop(i)) continue;
        TreeNode n = g.nodes[i];
        n.position += move(i);
        n.parent = n.parent < 0 ? -1 : map[static_cast<std::size_t>(n.parent)];
        map[i] = static_cast<int>(out.nodes.size());
        out.nodes.push_back(n);
        if (sprout(i)) {
            TreeNode twig = n;
            twig.parent = map[i];
            twig.position += glm::vec3(0.03f, 0.02f, 0.0f);
            out.nodes.push_back(twig);
        }
    }
    return out;
}

/// The quads of one lobe, in node order.
std::vector<std::array<glm::vec3, 4>> lobe_quads(const TreeGraph& g, const SurfaceGeometry& s, const std::vector<int>& quad_nodes,
                                                 int lobe = 0)
{
    std::vector<std::array<glm::vec3, 4>> out;
    for (std::size_t q = 0; q < quad_nodes.size(); ++q)
        if (g.nodes[static_cast<std::size_t>(quad_nodes[q])].lobe == lobe)
            out.push_back({s.positions[4 * q], s.positions[4 * q + 1], s.positions[4 * q + 2], s.positions[4 * q + 3]});
    return out;
}

} // namespace

TEST(Leaves, CountIsTipsTimesPerNodeAtLod0AndTheyHangAtTheTips)
{
    const TreeGraph g = binary_test_tree();
    LeafSettings l;
    std::vector<int> nodes;
    const SurfaceGeometry s = build_leaf_quads(g, l, 1, {}, &nodes);
    EXPECT_EQ(grown_tips(g), 256u);
    EXPECT_EQ(leaf_tip_nodes(g).size(), 256u);
    EXPECT_EQ(s.triangle_count(), 2u * 256u * static_cast<std::size_t>(l.per_node));
    EXPECT_EQ(s.vertex_count(), 4u * 256u * static_cast<std::size_t>(l.per_node));
    ASSERT_EQ(nodes.size(), 256u * static_cast<std::size_t>(l.per_node));
    for (std::size_t q = 0; q < nodes.size(); ++q) {
        const Quad Q = quad(s, q);
        EXPECT_LT(glm::length(Q.base_centre() - glm::dvec3(g.nodes[static_cast<std::size_t>(nodes[q])].position)), 1e-6);
        EXPECT_NEAR(Q.length(), l.length_m, 1e-6);
        EXPECT_NEAR(Q.width(), l.width_m, 1e-6);
    }
    // Other per-node counts.
    for (int per : {0, 1, 7}) {
        l.per_node = per;
        EXPECT_EQ(build_leaf_quads(g, l, 1).triangle_count(), 2u * 256u * static_cast<std::size_t>(per));
    }
}

TEST(Leaves, LeavesDeviateFromTheBranchDirectionByAtMostDeviationDeg)
{
    const TreeGraph g = binary_test_tree();
    for (double dev : {0.0, 20.0, 35.0, 90.0}) {
        LeafSettings l;
        l.deviation_deg = dev;
        std::vector<int> nodes;
        const SurfaceGeometry s = build_leaf_quads(g, l, 9, {}, &nodes);
        double worst = 0.0;
        for (std::size_t q = 0; q < nodes.size(); ++q) {
            const TreeNode& tip = g.nodes[static_cast<std::size_t>(nodes[q])];
            const glm::dvec3 dir = glm::normalize(glm::dvec3(tip.position) - glm::dvec3(g.nodes[static_cast<std::size_t>(tip.parent)].position));
            worst = std::max(worst, std::acos(std::clamp(glm::dot(quad(s, q).axis(), dir), -1.0, 1.0)) / kDeg);
        }
        EXPECT_LE(worst, dev + 1e-3) << dev;
        if (dev > 0) {
            EXPECT_GT(worst, 0.5 * dev) << "the deviation is used";
        }
    }
}

TEST(Leaves, QuadsAreValidUnitNormalTexturedAndWithoutSharedPositions)
{
    const SurfaceGeometry s = build_leaf_quads(binary_test_tree(), LeafSettings{}, 4);
    EXPECT_TRUE(indices_valid(s));
    EXPECT_TRUE(all_finite(s));
    EXPECT_LT(worst_normal_length_error(s), 1e-5);
    EXPECT_GT(smallest_triangle_area(s), 1e-8);
    EXPECT_EQ(coincident_vertex_pairs(s), 0u);
    for (std::size_t q = 0; q * 4 < s.vertex_count(); ++q) {
        // uv spans the texture, v along the leaf (1 at the base, 0 at the tip).
        EXPECT_EQ(s.uvs[4 * q + 0], glm::vec2(0, 1));
        EXPECT_EQ(s.uvs[4 * q + 1], glm::vec2(1, 1));
        EXPECT_EQ(s.uvs[4 * q + 2], glm::vec2(1, 0));
        EXPECT_EQ(s.uvs[4 * q + 3], glm::vec2(0, 0));
        // The normal is the quad's face normal (counter-clockwise front).
        const auto& t = s.triangles[2 * q];
        const glm::vec3 fn = glm::normalize(glm::cross(s.positions[t[1]] - s.positions[t[0]], s.positions[t[2]] - s.positions[t[0]]));
        EXPECT_GT(glm::dot(fn, s.normals[4 * q]), 0.9999f);
    }
}

TEST(Leaves, SameSeedGivesIdenticalBytesAndAnotherSeedDifferentLeaves)
{
    const TreeGraph g = binary_test_tree();
    const SurfaceGeometry a = build_leaf_quads(g, LeafSettings{}, 42);
    const SurfaceGeometry b = build_leaf_quads(g, LeafSettings{}, 42);
    const SurfaceGeometry c = build_leaf_quads(g, LeafSettings{}, 43);
    EXPECT_TRUE(same_bytes(a, b));
    ASSERT_EQ(a.vertex_count(), c.vertex_count());
    std::size_t differing = 0;
    for (std::size_t i = 0; i < a.vertex_count(); i += 4)
        if (a.positions[i + 2] != c.positions[i + 2]) ++differing;
    EXPECT_GT(differing, a.vertex_count() / 4 * 9 / 10) << "almost every leaf changes with the seed";
}

TEST(Leaves, EditingTheNodesOfLobe1LeavesTheLeavesOfLobe0BitIdentical)
{
    const TreeGraph g = binary_test_tree();
    // Lobe nodes are interleaved in node order: removing lobe-1 nodes shifts lobe-0 indices.
    const auto children = tree_children(g);
    std::size_t dropped = 0, first_sprout = g.size();
    for (std::size_t i = 0; i < g.size() && first_sprout == g.size(); ++i)
        if (g.nodes[i].lobe == 1) first_sprout = i;
    const TreeGraph e = edited(
        g,
        [&](std::size_t i) {
            const bool drop = g.nodes[i].lobe == 1 && children[i].empty() && i % 3 == 0;
            dropped += drop;
            return drop;
        },
        [&](std::size_t i) { return g.nodes[i].lobe == 1 ? glm::vec3(0.01f, 0.0f, -0.02f) : glm::vec3(0.0f); },
        [&](std::size_t i) { return i == first_sprout; });
    ASSERT_GT(dropped, 10u);
    std::size_t shifted = 0; // lobe-0 nodes whose global index changes
    for (std::size_t i = first_sprout; i < g.size(); ++i) shifted += g.nodes[i].lobe == 0;
    ASSERT_GT(shifted, 700u);
    LeafSettings l;
    std::vector<int> qa, qb;
    const SurfaceGeometry a = build_leaf_quads(g, l, 5, {}, &qa);
    const SurfaceGeometry b = build_leaf_quads(e, l, 5, {}, &qb);
    const auto la = lobe_quads(g, a, qa), lb = lobe_quads(e, b, qb);
    ASSERT_EQ(la.size(), 128u * static_cast<std::size_t>(l.per_node));
    ASSERT_EQ(la.size(), lb.size());
    EXPECT_EQ(std::memcmp(la.data(), lb.data(), la.size() * sizeof(la[0])), 0);
    // The lobe-1 leaves did change.
    const auto ma = lobe_quads(g, a, qa, 1), mb = lobe_quads(e, b, qb, 1);
    ASSERT_EQ(ma.size() + static_cast<std::size_t>(l.per_node), mb.size()); // a dropped tip makes its parent a tip; one twig more
    EXPECT_NE(std::memcmp(ma.data(), mb.data(), ma.size() * sizeof(ma[0])), 0);
    // build_tree_geometry's LOD0 leaves are these quads on the atlas's single-leaf half.
    const TreeGeometry ga = build_tree_geometry(g, BranchSettings{}, l, 5), gb = build_tree_geometry(e, BranchSettings{}, l, 5);
    SurfaceGeometry a_atlas = a;
    use_single_leaf_half(a_atlas);
    EXPECT_TRUE(same_bytes(ga.lods[0].leaves, a_atlas));
    std::vector<int> n1a, n1b;
    const SurfaceGeometry a1 = build_leaf_quads(g, l, 5, {0.5}, &n1a), b1 = build_leaf_quads(e, l, 5, {0.5}, &n1b);
    const auto l1a = lobe_quads(g, a1, n1a), l1b = lobe_quads(e, b1, n1b);
    ASSERT_EQ(l1a.size(), l1b.size());
    EXPECT_EQ(std::memcmp(l1a.data(), l1b.data(), l1a.size() * sizeof(l1a[0])), 0);
    // (The coarser LODs of build_tree_geometry merge leaves over the whole crown, growth/leaf_lod.h.)
    (void)gb;
}

TEST(Leaves, CoarserLodsHaveFewerLeafCardsAllInsideTheLod0Foliage)
{
    BranchSettings b;
    b.lod_count = 6;
    for (int per : {1, 3, 4, 6}) {
        LeafSettings l;
        l.per_node = per;
        const TreeGeometry geo = build_tree_geometry(binary_test_tree(), b, l, 8);
        const double a0 = total_area(geo.lods[0].leaves);
        EXPECT_NEAR(a0, 256.0 * per * l.length_m * l.width_m, 1e-6 * a0);
        const Bounds b0 = bounds_of(geo.lods[0].leaves);
        for (std::size_t k = 1; k < geo.lods.size(); ++k) {
            EXPECT_LT(geo.lods[k].leaves.triangle_count(), geo.lods[k - 1].leaves.triangle_count()) << per << " LOD" << k;
            // Merged, not blown up: no card reaches past the LOD0 leaves.
            const Bounds bk = bounds_of(geo.lods[k].leaves);
            for (int axis = 0; axis < 3; ++axis) {
                EXPECT_GE(bk.lo[axis], b0.lo[axis] - 1e-5) << per << " LOD" << k << " axis " << axis;
                EXPECT_LE(bk.hi[axis], b0.hi[axis] + 1e-5) << per << " LOD" << k << " axis " << axis;
            }
        }
    }
}

TEST(Leaves, Lod2LeafBoundsCoverAtLeast90PercentOfLod0s)
{
    const TreeGeometry geo = build_tree_geometry(binary_test_tree(), BranchSettings{}, LeafSettings{}, 8);
    const Bounds b0 = bounds_of(geo.lods[0].leaves), b2 = bounds_of(geo.lods[2].leaves);
    for (int axis = 0; axis < 3; ++axis) {
        const double covered = std::min(b0.hi[axis], b2.hi[axis]) - std::max(b0.lo[axis], b2.lo[axis]);
        EXPECT_GE(covered, 0.9 * b0.extent()[axis]) << "axis " << axis;
    }
}

TEST(Leaves, CoarseLodLeavesAreTheFirstLod0LeavesOfTheirTipScaledUpMostlyInWidthAboutTheirCentre)
{
    const TreeGraph g = binary_test_tree();
    LeafSettings l;
    std::vector<int> n0, n1;
    const SurfaceGeometry s0 = build_leaf_quads(g, l, 3, {}, &n0);
    const SurfaceGeometry s1 = build_leaf_quads(g, l, 3, {0.5}, &n1);
    std::map<int, std::size_t> first0;
    for (std::size_t q = n0.size(); q-- > 0;) first0[n0[q]] = q;
    std::map<int, std::size_t> seen;
    for (std::size_t q = 0; q < n1.size(); ++q) {
        const std::size_t q0 = first0.at(n1[q]) + seen[n1[q]]++;
        const Quad a = quad(s0, q0), b = quad(s1, q);
        // Half the leaves, twice the area each: length × 2^⅛, width × 2^⅞, same centre, so
        // the crown's outline stays where LOD0's is.
        EXPECT_LT(glm::length(a.centre() - b.centre()), 1e-6);
        EXPECT_LT(glm::length(a.axis() - b.axis()), 1e-5);
        EXPECT_NEAR(b.length(), a.length() * std::pow(2.0, 0.125), 1e-6);
        EXPECT_NEAR(b.width(), a.width() * std::pow(2.0, 0.875), 1e-6);
    }
}

TEST(Leaves, SkeletonRootAndInnerNodesGetNoLeavesAndDegenerateTipsGetAValidOne)
{
    TreeGraph g;
    TreeNode root;
    root.kind = TreeNodeKind::Root;
    g.nodes.push_back(root);
    TreeNode trunk;
    trunk.parent = 0;
    trunk.position = {0, 1, 0};
    trunk.kind = TreeNodeKind::Skeleton;
    g.nodes.push_back(trunk); // a skeleton tip: no leaves
    TreeNode grown;
    grown.parent = 0;
    grown.position = {0, 0, 0}; // at its parent: direction from further up (none: +Y)
    grown.kind = TreeNodeKind::Grown;
    g.nodes.push_back(grown);
    std::vector<int> nodes;
    const SurfaceGeometry s = build_leaf_quads(g, LeafSettings{}, 1, {}, &nodes);
    EXPECT_EQ(leaf_tip_nodes(g), std::vector<int>{2});
    EXPECT_EQ(s.triangle_count(), 2u * 4u);
    EXPECT_TRUE(all_finite(s));
    for (int n : nodes) EXPECT_EQ(n, 2);
    // Only the root: nothing.
    TreeGraph lone;
    lone.nodes.push_back(root);
    EXPECT_TRUE(build_leaf_quads(lone, LeafSettings{}, 1).empty());
    EXPECT_TRUE(build_leaf_quads(TreeGraph{}, LeafSettings{}, 1).empty());
    EXPECT_THROW(build_leaf_quads(g, LeafSettings{}, 1, {0.0}), InvalidInput);
    EXPECT_THROW(build_leaf_quads(g, LeafSettings{}, 1, {1.5}), InvalidInput);
}

TEST(Leaves, TextureIsTransparentAtTheCornersOpaqueAtTheCentreAndLight)
{
    for (const char* shape : {"ovate", "round", "needle"}) {
        for (int size : {16, 64, 128, 256}) {
            const RgbaImage img = make_leaf_texture(shape, size);
            ASSERT_EQ(img.width, size);
            ASSERT_EQ(img.height, size);
            ASSERT_EQ(img.pixels.size(), static_cast<std::size_t>(size * size * 4));
            auto alpha = [&](int x, int y) { return img.pixels[(static_cast<std::size_t>(y) * static_cast<std::size_t>(size) + static_cast<std::size_t>(x)) * 4 + 3]; };
            EXPECT_EQ(alpha(0, 0), 0) << shape;
            EXPECT_EQ(alpha(size - 1, 0), 0) << shape;
            EXPECT_EQ(alpha(0, size - 1), 0) << shape;
            EXPECT_EQ(alpha(size - 1, size - 1), 0) << shape;
            EXPECT_EQ(alpha(size / 2, size / 2), 255) << shape << " " << size;
            // Light colours (the material colour multiplies them): mean luminance of the blade.
            double lum = 0.0;
            std::size_t opaque = 0;
            for (std::size_t i = 0; i < img.pixels.size(); i += 4)
                if (img.pixels[i + 3] == 255) {
                    lum += (img.pixels[i] + img.pixels[i + 1] + img.pixels[i + 2]) / (3.0 * 255.0);
                    ++opaque;
                }
            ASSERT_GT(opaque, 0u);
            EXPECT_GT(lum / static_cast<double>(opaque), 0.65) << shape;
        }
    }
}

TEST(Leaves, TexturesDifferBetweenShapesAndHaveVeins)
{
    const RgbaImage ovate = make_leaf_texture("ovate"), round = make_leaf_texture("round"), needle = make_leaf_texture("needle");
    EXPECT_NE(ovate.pixels, round.pixels);
    EXPECT_NE(ovate.pixels, needle.pixels);
    EXPECT_NE(round.pixels, needle.pixels);
    auto coverage = [](const RgbaImage& img) {
        std::size_t n = 0;
        for (std::size_t i = 3; i < img.pixels.size(); i += 4) n += img.pixels[i] > 127;
        return static_cast<double>(n) / (img.width * img.height);
    };
    EXPECT_GT(coverage(round), coverage(ovate));
    EXPECT_GT(coverage(ovate), 2.0 * coverage(needle));
    // The midrib is lighter than the blade beside it.
    auto red = [&](const RgbaImage& img, int x, int y) { return img.pixels[(static_cast<std::size_t>(y) * 128 + static_cast<std::size_t>(x)) * 4]; };
    EXPECT_GT(red(ovate, 64, 64), red(ovate, 64 + 12, 64));
    EXPECT_GT(red(ovate, 63, 64), red(ovate, 63 - 12, 64));
    // Deterministic.
    EXPECT_EQ(make_leaf_texture("ovate").pixels, ovate.pixels);
}

TEST(Leaves, UnknownShapesAndSizesThrowInvalidInput)
{
    EXPECT_THROW(make_leaf_texture("fern"), InvalidInput);
    EXPECT_THROW(make_leaf_texture("ovate", 4), InvalidInput);
    EXPECT_THROW(make_leaf_texture("ovate", 100000), InvalidInput);
}

TEST(Leaves, CloudCountsAndEmitsTheSameQuadsAsBuildLeafQuads)
{
    const TreeGraph g = binary_test_tree();
    LeafSettings l;
    l.per_node = 3;
    const LeafCloud cloud = make_leaf_cloud(g, l, 21);
    EXPECT_EQ(cloud.leaves.size(), 256u * 3u);
    SurfaceGeometry out;
    for (double keep : {1.0, 0.5, 0.3, 0.1}) {
        emit_leaf_quads(cloud, {keep}, out);
        EXPECT_EQ(out.triangle_count(), 2 * count_leaf_quads(cloud, keep)) << keep;
        EXPECT_TRUE(same_bytes(out, build_leaf_quads(g, l, 21, {keep}))) << keep;
    }
    for (const LeafCloud::Leaf& leaf : cloud.leaves) {
        EXPECT_NEAR(glm::length(leaf.axis), 1.0f, 1e-5f);
        EXPECT_NEAR(glm::length(leaf.across), 1.0f, 1e-5f);
        EXPECT_NEAR(glm::dot(leaf.axis, leaf.across), 0.0f, 1e-5f);
        EXPECT_GE(leaf.keep_offset, 0.0f);
        EXPECT_LT(leaf.keep_offset, 1.0f);
    }
}

namespace {
/// The quads of `cloud` at `keep`, with their tip nodes.
SurfaceGeometry emitted(const LeafCloud& cloud, double keep, std::vector<int>& nodes)
{
    SurfaceGeometry out;
    emit_leaf_quads(cloud, {keep}, out, &nodes);
    return out;
}
} // namespace

TEST(Leaves, LobeOverrideSetsLeafSizeAndCountOfItsLobeAndLeavesTheOtherLobeBitIdentical)
{
    const TreeGraph g = binary_test_tree();
    const LeafSettings l;
    LobeLeafOverrides over(2);
    over[1].length_m = 2.0 * l.length_m;
    over[1].per_node = l.per_node + 2;
    for (double keep : {1.0, 0.5}) {
        std::vector<int> na, nb;
        const SurfaceGeometry a = emitted(make_leaf_cloud(g, l, 5), keep, na);
        const LeafCloud cloud = make_leaf_cloud(g, l, 5, over);
        const SurfaceGeometry b = emitted(cloud, keep, nb);
        EXPECT_EQ(b.triangle_count(), 2 * count_leaf_quads(cloud, keep)) << keep;
        const auto a0 = lobe_quads(g, a, na, 0), b0 = lobe_quads(g, b, nb, 0);
        ASSERT_EQ(a0.size(), b0.size()) << keep;
        EXPECT_EQ(std::memcmp(a0.data(), b0.data(), a0.size() * sizeof(a0[0])), 0) << "lobe 0 keeps the tree's leaves";
        if (keep == 1.0) {
            EXPECT_EQ(lobe_quads(g, b, nb, 1).size(), 128u * static_cast<std::size_t>(l.per_node + 2));
        }
        std::size_t lobe1 = 0;
        const double grow = 1.0 / keep, length_scale = std::pow(grow, 0.125);
        for (std::size_t q = 0; q < nb.size(); ++q) {
            if (g.nodes[static_cast<std::size_t>(nb[q])].lobe != 1) continue;
            ++lobe1;
            EXPECT_NEAR(quad(b, q).length(), 2.0 * l.length_m * length_scale, 1e-6) << keep;
            EXPECT_NEAR(quad(b, q).width(), 2.0 * l.width_m * grow / length_scale, 1e-6) << keep;
        }
        EXPECT_GT(lobe1, 0u);
    }
}

TEST(Leaves, LobeSeedOverrideRedrawsOnlyThatLobesLeavesAsTheTreeSeedWould)
{
    const TreeGraph g = binary_test_tree();
    const LeafSettings l;
    LobeLeafOverrides over(2);
    over[1].seed = 99;
    std::vector<int> n5, n99, nover;
    const SurfaceGeometry s5 = emitted(make_leaf_cloud(g, l, 5), 1.0, n5);
    const SurfaceGeometry s99 = emitted(make_leaf_cloud(g, l, 99), 1.0, n99);
    const SurfaceGeometry so = emitted(make_leaf_cloud(g, l, 5, over), 1.0, nover);
    const auto a0 = lobe_quads(g, s5, n5, 0), o0 = lobe_quads(g, so, nover, 0);
    const auto a1 = lobe_quads(g, s99, n99, 1), o1 = lobe_quads(g, so, nover, 1);
    ASSERT_EQ(a0.size(), o0.size());
    ASSERT_EQ(a1.size(), o1.size());
    EXPECT_EQ(std::memcmp(a0.data(), o0.data(), a0.size() * sizeof(a0[0])), 0);
    EXPECT_EQ(std::memcmp(a1.data(), o1.data(), a1.size() * sizeof(a1[0])), 0);
    const auto b1 = lobe_quads(g, s5, n5, 1);
    EXPECT_NE(std::memcmp(b1.data(), o1.data(), b1.size() * sizeof(b1[0])), 0);
}

TEST(Leaves, EmptyOverridesGiveTheTreesBytesAndAZeroCountLobeHasNoLeaves)
{
    const TreeGraph g = binary_test_tree();
    const LeafSettings l;
    std::vector<int> n;
    EXPECT_TRUE(same_bytes(emitted(make_leaf_cloud(g, l, 5, LobeLeafOverrides(2)), 1.0, n), build_leaf_quads(g, l, 5)));
    LobeLeafOverrides none(1);
    none[0].per_node = 0;
    const SurfaceGeometry s = emitted(make_leaf_cloud(g, l, 5, none), 1.0, n);
    EXPECT_TRUE(lobe_quads(g, s, n, 0).empty());
    EXPECT_EQ(lobe_quads(g, s, n, 1).size(), 128u * static_cast<std::size_t>(l.per_node));
    // A lobe may have leaves where the tree has none.
    LeafSettings bare = l;
    bare.per_node = 0;
    LobeLeafOverrides some(2);
    some[1].per_node = 2;
    const SurfaceGeometry t = emitted(make_leaf_cloud(g, bare, 5, some), 1.0, n);
    EXPECT_TRUE(lobe_quads(g, t, n, 0).empty());
    EXPECT_EQ(lobe_quads(g, t, n, 1).size(), 256u);
}

TEST(Leaves, OverridesOutOfRangeThrowInvalidInput)
{
    const TreeGraph g = binary_test_tree();
    LobeLeafOverrides bad(1);
    bad[0].length_m = 0.0;
    EXPECT_THROW(make_leaf_cloud(g, LeafSettings{}, 1, bad), InvalidInput);
    bad[0].length_m = std::nullopt;
    bad[0].per_node = 65;
    EXPECT_THROW(make_leaf_cloud(g, LeafSettings{}, 1, bad), InvalidInput);
    bad[0].per_node = -1;
    EXPECT_THROW(make_leaf_cloud(g, LeafSettings{}, 1, bad), InvalidInput);
}
