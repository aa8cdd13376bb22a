// Mesh repair with CGAL's Polygon Mesh Processing: the steps of repair_mesh (repair.h) but the
// hole filling (hole_filling_cgal.cpp) and the search for self-intersections
// (self_intersections_cgal.cpp), each a translation unit of its own. Works on CGAL::Surface_mesh
// rather than OpenMesh: the soup-to-mesh functions, hole filling and component removal need no
// per-element status bookkeeping there, and nothing outside these files sees the type.
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
#include <utility>
#include <vector>

#include "meshing/cgal_prelude.h"
LOBE_CGAL_HEADERS_BEGIN
#include <CGAL/boost/graph/Euler_operations.h>
#include <CGAL/boost/graph/selection.h>
#include <CGAL/Polygon_mesh_processing/connected_components.h>
#include <CGAL/Polygon_mesh_processing/manifoldness.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/repair_polygon_soup.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/bounding_box.h>
LOBE_CGAL_HEADERS_END

#include "core/errors.h"
#include "meshing/mesh_quality.h"
#include "meshing/repair_cgal.h"

namespace lobe {

namespace {

using namespace cgal; // Kernel, Point, Mesh, PMP
using VertexIndex = Mesh::Vertex_index;
using Polygon = cgal::Polygon;
using repair_detail::crossing_pairs;
using repair_detail::fill_holes;
using repair_detail::to_triangle_mesh;

} // namespace

TriangleMesh repair_detail::to_triangle_mesh(Mesh& mesh)
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

std::optional<std::vector<std::array<std::size_t, 2>>> repair_detail::crossing_pairs(const TriangleMesh& tm)
{
    try {
        return self_intersecting_pairs(tm);
    } catch (const InvalidInput&) {
        return std::nullopt;
    }
}

namespace {

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

/// \throw InvalidInput when no triangle of the soup has area.
void check_has_area(const std::vector<Point>& points, const std::vector<Polygon>& polygons)
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

/// Step 5 of repair_mesh: cut_out_crossings where `known_pairs` (the crossing pairs, when
/// found on the way) or a search finds crossings, the bisected cuts against the cuts of whole
/// triangles. Counts what it did in `r` and returns the note it added (empty: nothing crossed).
std::string remove_self_intersections(Mesh& mesh, RepairReport& r,
                                      std::optional<std::vector<std::array<std::size_t, 2>>> known_pairs)
{
    const auto pairs = known_pairs ? std::move(*known_pairs) : self_intersecting_pairs(to_triangle_mesh(mesh));
    if (pairs.empty()) return {};
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
    return note;
}

} // namespace

TriangleMesh repair_mesh(const TriangleMesh& in, RepairReport* report)
{
    RepairReport r;
    r.input_vertices = in.positions.size();
    r.input_triangles = in.triangles.size();
    std::vector<Point> points;
    std::vector<Polygon> polygons;
    cgal::to_polygon_soup(in, "repair_mesh", points, polygons);

    // 1. Soup clean-up: repeated vertices in a triangle, duplicate triangles, duplicate and
    //    unused points.
    PMP::repair_polygon_soup(points, polygons);
    r.merged_vertices = in.positions.size() - points.size();
    r.removed_triangles = in.triangles.size() - polygons.size();
    if (polygons.empty()) throw InvalidInput("repair_mesh: no valid triangle left after removing degenerate ones");
    check_has_area(points, polygons);
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
    const std::string removal_note = remove_self_intersections(mesh, r, std::move(known_pairs));

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

// One soup reader for repair and the self-intersection checks (cgal_prelude.h).
void cgal::to_polygon_soup(const TriangleMesh& in, const char* who, std::vector<Point>& points, std::vector<Polygon>& polygons)
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


} // namespace lobe
