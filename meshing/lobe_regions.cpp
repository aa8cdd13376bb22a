#include "meshing/lobe_regions.h"

#include <algorithm>
#include <array>
#include <map>
#include <numeric>
#include <tuple>

#include <glm/geometric.hpp>

namespace lobe {

namespace {

using Index = std::size_t;
using Key3 = std::array<float, 3>;
using DirectedEdge = RegionStrokeEdge;

Key3 key_of(const glm::vec3& p) { return {p.x, p.y, p.z}; }

/// Edges bucketed by their lower vertex (a counting sort: a vertex has a handful), so that
/// finding an edge is a scan of a few entries instead of a search in all of them. This runs
/// twice for every stroke added to a lobe; sorted arrays made the region bookkeeping a third
/// of the time of adding a stroke.
struct EdgeBuckets {
    std::vector<int> start;                   ///< #V + 1
    std::vector<std::array<int, 2>> entries;  ///< (higher vertex, payload)

    template <class ForEach>
    EdgeBuckets(Index vertices, Index count, ForEach&& for_each) : start(vertices + 1, 0), entries(count)
    {
        for_each([&](int a, int b, int) { ++start[static_cast<Index>(std::min(a, b)) + 1]; });
        for (Index i = 1; i < start.size(); ++i) start[i] += start[i - 1];
        std::vector<int> next(start.begin(), start.end() - 1);
        for_each([&](int a, int b, int payload) {
            entries[static_cast<Index>(next[static_cast<Index>(std::min(a, b))]++)] = {std::max(a, b), payload};
        });
    }
    /// The payload of edge (a, b), or −1.
    int find(int a, int b) const
    {
        const Index lo = static_cast<Index>(std::min(a, b));
        const int hi = std::max(a, b);
        for (int i = start[lo]; i < start[lo + 1]; ++i)
            if (entries[static_cast<Index>(i)][0] == hi) return entries[static_cast<Index>(i)][1];
        return -1;
    }
};

/// Whether each vertex lies on a feature edge, and whether an edge is one.
struct Features {
    std::vector<char> on_vertex;
    EdgeBuckets edges;

    explicit Features(const TriangleMesh& mesh)
        : on_vertex(mesh.positions.size(), 0),
          edges(mesh.positions.size(), mesh.feature_edges.size(), [&](auto&& f) {
              for (const auto& e : mesh.feature_edges) f(e[0], e[1], 1);
          })
    {
        for (const auto& e : mesh.feature_edges) on_vertex[static_cast<Index>(e[0])] = on_vertex[static_cast<Index>(e[1])] = 1;
    }
    bool has(int a, int b) const { return on_vertex[static_cast<Index>(a)] && on_vertex[static_cast<Index>(b)] && edges.find(a, b) >= 0; }
};

MeshRegions regions_of(const TriangleMesh& mesh, const Features& features)
{
    const Index nf = mesh.triangles.size();
    std::vector<int> parent(nf);
    std::iota(parent.begin(), parent.end(), 0);
    auto find = [&](int x) {
        while (parent[static_cast<Index>(x)] != x)
            x = parent[static_cast<Index>(x)] = parent[static_cast<Index>(parent[static_cast<Index>(x)])];
        return x;
    };
    // Every edge with one face; the second face of an edge joins the first's region.
    const EdgeBuckets edges(mesh.positions.size(), 3 * nf, [&](auto&& f) {
        for (Index i = 0; i < nf; ++i)
            for (Index k = 0; k < 3; ++k) f(mesh.triangles[i][k], mesh.triangles[i][(k + 1) % 3], static_cast<int>(i));
    });
    for (Index v = 0; v + 1 < edges.start.size(); ++v) {
        const int begin = edges.start[v], end = edges.start[v + 1];
        for (int i = begin; i < end; ++i)
            for (int j = i + 1; j < end; ++j) {
                const auto& e = edges.entries[static_cast<Index>(i)];
                const auto& g = edges.entries[static_cast<Index>(j)];
                if (e[0] != g[0] || features.has(static_cast<int>(v), e[0])) continue;
                const int a = find(e[1]), b = find(g[1]);
                if (a != b) parent[static_cast<Index>(std::max(a, b))] = std::min(a, b);
            }
    }
    MeshRegions out;
    out.face_region.assign(nf, -1);
    std::vector<int> region_of_root(nf, -1);
    for (Index f = 0; f < nf; ++f) {
        int& r = region_of_root[static_cast<Index>(find(static_cast<int>(f)))];
        if (r < 0) r = out.count++;
        out.face_region[f] = r;
    }
    return out;
}

/// Each region's stroke edges, directed as its triangles run round them, sorted.
std::vector<std::vector<DirectedEdge>> region_keys(const TriangleMesh& mesh, const Features& features,
                                                   const MeshRegions& regions)
{
    std::vector<std::vector<DirectedEdge>> keys(static_cast<Index>(regions.count));
    for (Index f = 0; f < mesh.triangles.size(); ++f) {
        const auto& t = mesh.triangles[f];
        for (int k = 0; k < 3; ++k) {
            const int a = t[static_cast<Index>(k)], b = t[static_cast<Index>((k + 1) % 3)];
            if (!features.has(a, b)) continue;
            const glm::vec3& p = mesh.positions[static_cast<Index>(a)];
            const glm::vec3& q = mesh.positions[static_cast<Index>(b)];
            keys[static_cast<Index>(regions.face_region[f])].push_back({p.x, p.y, p.z, q.x, q.y, q.z});
        }
    }
    for (auto& k : keys) std::sort(k.begin(), k.end());
    return keys;
}

} // namespace

MeshRegions mesh_regions(const TriangleMesh& mesh) { return regions_of(mesh, Features(mesh)); }

std::vector<std::vector<RegionStrokeEdge>> region_stroke_edges(const TriangleMesh& mesh, const MeshRegions& regions)
{
    return region_keys(mesh, Features(mesh), regions);
}

SurfaceRegions surface_regions(const TriangleMesh& mesh)
{
    const Features features(mesh);
    SurfaceRegions out;
    out.regions = regions_of(mesh, features);
    out.edges = region_keys(mesh, features, out.regions);
    return out;
}

KeptRegions keep_unchanged_regions(const LobeSurface& previous, const SurfaceRegions& previous_regions,
                                   LobeSurface& next, SurfaceRegions& next_regions_out)
{
    KeptRegions result;
    const Features next_features(next.mesh);
    next_regions_out.regions = regions_of(next.mesh, next_features);
    next_regions_out.edges = region_keys(next.mesh, next_features, next_regions_out.regions);
    const MeshRegions& next_regions = next_regions_out.regions;
    const auto& next_keys = next_regions_out.edges;
    result.regions = next_regions.count;
    if (previous.centre != next.centre || previous.reference_radius != next.reference_radius ||
        previous.mesh.triangles.empty() || previous_regions.regions.face_region.size() != previous.mesh.triangles.size())
        return result;
    std::vector<char> prev_on_stroke(previous.mesh.positions.size(), 0);
    for (const auto& e : previous.mesh.feature_edges)
        prev_on_stroke[static_cast<Index>(e[0])] = prev_on_stroke[static_cast<Index>(e[1])] = 1;
    const MeshRegions& prev_regions = previous_regions.regions;
    const auto& prev_keys = previous_regions.edges;
    std::map<std::vector<DirectedEdge>, int> prev_by_key;
    for (Index r = 0; r < prev_keys.size(); ++r)
        if (!prev_keys[r].empty()) prev_by_key.emplace(prev_keys[r], static_cast<int>(r));
    std::vector<int> source(static_cast<Index>(next_regions.count), -1); // region of `previous` kept
    for (Index r = 0; r < next_keys.size(); ++r) {
        const auto it = next_keys[r].empty() ? prev_by_key.end() : prev_by_key.find(next_keys[r]);
        if (it == prev_by_key.end()) continue;
        source[r] = it->second;
        ++result.kept;
    }
    if (result.kept == 0) return result;

    // Vertices on strokes are shared by position: every stroke edge of a kept region is one
    // of `next` (the keys matched), so its ends are vertices of `next` at the same place.
    std::vector<std::pair<Key3, int>> on_stroke;
    for (Index v = 0; v < next.mesh.positions.size(); ++v)
        if (next_features.on_vertex[v]) on_stroke.emplace_back(key_of(next.mesh.positions[v]), static_cast<int>(v));
    std::sort(on_stroke.begin(), on_stroke.end());

    // All vertices of both surfaces that the result may use: `next`'s, then `previous`'s
    // inner vertices of kept regions.
    struct Vertex {
        glm::vec3 position;
        LobeVertexOrigin origin;
    };
    std::vector<Vertex> all;
    all.reserve(next.mesh.positions.size());
    for (Index v = 0; v < next.mesh.positions.size(); ++v) all.push_back({next.mesh.positions[v], next.origins[v]});
    std::vector<int> from_previous(previous.mesh.positions.size(), -1);
    std::vector<std::array<int, 3>> tris;
    std::vector<int> tri_region; // region of `next` each triangle belongs to
    tris.reserve(next.mesh.triangles.size());
    for (Index f = 0; f < next.mesh.triangles.size(); ++f)
        if (source[static_cast<Index>(next_regions.face_region[f])] < 0) {
            tris.push_back(next.mesh.triangles[f]);
            tri_region.push_back(next_regions.face_region[f]);
        }
    std::vector<int> kept_as(static_cast<Index>(prev_regions.count), -1); // region of `previous` → of `next`
    for (Index r = 0; r < source.size(); ++r)
        if (source[r] >= 0) kept_as[static_cast<Index>(source[r])] = static_cast<int>(r);
    for (Index f = 0; f < previous.mesh.triangles.size(); ++f) {
        const int as = kept_as[static_cast<Index>(prev_regions.face_region[f])];
        if (as < 0) continue;
        tri_region.push_back(as);
        std::array<int, 3> t{};
        for (int k = 0; k < 3; ++k) {
            const int v = previous.mesh.triangles[f][static_cast<Index>(k)];
            int& mapped = from_previous[static_cast<Index>(v)];
            if (mapped < 0) {
                const glm::vec3& p = previous.mesh.positions[static_cast<Index>(v)];
                if (prev_on_stroke[static_cast<Index>(v)]) {
                    const auto it = std::lower_bound(on_stroke.begin(), on_stroke.end(), std::make_pair(key_of(p), -1));
                    if (it == on_stroke.end() || it->first != key_of(p)) return KeptRegions{result.regions, 0, 0};
                    mapped = it->second;
                } else {
                    mapped = static_cast<int>(all.size());
                    all.push_back({p, previous.origins[static_cast<Index>(v)]});
                }
            }
            t[static_cast<Index>(k)] = mapped;
        }
        tris.push_back(t);
        ++result.kept_triangles;
    }

    // Canonical order, as build_lobe_surface emits it: stroke vertices in their order, then
    // interpolated vertices by direction from the centre; only vertices some triangle uses.
    std::vector<char> used(all.size(), 0);
    for (const auto& t : tris)
        for (int v : t) used[static_cast<Index>(v)] = 1;
    std::vector<int> order;
    std::vector<std::tuple<double, double, double, float, float, float, int>> fill;
    for (Index v = 0; v < all.size(); ++v) {
        if (!used[v]) continue;
        if (all[v].origin.kind != LobeVertexKind::Fill) {
            order.push_back(static_cast<int>(v));
            continue;
        }
        const glm::vec3& p = all[v].position;
        const glm::dvec3 d = glm::normalize(glm::dvec3(p) - next.centre);
        fill.emplace_back(d.x, d.y, d.z, p.x, p.y, p.z, static_cast<int>(v));
    }
    std::sort(fill.begin(), fill.end());
    for (const auto& f : fill) order.push_back(std::get<6>(f));
    std::vector<int> new_index(all.size(), -1);
    LobeSurface out;
    out.centre = next.centre;
    out.reference_radius = next.reference_radius;
    out.paper_strip_triangles = next.paper_strip_triangles;
    out.crossings = next.crossings;
    out.mesh.positions.reserve(order.size());
    out.origins.reserve(order.size());
    for (int v : order) {
        new_index[static_cast<Index>(v)] = static_cast<int>(out.mesh.positions.size());
        out.mesh.positions.push_back(all[static_cast<Index>(v)].position);
        out.origins.push_back(all[static_cast<Index>(v)].origin);
    }
    {
        // Sorted as build_lobe_surface sorts them: by first (lowest) index, then within; each
        // with its region.
        std::vector<std::pair<std::array<int, 3>, int>> tagged;
        tagged.reserve(tris.size());
        for (Index i = 0; i < tris.size(); ++i) {
            const auto& t = tris[i];
            const std::array<int, 3> o{new_index[static_cast<Index>(t[0])], new_index[static_cast<Index>(t[1])],
                                       new_index[static_cast<Index>(t[2])]};
            const Index first = static_cast<Index>(std::min_element(o.begin(), o.end()) - o.begin());
            tagged.push_back({{o[first], o[(first + 1) % 3], o[(first + 2) % 3]}, tri_region[i]});
        }
        std::vector<int> start(out.mesh.positions.size() + 1, 0);
        for (const auto& x : tagged) ++start[static_cast<Index>(x.first[0]) + 1];
        for (Index i = 1; i < start.size(); ++i) start[i] += start[i - 1];
        std::vector<std::pair<std::array<int, 3>, int>> sorted(tagged.size());
        std::vector<int> next_slot(start.begin(), start.end() - 1);
        for (const auto& x : tagged) sorted[static_cast<Index>(next_slot[static_cast<Index>(x.first[0])]++)] = x;
        for (Index i = 0; i + 1 < start.size(); ++i) std::sort(sorted.begin() + start[i], sorted.begin() + start[i + 1]);
        // The result's regions are `next`'s, numbered again by their first triangle.
        std::vector<int> renumber(static_cast<Index>(next_regions.count), -1);
        MeshRegions regions;
        regions.face_region.reserve(sorted.size());
        out.mesh.triangles.reserve(sorted.size());
        for (const auto& [t, r] : sorted) {
            int& n = renumber[static_cast<Index>(r)];
            if (n < 0) n = regions.count++;
            regions.face_region.push_back(n);
            out.mesh.triangles.push_back(t);
        }
        std::vector<std::vector<RegionStrokeEdge>> edges(static_cast<Index>(regions.count));
        for (Index r = 0; r < renumber.size(); ++r)
            if (renumber[r] >= 0) edges[static_cast<Index>(renumber[r])] = std::move(next_regions_out.edges[r]);
        next_regions_out.regions = std::move(regions);
        next_regions_out.edges = std::move(edges);
    }
    for (const auto& e : next.mesh.feature_edges) {
        const int a = new_index[static_cast<Index>(e[0])], b = new_index[static_cast<Index>(e[1])];
        if (a >= 0 && b >= 0) out.mesh.feature_edges.push_back({std::min(a, b), std::max(a, b)});
    }
    std::sort(out.mesh.feature_edges.begin(), out.mesh.feature_edges.end());
    next = std::move(out);
    return result;
}

} // namespace lobe
