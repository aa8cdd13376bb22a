// Self-intersection test and removal (CGAL Polygon Mesh Processing on a Surface_mesh), in a
// translation unit of their own: repair_self_intersections.h alone takes about as long to
// compile as the rest of the repair code.
#include "meshing/repair.h"

#include <array>
#include <iterator>
#include <utility>
#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wconversion"
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wsign-conversion"
#pragma GCC diagnostic ignored "-Wunused-parameter"
#pragma GCC diagnostic ignored "-Wpedantic"
#ifndef __clang__ // GCC only: Clang has no such warning and would warn about the pragma
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/repair_self_intersections.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>
#pragma GCC diagnostic pop

#include "core/errors.h"

namespace lobe {

namespace {

namespace PMP = CGAL::Polygon_mesh_processing;
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Mesh = CGAL::Surface_mesh<Point>;

/// `in` as a Surface_mesh. \throw InvalidInput when it is not a 2-manifold mesh.
Mesh to_surface_mesh(const TriangleMesh& in, const char* who)
{
    std::vector<Point> points;
    std::vector<std::vector<std::size_t>> polygons;
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
    if (!PMP::is_polygon_soup_a_polygon_mesh(polygons))
        throw InvalidInput(std::string(who) + ": the mesh is not 2-manifold");
    Mesh mesh;
    PMP::polygon_soup_to_polygon_mesh(points, polygons, mesh);
    return mesh;
}

} // namespace

bool self_intersects(const TriangleMesh& in)
{
    return PMP::does_self_intersect(to_surface_mesh(in, "self_intersects"));
}

std::vector<std::array<std::size_t, 2>> self_intersecting_pairs(const TriangleMesh& in)
{
    const Mesh sm = to_surface_mesh(in, "self_intersecting_pairs");
    std::vector<std::pair<Mesh::Face_index, Mesh::Face_index>> pairs;
    PMP::self_intersections(faces(sm), sm, std::back_inserter(pairs));
    // A mesh built from a soup numbers its faces as the soup's triangles.
    std::vector<std::array<std::size_t, 2>> out;
    out.reserve(pairs.size());
    for (const auto& [f, g] : pairs) out.push_back({static_cast<std::size_t>(f.idx()), static_cast<std::size_t>(g.idx())});
    return out;
}

bool remove_self_intersections(TriangleMesh& mesh)
{
    Mesh sm = to_surface_mesh(mesh, "remove_self_intersections");
    // With preserve_genus(true) CGAL left 19 intersecting pairs on the cow; a lobe (an
    // envelope of foliage) does not mind a cut handle.
    // Four steps, not CGAL's default seven: each step widens the region smoothed round what is
    // left, and on a 1,900-vertex dome whose shifted base runs through its first band (found by
    // the hole_fill fuzz target) one component's smoothing in a later step ran for minutes
    // (3.5 min in all, against 1 s with four steps and some crossings left). The cow is clean
    // after three, and the four reference models repair to the same bytes as with seven.
    // This narrows what can take long; it bounds nothing (docs/lobes-from-models.md, Limits).
    PMP::experimental::remove_self_intersections(faces(sm), sm,
                                                 CGAL::parameters::preserve_genus(false).number_of_iterations(4));
    const bool clean = !PMP::does_self_intersect(sm);
    sm.collect_garbage();
    TriangleMesh out;
    out.positions.reserve(sm.number_of_vertices());
    for (auto v : sm.vertices()) {
        const Point& p = sm.point(v);
        out.positions.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()));
    }
    for (auto f : sm.faces()) {
        std::array<int, 3> t{};
        int k = 0;
        for (auto v : CGAL::vertices_around_face(sm.halfedge(f), sm))
            if (k < 3) t[static_cast<std::size_t>(k++)] = static_cast<int>(v.idx());
        out.triangles.push_back(t);
    }
    mesh = std::move(out);
    return clean;
}

} // namespace lobe
