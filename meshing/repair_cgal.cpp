// Mesh repair with CGAL's Polygon Mesh Processing (finding self-intersections is in
// self_intersections_cgal.cpp, a translation unit of its own). Works on CGAL::Surface_mesh rather than
// OpenMesh: the soup-to-mesh functions, hole filling and component removal need no
// per-element status bookkeeping there, and nothing outside this file sees the type.
#include "meshing/repair.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <iterator>
#include <limits>
#include <map>
#include <optional>
#include <queue>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "meshing/cgal_prelude.h"
LOBE_CGAL_HEADERS_BEGIN
#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Delaunay_mesh_face_base_2.h>
#include <CGAL/Delaunay_mesh_vertex_base_2.h>
#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Polygon_2_algorithms.h>
#include <CGAL/Projection_traits_3.h>
#include <CGAL/boost/graph/Euler_operations.h>
#include <CGAL/boost/graph/selection.h>
#include <CGAL/Polygon_mesh_processing/border.h>
#include <CGAL/Polygon_mesh_processing/compute_normal.h>
#include <CGAL/Polygon_mesh_processing/connected_components.h>
#include <CGAL/Polygon_mesh_processing/fair.h>
#include <CGAL/Polygon_mesh_processing/manifoldness.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/refine.h>
#include <CGAL/Polygon_mesh_processing/repair_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/triangulate_hole.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>
#include <CGAL/bounding_box.h>
LOBE_CGAL_HEADERS_END

#include "core/errors.h"
#include "meshing/mesh_quality.h"

namespace lobe {

namespace {

using namespace cgal; // Kernel, Point, Mesh, PMP
using VertexIndex = Mesh::Vertex_index;
using Polygon = std::vector<std::size_t>;

/// The input as a polygon soup, with its preconditions checked.
void to_soup(const TriangleMesh& in, const char* who, std::vector<Point>& points, std::vector<Polygon>& polygons)
{
    points.reserve(in.positions.size());
    for (const glm::vec3& p : in.positions) {
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
            throw InvalidInput(std::string(who) + ": vertex with a non-finite coordinate");
        points.emplace_back(p.x, p.y, p.z);
    }
    const auto n = static_cast<long long>(in.positions.size());
    polygons.reserve(in.triangles.size());
    for (const auto& t : in.triangles) {
        for (int v : t)
            if (v < 0 || v >= n) throw InvalidInput(std::string(who) + ": triangle index out of range");
        polygons.push_back({static_cast<std::size_t>(t[0]), static_cast<std::size_t>(t[1]), static_cast<std::size_t>(t[2])});
    }
}

/// A compact (garbage-free) Surface_mesh as a TriangleMesh.
TriangleMesh to_triangle_mesh(Mesh& mesh)
{
    mesh.collect_garbage();
    TriangleMesh out;
    out.positions.reserve(mesh.number_of_vertices());
    for (VertexIndex v : mesh.vertices()) {
        const Point& p = mesh.point(v);
        out.positions.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()));
    }
    out.triangles.reserve(mesh.number_of_faces());
    for (auto f : mesh.faces()) {
        std::array<int, 3> t{};
        int k = 0;
        for (VertexIndex v : CGAL::vertices_around_face(mesh.halfedge(f), mesh)) {
            if (k < 3) t[static_cast<std::size_t>(k)] = static_cast<int>(v.idx());
            ++k;
        }
        if (k != 3) throw InvalidInput("repair_mesh: internal error: a face is not a triangle");
        out.triangles.push_back(t);
    }
    return out;
}

/// Vertices at exactly the same position (the copies of a split non-manifold vertex) are
/// moved 1% of the way towards the centroid of their own neighbours, so the surface no
/// longer touches itself there. Returns how many vertices moved.
std::size_t separate_coincident_vertices(Mesh& mesh)
{
    std::map<std::array<double, 3>, std::vector<VertexIndex>> at;
    for (VertexIndex v : mesh.vertices()) {
        const Point& p = mesh.point(v);
        at[{p.x(), p.y(), p.z()}].push_back(v);
    }
    std::size_t moved = 0;
    for (const auto& [key, group] : at) {
        if (group.size() < 2) continue;
        for (VertexIndex v : group) {
            double c[3] = {0, 0, 0};
            int n = 0;
            for (VertexIndex w : CGAL::vertices_around_target(mesh.halfedge(v), mesh)) {
                const Point& q = mesh.point(w);
                c[0] += q.x();
                c[1] += q.y();
                c[2] += q.z();
                ++n;
            }
            if (n == 0) continue;
            const double s = 0.01 / n;
            mesh.point(v) = Point(key[0] + (c[0] - n * key[0]) * s, key[1] + (c[1] - n * key[1]) * s,
                                  key[2] + (c[2] - n * key[2]) * s);
            ++moved;
        }
    }
    return moved;
}

/// Keeps the component with the most triangles.
void keep_largest_component(Mesh& mesh, RepairReport& r)
{
    auto fcc = mesh.add_property_map<Mesh::Face_index, std::size_t>("f:lobe_cc").first;
    const std::size_t n = PMP::connected_components(mesh, fcc);
    mesh.remove_property_map(fcc);
    r.components = std::max(r.components, n);
    if (n <= 1) return;
    const std::size_t faces_before = mesh.number_of_faces();
    PMP::keep_largest_connected_components(mesh, 1);
    mesh.collect_garbage();
    r.removed_component_triangles += faces_before - mesh.number_of_faces();
    r.notes.push_back("kept the largest of " + std::to_string(n) + " connected components (dropped " +
                      std::to_string(faces_before - mesh.number_of_faces()) + " triangles)");
}

/// Holes with more border edges than this are not handed to CGAL's whole search for the best
/// patch. It runs over the faces of the border points' 3D Delaunay triangulation, which on a
/// long border that is nearly flat or nearly on a sphere (the cut-off base of a scan) holds a
/// large share of all point pairs: 550 MB for 2,000 edges, 1.6 GB for 3,000. When that finds
/// nothing it falls back to a search over all triangulations of the border, cubic in its
/// length, which on thousands of edges would run for hours. Up to this size both are kept;
/// the reference models' largest hole (the bunny's base) has 80 edges.
constexpr std::size_t kLargeHole = 200;
/// Large holes whose border is not a simple polygon in its plane still get the Delaunay
/// search, without the cubic fallback, up to this size (about 140 MB at worst): its patch
/// crosses the surface far less often than a fan, and crossings can cost the
/// self-intersection removal tens of seconds.
constexpr std::size_t kSearchedHole = 1000;

std::size_t border_edges(const Mesh& mesh, Mesh::Halfedge_index h)
{
    std::size_t n = 0;
    for (auto it = h;;) {
        ++n;
        it = mesh.next(it);
        if (it == h) return n;
    }
}

/// Triangulates the polygon face `f` by the 2D constrained Delaunay triangulation of its
/// border seen along `normal` (the triangles CGAL's triangulate_face makes), and appends the
/// faces to `patch`. Returns false, leaving the mesh as it was, where that triangulation has
/// other vertices than the border (two border points meet in the plane) or no area.
///
/// Written here rather than calling triangulate_face so that the result does not depend on
/// what ran before in the process: triangulate_face creates the patch's edges in the order of
/// the triangulation's edge iterator, which reports each edge from the face whose handle
/// compares smaller, and handles of faces without time stamps compare by address, i.e. by
/// the heap's history. The same hole then got other halfedge numbers, which refinement,
/// fairing and the cuts of step 5 follow, so a mesh repaired twice in one process could come
/// out two ways. Here the triangulation's faces and vertices carry time stamps (the base
/// classes of CGAL's 2D mesher) and the face is split along the triangulation's inner edges,
/// one by one, in the order of its faces.
bool triangulate_in_plane(Mesh& mesh, Mesh::Face_index f, const Kernel::Vector_3& normal,
                          std::vector<Mesh::Face_index>& patch)
{
    using Traits = CGAL::Projection_traits_3<Kernel>;
    using Vb = CGAL::Triangulation_vertex_base_with_info_2<VertexIndex, Traits, CGAL::Delaunay_mesh_vertex_base_2<Traits>>;
    using Fb = CGAL::Delaunay_mesh_face_base_2<Traits>; // in_domain: inside the polygon
    using Tds = CGAL::Triangulation_data_structure_2<Vb, Fb>;
    using Cdt = CGAL::Constrained_Delaunay_triangulation_2<Traits, Tds, CGAL::Exact_intersections_tag>;
    Cdt cdt{Traits(normal)};
    std::size_t corners = 0;
    Cdt::Vertex_handle first, previous;
    for (VertexIndex v : CGAL::vertices_around_face(mesh.halfedge(f), mesh)) {
        const Cdt::Vertex_handle w = cdt.insert(mesh.point(v));
        w->info() = v;
        if (first == Cdt::Vertex_handle()) first = w;
        if (previous != Cdt::Vertex_handle() && previous != w) cdt.insert_constraint(previous, w);
        previous = w;
        ++corners;
    }
    if (previous != first) cdt.insert_constraint(previous, first);
    if (cdt.dimension() != 2 || cdt.number_of_vertices() != corners) return false;
    // Outside: what the infinite faces reach without crossing the border.
    for (auto g : cdt.all_face_handles()) g->set_in_domain(true);
    std::vector<Cdt::Face_handle> stack{cdt.infinite_face()};
    while (!stack.empty()) {
        const Cdt::Face_handle g = stack.back();
        stack.pop_back();
        if (!g->is_in_domain()) continue;
        g->set_in_domain(false);
        for (int i = 0; i < 3; ++i)
            if (!cdt.is_constrained({g, i})) stack.push_back(g->neighbor(i));
    }
    // The inner edges, each once (from its face with the smaller time stamp).
    std::vector<std::array<VertexIndex, 2>> diagonals;
    for (auto g : cdt.finite_face_handles()) {
        if (!g->is_in_domain()) continue;
        for (int i = 0; i < 3; ++i) {
            const Cdt::Face_handle n = g->neighbor(i);
            if (cdt.is_constrained({g, i}) || !n->is_in_domain() || n->time_stamp() < g->time_stamp()) continue;
            diagonals.push_back({g->vertex(Cdt::ccw(i))->info(), g->vertex(Cdt::cw(i))->info()});
        }
    }
    // Splitting the polygon along each diagonal in turn: both ends lie on one face of the
    // patch, which the diagonal splits in two.
    std::vector<char> in_patch(mesh.number_of_faces() + mesh.number_of_removed_faces() + diagonals.size() + 1, 0);
    in_patch[f.idx()] = 1;
    patch.push_back(f);
    for (const auto& [a, b] : diagonals) {
        Mesh::Halfedge_index at_a, at_b;
        for (Mesh::Halfedge_index h : CGAL::halfedges_around_target(a, mesh)) {
            const Mesh::Face_index g = mesh.face(h);
            if (g == Mesh::null_face() || !in_patch[g.idx()]) continue;
            for (Mesh::Halfedge_index k : CGAL::halfedges_around_face(h, mesh))
                if (mesh.target(k) == b) at_b = k;
            if (at_b != Mesh::null_halfedge()) {
                at_a = h;
                break;
            }
        }
        // Cannot happen for a triangulation of the polygon; said rather than split wrongly.
        if (at_a == Mesh::null_halfedge()) throw InvalidInput("repair_mesh: a hole's triangulation does not fit its border");
        const Mesh::Halfedge_index d = CGAL::Euler::split_face(at_a, at_b, mesh);
        Mesh::Face_index g = mesh.face(d); // the new one of the two faces
        if (g.idx() < in_patch.size() && in_patch[g.idx()]) g = mesh.face(mesh.opposite(d));
        if (g.idx() >= in_patch.size()) in_patch.resize(g.idx() + 1, 0);
        in_patch[g.idx()] = 1;
        patch.push_back(g);
    }
    return true;
}

/// The patch CGAL's triangulate_hole finds for the hole whose border starts at `h` (a border
/// halfedge), found the same way but with ties broken by vertex order rather than by memory:
/// among the triangulations of the border polygon whose triangles are faces of the border
/// points' 3D Delaunay triangulation, the one with the smallest largest dihedral angle
/// (between neighbouring patch triangles, and between a triangle on the border and the face
/// beyond it), then the smallest area; no triangle with collinear corners, and no patch edge
/// that the surface already has. Dynamic programming over sub-polygons (Liepa 2003, with the
/// Delaunay restriction of Zou et al. 2013). The weights are computed as CGAL computes them,
/// so where no two patches tie this is CGAL's patch, triangle for triangle, and the faces are
/// made in the order CGAL makes them.
///
/// Why not CGAL's own: its search starts from the Delaunay edge between the border's first and
/// last point as the triangulation's edge iterator gives it, which reports each edge from the
/// cell whose handle compares smaller, by address (CGAL 5.5's cells carry no time stamps), and
/// of equally good candidates keeps the first it meets going round that edge. A flat or round
/// border has many ties, so the patch depended on what the process had allocated before.
///
/// Where the Delaunay triangulation lacks a border edge, every triangle on that edge, and the
/// two others such a triangle needs, are candidates too, as in CGAL. Returns the patch's faces;
/// none where no such patch exists (CGAL then searches all triangulations, when allowed:
/// `cubic_may_help`) or where the border meets itself at a vertex (CGAL gives up).
std::vector<Mesh::Face_index> search_hole_patch(Mesh& mesh, Mesh::Halfedge_index h, bool& cubic_may_help)
{
    cubic_may_help = false;
    // The border: P[k] the target of its k-th halfedge, Q[k] the corner opposite the next
    // border edge in the face beyond it.
    std::vector<Mesh::Halfedge_index> edges;
    std::vector<Point> P, Q;
    std::map<VertexIndex, int> id;
    for (Mesh::Halfedge_index k : CGAL::halfedges_around_face(h, mesh)) {
        if (!id.emplace(mesh.target(k), static_cast<int>(P.size())).second) return {};
        edges.push_back(k);
        P.push_back(mesh.point(mesh.target(k)));
        Q.push_back(mesh.point(mesh.target(mesh.next(mesh.opposite(mesh.next(k))))));
    }
    const int n = static_cast<int>(P.size());
    cubic_may_help = true;
    if (n < 3) return {};
    // Edges the surface already has between border vertices that are not border neighbours.
    std::vector<std::pair<int, int>> existing;
    for (const auto& [v, i] : id)
        for (Mesh::Halfedge_index k : CGAL::halfedges_around_target(v, mesh)) {
            const auto other = id.find(mesh.source(k));
            if (other == id.end()) continue;
            const int j = other->second;
            if (j != (i + n - 1) % n && j != (i + 1) % n && i < j) existing.emplace_back(i, j);
        }
    std::sort(existing.begin(), existing.end());
    auto has_edge = [&](int a, int b) { return std::binary_search(existing.begin(), existing.end(), std::make_pair(a, b)); };

    // The Delaunay faces, as the third corners of each edge (i < j), in increasing order.
    using Vb = CGAL::Triangulation_vertex_base_with_info_3<int, Kernel>;
    using Tds = CGAL::Triangulation_data_structure_3<Vb, CGAL::Delaunay_triangulation_cell_base_3<Kernel>>;
    using Delaunay = CGAL::Delaunay_triangulation_3<Kernel, Tds>;
    std::vector<std::pair<Point, int>> points;
    for (int i = 0; i < n; ++i) points.emplace_back(P[static_cast<std::size_t>(i)], i);
    Delaunay dt(points.begin(), points.end());
    if (dt.dimension() < 2) return {};
    auto key = [n](int a, int b) { return static_cast<std::int64_t>(std::min(a, b)) * n + std::max(a, b); };
    std::vector<std::pair<std::int64_t, int>> thirds; // (key(i, j), k)
    for (auto f = dt.finite_facets_begin(); f != dt.finite_facets_end(); ++f) {
        std::array<int, 3> c{};
        int m = 0;
        for (int k = 0; k < 4; ++k)
            if (k != f->second) c[static_cast<std::size_t>(m++)] = f->first->vertex(k)->info();
        thirds.emplace_back(key(c[0], c[1]), c[2]);
        thirds.emplace_back(key(c[0], c[2]), c[1]);
        thirds.emplace_back(key(c[1], c[2]), c[0]);
    }
    std::sort(thirds.begin(), thirds.end());
    std::vector<std::pair<int, int>> missing;
    auto by_edge = [](const std::pair<std::int64_t, int>& x, const std::pair<std::int64_t, int>& y) { return x.first < y.first; };
    for (int i = 0; i < n; ++i)
        if (!std::binary_search(thirds.begin(), thirds.end(), std::make_pair(key(i, (i + 1) % n), 0), by_edge))
            missing.emplace_back(i, (i + 1) % n);
    for (const auto& [a, b] : missing)
        for (int k = 0; k < n; ++k) {
            if (k == a || k == b) continue;
            thirds.emplace_back(key(a, b), k);
            thirds.emplace_back(key(k, a), b);
            thirds.emplace_back(key(k, b), a);
        }
    if (!missing.empty()) {
        std::sort(thirds.begin(), thirds.end());
        thirds.erase(std::unique(thirds.begin(), thirds.end()), thirds.end());
    }
    auto third_range = [&](int a, int b) { return std::equal_range(thirds.begin(), thirds.end(), std::make_pair(key(a, b), 0), by_edge); };

    // W(i, j): the best patch of the polygon i, i+1, …, j (i < j) closed by the edge j → i, as
    // (largest angle, area); NOT_VALID (-1, -1) where none; lambda: its triangle's third corner.
    using Weight = std::pair<double, double>;
    const Weight not_valid(-1.0, -1.0);
    const std::size_t nn = static_cast<std::size_t>(n) * static_cast<std::size_t>(n);
    std::vector<Weight> W(nn, Weight(0.0, 0.0));
    std::vector<int> lambda(nn, -1);
    std::vector<char> done(nn, 0);
    auto at = [n](int a, int b) { return static_cast<std::size_t>(a) * static_cast<std::size_t>(n) + static_cast<std::size_t>(b); };
    auto is_border = [n](int a, int b) { return a + 1 == b || (a == n - 1 && b == 0); };
    // The triangle (i, m, j)'s weight: the largest of 180° less the dihedral angle with the face
    // beyond each border edge, and with the triangle the sub-polygon beyond (i, m) and (m, j)
    // chose; the edge (j, i) is weighed by the triangle above it.
    auto weight = [&](int i, int m, int j) {
        const std::array<int, 3> v{i, m, j};
        double largest = 0;
        for (std::size_t e = 0; e < 3; ++e) {
            const int a = v[e], b = v[(e + 1) % 3], c = v[(e + 2) % 3];
            double angle = 0;
            const auto pa = static_cast<std::size_t>(a), pb = static_cast<std::size_t>(b), pc = static_cast<std::size_t>(c);
            if (is_border(a, b)) {
                angle = 180 - std::abs(CGAL::to_double(CGAL::approximate_dihedral_angle(P[pa], P[pb], P[pc], Q[pa])));
            } else if (e != 2 && lambda[at(a, b)] != -1) {
                const Point& beyond = P[static_cast<std::size_t>(lambda[at(a, b)])];
                angle = 180 - std::abs(CGAL::to_double(CGAL::approximate_dihedral_angle(P[pa], P[pb], P[pc], beyond)));
            }
            largest = std::max(largest, angle);
        }
        const double area = CGAL::to_double(CGAL::approximate_sqrt(CGAL::squared_area(
            P[static_cast<std::size_t>(i)], P[static_cast<std::size_t>(m)], P[static_cast<std::size_t>(j)])));
        return Weight(largest, area);
    };
    // A candidate triangle: its third corner between i and j, corners not collinear, no edge the
    // surface has (the edge j → i is checked by the triangle above it).
    auto usable = [&](int i, int m, int j) {
        return i < m && m < j &&
               !CGAL::collinear(P[static_cast<std::size_t>(i)], P[static_cast<std::size_t>(m)], P[static_cast<std::size_t>(j)]) &&
               (m == i + 1 || !has_edge(i, m)) && (j == m + 1 || !has_edge(m, j));
    };
    auto less = [](const Weight& a, const Weight& b) { return a.first == b.first ? a.second < b.second : a.first < b.first; };
    // Depth-first, without recursion: a border hole has up to kSearchedHole corners.
    std::vector<std::pair<int, int>> stack{{0, n - 1}};
    while (!stack.empty()) {
        const auto [i, j] = stack.back();
        if (j - i < 2 || done[at(i, j)]) {
            stack.pop_back();
            continue;
        }
        // Every sub-polygon a candidate needs is solved first.
        bool ready = true;
        const auto [lo, hi] = third_range(i, j);
        for (auto t = lo; t != hi; ++t) {
            const int m = t->second;
            if (!usable(i, m, j)) continue;
            for (const auto& [a, b] : {std::make_pair(i, m), std::make_pair(m, j)})
                if (b - a >= 2 && !done[at(a, b)]) {
                    stack.emplace_back(a, b);
                    ready = false;
                }
        }
        if (!ready) continue;
        stack.pop_back();
        Weight best = not_valid;
        int best_m = -1;
        for (auto t = lo; t != hi; ++t) {
            const int m = t->second;
            if (!usable(i, m, j)) continue;
            const Weight& left = W[at(i, m)];
            const Weight& right = W[at(m, j)];
            if (left == not_valid || right == not_valid) continue;
            const Weight own = weight(i, m, j);
            const Weight w(std::max({0.0, left.first, right.first, own.first}), ((0.0 + left.second) + right.second) + own.second);
            if (best_m == -1 || less(w, best)) {
                best = w;
                best_m = m;
            }
        }
        W[at(i, j)] = best;
        lambda[at(i, j)] = best_m;
        done[at(i, j)] = 1;
    }
    if (lambda[at(0, n - 1)] == -1) return {};

    // The faces, made as CGAL's tracer makes them: each sub-polygon's two halves first, then its
    // triangle added to the border between them (the last one closes the hole).
    std::vector<Mesh::Face_index> patch;
    struct Frame {
        int i, k;
        bool last;
        int stage; ///< 0: halves to make, 1: left made, 2: both made
        Mesh::Halfedge_index left;
    };
    std::vector<Frame> frames{{0, n - 1, true, 0, {}}};
    Mesh::Halfedge_index result;
    while (!frames.empty()) {
        Frame& fr = frames.back();
        const auto ui = static_cast<std::size_t>(fr.i);
        if (fr.i + 1 == fr.k) {
            result = edges[(ui + 1) % static_cast<std::size_t>(n)];
            frames.pop_back();
            continue;
        }
        Mesh::Halfedge_index made;
        if (fr.i + 2 == fr.k) {
            const Mesh::Halfedge_index e1 = edges[ui + 1], e2 = edges[(ui + 2) % static_cast<std::size_t>(n)];
            if (fr.last) {
                made = e1;
                CGAL::Euler::fill_hole(made, mesh);
            } else {
                made = CGAL::Euler::add_face_to_border(mesh.prev(e1), e2, mesh);
            }
        } else {
            const int m = lambda[at(fr.i, fr.k)];
            if (fr.stage == 0) {
                fr.stage = 1;
                frames.push_back({fr.i, m, false, 0, {}});
                continue;
            }
            if (fr.stage == 1) {
                fr.left = result;
                fr.stage = 2;
                frames.push_back({m, fr.k, false, 0, {}});
                continue;
            }
            if (fr.last) {
                made = result;
                CGAL::Euler::fill_hole(made, mesh);
            } else {
                made = CGAL::Euler::add_face_to_border(mesh.prev(fr.left), result, mesh);
            }
        }
        patch.push_back(mesh.face(made));
        result = mesh.opposite(made);
        frames.pop_back();
    }
    return patch;
}

/// A hole's patch as CGAL's triangulate_hole makes it (search_hole_patch), with CGAL's search
/// over all triangulations, cubic in the border, where no Delaunay patch exists and `cubic`
/// allows it (that search has no ties left to memory: it tries the corners in order).
std::vector<Mesh::Face_index> triangulate_hole_searched(Mesh& mesh, Mesh::Halfedge_index h, bool cubic)
{
    bool cubic_may_help = false;
    std::vector<Mesh::Face_index> patch = search_hole_patch(mesh, h, cubic_may_help);
    if (patch.empty() && cubic && cubic_may_help)
        PMP::triangulate_hole(mesh, h, std::back_inserter(patch), PMP::parameters::use_delaunay_triangulation(false));
    return patch;
}

/// Refines a hole's patch and fairs the new vertices unless `unfaired`, as CGAL's
/// triangulate_refine_and_fair_hole does after triangulating; `new_faces` receives the patch
/// and the faces refining made, `new_vertices` (appended to) the vertices it made. Returns
/// whether the patch was faired.
bool refine_and_fair(Mesh& mesh, const std::vector<Mesh::Face_index>& patch, bool unfaired,
                     std::vector<Mesh::Face_index>& new_faces, std::vector<VertexIndex>& new_vertices)
{
    new_faces = patch;
    PMP::refine(mesh, patch, std::back_inserter(new_faces), std::back_inserter(new_vertices));
    return !unfaired && PMP::fair(mesh, new_vertices);
}

/// Fills a large hole (kLargeHole) and refines the patch, faired unless `unfaired`:
/// 1. in the plane of its vector area, by a 2D constrained Delaunay triangulation
///    (triangulate_in_plane on the hole made one polygon), where the border seen in that
///    plane is a simple polygon (the wavy base of a scan): O(n log n) time, linear memory;
/// 2. otherwise, up to kSearchedHole edges, by the search for the best patch among the
///    faces of the border's 3D Delaunay triangulation (search_hole_patch), without the cubic
///    fallback;
/// 3. otherwise by a fan from the border's centroid, always a manifold patch.
/// Any of them may cross the surface; the crossing check after filling deals with that.
/// (CGAL's own planar route in triangulate_hole averages the normals of a fan after turning
/// each towards positive x, which fails on a flat border seen edge-on in x.)
/// Returns whether the patch was faired; `by_fan` tells whether step 3 made it.
bool fill_large_hole(Mesh& mesh, Mesh::Halfedge_index h, bool unfaired, std::vector<Mesh::Face_index>& new_faces,
                     std::vector<VertexIndex>& new_vertices, bool& by_fan)
{
    std::vector<Point> ring; // the border, from h on
    for (VertexIndex v : CGAL::vertices_around_face(h, mesh)) ring.push_back(mesh.point(v));
    by_fan = false;
    std::vector<Mesh::Face_index> patch;
    CGAL::Euler::fill_hole(h, mesh);
    // A constrained triangulation refuses a polygon that runs over itself in its plane only
    // after inserting every crossing exactly, which took CGAL's triangulate_face minutes on a
    // steep zig-zag: the polygon is tested first (a sweep), seen along the same normal.
    const Kernel::Vector_3 normal = PMP::compute_face_normal(mesh.face(h), mesh);
    const bool simple = normal != CGAL::NULL_VECTOR &&
                        CGAL::is_simple_2(ring.begin(), ring.end(), CGAL::Projection_traits_3<Kernel>(normal));
    if (!simple || !triangulate_in_plane(mesh, mesh.face(h), normal, patch)) {
        patch.clear();
        if (ring.size() <= kSearchedHole) {
            CGAL::Euler::remove_face(h, mesh); // a hole again (a refusing triangulate_in_plane leaves the polygon)
            patch = triangulate_hole_searched(mesh, h, false);
            if (patch.empty()) CGAL::Euler::fill_hole(h, mesh);
        }
        if (patch.empty()) {
            by_fan = true;
            const Mesh::Halfedge_index spoke = CGAL::Euler::add_center_vertex(h, mesh);
            const VertexIndex centre = mesh.target(spoke);
            double c[3] = {0, 0, 0};
            for (const Point& p : ring) {
                c[0] += p.x();
                c[1] += p.y();
                c[2] += p.z();
            }
            const double inv = 1.0 / static_cast<double>(ring.size());
            mesh.point(centre) = Point(c[0] * inv, c[1] * inv, c[2] * inv);
            new_vertices.push_back(centre);
            for (auto f : CGAL::faces_around_target(spoke, mesh)) patch.push_back(f);
        }
    }
    return refine_and_fair(mesh, patch, unfaired, new_faces, new_vertices);
}

struct FillCounts {
    std::size_t filled = 0, faired = 0, fans = 0; ///< fans: large holes filled by a fan
};

/// Fills the holes whose boundary cycles start at `borders`, each with a refined, faired
/// patch unless `unfaired` flags it (a refined patch then, not faired); large holes
/// (kLargeHole) by fill_large_hole.
/// `patch` receives, per face, 1 + the index of the hole it fills (0: not a patch face).
FillCounts fill_holes_once(Mesh& mesh, const std::vector<Mesh::Halfedge_index>& borders,
                           const std::vector<char>& unfaired, Mesh::Property_map<Mesh::Face_index, std::size_t> patch)
{
    FillCounts n;
    for (std::size_t i = 0; i < borders.size(); ++i) {
        const Mesh::Halfedge_index h = borders[i];
        std::vector<Mesh::Face_index> new_faces;
        std::vector<VertexIndex> new_vertices;
        const bool large = border_edges(mesh, h) > kLargeHole;
        if (large) {
            bool by_fan = false;
            if (fill_large_hole(mesh, h, unfaired[i] != 0, new_faces, new_vertices, by_fan)) ++n.faired;
            if (by_fan) ++n.fans;
        } else if (refine_and_fair(mesh, triangulate_hole_searched(mesh, h, true), unfaired[i] != 0, new_faces,
                                   new_vertices)) {
            ++n.faired;
        }
        if (!new_faces.empty()) ++n.filled;
        for (Mesh::Face_index f : new_faces) patch[f] = i + 1;
    }
    return n;
}

/// Which hole's patch each face of `mesh` belongs to (1 + its index; 0: none), for fill_holes
/// to tell which patches cross; in the order to_triangle_mesh writes the faces.
Mesh::Property_map<Mesh::Face_index, std::size_t> patch_map(Mesh& mesh)
{
    return mesh.add_property_map<Mesh::Face_index, std::size_t>("f:lobe_patch", 0).first;
}

std::vector<std::size_t> patch_of_faces(Mesh& mesh)
{
    const auto patch = patch_map(mesh);
    std::vector<std::size_t> out;
    out.reserve(mesh.number_of_faces());
    for (auto f : mesh.faces()) out.push_back(patch[f]);
    return out;
}

/// The pairs of intersecting triangles of `tm`; nothing when it is not 2-manifold as a soup
/// (the self-intersection step says so, as it always did).
std::optional<std::vector<std::array<std::size_t, 2>>> crossing_pairs(const TriangleMesh& tm)
{
    try {
        return self_intersecting_pairs(tm);
    } catch (const InvalidInput&) {
        return std::nullopt;
    }
}

/// Fills every hole with a refined, faired patch.
/// Fairing keeps the patch's interior smooth but not out of the surface's way: over a long,
/// wavy border (the open base of a scan, say) the faired patch can fold through itself or
/// the surface. Those holes are filled again with the refined patch alone, which lies on the
/// border's triangulation. Left to CGAL's self-intersection removal, such a fold cost a minute on a
/// 1,000-edge border and took most of the mesh with it. `pairs` (when given) receives the
/// intersecting pairs of the result when they were found on the way (one pass saved).
/// \throw InvalidInput when a hole stays open.
void fill_holes(Mesh& mesh, RepairReport& r, std::optional<std::vector<std::array<std::size_t, 2>>>* pairs = nullptr)
{
    std::vector<Mesh::Halfedge_index> borders;
    PMP::extract_boundary_cycles(mesh, std::back_inserter(borders));
    if (borders.empty()) return;
    const Mesh before = mesh; // halfedge indices (the borders) stay valid in the copy
    std::vector<char> unfaired(borders.size(), 0);
    FillCounts n = fill_holes_once(mesh, borders, unfaired, patch_map(mesh));
    std::size_t refilled = 0;
    if (n.faired > 0 && CGAL::is_closed(mesh)) {
        const TriangleMesh tm = to_triangle_mesh(mesh);
        const std::vector<std::size_t> patch_of = patch_of_faces(mesh);
        auto found = crossing_pairs(tm);
        if (found)
            for (const auto& pair : *found)
                for (std::size_t t : pair)
                    if (t < patch_of.size() && patch_of[t] > 0 && !unfaired[patch_of[t] - 1]) {
                        unfaired[patch_of[t] - 1] = 1;
                        ++refilled;
                    }
        if (refilled > 0) {
            mesh = before;
            n = fill_holes_once(mesh, borders, unfaired, patch_map(mesh));
        } else if (pairs && found) {
            *pairs = std::move(*found);
        }
    }
    r.holes_filled += n.filled;
    r.holes_faired += n.faired;
    r.holes_not_faired += refilled;
    r.holes_fanned += n.fans;
    r.notes.push_back("filled " + std::to_string(n.filled) + " of " + std::to_string(borders.size()) + " holes (" +
                      std::to_string(n.faired) + " faired" +
                      (refilled ? ", " + std::to_string(refilled) + " not faired: a faired patch crossed the surface" : "") +
                      (n.fans ? ", " + std::to_string(n.fans) + " filled by a fan from the centre (long, and running over itself in its plane)" : "") +
                      ")");
    if (!CGAL::is_closed(mesh))
        throw InvalidInput("repair_mesh: a hole could not be filled (" + std::to_string(borders.size() - n.filled) +
                           " of " + std::to_string(borders.size()) + " left open)");
}

/// Steps of cut_out_crossings; each cuts one ring wider round what still crosses.
constexpr unsigned kRemovalSteps = 4;

/// `mesh` without the faces `cut` flags, its vertices renumbered (unused ones dropped).
Mesh without_faces(const Mesh& mesh, Mesh::Property_map<Mesh::Face_index, bool> cut)
{
    std::vector<Point> points;
    std::vector<Polygon> polygons;
    std::vector<std::size_t> index(mesh.number_of_vertices() + mesh.number_of_removed_vertices(), SIZE_MAX);
    for (auto f : mesh.faces()) {
        if (cut[f]) continue;
        Polygon t;
        for (VertexIndex v : CGAL::vertices_around_face(mesh.halfedge(f), mesh)) {
            std::size_t& i = index[v.idx()];
            if (i == SIZE_MAX) {
                i = points.size();
                points.push_back(mesh.point(v));
            }
            t.push_back(i);
        }
        polygons.push_back(std::move(t));
    }
    Mesh out;
    PMP::polygon_soup_to_polygon_mesh(points, polygons, out);
    return out;
}

/// The squared length of the edge of `h`.
double squared_length(const Mesh& mesh, Mesh::Halfedge_index h)
{
    return CGAL::to_double(CGAL::squared_distance(mesh.point(mesh.source(h)), mesh.point(mesh.target(h))));
}

/// Longest-edge bisection (Rivara) of the faces `region` flags, until no edge of them is
/// longer than `max_length` or `max_splits` edges were split: the longest edge first, split at
/// its midpoint and joined to the opposite corner on both sides (a face outside the region
/// that shares the edge is split too, and stays outside). The new edges are candidates
/// themselves, so a long, thin triangle becomes a ladder of short rungs across it rather than
/// a fan of long slivers from one corner, which is what CGAL's split_long_edges leaves (it
/// splits only the edges it is given). Returns the number of splits.
std::size_t bisect_long_edges(Mesh& mesh, Mesh::Property_map<Mesh::Face_index, bool> region, double max_length,
                              std::size_t max_splits)
{
    const double limit = max_length * max_length;
    auto squared = [&](Mesh::Halfedge_index h) { return squared_length(mesh, h); };
    auto in_region = [&](Mesh::Halfedge_index h) {
        const auto f = mesh.face(h), g = mesh.face(mesh.opposite(h));
        return (f != Mesh::null_face() && region[f]) || (g != Mesh::null_face() && region[g]);
    };
    // (squared length, halfedge); an entry whose edge has since been split (its length no
    // longer matches) is passed over: the halves were queued when it was split.
    std::priority_queue<std::pair<double, std::uint32_t>> queue;
    auto consider = [&](Mesh::Halfedge_index h) {
        const double l = squared(h);
        if (l > limit && in_region(h)) queue.push({l, static_cast<std::uint32_t>(h.idx())});
    };
    for (auto f : mesh.faces())
        if (region[f])
            for (auto h : CGAL::halfedges_around_face(mesh.halfedge(f), mesh))
                if (h < mesh.opposite(h) || mesh.is_border(mesh.opposite(h)) || !region[mesh.face(mesh.opposite(h))])
                    consider(h);
    std::size_t splits = 0;
    while (!queue.empty() && splits < max_splits) {
        const auto [length, index] = queue.top();
        queue.pop();
        const Mesh::Halfedge_index h(index);
        if (squared(h) != length) continue;
        const Point mid = CGAL::midpoint(mesh.point(mesh.source(h)), mesh.point(mesh.target(h)));
        const Mesh::Halfedge_index hnew = CGAL::Euler::split_edge(h, mesh); // target: the new vertex; next: h
        mesh.point(mesh.target(hnew)) = mid;
        ++splits;
        consider(hnew);
        consider(h);
        if (!mesh.is_border(hnew)) {
            const auto f = mesh.face(hnew);
            const Mesh::Halfedge_index d = CGAL::Euler::split_face(hnew, mesh.next(mesh.next(hnew)), mesh);
            region[mesh.face(mesh.opposite(d))] = region[f];
            region[mesh.face(d)] = region[f];
            consider(d);
        }
        const Mesh::Halfedge_index o = mesh.opposite(hnew);
        if (!mesh.is_border(o)) {
            const auto f = mesh.face(o);
            const Mesh::Halfedge_index d = CGAL::Euler::split_face(mesh.prev(o), mesh.next(o), mesh);
            region[mesh.face(mesh.opposite(d))] = region[f];
            region[mesh.face(d)] = region[f];
            consider(d);
        }
    }
    return splits;
}

/// How finely the region of cut_out_crossings' first cut is bisected: six times the median
/// shortest edge of the crossing faces, so that on a mesh of even triangles nothing is split
/// and a long, thin triangle (a band of a coarse dome, a CAD export) becomes rungs at most six
/// times as long as it is wide; at least a thousandth of the mesh's bounding box.
double rung_length(const Mesh& mesh, const std::vector<Mesh::Face_index>& faces)
{
    std::vector<double> shortest;
    shortest.reserve(faces.size());
    for (auto f : faces) {
        double s = std::numeric_limits<double>::infinity();
        for (auto h : CGAL::halfedges_around_face(mesh.halfedge(f), mesh))
            s = std::min(s, squared_length(mesh, h));
        shortest.push_back(std::sqrt(s));
    }
    if (shortest.empty()) return std::numeric_limits<double>::infinity();
    std::nth_element(shortest.begin(), shortest.begin() + static_cast<std::ptrdiff_t>(shortest.size() / 2), shortest.end());
    const auto box = CGAL::bounding_box(mesh.points().begin(), mesh.points().end());
    const double diagonal = std::sqrt(CGAL::to_double(CGAL::squared_distance(box.min(), box.max())));
    return std::max(6.0 * shortest[shortest.size() / 2], 1e-3 * diagonal);
}

/// Splits bisect_long_edges may make: at most as many as the mesh has faces, and 50,000, so
/// the mesh grows to at most three times its faces. (Bisected at every step with a looser
/// bound, hole_fill's domes grew to 110,000 faces and took up to 9.4 s in release.)
std::size_t split_budget(const Mesh& mesh) { return std::min<std::size_t>(mesh.number_of_faces(), 50000); }

/// Steps of a removal whose first cut was bisected. Narrow rings clear the crossings a refilled
/// hole's patch makes less often than rings of whole triangles, and every step over a bisected
/// mesh costs its fill and a crossing search on up to three times the faces. With a second step,
/// 27 instead of 17 of 350 hole_fill domes kept over 2 % more volume than the whole-triangle
/// cuts, but the folded 638-edge seed took 22–30 s under ASan (the fuzz timeout was 30 s). One
/// step, then, and repair_mesh compares its result with the cuts of whole triangles (step 5).
constexpr unsigned kBisectedSteps = 1;

/// The volume a closed, consistently oriented surface encloses (negative: inside out).
double enclosed_volume(const Mesh& mesh)
{
    double six = 0.0;
    for (auto f : mesh.faces()) {
        const auto h = mesh.halfedge(f);
        const Point& a = mesh.point(mesh.source(h));
        const Point& b = mesh.point(mesh.target(h));
        const Point& c = mesh.point(mesh.target(mesh.next(h)));
        six += CGAL::to_double(CGAL::determinant(a - CGAL::ORIGIN, b - CGAL::ORIGIN, c - CGAL::ORIGIN));
    }
    return six / 6.0;
}

/// Flags in `selected` the faces of `pairs` (indices of a garbage-free mesh) and returns them.
std::vector<Mesh::Face_index> select_faces(const Mesh& mesh, const std::vector<std::array<std::size_t, 2>>& pairs,
                                           Mesh::Property_map<Mesh::Face_index, bool> selected)
{
    std::vector<Mesh::Face_index> out;
    for (const auto& pair : pairs)
        for (std::size_t t : pair) {
            const Mesh::Face_index f(static_cast<Mesh::size_type>(t));
            if (t < mesh.number_of_faces() && !selected[f]) {
                selected[f] = true;
                out.push_back(f);
            }
        }
    return out;
}

/// What cut_out_crossings left, and why it stopped.
struct Removal {
    std::size_t left = 0;  ///< crossing pairs left
    bool bisected = false; ///< the first cut's region was bisected (bisect_long_edges split something)
    enum class Stop { Clean, Steps, WholeMesh, Unfillable } stop = Stop::Clean;
};

/// Removes self-intersections (the cow's tail runs into its body) by cutting out the
/// crossing triangles, `pairs` (indices in the order to_triangle_mesh writes the faces), with
/// one ring of neighbours at the first step, two at the second and so on, widened so that the
/// cut pinches no vertex (expand_face_selection_for_removal); then the largest piece is kept
/// and the holes are filled as in step 4 (fill_holes), whose time and memory are bounded by
/// the border: CGAL's full search only up to kLargeHole edges, linear work beyond. Stops when
/// nothing crosses, after kRemovalSteps rings, or before a cut that would take the whole
/// mesh. A cut whose holes cannot be filled into a closed 2-manifold surface is not kept (the
/// next step tries one ring wider). Counts the cuts kept in `r` (removal_steps,
/// cut_triangles, cut_holes_filled). With `bisect`, the first cut's region is bisected first
/// (bisect_long_edges, to rung_length), so that on long, thin triangles a ring is not a whole
/// band of the mesh; where that split anything, at most kBisectedSteps steps are made.
///
/// Our own rather than CGAL's experimental remove_self_intersections, which bounds neither
/// time nor memory: it smooths each region for 100 rounds, projecting every vertex onto the
/// region's input in each, after growing the region to the bounding box of its crossings (on
/// a dome folded through its first band, tens of thousands of vertices: 20 s in release,
/// minutes under ASan); and it fills what it cuts with CGAL's full hole search, whose memory
/// grows with the square of the border. On the cow it also cut the tail off, where this keeps it.
Removal cut_out_crossings(Mesh& mesh, std::vector<std::array<std::size_t, 2>> pairs, RepairReport& r, bool bisect)
{
    Removal out;
    bool unfillable = false; // the last cut tried could not be filled into a 2-manifold surface
    unsigned steps = kRemovalSteps;
    for (unsigned rings = 1; rings <= steps && !pairs.empty(); ++rings) {
        mesh.collect_garbage(); // face i is triangle i of to_triangle_mesh
        Mesh::Property_map<Mesh::Face_index, bool> cut;
        std::vector<Mesh::Face_index> seeds, grown;
        // The crossing faces of `pairs` and `rings` rings round them.
        auto select = [&] {
            cut = mesh.add_property_map<Mesh::Face_index, bool>("f:lobe_cut", false).first;
            seeds = select_faces(mesh, pairs, cut);
            grown = seeds;
            CGAL::expand_face_selection(seeds, mesh, rings, cut, std::back_inserter(grown));
        };
        select();
        if (bisect && rings == 1) {
            r.bisected_edges = bisect_long_edges(mesh, cut, rung_length(mesh, seeds), split_budget(mesh));
            if (r.bisected_edges > 0) {
                // The region is cut finer: what crosses, and the ring round it, again.
                out.bisected = true;
                steps = kBisectedSteps;
                mesh.remove_property_map(cut);
                auto found = crossing_pairs(to_triangle_mesh(mesh));
                if (!found) break; // cannot happen (splits keep a 2-manifold surface as it was): stop as if out of steps
                pairs = std::move(*found);
                if (pairs.empty()) break;
                select();
            }
        }
        CGAL::expand_face_selection_for_removal(grown, mesh, cut);
        std::size_t n = 0;
        for (auto f : mesh.faces()) n += cut[f] ? 1 : 0;
        if (n >= mesh.number_of_faces()) {
            mesh.remove_property_map(cut);
            out.stop = Removal::Stop::WholeMesh;
            break;
        }
        Mesh next = without_faces(mesh, cut);
        mesh.remove_property_map(cut);
        // The fills' own notes are left out: the removal's note says it filled the gaps.
        RepairReport trial = r, fills;
        std::optional<std::vector<std::array<std::size_t, 2>>> found;
        try {
            keep_largest_component(next, trial);
            fill_holes(next, fills, &found);
            // Nothing when the filled surface is not 2-manifold: a patch can add an edge the
            // surface already has, where two of a hole's border vertices are also joined
            // outside it (found by the hole_fill fuzz target: one edge of three triangles).
            if (!found) found = crossing_pairs(to_triangle_mesh(next));
        } catch (const InvalidInput&) {
        }
        unfillable = !found;
        if (unfillable) continue; // not kept: the next step cuts one ring wider
        r = std::move(trial);
        ++r.removal_steps;
        r.cut_triangles += n;
        r.cut_holes_filled += fills.holes_filled;
        mesh = std::move(next);
        pairs = std::move(*found);
    }
    out.left = pairs.size();
    if (out.left > 0 && out.stop == Removal::Stop::Clean)
        out.stop = unfillable ? Removal::Stop::Unfillable : Removal::Stop::Steps;
    return out;
}

} // namespace

void check_encloses_volume(const TriangleMesh& mesh, const MeshQuality& q, const std::string& what)
{
    // A flat or single-sheet input (one triangle, a plane) gets its one boundary capped by a
    // copy of itself, and the self-intersection removal can leave a sliver: closed and
    // manifold, but with nothing inside (a signed volume of ±1e-20 passes "> 0" by rounding).
    // A lobe holds at least a millionth of its bounding cube.
    glm::dvec3 lo, hi;
    bounding_box(mesh, lo, hi);
    const double extent = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
    const double least = 1e-6 * extent * extent * extent;
    if (q.closed && q.manifold && !(std::abs(q.signed_volume_m3) > least))
        throw InvalidInput(what + " encloses no volume (the mesh is flat, a single open sheet or a sliver), so it "
                                  "cannot become a closed lobe");
    if (!q.closed || !q.manifold || !(q.signed_volume_m3 > least))
        throw InvalidInput(what + " is not " +
                           (!q.closed ? "closed (" + std::to_string(q.boundary_edges) + " boundary edges)"
                            : !q.manifold ? "2-manifold (" + std::to_string(q.non_manifold_edges) + " non-manifold edges, " +
                                                std::to_string(q.non_manifold_vertices) + " non-manifold vertices, " +
                                                std::to_string(q.inconsistent_edges) + " inconsistently oriented edges)"
                                          : std::string("oriented outward (its signed volume is negative)")));
}

TriangleMesh repair_mesh(const TriangleMesh& in, RepairReport* report)
{
    RepairReport r;
    r.input_vertices = in.positions.size();
    r.input_triangles = in.triangles.size();
    std::vector<Point> points;
    std::vector<Polygon> polygons;
    to_soup(in, "repair_mesh", points, polygons);

    // 1. Soup clean-up: repeated vertices in a triangle, duplicate triangles, duplicate and
    //    unused points.
    PMP::repair_polygon_soup(points, polygons);
    r.merged_vertices = in.positions.size() - points.size();
    r.removed_triangles = in.triangles.size() - polygons.size();
    if (polygons.empty()) throw InvalidInput("repair_mesh: no valid triangle left after removing degenerate ones");
    {
        // Triangles whose corners are collinear pass the clean-up but bound nothing, and hole
        // filling would then report an open hole: say what is wrong instead.
        double lo[3] = {points[0].x(), points[0].y(), points[0].z()}, hi[3] = {lo[0], lo[1], lo[2]};
        for (const Point& p : points)
            for (int k = 0; k < 3; ++k) {
                lo[k] = std::min(lo[k], p[k]);
                hi[k] = std::max(hi[k], p[k]);
            }
        const double extent = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
        double area = 0.0;
        for (const Polygon& t : polygons)
            for (std::size_t k = 2; k < t.size(); ++k) // a fan, should the clean-up leave a polygon
                area += std::sqrt(CGAL::to_double(CGAL::squared_area(points[t[0]], points[t[k - 1]], points[t[k]])));
        if (!(area > 1e-12 * extent * extent))
            throw InvalidInput("repair_mesh: the mesh has no area (the corners of every triangle are collinear)");
    }
    if (r.merged_vertices) r.notes.push_back("merged or dropped " + std::to_string(r.merged_vertices) + " duplicate or unused vertices");
    if (r.removed_triangles) r.notes.push_back("removed " + std::to_string(r.removed_triangles) + " degenerate or duplicate triangles");

    // 2. Consistent orientation; non-manifold vertices and edges are split here.
    const std::size_t before_orient = points.size();
    PMP::orient_polygon_soup(points, polygons);
    r.split_non_manifold_vertices = points.size() - before_orient;
    Mesh mesh;
    PMP::polygon_soup_to_polygon_mesh(points, polygons, mesh);
    r.split_non_manifold_vertices += PMP::duplicate_non_manifold_vertices(mesh);
    if (r.split_non_manifold_vertices)
        r.notes.push_back("split non-manifold vertices (" + std::to_string(r.split_non_manifold_vertices) + " copies made)");

    // 3. One component, 4. no holes.
    keep_largest_component(mesh, r);
    std::optional<std::vector<std::array<std::size_t, 2>>> known_pairs;
    fill_holes(mesh, r, &known_pairs);

    // Copies of split vertices would make the surface touch itself at a point.
    if (separate_coincident_vertices(mesh) > 0) known_pairs.reset();

    // 5. Self-intersections (the cow's tail runs into its body, or a hole's patch over a
    //    steep zig-zag border crosses the surface): cut_out_crossings cuts out the faces
    //    involved with a growing ring round them and fills the gaps as in step 4; it may also
    //    cut through a handle, which a lobe (an envelope of foliage) does not mind.
    std::string removal_note;
    {
        const auto pairs = known_pairs ? std::move(*known_pairs) : self_intersecting_pairs(to_triangle_mesh(mesh));
        if (!pairs.empty()) {
            r.crossing_pairs = pairs.size();
            // The first cut's region is bisected where its triangles are long and thin. Then
            // the cuts of whole triangles are made too, from the mesh as it was, and the result
            // with fewer crossings left is kept, of two equally clean ones the larger: on
            // hole_fill's domes folded through themselves thousands of times the bisected
            // cuts sometimes clear less, or keep less of the dome.
            Mesh whole = mesh;
            RepairReport whole_report = r;
            Removal removal = cut_out_crossings(mesh, pairs, r, true);
            if (removal.bisected) {
                const Removal other = cut_out_crossings(whole, pairs, whole_report, false);
                if (other.left < removal.left ||
                    (other.left == removal.left && std::abs(enclosed_volume(whole)) > std::abs(enclosed_volume(mesh)))) {
                    removal = other;
                    mesh = std::move(whole);
                    r = std::move(whole_report);
                }
            }
            r.crossing_pairs_left = removal.left;
            r.self_intersections_left = removal.left > 0;
            const std::string cuts =
                std::to_string(r.cut_triangles) + " triangles round them in " + std::to_string(r.removal_steps) +
                (r.removal_steps == 1 ? " step" : " steps") +
                (r.bisected_edges ? " after splitting " + std::to_string(r.bisected_edges) + " long edges there in two" : "");
            using Stop = Removal::Stop;
            std::string note;
            if (removal.left == 0) {
                note = "removed self-intersections (" + std::to_string(pairs.size()) + " crossing pairs; cut out " + cuts +
                       " and filled the " +
                       (r.cut_holes_filled == 1 ? std::string("hole") : std::to_string(r.cut_holes_filled) + " holes") +
                       " left)";
            } else {
                note = "some self-intersections could not be removed (" + std::to_string(pairs.size()) + " crossing pairs";
                if (r.removal_steps > 0)
                    note += ", " + std::to_string(removal.left) + " left after cutting out " + cuts;
                note += removal.stop == Stop::WholeMesh    ? ": cutting them out would take the whole mesh)"
                        : removal.stop == Stop::Unfillable ? ": a cut left a hole that could not be filled)"
                                                           : ")";
            }
            r.notes.push_back(note);
            removal_note = note;
        }
    }

    // 6. Outward orientation.
    if (!PMP::is_outward_oriented(mesh)) {
        PMP::reverse_face_orientations(mesh);
        r.reoriented = true;
        r.notes.push_back("flipped all faces to point outward");
    }

    TriangleMesh out = to_triangle_mesh(mesh);
    const MeshQuality q = measure_quality(out);
    try {
        check_encloses_volume(out, q, "repair_mesh: the result");
    } catch (const InvalidInput& e) {
        if (!r.self_intersections_left) throw;
        // A surface that still passes through itself has no consistent inside: say why.
        throw InvalidInput(std::string(e.what()) + "; " + removal_note);
    }
    r.output_vertices = out.positions.size();
    r.output_triangles = out.triangles.size();
    if (report) *report = std::move(r);
    return out;
}

} // namespace lobe
