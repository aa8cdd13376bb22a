// Wood volume, biomass, carbon and CO₂ of a tree graph (growth/wood.h).
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "core/errors.h"
#include "growth/wood.h"
#include "tests/support/expect_throw.h"

namespace lobe {
namespace {

TreeNode node(glm::vec3 p, int parent, float radius)
{
    TreeNode n;
    n.position = p;
    n.parent = parent;
    n.radius = radius;
    return n;
}

TEST(Wood, AStraightCylinderAndAConeFrustumHaveTheirVolumes)
{
    // A cylinder of radius 0.1 m and length 3 m in two internodes, and beside it a frustum
    // from radius 0.2 to 0.1 over 1 m from the same root.
    TreeGraph g;
    g.nodes = {node({0, 0, 0}, -1, 0.1f), node({0, 1, 0}, 0, 0.1f), node({0, 3, 0}, 1, 0.1f)};
    const double cylinder = std::numbers::pi * 0.01 * 3.0;
    EXPECT_NEAR(wood_volume_m3(g), cylinder, 1e-7);
    TreeGraph f;
    f.nodes = {node({0, 0, 0}, -1, 0.2f), node({1, 0, 0}, 0, 0.1f)};
    EXPECT_NEAR(wood_volume_m3(f), std::numbers::pi / 3.0 * (0.04 + 0.02 + 0.01), 1e-7);
}

TEST(Wood, BiomassCarbonAndCo2FollowTheDensityAndScaleWithTheCubeOfSize)
{
    TreeGraph g;
    g.nodes = {node({0, 0, 0}, -1, 0.1f), node({0, 2, 0}, 0, 0.1f)};
    const double v = std::numbers::pi * 0.01 * 2.0;
    const WoodEstimate e = estimate_wood(g, 600.0);
    EXPECT_NEAR(e.wood_volume_m3, v, 1e-7);
    EXPECT_NEAR(e.dry_biomass_kg, v * 600.0, 1e-4);
    EXPECT_NEAR(e.carbon_kg, v * 300.0, 1e-4);
    EXPECT_NEAR(e.co2_kg, v * 300.0 * 44.0 / 12.0, 1e-4);
    EXPECT_EQ(e.density_kg_m3, 600.0);
    EXPECT_NEAR(estimate_wood(g, 600.0, 2.0).co2_kg, 8.0 * e.co2_kg, 1e-9 * e.co2_kg * 8.0);
}

TEST(Wood, EverySpeciesPresetHasADensityAndBadNumbersAreRefusedInOneLine)
{
    EXPECT_EQ(basic_wood_density("broadleaf"), 600.0);
    EXPECT_EQ(basic_wood_density("conifer"), 340.0);
    EXPECT_EQ(basic_wood_density("birch"), 480.0);
    EXPECT_EQ(basic_wood_density("willow"), 360.0);
    EXPECT_EQ(basic_wood_density("my-preset.json"), 600.0);
    const TreeGraph g;
    test::expect_one_line_throw<InvalidInput>([&] { estimate_wood(g, 0.0); });
    test::expect_one_line_throw<InvalidInput>([&] { estimate_wood(g, 500.0, std::nan("")); });
}

} // namespace
} // namespace lobe
