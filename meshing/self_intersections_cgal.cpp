// Self-intersection tests (CGAL Polygon Mesh Processing on a Surface_mesh), in a translation
// unit of their own: self_intersections.h is heavy to compile.
#include "meshing/repair.h"

#include <array>
#include <iterator>
#include <utility>
#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include "meshing/cgal_prelude.h"
LOBE_CGAL_HEADERS_BEGIN
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>
LOBE_CGAL_HEADERS_END

#include "core/errors.h"

namespace lobe {

namespace {

using namespace cgal; // Kernel, Point, Mesh, PMP

/// `in` as a Surface_mesh. \throw InvalidInput when it is not a 2-manifold mesh.
Mesh to_surface_mesh(const TriangleMesh& in, const char* who)
{
    std::vector<Point> points;
    std::vector<Polygon> polygons;
    to_polygon_soup(in, who, points, polygons);
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

} // namespace lobe
