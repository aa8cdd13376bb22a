#pragma once
/// \file repair.h
/// Turning an external mesh (a scan, a model from the web) into a valid lobe surface:
/// closed, 2-manifold, one component, oriented outward. CGAL works behind this plain
/// interface (repair_cgal.cpp). See docs/lobes-from-models.md.

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "core/mesh.h"
#include "meshing/mesh_quality.h"

namespace lobe {

/// What repair_mesh() did, for the import report.
struct RepairReport {
    /// Triangles of the mesh as read, where lobe_from_mesh simplified it before repair
    /// (cluster_vertices, model_import.h); 0 where it did not. The counts below are then the
    /// simplified mesh's.
    std::size_t simplified_from_triangles = 0;
    double simplify_cell_m = 0;              ///< the clustering's cube side, at the lobe's size
    std::size_t input_vertices = 0;
    std::size_t input_triangles = 0;
    std::size_t merged_vertices = 0;         ///< duplicate points merged or unused points dropped
    std::size_t removed_triangles = 0;       ///< degenerate (repeated vertex) or duplicate triangles
    std::size_t split_non_manifold_vertices = 0; ///< vertex copies made to split non-manifold vertices
    std::size_t holes_filled = 0;
    std::size_t holes_faired = 0;            ///< of those, filled with a smooth (faired) patch
    std::size_t holes_not_faired = 0;        ///< of those, filled again without fairing: the faired
                                             ///< patch crossed itself or the surface
    std::size_t holes_fanned = 0;            ///< of those, holes of over 200 edges that run over
                                             ///< themselves in their plane and got no searched
                                             ///< patch: filled by a fan from their centroid
    std::size_t components = 0;              ///< connected components before keeping the largest
    std::size_t removed_component_triangles = 0; ///< triangles of the smaller components, dropped
    std::size_t crossing_pairs = 0;          ///< pairs of intersecting triangles step 5 set out to remove
    unsigned removal_steps = 0;              ///< cuts step 5 kept (step k cuts k rings round the crossings)
    std::size_t cut_triangles = 0;           ///< triangles those cuts took out
    std::size_t bisected_edges = 0;          ///< long edges split in two round the crossings before
                                             ///< the first cut (long, thin triangles)
    std::size_t cut_holes_filled = 0;        ///< holes those cuts left, filled as in step 4
    std::size_t crossing_pairs_left = 0;     ///< of those, or of the pairs the cuts made, left
    bool self_intersections_left = false;    ///< the input self-intersected and not all could be removed
    bool reoriented = false;                 ///< all faces were flipped to point outward
    std::size_t output_vertices = 0;
    std::size_t output_triangles = 0;
    std::vector<std::string> notes;          ///< one line per notable step, in order
};

/// Repairs a triangle soup into one closed, 2-manifold, outward-oriented surface:
/// 1. drops triangles with repeated vertices and duplicate triangles, merges vertices at the
///    same position, drops unused vertices (CGAL repair_polygon_soup);
/// 2. orients the soup consistently, splitting vertices and edges where it is not manifold
///    (orient_polygon_soup), builds a halfedge mesh and splits any remaining non-manifold
///    vertex (duplicate_non_manifold_vertices); the copies of a split vertex are moved a
///    hair apart (1% towards their own fan) so the surface does not touch itself there;
/// 3. keeps the largest connected component (by triangle count), noting the others;
/// 4. fills every hole as CGAL's triangulate_refine_and_fair_hole does (the best patch
///    among the faces of the border's 3D Delaunay triangulation, else over all
///    triangulations; refined, faired), the patch found by our own search with CGAL's
///    weights and ties broken by vertex order, so that a repair does not depend on what ran
///    before in the process; holes of over 200 edges by a constrained Delaunay patch in their
///    plane where the border is a simple polygon there, else by the Delaunay search without
///    its cubic fallback (up to 1,000 edges) or a fan from their centroid, then refined and
///    faired (CGAL's full search takes memory and time that grow much faster than the
///    border there: gigabytes, or hours); a faired patch that intersects itself or the surface (a long,
///    wavy border) is replaced by the refined patch without fairing;
/// 5. removes self-intersections (the input's, or a patch's that still crosses) where it
///    can: cuts out the crossing triangles with a ring of neighbours (one ring wider at each
///    of up to four steps, never the whole mesh; a cut that does not fill into a 2-manifold
///    surface is not kept), keeps the largest piece and fills the holes as in step 4; where
///    the first cut's triangles are long and thin, that region is bisected first and the
///    result compared with the cuts of whole triangles (bisected_edges); what is left is
///    reported in
///    RepairReport::self_intersections_left, not thrown;
/// 6. orients the faces outward (is_outward_oriented, reverse_face_orientations).
/// Feature edges of the input are dropped. `report` (optional) receives what was done.
/// \throw InvalidInput when an index is out of range, a coordinate is not finite, nothing
/// is left after step 1, or the result is still not closed and 2-manifold (a hole that
/// cannot be triangulated), with a one-line message.
TriangleMesh repair_mesh(const TriangleMesh& mesh, RepairReport* report = nullptr);

/// Throws InvalidInput, "<what> encloses no volume …" or "<what> is not closed / 2-manifold /
/// oriented outward (…)", unless `mesh` (measured as `q`) is closed, 2-manifold and encloses
/// a positive volume of at least a millionth of its bounding cube (its largest side cubed).
void check_encloses_volume(const TriangleMesh& mesh, const MeshQuality& q, const std::string& what);

/// True when two non-adjacent triangles of `mesh` intersect
/// (CGAL::Polygon_mesh_processing::does_self_intersect).
/// \pre mesh is 2-manifold (it is converted to a halfedge mesh).
/// \throw InvalidInput when it is not.
bool self_intersects(const TriangleMesh& mesh);

/// The pairs of non-adjacent triangles of `mesh` that intersect, as indices into
/// mesh.triangles (CGAL::Polygon_mesh_processing::self_intersections).
/// \pre mesh is 2-manifold. \throw InvalidInput when it is not.
std::vector<std::array<std::size_t, 2>> self_intersecting_pairs(const TriangleMesh& mesh);

} // namespace lobe
