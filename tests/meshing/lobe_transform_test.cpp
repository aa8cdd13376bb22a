// Moving, rotating and scaling lobes (meshing/lobe_transform.h).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include <glm/geometric.hpp>

#include "core/errors.h"
#include "meshing/lobe_transform.h"
#include "tests/support/expect_throw.h"

using namespace lobe;

namespace {

constexpr double kPi = 3.14159265358979323846;

glm::dvec3 apply(const glm::dmat4& m, const glm::dvec3& p) { return glm::dvec3(m * glm::dvec4(p, 1.0)); }

void expect_near(const glm::dvec3& a, const glm::dvec3& b, double tol = 1e-12)
{
    EXPECT_NEAR(a.x, b.x, tol);
    EXPECT_NEAR(a.y, b.y, tol);
    EXPECT_NEAR(a.z, b.z, tol);
}

void expect_identity(const glm::dmat4& m)
{
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) EXPECT_EQ(m[c][r], c == r ? 1.0 : 0.0) << c << "," << r;
}

template <class F> void expect_invalid_one_line(F&& f) { test::expect_one_line_throw<InvalidInput>(f); }

const glm::dvec3 kCentre(0.05, 1.40, -0.42);

} // namespace

TEST(LobeTransform, MoveIsTheTranslationFromStartToEnd)
{
    const glm::dmat4 m = move_transform({0.1, 1.5, -0.4}, {0.15, 1.45, -0.3});
    expect_near(apply(m, {0, 0, 0}), {0.05, -0.05, 0.1}, 1e-15);
    expect_near(apply(m, kCentre), kCentre + glm::dvec3(0.05, -0.05, 0.1), 1e-15);
    expect_near(glm::dvec3(m * glm::dvec4(1, 0, 0, 0)), {1, 0, 0}, 0); // directions unchanged
    EXPECT_EQ(similarity_scale(m), 1.0);
    const std::vector<glm::vec3> path = {{0.1f, 1.5f, -0.4f}, {0.3f, 1.0f, 0.0f}, {0.15f, 1.45f, -0.3f}};
    const glm::dmat4 d = drag_transform(LobeTransformKind::Move, path, {9, 9, 9});
    expect_near(glm::dvec3(d[3]), glm::dvec3(path.back()) - glm::dvec3(path.front()), 0); // only the ends count
}

TEST(LobeTransform, RotateTakesTheStartDirectionToTheEndDirectionAboutTheCentre)
{
    // A quarter turn about +Y: +X goes to −Z.
    const glm::dmat4 m = rotate_transform(kCentre + glm::dvec3(0.17, 0, 0), kCentre + glm::dvec3(0, 0, -0.2), kCentre);
    expect_near(apply(m, kCentre), kCentre);
    expect_near(apply(m, kCentre + glm::dvec3(0.1, 0, 0)), kCentre + glm::dvec3(0, 0, -0.1));
    expect_near(apply(m, kCentre + glm::dvec3(0, 0, -0.1)), kCentre + glm::dvec3(-0.1, 0, 0));
    expect_near(apply(m, kCentre + glm::dvec3(0, 0.3, 0)), kCentre + glm::dvec3(0, 0.3, 0)); // the axis stays
    EXPECT_NEAR(similarity_scale(m), 1.0, 1e-15);

    // 25° about +Y through the centre, the start 17 cm out on −X (the recorded scenario).
    const double a = 25 * kPi / 180;
    const glm::dvec3 s = kCentre + glm::dvec3(-0.17, 0, 0), e = kCentre + 0.17 * glm::dvec3(-std::cos(a), 0, std::sin(a));
    const glm::dmat4 r = rotate_transform(s, e, kCentre);
    expect_near(apply(r, s), e);
    expect_near(apply(r, kCentre + glm::dvec3(0, 0, -0.1)), kCentre + 0.1 * glm::dvec3(-std::sin(a), 0, -std::cos(a)));

    // Minimal: a general pair turns about their cross product, by the angle between them,
    // and the distance of the end from the centre does not matter.
    const glm::dvec3 u(0.1, 0.05, -0.02), v(-0.03, 0.2, 0.08);
    const glm::dmat4 g = rotate_transform(kCentre + u, kCentre + 3.0 * v, kCentre);
    expect_near(apply(g, kCentre + u), kCentre + glm::length(u) * glm::normalize(v));
    const glm::dvec3 axis = glm::normalize(glm::cross(u, v));
    expect_near(apply(g, kCentre + axis), kCentre + axis);
    EXPECT_NEAR(glm::determinant(glm::dmat3(g)), 1.0, 1e-14);
}

TEST(LobeTransform, RotateFallsBackToIdentityNearTheCentreAndHasAFixedAxisWhenOpposite)
{
    LobeTransformOptions o; // min_lever_m = 2 cm
    expect_identity(rotate_transform(kCentre + glm::dvec3(0.019, 0, 0), kCentre + glm::dvec3(0, 0.1, 0), kCentre, o));
    expect_identity(rotate_transform(kCentre + glm::dvec3(0.1, 0, 0), kCentre + glm::dvec3(0, 0.019, 0), kCentre, o));
    expect_identity(rotate_transform(kCentre, kCentre, kCentre, o));
    o.min_lever_m = 0.0;
    expect_identity(rotate_transform(kCentre, kCentre + glm::dvec3(0, 0.1, 0), kCentre, o)); // no direction at all
    expect_identity(rotate_transform(kCentre + glm::dvec3(0.1, 0, 0), kCentre + glm::dvec3(0.3, 0, 0), kCentre));

    // Opposite: a half turn about the axis perpendicular to the start direction and to the
    // coordinate axis it is least aligned with (here +X is least aligned with (0, 0.6, 0.8)).
    const glm::dvec3 a(0, 0.06, 0.08);
    const glm::dmat4 h = rotate_transform(kCentre + a, kCentre - 2.0 * a, kCentre);
    expect_near(apply(h, kCentre + a), kCentre - a);
    const glm::dvec3 axis = glm::normalize(glm::cross(glm::normalize(a), glm::dvec3(1, 0, 0)));
    expect_near(apply(h, kCentre + axis), kCentre + axis);
    expect_near(apply(h, kCentre + glm::dvec3(0.1, 0, 0)), kCentre - glm::dvec3(0.1, 0, 0));
}

TEST(LobeTransform, ScaleIsTheRatioOfDistancesToTheCentreClamped)
{
    const glm::dvec3 s = kCentre + glm::dvec3(0, 0.14, 0), e = kCentre + glm::dvec3(0, 0.182, 0);
    EXPECT_NEAR(drag_scale_factor(s, e, kCentre), 1.3, 1e-12);
    const glm::dmat4 m = scale_transform(s, e, kCentre);
    expect_near(apply(m, kCentre), kCentre);
    expect_near(apply(m, s), e);
    expect_near(apply(m, kCentre + glm::dvec3(0.1, -0.2, 0.05)), kCentre + 1.3 * glm::dvec3(0.1, -0.2, 0.05));
    EXPECT_NEAR(similarity_scale(m), 1.3, 1e-12);
    // Direction does not matter, only distances: a sideways end 7 cm out halves the lobe.
    EXPECT_NEAR(drag_scale_factor(s, kCentre + glm::dvec3(0.07, 0, 0), kCentre), 0.5, 1e-12);

    // Clamped to [0.1, 10].
    EXPECT_DOUBLE_EQ(drag_scale_factor(s, kCentre, kCentre), 0.1);
    EXPECT_DOUBLE_EQ(drag_scale_factor(s, kCentre + glm::dvec3(0, 2.0, 0), kCentre), 10.0);
    LobeTransformOptions o;
    o.min_scale = 0.5;
    o.max_scale = 2.0;
    EXPECT_DOUBLE_EQ(drag_scale_factor(s, kCentre + glm::dvec3(0, 0.01, 0), kCentre, o), 0.5);
    EXPECT_DOUBLE_EQ(drag_scale_factor(s, kCentre + glm::dvec3(0, 1.0, 0), kCentre, o), 2.0);
    // A start within 2 cm of the centre has no lever: identity.
    expect_identity(scale_transform(kCentre + glm::dvec3(0.01, 0, 0), kCentre + glm::dvec3(0.3, 0, 0), kCentre));
    EXPECT_EQ(drag_scale_factor(kCentre, kCentre + glm::dvec3(0.3, 0, 0), kCentre), 1.0);
}

TEST(LobeTransform, TransformsComposeInTheOrderTheyWereMade)
{
    // Move 10 cm along +X, then a quarter turn about +Y through the moved centre: the lobe
    // ends up beside where it was moved, turned. The other order differs.
    const glm::dmat4 move = move_transform(kCentre, kCentre + glm::dvec3(0.1, 0, 0));
    const glm::dvec3 c2 = kCentre + glm::dvec3(0.1, 0, 0);
    const glm::dmat4 rot = rotate_transform(c2 + glm::dvec3(0.1, 0, 0), c2 + glm::dvec3(0, 0, -0.1), c2);
    const glm::dmat4 both = rot * move;
    const glm::dvec3 p = kCentre + glm::dvec3(0.05, 0, 0);
    expect_near(apply(both, p), c2 + glm::dvec3(0, 0, -0.05));
    expect_near(apply(move * rot, p), kCentre + glm::dvec3(0.2, 0, 0.05));
    // Scale about the centre after both: distances from the new centre grow.
    const glm::dmat4 sc = scale_transform(c2 + glm::dvec3(0, 0.1, 0), c2 + glm::dvec3(0, 0.2, 0), c2);
    expect_near(apply(sc * both, p), c2 + glm::dvec3(0, 0, -0.1));
    EXPECT_NEAR(similarity_scale(sc * both), 2.0, 1e-12);
}

TEST(LobeTransform, MeshesAndStrokesAreTransformedInPlace)
{
    TriangleMesh mesh;
    mesh.positions = {{0.1f, 1.4f, -0.4f}, {0.2f, 1.4f, -0.4f}, {0.1f, 1.5f, -0.4f}};
    mesh.triangles = {{0, 1, 2}};
    mesh.feature_edges = {{0, 1}};
    const TriangleMesh before = mesh;
    const glm::dmat4 m = scale_transform(glm::dvec3(0.1, 1.5, -0.4), glm::dvec3(0.1, 1.6, -0.4), glm::dvec3(0.1, 1.4, -0.4));
    transform_mesh(mesh, m);
    EXPECT_EQ(mesh.positions[0], before.positions[0]);
    EXPECT_NEAR(mesh.positions[1].x, 0.3f, 1e-6f);
    EXPECT_NEAR(mesh.positions[2].y, 1.6f, 1e-6f);
    EXPECT_EQ(mesh.triangles, before.triangles);
    EXPECT_EQ(mesh.feature_edges, before.feature_edges);

    // A mirror would turn the triangles inside out: refused, mesh unchanged.
    glm::dmat4 mirror(1.0);
    mirror[0][0] = -1.0;
    const TriangleMesh kept = mesh;
    expect_invalid_one_line([&] { transform_mesh(mesh, mirror); });
    glm::dmat4 bad(1.0);
    bad[3][1] = std::numeric_limits<double>::quiet_NaN();
    expect_invalid_one_line([&] { transform_mesh(mesh, bad); });
    EXPECT_EQ(mesh.positions, kept.positions);

    Stroke s;
    s.points = {{{0.0f, 1.0f, 0.0f}, 2.5}, {{0.1f, 1.0f, 0.0f}, 2.6}};
    transform_stroke(s, move_transform({0, 0, 0}, {0, 0.5, 0}));
    EXPECT_EQ(s.points[1].position, glm::vec3(0.1f, 1.5f, 0.0f));
    EXPECT_EQ(s.points[1].time, 2.6);
    expect_invalid_one_line([&] { transform_stroke(s, bad); });
    EXPECT_EQ(s.points[1].position, glm::vec3(0.1f, 1.5f, 0.0f));
}

TEST(LobeTransform, BadInputIsRefusedWithOneLine)
{
    const double nan = std::numeric_limits<double>::quiet_NaN();
    expect_invalid_one_line([&] { move_transform({nan, 0, 0}, {0, 0, 0}); });
    expect_invalid_one_line([&] { rotate_transform({0.1, 0, 0}, {0, 0.1, 0}, {0, nan, 0}); });
    expect_invalid_one_line([&] { scale_transform({0.1, 0, 0}, {0, std::numeric_limits<double>::infinity(), 0}, {0, 0, 0}); });
    expect_invalid_one_line([&] { drag_transform(LobeTransformKind::Move, {}, kCentre); });
    LobeTransformOptions o;
    o.min_scale = 0.0;
    expect_invalid_one_line([&] { scale_transform({0.1, 0, 0}, {0.2, 0, 0}, {0, 0, 0}, o); });
    o = {};
    o.max_scale = 0.5;
    expect_invalid_one_line([&] { scale_transform({0.1, 0, 0}, {0.2, 0, 0}, {0, 0, 0}, o); });
    o = {};
    o.min_lever_m = -1;
    expect_invalid_one_line([&] { rotate_transform({0.1, 0, 0}, {0, 0.1, 0}, {0, 0, 0}, o); });
}
