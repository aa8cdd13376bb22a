#include "input/synth_geometry.h"

#include <cmath>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>

namespace lobe::synth {

namespace {

dvec3 catmull_rom(const dvec3& p0, const dvec3& p1, const dvec3& p2, const dvec3& p3, double u)
{
    // Centripetal parameterisation (alpha = 1/2), Barry–Goldman pyramid.
    auto knot = [](const dvec3& a, const dvec3& b) { return std::max(std::sqrt(glm::distance(a, b)), 1e-6); };
    double t0 = 0.0, t1 = t0 + knot(p0, p1), t2 = t1 + knot(p1, p2), t3 = t2 + knot(p2, p3);
    double t = t1 + (t2 - t1) * u;
    dvec3 a1 = (t1 - t) / (t1 - t0) * p0 + (t - t0) / (t1 - t0) * p1;
    dvec3 a2 = (t2 - t) / (t2 - t1) * p1 + (t - t1) / (t2 - t1) * p2;
    dvec3 a3 = (t3 - t) / (t3 - t2) * p2 + (t - t2) / (t3 - t2) * p3;
    dvec3 b1 = (t2 - t) / (t2 - t0) * a1 + (t - t0) / (t2 - t0) * a2;
    dvec3 b2 = (t3 - t) / (t3 - t1) * a2 + (t - t1) / (t3 - t1) * a3;
    return (t2 - t) / (t2 - t1) * b1 + (t - t1) / (t2 - t1) * b2;
}

} // namespace

double min_jerk(double u)
{
    u = std::clamp(u, 0.0, 1.0);
    return u * u * u * (10.0 + u * (-15.0 + 6.0 * u));
}

dvec3 safe_normalize(const dvec3& v, const dvec3& fallback)
{
    double l = glm::length(v);
    return l > 1e-12 ? v / l : fallback;
}

dvec3 slerp_dir(const dvec3& a, const dvec3& b, double s)
{
    double c = std::clamp(glm::dot(a, b), -1.0, 1.0);
    double th = std::acos(c);
    if (th < 1e-6) return safe_normalize(a + (b - a) * s, a);
    return (std::sin((1.0 - s) * th) * a + std::sin(s * th) * b) / std::sin(th);
}

dquat look_frame(const dvec3& forward, const dvec3& up)
{
    dvec3 z = -safe_normalize(forward, dvec3(0.0, 0.0, -1.0));
    dvec3 y = up - glm::dot(up, z) * z;
    if (glm::length(y) < 1e-6) y = dvec3(0.0, 0.0, 1.0) - z.z * z;
    y = glm::normalize(y);
    dvec3 x = glm::cross(y, z);
    return glm::normalize(glm::quat_cast(glm::dmat3(x, y, z)));
}

dquat axis_angle(const dvec3& axis, double angle)
{
    return glm::angleAxis(angle, safe_normalize(axis, dvec3(0, 1, 0)));
}

std::vector<dvec3> distinct_points(const std::vector<glm::vec3>& ctrl, bool closed)
{
    std::vector<dvec3> out;
    out.reserve(ctrl.size());
    for (const glm::vec3& c : ctrl) {
        dvec3 d = to_d(c);
        if (out.empty() || glm::distance(out.back(), d) > 1e-6) out.push_back(d);
    }
    if (closed)
        while (out.size() > 1 && glm::distance(out.front(), out.back()) <= 1e-6) out.pop_back();
    return out;
}

DenseCurve densify(const std::vector<glm::vec3>& ctrl, bool closed)
{
    std::vector<dvec3> c = distinct_points(ctrl, closed);
    DenseCurve out;
    const std::size_t n = c.size();
    const std::size_t segments = closed ? n : n - 1;
    auto point = [&](long i) -> dvec3 {
        const long m = static_cast<long>(n);
        if (closed) return c[static_cast<std::size_t>(((i % m) + m) % m)];
        if (i < 0) return 2.0 * c[0] - c[1];
        if (i >= m) return 2.0 * c[n - 1] - c[n - 2];
        return c[static_cast<std::size_t>(i)];
    };
    for (std::size_t k = 0; k < segments; ++k) {
        const long i = static_cast<long>(k);
        dvec3 p0 = point(i - 1), p1 = point(i), p2 = point(i + 1), p3 = point(i + 2);
        auto samples = static_cast<std::size_t>(std::ceil(glm::distance(p1, p2) / 0.0008)) + 1;
        for (std::size_t q = 0; q < samples; ++q)
            out.p.push_back(catmull_rom(p0, p1, p2, p3, static_cast<double>(q) / static_cast<double>(samples)));
    }
    out.p.push_back(closed ? c[0] : c[n - 1]);
    out.s.resize(out.p.size());
    out.s[0] = 0.0;
    for (std::size_t i = 1; i < out.p.size(); ++i) out.s[i] = out.s[i - 1] + glm::distance(out.p[i - 1], out.p[i]);
    return out;
}

std::vector<glm::vec3> resample(const DenseCurve& c)
{
    const double len = c.length();
    auto n = static_cast<std::size_t>(std::ceil(len / 0.0015));
    n = std::max<std::size_t>(n, 1);
    std::vector<glm::vec3> out;
    out.reserve(n + 1);
    for (std::size_t i = 0; i <= n; ++i)
        out.push_back(glm::vec3(c.at(len * static_cast<double>(i) / static_cast<double>(n))));
    return out;
}

void on_surface(DenseCurve& c, const TruthSurface& surface)
{
    for (dvec3& p : c.p) p = project_radially(surface, p);
    for (std::size_t i = 1; i < c.p.size(); ++i) c.s[i] = c.s[i - 1] + glm::distance(c.p[i - 1], c.p[i]);
}

double polyline_length(const std::vector<glm::vec3>& c, bool closed)
{
    double len = 0.0;
    for (std::size_t i = 1; i < c.size(); ++i) len += glm::distance(to_d(c[i - 1]), to_d(c[i]));
    if (closed && c.size() > 2) len += glm::distance(to_d(c.back()), to_d(c.front()));
    return len;
}

} // namespace lobe::synth
