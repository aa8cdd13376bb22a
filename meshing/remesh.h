#pragma once
/// \file remesh.h
/// Isotropic remeshing of lobe surfaces to the attractor spacing, with the stroke edges as
/// constraints (the attractors of growth are the lobe's vertices). CGAL works behind
/// this plain interface (remesh_cgal.cpp). See docs/lobes-from-models.md.

#include <optional>
#include <vector>

#include <glm/vec3.hpp>

#include "core/mesh.h"
#include "core/settings.h"

namespace lobe {

/// Remeshing options.
struct RemeshOptions {
    /// Target edge length: the attractor spacing, one absolute length for every lobe
    /// (settings.lobes.edge_length_m, whose default this is).
    double target_edge_length_m = LobeSettings{}.edge_length_m;
    /// Rounds of split / collapse / flip / tangential relaxation / projection
    /// (settings.lobes.remesh_iterations, whose default this is).
    unsigned iterations = static_cast<unsigned>(LobeSettings{}.remesh_iterations);
    /// Keep TriangleMesh::feature_edges: they are first split to at most the target length
    /// (so CGAL's protect_constraints precondition, < 4/3 target, holds), then neither split,
    /// collapsed, flipped nor moved. Otherwise they are ignored (and dropped in the output).
    bool protect_feature_edges = true;
    /// With protect_feature_edges: let remeshing also split and collapse feature edges along
    /// their polyline (CGAL's protect_constraints(false)), so short pieces merge into
    /// target-length edges and densely sampled strokes do not force slivers, and let their
    /// vertices slide along it (CGAL's relax_constraints, each vertex put back onto the input
    /// polyline after every round), so triangles along strokes get their shape too. Feature
    /// edges are never flipped, and their vertices end on the input polylines. Whole-mesh
    /// remeshing only (`faces` empty).
    bool relax_feature_edges = false;
    /// With protect_feature_edges and feature edges that stay (relax_feature_edges off): run
    /// the rounds as relax_feature_edges does, CGAL's split, collapse and flip one round at a
    /// time, then our tangential relaxation and a projection onto the input by walking it,
    /// then the small-angle repairs; instead of CGAL's relaxation (its vertex normals) and
    /// projection (an AABB tree built on every call; what they cost: docs/lobes.md,
    /// "Measured"). Whole-mesh remeshing only (`faces` empty).
    bool own_rounds = false;
    /// Triangle indices to remesh (incremental remeshing of a changed region); empty: all.
    /// The region's border edges are constrained too (split first when longer than the
    /// target), so every vertex outside the region keeps its position.
    std::vector<int> faces;
    /// A stroke lobe's centre (the input is star-shaped around it: every triangle covers its
    /// own piece of the sphere of directions and faces away from it). Then free vertices go,
    /// instead of to the nearest point of the input, to the point on the ray from the centre
    /// through them whose distance from the centre is interpolated linearly across the
    /// input triangle the ray passes through. The lobe keeps its curvature between the
    /// input's vertices (a sphere stays a sphere) where the nearest point lies on a flat
    /// facet. Only the own rounds (own_rounds, relax_feature_edges) use it.
    std::optional<glm::dvec3> radial_centre;
};

/// Most triangles a remeshing may make, estimated before it starts from the area it remeshes
/// and the target edge length (an equilateral triangle of that edge covers √3/4 · L²). A
/// larger surface or a finer spacing is refused, so no input can make remeshing run out of
/// memory (docs/limits.md). 3 cm spacing reaches it at about 1,500 m², 5 mm at about 43 m².
inline constexpr std::size_t kMaxRemeshTriangles = 4000000;

/// The area remesh_isotropic remeshes (every triangle, or those of `faces` in range), m², and
/// the triangles it would make of it at `target` (each about √3/4 · target²).
double remesh_area(const TriangleMesh& mesh, const std::vector<int>& faces = {});
double remesh_triangle_estimate(double area, double target);

/// Remeshes `mesh` towards edges of options.target_edge_length_m with
/// CGAL::Polygon_mesh_processing::isotropic_remeshing on an OpenMesh TriMesh, projecting
/// onto the input surface. The output's feature_edges are the constrained edges after
/// splitting. Vertex indices change; positions of vertices outside options.faces do not.
/// \pre mesh is 2-manifold (closed or with boundary), indices in range; target > 0.
/// \throw InvalidInput when the precondition does not hold, or the estimate exceeds
/// kMaxRemeshTriangles (one-line message).
TriangleMesh remesh_isotropic(const TriangleMesh& mesh, const RemeshOptions& options = {});

} // namespace lobe
