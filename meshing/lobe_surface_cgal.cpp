// Stage 6 of a lobe surface build (lobe_surface_builder.h), the one that needs CGAL: the
// constrained Delaunay triangulation of the strokes on the sphere of directions around the
// lobe's centre (CGAL's Constrained_Delaunay_triangulation_2 in a stereographic projection),
// its regions, the paper's strips and the fill vertices; and the entry points that run a
// build's stages in order. See lobe_surface.h.
#include "meshing/lobe_surface.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>

#include "meshing/cgal_prelude.h"
LOBE_CGAL_HEADERS_BEGIN
#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Constrained_triangulation_face_base_2.h>
#include <CGAL/Spatial_sort_traits_adapter_2.h>
#include <CGAL/property_map.h>
#include <CGAL/spatial_sort.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>
LOBE_CGAL_HEADERS_END

#include "core/errors.h"
#include "meshing/lobe_regions.h"
#include "meshing/lobe_surface_builder.h"
#include "meshing/stereographic.h"

namespace lobe {

namespace lobe_surface_detail {

namespace {

using cgal::Kernel;
struct VertexInfo {
    int id = -1; ///< index into the node table; -1: created by CGAL at a residual crossing
};
struct FaceInfo {
    int region = -1;  ///< region id (see mark_regions)
    bool fine = false; ///< refinement found nothing to add here; reset when the face changes
};
using Vb = CGAL::Triangulation_vertex_base_with_info_2<VertexInfo, Kernel>;
using Fb0 = CGAL::Constrained_triangulation_face_base_2<Kernel>;
using Fb = CGAL::Triangulation_face_base_with_info_2<FaceInfo, Kernel, Fb0>;
using Tds = CGAL::Triangulation_data_structure_2<Vb, Fb>;
using CDT = CGAL::Constrained_Delaunay_triangulation_2<Kernel, Tds, CGAL::Exact_predicates_tag>;
using VH = CDT::Vertex_handle;
using FH = CDT::Face_handle;

/// Sorts `order` (indices into `where`) along a space-filling curve: points inserted into
/// the triangulation in that order stay near the last one, where points taken along a
/// stroke, or along the Fibonacci lattice, make insertions flip long fans or walk far.
void spatially_sort(std::vector<std::size_t>& order, std::vector<Kernel::Point_2>& where)
{
    using Map = CGAL::Pointer_property_map<Kernel::Point_2>::type;
    CGAL::spatial_sort(order.begin(), order.end(), CGAL::Spatial_sort_traits_adapter_2<Kernel, Map>(CGAL::make_property_map(where)));
}

/// A lobe surface build with its triangulation: the constrained Delaunay triangulation of the
/// strokes' chains in the stereographic projection from the pole, refined with fill vertices.
class CdtLobeSurfaceBuilder final : public LobeSurfaceBuilder {
public:
    using LobeSurfaceBuilder::LobeSurfaceBuilder;

    /// `regions` (may be null): set to surface_regions of the result, which the build knows.
    LobeSurface run(SurfaceRegions* regions = nullptr);

private:
    void triangulate();
    void mark_regions();
    void mark_inside();
    void find_paper_regions();
    void refine();
    void seed_fill(double max_edge, int& added);
    void insert_fill(const glm::dvec2& x, int region, VH& hint, int& added);
    void insert_fill(const Node& n, const glm::dvec2& x, int region, VH& hint, int& added);
    /// The triangles of the triangulation and of the paper strips, for emit.
    SphereTriangles collect_triangles();
    VH insert_node(int id, VH hint);

    CDT cdt_;
    std::vector<VH> node_vertex_;                  ///< node → CDT vertex (several nodes may share one)
    std::vector<char> paper_region_;               ///< per region: stitched with stitch_closed_closed
    std::vector<std::pair<int, int>> region_strokes_;
    int region_count_ = 0;
    bool regions_stale_ = false;                   ///< faces' regions must be marked again
    int pole_node_ = -1;
    std::vector<char> region_inside_;              ///< per region: to be emitted
    std::vector<std::array<int, 2>> border_;       ///< node pairs (u, v): changed side runs u → v outward
    std::vector<std::array<int, 2>> inserted_;     ///< constrained node pairs
    double ring_angle_ = 0;
};

LobeSurface CdtLobeSurfaceBuilder::run(SurfaceRegions* regions)
{
    plan();
    LobeSurface out = start_surface();
    try {
        triangulate();
        refine();
        SphereTriangles built = collect_triangles();
        emit(std::move(built), out, regions);
    } catch (const CGAL::Failure_exception& e) {
        throw InvalidInput(std::string("the lobe's strokes could not be triangulated: ") + e.message());
    }
    return out;
}

VH CdtLobeSurfaceBuilder::insert_node(int id, VH hint)
{
    const glm::dvec2 x = stereo_.to_plane(nodes_[static_cast<Index>(id)].dir);
    const Kernel::Point_2 p(x.x, x.y);
    VH v = hint == VH() ? cdt_.insert(p) : cdt_.insert(p, hint->face());
    // Nodes at one point (two strokes through the same sample) share the vertex: it is the
    // first node's, whatever order they went in.
    if (v->info().id < 0 || id < v->info().id) v->info().id = id;
    return v;
}

void CdtLobeSurfaceBuilder::triangulate()
{
    node_vertex_.assign(nodes_.size(), VH());
    VH hint;
    {
        std::vector<Kernel::Point_2> where(nodes_.size());
        std::vector<std::size_t> order;
        std::vector<char> seen(nodes_.size(), 0);
        if (partial_) {
            // Only the nodes of the stroke edges in or around the changed regions.
            std::fill(seen.begin(), seen.end(), 1);
            for (Index s = 0; s < chains_.size(); ++s) {
                const auto& chain = chains_[s];
                const auto& edges = changed_.edges[s];
                for (Index i = 0; i < edges.size(); ++i)
                    if (edges[i] != ChangedRegions::Outside)
                        seen[static_cast<Index>(chain[i])] = seen[static_cast<Index>(chain[(i + 1) % chain.size()])] = 0;
            }
        }
        for (const auto& chain : chains_)
            for (int id : chain)
                if (!seen[static_cast<Index>(id)]) {
                    seen[static_cast<Index>(id)] = 1;
                    const glm::dvec2 x = stereo_.to_plane(nodes_[static_cast<Index>(id)].dir);
                    where[static_cast<Index>(id)] = Kernel::Point_2(x.x, x.y);
                    order.push_back(static_cast<std::size_t>(id));
                }
        spatially_sort(order, where);
        for (std::size_t id : order) hint = node_vertex_[id] = insert_node(static_cast<int>(id), hint);
    }
    // A small ring around the pole closes the planar triangulation's outside: the ring
    // encloses every stroke point, and the pole vertex fans the ring.
    const double ring_angle = ring_angle_ = std::min(empty_angle_ * 0.5, 2.0 * M_PI / 180.0);
    for (int k = 0; k < 6; ++k) {
        const double a = k * M_PI / 3.0;
        const glm::dvec3 d = std::cos(ring_angle) * stereo_.pole +
                             std::sin(ring_angle) * (std::cos(a) * stereo_.e1 + std::sin(a) * stereo_.e2);
        Node n;
        n.dir = d;
        const int id = add_node(n);
        node_vertex_.push_back(VH());
        node_vertex_[static_cast<Index>(id)] = insert_node(id, hint);
    }
    for (Index s = 0; s < chains_.size(); ++s) {
        const auto& chain = chains_[s];
        const Index n = chain.size();
        const Index count = strokes_[s].closed ? n : n - 1;
        for (Index i = 0; i < count; ++i) {
            const int u = chain[i], v = chain[(i + 1) % n];
            if (partial_) {
                const auto kind = changed_.edges[s][i];
                if (kind == ChangedRegions::Outside) continue;
                inserted_.push_back({u, v});
                if (kind == ChangedRegions::BorderAhead) border_.push_back({u, v});
                if (kind == ChangedRegions::BorderBack) border_.push_back({v, u});
            }
            const VH a = node_vertex_[static_cast<Index>(u)];
            const VH b = node_vertex_[static_cast<Index>(v)];
            if (a != b) cdt_.insert_constraint(a, b);
        }
    }
    Node pole;
    pole.dir = stereo_.pole;
    pole_node_ = add_node(pole);
    node_vertex_.push_back(VH());
}

void CdtLobeSurfaceBuilder::mark_regions()
{
    for (FH f : cdt_.all_face_handles()) f->info() = FaceInfo{};
    region_count_ = 0;
    std::vector<FH> stack;
    for (FH f : cdt_.finite_face_handles()) {
        if (f->info().region >= 0) continue;
        f->info().region = region_count_;
        stack.push_back(f);
        while (!stack.empty()) {
            FH g = stack.back();
            stack.pop_back();
            for (int i = 0; i < 3; ++i) {
                FH h = g->neighbor(i);
                if (cdt_.is_infinite(h) || h->info().region >= 0 || cdt_.is_constrained(CDT::Edge(g, i))) continue;
                h->info().region = region_count_;
                stack.push_back(h);
            }
        }
        ++region_count_;
    }
    mark_inside();
}

void CdtLobeSurfaceBuilder::mark_inside()
{
    region_inside_.assign(static_cast<Index>(region_count_), 1);
    if (!partial_) return;
    // The changed side of every border edge is in, the kept side out; every region is one
    // or the other (the border edges enclose the changed regions).
    std::vector<char> in(static_cast<Index>(region_count_), 0), out(static_cast<Index>(region_count_), 0);
    for (const auto& [u, v] : border_) {
        const VH a = node_vertex_[static_cast<Index>(u)], b = node_vertex_[static_cast<Index>(v)];
        FH f;
        int i = 0;
        if (a == b || !cdt_.is_edge(a, b, f, i)) throw PartialFailed{};
        // Outward u → v is planar clockwise: the changed side's face runs v → u counter-clockwise.
        const FH changed = f->vertex(CDT::ccw(i)) == b ? f : f->neighbor(i);
        const FH kept = changed == f ? f->neighbor(i) : f;
        if (cdt_.is_infinite(changed) || cdt_.is_infinite(kept)) throw PartialFailed{};
        in[static_cast<Index>(changed->info().region)] = 1;
        out[static_cast<Index>(kept->info().region)] = 1;
    }
    for (Index r = 0; r < in.size(); ++r) {
        if (in[r] && out[r]) throw PartialFailed{};
        region_inside_[r] = !out[r];
    }
}

void CdtLobeSurfaceBuilder::find_paper_regions()
{
    paper_region_.assign(static_cast<Index>(region_count_), 0);
    region_strokes_.assign(static_cast<Index>(region_count_), {-1, -1});
    if (!options_.paper_strips) return;
    std::vector<char> bad(static_cast<Index>(region_count_), 0);
    auto stroke_of = [&](VH v) -> int {
        const int id = v->info().id;
        if (id < 0) return -1;
        const auto& o = nodes_[static_cast<Index>(id)].origin;
        return o.kind == LobeVertexKind::Sample || o.kind == LobeVertexKind::Segment ? o.stroke : -1;
    };
    for (Index r = 0; r < static_cast<Index>(region_count_); ++r)
        if (!region_inside_[r]) bad[r] = 1;
    std::vector<std::array<int, 2>> edge_counts(static_cast<Index>(region_count_), {0, 0});
    for (FH f : cdt_.finite_face_handles()) {
        const Index r = static_cast<Index>(f->info().region);
        auto& rs = region_strokes_[r];
        for (int i = 0; i < 3; ++i) {
            const int s = stroke_of(f->vertex(i));
            if (s < 0 || crossing_count_[static_cast<Index>(s)] > 0 || !strokes_[static_cast<Index>(s)].closed) {
                bad[r] = 1;
                continue;
            }
            if (rs.first < 0 || rs.first == s) rs.first = s;
            else if (rs.second < 0 || rs.second == s) rs.second = s;
            else bad[r] = 1;
            if (cdt_.is_infinite(f->neighbor(i))) bad[r] = 1;
        }
        for (int i = 0; i < 3; ++i) {
            if (!cdt_.is_constrained(CDT::Edge(f, i))) continue;
            const int s = stroke_of(f->vertex((i + 1) % 3));
            if (s == rs.first) ++edge_counts[r][0];
            else if (s == rs.second) ++edge_counts[r][1];
        }
    }
    for (Index r = 0; r < static_cast<Index>(region_count_); ++r) {
        const auto [a, b] = region_strokes_[r];
        if (bad[r] || a < 0 || b < 0) continue;
        // The region is the whole annulus between the two loops: all their edges bound it.
        if (edge_counts[r][0] != static_cast<int>(chains_[static_cast<Index>(a)].size()) ||
            edge_counts[r][1] != static_cast<int>(chains_[static_cast<Index>(b)].size()))
            continue;
        paper_region_[r] = 1;
    }
}

void CdtLobeSurfaceBuilder::insert_fill(const glm::dvec2& x, int region, VH& hint, int& added)
{
    Node n;
    n.dir = glm::normalize(stereo_.to_sphere(x));
    insert_fill(n, x, region, hint, added);
}

void CdtLobeSurfaceBuilder::insert_fill(const Node& n, const glm::dvec2& x, int region, VH& hint, int& added)
{
    const int id = add_node(n);
    node_vertex_.push_back(VH());
    const Kernel::Point_2 p(x.x, x.y);
    const std::size_t before = cdt_.number_of_vertices();
    VH v = hint == VH() ? cdt_.insert(p) : cdt_.insert(p, hint->face());
    if (v->info().id < 0) v->info().id = id;
    node_vertex_[static_cast<Index>(id)] = v;
    hint = v;
    ++added;
    if (cdt_.number_of_vertices() == before) return; // an existing vertex: nothing changed
    // Every face an insertion creates or changes is incident to the new vertex, and lies in
    // the region of the point, unless the point fell on a stroke segment (which it then
    // splits) or outside every region: then the regions are marked again before they are read.
    if (region < 0 || cdt_.are_there_incident_constraints(v)) {
        regions_stale_ = true;
        return;
    }
    auto f = cdt_.incident_faces(v);
    const auto done = f;
    do {
        if (!cdt_.is_infinite(f)) f->info() = FaceInfo{region, false};
    } while (++f != done);
}

void CdtLobeSurfaceBuilder::seed_fill(double max_edge, int& added)
{
    // Fill vertices on a Fibonacci lattice of directions about as dense as the largest
    // allowed triangle, except near strokes and near the pole: uniform, deterministic, and
    // a new stroke only removes the lattice points near it.
    const std::vector<glm::dvec3> lattice = fill_lattice(max_edge, ring_angle_);
    std::vector<Kernel::Point_2> where;
    for (const glm::dvec3& d : lattice) {
        const glm::dvec2 x = stereo_.to_plane(d);
        where.emplace_back(x.x, x.y);
    }
    // Located and inserted along a space-filling curve.
    std::vector<std::size_t> order(lattice.size());
    for (Index i = 0; i < order.size(); ++i) order[i] = i;
    spatially_sort(order, where);
    struct Candidate {
        glm::dvec3 dir;
        int region; ///< -1: not located inside a face
    };
    std::vector<Candidate> candidates;
    FH hint_face;
    for (std::size_t i : order) {
        const glm::dvec3& d = lattice[i];
        const Kernel::Point_2& p = where[i];
        // Located before any fill vertex goes in.
        CDT::Locate_type lt;
        int li = 0;
        hint_face = cdt_.locate(p, lt, li, hint_face);
        const bool inside = hint_face != FH() && !cdt_.is_infinite(hint_face) && hint_face->info().region >= 0;
        if (inside && static_cast<Index>(hint_face->info().region) < paper_region_.size() &&
            (paper_region_[static_cast<Index>(hint_face->info().region)] ||
             !region_inside_[static_cast<Index>(hint_face->info().region)]))
            continue;
        candidates.push_back({d, inside && lt == CDT::FACE ? hint_face->info().region : -1});
    }
    VH hint;
    for (const Candidate& c : candidates) {
        if (added >= options_.max_fill_vertices) break;
        Node n;
        n.dir = c.dir;
        insert_fill(n, stereo_.to_plane(c.dir), c.region, hint, added);
    }
}


void CdtLobeSurfaceBuilder::refine()
{
    const double r = std::max(options_.reference_radius_m > 0 ? options_.reference_radius_m : mean_radius_, 1e-6);
    const double by_sagitta = std::acos(std::clamp(1.0 - options_.fill_sagitta_m / r, -1.0, 1.0));
    const double by_edge = options_.fill_edge_m / r;
    const double coarseness = std::isfinite(options_.fill_coarseness) ? std::clamp(options_.fill_coarseness, 1.0, 4.0) : 1.0;
    const double max_angle = std::max(1e-3, std::min(by_sagitta, by_edge) * coarseness);
    const double max_edge = std::sqrt(3.0) * max_angle;
    // A side whose chord is below this spans less than max_edge (with a margin far above
    // rounding), so most triangles are passed without an arcsine.
    const double short_chord = 2.0 * std::sin(0.5 * max_edge) * (1.0 - 1e-9);
    int added = 0;
    auto dir_of = [&](VH v) {
        const int id = v->info().id;
        if (id >= 0) return nodes_[static_cast<Index>(id)].dir;
        return glm::normalize(stereo_.to_sphere({v->point().x(), v->point().y()}));
    };
    // Regions are marked once; fill vertices inserted into a region keep its faces tagged
    // (insert_fill), and faces found fine in one pass are not looked at again until an
    // insertion changes them. Neither changes which points a pass adds.
    mark_regions();
    find_paper_regions();
    regions_stale_ = false;
    // Where every region built is a paper strip (a ring drawn between two others, Fig. 5),
    // there is nothing to fill: fill vertices go into the other regions only, and those are
    // the kept ones.
    bool to_fill = false;
    for (Index k = 0; k < static_cast<Index>(region_count_); ++k)
        to_fill = to_fill || (region_inside_[k] && !paper_region_[k]);
    if (!to_fill) return;
    seed_fill(max_edge, added);
    for (int pass = 0; pass < 4; ++pass) {
        if (regions_stale_) {
            mark_regions();
            find_paper_regions();
            regions_stale_ = false;
        }
        std::vector<std::pair<glm::dvec2, int>> points; // (where, region)
        for (FH f : cdt_.finite_face_handles()) {
            if (f->info().fine) continue;
            const int region = f->info().region;
            if (paper_region_[static_cast<Index>(region)] || !region_inside_[static_cast<Index>(region)]) {
                f->info().fine = true;
                continue;
            }
            const glm::dvec3 a = dir_of(f->vertex(0)), b = dir_of(f->vertex(1)), c = dir_of(f->vertex(2));
            // Too large: a free side longer than that of an equilateral triangle with the
            // largest circumradius allowed.
            // Stroke segments are never split here (remeshing splits them), so only free sides count.
            const std::array<glm::dvec3, 3> d{a, b, c};
            double chord = 0;
            for (int i = 0; i < 3; ++i)
                if (!cdt_.is_constrained(CDT::Edge(f, i)))
                    chord = std::max(chord, glm::length(d[static_cast<Index>((i + 1) % 3)] - d[static_cast<Index>((i + 2) % 3)]));
            if (chord < short_chord) {
                f->info().fine = true;
                continue;
            }
            double longest = 0;
            for (int i = 0; i < 3; ++i)
                if (!cdt_.is_constrained(CDT::Edge(f, i)))
                    longest = std::max(longest, angle_between(d[static_cast<Index>((i + 1) % 3)], d[static_cast<Index>((i + 2) % 3)]));
            if (longest <= max_edge) {
                f->info().fine = true;
                continue;
            }
            // The circumcentre (Delaunay refinement) when the triangle is not a sliver and its
            // circumcentre lies in the same region, else the centroid, which is inside the
            // triangle: no stroke is crossed either way.
            const double radius = circumradius_angle(a, b, c);
            bool use_cc = radius < longest;
            Kernel::Point_2 cc;
            if (use_cc) {
                cc = CGAL::circumcenter(f->vertex(0)->point(), f->vertex(1)->point(), f->vertex(2)->point());
                CDT::Locate_type lt;
                int li = 0;
                FH located = cdt_.locate(cc, lt, li, f);
                use_cc = lt == CDT::FACE && !cdt_.is_infinite(located) && located->info().region == region;
            }
            if (use_cc) {
                points.emplace_back(glm::dvec2(cc.x(), cc.y()), region);
            } else {
                glm::dvec2 x(0.0);
                for (int i = 0; i < 3; ++i) x += glm::dvec2(f->vertex(i)->point().x(), f->vertex(i)->point().y());
                points.emplace_back(x / 3.0, region);
            }
        }
        if (points.empty()) break;
        VH hint;
        for (const auto& [x, region] : points) {
            if (added >= options_.max_fill_vertices) break;
            insert_fill(x, region, hint, added);
        }
        if (added >= options_.max_fill_vertices) break;
    }
    // The output emits paper regions in region order (regions numbered by their first face):
    // with any paper region, or when an insertion left the regions stale, they are marked
    // again on the final triangulation. Otherwise the tags kept up by insert_fill are exact.
    if (regions_stale_ || std::find(paper_region_.begin(), paper_region_.end(), 1) != paper_region_.end()) {
        mark_regions();
        find_paper_regions();
        regions_stale_ = false;
    }
}

SphereTriangles CdtLobeSurfaceBuilder::collect_triangles()
{
    // CGAL vertices without a node (residual crossings it split itself) become fill nodes.
    for (auto v = cdt_.finite_vertices_begin(); v != cdt_.finite_vertices_end(); ++v) {
        if (v->info().id >= 0) continue;
        Node n;
        n.dir = glm::normalize(stereo_.to_sphere({v->point().x(), v->point().y()}));
        v->info().id = add_node(n);
        node_vertex_.push_back(v);
    }
    auto node_of = [&](VH v) { return v->info().id; };
    // The paper's strips for the regions between two uncrossed loops; a strip that would
    // fold seen from the centre leaves its region to the Delaunay triangles.
    SphereTriangles out;
    std::vector<std::array<int, 3>>& tris = out.triangles; // node ids, outward
    // Per triangle: its region of the triangulation, and which of its sides (side k: corner k
    // to corner k + 1) are stroke edges, so that the output's regions need not be found again.
    std::vector<int>& tri_region = out.region;
    std::vector<std::uint8_t>& tri_mask = out.stroke_sides;
    tris.reserve(cdt_.number_of_faces() + 8);
    tri_region.reserve(cdt_.number_of_faces() + 8);
    tri_mask.reserve(cdt_.number_of_faces() + 8);
    for (Index r = 0; r < paper_region_.size(); ++r) {
        if (!paper_region_[r]) continue;
        const auto [a, b] = region_strokes_[r];
        const std::vector<std::array<int, 3>> region = paper_strip(a, b);
        if (region.empty()) {
            paper_region_[r] = 0;
            continue;
        }
        tris.insert(tris.end(), region.begin(), region.end());
        for (const auto& t : region) {
            // A strip's stroke edges are its chains' edges: constrained edges of the triangulation.
            std::uint8_t mask = 0;
            for (int k = 0; k < 3; ++k) {
                const VH x = node_vertex_[static_cast<Index>(t[static_cast<Index>(k)])];
                const VH y = node_vertex_[static_cast<Index>(t[static_cast<Index>((k + 1) % 3)])];
                FH f;
                int i = 0;
                if (x != y && cdt_.is_edge(x, y, f, i) && cdt_.is_constrained(CDT::Edge(f, i)))
                    mask = static_cast<std::uint8_t>(mask | (1u << k));
            }
            tri_region.push_back(static_cast<int>(r));
            tri_mask.push_back(mask);
        }
    }
    out.strip_triangles = tris.size();
    if (partial_)
        // Every stroke edge triangulated lies in or around the changed regions: one that lies
        // in a kept region means the new strokes ran into a region taken for unchanged.
        for (const auto& [u, v] : inserted_) {
            const VH a = node_vertex_[static_cast<Index>(u)], b = node_vertex_[static_cast<Index>(v)];
            FH f;
            int i = 0;
            if (a == b) continue;
            if (!cdt_.is_edge(a, b, f, i)) throw PartialFailed{};
            const FH g = f->neighbor(i);
            if (!region_inside_[static_cast<Index>(f->info().region)] &&
                (cdt_.is_infinite(g) || !region_inside_[static_cast<Index>(g->info().region)]))
                throw PartialFailed{};
        }
    for (FH f : cdt_.finite_face_handles()) {
        if (paper_region_[static_cast<Index>(f->info().region)] || !region_inside_[static_cast<Index>(f->info().region)])
            continue;
        // Planar counter-clockwise is clockwise seen from outside the sphere.
        tris.push_back({node_of(f->vertex(0)), node_of(f->vertex(2)), node_of(f->vertex(1))});
        // Sides v0 v2, v2 v1, v1 v0: the edges opposite v1, v0 and v2.
        tri_region.push_back(f->info().region);
        tri_mask.push_back(static_cast<std::uint8_t>((cdt_.is_constrained(CDT::Edge(f, 1)) ? 1u : 0u) |
                                                     (cdt_.is_constrained(CDT::Edge(f, 0)) ? 2u : 0u) |
                                                     (cdt_.is_constrained(CDT::Edge(f, 2)) ? 4u : 0u)));
    }
    // The pole fans the ring (the triangulation's outer boundary).
    for (FH f : cdt_.all_face_handles()) {
        if (!cdt_.is_infinite(f)) continue;
        const int i = f->index(cdt_.infinite_vertex());
        if (!region_inside_[static_cast<Index>(f->neighbor(i)->info().region)]) continue;
        std::array<int, 3> t{pole_node_, node_of(f->vertex((i + 1) % 3)), node_of(f->vertex((i + 2) % 3))};
        if (orient3(nodes_[static_cast<Index>(t[0])].dir, nodes_[static_cast<Index>(t[1])].dir,
                    nodes_[static_cast<Index>(t[2])].dir) < 0)
            std::swap(t[1], t[2]);
        tris.push_back(t);
        tri_region.push_back(f->neighbor(i)->info().region);
        tri_mask.push_back(0); // the pole and the ring: no stroke edges
    }
    // Stroke segments (split at crossings) are the constraints of remeshing.
    for (const auto& e : cdt_.constrained_edges())
        out.stroke_edges.push_back({node_of(e.first->vertex(CDT::ccw(e.second))), node_of(e.first->vertex(CDT::cw(e.second)))});
    out.region_count = region_count_;
    return out;
}

} // namespace

} // namespace lobe_surface_detail

using lobe_surface_detail::CdtLobeSurfaceBuilder;
using lobe_surface_detail::PartialFailed;
using lobe_surface_detail::closed_surface;
using lobe_surface_detail::require_closed;

LobeSurface build_lobe_surface(const std::vector<LobeStrokeSamples>& strokes, const glm::dvec3& centre,
                               const LobeSurfaceOptions& options)
{
    CdtLobeSurfaceBuilder b(strokes, centre, options);
    LobeSurface surface = b.run();
    require_closed(surface.mesh);
    return surface;
}

LobeSurface continue_lobe_surface(const LobeSurface& previous, const SurfaceRegions& previous_regions,
                                  const std::vector<LobeStrokeSamples>& strokes, const glm::dvec3& centre,
                                  const LobeSurfaceOptions& options, SurfaceRegions& regions, KeptRegions& kept)
{
    // The builder hands on the regions of what it built, so they are not found again.
    try {
        CdtLobeSurfaceBuilder b(strokes, centre, options);
        b.set_previous(previous, previous_regions);
        SurfaceRegions built;
        LobeSurface surface = b.run(&built);
        if (!b.partial()) {
            regions = std::move(built);
            kept = keep_unchanged_regions(previous, previous_regions, surface, regions, true);
            kept.followed_previous_build = b.followed_previous();
            require_closed(surface.mesh);
            return surface;
        }
        // An open result of the changed regions falls back to the whole build, which refuses it
        // if it is open too.
        if (complete_with_kept_regions(previous, previous_regions, b.kept_previous_regions(), surface, built, kept, true) &&
            closed_surface(surface.mesh)) {
            regions = std::move(built);
            kept.built_changed_only = true;
            kept.followed_previous_build = b.followed_previous();
            return surface;
        }
    } catch (const PartialFailed&) {
    }
    CdtLobeSurfaceBuilder b(strokes, centre, options);
    b.set_previous(previous, previous_regions, false);
    LobeSurface surface = b.run(&regions);
    kept = keep_unchanged_regions(previous, previous_regions, surface, regions, true);
    kept.followed_previous_build = b.followed_previous();
    require_closed(surface.mesh);
    return surface;
}

} // namespace lobe
