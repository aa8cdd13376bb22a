// Isotropic remeshing: CGAL's isotropic_remeshing running directly on an OpenMesh TriMesh
// through CGAL's OpenMesh adapters (DESIGN.md), behind the plain interface of remesh.h.
#include "meshing/remesh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wconversion"
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wsign-conversion"
#pragma GCC diagnostic ignored "-Wunused-parameter"
#pragma GCC diagnostic ignored "-Wpedantic"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#pragma GCC diagnostic ignored "-Wdeprecated-copy"
#pragma GCC diagnostic ignored "-Woverloaded-virtual"
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <CGAL/boost/graph/graph_traits_TriMesh_ArrayKernelT.h>
#include <CGAL/boost/graph/properties_TriMesh_ArrayKernelT.h>
#include <CGAL/Polygon_mesh_processing/remesh.h>
#pragma GCC diagnostic pop

#include <glm/geometric.hpp>

#include "core/errors.h"
#include "meshing/mesh_quality.h"

namespace lobe {

namespace {

namespace PMP = CGAL::Polygon_mesh_processing;

/// Double-precision points: CGAL's adapter converts them to Epick points without loss.
struct OmTraits : public OpenMesh::DefaultTraits {
    typedef OpenMesh::Vec3d Point;
    typedef OpenMesh::Vec3d Normal;
};
using OMesh = OpenMesh::TriMesh_ArrayKernelT<OmTraits>;
using EdgeDescriptor = boost::graph_traits<OMesh>::edge_descriptor;

/// CGAL's edge_is_constrained_map over an OpenMesh edge property. Edges that remeshing
/// creates get OpenMesh's default, false; CGAL marks sub-edges of constrained edges itself.
struct ConstrainedEdgeMap {
    using key_type = EdgeDescriptor;
    using value_type = bool;
    using reference = bool;
    using category = boost::read_write_property_map_tag;

    OMesh* mesh = nullptr;
    OpenMesh::EPropHandleT<bool> prop;

    friend bool get(const ConstrainedEdgeMap& m, const key_type& e)
    {
        return m.mesh->property(m.prop, OMesh::EdgeHandle(static_cast<int>(e.idx())));
    }
    friend void put(const ConstrainedEdgeMap& m, const key_type& e, bool value)
    {
        m.mesh->property(m.prop, OMesh::EdgeHandle(static_cast<int>(e.idx()))) = value;
    }
};

OMesh::Point om_point(const glm::vec3& p) { return OMesh::Point(p.x, p.y, p.z); }

/// Splits edge `e` (from a to b) at the point at fraction t, keeping per-edge "constrained"
/// on the two halves only and per-face "in region" on the faces each old face became.
void split_edge(OMesh& om, OMesh::EdgeHandle e, double t, OpenMesh::EPropHandleT<bool> constrained,
                OpenMesh::FPropHandleT<bool> in_region)
{
    const OMesh::HalfedgeHandle h0 = om.halfedge_handle(e, 0), h1 = om.halfedge_handle(e, 1);
    const OMesh::VertexHandle a = om.from_vertex_handle(h0), b = om.to_vertex_handle(h0);
    const bool was_constrained = om.property(constrained, e);
    // Opposite vertex and region flag of each incident face.
    std::array<OMesh::VertexHandle, 2> opp;
    std::array<bool, 2> flag{false, false};
    const std::array<OMesh::HalfedgeHandle, 2> hs{h0, h1};
    for (int k = 0; k < 2; ++k) {
        const auto ku = static_cast<std::size_t>(k);
        if (om.is_boundary(hs[ku])) continue;
        opp[ku] = om.to_vertex_handle(om.next_halfedge_handle(hs[ku]));
        flag[ku] = om.property(in_region, om.face_handle(hs[ku]));
    }
    const OMesh::Point p = om.point(a) * (1.0 - t) + om.point(b) * t;
    const OMesh::VertexHandle m = om.add_vertex(p);
    om.split(e, m);
    for (OMesh::VertexOHalfedgeIter it = om.voh_iter(m); it.is_valid(); ++it) {
        const OMesh::VertexHandle w = om.to_vertex_handle(*it);
        om.property(constrained, om.edge_handle(*it)) = (w == a || w == b) && was_constrained;
        const OMesh::FaceHandle f = om.face_handle(*it);
        if (!f.is_valid()) continue;
        bool has_opp0 = false;
        for (OMesh::FaceVertexIter fv = om.fv_iter(f); fv.is_valid(); ++fv)
            if (*fv == opp[0]) has_opp0 = true;
        om.property(in_region, f) = has_opp0 ? flag[0] : flag[1];
    }
}

} // namespace

TriangleMesh remesh_isotropic(const TriangleMesh& mesh, const RemeshOptions& options)
{
    const double target = options.target_edge_length_m;
    if (!(target > 0) || !std::isfinite(target))
        throw InvalidInput("remesh_isotropic: target edge length must be a positive number");
    if (options.iterations > 100) throw InvalidInput("remesh_isotropic: more than 100 iterations");
    for (const glm::vec3& p : mesh.positions)
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
            throw InvalidInput("remesh_isotropic: vertex with a non-finite coordinate");
    const MeshQuality q = measure_quality(mesh); // also checks the indices
    if (!q.manifold)
        throw InvalidInput("remesh_isotropic: the mesh is not 2-manifold or not consistently oriented "
                           "(run repair_mesh first)");
    {
        // What the remeshing would make, before it allocates anything (kMaxRemeshTriangles).
        auto area_of = [&](std::size_t f) {
            const auto& t = mesh.triangles[f];
            const glm::dvec3 a(mesh.positions[static_cast<std::size_t>(t[0])]);
            const glm::dvec3 b(mesh.positions[static_cast<std::size_t>(t[1])]);
            const glm::dvec3 c(mesh.positions[static_cast<std::size_t>(t[2])]);
            return 0.5 * glm::length(glm::cross(b - a, c - a));
        };
        double area = 0.0;
        if (options.faces.empty()) {
            for (std::size_t f = 0; f < mesh.triangles.size(); ++f) area += area_of(f);
        } else {
            for (int f : options.faces)
                if (f >= 0 && f < static_cast<int>(mesh.triangles.size())) area += area_of(static_cast<std::size_t>(f));
        }
        const double estimate = area / (std::sqrt(3.0) / 4.0 * target * target);
        if (!(estimate <= static_cast<double>(kMaxRemeshTriangles))) {
            char buf[200];
            std::snprintf(buf, sizeof buf,
                          "remesh_isotropic: %.3g m² at edge length %g m would make about %.3g triangles, more than the "
                          "%zu allowed",
                          area, target, estimate, kMaxRemeshTriangles);
            throw InvalidInput(buf);
        }
    }

    OMesh om;
    om.request_vertex_status();
    om.request_edge_status();
    om.request_halfedge_status();
    om.request_face_status();
    std::vector<OMesh::VertexHandle> vh;
    vh.reserve(mesh.positions.size());
    for (const glm::vec3& p : mesh.positions) vh.push_back(om.add_vertex(om_point(p)));
    for (const auto& t : mesh.triangles) {
        const OMesh::FaceHandle f = om.add_face(vh[static_cast<std::size_t>(t[0])], vh[static_cast<std::size_t>(t[1])],
                                                vh[static_cast<std::size_t>(t[2])]);
        if (!f.is_valid()) throw InvalidInput("remesh_isotropic: a triangle cannot be added (not 2-manifold)");
    }

    OpenMesh::EPropHandleT<bool> constrained;
    OpenMesh::FPropHandleT<bool> in_region;
    om.add_property(constrained);
    om.add_property(in_region);
    for (auto e : om.edges()) om.property(constrained, e) = false;
    const bool whole = options.faces.empty();
    for (auto f : om.faces()) om.property(in_region, f) = whole;
    for (int f : options.faces) {
        if (f < 0 || f >= static_cast<int>(mesh.triangles.size()))
            throw InvalidInput("remesh_isotropic: face index " + std::to_string(f) + " out of range");
        om.property(in_region, OMesh::FaceHandle(f)) = true;
    }
    if (options.protect_feature_edges) {
        for (const auto& fe : mesh.feature_edges) {
            const int n = static_cast<int>(mesh.positions.size());
            if (fe[0] < 0 || fe[0] >= n || fe[1] < 0 || fe[1] >= n)
                throw InvalidInput("remesh_isotropic: feature edge index out of range");
            const OMesh::HalfedgeHandle h =
                om.find_halfedge(vh[static_cast<std::size_t>(fe[0])], vh[static_cast<std::size_t>(fe[1])]);
            if (!h.is_valid()) throw InvalidInput("remesh_isotropic: a feature edge is not an edge of the mesh");
            om.property(constrained, om.edge_handle(h)) = true;
        }
    }

    // protect_constraints(true) needs every constrained edge shorter than 4/3 of the target,
    // or remeshing may not terminate. Constrained here: feature edges, and the borders of the
    // region (and of the mesh), which CGAL always treats as constrained. Halve those longer
    // than 1.25 × target until none is left (each round halves them all, so a 1 km edge
    // needs 15 rounds at 3 cm).
    std::vector<OMesh::EdgeHandle> long_edges;
    for (int round = 0; round < 64; ++round) {
        long_edges.clear();
        for (auto e : om.edges()) {
            const OMesh::HalfedgeHandle h0 = om.halfedge_handle(e, 0), h1 = om.halfedge_handle(e, 1);
            const bool r0 = !om.is_boundary(h0) && om.property(in_region, om.face_handle(h0));
            const bool r1 = !om.is_boundary(h1) && om.property(in_region, om.face_handle(h1));
            const bool fixed = om.property(constrained, e) || (r0 != r1);
            if ((r0 || r1) && fixed && om.calc_edge_length(e) > target * 1.25) long_edges.push_back(e);
        }
        if (long_edges.empty()) break;
        for (OMesh::EdgeHandle e : long_edges) split_edge(om, e, 0.5, constrained, in_region);
    }

    std::vector<OMesh::FaceHandle> region;
    for (auto f : om.faces())
        if (om.property(in_region, f)) region.push_back(f);

    ConstrainedEdgeMap ecm{&om, constrained};
    PMP::isotropic_remeshing(region, target, om,
                             CGAL::parameters::number_of_iterations(options.iterations)
                                 .edge_is_constrained_map(ecm)
                                 .protect_constraints(!(options.relax_feature_edges && whole)));
    om.garbage_collection();

    TriangleMesh out;
    out.positions.reserve(om.n_vertices());
    for (auto v : om.vertices()) {
        const OMesh::Point& p = om.point(v);
        out.positions.emplace_back(static_cast<float>(p[0]), static_cast<float>(p[1]), static_cast<float>(p[2]));
    }
    out.triangles.reserve(om.n_faces());
    for (auto f : om.faces()) {
        std::array<int, 3> t{};
        int k = 0;
        for (OMesh::FaceVertexIter fv = om.fv_iter(f); fv.is_valid() && k < 3; ++fv) t[static_cast<std::size_t>(k++)] = fv->idx();
        out.triangles.push_back(t);
    }
    if (options.protect_feature_edges)
        for (auto e : om.edges())
            if (om.property(constrained, e)) {
                const OMesh::HalfedgeHandle h = om.halfedge_handle(e, 0);
                out.feature_edges.push_back({om.from_vertex_handle(h).idx(), om.to_vertex_handle(h).idx()});
            }
    return out;
}

} // namespace lobe
