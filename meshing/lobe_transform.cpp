#include "meshing/lobe_transform.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

#include "core/errors.h"

namespace lobe {

namespace {

bool finite(const glm::dvec3& p) { return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z); }

void check_points(std::initializer_list<glm::dvec3> points, const char* who)
{
    for (const glm::dvec3& p : points)
        if (!finite(p)) throw InvalidInput(std::string(who) + ": non-finite point");
}

void check_options(const LobeTransformOptions& o, const char* who)
{
    if (!(o.min_lever_m >= 0.0 && o.min_lever_m <= 10.0))
        throw InvalidInput(std::string(who) + ": min_lever_m must be in [0, 10]");
    if (!(o.min_scale > 0.0 && o.min_scale <= 1.0 && o.max_scale >= 1.0 && o.max_scale <= 1e6))
        throw InvalidInput(std::string(who) + ": scale clamp must satisfy 0 < min_scale <= 1 <= max_scale <= 1e6");
}

/// x ↦ centre + L (x − centre) as a 4×4 matrix (column-major, as GLM stores it).
glm::dmat4 about_centre(const glm::dmat3& linear, const glm::dvec3& centre)
{
    glm::dmat4 m(linear);
    const glm::dvec3 t = centre - linear * centre;
    m[3] = glm::dvec4(t, 1.0);
    return m;
}

bool finite(const glm::dmat4& m)
{
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (!std::isfinite(m[c][r])) return false;
    return true;
}

glm::dvec3 apply(const glm::dmat4& m, const glm::vec3& p)
{
    return glm::dvec3(m * glm::dvec4(glm::dvec3(p), 1.0));
}

} // namespace

glm::dmat4 move_transform(const glm::dvec3& start, const glm::dvec3& end)
{
    check_points({start, end}, "move lobe");
    glm::dmat4 m(1.0);
    m[3] = glm::dvec4(end - start, 1.0);
    return m;
}

glm::dmat4 rotate_transform(const glm::dvec3& start, const glm::dvec3& end, const glm::dvec3& centre,
                            const LobeTransformOptions& options)
{
    check_points({start, end, centre}, "rotate lobe");
    check_options(options, "rotate lobe");
    const glm::dvec3 a0 = start - centre, b0 = end - centre;
    const double la = glm::length(a0), lb = glm::length(b0);
    if (la < options.min_lever_m || lb < options.min_lever_m || la == 0.0 || lb == 0.0) return glm::dmat4(1.0);
    const glm::dvec3 a = a0 / la, b = b0 / lb;

    // Unit quaternion (w, v) of the smallest rotation taking a to b: w = cos(θ/2),
    // v = sin(θ/2) k. Unnormalised it is (1 + a·b, a × b), which loses all precision only
    // when a and b are opposite; then any axis perpendicular to a turns a onto b by 180°.
    double w = 1.0 + glm::dot(a, b);
    glm::dvec3 v = glm::cross(a, b);
    if (w < 1e-12) {
        int least = 0;
        for (int i = 1; i < 3; ++i)
            if (std::abs(a[i]) < std::abs(a[least])) least = i;
        glm::dvec3 e(0.0);
        e[least] = 1.0;
        v = glm::normalize(glm::cross(a, e));
        w = 0.0;
    }
    const double n = std::sqrt(w * w + glm::dot(v, v));
    w /= n;
    v /= n;
    // Rotation matrix of the unit quaternion (columns are the images of the axes).
    const double x = v.x, y = v.y, z = v.z;
    glm::dmat3 r;
    r[0] = {1 - 2 * (y * y + z * z), 2 * (x * y + w * z), 2 * (x * z - w * y)};
    r[1] = {2 * (x * y - w * z), 1 - 2 * (x * x + z * z), 2 * (y * z + w * x)};
    r[2] = {2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y)};
    return about_centre(r, centre);
}

double drag_scale_factor(const glm::dvec3& start, const glm::dvec3& end, const glm::dvec3& centre,
                         const LobeTransformOptions& options)
{
    check_points({start, end, centre}, "scale lobe");
    check_options(options, "scale lobe");
    const double la = glm::length(start - centre);
    if (la < options.min_lever_m || la == 0.0) return 1.0;
    return std::clamp(glm::length(end - centre) / la, options.min_scale, options.max_scale);
}

glm::dmat4 scale_transform(const glm::dvec3& start, const glm::dvec3& end, const glm::dvec3& centre,
                           const LobeTransformOptions& options)
{
    const double s = drag_scale_factor(start, end, centre, options);
    if (s == 1.0) return glm::dmat4(1.0);
    return about_centre(glm::dmat3(s), centre);
}

glm::dmat4 drag_transform(LobeTransformKind kind, const std::vector<glm::vec3>& path, const glm::dvec3& centre,
                          const LobeTransformOptions& options)
{
    if (path.empty()) throw InvalidInput("lobe transform: the drag has no points");
    const glm::dvec3 start(path.front()), end(path.back());
    switch (kind) {
    case LobeTransformKind::Move: return move_transform(start, end);
    case LobeTransformKind::Rotate: return rotate_transform(start, end, centre, options);
    case LobeTransformKind::Scale: return scale_transform(start, end, centre, options);
    }
    throw InvalidInput("lobe transform: unknown kind");
}

double similarity_scale(const glm::dmat4& transform)
{
    return std::cbrt(std::abs(glm::determinant(glm::dmat3(transform))));
}

void transform_mesh(TriangleMesh& mesh, const glm::dmat4& transform)
{
    if (!finite(transform)) throw InvalidInput("transform mesh: non-finite matrix");
    if (!(glm::determinant(glm::dmat3(transform)) > 0.0))
        throw InvalidInput("transform mesh: the matrix mirrors or collapses the mesh (determinant <= 0)");
    std::vector<glm::vec3> out(mesh.positions.size());
    for (std::size_t i = 0; i < out.size(); ++i) {
        out[i] = glm::vec3(apply(transform, mesh.positions[i]));
        if (!std::isfinite(out[i].x) || !std::isfinite(out[i].y) || !std::isfinite(out[i].z))
            throw InvalidInput("transform mesh: vertex " + std::to_string(i) + " leaves the float range");
    }
    mesh.positions = std::move(out);
}

void transform_stroke(Stroke& stroke, const glm::dmat4& transform)
{
    if (!finite(transform)) throw InvalidInput("transform stroke: non-finite matrix");
    std::vector<glm::vec3> out(stroke.points.size());
    for (std::size_t i = 0; i < out.size(); ++i) {
        out[i] = glm::vec3(apply(transform, stroke.points[i].position));
        if (!std::isfinite(out[i].x) || !std::isfinite(out[i].y) || !std::isfinite(out[i].z))
            throw InvalidInput("transform stroke: point " + std::to_string(i) + " leaves the float range");
    }
    for (std::size_t i = 0; i < out.size(); ++i) stroke.points[i].position = out[i];
}

} // namespace lobe
