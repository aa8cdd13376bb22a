// Step 4 of repair_mesh (repair.h): every hole filled with a refined, faired patch, the patch
// found as CGAL's triangulate_hole finds it but independently of what ran before in the
// process (search_hole_patch), large holes in their plane or by a fan. CGAL's Polygon Mesh
// Processing on a Surface_mesh. See docs/lobes-from-models.md.
#include "meshing/repair_cgal.h"

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <iterator>
#include <map>
#include <string>
#include <utility>
#include <vector>

LOBE_CGAL_HEADERS_BEGIN
#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Delaunay_mesh_face_base_2.h>
#include <CGAL/Delaunay_mesh_vertex_base_2.h>
#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Polygon_2_algorithms.h>
#include <CGAL/Projection_traits_3.h>
#include <CGAL/boost/graph/Euler_operations.h>
#include <CGAL/Polygon_mesh_processing/border.h>
#include <CGAL/Polygon_mesh_processing/compute_normal.h>
#include <CGAL/Polygon_mesh_processing/fair.h>
#include <CGAL/Polygon_mesh_processing/refine.h>
#include <CGAL/Polygon_mesh_processing/triangulate_hole.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>
LOBE_CGAL_HEADERS_END

#include "core/errors.h"

namespace lobe::repair_detail {

namespace {

using namespace cgal; // Kernel, Point, Mesh, PMP
using VertexIndex = Mesh::Vertex_index;

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

/// A hole's border as the patch search reads it.
struct HoleBorder {
    std::vector<Mesh::Halfedge_index> edges; ///< its halfedges, from the first on
    std::vector<Point> P;                    ///< P[k]: the target of edges[k]
    std::vector<Point> Q;                    ///< Q[k]: the corner opposite the next border edge in the face beyond it
    std::map<VertexIndex, int> id;           ///< border vertex → k
};

/// Reads the border of the hole whose border halfedge is `h`; false where the border meets
/// itself at a vertex.
bool read_border(const Mesh& mesh, Mesh::Halfedge_index h, HoleBorder& border)
{
    for (Mesh::Halfedge_index k : CGAL::halfedges_around_face(h, mesh)) {
        if (!border.id.emplace(mesh.target(k), static_cast<int>(border.P.size())).second) return false;
        border.edges.push_back(k);
        border.P.push_back(mesh.point(mesh.target(k)));
        border.Q.push_back(mesh.point(mesh.target(mesh.next(mesh.opposite(mesh.next(k))))));
    }
    return true;
}

/// Where the search keeps the sub-polygon i, i+1, …, j of an n-corner border.
std::size_t table_index(int n, int a, int b)
{
    return static_cast<std::size_t>(a) * static_cast<std::size_t>(n) + static_cast<std::size_t>(b);
}

/// Edges the surface already has between border vertices that are not border neighbours, as
/// pairs of border indices (i < j), sorted.
std::vector<std::pair<int, int>> existing_chords(const Mesh& mesh, const HoleBorder& border)
{
    const int n = static_cast<int>(border.P.size());
    const std::map<VertexIndex, int>& id = border.id;
    std::vector<std::pair<int, int>> existing;
    for (const auto& [v, i] : id)
        for (Mesh::Halfedge_index k : CGAL::halfedges_around_target(v, mesh)) {
            const auto other = id.find(mesh.source(k));
            if (other == id.end()) continue;
            const int j = other->second;
            if (j != (i + n - 1) % n && j != (i + 1) % n && i < j) existing.emplace_back(i, j);
        }
    std::sort(existing.begin(), existing.end());
    return existing;
}

/// The candidate triangles of the patch search: for each edge (i, j) of border indices, the
/// third corners of the triangles on it. The faces of the border points' 3D Delaunay
/// triangulation; where that lacks a border edge, every triangle on that edge and the two
/// others such a triangle needs, as in CGAL.
class PatchCandidates {
public:
    using Entry = std::pair<std::int64_t, int>; ///< (key(i, j), k)

    explicit PatchCandidates(int n) : n_(n) {}
    /// False (no candidates) where the border points span no plane.
    bool find(const std::vector<Point>& P);
    /// The entries of the edge (a, b), in increasing order of the third corner.
    std::pair<std::vector<Entry>::const_iterator, std::vector<Entry>::const_iterator> thirds_of(int a, int b) const
    {
        return std::equal_range(thirds_.begin(), thirds_.end(), std::make_pair(key(a, b), 0), by_edge);
    }

private:
    std::int64_t key(int a, int b) const { return static_cast<std::int64_t>(std::min(a, b)) * n_ + std::max(a, b); }
    static bool by_edge(const Entry& x, const Entry& y) { return x.first < y.first; }

    int n_;
    std::vector<Entry> thirds_; ///< sorted
};

bool PatchCandidates::find(const std::vector<Point>& P)
{
    const int n = n_;
    // The Delaunay faces, as the third corners of each edge (i < j), in increasing order.
    using Vb = CGAL::Triangulation_vertex_base_with_info_3<int, Kernel>;
    using Tds = CGAL::Triangulation_data_structure_3<Vb, CGAL::Delaunay_triangulation_cell_base_3<Kernel>>;
    using Delaunay = CGAL::Delaunay_triangulation_3<Kernel, Tds>;
    std::vector<std::pair<Point, int>> points;
    for (int i = 0; i < n; ++i) points.emplace_back(P[static_cast<std::size_t>(i)], i);
    Delaunay dt(points.begin(), points.end());
    if (dt.dimension() < 2) return false;
    for (auto f = dt.finite_facets_begin(); f != dt.finite_facets_end(); ++f) {
        std::array<int, 3> c{};
        int m = 0;
        for (int k = 0; k < 4; ++k)
            if (k != f->second) c[static_cast<std::size_t>(m++)] = f->first->vertex(k)->info();
        thirds_.emplace_back(key(c[0], c[1]), c[2]);
        thirds_.emplace_back(key(c[0], c[2]), c[1]);
        thirds_.emplace_back(key(c[1], c[2]), c[0]);
    }
    std::sort(thirds_.begin(), thirds_.end());
    std::vector<std::pair<int, int>> missing;
    for (int i = 0; i < n; ++i)
        if (!std::binary_search(thirds_.begin(), thirds_.end(), std::make_pair(key(i, (i + 1) % n), 0), by_edge))
            missing.emplace_back(i, (i + 1) % n);
    for (const auto& [a, b] : missing)
        for (int k = 0; k < n; ++k) {
            if (k == a || k == b) continue;
            thirds_.emplace_back(key(a, b), k);
            thirds_.emplace_back(key(k, a), b);
            thirds_.emplace_back(key(k, b), a);
        }
    if (!missing.empty()) {
        std::sort(thirds_.begin(), thirds_.end());
        thirds_.erase(std::unique(thirds_.begin(), thirds_.end()), thirds_.end());
    }
    return true;
}

/// The best patch of the border (the search's dynamic programming over sub-polygons): at
/// table_index(n, i, j), the third corner of the triangle on the edge j → i in the best patch
/// of the polygon i, i+1, …, j; -1 where there is none.
std::vector<int> best_patch(const HoleBorder& border, const PatchCandidates& candidates,
                            const std::vector<std::pair<int, int>>& existing)
{
    const std::vector<Point>& P = border.P;
    const std::vector<Point>& Q = border.Q;
    const int n = static_cast<int>(P.size());
    auto has_edge = [&](int a, int b) { return std::binary_search(existing.begin(), existing.end(), std::make_pair(a, b)); };

    // W(i, j): the best patch of the polygon i, i+1, …, j (i < j) closed by the edge j → i, as
    // (largest angle, area); NOT_VALID (-1, -1) where none; lambda: its triangle's third corner.
    using Weight = std::pair<double, double>;
    const Weight not_valid(-1.0, -1.0);
    const std::size_t nn = static_cast<std::size_t>(n) * static_cast<std::size_t>(n);
    std::vector<Weight> W(nn, Weight(0.0, 0.0));
    std::vector<int> lambda(nn, -1);
    std::vector<char> done(nn, 0);
    auto at = [n](int a, int b) { return table_index(n, a, b); };
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
        const auto [lo, hi] = candidates.thirds_of(i, j);
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
    return lambda;
}

/// Adds the patch `lambda` (best_patch) of the hole whose border halfedges are `edges`: the
/// faces made as CGAL's tracer makes them.
std::vector<Mesh::Face_index> add_patch_faces(Mesh& mesh, const std::vector<Mesh::Halfedge_index>& edges,
                                              const std::vector<int>& lambda)
{
    const int n = static_cast<int>(edges.size());
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
            const int m = lambda[table_index(n, fr.i, fr.k)];
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
    HoleBorder border;
    if (!read_border(mesh, h, border)) return {};
    const int n = static_cast<int>(border.P.size());
    cubic_may_help = true;
    if (n < 3) return {};
    const std::vector<std::pair<int, int>> existing = existing_chords(mesh, border);
    PatchCandidates candidates(n);
    if (!candidates.find(border.P)) return {};
    const std::vector<int> lambda = best_patch(border, candidates, existing);
    if (lambda[table_index(n, 0, n - 1)] == -1) return {};
    return add_patch_faces(mesh, border.edges, lambda);
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

} // namespace

void fill_holes(Mesh& mesh, RepairReport& r, std::optional<std::vector<std::array<std::size_t, 2>>>* pairs)
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

} // namespace lobe::repair_detail
