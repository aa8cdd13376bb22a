// The test shapes (tests/support/shapes.h) have the counts their documentation states and
// are closed, 2-manifold and outward oriented.
#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "meshing/mesh_quality.h"
#include "tests/support/shapes.h"

namespace lobe {
namespace {

void expect_closed_outward(const TriangleMesh& m, const std::string& what)
{
    const MeshQuality q = measure_quality(m);
    EXPECT_TRUE(q.closed) << what;
    EXPECT_TRUE(q.manifold) << what;
    EXPECT_TRUE(q.outward) << what;
    EXPECT_EQ(q.components, 1u) << what;
}

} // namespace

TEST(TestShapes, IcosphereHasTenTimesFourToTheLevelsPlusTwoVerticesOnItsSphere)
{
    const glm::dvec3 centre(0.1, 1.3, -0.4);
    for (int levels = 0; levels <= 4; ++levels) {
        const TriangleMesh m = test::icosphere(levels, 0.2, centre);
        const std::size_t four_to_the_levels = std::size_t{1} << (2 * levels);
        EXPECT_EQ(m.vertex_count(), 10 * four_to_the_levels + 2) << levels;
        EXPECT_EQ(m.triangle_count(), 20 * four_to_the_levels) << levels;
        expect_closed_outward(m, "icosphere " + std::to_string(levels));
        for (const glm::vec3& p : m.positions) EXPECT_NEAR(glm::distance(glm::dvec3(p), centre), 0.2, 1e-6);
    }
}

TEST(TestShapes, GeodesicSphereHasTenTimesTheFrequencySquaredPlusTwoVertices)
{
    for (int frequency : {1, 2, 5, 22}) {
        const TriangleMesh m = test::geodesic_sphere(frequency, glm::dvec3(0.0, 1.2, -0.4), 0.25);
        EXPECT_EQ(m.vertex_count(), std::size_t(10 * frequency * frequency + 2)) << frequency;
        EXPECT_EQ(m.triangle_count(), std::size_t(20 * frequency * frequency)) << frequency;
        expect_closed_outward(m, "geodesic sphere " + std::to_string(frequency));
    }
}

TEST(TestShapes, UvSphereKeepsItsEquatorAsAFeatureLoop)
{
    std::vector<int> equator;
    const TriangleMesh m = test::uv_sphere(16, 24, 0.2, equator);
    EXPECT_EQ(m.vertex_count(), std::size_t(15 * 24 + 2));
    EXPECT_EQ(m.triangle_count(), std::size_t(2 * 15 * 24));
    expect_closed_outward(m, "uv sphere");
    ASSERT_EQ(equator.size(), 24u);
    ASSERT_EQ(m.feature_edges.size(), 24u);
    for (std::size_t j = 0; j < equator.size(); ++j) {
        EXPECT_NEAR(m.positions[static_cast<std::size_t>(equator[j])].y, 0.0f, 1e-7f);
        EXPECT_EQ(m.feature_edges[j][0], equator[j]);
        EXPECT_EQ(m.feature_edges[j][1], equator[(j + 1) % equator.size()]);
    }
}

TEST(TestShapes, OctahedronAndEllipsoidAreClosedAndOutward)
{
    const TriangleMesh octahedron = test::octahedron(glm::vec3(0.5f, 2.7f, 0.0f), 0.6f);
    EXPECT_EQ(octahedron.vertex_count(), 6u);
    EXPECT_EQ(octahedron.triangle_count(), 8u);
    expect_closed_outward(octahedron, "octahedron");
    const TriangleMesh ellipsoid = test::ellipsoid({0.0, 1.4, 0.0}, {0.17, 0.14, 0.16});
    EXPECT_EQ(ellipsoid.vertex_count(), 642u);
    EXPECT_EQ(ellipsoid.triangle_count(), 1280u);
    expect_closed_outward(ellipsoid, "ellipsoid");
}

TEST(TestShapes, SphereDirectionsAreUnitAndRunFromTopToBottom)
{
    const std::vector<glm::dvec3> dirs = test::sphere_directions(500);
    ASSERT_EQ(dirs.size(), 500u);
    for (const glm::dvec3& u : dirs) EXPECT_NEAR(glm::length(u), 1.0, 1e-12);
    EXPECT_NEAR(dirs.front().z, 1.0 - 1.0 / 500.0, 1e-15);
    EXPECT_NEAR(dirs.back().z, -(1.0 - 1.0 / 500.0), 1e-15);
}

TEST(TestShapes, RawLoopPointsAreAboutFiveMillimetresApartAndWithinAMillimetreOfTheCircle)
{
    const glm::dvec3 centre(0.0, 1.4, -0.45);
    const std::vector<glm::vec3> loop = test::raw_loop(centre, {1, 0, 0}, {0, 0, 1}, 0.2, 3);
    EXPECT_EQ(loop.size(), 251u); // ⌊2π · 0.2 / 0.005⌋
    for (std::size_t i = 0; i < loop.size(); ++i) {
        EXPECT_NEAR(glm::distance(glm::dvec3(loop[i]), centre), 0.2, 0.001 + 1e-6);
        const double step = glm::distance(loop[i], loop[(i + 1) % loop.size()]);
        EXPECT_GT(step, 0.0045);
        EXPECT_LT(step, 0.0055);
    }
    EXPECT_EQ(test::ten_stroke_lobe().size(), 10u);
}

} // namespace lobe
