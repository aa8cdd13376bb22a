#include "tests/support/shapes.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <map>
#include <stdexcept>
#include <tuple>
#include <utility>

#include <glm/geometric.hpp>

namespace lobe::test {
namespace {

constexpr double kPi = 3.14159265358979323846;

/// The icosahedron with vertices (0, ±1, ±φ) and their cyclic permutations (not normalised),
/// its 20 faces counter-clockwise seen from outside.
std::vector<glm::dvec3> icosahedron_vertices()
{
    const double t = (1.0 + std::sqrt(5.0)) / 2.0;
    return {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
            {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
}

const std::vector<std::array<int, 3>> kIcosahedronFaces = {
    {0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9},  {5, 11, 4},
    {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},   {3, 4, 2},  {3, 2, 6},   {3, 6, 8},
    {3, 8, 9},  {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};

RadiusOfDirection constant(double radius)
{
    return [radius](const glm::dvec3&) { return radius; };
}

} // namespace

TriangleMesh icosphere(int levels, double radius, glm::dvec3 centre)
{
    return icosphere(levels, constant(radius), centre);
}

TriangleMesh icosphere(int levels, const RadiusOfDirection& radius, glm::dvec3 centre)
{
    std::vector<glm::dvec3> p = icosahedron_vertices();
    std::vector<std::array<int, 3>> f = kIcosahedronFaces;
    for (int l = 0; l < levels; ++l) {
        std::map<std::pair<int, int>, int> mid;
        auto midpoint = [&](int a, int b) {
            const auto key = std::make_pair(std::min(a, b), std::max(a, b));
            auto it = mid.find(key);
            if (it != mid.end()) return it->second;
            p.push_back(0.5 * (p[static_cast<std::size_t>(a)] + p[static_cast<std::size_t>(b)]));
            return mid[key] = static_cast<int>(p.size()) - 1;
        };
        std::vector<std::array<int, 3>> g;
        for (const auto& tri : f) {
            const int ab = midpoint(tri[0], tri[1]), bc = midpoint(tri[1], tri[2]), ca = midpoint(tri[2], tri[0]);
            g.push_back({tri[0], ab, ca});
            g.push_back({tri[1], bc, ab});
            g.push_back({tri[2], ca, bc});
            g.push_back({ab, bc, ca});
        }
        f = std::move(g);
    }
    TriangleMesh m;
    for (const auto& q : p) {
        const glm::dvec3 u = glm::normalize(q);
        m.positions.emplace_back(centre + radius(u) * u);
    }
    m.triangles = f;
    return m;
}

TriangleMesh geodesic_sphere(int frequency, glm::dvec3 centre, double radius)
{
    return geodesic_sphere(frequency, centre, constant(radius));
}

TriangleMesh geodesic_sphere(int frequency, glm::dvec3 centre, const RadiusOfDirection& radius)
{
    const std::vector<glm::dvec3> ico = icosahedron_vertices();
    TriangleMesh mesh;
    // Grid points on shared edges are met once per face: keyed by their direction.
    std::map<std::tuple<long long, long long, long long>, int> index;
    auto vertex = [&](const glm::dvec3& p) {
        const glm::dvec3 u = glm::normalize(p);
        const auto key = std::make_tuple(std::llround(u.x * 1e7), std::llround(u.y * 1e7), std::llround(u.z * 1e7));
        const auto [it, added] = index.emplace(key, int(mesh.positions.size()));
        if (added)
            mesh.positions.emplace_back(centre + radius(u) * u);
        return it->second;
    };
    const int n = frequency;
    for (auto f : kIcosahedronFaces) {
        const glm::dvec3 a = ico[std::size_t(f[0])], b = ico[std::size_t(f[1])], c = ico[std::size_t(f[2])];
        if (glm::dot(glm::cross(b - a, c - a), a + b + c) < 0.0)
            throw std::logic_error("icosahedron face not counter-clockwise");
        auto at = [&](int i, int j) { return vertex(a + (b - a) * (double(i) / n) + (c - a) * (double(j) / n)); };
        for (int i = 0; i < n; ++i)
            for (int j = 0; i + j < n; ++j) {
                mesh.triangles.push_back({at(i, j), at(i + 1, j), at(i, j + 1)});
                if (i + j + 1 < n)
                    mesh.triangles.push_back({at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)});
            }
    }
    return mesh;
}

TriangleMesh uv_sphere(int rings, int segments, double radius, std::vector<int>& equator)
{
    const double r = radius;
    TriangleMesh m;
    m.positions.emplace_back(0.f, static_cast<float>(r), 0.f);
    for (int i = 1; i < rings; ++i) {
        const double th = kPi * i / rings;
        for (int j = 0; j < segments; ++j) {
            const double ph = 2.0 * kPi * j / segments;
            m.positions.emplace_back(glm::dvec3(r * std::sin(th) * std::cos(ph), r * std::cos(th), r * std::sin(th) * std::sin(ph)));
        }
    }
    m.positions.emplace_back(0.f, static_cast<float>(-r), 0.f);
    const int south = static_cast<int>(m.positions.size()) - 1;
    auto at = [&](int ring, int j) { return 1 + (ring - 1) * segments + (j % segments); };
    for (int j = 0; j < segments; ++j) m.triangles.push_back({0, at(1, j + 1), at(1, j)});
    for (int i = 1; i + 1 < rings; ++i)
        for (int j = 0; j < segments; ++j) {
            m.triangles.push_back({at(i, j), at(i, j + 1), at(i + 1, j + 1)});
            m.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i + 1, j)});
        }
    for (int j = 0; j < segments; ++j) m.triangles.push_back({south, at(rings - 1, j), at(rings - 1, j + 1)});
    equator.clear();
    for (int j = 0; j < segments; ++j) equator.push_back(at(rings / 2, j));
    for (int j = 0; j < segments; ++j)
        m.feature_edges.push_back({equator[static_cast<std::size_t>(j)], equator[static_cast<std::size_t>((j + 1) % segments)]});
    return m;
}

TriangleMesh octahedron(glm::vec3 centre, float radius)
{
    const glm::vec3 c = centre;
    const float r = radius;
    TriangleMesh m;
    m.positions = {c + glm::vec3(r, 0, 0), c - glm::vec3(r, 0, 0), c + glm::vec3(0, r, 0),
                   c - glm::vec3(0, r, 0), c + glm::vec3(0, 0, r), c - glm::vec3(0, 0, r)};
    m.triangles = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
    return m;
}

TruthSurface ellipsoid_surface(glm::dvec3 centre, glm::dvec3 radii)
{
    TruthSurface s;
    s.center = centre;
    s.radii = radii;
    return s;
}

TriangleMesh ellipsoid(glm::dvec3 centre, glm::dvec3 radii, int subdivisions)
{
    return truth_surface_mesh(ellipsoid_surface(centre, radii), subdivisions);
}

std::vector<glm::dvec3> sphere_directions(int n)
{
    std::vector<glm::dvec3> out;
    for (int i = 0; i < n; ++i) {
        const double z = 1.0 - (2.0 * i + 1.0) / n;
        const double rho = std::sqrt(1.0 - z * z);
        const double phi = kPi * (3.0 - std::sqrt(5.0)) * i;
        out.emplace_back(rho * std::cos(phi), rho * std::sin(phi), z);
    }
    return out;
}

std::vector<glm::vec3> raw_loop(const glm::dvec3& centre, const glm::dvec3& u, const glm::dvec3& v, double radius,
                                int seed)
{
    const double r = radius;
    const int n = static_cast<int>(2 * kPi * r / 0.005);
    std::vector<glm::vec3> out;
    for (int i = 0; i < n; ++i) {
        const double t = 2 * kPi * i / n;
        const double w = 0.001 * std::sin(7 * t + seed);
        out.emplace_back(centre + (r + w) * (std::cos(t) * u + std::sin(t) * v));
    }
    return out;
}

std::vector<std::vector<glm::vec3>> ten_stroke_lobe()
{
    const glm::dvec3 c(0.0, 1.4, -0.45);
    const double r = 0.2;
    std::vector<std::vector<glm::vec3>> s;
    for (int k = 0; k < 6; ++k) {
        const double a = k * kPi / 6;
        s.push_back(raw_loop(c, {0, 1, 0}, {std::cos(a), 0, std::sin(a)}, r, k));
    }
    for (double h : {-0.15, -0.08, 0.08, 0.15})
        s.push_back(raw_loop(c + glm::dvec3(0, h, 0), {1, 0, 0}, {0, 0, 1}, std::sqrt(r * r - h * h), static_cast<int>(h * 100)));
    return s;
}

} // namespace lobe::test
