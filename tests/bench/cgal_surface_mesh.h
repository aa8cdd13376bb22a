#pragma once
// TriangleMesh ⇄ CGAL::Surface_mesh for the benchmarks that time plain CGAL calls beside ours.
#include <array>
#include <vector>

#include "meshing/cgal_prelude.h"
LOBE_CGAL_HEADERS_BEGIN
#include <CGAL/Surface_mesh.h>
LOBE_CGAL_HEADERS_END

#include "core/mesh.h"

namespace lobe::bench {

inline cgal::Mesh to_surface_mesh(const TriangleMesh& m)
{
    cgal::Mesh sm;
    std::vector<cgal::Mesh::Vertex_index> v;
    for (const auto& p : m.positions) v.push_back(sm.add_vertex(cgal::Point(p.x, p.y, p.z)));
    for (const auto& t : m.triangles)
        sm.add_face(v[static_cast<std::size_t>(t[0])], v[static_cast<std::size_t>(t[1])], v[static_cast<std::size_t>(t[2])]);
    return sm;
}

inline TriangleMesh from_surface_mesh(cgal::Mesh& sm)
{
    sm.collect_garbage();
    TriangleMesh m;
    for (auto v : sm.vertices()) {
        const auto& p = sm.point(v);
        m.positions.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()));
    }
    for (auto f : sm.faces()) {
        std::array<int, 3> t{};
        int k = 0;
        for (auto v : CGAL::vertices_around_face(sm.halfedge(f), sm))
            if (k < 3) t[static_cast<std::size_t>(k++)] = static_cast<int>(v.idx());
        m.triangles.push_back(t);
    }
    return m;
}


} // namespace lobe::bench
