#include "meshing/model_import.h"

#include <algorithm>
#include <cmath>

#include <glm/common.hpp>

#include "core/errors.h"
#include "meshing/mesh_quality.h"

namespace lobe {

TriangleMesh normalize_to_box(const TriangleMesh& mesh, double size_m)
{
    if (!(size_m > 0) || !std::isfinite(size_m)) throw InvalidInput("normalize_to_box: size must be a positive number");
    if (mesh.positions.empty()) throw InvalidInput("normalize_to_box: mesh has no vertex");
    for (const glm::vec3& p : mesh.positions)
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
            throw InvalidInput("normalize_to_box: vertex with a non-finite coordinate");
    glm::dvec3 lo, hi;
    bounding_box(mesh, lo, hi);
    const glm::dvec3 ext = hi - lo;
    const double largest = std::max({ext.x, ext.y, ext.z});
    if (!(largest > 0)) throw InvalidInput("normalize_to_box: mesh has zero extent");
    const double s = size_m / largest;
    // Base centred on the origin: x and z centred, lowest point at y = 0.
    const glm::dvec3 anchor(0.5 * (lo.x + hi.x), lo.y, 0.5 * (lo.z + hi.z));
    TriangleMesh out = mesh;
    for (glm::vec3& p : out.positions) p = glm::vec3((glm::dvec3(p) - anchor) * s);
    return out;
}

} // namespace lobe
