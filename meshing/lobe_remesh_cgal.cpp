// Region-by-region remeshing of lobe surfaces (lobe_remesh.h): every region triangulated
// afresh in its own stereographic chart with CGAL's Constrained_Delaunay_triangulation_2,
// then remeshed with remesh_isotropic, its border fixed.
#include "meshing/lobe_remesh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <deque>
#include <tuple>
#include <utility>

#include "meshing/cgal_prelude.h"
LOBE_CGAL_HEADERS_BEGIN
#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>
LOBE_CGAL_HEADERS_END

#include <glm/geometric.hpp>

#include "core/errors.h"
#include "meshing/lobe_regions.h"
#include "meshing/mesh_quality.h"
#include "meshing/stereographic.h"

namespace lobe {

namespace {

using Index = std::size_t;
using cgal::Kernel;
using Vb = CGAL::Triangulation_vertex_base_with_info_2<int, Kernel>;
using Fb0 = CGAL::Constrained_triangulation_face_base_2<Kernel>;
using Fb = CGAL::Triangulation_face_base_with_info_2<int, Kernel, Fb0>;
using Tds = CGAL::Triangulation_data_structure_2<Vb, Fb>;
using CDT = CGAL::Constrained_Delaunay_triangulation_2<Kernel, Tds, CGAL::Exact_predicates_tag>;
using Key3 = std::array<float, 3>;

constexpr double kDegree = 3.14159265358979323846 / 180.0;

Key3 key_of(const glm::vec3& p) { return {p.x, p.y, p.z}; }

double orient3(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) { return glm::dot(a, glm::cross(b, c)); }

/// A stroke piece: feature edges from corner to corner (or a closed loop without corners),
/// and its resampling.
struct Piece {
    std::vector<int> vertices;       ///< surface vertices in the piece's canonical direction
    bool loop = false;               ///< closed: the last vertex joins the first
    std::vector<glm::vec3> samples;  ///< resampled, from the first vertex (loops: not repeated)
};

/// Splits the feature edges into pieces, each oriented by position (an open piece runs from
/// its lesser end; a loop starts at its least vertex towards its lesser neighbour), so that
/// the same piece in two surfaces is walked the same way whatever the vertex numbers.
std::vector<Piece> stroke_pieces(const TriangleMesh& mesh)
{
    const Index nv = mesh.positions.size();
    std::vector<std::vector<int>> adjacent(nv);
    for (const auto& e : mesh.feature_edges) {
        adjacent[static_cast<Index>(e[0])].push_back(e[1]);
        adjacent[static_cast<Index>(e[1])].push_back(e[0]);
    }
    auto less = [&](int a, int b) { return key_of(mesh.positions[static_cast<Index>(a)]) < key_of(mesh.positions[static_cast<Index>(b)]); };
    auto edge = [](int a, int b) { return std::array<int, 2>{std::min(a, b), std::max(a, b)}; };
    std::vector<std::array<int, 2>> all;
    for (const auto& e : mesh.feature_edges) all.push_back(edge(e[0], e[1]));
    std::sort(all.begin(), all.end());
    std::vector<char> done(all.size(), 0);
    auto mark = [&](int a, int b) {
        const auto it = std::lower_bound(all.begin(), all.end(), edge(a, b));
        const Index i = static_cast<Index>(it - all.begin());
        if (done[i]) return false;
        done[i] = 1;
        return true;
    };
    auto is_done = [&](int a, int b) { return done[static_cast<Index>(std::lower_bound(all.begin(), all.end(), edge(a, b)) - all.begin())] != 0; };
    std::vector<Piece> pieces;
    // Open pieces: from every corner (not two stroke edges) along each of its edges.
    for (Index v = 0; v < nv; ++v) {
        if (adjacent[v].empty() || adjacent[v].size() == 2) continue;
        for (int w : adjacent[v]) {
            if (is_done(static_cast<int>(v), w)) continue;
            Piece p;
            p.vertices = {static_cast<int>(v)};
            int prev = static_cast<int>(v), cur = w;
            mark(prev, cur);
            p.vertices.push_back(cur);
            while (adjacent[static_cast<Index>(cur)].size() == 2) {
                const auto& a = adjacent[static_cast<Index>(cur)];
                const int next = a[0] == prev ? a[1] : a[0];
                if (!mark(cur, next)) break;
                prev = cur;
                cur = next;
                p.vertices.push_back(cur);
            }
            const auto& walk = p.vertices;
            const bool round = walk.front() == walk.back() && walk.size() > 2; // back to its own corner
            if (round ? less(walk[walk.size() - 2], walk[1]) : less(walk.back(), walk.front()))
                std::reverse(p.vertices.begin(), p.vertices.end());
            pieces.push_back(std::move(p));
        }
    }
    // Loops: every vertex has two stroke edges.
    for (Index i = 0; i < all.size(); ++i) {
        if (done[i]) continue;
        std::vector<int> loop{all[i][0]};
        int prev = all[i][0], cur = all[i][1];
        mark(prev, cur);
        while (cur != loop.front()) {
            loop.push_back(cur);
            const auto& a = adjacent[static_cast<Index>(cur)];
            const int next = a[0] == prev ? a[1] : a[0];
            if (a.size() != 2 || !mark(cur, next)) return {}; // not a loop after all (never from a lobe surface)
            prev = cur;
            cur = next;
        }
        const Index m = loop.size();
        const Index least = static_cast<Index>(std::min_element(loop.begin(), loop.end(), less) - loop.begin());
        Piece p;
        p.loop = true;
        const bool forward = less(loop[(least + 1) % m], loop[(least + m - 1) % m]);
        for (Index k = 0; k < m; ++k) p.vertices.push_back(loop[forward ? (least + k) % m : (least + m - k) % m]);
        pieces.push_back(std::move(p));
    }
    return pieces;
}

/// Equal steps along the piece, as many as make them about `target` long and at most 1.2 ×
/// target (so remeshing never splits them: remesh_isotropic splits fixed edges over 1.25 ×).
void resample(Piece& piece, const TriangleMesh& mesh, double target)
{
    std::vector<glm::dvec3> p;
    for (int v : piece.vertices) p.emplace_back(mesh.positions[static_cast<Index>(v)]);
    if (piece.loop) p.push_back(p.front());
    std::vector<double> arc(p.size(), 0.0);
    for (Index i = 1; i < p.size(); ++i) arc[i] = arc[i - 1] + glm::distance(p[i - 1], p[i]);
    const double length = arc.back();
    long n = std::max({1L, std::lround(length / target), static_cast<long>(std::ceil(length / (1.2 * target)))});
    if (piece.loop || piece.vertices.front() == piece.vertices.back()) n = std::max(n, 3L); // a ring: a triangle at least
    piece.samples.clear();
    piece.samples.push_back(mesh.positions[static_cast<Index>(piece.vertices.front())]);
    Index seg = 0;
    for (long k = 1; k < n; ++k) {
        const double s = length * static_cast<double>(k) / static_cast<double>(n);
        while (seg + 2 < arc.size() && arc[seg + 1] < s) ++seg;
        const double span = arc[seg + 1] - arc[seg];
        const double t = span > 0.0 ? std::clamp((s - arc[seg]) / span, 0.0, 1.0) : 0.0;
        piece.samples.emplace_back(p[seg] + t * (p[seg + 1] - p[seg]));
    }
    if (!piece.loop) piece.samples.push_back(mesh.positions[static_cast<Index>(piece.vertices.back())]);
}

/// One region ready to be triangulated: its inner vertices and the pieces around it.
struct RegionInput {
    std::vector<int> faces;
    std::vector<int> inner;                ///< surface vertices on no stroke edge
    std::vector<std::pair<int, bool>> pieces; ///< (piece, dangling: the region lies on both sides)
};

/// The pole of a region's chart: opposite the region's mean direction from `centre` when
/// that lies outside every triangle of the region and at least 10° from its vertices;
/// otherwise (a strip that runs all the way round the centre has no useful mean) the
/// direction of a fixed lattice that lies outside the region farthest from its vertices, if
/// that is 2° or more; (0, 0, 0) where there is none.
glm::dvec3 chart_pole(const TriangleMesh& mesh, const glm::dvec3& centre, const RegionInput& region)
{
    auto direction = [&](const glm::vec3& p) { return glm::normalize(glm::dvec3(p) - centre); };
    std::vector<glm::dvec3> dirs;
    glm::dvec3 mean(0.0);
    for (int f : region.faces) {
        const auto& t = mesh.triangles[static_cast<Index>(f)];
        const glm::dvec3 a = direction(mesh.positions[static_cast<Index>(t[0])]);
        const glm::dvec3 b = direction(mesh.positions[static_cast<Index>(t[1])]);
        const glm::dvec3 c = direction(mesh.positions[static_cast<Index>(t[2])]);
        mean += 0.5 * glm::length(glm::cross(b - a, c - a)) * glm::normalize(a + b + c);
        dirs.insert(dirs.end(), {a, b, c});
    }
    auto nearest_cos = [&](const glm::dvec3& pole) {
        double most = -1.0;
        for (const glm::dvec3& d : dirs) most = std::max(most, glm::dot(d, pole));
        return most;
    };
    auto outside = [&](const glm::dvec3& pole) { // dirs holds each face's three corners in turn
        for (Index i = 0; i + 2 < dirs.size(); i += 3)
            if (orient3(dirs[i], dirs[i + 1], pole) >= 0.0 && orient3(dirs[i + 1], dirs[i + 2], pole) >= 0.0 &&
                orient3(dirs[i + 2], dirs[i], pole) >= 0.0)
                return false;
        return true;
    };
    glm::dvec3 pole(0.0);
    if (glm::length(mean) > 1e-9) {
        const glm::dvec3 p = -glm::normalize(mean);
        if (nearest_cos(p) < std::cos(10.0 * kDegree) && outside(p)) pole = p;
    }
    if (pole == glm::dvec3(0.0)) {
        constexpr int kLattice = 64;
        std::vector<std::pair<double, int>> ranked;
        for (int i = 0; i < kLattice; ++i) {
            // Fibonacci lattice of directions.
            const double z = 1.0 - (2.0 * i + 1.0) / kLattice;
            const double rho = std::sqrt(std::max(0.0, 1.0 - z * z));
            const double phi = i * 2.39996322972865332;
            ranked.emplace_back(nearest_cos({rho * std::cos(phi), rho * std::sin(phi), z}), i);
        }
        std::sort(ranked.begin(), ranked.end());
        for (const auto& [cos_near, i] : ranked) {
            if (cos_near > std::cos(2.0 * kDegree)) break;
            const double z = 1.0 - (2.0 * i + 1.0) / kLattice;
            const double rho = std::sqrt(std::max(0.0, 1.0 - z * z));
            const double phi = i * 2.39996322972865332;
            const glm::dvec3 p(rho * std::cos(phi), rho * std::sin(phi), z);
            if (outside(p)) {
                pole = p;
                break;
            }
        }
    }
    return pole;
}

/// A region's points in its chart: its inner vertices and its pieces' samples (a corner
/// shared by pieces once) as the positions of `out`, the pieces' segments as its feature
/// edges and as the triangulation's constraints, those of dangling pieces (the region on both
/// sides) also sorted in `dangling`.
struct ChartPoints {
    TriangleMesh out;
    std::vector<std::pair<Kernel::Point_2, int>> points; ///< (where in the chart, vertex of `out`)
    std::vector<std::array<int, 2>> constraints, dangling;
};

ChartPoints chart_points(const TriangleMesh& mesh, const glm::dvec3& centre, const Stereo& chart,
                         const RegionInput& region, const std::vector<Piece>& pieces)
{
    auto direction = [&](const glm::vec3& p) { return glm::normalize(glm::dvec3(p) - centre); };
    auto plane_point = [&](const glm::dvec3& d) {
        const glm::dvec2 x = chart.to_plane(d);
        return Kernel::Point_2(x.x, x.y);
    };
    ChartPoints cp;
    TriangleMesh& out = cp.out;
    std::vector<std::pair<Kernel::Point_2, int>>& points = cp.points;
    for (int v : region.inner) {
        points.emplace_back(plane_point(direction(mesh.positions[static_cast<Index>(v)])), static_cast<int>(out.positions.size()));
        out.positions.push_back(mesh.positions[static_cast<Index>(v)]);
    }
    // Piece samples: their ends (corners) may be shared by several pieces.
    std::vector<std::pair<Key3, int>> corner;
    auto add_sample = [&](const glm::vec3& p, bool end) {
        if (end) {
            for (const auto& [k, i] : corner)
                if (k == key_of(p)) return i;
        }
        const int i = static_cast<int>(out.positions.size());
        out.positions.push_back(p);
        points.emplace_back(plane_point(direction(p)), i);
        if (end) corner.emplace_back(key_of(p), i);
        return i;
    };
    std::vector<std::array<int, 2>>& constraints = cp.constraints;
    std::vector<std::array<int, 2>>& dangling = cp.dangling;
    for (const auto& [pi, both] : region.pieces) {
        const Piece& piece = pieces[static_cast<Index>(pi)];
        std::vector<int> ids;
        for (Index k = 0; k < piece.samples.size(); ++k)
            ids.push_back(add_sample(piece.samples[k], !piece.loop && (k == 0 || k + 1 == piece.samples.size())));
        if (piece.loop) ids.push_back(ids.front());
        for (Index k = 0; k + 1 < ids.size(); ++k) {
            constraints.push_back({ids[k], ids[k + 1]});
            if (both) dangling.push_back({std::min(ids[k], ids[k + 1]), std::max(ids[k], ids[k + 1])});
        }
    }
    std::sort(dangling.begin(), dangling.end());
    for (const auto& c : constraints) out.feature_edges.push_back({std::min(c[0], c[1]), std::max(c[0], c[1])});
    return cp;
}

/// The triangles of the region (those inside its border in the constrained Delaunay
/// triangulation of `cp`) into cp.out; false where they cannot be made (points that coincide
/// in the chart, pieces that cross, a triangle facing the centre, none at all).
bool triangulate_in_chart(ChartPoints& cp, const glm::dvec3& centre)
{
    TriangleMesh& out = cp.out;
    const auto& points = cp.points;
    const auto& constraints = cp.constraints;
    const auto& dangling = cp.dangling;
    CDT cdt;
    std::vector<CDT::Vertex_handle> handle(out.positions.size());
    for (const auto& [x, i] : points) {
        const CDT::Vertex_handle v = cdt.insert(x);
        v->info() = i; // a point where another already is leaves the count short (below)
        handle[static_cast<Index>(i)] = v;
    }
    if (cdt.number_of_vertices() != out.positions.size()) return false;
    for (const auto& c : constraints) cdt.insert_constraint(handle[static_cast<Index>(c[0])], handle[static_cast<Index>(c[1])]);
    // A piece crossing another (or an inner vertex on a piece) made a vertex of its own.
    if (cdt.number_of_vertices() != out.positions.size()) return false;
    // Every point on one line of the chart: no faces (a 1-dimensional triangulation's have
    // no neighbours to walk), nothing to triangulate.
    if (cdt.dimension() < 2) return false;

    // Inside: reached from outside across an odd number of border constraints.
    for (auto f = cdt.all_faces_begin(); f != cdt.all_faces_end(); ++f) f->info() = -1;
    std::deque<std::pair<CDT::Face_handle, int>> queue{{cdt.infinite_face(), 0}};
    while (!queue.empty()) {
        const auto [f, level] = queue.front();
        queue.pop_front();
        if (f->info() >= 0) continue;
        f->info() = level;
        for (int i = 0; i < 3; ++i) {
            const CDT::Face_handle g = f->neighbor(i);
            if (g->info() >= 0) continue;
            const bool border = f->is_constrained(i) &&
                                !std::binary_search(dangling.begin(), dangling.end(),
                                                    std::array<int, 2>{std::min(f->vertex(CDT::cw(i))->info(), f->vertex(CDT::ccw(i))->info()),
                                                                       std::max(f->vertex(CDT::cw(i))->info(), f->vertex(CDT::ccw(i))->info())});
            if (border) queue.emplace_back(g, level + 1);
            else queue.emplace_front(g, level);
        }
    }
    for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f) {
        if (f->info() % 2 == 0) continue;
        // Planar counter-clockwise is clockwise seen from outside the sphere.
        const std::array<int, 3> t{f->vertex(0)->info(), f->vertex(2)->info(), f->vertex(1)->info()};
        const glm::dvec3 a(out.positions[static_cast<Index>(t[0])]), b(out.positions[static_cast<Index>(t[1])]),
            c(out.positions[static_cast<Index>(t[2])]);
        if (!(glm::dot(glm::cross(b - a, c - a), (a + b + c) / 3.0 - centre) > 0.0)) return false;
        out.triangles.push_back(t);
    }
    if (out.triangles.empty()) return false;
    return true;
}

/// `out` without the vertices no triangle uses; empty where a feature edge is one of them.
TriangleMesh without_unused_vertices(TriangleMesh out)
{
    // An inner vertex the resampled border left outside (between a piece's chord and the
    // drawn stroke) is used by no triangle: dropped, so that it becomes no attractor.
    std::vector<int> index(out.positions.size(), -1);
    for (const auto& t : out.triangles)
        for (int v : t) index[static_cast<Index>(v)] = 0;
    for (const auto& e : out.feature_edges)
        if (index[static_cast<Index>(e[0])] < 0 || index[static_cast<Index>(e[1])] < 0) return {}; // a piece outside
    int used = 0;
    for (int& i : index)
        if (i == 0) i = used++;
    if (used == static_cast<int>(out.positions.size())) return out;
    TriangleMesh compact;
    for (Index v = 0; v < out.positions.size(); ++v)
        if (index[v] >= 0) compact.positions.push_back(out.positions[v]);
    for (const auto& t : out.triangles)
        compact.triangles.push_back({index[static_cast<Index>(t[0])], index[static_cast<Index>(t[1])], index[static_cast<Index>(t[2])]});
    for (const auto& e : out.feature_edges) compact.feature_edges.push_back({index[static_cast<Index>(e[0])], index[static_cast<Index>(e[1])]});
    return compact;
}

/// The region triangulated in its own chart from its resampled pieces and inner vertices;
/// empty when that is not possible (then the lobe is remeshed whole).
TriangleMesh triangulate_region(const LobeSurface& surface, const RegionInput& region, const std::vector<Piece>& pieces)
{
    const glm::dvec3 pole = chart_pole(surface.mesh, surface.centre, region);
    if (pole == glm::dvec3(0.0)) return {};
    const Stereo chart(pole);
    ChartPoints cp = chart_points(surface.mesh, surface.centre, chart, region, pieces);
    if (!triangulate_in_chart(cp, surface.centre)) return {};
    return without_unused_vertices(std::move(cp.out));
}

TriangleMesh remesh_whole(const LobeSurface& surface, const RemeshOptions& options)
{
    RemeshOptions o = options;
    o.protect_feature_edges = true;
    o.relax_feature_edges = true;
    o.faces.clear();
    o.radial_centre = surface.centre;
    TriangleMesh out = remesh_isotropic(surface.mesh, o);
    // A lobe not much larger than the spacing collapses (CGAL collapses every edge under 4/5
    // of the target): two triangles back to back are no lobe to grow a tree in.
    const MeshQuality q = measure_quality(out);
    if (!q.closed || !q.manifold || !q.outward || q.components != 1 || !(q.signed_volume_m3 > 0.0)) {
        char buf[160];
        std::snprintf(buf, sizeof buf, "remeshing at %g cm leaves no closed surface of this lobe (too small for the attractor spacing)",
                      100.0 * options.target_edge_length_m);
        throw InvalidInput(buf);
    }
    return out;
}

/// Every stroke edge's piece, and whether the piece runs along it from its lower vertex.
class EdgePieces {
public:
    explicit EdgePieces(const std::vector<Piece>& pieces)
    {
        for (Index i = 0; i < pieces.size(); ++i) {
            const auto& v = pieces[i].vertices;
            for (Index k = 0; k + 1 < v.size() + (pieces[i].loop ? 1 : 0); ++k) {
                const int a = v[k], b = v[(k + 1) % v.size()];
                edge_piece_.push_back({{std::min(a, b), std::max(a, b)}, {static_cast<int>(i), a < b}});
            }
        }
        std::sort(edge_piece_.begin(), edge_piece_.end());
    }
    /// (piece, 1 when the piece runs from a to b, 2 when from b to a), or (−1, 0).
    std::pair<int, int> piece_of(int a, int b) const
    {
        const std::array<int, 2> e{std::min(a, b), std::max(a, b)};
        const auto it = std::lower_bound(edge_piece_.begin(), edge_piece_.end(), std::make_pair(e, std::make_pair(-1, false)));
        if (it == edge_piece_.end() || it->first != e) return std::make_pair(-1, 0);
        return std::make_pair(it->second.first, it->second.second == (a < b) ? 1 : 2);
    }

private:
    std::vector<std::pair<std::array<int, 2>, std::pair<int, bool>>> edge_piece_;
};

/// Each region's faces, inner vertices (on no stroke edge) and pieces (dangling where the
/// region lies on both sides of one).
std::vector<RegionInput> region_inputs(const TriangleMesh& mesh, const MeshRegions& regions, const EdgePieces& edges)
{
    std::vector<RegionInput> input(static_cast<Index>(regions.count));
    std::vector<char> on_stroke(mesh.positions.size(), 0);
    for (const auto& e : mesh.feature_edges) on_stroke[static_cast<Index>(e[0])] = on_stroke[static_cast<Index>(e[1])] = 1;
    std::vector<int> seen(mesh.positions.size(), -1);
    std::vector<std::vector<std::pair<int, int>>> sides(input.size()); // (piece, +1 / −1 per side seen)
    for (Index f = 0; f < mesh.triangles.size(); ++f) {
        const int r = regions.face_region[f];
        RegionInput& in = input[static_cast<Index>(r)];
        in.faces.push_back(static_cast<int>(f));
        const auto& t = mesh.triangles[f];
        for (int k = 0; k < 3; ++k) {
            const int a = t[static_cast<Index>(k)], b = t[static_cast<Index>((k + 1) % 3)];
            if (!on_stroke[static_cast<Index>(a)] && seen[static_cast<Index>(a)] != r) {
                seen[static_cast<Index>(a)] = r;
                in.inner.push_back(a);
            }
            const auto [p, side] = edges.piece_of(a, b);
            if (p >= 0) sides[static_cast<Index>(r)].emplace_back(p, side);
        }
    }
    for (Index r = 0; r < input.size(); ++r) {
        auto& s = sides[r];
        std::sort(s.begin(), s.end());
        for (Index i = 0; i < s.size();) {
            Index j = i;
            int mask = 0;
            while (j < s.size() && s[j].first == s[i].first) mask |= s[j++].second;
            input[r].pieces.emplace_back(s[i].first, mask == 3);
            i = j;
        }
    }
    return input;
}

/// Puts the region's faces, inner vertices and pieces in an order of their own (by position),
/// so that what is made of them does not depend on how the surface numbers them: the same
/// region in the next surface, numbered otherwise, is remeshed the same. Returns the region's
/// key: its triangles' corners and its pieces' samples in that order.
std::vector<float> order_region(const TriangleMesh& mesh, RegionInput& in, const std::vector<Piece>& pieces)
{
    std::vector<std::pair<std::array<float, 9>, int>> tagged;
    for (int f : in.faces) {
        std::array<Key3, 3> c{};
        for (Index k = 0; k < 3; ++k) c[k] = key_of(mesh.positions[static_cast<Index>(mesh.triangles[static_cast<Index>(f)][k])]);
        const Index first = static_cast<Index>(std::min_element(c.begin(), c.end()) - c.begin());
        std::array<float, 9> t{};
        for (Index k = 0; k < 3; ++k)
            for (Index j = 0; j < 3; ++j) t[3 * k + j] = c[(first + k) % 3][j];
        tagged.emplace_back(t, f);
    }
    std::sort(tagged.begin(), tagged.end());
    std::vector<std::array<float, 9>> tris;
    for (Index i = 0; i < tagged.size(); ++i) {
        tris.push_back(tagged[i].first);
        in.faces[i] = tagged[i].second;
    }
    std::sort(in.inner.begin(), in.inner.end(), [&](int a, int b) {
        return key_of(mesh.positions[static_cast<Index>(a)]) < key_of(mesh.positions[static_cast<Index>(b)]);
    });
    std::sort(in.pieces.begin(), in.pieces.end(), [&](const std::pair<int, bool>& a, const std::pair<int, bool>& b) {
        const auto& x = pieces[static_cast<Index>(a.first)].samples;
        const auto& y = pieces[static_cast<Index>(b.first)].samples;
        const bool less = std::lexicographical_compare(x.begin(), x.end(), y.begin(), y.end(), [](const glm::vec3& u, const glm::vec3& w) {
            return key_of(u) < key_of(w);
        });
        const bool more = std::lexicographical_compare(y.begin(), y.end(), x.begin(), x.end(), [](const glm::vec3& u, const glm::vec3& w) {
            return key_of(u) < key_of(w);
        });
        return less || (!more && a.second < b.second);
    });
    std::vector<float> key;
    key.reserve(9 * tris.size() + 16);
    for (const auto& t : tris) key.insert(key.end(), t.begin(), t.end());
    for (const auto& [p, both] : in.pieces) {
        key.push_back(both ? 2.0f : 1.0f);
        for (const glm::vec3& s : pieces[static_cast<Index>(p)].samples) key.insert(key.end(), {s.x, s.y, s.z});
    }
    return key;
}

/// The remeshed regions joined at their stroke vertices (the same positions on both sides).
TriangleMesh join_regions(const std::vector<const TriangleMesh*>& remeshed)
{
    TriangleMesh out;
    std::map<Key3, int> shared;
    for (const TriangleMesh* part : remeshed) {
        std::vector<char> on(part->positions.size(), 0);
        for (const auto& e : part->feature_edges) on[static_cast<Index>(e[0])] = on[static_cast<Index>(e[1])] = 1;
        std::vector<int> index(part->positions.size(), -1);
        for (Index v = 0; v < part->positions.size(); ++v) {
            if (on[v]) {
                const auto [it, added] = shared.emplace(key_of(part->positions[v]), static_cast<int>(out.positions.size()));
                index[v] = it->second;
                if (!added) continue;
            } else {
                index[v] = static_cast<int>(out.positions.size());
            }
            out.positions.push_back(part->positions[v]);
        }
        for (const auto& t : part->triangles)
            out.triangles.push_back({index[static_cast<Index>(t[0])], index[static_cast<Index>(t[1])], index[static_cast<Index>(t[2])]});
        for (const auto& e : part->feature_edges) {
            const int a = index[static_cast<Index>(e[0])], b = index[static_cast<Index>(e[1])];
            out.feature_edges.push_back({std::min(a, b), std::max(a, b)});
        }
    }
    std::sort(out.feature_edges.begin(), out.feature_edges.end());
    out.feature_edges.erase(std::unique(out.feature_edges.begin(), out.feature_edges.end()), out.feature_edges.end());
    return out;
}

/// Whether the joined regions make a closed, 2-manifold, outward surface using every vertex.
bool joined_surface_ok(const TriangleMesh& out)
{
    const MeshQuality q = measure_quality(out);
    std::vector<char> used(out.positions.size(), 0);
    for (const auto& t : out.triangles)
        for (int v : t) used[static_cast<Index>(v)] = 1;
    const bool all_used = std::find(used.begin(), used.end(), 0) == used.end();
    return q.closed && q.manifold && q.outward && all_used;
}

} // namespace

TriangleMesh remesh_lobe_surface(const LobeSurface& surface, const RemeshOptions& options, LobeRemeshCache* cache,
                                 LobeRemeshStats* stats)
{
    LobeRemeshStats local;
    LobeRemeshStats& st = stats ? *stats : local;
    st = {};
    const double target = options.target_edge_length_m;
    const TriangleMesh& mesh = surface.mesh;
    if (!(target > 0) || !std::isfinite(target) || options.iterations == 0 || mesh.feature_edges.empty() ||
        surface.origins.size() != mesh.positions.size()) {
        st.whole = true;
        return remesh_whole(surface, options);
    }
    // The limit of remesh_isotropic on the whole surface, before anything is allocated.
    if (!(remesh_triangle_estimate(remesh_area(mesh), target) <= static_cast<double>(kMaxRemeshTriangles))) {
        st.whole = true;
        return remesh_whole(surface, options); // which refuses it with its message
    }
    if (cache && (cache->target != target || cache->iterations != options.iterations || cache->centre != surface.centre)) {
        // A region's remeshing depends on these too (a paper strip has no inner vertex, so its
        // triangles stay the same when the centre moves; its chart does not).
        cache->regions.clear();
        cache->target = target;
        cache->iterations = options.iterations;
        cache->centre = surface.centre;
    }

    std::vector<Piece> pieces = stroke_pieces(mesh);
    if (pieces.empty()) {
        st.whole = true;
        return remesh_whole(surface, options);
    }
    for (Piece& p : pieces) resample(p, mesh, target);
    const EdgePieces edges(pieces);

    const MeshRegions regions = mesh_regions(mesh);
    st.regions = regions.count;
    std::vector<RegionInput> input = region_inputs(mesh, regions, edges);

    // Each region: from the cache, or triangulated and remeshed.
    RemeshOptions region_options;
    region_options.target_edge_length_m = target;
    region_options.iterations = options.iterations;
    region_options.protect_feature_edges = true;
    region_options.relax_feature_edges = false;
    region_options.own_rounds = true; // with the small-angle repairs
    region_options.radial_centre = surface.centre;

    std::map<std::vector<float>, TriangleMesh> now;
    std::vector<const TriangleMesh*> remeshed(input.size(), nullptr);
    for (Index r = 0; r < input.size(); ++r) {
        RegionInput& in = input[r];
        const std::vector<float> key = order_region(mesh, in, pieces);
        auto it = now.find(key);
        if (it == now.end() && cache) {
            const auto c = cache->regions.find(key);
            if (c != cache->regions.end()) {
                it = now.emplace(key, std::move(c->second)).first;
                ++st.reused;
            }
        }
        if (it == now.end()) {
            TriangleMesh start = triangulate_region(surface, in, pieces);
            TriangleMesh done;
            if (!start.triangles.empty()) {
                try {
                    done = remesh_isotropic(start, region_options);
                } catch (const InvalidInput&) {
                    done = TriangleMesh{}; // the whole lobe is remeshed instead (below)
                }
            }
            if (done.triangles.empty()) {
                if (cache) cache->regions.clear();
                st = {};
                st.regions = regions.count;
                st.whole = true;
                return remesh_whole(surface, options);
            }
            it = now.emplace(key, std::move(done)).first;
            ++st.remeshed;
        }
        remeshed[r] = &it->second;
    }

    TriangleMesh out = join_regions(remeshed);
    if (!joined_surface_ok(out)) {
        if (cache) cache->regions.clear();
        st = {};
        st.regions = regions.count;
        st.whole = true;
        return remesh_whole(surface, options);
    }
    if (cache) cache->regions = std::move(now);
    return out;
}

} // namespace lobe
