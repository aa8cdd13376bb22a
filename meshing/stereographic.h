#pragma once
/// \file stereographic.h
/// Stereographic projection of the sphere of directions around a lobe's centre onto a plane,
/// for the constrained Delaunay triangulations of lobe surfaces (lobe_surface_cgal.cpp) and
/// of their regions (lobe_remesh_cgal.cpp).

#include <cmath>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace lobe {

/// Stereographic projection from `pole` (a unit direction) onto the plane through the
/// centre normal to it: circles map to circles, so the planar constrained Delaunay
/// triangulation is the spherical one. Directions near the pole go far out.
struct Stereo {
    glm::dvec3 pole, e1, e2;

    explicit Stereo(const glm::dvec3& n) : pole(n)
    {
        const glm::dvec3 a = std::abs(n.x) < 0.6 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
        e1 = glm::normalize(glm::cross(n, a));
        e2 = glm::cross(n, e1);
    }
    glm::dvec2 to_plane(const glm::dvec3& d) const
    {
        const double w = 1.0 - glm::dot(d, pole);
        return {glm::dot(d, e1) / w, glm::dot(d, e2) / w};
    }
    glm::dvec3 to_sphere(const glm::dvec2& x) const
    {
        const double s = glm::dot(x, x);
        return (2.0 * x.x * e1 + 2.0 * x.y * e2 + (s - 1.0) * pole) / (s + 1.0);
    }
};

} // namespace lobe
