#pragma once
// TriangleMesh ⇄ CGAL::Surface_mesh for the benchmarks that time plain CGAL calls beside ours.
#include <array>
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
#include <CGAL/Surface_mesh.h>
#pragma GCC diagnostic pop

#include "core/mesh.h"

namespace lobe::bench {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using SurfaceMesh = CGAL::Surface_mesh<Kernel::Point_3>;

inline SurfaceMesh to_surface_mesh(const TriangleMesh& m)
{
    SurfaceMesh sm;
    std::vector<SurfaceMesh::Vertex_index> v;
    for (const auto& p : m.positions) v.push_back(sm.add_vertex(Kernel::Point_3(p.x, p.y, p.z)));
    for (const auto& t : m.triangles)
        sm.add_face(v[static_cast<std::size_t>(t[0])], v[static_cast<std::size_t>(t[1])], v[static_cast<std::size_t>(t[2])]);
    return sm;
}

inline TriangleMesh from_surface_mesh(SurfaceMesh& sm)
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
