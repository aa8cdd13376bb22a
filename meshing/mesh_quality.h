#pragma once
/// \file mesh_quality.h
/// Measures of a triangle mesh's shape quality and validity (CGAL-free): angles, edge
/// lengths, closedness, manifoldness, orientation, and the distance from one mesh to
/// another. Used by tests, benchmarks and the model import report.

#include <cstddef>

#include <glm/vec3.hpp>

#include "core/mesh.h"

namespace lobe {

/// Shape and validity figures of a triangle mesh. Angles in degrees, lengths in metres.
struct MeshQuality {
    std::size_t vertices = 0;
    std::size_t triangles = 0;
    double min_angle_deg = 0;          ///< smallest triangle angle
    double max_angle_deg = 0;          ///< largest triangle angle
    double share_all_angles_ge_30 = 0; ///< fraction (0–1) of triangles whose three angles are ≥ 30°
    std::size_t count_angle_lt_15 = 0; ///< triangles with an angle < 15°
    double edge_min_m = 0;
    double edge_max_m = 0;
    double edge_mean_m = 0;
    double edge_stddev_m = 0;
    std::size_t boundary_edges = 0;     ///< edges with one incident triangle
    std::size_t non_manifold_edges = 0; ///< edges with more than two incident triangles
    std::size_t non_manifold_vertices = 0; ///< vertices whose triangles form more than one fan
    std::size_t inconsistent_edges = 0; ///< interior edges whose two triangles run it the same way
    std::size_t components = 0;         ///< connected components (by shared vertices)
    double signed_volume_m3 = 0;        ///< divergence-theorem volume; > 0 for outward normals
    bool closed = false;                ///< no boundary edge
    bool manifold = false;              ///< every edge has ≤ 2 triangles, every vertex one fan, consistent orientation
    bool outward = false;               ///< closed, and signed volume > 0
};

/// Measures `mesh`. Triangles with an index out of range are a precondition failure.
/// \throw InvalidInput when an index is out of range or the mesh has no triangle.
MeshQuality measure_quality(const TriangleMesh& mesh);

/// Axis-aligned bounding box of the positions.
/// \pre at least one position.
void bounding_box(const TriangleMesh& mesh, glm::dvec3& lo, glm::dvec3& hi);

/// One-sided Hausdorff distance: the largest distance from a vertex of `from` to the surface
/// (triangles) of `to`, found exactly with a uniform grid over `to`'s triangles.
/// \throw InvalidInput when `to` has no triangle or an index out of range.
double max_vertex_distance(const TriangleMesh& from, const TriangleMesh& to);

} // namespace lobe
