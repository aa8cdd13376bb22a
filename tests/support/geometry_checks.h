#pragma once
// Property checks on SurfaceGeometry shared by the branch and leaf tests.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <unordered_map>
#include <vector>

#include <glm/geometric.hpp>

#include "growth/tree_geometry.h"

namespace lobe::test {

inline bool all_finite(const SurfaceGeometry& g)
{
    for (const glm::vec3& p : g.positions)
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) return false;
    for (const glm::vec3& n : g.normals)
        if (!std::isfinite(n.x) || !std::isfinite(n.y) || !std::isfinite(n.z)) return false;
    for (const glm::vec2& t : g.uvs)
        if (!std::isfinite(t.x) || !std::isfinite(t.y)) return false;
    return true;
}

inline bool indices_valid(const SurfaceGeometry& g)
{
    if (g.normals.size() != g.positions.size() || g.uvs.size() != g.positions.size()) return false;
    for (const auto& t : g.triangles)
        for (std::uint32_t i : t)
            if (i >= g.positions.size()) return false;
    return true;
}

/// Largest | |n| − 1 | over the normals.
inline double worst_normal_length_error(const SurfaceGeometry& g)
{
    double worst = 0.0;
    for (const glm::vec3& n : g.normals) worst = std::max(worst, std::abs(static_cast<double>(glm::length(n)) - 1.0));
    return worst;
}

inline double triangle_area(const SurfaceGeometry& g, const std::array<std::uint32_t, 3>& t)
{
    const glm::dvec3 a(g.positions[t[0]]), b(g.positions[t[1]]), c(g.positions[t[2]]);
    return 0.5 * glm::length(glm::cross(b - a, c - a));
}

inline double smallest_triangle_area(const SurfaceGeometry& g)
{
    double smallest = 1e30;
    for (const auto& t : g.triangles) smallest = std::min(smallest, triangle_area(g, t));
    return smallest;
}

/// Number of vertex pairs closer than `tolerance` (grid hashing with cells of 10 × tolerance).
inline std::size_t coincident_vertex_pairs(const SurfaceGeometry& g, double tolerance = 1e-7)
{
    const double cell = tolerance * 10.0;
    auto key = [](long long x, long long y, long long z) {
        return static_cast<std::uint64_t>(x) * 0x9E3779B97F4A7C15ull ^ static_cast<std::uint64_t>(y) * 0xC2B2AE3D27D4EB4Full ^
               static_cast<std::uint64_t>(z) * 0x165667B19E3779F9ull;
    };
    std::unordered_multimap<std::uint64_t, std::uint32_t> grid;
    grid.reserve(g.positions.size() * 2);
    std::size_t pairs = 0;
    const double tol2 = tolerance * tolerance;
    for (std::uint32_t i = 0; i < g.positions.size(); ++i) {
        const glm::dvec3 p(g.positions[i]);
        const auto cx = static_cast<long long>(std::floor(p.x / cell)), cy = static_cast<long long>(std::floor(p.y / cell)),
                   cz = static_cast<long long>(std::floor(p.z / cell));
        for (long long dx = -1; dx <= 1; ++dx)
            for (long long dy = -1; dy <= 1; ++dy)
                for (long long dz = -1; dz <= 1; ++dz) {
                    auto range = grid.equal_range(key(cx + dx, cy + dy, cz + dz));
                    for (auto it = range.first; it != range.second; ++it) {
                        const glm::dvec3 d = glm::dvec3(g.positions[it->second]) - p;
                        if (glm::dot(d, d) < tol2) ++pairs;
                    }
                }
        grid.emplace(key(cx, cy, cz), i);
    }
    return pairs;
}

/// Axis-aligned bounds of the positions.
struct Bounds {
    glm::dvec3 lo{1e30}, hi{-1e30};
    glm::dvec3 extent() const { return hi - lo; }
};

inline Bounds bounds_of(const SurfaceGeometry& g)
{
    Bounds b;
    for (const glm::vec3& p : g.positions) {
        b.lo = glm::min(b.lo, glm::dvec3(p));
        b.hi = glm::max(b.hi, glm::dvec3(p));
    }
    return b;
}

inline double total_area(const SurfaceGeometry& g)
{
    double a = 0.0;
    for (const auto& t : g.triangles) a += triangle_area(g, t);
    return a;
}

/// Byte-for-byte equality of two meshes.
inline bool same_bytes(const SurfaceGeometry& a, const SurfaceGeometry& b)
{
    auto eq = [](const auto& x, const auto& y) {
        return x.size() == y.size() && (x.empty() || std::memcmp(x.data(), y.data(), x.size() * sizeof(x[0])) == 0);
    };
    return eq(a.positions, b.positions) && eq(a.normals, b.normals) && eq(a.uvs, b.uvs) && eq(a.triangles, b.triangles);
}

} // namespace lobe::test
