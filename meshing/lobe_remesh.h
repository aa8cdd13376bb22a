#pragma once
/// \file lobe_remesh.h
/// Remeshing a lobe region by region, so that adding a stroke remeshes only the regions it
/// changed (CGAL behind a plain interface: lobe_remesh_cgal.cpp). See docs/lobes.md,
/// "Only the changed region remeshed".
///
/// The strokes cut a lobe into regions (lobe_regions.h). Every stroke piece between two
/// corners (crossings, stroke ends) is first resampled to equal steps of about the target
/// edge length along the drawn stroke; that depends on the piece alone, so the two regions
/// beside it meet at the same vertices. Each region is then triangulated afresh from its
/// resampled pieces and its inner vertices (a constrained Delaunay triangulation on the sphere
/// of directions around the lobe's centre, as the surface itself) and remeshed on its own
/// with its border fixed. So a region's remeshed triangles depend on that region alone, and a
/// region that a stroke left as it was (bit for bit, lobe_regions.h) is taken as it was
/// remeshed before.

#include <map>
#include <vector>

#include <glm/vec3.hpp>

#include "core/mesh.h"
#include "meshing/lobe_surface.h"
#include "meshing/remesh.h"

namespace lobe {

/// Remeshed regions of one lobe, by what they were remeshed from.
struct LobeRemeshCache {
    double target = 0.0;
    unsigned iterations = 0;
    glm::dvec3 centre{0.0}; ///< the surface's centre: each region is charted around it
    /// A region's triangles (corner positions) and the resampled stroke pieces around it →
    /// the region remeshed (its feature_edges: the pieces' edges).
    std::map<std::vector<float>, TriangleMesh> regions;
};

/// What remesh_lobe_surface did.
struct LobeRemeshStats {
    int regions = 0;      ///< stroke-bounded regions of the surface
    int remeshed = 0;     ///< of them, remeshed by this call
    int reused = 0;       ///< of them, taken from the cache
    bool whole = false;   ///< remeshed as one mesh instead (a region could not be charted)
};

/// Remeshes `surface` region by region (options.target_edge_length_m, options.iterations;
/// the small-angle repairs of remesh_isotropic after each region's rounds). With `cache`,
/// regions found in it are taken from it, and it is left holding this surface's regions.
/// The result does not depend on the cache. Where a region cannot be triangulated on its own
/// (it wraps nearly all the way round the centre, or its resampled pieces cross another
/// piece), the whole surface is remeshed with remesh_isotropic and relaxed stroke vertices
/// instead. The output's feature_edges are the resampled stroke pieces.
/// \throw InvalidInput as remesh_isotropic, and when the whole-lobe remeshing leaves no closed,
/// outward surface of one piece (a lobe not much larger than the spacing collapses).
TriangleMesh remesh_lobe_surface(const LobeSurface& surface, const RemeshOptions& options,
                                 LobeRemeshCache* cache = nullptr, LobeRemeshStats* stats = nullptr);

} // namespace lobe
