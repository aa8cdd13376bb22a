#include "meshing/model_import.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include <glm/common.hpp>
#include <glm/vec3.hpp>

#include "core/errors.h"
#include "meshing/mesh_quality.h"

namespace lobe {

TriangleMesh normalize_to_box(const TriangleMesh& mesh, double size_m)
{
    if (!(size_m > 0) || !std::isfinite(size_m)) throw InvalidInput("normalize_to_box: size must be a positive number");
    if (mesh.positions.empty()) throw InvalidInput("normalize_to_box: mesh has no vertex");
    for (const glm::vec3& p : mesh.positions)
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
            throw InvalidInput("normalize_to_box: vertex with a non-finite coordinate");
    glm::dvec3 lo, hi;
    bounding_box(mesh, lo, hi);
    const glm::dvec3 ext = hi - lo;
    const double largest = std::max({ext.x, ext.y, ext.z});
    if (!(largest > 0)) throw InvalidInput("normalize_to_box: mesh has zero extent");
    const double s = size_m / largest;
    // Base centred on the origin: x and z centred, lowest point at y = 0.
    const glm::dvec3 anchor(0.5 * (lo.x + hi.x), lo.y, 0.5 * (lo.z + hi.z));
    TriangleMesh out = mesh;
    for (glm::vec3& p : out.positions) p = glm::vec3((glm::dvec3(p) - anchor) * s);
    return out;
}

TriangleMesh cluster_vertices(const TriangleMesh& mesh, double cell)
{
    using Index = std::size_t;
    std::vector<char> used(mesh.positions.size(), 0);
    for (const auto& t : mesh.triangles)
        for (int v : t) {
            if (v < 0 || static_cast<Index>(v) >= mesh.positions.size())
                throw InvalidInput("cluster_vertices: triangle index out of range");
            used[static_cast<Index>(v)] = 1;
        }
    glm::dvec3 lo(0.0);
    bool any = false;
    for (Index v = 0; v < mesh.positions.size(); ++v)
        if (used[v]) {
            lo = any ? glm::min(lo, glm::dvec3(mesh.positions[v])) : glm::dvec3(mesh.positions[v]);
            any = true;
        }
    // Cube coordinates of 20 bits each (a million cubes a side: far more than any caller
    // asks for), packed into one key; vertices sorted by key are grouped by cube.
    constexpr double kMaxCoord = (1 << 20) - 1;
    auto coord = [&](double x, double origin) {
        return static_cast<std::uint64_t>(std::min(kMaxCoord, std::floor((x - origin) / cell)));
    };
    std::vector<std::pair<std::uint64_t, int>> keyed;
    for (Index v = 0; v < mesh.positions.size(); ++v) {
        if (!used[v]) continue;
        const glm::vec3& p = mesh.positions[v];
        keyed.emplace_back(coord(p.x, lo.x) | coord(p.y, lo.y) << 20 | coord(p.z, lo.z) << 40, static_cast<int>(v));
    }
    std::sort(keyed.begin(), keyed.end());
    TriangleMesh out;
    std::vector<int> cluster(mesh.positions.size(), -1);
    for (Index i = 0; i < keyed.size();) {
        Index j = i;
        glm::dvec3 sum(0.0);
        for (; j < keyed.size() && keyed[j].first == keyed[i].first; ++j) {
            sum += glm::dvec3(mesh.positions[static_cast<Index>(keyed[j].second)]);
            cluster[static_cast<Index>(keyed[j].second)] = static_cast<int>(out.positions.size());
        }
        out.positions.emplace_back(sum / static_cast<double>(j - i));
        i = j;
    }
    // Triangles on three cubes; those on the same three as another (either way round: a thin
    // part or fold the grid flattened into two coincident triangles) are all dropped, which
    // leaves a small hole or nothing instead of a fin that is not 2-manifold.
    std::vector<std::pair<std::array<int, 3>, Index>> sorted; // (corners in increasing order, triangle)
    std::vector<std::array<int, 3>> kept;
    for (const auto& t : mesh.triangles) {
        const std::array<int, 3> c{cluster[static_cast<Index>(t[0])], cluster[static_cast<Index>(t[1])],
                                   cluster[static_cast<Index>(t[2])]};
        if (c[0] == c[1] || c[1] == c[2] || c[0] == c[2]) continue;
        std::array<int, 3> k = c;
        std::sort(k.begin(), k.end());
        sorted.emplace_back(k, kept.size());
        kept.push_back(c);
    }
    std::sort(sorted.begin(), sorted.end());
    std::vector<char> alone(kept.size(), 1);
    for (Index i = 0; i + 1 < sorted.size(); ++i)
        if (sorted[i].first == sorted[i + 1].first) alone[sorted[i].second] = alone[sorted[i + 1].second] = 0;
    // Then every triangle on an edge that more than two triangles share (two sheets the grid
    // pinched together), and where two triangles run round an edge the same way: what is left
    // is 2-manifold along its edges, with small holes where such triangles were.
    std::vector<std::array<int, 3>> edges; // (lower, higher, direction)
    for (Index i = 0; i < kept.size(); ++i) {
        if (!alone[i]) continue;
        for (Index k = 0; k < 3; ++k) {
            const int a = kept[i][k], b = kept[i][(k + 1) % 3];
            edges.push_back({std::min(a, b), std::max(a, b), a < b ? 1 : 0});
        }
    }
    std::sort(edges.begin(), edges.end());
    std::vector<std::array<int, 2>> bad; // edges to drop the triangles of
    for (Index i = 0; i < edges.size();) {
        Index j = i;
        int forward = 0;
        while (j < edges.size() && edges[j][0] == edges[i][0] && edges[j][1] == edges[i][1]) forward += edges[j++][2];
        const Index count = j - i;
        if (count > 2 || (count == 2 && forward != 1)) bad.push_back({edges[i][0], edges[i][1]});
        i = j;
    }
    for (Index i = 0; i < kept.size(); ++i) {
        if (!alone[i]) continue;
        bool on_bad = false;
        for (Index k = 0; k < 3 && !on_bad; ++k) {
            const int a = kept[i][k], b = kept[i][(k + 1) % 3];
            on_bad = std::binary_search(bad.begin(), bad.end(), std::array<int, 2>{std::min(a, b), std::max(a, b)});
        }
        if (!on_bad) out.triangles.push_back(kept[i]);
    }
    return out;
}

} // namespace lobe
