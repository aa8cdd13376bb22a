// The checks of repair.h that need no CGAL.
#include "meshing/repair.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <glm/vec3.hpp>

#include "core/errors.h"

namespace lobe {

void check_encloses_volume(const TriangleMesh& mesh, const MeshQuality& q, const std::string& what)
{
    // A flat or single-sheet input (one triangle, a plane) gets its one boundary capped by a
    // copy of itself, and the self-intersection removal can leave a sliver: closed and
    // manifold, but with nothing inside (a signed volume of ±1e-20 passes "> 0" by rounding).
    // A lobe holds at least a millionth of its bounding cube.
    glm::dvec3 lo, hi;
    bounding_box(mesh, lo, hi);
    const double extent = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
    const double least = 1e-6 * extent * extent * extent;
    if (q.closed && q.manifold && !(std::abs(q.signed_volume_m3) > least))
        throw InvalidInput(what + " encloses no volume (the mesh is flat, a single open sheet or a sliver), so it "
                                  "cannot become a closed lobe");
    if (!q.closed || !q.manifold || !(q.signed_volume_m3 > least))
        throw InvalidInput(what + " is not " +
                           (!q.closed ? "closed (" + std::to_string(q.boundary_edges) + " boundary edges)"
                            : !q.manifold ? "2-manifold (" + std::to_string(q.non_manifold_edges) + " non-manifold edges, " +
                                                std::to_string(q.non_manifold_vertices) + " non-manifold vertices, " +
                                                std::to_string(q.inconsistent_edges) + " inconsistently oriented edges)"
                                          : std::string("oriented outward (its signed volume is negative)")));
}

} // namespace lobe
