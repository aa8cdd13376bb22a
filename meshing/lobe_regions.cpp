#include "meshing/lobe_regions.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <limits>
#include <map>
#include <numeric>
#include <tuple>

#include <glm/geometric.hpp>

namespace lobe {

namespace {

using Index = std::size_t;
using DirectedEdge = RegionStrokeEdge;

/// Vertices by exact position: an open-addressing hash table (linear probing, at most half
/// full). This runs on every stroke vertex of the lobe twice per stroke added; a sorted
/// array and binary searches cost several times as much.
class PositionIndex {
public:
    /// Room for `count` vertices.
    explicit PositionIndex(Index count)
    {
        Index size = 16;
        while (size < 2 * count) size *= 2;
        mask_ = size - 1;
        slots_.assign(size, Slot{});
    }
    /// Adds vertex `v` at `p` unless a vertex was added there before (the first one stays).
    void add(const glm::vec3& p, int v)
    {
        const Bits k = bits(p);
        for (Index i = hash(k) & mask_;; i = (i + 1) & mask_) {
            Slot& s = slots_[i];
            if (s.vertex < 0) {
                s = {k, v};
                return;
            }
            if (s.key == k) return;
        }
    }
    /// The vertex at `p`, or −1.
    int find(const glm::vec3& p) const
    {
        const Bits k = bits(p);
        for (Index i = hash(k) & mask_;; i = (i + 1) & mask_) {
            const Slot& s = slots_[i];
            if (s.vertex < 0) return -1;
            if (s.key == k) return s.vertex;
        }
    }

private:
    using Bits = std::array<std::uint32_t, 3>;
    struct Slot {
        Bits key{};
        int vertex = -1;
    };
    static Bits bits(const glm::vec3& p)
    {
        // + 0.0f makes −0 and +0 (equal positions) one key.
        Bits b{};
        const float c[3] = {p.x + 0.0f, p.y + 0.0f, p.z + 0.0f};
        std::memcpy(b.data(), c, sizeof c);
        return b;
    }
    static Index hash(const Bits& b)
    {
        std::uint64_t h = b[0] * 0x9E3779B97F4A7C15ull;
        h ^= (h >> 29) ^ (b[1] * 0xC2B2AE3D27D4EB4Full);
        h ^= (h >> 31) ^ (b[2] * 0x165667B19E3779F9ull);
        h ^= h >> 32;
        return static_cast<Index>(h);
    }
    std::vector<Slot> slots_;
    Index mask_ = 0;
};

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
              for (Index i = 0; i < mesh.feature_edges.size(); ++i)
                  f(mesh.feature_edges[i][0], mesh.feature_edges[i][1], static_cast<int>(i));
          })
    {
        for (const auto& e : mesh.feature_edges) on_vertex[static_cast<Index>(e[0])] = on_vertex[static_cast<Index>(e[1])] = 1;
    }
    bool has(int a, int b) const { return find(a, b) >= 0; }
    /// Index of the feature edge (a, b), or −1.
    int find(int a, int b) const
    {
        return on_vertex[static_cast<Index>(a)] && on_vertex[static_cast<Index>(b)] ? edges.find(a, b) : -1;
    }
};

/// Sorts edges (lower, higher) and drops repeats: bucketed by the lower vertex (a counting
/// sort), each bucket (a vertex's few edges) sorted on its own.
void sort_unique_edges(std::vector<std::array<int, 2>>& edges, Index vertices)
{
    std::vector<int> start(vertices + 1, 0);
    for (const auto& e : edges) ++start[static_cast<Index>(e[0]) + 1];
    for (Index i = 1; i < start.size(); ++i) start[i] += start[i - 1];
    std::vector<int> sorted(edges.size());
    std::vector<int> next(start.begin(), start.end() - 1);
    for (const auto& e : edges) sorted[static_cast<Index>(next[static_cast<Index>(e[0])]++)] = e[1];
    Index out = 0;
    for (Index v = 0; v + 1 < start.size(); ++v) {
        const auto first = sorted.begin() + start[v], last = sorted.begin() + start[v + 1];
        std::sort(first, last);
        for (auto it = first; it != last; ++it)
            if (it == first || *it != *(it - 1)) edges[out++] = {static_cast<int>(v), *it};
    }
    edges.resize(out);
}

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

// Not inlined (see lobe_regions.h): its callers must see the float position as stored.
[[gnu::noinline]] FillOrderKey fill_order_key(const glm::vec3& position, const glm::dvec3& centre, int vertex)
{
    const glm::dvec3 d = glm::normalize(glm::dvec3(position) - centre);
    return {d.x, d.y, d.z, position.x, position.y, position.z, vertex};
}

namespace {

/// The region of the result each region of `previous` becomes where it is kept: the region
/// of `next` with the same stroke edges, or (`also_keep`) one numbered after `next`'s; -1
/// where it is not kept. Counts them in result.kept, and all regions in result.regions.
std::vector<int> match_kept_regions(const SurfaceRegions& previous_regions, const SurfaceRegions& next_regions_out,
                                    const std::vector<char>* also_keep, KeptRegions& result)
{
    const MeshRegions& prev_regions = previous_regions.regions;
    const auto& prev_keys = previous_regions.edges;
    const auto& next_keys = next_regions_out.edges;
    std::vector<int> kept_as(static_cast<Index>(prev_regions.count), -1);
    {
        // A region kept already (also_keep) is no region of `next`: only the others can match.
        std::map<std::vector<DirectedEdge>, int> prev_by_key;
        for (Index r = 0; r < prev_keys.size(); ++r)
            if (!prev_keys[r].empty() && !(also_keep && r < also_keep->size() && (*also_keep)[r]))
                prev_by_key.emplace(prev_keys[r], static_cast<int>(r));
        for (Index r = 0; r < next_keys.size(); ++r) {
            const auto it = next_keys[r].empty() ? prev_by_key.end() : prev_by_key.find(next_keys[r]);
            if (it == prev_by_key.end()) continue;
            kept_as[static_cast<Index>(it->second)] = static_cast<int>(r);
            ++result.kept;
        }
    }
    int region_count = next_regions_out.regions.count;
    if (also_keep)
        for (Index r = 0; r < also_keep->size() && r < kept_as.size(); ++r)
            if ((*also_keep)[r] && kept_as[r] < 0) {
                kept_as[r] = region_count++;
                ++result.kept;
            }
    result.regions = region_count;
    return kept_as;
}

/// What keep_regions makes of `next` and the kept regions of `previous` before putting it in
/// canonical order.
struct MergedSurface {
    struct Vertex {
        glm::vec3 position;
        LobeVertexOrigin origin;
    };
    /// All vertices of both surfaces that the result may use: `next`'s, then `previous`'s
    /// inner vertices of kept regions (from index from_next on).
    std::vector<Vertex> all;
    Index from_next = 0;
    /// The result's triangles (over `all`): `next`'s that are not kept (the first
    /// tris_from_next), then the kept ones; each with its region of the result and whether it
    /// is a paper strip's.
    std::vector<std::array<int, 3>> tris;
    std::vector<int> tri_region;
    std::vector<std::uint8_t> tri_strip;
    Index tris_from_next = 0;
    std::vector<std::array<int, 2>> kept_features; ///< stroke edges of kept triangles (also_keep)
};

/// Merges the triangles of `next` that are not kept with the kept regions of `previous`
/// (`kept_as`, match_kept_regions) into `m`; counts the kept triangles in `result`. False (`m`
/// incomplete) when a stroke vertex of a kept region is not one of `next`'s.
bool merge_kept_regions(const LobeSurface& previous, const MeshRegions& prev_regions, const Features& prev_features,
                        const std::vector<int>& kept_as, const LobeSurface& next, const MeshRegions& next_regions,
                        const Features& next_features, bool also_keep, MergedSurface& m, KeptRegions& result)
{
    // Vertices on strokes are shared by position: every stroke edge of a kept region is one
    // of `next` (the keys matched; a build of the changed regions has every stroke vertex),
    // so its ends are vertices of `next` at the same place.
    auto on_stroke_of_next = [&](Index v) {
        return next_features.on_vertex[v] || next.origins[v].kind != LobeVertexKind::Fill;
    };
    Index stroke_vertices = 0;
    for (Index v = 0; v < next.mesh.positions.size(); ++v) stroke_vertices += on_stroke_of_next(v) ? 1 : 0;
    PositionIndex on_stroke(stroke_vertices);
    for (Index v = 0; v < next.mesh.positions.size(); ++v)
        if (on_stroke_of_next(v)) on_stroke.add(next.mesh.positions[v], static_cast<int>(v));

    std::vector<MergedSurface::Vertex>& all = m.all;
    all.reserve(next.mesh.positions.size() + previous.mesh.positions.size());
    for (Index v = 0; v < next.mesh.positions.size(); ++v) all.push_back({next.mesh.positions[v], next.origins[v]});
    std::vector<int> from_previous(previous.mesh.positions.size(), -1);
    // The result's triangles before sorting, written in place (sized for all of both; this
    // and the loops below run on every triangle of the lobe for every stroke).
    const bool next_strips = next.paper_strip_faces.size() == next.mesh.triangles.size();
    const bool prev_strips = previous.paper_strip_faces.size() == previous.mesh.triangles.size();
    const Index at_most = next.mesh.triangles.size() + previous.mesh.triangles.size();
    std::vector<std::array<int, 3>>& tris = m.tris;
    std::vector<int>& tri_region = m.tri_region; // region of the result each triangle belongs to
    std::vector<std::uint8_t>& tri_strip = m.tri_strip;
    tris.resize(at_most);
    tri_region.resize(at_most);
    tri_strip.resize(at_most);
    Index tri_count = 0;
    std::vector<char> next_kept(static_cast<Index>(next_regions.count), 0);
    for (int as : kept_as)
        if (as >= 0 && as < next_regions.count) next_kept[static_cast<Index>(as)] = 1;
    for (Index f = 0; f < next.mesh.triangles.size(); ++f)
        if (!next_kept[static_cast<Index>(next_regions.face_region[f])]) {
            tris[tri_count] = next.mesh.triangles[f];
            tri_region[tri_count] = next_regions.face_region[f];
            tri_strip[tri_count++] = next_strips ? next.paper_strip_faces[f] : 0;
        }
    const Index tris_from_next = tri_count;
    // The kept triangles' vertices: stroke vertices are `next`'s at the same place; inner ones
    // are added in `previous`'s order (canonical there, so the order below is a merge).
    constexpr int kNeeded = -2;
    for (Index f = 0; f < previous.mesh.triangles.size(); ++f) {
        if (kept_as[static_cast<Index>(prev_regions.face_region[f])] < 0) continue;
        for (int v : previous.mesh.triangles[f]) {
            int& mapped = from_previous[static_cast<Index>(v)];
            if (mapped != -1) continue;
            if (!prev_features.on_vertex[static_cast<Index>(v)]) {
                mapped = kNeeded;
                continue;
            }
            mapped = on_stroke.find(previous.mesh.positions[static_cast<Index>(v)]);
            if (mapped < 0) return false;
        }
    }
    const Index from_next = all.size();
    for (Index v = 0; v < from_previous.size(); ++v)
        if (from_previous[v] == kNeeded) {
            from_previous[v] = static_cast<int>(all.size());
            all.push_back({previous.mesh.positions[v], previous.origins[v]});
        }
    std::vector<std::array<int, 2>>& kept_features = m.kept_features;
    for (Index f = 0; f < previous.mesh.triangles.size(); ++f) {
        const int as = kept_as[static_cast<Index>(prev_regions.face_region[f])];
        if (as < 0) continue;
        tri_region[tri_count] = as;
        tri_strip[tri_count] = prev_strips ? previous.paper_strip_faces[f] : 0;
        const auto& pt = previous.mesh.triangles[f];
        const std::array<int, 3> t{from_previous[static_cast<Index>(pt[0])], from_previous[static_cast<Index>(pt[1])],
                                   from_previous[static_cast<Index>(pt[2])]};
        if (also_keep)
            for (Index k = 0; k < 3; ++k) {
                const int a = pt[k], b = pt[(k + 1) % 3];
                if (a < b && prev_features.has(a, b)) kept_features.push_back({t[k], t[(k + 1) % 3]});
            }
        tris[tri_count++] = t;
        ++result.kept_triangles;
    }
    tris.resize(tri_count);
    tri_region.resize(tri_count);
    tri_strip.resize(tri_count);

    m.from_next = from_next;
    m.tris_from_next = tris_from_next;
    return true;
}

/// The vertices of `m` that some triangle uses, into `out` in canonical order (as
/// build_lobe_surface emits them: stroke vertices in their order, then interpolated vertices
/// by direction from `centre`); returns each vertex's index there, or -1.
std::vector<int> emit_merged_vertices(const MergedSurface& m, const glm::dvec3& centre, LobeSurface& out)
{
    const auto& all = m.all;
    const auto& tris = m.tris;
    const Index from_next = m.from_next;
    std::vector<char> used(all.size(), 0);
    for (const auto& t : tris)
        for (int v : t) used[static_cast<Index>(v)] = 1;
    std::vector<int> order;
    order.reserve(all.size());
    std::vector<FillOrderKey> fill;
    fill.reserve(all.size());
    for (Index v = 0; v < all.size(); ++v) {
        if (!used[v]) continue;
        if (all[v].origin.kind != LobeVertexKind::Fill) {
            order.push_back(static_cast<int>(v));
            continue;
        }
        fill.push_back(fill_order_key(all[v].position, centre, static_cast<int>(v)));
    }
    // `next`'s interpolated vertices, then `previous`'s: each list is sorted already when it
    // came from a build or from this function (both order them so); a surface made otherwise
    // is sorted.
    {
        const auto middle = std::partition_point(fill.begin(), fill.end(), [&](const auto& f) {
            return static_cast<Index>(std::get<6>(f)) < from_next;
        });
        if (std::is_sorted(fill.begin(), middle) && std::is_sorted(middle, fill.end()))
            std::inplace_merge(fill.begin(), middle, fill.end());
        else
            std::sort(fill.begin(), fill.end());
    }
    for (const auto& f : fill) order.push_back(std::get<6>(f));
    std::vector<int> new_index(all.size(), -1);
    out.mesh.positions.reserve(order.size());
    out.origins.reserve(order.size());
    for (int v : order) {
        new_index[static_cast<Index>(v)] = static_cast<int>(out.mesh.positions.size());
        out.mesh.positions.push_back(all[static_cast<Index>(v)].position);
        out.origins.push_back(all[static_cast<Index>(v)].origin);
    }
    return new_index;
}

/// The triangles of `m` over the vertices' new indices into `out`, sorted as
/// build_lobe_surface sorts them, and the result's regions (`next_regions_out`): numbered again by
/// their first triangle, each with its stroke edges (`next`'s as next_regions_out held them on
/// entry, the kept ones' from `prev_keys`).
void emit_merged_triangles(const MergedSurface& m, const std::vector<int>& new_index, int region_count,
                           const std::vector<int>& kept_as, const std::vector<std::vector<DirectedEdge>>& prev_keys,
                           SurfaceRegions& next_regions_out, LobeSurface& out)
{
    const auto& tris = m.tris;
    const auto& tri_region = m.tri_region;
    const auto& tri_strip = m.tri_strip;
    const Index tris_from_next = m.tris_from_next;
    const int next_count = next_regions_out.regions.count;
    // Sorted as build_lobe_surface sorts them: by first (lowest) index, then within; each
    // with its region and whether it is a paper strip's.
    struct Tagged {
        std::array<int, 3> t;
        int region;
        std::uint8_t strip;
    };
    std::vector<Tagged> tagged(tris.size());
    for (Index i = 0; i < tris.size(); ++i) {
        const auto& t = tris[i];
        const std::array<int, 3> o{new_index[static_cast<Index>(t[0])], new_index[static_cast<Index>(t[1])],
                                   new_index[static_cast<Index>(t[2])]};
        const Index first = static_cast<Index>(std::min_element(o.begin(), o.end()) - o.begin());
        tagged[i] = {{o[first], o[(first + 1) % 3], o[(first + 2) % 3]}, tri_region[i], tri_strip[i]};
    }
    const auto by_corners = [](const Tagged& x, const Tagged& y) { return x.t < y.t; };
    std::vector<Tagged> sorted(tagged.size());
    // `next`'s triangles and the kept ones are each in order already where the vertices
    // kept their relative order (the usual case): then a merge; else a bucket sort.
    const auto middle = tagged.begin() + static_cast<std::ptrdiff_t>(tris_from_next);
    if (std::is_sorted(tagged.begin(), middle, by_corners) && std::is_sorted(middle, tagged.end(), by_corners)) {
        std::merge(tagged.begin(), middle, middle, tagged.end(), sorted.begin(), by_corners);
    } else {
        std::vector<int> start(out.mesh.positions.size() + 1, 0);
        for (const auto& x : tagged) ++start[static_cast<Index>(x.t[0]) + 1];
        for (Index i = 1; i < start.size(); ++i) start[i] += start[i - 1];
        std::vector<int> next_slot(start.begin(), start.end() - 1);
        for (const auto& x : tagged) sorted[static_cast<Index>(next_slot[static_cast<Index>(x.t[0])]++)] = x;
        for (Index i = 0; i + 1 < start.size(); ++i)
            std::sort(sorted.begin() + start[i], sorted.begin() + start[i + 1], by_corners);
    }
    // The result's regions, numbered again by their first triangle.
    std::vector<int> renumber(static_cast<Index>(region_count), -1);
    MeshRegions regions;
    regions.face_region.resize(sorted.size());
    out.mesh.triangles.resize(sorted.size());
    out.paper_strip_faces.resize(sorted.size());
    for (Index i = 0; i < sorted.size(); ++i) {
        const Tagged& x = sorted[i];
        int& n = renumber[static_cast<Index>(x.region)];
        if (n < 0) n = regions.count++;
        regions.face_region[i] = n;
        out.mesh.triangles[i] = x.t;
        out.paper_strip_faces[i] = x.strip;
        out.paper_strip_triangles += x.strip;
    }
    std::vector<std::vector<RegionStrokeEdge>> edges(static_cast<Index>(regions.count));
    for (Index r = 0; r < static_cast<Index>(next_count); ++r)
        if (renumber[r] >= 0) edges[static_cast<Index>(renumber[r])] = std::move(next_regions_out.edges[r]);
    for (Index r = 0; r < kept_as.size(); ++r) {
        const int as = kept_as[r];
        if (as >= next_count && renumber[static_cast<Index>(as)] >= 0)
            edges[static_cast<Index>(renumber[static_cast<Index>(as)])] = prev_keys[r];
    }
    next_regions_out.regions = std::move(regions);
    next_regions_out.edges = std::move(edges);
}

/// keep_unchanged_regions and complete_with_kept_regions: `also_keep` (may be null) flags the
/// regions of `previous` that `next` lacks and that complete it. False when a stroke vertex of
/// a kept region is not one of `next`'s (nothing is changed then).
bool keep_regions(const LobeSurface& previous, const SurfaceRegions& previous_regions, const std::vector<char>* also_keep,
                  LobeSurface& next, SurfaceRegions& next_regions_out, bool next_regions_known, KeptRegions& result)
{
    result = {};
    const Features next_features(next.mesh);
    if (!next_regions_known) {
        next_regions_out.regions = regions_of(next.mesh, next_features);
        next_regions_out.edges = region_keys(next.mesh, next_features, next_regions_out.regions);
    }
    const MeshRegions& next_regions = next_regions_out.regions;
    result.regions = next_regions.count;
    if (previous.centre != next.centre || previous.reference_radius != next.reference_radius ||
        previous.mesh.triangles.empty() || previous_regions.regions.face_region.size() != previous.mesh.triangles.size())
        return also_keep == nullptr;
    const Features prev_features(previous.mesh);
    const std::vector<int> kept_as = match_kept_regions(previous_regions, next_regions_out, also_keep, result);
    const int region_count = result.regions;
    if (result.kept == 0) return true;

    MergedSurface m;
    if (!merge_kept_regions(previous, previous_regions.regions, prev_features, kept_as, next, next_regions, next_features,
                            also_keep != nullptr, m, result)) {
        if (also_keep) return false;
        result = KeptRegions{next_regions.count, 0, 0, false};
        return true;
    }
    LobeSurface out;
    out.centre = next.centre;
    out.reference_radius = next.reference_radius;
    out.crossings = next.crossings;
    out.memo = next.memo;
    const std::vector<int> new_index = emit_merged_vertices(m, next.centre, out);
    emit_merged_triangles(m, new_index, region_count, kept_as, previous_regions.edges, next_regions_out, out);
    for (const auto& e : next.mesh.feature_edges) {
        const int a = new_index[static_cast<Index>(e[0])], b = new_index[static_cast<Index>(e[1])];
        if (a >= 0 && b >= 0) out.mesh.feature_edges.push_back({std::min(a, b), std::max(a, b)});
    }
    for (const auto& e : m.kept_features) {
        const int a = new_index[static_cast<Index>(e[0])], b = new_index[static_cast<Index>(e[1])];
        out.mesh.feature_edges.push_back({std::min(a, b), std::max(a, b)});
    }
    sort_unique_edges(out.mesh.feature_edges, out.mesh.positions.size());
    next = std::move(out);
    return true;
}

/// The region of `surface` whose triangles cover `direction` as seen from the centre (the
/// triangle it lies deepest inside), or −1.
int region_at(const LobeSurface& surface, const MeshRegions& regions, const glm::dvec3& direction)
{
    std::vector<glm::dvec3> dirs(surface.mesh.positions.size());
    for (Index v = 0; v < dirs.size(); ++v) dirs[v] = glm::normalize(glm::dvec3(surface.mesh.positions[v]) - surface.centre);
    double best = -std::numeric_limits<double>::infinity();
    int region = -1;
    for (Index f = 0; f < surface.mesh.triangles.size(); ++f) {
        const auto& t = surface.mesh.triangles[f];
        const glm::dvec3& a = dirs[static_cast<Index>(t[0])];
        const glm::dvec3& b = dirs[static_cast<Index>(t[1])];
        const glm::dvec3& c = dirs[static_cast<Index>(t[2])];
        if (glm::dot(direction, a + b + c) <= 0.0) continue;
        const double m = std::min({glm::dot(glm::cross(a, b), direction), glm::dot(glm::cross(b, c), direction),
                                   glm::dot(glm::cross(c, a), direction)});
        if (m > best) {
            best = m;
            region = regions.face_region[f];
        }
    }
    return best >= -1e-12 ? region : -1;
}

} // namespace

KeptRegions keep_unchanged_regions(const LobeSurface& previous, const SurfaceRegions& previous_regions,
                                   LobeSurface& next, SurfaceRegions& next_regions, bool next_regions_known)
{
    KeptRegions result;
    keep_regions(previous, previous_regions, nullptr, next, next_regions, next_regions_known, result);
    return result;
}

bool complete_with_kept_regions(const LobeSurface& previous, const SurfaceRegions& previous_regions,
                                const std::vector<char>& keep, LobeSurface& next, SurfaceRegions& next_regions,
                                KeptRegions& kept, bool next_regions_known)
{
    return keep_regions(previous, previous_regions, &keep, next, next_regions, next_regions_known, kept);
}

ChangedRegions find_changed_regions(const LobeSurface& previous, const SurfaceRegions& previous_regions,
                                    const std::vector<RegionChain>& chains)
{
    ChangedRegions out;
    const TriangleMesh& mesh = previous.mesh;
    const MeshRegions& regions = previous_regions.regions;
    if (mesh.triangles.empty() || regions.face_region.size() != mesh.triangles.size() || regions.count < 2) {
        out.everything = true;
        return out;
    }
    const Features features(mesh);
    PositionIndex on_stroke(static_cast<Index>(std::count(features.on_vertex.begin(), features.on_vertex.end(), 1)));
    for (Index v = 0; v < mesh.positions.size(); ++v)
        if (features.on_vertex[v]) on_stroke.add(mesh.positions[v], static_cast<int>(v));
    auto vertex_at = [&](const glm::vec3& p) { return on_stroke.find(p); };
    // The regions on the two sides of every stroke edge: [0] where the triangles run round it
    // from its lower to its higher vertex, [1] the other way.
    const auto& fe = mesh.feature_edges;
    std::vector<std::array<int, 2>> side(fe.size(), {-1, -1});
    for (Index f = 0; f < mesh.triangles.size(); ++f)
        for (Index k = 0; k < 3; ++k) {
            const int a = mesh.triangles[f][k], b = mesh.triangles[f][(k + 1) % 3];
            const int e = features.find(a, b);
            if (e >= 0) side[static_cast<Index>(e)][a < b ? 0 : 1] = regions.face_region[f];
        }
    std::vector<char> present(fe.size(), 0), changed(static_cast<Index>(regions.count), 0);
    std::vector<std::vector<int>> chain_vertex(chains.size()), chain_edge(chains.size());
    std::vector<glm::dvec3> to_locate;
    for (Index c = 0; c < chains.size(); ++c) {
        const auto& pts = chains[c].points;
        const Index n = pts.size();
        const Index m = chains[c].closed ? n : (n > 0 ? n - 1 : 0);
        auto& vid = chain_vertex[c];
        vid.resize(n);
        for (Index i = 0; i < n; ++i) vid[i] = vertex_at(pts[i]);
        chain_edge[c].assign(m, -1);
        Index first_new = m;
        for (Index i = 0; i < m; ++i) {
            const int a = vid[i], b = vid[(i + 1) % n];
            const int e = a >= 0 && b >= 0 ? features.find(a, b) : -1;
            if (e >= 0) {
                present[static_cast<Index>(e)] = 1;
                chain_edge[c][i] = e;
            } else if (first_new == m) {
                first_new = i;
            }
        }
        // A chain with new edges and no crossing lies inside one region; a crossed one splits
        // an edge of every region it enters.
        if (first_new < m && !chains[c].crossed)
            to_locate.push_back(glm::dvec3(pts[first_new]) + glm::dvec3(pts[(first_new + 1) % n]) - 2.0 * previous.centre);
    }
    for (Index e = 0; e < fe.size(); ++e)
        if (!present[e])
            for (int r : side[e])
                if (r >= 0) changed[static_cast<Index>(r)] = 1;
    for (const glm::dvec3& d : to_locate) {
        const double len = glm::length(d);
        const int r = len > 0.0 ? region_at(previous, regions, d / len) : -1;
        if (r < 0) {
            out.everything = true;
            return out;
        }
        changed[static_cast<Index>(r)] = 1;
    }
    const auto changed_count = std::count(changed.begin(), changed.end(), 1);
    if (changed_count == 0 || changed_count == regions.count) {
        out.everything = true;
        return out;
    }
    out.keep.resize(changed.size());
    for (Index r = 0; r < changed.size(); ++r) out.keep[r] = !changed[r];
    out.edges.resize(chains.size());
    for (Index c = 0; c < chains.size(); ++c) {
        const Index n = chains[c].points.size();
        auto& edges = out.edges[c];
        edges.assign(chain_edge[c].size(), ChangedRegions::Inside);
        for (Index i = 0; i < edges.size(); ++i) {
            const int e = chain_edge[c][i];
            if (e < 0) continue;
            const auto [s0, s1] = side[static_cast<Index>(e)];
            const bool c0 = s0 >= 0 && changed[static_cast<Index>(s0)], c1 = s1 >= 0 && changed[static_cast<Index>(s1)];
            if (!c0 && !c1) {
                edges[i] = ChangedRegions::Outside;
            } else if (c0 != c1) {
                // Side 0 runs from the lower vertex to the higher.
                const bool ahead = (chain_vertex[c][i] < chain_vertex[c][(i + 1) % n]) == c0;
                edges[i] = ahead ? ChangedRegions::BorderAhead : ChangedRegions::BorderBack;
            }
        }
    }
    return out;
}

} // namespace lobe
