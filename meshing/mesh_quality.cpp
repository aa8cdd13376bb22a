#include "meshing/mesh_quality.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>

#include "core/errors.h"
#include "meshing/triangle_distance.h"

namespace lobe {

namespace {

constexpr double kPi = 3.14159265358979323846;

glm::dvec3 pos(const TriangleMesh& m, int v) { return glm::dvec3(m.positions[static_cast<std::size_t>(v)]); }

void check_mesh(const TriangleMesh& mesh, const char* who)
{
    if (mesh.triangles.empty()) throw InvalidInput(std::string(who) + ": mesh has no triangle");
    const auto n = static_cast<long long>(mesh.positions.size());
    for (const auto& t : mesh.triangles)
        for (int v : t)
            if (v < 0 || v >= n) throw InvalidInput(std::string(who) + ": triangle index out of range");
}

/// Interior angle at `a` of triangle (a, b, c), degrees; 0 for a degenerate corner.
double corner_angle(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c)
{
    const glm::dvec3 u = b - a, v = c - a;
    const double s = glm::length(glm::cross(u, v)), d = glm::dot(u, v);
    return std::atan2(s, d) * 180.0 / kPi;
}

std::uint64_t edge_key(int a, int b)
{
    const auto lo = static_cast<std::uint32_t>(std::min(a, b)), hi = static_cast<std::uint32_t>(std::max(a, b));
    return (static_cast<std::uint64_t>(lo) << 32) | hi;
}

int find_root(std::vector<int>& parent, int x)
{
    while (parent[static_cast<std::size_t>(x)] != x) {
        parent[static_cast<std::size_t>(x)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(x)])];
        x = parent[static_cast<std::size_t>(x)];
    }
    return x;
}

} // namespace

void bounding_box(const TriangleMesh& mesh, glm::dvec3& lo, glm::dvec3& hi)
{
    if (mesh.positions.empty()) throw InvalidInput("bounding_box: mesh has no vertex");
    lo = hi = glm::dvec3(mesh.positions.front());
    for (const glm::vec3& p : mesh.positions) {
        lo = glm::min(lo, glm::dvec3(p));
        hi = glm::max(hi, glm::dvec3(p));
    }
}

MeshQuality measure_quality(const TriangleMesh& mesh)
{
    check_mesh(mesh, "measure_quality");
    MeshQuality q;
    q.vertices = mesh.positions.size();
    q.triangles = mesh.triangles.size();

    // Angles and volume.
    q.min_angle_deg = 180.0;
    std::size_t good = 0;
    double volume6 = 0;
    for (const auto& t : mesh.triangles) {
        const glm::dvec3 a = pos(mesh, t[0]), b = pos(mesh, t[1]), c = pos(mesh, t[2]);
        // The smallest angle faces the shortest edge, the largest the longest.
        const double ab = glm::dot(b - a, b - a), bc = glm::dot(c - b, c - b), ca = glm::dot(a - c, a - c);
        const double lo = bc <= ab && bc <= ca ? corner_angle(a, b, c) : (ca <= ab ? corner_angle(b, c, a) : corner_angle(c, a, b));
        const double hi = bc >= ab && bc >= ca ? corner_angle(a, b, c) : (ca >= ab ? corner_angle(b, c, a) : corner_angle(c, a, b));
        q.min_angle_deg = std::min(q.min_angle_deg, lo);
        q.max_angle_deg = std::max(q.max_angle_deg, hi);
        if (lo >= 30.0) ++good;
        if (lo < 15.0) ++q.count_angle_lt_15;
        volume6 += glm::dot(a, glm::cross(b, c));
    }
    q.share_all_angles_ge_30 = static_cast<double>(good) / static_cast<double>(q.triangles);
    q.signed_volume_m3 = volume6 / 6.0;

    // Edges: incidence counts and directions. Every corner's outgoing edge as (undirected
    // key, runs from the smaller index), sorted, so each edge's uses lie side by side.
    std::vector<std::pair<std::uint64_t, bool>> uses;
    uses.reserve(mesh.triangles.size() * 3);
    for (const auto& t : mesh.triangles)
        for (int k = 0; k < 3; ++k) {
            const int a = t[static_cast<std::size_t>(k)], b = t[static_cast<std::size_t>((k + 1) % 3)];
            uses.emplace_back(edge_key(a, b), a < b);
        }
    std::sort(uses.begin(), uses.end());
    double sum = 0, sum2 = 0;
    std::size_t edge_count = 0;
    q.edge_min_m = std::numeric_limits<double>::max();
    for (std::size_t i = 0; i < uses.size();) {
        std::size_t j = i;
        int forward = 0;
        for (; j < uses.size() && uses[j].first == uses[i].first; ++j) forward += uses[j].second ? 1 : 0;
        const int count = static_cast<int>(j - i);
        const int ea = static_cast<int>(uses[i].first >> 32), eb = static_cast<int>(uses[i].first & 0xffffffffu);
        const double len = glm::length(pos(mesh, ea) - pos(mesh, eb));
        q.edge_min_m = std::min(q.edge_min_m, len);
        q.edge_max_m = std::max(q.edge_max_m, len);
        sum += len;
        sum2 += len * len;
        ++edge_count;
        if (count == 1) ++q.boundary_edges;
        if (count > 2) ++q.non_manifold_edges;
        if (count == 2 && forward != 1) ++q.inconsistent_edges;
        i = j;
    }
    const double n = static_cast<double>(edge_count);
    q.edge_mean_m = sum / n;
    q.edge_stddev_m = std::sqrt(std::max(0.0, sum2 / n - q.edge_mean_m * q.edge_mean_m));

    // Vertex fans: the triangles around a vertex, joined through shared edges, must form one
    // fan. Count per vertex the incident triangles and the fan pieces (union-find over the
    // triangle corners that share an edge at that vertex: corners listing the same other
    // vertex, found side by side after sorting).
    const std::size_t nv = mesh.positions.size();
    std::vector<int> corner_start(nv + 1, 0);
    for (const auto& t : mesh.triangles)
        for (int v : t) ++corner_start[static_cast<std::size_t>(v) + 1];
    std::partial_sum(corner_start.begin(), corner_start.end(), corner_start.begin());
    std::vector<int> corner_tri(corner_start.back());
    {
        std::vector<int> fill(corner_start.begin(), corner_start.end() - 1);
        for (std::size_t f = 0; f < mesh.triangles.size(); ++f)
            for (int v : mesh.triangles[f]) corner_tri[static_cast<std::size_t>(fill[static_cast<std::size_t>(v)]++)] = static_cast<int>(f);
    }
    std::vector<int> parent;
    std::vector<std::pair<int, int>> others; // (other vertex, local corner)
    for (std::size_t v = 0; v < nv; ++v) {
        const int b = corner_start[v], e = corner_start[v + 1];
        if (e - b == 0) continue;
        others.clear();
        parent.resize(static_cast<std::size_t>(e - b));
        std::iota(parent.begin(), parent.end(), 0);
        for (int i = b; i < e; ++i) {
            const auto& t = mesh.triangles[static_cast<std::size_t>(corner_tri[static_cast<std::size_t>(i)])];
            for (int w : t)
                if (w != static_cast<int>(v)) others.emplace_back(w, i - b);
        }
        std::sort(others.begin(), others.end());
        for (std::size_t k = 1; k < others.size(); ++k)
            if (others[k].first == others[k - 1].first) {
                const int ra = find_root(parent, others[k - 1].second), rb = find_root(parent, others[k].second);
                if (ra != rb) parent[static_cast<std::size_t>(ra)] = rb;
            }
        int pieces = 0;
        for (int i = 0; i < e - b; ++i)
            if (find_root(parent, i) == i) ++pieces;
        if (pieces > 1) ++q.non_manifold_vertices;
    }

    // Components over shared vertices.
    parent.resize(nv);
    std::iota(parent.begin(), parent.end(), 0);
    for (const auto& t : mesh.triangles)
        for (int k = 1; k < 3; ++k) {
            const int ra = find_root(parent, t[0]), rb = find_root(parent, t[static_cast<std::size_t>(k)]);
            if (ra != rb) parent[static_cast<std::size_t>(ra)] = rb;
        }
    std::vector<char> used(nv, 0);
    for (const auto& t : mesh.triangles)
        for (int v : t) used[static_cast<std::size_t>(v)] = 1;
    for (std::size_t v = 0; v < nv; ++v)
        if (used[v] && find_root(parent, static_cast<int>(v)) == static_cast<int>(v)) ++q.components;

    q.closed = q.boundary_edges == 0;
    q.manifold = q.non_manifold_edges == 0 && q.non_manifold_vertices == 0 && q.inconsistent_edges == 0;
    q.outward = q.closed && q.signed_volume_m3 > 0;
    return q;
}

double max_vertex_distance(const TriangleMesh& from, const TriangleMesh& to)
{
    check_mesh(to, "max_vertex_distance");
    glm::dvec3 lo, hi;
    bounding_box(to, lo, hi);
    // Cell size: about twice the mean edge, and at most 64 cells per axis so that memory
    // stays small.
    double mean_edge = 0;
    for (const auto& t : to.triangles) mean_edge += glm::length(pos(to, t[0]) - pos(to, t[1]));
    mean_edge /= static_cast<double>(to.triangles.size());
    const glm::dvec3 ext = hi - lo;
    double cell = std::max({mean_edge * 2.0, std::max({ext.x, ext.y, ext.z}) / 64.0, 1e-9});
    const glm::ivec3 dims = glm::ivec3(glm::max(glm::dvec3(1.0), glm::ceil(ext / cell + 1e-9)));
    auto cell_of = [&](const glm::dvec3& p) {
        return glm::clamp(glm::ivec3(glm::floor((p - lo) / cell)), glm::ivec3(0), dims - 1);
    };
    auto cell_index = [&](const glm::ivec3& c) {
        return (static_cast<std::size_t>(c.z) * static_cast<std::size_t>(dims.y) + static_cast<std::size_t>(c.y)) *
                   static_cast<std::size_t>(dims.x) + static_cast<std::size_t>(c.x);
    };
    const std::size_t ncells = static_cast<std::size_t>(dims.x) * static_cast<std::size_t>(dims.y) * static_cast<std::size_t>(dims.z);
    std::vector<std::vector<int>> cells(ncells);
    for (std::size_t f = 0; f < to.triangles.size(); ++f) {
        const auto& t = to.triangles[f];
        const glm::dvec3 a = pos(to, t[0]), b = pos(to, t[1]), c = pos(to, t[2]);
        const glm::ivec3 c0 = cell_of(glm::min(a, glm::min(b, c))), c1 = cell_of(glm::max(a, glm::max(b, c)));
        for (int z = c0.z; z <= c1.z; ++z)
            for (int y = c0.y; y <= c1.y; ++y)
                for (int x = c0.x; x <= c1.x; ++x) cells[cell_index({x, y, z})].push_back(static_cast<int>(f));
    }

    // For each query point, search the cells within a cube of half-side r around it; a
    // triangle nearer than r has its bounding box overlap that cube, so once the best found
    // is ≤ r it is exact. Otherwise double r.
    std::vector<int> stamp(to.triangles.size(), -1);
    double worst = 0;
    for (std::size_t qi = 0; qi < from.positions.size(); ++qi) {
        const glm::dvec3 p(from.positions[qi]);
        double best = std::numeric_limits<double>::max();
        for (double r = cell;; r *= 2.0) {
            const glm::ivec3 c0 = cell_of(p - r), c1 = cell_of(p + r);
            for (int z = c0.z; z <= c1.z; ++z)
                for (int y = c0.y; y <= c1.y; ++y)
                    for (int x = c0.x; x <= c1.x; ++x)
                        for (int f : cells[cell_index({x, y, z})]) {
                            if (stamp[static_cast<std::size_t>(f)] == static_cast<int>(qi)) continue;
                            stamp[static_cast<std::size_t>(f)] = static_cast<int>(qi);
                            const auto& t = to.triangles[static_cast<std::size_t>(f)];
                            best = std::min(best, point_triangle_distance(p, pos(to, t[0]), pos(to, t[1]), pos(to, t[2])));
                        }
            const bool covers_all = c0 == glm::ivec3(0) && c1 == dims - 1;
            if (best <= r || covers_all) break;
        }
        worst = std::max(worst, best);
    }
    return worst;
}

} // namespace lobe
