// Coarse-LOD leaf cards and the leaf atlas (growth/leaf_lod.h).
#include <gtest/gtest.h>

#include <cstring>

#include "core/errors.h"
#include "growth/branch_geometry.h"
#include "growth/leaf_lod.h"
#include "growth/leaves.h"
#include "tests/support/geometry_checks.h"
#include "tests/support/tree_fixtures.h"

using namespace lobe;
using namespace lobe::test;

namespace {

std::uint8_t alpha_at(const RgbaImage& img, int x, int y)
{
    return img.pixels[(static_cast<std::size_t>(y) * static_cast<std::size_t>(img.width) + static_cast<std::size_t>(x)) * 4 + 3];
}

} // namespace

TEST(LeafLod, AtlasHoldsTheLeafOnTheLeftAndASprayOfLeavesOnTheRight)
{
    const RgbaImage leaf = make_leaf_texture("ovate", 64);
    const RgbaImage atlas = make_leaf_atlas(leaf);
    ASSERT_EQ(atlas.width, 128);
    ASSERT_EQ(atlas.height, 64);
    for (int y = 0; y < 64; ++y)
        EXPECT_EQ(std::memcmp(&atlas.pixels[static_cast<std::size_t>(y) * 128 * 4], &leaf.pixels[static_cast<std::size_t>(y) * 64 * 4], 64 * 4), 0);
    // The spray: leaves turned both ways (opaque pixels in the outer quarters of its half,
    // where one upright leaf has none), its top corners clear.
    std::size_t left = 0, right = 0;
    for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 16; ++x) {
            left += alpha_at(atlas, 64 + x, y) >= 128;
            right += alpha_at(atlas, 127 - x, y) >= 128;
        }
    EXPECT_GT(left, 40u);
    EXPECT_GT(right, 40u);
    EXPECT_EQ(alpha_at(atlas, 64, 0), 0);
    EXPECT_EQ(alpha_at(atlas, 127, 0), 0);
    EXPECT_EQ(make_leaf_atlas(leaf).pixels, atlas.pixels);
    EXPECT_THROW(make_leaf_atlas(RgbaImage{}), InvalidInput);
}

TEST(LeafLod, ClusterCardsNumberAtMostTheLimitAndEveryLeafAloneGivesTheLod0Quads)
{
    const TreeGraph g = binary_test_tree();
    const LeafCloud cloud = make_leaf_cloud(g, LeafSettings{}, 5);
    ASSERT_GT(cloud.leaves.size(), 100u);
    for (std::size_t limit : {1u, 7u, 40u, 200u}) {
        SurfaceGeometry cards;
        emit_leaf_cluster_cards(cloud, limit, cards);
        EXPECT_LE(cards.triangle_count(), 2 * limit) << limit;
        EXPECT_GT(cards.triangle_count(), 0u);
        EXPECT_EQ(cards.positions.size(), 2 * cards.triangle_count());
        for (const glm::vec3& n : cards.normals) EXPECT_NEAR(glm::length(n), 1.0f, 1e-4f);
        for (const glm::vec2& uv : cards.uvs) EXPECT_TRUE(uv.x >= 0.0f && uv.x <= 1.0f && uv.y >= 0.0f && uv.y <= 1.0f);
    }
    // Enough cards for every leaf: the LOD0 quads themselves (in another order), on the single-leaf half.
    SurfaceGeometry all, lod0;
    emit_leaf_cluster_cards(cloud, cloud.leaves.size(), all);
    emit_leaf_quads(cloud, {}, lod0);
    EXPECT_EQ(all.triangle_count(), lod0.triangle_count());
    EXPECT_NEAR(total_area(all), total_area(lod0), 1e-6 * total_area(lod0));
    for (const glm::vec2& uv : all.uvs) EXPECT_LE(uv.x, 0.5f);
    SurfaceGeometry none;
    emit_leaf_cluster_cards(cloud, 0, none);
    EXPECT_TRUE(none.empty());
}

TEST(LeafLod, TallTreeAtSixLodsKeepsItsCoarsestLeavesAboveTheGroundAndWithinTheCrown)
{
    // The regression this replaces: coarse leaves were blown up by 1/keep and at LOD5 of an
    // 8 m tree reached 10.9 m and below the ground.
    TreeGraph g = binary_test_tree();
    for (TreeNode& n : g.nodes) n.position *= 8.0f;
    BranchSettings b;
    b.lod_count = 6;
    const TreeGeometry geo = build_tree_geometry(g, b, LeafSettings{}, 2);
    const Bounds b0 = bounds_of(geo.lods[0].leaves);
    const double height = bounds_of(geo.lods[0].branches).hi.y;
    ASSERT_GT(height, 20.0);
    for (std::size_t k = 1; k < geo.lods.size(); ++k) {
        const Bounds bk = bounds_of(geo.lods[k].leaves);
        for (int axis = 0; axis < 3; ++axis) {
            EXPECT_GE(bk.lo[axis], b0.lo[axis] - 1e-4) << "LOD" << k << " axis " << axis;
            EXPECT_LE(bk.hi[axis], b0.hi[axis] + 1e-4) << "LOD" << k << " axis " << axis;
        }
        EXPECT_GT(bk.lo.y, 0.0) << "LOD" << k;
    }
}
