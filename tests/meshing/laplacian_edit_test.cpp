#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <functional>
#include <limits>
#include <map>
#include <queue>
#include <random>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wconversion"
#pragma GCC diagnostic ignored "-Wshadow"
#ifndef __clang__ // GCC only: Clang has no such warning and would warn about the pragma
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <Eigen/Dense>
#pragma GCC diagnostic pop

#include "core/errors.h"
#include "core/mesh.h"
#include "meshing/laplacian_edit.h"
#include "tests/support/expect_throw.h"
#include "tests/support/shapes.h"

using namespace lobe;

namespace {

constexpr double kRadius = 0.25;
const glm::dvec3 kCentre{0.0, 1.2, -0.4};

/// The test lobe: a geodesic sphere of kRadius about kCentre (frequency 22: 4,842 vertices).
TriangleMesh sphere(int frequency = 22)
{
    return test::geodesic_sphere(frequency, kCentre, kRadius);
}

/// Gaussian bump of the given height and width (metres, along the surface) around `axis`.
double bump_height(const glm::dvec3& u, const glm::dvec3& axis, double height, double sigma)
{
    const double s = kRadius * std::acos(std::clamp(glm::dot(u, axis), -1.0, 1.0));
    return height * std::exp(-(s / sigma) * (s / sigma));
}

glm::dvec3 outward(const TriangleMesh& mesh, int v) { return glm::normalize(glm::dvec3(mesh.positions[std::size_t(v)]) - kCentre); }

/// The vertex nearest to the sphere point in direction u.
int vertex_towards(const TriangleMesh& mesh, const glm::dvec3& u)
{
    return pick_handle(mesh, glm::vec3(kCentre + kRadius * glm::normalize(u)), 0.03);
}

std::vector<std::vector<int>> neighbours(const TriangleMesh& mesh)
{
    std::vector<std::set<int>> sets(mesh.vertex_count());
    for (const auto& t : mesh.triangles)
        for (int k = 0; k < 3; ++k) {
            sets[std::size_t(t[std::size_t(k)])].insert(t[std::size_t((k + 1) % 3)]);
            sets[std::size_t(t[std::size_t(k)])].insert(t[std::size_t((k + 2) % 3)]);
        }
    std::vector<std::vector<int>> out;
    for (const auto& s : sets)
        out.emplace_back(s.begin(), s.end());
    return out;
}

/// Shortest-path distances along edges (plain Dijkstra, written separately from the editor's).
std::vector<double> edge_distances(const TriangleMesh& mesh, int source)
{
    const auto nb = neighbours(mesh);
    std::vector<double> d(mesh.vertex_count(), std::numeric_limits<double>::infinity());
    std::vector<bool> done(mesh.vertex_count(), false);
    d[std::size_t(source)] = 0.0;
    for (;;) {
        int v = -1;
        for (std::size_t i = 0; i < d.size(); ++i)
            if (!done[i] && std::isfinite(d[i]) && (v < 0 || d[i] < d[std::size_t(v)]))
                v = int(i);
        if (v < 0)
            return d;
        done[std::size_t(v)] = true;
        for (int u : nb[std::size_t(v)])
            d[std::size_t(u)] = std::min(d[std::size_t(u)], d[std::size_t(v)] + glm::length(glm::dvec3(mesh.positions[std::size_t(u)]) -
                                                                                             glm::dvec3(mesh.positions[std::size_t(v)])));
    }
}

double distance(const glm::vec3& a, const glm::vec3& b) { return glm::length(glm::dvec3(a) - glm::dvec3(b)); }

/// Area-weighted vertex normals.
std::vector<glm::dvec3> vertex_normals(const TriangleMesh& mesh)
{
    std::vector<glm::dvec3> n(mesh.vertex_count(), glm::dvec3(0.0));
    for (const auto& t : mesh.triangles) {
        const glm::dvec3 a(mesh.positions[std::size_t(t[0])]), b(mesh.positions[std::size_t(t[1])]),
            c(mesh.positions[std::size_t(t[2])]);
        const glm::dvec3 f = glm::cross(b - a, c - a);
        for (int v : t)
            n[std::size_t(v)] += f;
    }
    for (auto& v : n)
        v = glm::normalize(v);
    return n;
}

bool same_positions(const TriangleMesh& a, const TriangleMesh& b)
{
    if (a.positions.size() != b.positions.size())
        return false;
    for (std::size_t i = 0; i < a.positions.size(); ++i)
        if (a.positions[i] != b.positions[i])
            return false;
    return true;
}

} // namespace

TEST(PinchEdit, SphereFixtureIsAClosedGeodesicSphere)
{
    const TriangleMesh mesh = sphere();
    EXPECT_EQ(mesh.vertex_count(), 10u * 22 * 22 + 2);
    EXPECT_EQ(mesh.triangle_count(), 20u * 22 * 22);
    std::map<std::pair<int, int>, int> directed;
    for (const auto& t : mesh.triangles)
        for (int k = 0; k < 3; ++k)
            ++directed[{t[std::size_t(k)], t[std::size_t((k + 1) % 3)]}];
    for (const auto& [e, count] : directed) {
        EXPECT_EQ(count, 1);
        EXPECT_EQ(directed.count({e.second, e.first}), 1u); // closed and consistently oriented
    }
}

TEST(PinchEdit, FiveCentimetreDragMovesTheHandleExactlyFiveCentimetres)
{
    for (const auto weights : {PinchEditOptions::Weights::Cotangent, PinchEditOptions::Weights::Uniform}) {
        const TriangleMesh before = sphere();
        TriangleMesh mesh = before;
        const int h = vertex_towards(mesh, {0.3, 1.0, 0.2});
        PinchEditOptions options;
        options.weights = weights;
        const PinchEditor editor(mesh, h, options);
        // Sideways and outwards: 3 cm along the surface, 4 cm out.
        const glm::dvec3 n = outward(mesh, h);
        const glm::dvec3 side = glm::normalize(glm::cross(n, glm::dvec3(0.0, 0.0, 1.0)));
        const glm::vec3 target = glm::vec3(glm::dvec3(before.positions[std::size_t(h)]) + 0.03 * side + 0.04 * n);
        editor.drag_to(target, mesh);

        EXPECT_EQ(mesh.positions[std::size_t(h)], target);
        EXPECT_NEAR(distance(mesh.positions[std::size_t(h)], before.positions[std::size_t(h)]), 0.05, 1e-6);

        // Smooth: no tent around the handle (its 1-ring follows it most of the way) and no
        // free vertex overshoots the handle.
        const auto nb = neighbours(mesh);
        double ring_min = 1.0;
        for (int u : nb[std::size_t(h)])
            ring_min = std::min(ring_min, distance(mesh.positions[std::size_t(u)], before.positions[std::size_t(u)]));
        EXPECT_GT(ring_min, 0.8 * 0.05);
        for (int v : editor.roi())
            EXPECT_LT(distance(mesh.positions[std::size_t(v)], before.positions[std::size_t(v)]), 0.05 * 1.05) << v;
    }
}

TEST(PinchEdit, VerticesOutsideTheRoiAreBitIdentical)
{
    const TriangleMesh before = sphere();
    TriangleMesh mesh = before;
    const int h = vertex_towards(mesh, {0.0, 1.0, 0.0});
    const PinchEditor editor(mesh, h);
    editor.drag_to(mesh.positions[std::size_t(h)] + glm::vec3(0.02f, 0.05f, -0.01f), mesh);
    const std::set<int> roi(editor.roi().begin(), editor.roi().end());
    std::size_t moved = 0;
    for (std::size_t i = 0; i < mesh.vertex_count(); ++i) {
        if (roi.count(int(i)) == 0)
            EXPECT_EQ(std::memcmp(&mesh.positions[i], &before.positions[i], sizeof(glm::vec3)), 0) << i;
        else
            moved += mesh.positions[i] != before.positions[i];
    }
    EXPECT_EQ(moved, roi.size()); // every ROI vertex moved a little
    EXPECT_EQ(mesh.triangles, before.triangles);
}

TEST(PinchEdit, RoiIsTheEdgeDistanceBallAndTheFixedRingSurroundsIt)
{
    const TriangleMesh mesh = sphere();
    const int h = vertex_towards(mesh, {-0.2, 0.5, 1.0});
    PinchEditOptions options;
    options.roi_radius_m = 0.06;
    const PinchEditor editor(mesh, h, options);
    const auto d = edge_distances(mesh, h);
    std::vector<int> expected_roi;
    for (std::size_t i = 0; i < d.size(); ++i)
        if (d[i] <= options.roi_radius_m)
            expected_roi.push_back(int(i));
    EXPECT_EQ(editor.roi(), expected_roi);
    EXPECT_EQ(editor.free_vertex_count(), expected_roi.size() - 1);
    EXPECT_EQ(editor.handle(), h);
    EXPECT_EQ(editor.handle_start(), mesh.positions[std::size_t(h)]);
    const auto nb = neighbours(mesh);
    std::set<int> expected_ring;
    for (int v : expected_roi)
        for (int u : nb[std::size_t(v)])
            if (!std::binary_search(expected_roi.begin(), expected_roi.end(), u))
                expected_ring.insert(u);
    EXPECT_EQ(editor.fixed_ring(), std::vector<int>(expected_ring.begin(), expected_ring.end()));
    EXPECT_GT(editor.roi().size(), 50u);
}

namespace {

/// The energy of PinchEditor rebuilt densely, independently: L (#V by #V) with
/// L(x)ᵢ = xᵢ − Σⱼ wᵢⱼ xⱼ / Σⱼ wᵢⱼ, δ = L x, and the least-squares problem
/// min ‖L_F x_F − (R δ − L_C x_C)‖ solved by column-pivoting Householder QR.
Eigen::MatrixXd dense_laplacian(const TriangleMesh& mesh, bool cotangent)
{
    const auto n = Eigen::Index(mesh.vertex_count());
    Eigen::MatrixXd w = Eigen::MatrixXd::Zero(n, n);
    for (const auto& t : mesh.triangles)
        for (int k = 0; k < 3; ++k) {
            const int i = t[std::size_t(k)], j = t[std::size_t((k + 1) % 3)], o = t[std::size_t((k + 2) % 3)];
            double c = 1.0;
            if (cotangent) { // edge i–j, angle at o
                const glm::dvec3 u = glm::dvec3(mesh.positions[std::size_t(i)]) - glm::dvec3(mesh.positions[std::size_t(o)]);
                const glm::dvec3 v = glm::dvec3(mesh.positions[std::size_t(j)]) - glm::dvec3(mesh.positions[std::size_t(o)]);
                c = 0.5 * glm::dot(u, v) / glm::length(glm::cross(u, v));
            }
            if (cotangent) {
                w(i, j) += c;
                w(j, i) += c;
            } else {
                w(i, j) = w(j, i) = 1.0;
            }
        }
    Eigen::MatrixXd l = Eigen::MatrixXd::Identity(n, n);
    for (Eigen::Index i = 0; i < n; ++i)
        l.row(i) -= w.row(i) / w.row(i).sum();
    return l;
}

/// Polar factor of a by SVD (a = UΣVᵀ → UVᵀ, reflection removed).
Eigen::Matrix3d dense_rotation(const Eigen::Matrix3d& a)
{
    Eigen::JacobiSVD<Eigen::Matrix3d> svd(a, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Matrix3d u = svd.matrixU();
    if ((u * svd.matrixV().transpose()).determinant() < 0)
        u.col(2) *= -1.0;
    return u * svd.matrixV().transpose();
}

TriangleMesh dense_pinch(const TriangleMesh& mesh, const std::vector<int>& roi, int h, const glm::vec3& target,
                         bool cotangent, int rotation_iterations)
{
    const auto n = Eigen::Index(mesh.vertex_count());
    const Eigen::MatrixXd l = dense_laplacian(mesh, cotangent);
    Eigen::MatrixXd x(n, 3);
    for (Eigen::Index i = 0; i < n; ++i)
        x.row(i) << mesh.positions[std::size_t(i)].x, mesh.positions[std::size_t(i)].y, mesh.positions[std::size_t(i)].z;
    const Eigen::MatrixXd delta = l * x;
    std::vector<Eigen::Index> free;
    for (int v : roi)
        if (v != h)
            free.push_back(v);
    Eigen::MatrixXd lf(n, Eigen::Index(free.size()));
    for (std::size_t k = 0; k < free.size(); ++k)
        lf.col(Eigen::Index(k)) = l.col(free[k]);
    Eigen::MatrixXd xc = x;
    for (Eigen::Index v : free)
        xc.row(v).setZero();
    xc.row(h) << target.x, target.y, target.z;
    const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(lf);
    const auto nb = neighbours(mesh);
    Eigen::MatrixXd rhs = delta;
    Eigen::MatrixXd y = xc;
    for (int it = 0; it <= rotation_iterations; ++it) {
        const Eigen::MatrixXd xf = qr.solve(rhs - l * xc);
        y = xc;
        for (std::size_t k = 0; k < free.size(); ++k)
            y.row(free[k]) = xf.row(Eigen::Index(k));
        // Rᵢ: the rotation that best maps i's 1-ring edges and its normal (weighted by the
        // ring's mean squared edge length) from before to after.
        TriangleMesh deformed = mesh;
        for (Eigen::Index i = 0; i < n; ++i)
            deformed.positions[std::size_t(i)] = glm::vec3(float(y(i, 0)), float(y(i, 1)), float(y(i, 2)));
        const auto n0 = vertex_normals(mesh);
        for (Eigen::Index i = 0; i < n; ++i) {
            Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
            double squared = 0.0;
            for (int j : nb[std::size_t(i)]) {
                a += (y.row(j) - y.row(i)).transpose() * (x.row(j) - x.row(i));
                squared += (x.row(j) - x.row(i)).squaredNorm();
            }
            glm::dvec3 n1(0.0);
            for (const auto& t : mesh.triangles)
                if (t[0] == i || t[1] == i || t[2] == i) {
                    const Eigen::Vector3d p0 = y.row(t[0]), p1 = y.row(t[1]), p2 = y.row(t[2]);
                    const Eigen::Vector3d c = (p1 - p0).cross(p2 - p0);
                    n1 += glm::dvec3(c.x(), c.y(), c.z());
                }
            n1 = glm::normalize(n1);
            const glm::dvec3 m0 = n0[std::size_t(i)];
            a += squared / double(nb[std::size_t(i)].size()) * Eigen::Vector3d(n1.x, n1.y, n1.z) *
                 Eigen::RowVector3d(m0.x, m0.y, m0.z);
            rhs.row(i) = (dense_rotation(a) * delta.row(i).transpose()).transpose();
        }
    }
    TriangleMesh out = mesh;
    for (Eigen::Index i = 0; i < n; ++i)
        out.positions[std::size_t(i)] = glm::vec3(float(y(i, 0)), float(y(i, 1)), float(y(i, 2)));
    return out;
}

} // namespace

TEST(LaplacianEdit, SolveMatchesAnIndependentDenseLeastSquaresSolveOfTheSameEnergy)
{
    // 362 vertices; a bump makes the cotangent weights uneven.
    const glm::dvec3 axis = glm::normalize(glm::dvec3(0.3, 1.0, 0.1));
    const TriangleMesh mesh = test::geodesic_sphere(6, kCentre, [&](const glm::dvec3& u) { return kRadius + bump_height(u, axis, 0.03, 0.06); });
    ASSERT_EQ(mesh.vertex_count(), 362u);
    const int h = pick_handle(mesh, glm::vec3(kCentre + 0.26 * glm::normalize(glm::dvec3(0.0, 1.0, 0.3))), 0.05);
    const glm::vec3 target = mesh.positions[std::size_t(h)] + glm::vec3(0.03f, 0.06f, -0.02f);
    for (const bool cotangent : {true, false})
        for (const bool rotations : {false, true}) {
            PinchEditOptions options;
            options.roi_radius_m = 0.2;
            options.weights = cotangent ? PinchEditOptions::Weights::Cotangent : PinchEditOptions::Weights::Uniform;
            options.rotation_invariant = rotations;
            TriangleMesh edited = mesh;
            const PinchEditor editor(edited, h, options);
            ASSERT_GT(editor.roi().size(), 40u);
            editor.drag_to(target, edited);
            const TriangleMesh dense =
                dense_pinch(mesh, editor.roi(), h, target, cotangent, rotations ? options.rotation_iterations : 0);
            double worst = 0.0;
            for (std::size_t i = 0; i < mesh.vertex_count(); ++i)
                worst = std::max(worst, distance(edited.positions[i], dense.positions[i]));
            EXPECT_LT(worst, 1e-6) << "cotangent " << cotangent << " rotations " << rotations;
        }
}

TEST(LaplacianEdit, BumpInTheRoiKeepsItsHeightProfileFarBetterThanADistanceFalloff)
{
    // A bump 1.2 cm high, σ = 1.2 cm, 5 cm from the handle; the handle is pulled 5 cm out.
    // The slope under the bump tilts; the bump should tilt with it (rotated δ), not lean
    // (a falloff moves every vertex the same way, so the bump keeps its old direction).
    const glm::dvec3 handle_dir = glm::normalize(glm::dvec3(0.0, 1.0, 0.15));
    const glm::dvec3 bump_axis = glm::normalize(handle_dir + glm::dvec3(0.2, 0.0, 0.0)); // ≈ 5 cm away
    const double height = 0.012, sigma = 0.012;
    const TriangleMesh plain = sphere();
    const TriangleMesh bumpy =
        test::geodesic_sphere(22, kCentre, [&](const glm::dvec3& u) { return kRadius + bump_height(u, bump_axis, height, sigma); });
    const int h = vertex_towards(plain, handle_dir);
    const double away = kRadius * std::acos(glm::dot(outward(plain, h), bump_axis));
    ASSERT_GT(away, 0.04);
    ASSERT_LT(away, 0.06);

    PinchEditOptions options;
    options.roi_radius_m = 0.14;
    const glm::dvec3 pull = 0.05 * outward(plain, h);
    auto laplacian = [&](const TriangleMesh& m) {
        TriangleMesh out = m;
        laplacian_deform(out, h, glm::vec3(glm::dvec3(m.positions[std::size_t(h)]) + pull), options);
        return out;
    };
    auto falloff = [&](const TriangleMesh& m) { // x′ = x + (1 − (d/r)²)² · pull
        TriangleMesh out = m;
        const auto d = edge_distances(m, h);
        for (std::size_t i = 0; i < d.size(); ++i)
            if (d[i] <= options.roi_radius_m) {
                const double t = d[i] / options.roi_radius_m;
                out.positions[i] = glm::vec3(glm::dvec3(m.positions[i]) + (1.0 - t * t) * (1.0 - t * t) * pull);
            }
        return out;
    };
    // Height profile error: the bump's offset from the (equally edited) plain sphere, against
    // its height along the edited plain sphere's normal, over the bump's vertices.
    auto profile_error = [&](const std::function<TriangleMesh(const TriangleMesh&)>& edit) {
        const TriangleMesh p = edit(plain), b = edit(bumpy);
        const auto normals = vertex_normals(p);
        double error = 0.0, total = 0.0;
        for (std::size_t i = 0; i < plain.vertex_count(); ++i) {
            const double hi = distance(bumpy.positions[i], plain.positions[i]);
            if (hi < 0.1 * height)
                continue;
            const glm::dvec3 offset = glm::dvec3(b.positions[i]) - glm::dvec3(p.positions[i]);
            error += glm::length(offset - hi * normals[i]);
            total += hi;
        }
        return error / total;
    };
    const double laplacian_error = profile_error(laplacian);
    const double falloff_error = profile_error(falloff);
    options.rotation_invariant = false;
    const double linear_error = profile_error(laplacian);
    RecordProperty("laplacian_error", std::to_string(laplacian_error));
    std::printf("height profile error: rotation-invariant Laplacian %.4f, linear Laplacian %.4f, falloff %.4f\n",
                laplacian_error, linear_error, falloff_error);
    EXPECT_GT(falloff_error, 0.15); // the falloff visibly leans the bump
    EXPECT_LT(laplacian_error, 0.2 * falloff_error);
}

TEST(PinchEdit, ReleaseKeepsTheShapeAndTheNextPinchStartsWhereItWas)
{
    const TriangleMesh before = sphere();
    TriangleMesh mesh = before;
    const int h = vertex_towards(mesh, {1.0, 0.2, 0.0});
    {
        const PinchEditor editor(mesh, h);
        editor.drag_to(mesh.positions[std::size_t(h)] + glm::vec3(0.05f, 0.0f, 0.0f), mesh);
    } // release: the editor is gone, the mesh keeps its shape
    const TriangleMesh released = mesh;
    EXPECT_FALSE(same_positions(released, before));

    // A new pinch on the edited mesh, held still, changes nothing.
    const int h2 = vertex_towards(mesh, {1.0, 0.25, 0.05});
    const PinchEditor again(mesh, h2);
    again.drag_to(mesh.positions[std::size_t(h2)], mesh);
    double worst = 0.0;
    for (std::size_t i = 0; i < mesh.vertex_count(); ++i)
        worst = std::max(worst, distance(mesh.positions[i], released.positions[i]));
    EXPECT_LT(worst, 1e-6);
}

TEST(PinchEdit, HoldingStillLeavesTheMeshWhereItWas)
{
    const TriangleMesh before = sphere();
    TriangleMesh mesh = before;
    const int h = vertex_towards(mesh, {0.0, 0.0, 1.0});
    for (const bool rotations : {false, true}) {
        PinchEditOptions options;
        options.rotation_invariant = rotations;
        const PinchEditor editor(mesh, h, options);
        editor.drag_to(before.positions[std::size_t(h)], mesh);
        double worst = 0.0;
        for (std::size_t i = 0; i < mesh.vertex_count(); ++i)
            worst = std::max(worst, distance(mesh.positions[i], before.positions[i]));
        EXPECT_LT(worst, 1e-6);
    }
}

TEST(PinchEdit, FactorOnceHundredDragsGiveTheSameResultAsAFreshEditor)
{
    const TriangleMesh before = sphere();
    TriangleMesh mesh = before;
    const int h = vertex_towards(mesh, {0.5, 0.5, -0.7});
    const PinchEditor editor(mesh, h);
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> offset(-0.04f, 0.04f);
    glm::vec3 target{};
    for (int frame = 0; frame < 100; ++frame) {
        target = before.positions[std::size_t(h)] + glm::vec3(offset(rng), offset(rng), offset(rng));
        editor.drag_to(target, mesh);
    }
    TriangleMesh fresh = before;
    laplacian_deform(fresh, h, target);
    EXPECT_TRUE(same_positions(mesh, fresh));
    EXPECT_EQ(mesh.positions[std::size_t(h)], target);
}

TEST(PinchEdit, PickHandleTakesTheNearestVertexWithinReach)
{
    const TriangleMesh mesh = sphere();
    const glm::vec3 p = mesh.positions[100] + glm::vec3(0.002f, -0.001f, 0.001f);
    EXPECT_EQ(pick_handle(mesh, p), 100);
    const glm::vec3 far = glm::vec3(kCentre + 0.29 * outward(mesh, 100)); // 4 cm off the surface
    test::expect_one_line_throw<InvalidInput>([&] { pick_handle(mesh, far, 0.03); });
    EXPECT_EQ(pick_handle(mesh, far, 0.05), 100);
    // The default reach is the pinch pick distance setting's default.
    EXPECT_EQ(pick_handle(mesh, far), 100);
    test::expect_one_line_throw<InvalidInput>([&] { pick_handle(TriangleMesh{}, p); });
    test::expect_one_line_throw<InvalidInput>([&] { pick_handle(mesh, glm::vec3(std::nanf(""), 0.f, 0.f)); });
}

TEST(PinchEdit, DegenerateInputsThrowOneLineMessagesAndLeaveTheMeshUnchanged)
{
    const TriangleMesh before = sphere(8);
    TriangleMesh mesh = before;
    const int h = 5;
    const float nan = std::numeric_limits<float>::quiet_NaN();

    test::expect_one_line_throw<InvalidInput>([&] { PinchEditor(TriangleMesh{}, 0); });
    test::expect_one_line_throw<InvalidInput>([&] { PinchEditor(mesh, -1); });
    test::expect_one_line_throw<InvalidInput>([&] { PinchEditor(mesh, int(mesh.vertex_count())); });
    PinchEditOptions tiny;
    tiny.roi_radius_m = 1e-4; // shorter than every edge: the ROI is the handle alone
    const std::string no_free = test::expect_one_line_throw<InvalidInput>([&] { PinchEditor(mesh, h, tiny); });
    EXPECT_NE(no_free.find("no free vertex"), std::string::npos) << no_free;
    PinchEditOptions bad_radius;
    bad_radius.roi_radius_m = std::nan("");
    test::expect_one_line_throw<InvalidInput>([&] { PinchEditor(mesh, h, bad_radius); });
    {
        TriangleMesh broken = mesh;
        broken.triangles[3][1] = 100000;
        test::expect_one_line_throw<InvalidInput>([&] { PinchEditor(broken, h); });
        broken = mesh;
        broken.positions[7].y = nan;
        test::expect_one_line_throw<InvalidInput>([&] { PinchEditor(broken, h); });
    }

    const PinchEditor editor(mesh, h);
    const glm::vec3 start = mesh.positions[std::size_t(h)];
    test::expect_one_line_throw<InvalidInput>([&] { editor.drag_to(glm::vec3(nan, 0.f, 0.f), mesh); });
    const std::string too_far =
        test::expect_one_line_throw<InvalidInput>([&] { editor.drag_to(start + glm::vec3(0.f, 1.01f, 0.f), mesh); });
    EXPECT_NE(too_far.find("1.01"), std::string::npos) << too_far;
    TriangleMesh other = sphere(5);
    test::expect_one_line_throw<InvalidInput>([&] { editor.drag_to(start, other); });
    test::expect_one_line_throw<InvalidInput>([&] { laplacian_deform(mesh, h, start + glm::vec3(0.f, 0.f, 1.5f)); });
    EXPECT_TRUE(same_positions(mesh, before));

    // Every vertex in one point: all cotangent weights vanish and the system is singular.
    TriangleMesh collapsed = before;
    std::fill(collapsed.positions.begin(), collapsed.positions.end(), glm::vec3(0.1f, 1.0f, 0.0f));
    const TriangleMesh collapsed_before = collapsed;
    test::expect_one_line_throw<SolverError>([&] { laplacian_deform(collapsed, h, glm::vec3(0.1f, 1.05f, 0.0f)); });
    EXPECT_TRUE(same_positions(collapsed, collapsed_before));
}
