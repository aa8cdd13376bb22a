// Stage 7 of a lobe surface build (lobe_surface_builder.h): the triangles of the triangulation
// on the sphere, and the paper's strips, turned into the surface in canonical order. No CGAL.
#include "meshing/lobe_surface_builder.h"

#include <algorithm>
#include <tuple>

#include <glm/geometric.hpp>

#include "core/errors.h"
#include "meshing/stitch.h"

namespace lobe {

namespace lobe_surface_detail {

std::vector<std::array<int, 3>> LobeSurfaceBuilder::paper_strip(int a, int b) const
{
    auto position = [&](int id) {
        const Node& n = nodes_[static_cast<Index>(id)];
        return centre_ + n.radius * n.dir;
    };
    auto valid = [&](const std::array<int, 3>& t) {
        const glm::dvec3 p0 = position(t[0]), p1 = position(t[1]), p2 = position(t[2]);
        return orient3(nodes_[static_cast<Index>(t[0])].dir, nodes_[static_cast<Index>(t[1])].dir,
                       nodes_[static_cast<Index>(t[2])].dir) > 0.0 &&
               glm::dot(glm::cross(p1 - p0, p2 - p0), (p0 + p1 + p2) / 3.0 - centre_) > 0.0;
    };
    std::vector<std::array<int, 3>> region;
    try {
        auto chain_points = [&](int stroke) {
            std::vector<glm::vec3> pts;
            for (int id : chains_[static_cast<Index>(stroke)]) pts.emplace_back(position(id));
            return pts;
        };
        const StrokeStrip strip = stitch_closed_closed(chain_points(a), chain_points(b));
        for (const auto& t : strip.triangles) {
            std::array<int, 3> ids{};
            for (int k = 0; k < 3; ++k) {
                const StripVertexSource src = strip.sources[static_cast<Index>(t[static_cast<Index>(k)])];
                const int s = src.stroke == 0 ? a : b;
                ids[static_cast<Index>(k)] = chains_[static_cast<Index>(s)][static_cast<Index>(src.sample)];
            }
            region.push_back(ids);
        }
    } catch (const InvalidInput&) {
        region.clear();
    }
    if (!region.empty() && !valid(region.front()))
        for (auto& u : region) std::swap(u[1], u[2]);
    const bool ok = !region.empty() && std::all_of(region.begin(), region.end(), valid);
    if (!ok) region.clear();
    return region;
}

namespace {

/// Appends the triangles of `built` (over the sorted nodes) to out.mesh as their vertices
/// (`out_index`) go, each starting at its lowest index (same orientation), and turns its
/// stroke sides' flags with it.
/// \throw InvalidInput where a triangle faces the centre: the strokes fold over each other.
void emit_triangles(SphereTriangles& built, const std::vector<Node>& nodes, const std::vector<int>& out_index,
                    const glm::dvec3& centre, LobeSurface& out)
{
    const std::vector<std::array<int, 3>>& tris = built.triangles;
    std::vector<std::uint8_t>& tri_mask = built.stroke_sides;
    for (const auto& t : tris) {
        const glm::dvec3 d0 = nodes[static_cast<Index>(t[0])].dir, d1 = nodes[static_cast<Index>(t[1])].dir,
                         d2 = nodes[static_cast<Index>(t[2])].dir;
        const std::array<int, 3> o{out_index[static_cast<Index>(t[0])], out_index[static_cast<Index>(t[1])],
                                   out_index[static_cast<Index>(t[2])]};
        const glm::dvec3 p0(out.mesh.positions[static_cast<Index>(o[0])]);
        const glm::dvec3 p1(out.mesh.positions[static_cast<Index>(o[1])]);
        const glm::dvec3 p2(out.mesh.positions[static_cast<Index>(o[2])]);
        const glm::dvec3 normal = glm::cross(p1 - p0, p2 - p0);
        const glm::dvec3 mid = (p0 + p1 + p2) / 3.0 - centre;
        if (!(orient3(d0, d1, d2) > 0.0) || !(glm::dot(normal, mid) > 0.0))
            throw InvalidInput("the lobe's strokes fold over each other as seen from its centre (draw around the lobe)");
        // Each triangle starts at its lowest index (same orientation), its sides' flags turned with it.
        const Index first = static_cast<Index>(std::min_element(o.begin(), o.end()) - o.begin());
        out.mesh.triangles.push_back({o[first], o[(first + 1) % 3], o[(first + 2) % 3]});
        const unsigned m = tri_mask[static_cast<Index>(&t - tris.data())];
        tri_mask[static_cast<Index>(&t - tris.data())] =
            static_cast<std::uint8_t>(((m >> first) | (m << (3 - first))) & 7u);
    }
}

/// Sorts out.mesh.triangles, bucketed by their first (lowest) index, each bucket (a vertex's
/// few triangles) sorted; flags the paper strips' triangles (the first built.strip_triangles);
/// `regions_out` (may be null) receives the regions as surface_regions finds them.
void sort_triangles(const SphereTriangles& built, LobeSurface& out, SurfaceRegions* regions_out)
{
    auto& tris_out = out.mesh.triangles;
    std::vector<int> start(out.mesh.positions.size() + 1, 0);
    for (const auto& t : tris_out) ++start[static_cast<Index>(t[0]) + 1];
    for (Index i = 1; i < start.size(); ++i) start[i] += start[i - 1];
    struct Sorted {
        std::array<int, 3> t;
        std::uint8_t strip, mask;
        int region;
    };
    std::vector<Sorted> sorted(tris_out.size());
    std::vector<int> next(start.begin(), start.end() - 1);
    for (Index k = 0; k < tris_out.size(); ++k)
        sorted[static_cast<Index>(next[static_cast<Index>(tris_out[k][0])]++)] = {
            tris_out[k], static_cast<std::uint8_t>(k < built.strip_triangles ? 1 : 0), built.stroke_sides[k], built.region[k]};
    for (Index i = 0; i + 1 < start.size(); ++i)
        std::sort(sorted.begin() + start[i], sorted.begin() + start[i + 1],
                  [](const Sorted& x, const Sorted& y) { return x.t < y.t; });
    out.paper_strip_faces.resize(sorted.size());
    for (Index k = 0; k < sorted.size(); ++k) {
        tris_out[k] = sorted[k].t;
        out.paper_strip_faces[k] = sorted[k].strip;
    }
    if (regions_out) {
        // As surface_regions finds them: numbered by their first triangle, each with its
        // stroke edges directed as its triangles run round them, sorted.
        std::vector<int> number(static_cast<Index>(built.region_count), -1);
        MeshRegions& mr = regions_out->regions;
        mr = MeshRegions{};
        mr.face_region.reserve(sorted.size());
        auto& keys = regions_out->edges;
        keys.clear();
        for (const Sorted& x : sorted) {
            int& n = number[static_cast<Index>(x.region)];
            if (n < 0) {
                n = mr.count++;
                keys.emplace_back();
            }
            mr.face_region.push_back(n);
            for (Index k = 0; k < 3; ++k) {
                if (!(x.mask & (1u << k))) continue;
                const glm::vec3& p = out.mesh.positions[static_cast<Index>(x.t[k])];
                const glm::vec3& q = out.mesh.positions[static_cast<Index>(x.t[(k + 1) % 3])];
                keys[static_cast<Index>(n)].push_back({p.x, p.y, p.z, q.x, q.y, q.z});
            }
        }
        for (auto& k : keys) std::sort(k.begin(), k.end());
    }
}

/// The stroke segments (split at crossings), the constraints of remeshing, as `mesh`'s
/// feature edges (sorted).
void emit_stroke_edges(const std::vector<std::array<int, 2>>& stroke_edges, const std::vector<int>& new_id,
                       const std::vector<int>& out_index, TriangleMesh& mesh)
{
    for (const auto& [u, v] : stroke_edges) {
        const int a = out_index[static_cast<Index>(new_id[static_cast<Index>(u)])];
        const int b = out_index[static_cast<Index>(new_id[static_cast<Index>(v)])];
        if (a >= 0 && b >= 0 && a != b) mesh.feature_edges.push_back({std::min(a, b), std::max(a, b)});
    }
    std::sort(mesh.feature_edges.begin(), mesh.feature_edges.end());
}

} // namespace

void LobeSurfaceBuilder::emit(SphereTriangles built, LobeSurface& out, SurfaceRegions* regions_out)
{
    out.paper_strip_triangles = built.strip_triangles;
    const std::vector<int> new_id = sort_nodes(built.triangles);
    std::vector<char> on_chain(nodes_.size(), 0);
    for (const auto& chain : chains_)
        for (int id : chain) on_chain[static_cast<Index>(new_id[static_cast<Index>(id)])] = 1;
    solve_fill_radii(built.triangles, on_chain);
    const std::vector<int> out_index = emit_vertices(built.triangles, on_chain, out);
    emit_triangles(built, nodes_, out_index, centre_, out);
    sort_triangles(built, out, regions_out);
    emit_stroke_edges(built.stroke_edges, new_id, out_index, out.mesh);
    std::vector<int> crossing_nodes;
    for (const Crossing& c : crossings_) crossing_nodes.push_back(c.node);
    std::sort(crossing_nodes.begin(), crossing_nodes.end());
    out.crossings = static_cast<std::size_t>(std::unique(crossing_nodes.begin(), crossing_nodes.end()) - crossing_nodes.begin());
}

std::vector<int> LobeSurfaceBuilder::sort_nodes(std::vector<std::array<int, 3>>& tris)
{
    // Canonical order: the stroke nodes keep theirs (it follows the strokes alone), the
    // interpolated nodes are sorted by direction, and below the triangles are sorted too, so
    // the output depends on the strokes alone and not on the order the triangulation made
    // things in (its faces, and the refinement's insertions that follow them).
    std::vector<int> new_id(nodes_.size());
    std::vector<int> order;
    order.reserve(nodes_.size());
    std::vector<std::tuple<double, double, double, int>> fill; // (direction, id): ties keep id order
    for (Index i = 0; i < nodes_.size(); ++i) {
        const Node& n = nodes_[i];
        if (n.origin.kind != LobeVertexKind::Fill) order.push_back(static_cast<int>(i));
        else fill.emplace_back(n.dir.x, n.dir.y, n.dir.z, static_cast<int>(i));
    }
    std::sort(fill.begin(), fill.end());
    for (const auto& f : fill) order.push_back(std::get<3>(f));
    std::vector<Node> sorted;
    sorted.reserve(nodes_.size());
    for (Index k = 0; k < order.size(); ++k) {
        new_id[static_cast<Index>(order[k])] = static_cast<int>(k);
        sorted.push_back(nodes_[static_cast<Index>(order[k])]);
    }
    nodes_ = std::move(sorted);
    for (auto& t : tris)
        for (int& id : t) id = new_id[static_cast<Index>(id)];
    return new_id;
}

std::vector<int> LobeSurfaceBuilder::emit_vertices(const std::vector<std::array<int, 3>>& tris,
                                                   const std::vector<char>& on_chain, LobeSurface& out) const
{
    // Output: only nodes used by triangles; a build of the changed regions has every stroke
    // node (the kept regions use them). The stroke nodes come first in node order (samples
    // first, by stroke), then the interpolated ones by the direction of their rounded position
    // from the centre: the order complete_with_kept_regions gives its result, so that it merges
    // a build's vertices with the kept ones instead of sorting them all.
    std::vector<int> out_index(nodes_.size(), -1);
    for (const auto& t : tris)
        for (int id : t) out_index[static_cast<Index>(id)] = 0;
    if (partial_)
        for (Index i = 0; i < nodes_.size(); ++i)
            if (on_chain[i]) out_index[i] = 0;
    std::vector<FillOrderKey> fill_out;
    for (Index i = 0; i < nodes_.size(); ++i) {
        if (out_index[i] < 0) continue;
        const Node& n = nodes_[i];
        const glm::vec3 p(n.origin.kind == LobeVertexKind::Sample
                              ? glm::dvec3(strokes_[static_cast<Index>(n.origin.stroke)]
                                               .points[static_cast<Index>(n.origin.sample)])
                              : centre_ + n.radius * n.dir);
        if (n.origin.kind == LobeVertexKind::Fill) {
            fill_out.push_back(fill_order_key(p, centre_, static_cast<int>(i)));
            continue;
        }
        out_index[i] = static_cast<int>(out.mesh.positions.size());
        out.mesh.positions.push_back(p);
        out.origins.push_back(n.origin);
    }
    // The nodes are in order of their directions already, which rounding swaps only here and
    // there: an insertion sort, handing over to a full sort should it move much.
    {
        std::size_t moves = 0;
        for (Index k = 1; k < fill_out.size() && moves <= 4 * fill_out.size(); ++k)
            for (Index j = k; j > 0 && fill_out[j] < fill_out[j - 1]; --j, ++moves) std::swap(fill_out[j], fill_out[j - 1]);
        if (moves > 4 * fill_out.size()) std::sort(fill_out.begin(), fill_out.end());
    }
    for (const auto& [dx, dy, dz, px, py, pz, i] : fill_out) {
        out_index[static_cast<Index>(i)] = static_cast<int>(out.mesh.positions.size());
        out.mesh.positions.emplace_back(px, py, pz);
        out.origins.push_back(nodes_[static_cast<Index>(i)].origin);
    }
    return out_index;
}

} // namespace lobe_surface_detail

} // namespace lobe
