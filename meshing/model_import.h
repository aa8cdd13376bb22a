#pragma once
/// \file model_import.h
/// Lobes from external meshes (the paper grows trees in the Stanford bunny, a cow and
/// Nefertiti, Fig. 14): read, repair, scale into a box, remesh to the attractor spacing.
/// See docs/lobes-from-models.md.

#include <cstddef>
#include <string>

#include "core/mesh.h"
#include "meshing/repair.h"
#include "meshing/remesh.h"

namespace lobe {

/// Uniformly scales and moves `mesh` so that its bounding box's largest side is `size_m`,
/// centred on the origin in x and z, its lowest point at y = 0.
/// \throw InvalidInput when the mesh has no vertex, a non-finite coordinate, or zero extent.
TriangleMesh normalize_to_box(const TriangleMesh& mesh, double size_m = 1.5);

/// Vertex clustering (Rossignac and Borrel 1993): the vertices that triangles use are
/// grouped by the cube of a grid of side `cell` (from the bounding box's lowest corner) they
/// lie in, each group becomes one vertex at its members' mean, and every triangle whose
/// corners fall into three different cubes is kept, on those vertices, unless another
/// triangle falls into the same three (a thin part flattened into coincident triangles), it
/// has an edge that more than two such triangles share (sheets the grid pinched together), or
/// it runs round an edge the same way as its neighbour there: all such are dropped. The result
/// is 2-manifold along its edges, but may be open where triangles were dropped and pinched at
/// vertices; repair_mesh handles both. Time O(V log V + F log F); memory about 24 bytes per
/// vertex read and 80 per triangle on three cubes, besides the result.
/// \pre finite positions; cell > 0.
/// \throw InvalidInput when a triangle's index is out of range.
TriangleMesh cluster_vertices(const TriangleMesh& mesh, double cell);

/// Options of lobe_from_model().
struct LobeFromModelOptions {
    double size_m = 1.5;                 ///< largest side of the lobe's bounding box
    double target_edge_length_m = RemeshOptions{}.target_edge_length_m; ///< attractor spacing
    unsigned iterations = RemeshOptions{}.iterations;                   ///< remeshing rounds
    /// A mesh of more triangles than this is simplified by cluster_vertices before repair,
    /// with cubes of `simplify_cell_fraction` × the target edge length at the lobe's size
    /// (the mesh's size taken from the middle 99 % of its vertices on each axis, so that a
    /// speck far away, which repair drops, does not coarsen them): the lobe keeps nothing
    /// finer than its spacing, and repair's memory and time grow with the triangles
    /// (docs/lobes-from-models.md, "Large meshes"). 0: never.
    std::size_t simplify_above_triangles = 1'000'000;
    double simplify_cell_fraction = 0.2;
};

/// [cluster_vertices, above `simplify_above_triangles`] → repair_mesh → normalize_to_box →
/// remesh_isotropic, and the result checked: closed, 2-manifold, enclosing a volume
/// (check_encloses_volume). `report` (optional) receives what repair did, the simplification
/// first among its notes (RepairReport::simplified_from_triangles). Where repair refuses the
/// simplified mesh, the mesh as it was is repaired instead.
/// \throw InvalidInput for a mesh beyond repair, or one that remeshing flattened (one line).
TriangleMesh lobe_from_mesh(const TriangleMesh& mesh, const LobeFromModelOptions& options = {},
                            RepairReport* report = nullptr);

/// read_mesh → lobe_from_mesh, errors naming the file.
/// \throw FileError for an unreadable or malformed file; InvalidInput for a mesh beyond
/// repair.
TriangleMesh lobe_from_model(const std::string& path, const LobeFromModelOptions& options = {},
                             RepairReport* report = nullptr);

} // namespace lobe
