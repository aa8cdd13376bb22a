#include "meshing/polyline.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

#include <glm/geometric.hpp>

#include "core/errors.h"

namespace lobe {

std::vector<glm::vec3> stroke_positions(const Stroke& stroke)
{
    std::vector<glm::vec3> out;
    out.reserve(stroke.points.size());
    for (const StrokePoint& p : stroke.points) out.push_back(p.position);
    return out;
}

void check_stroke_points(const std::vector<glm::vec3>& points, const std::string& who,
                         std::size_t min_points)
{
    const std::size_t n = points.size();
    if (n < min_points)
        throw InvalidInput(who + ": stroke has " + std::to_string(n) + " point" + (n == 1 ? "" : "s") +
                           ", at least " + std::to_string(min_points) + " are needed");
    if (n > StrokeLimits::max_points)
        throw InvalidInput(who + ": stroke has " + std::to_string(n) + " points, more than the " +
                           std::to_string(StrokeLimits::max_points) + " a stroke may have");
    double max_abs = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
        for (int c = 0; c < 3; ++c) {
            const double v = static_cast<double>(points[i][c]);
            if (!std::isfinite(v))
                throw InvalidInput(who + ": point " + std::to_string(i) + " has a coordinate that is not finite");
            max_abs = std::max(max_abs, std::abs(v));
            if (std::abs(v) > StrokeLimits::max_coordinate_m) {
                std::ostringstream msg;
                msg << who << ": point " << i << " lies " << std::abs(v) << " m from the origin along an axis (limit "
                    << StrokeLimits::max_coordinate_m << " m)";
                throw InvalidInput(msg.str());
            }
        }
    }
    // Extent: the point farthest from the first, then the point farthest from that one.
    const std::vector<glm::dvec3> p = to_double(points);
    auto farthest_from = [&](const glm::dvec3& q) {
        std::size_t best = 0;
        double best_d = -1.0;
        for (std::size_t i = 0; i < n; ++i) {
            const double d = glm::distance(p[i], q);
            if (d > best_d) { best_d = d; best = i; }
        }
        return best;
    };
    const std::size_t e0 = farthest_from(p[0]);
    const std::size_t e1 = farthest_from(p[e0]);
    const double extent = glm::distance(p[e0], p[e1]);
    // Float positions carry about 1e-7 relative error: below that nothing is distinguishable.
    const double resolution = std::max(1e-6, 4e-7 * max_abs);
    if (extent <= resolution) throw InvalidInput(who + ": all points coincide (the stroke has zero length)");
    const glm::dvec3 axis = (p[e1] - p[e0]) / extent;
    double max_off = 0.0;
    for (const glm::dvec3& q : p) {
        const glm::dvec3 d = q - p[e0];
        max_off = std::max(max_off, glm::length(d - axis * glm::dot(d, axis)));
    }
    if (max_off <= std::max(1e-5 * extent, resolution))
        throw InvalidInput(who + ": all points lie on one straight line");
}

void check_strokes_differ(const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b,
                          const std::string& who)
{
    if (a.size() != b.size()) return;
    auto sorted = [](const std::vector<glm::vec3>& v) {
        std::vector<std::array<float, 3>> s;
        s.reserve(v.size());
        for (const glm::vec3& q : v) s.push_back({q.x, q.y, q.z});
        std::sort(s.begin(), s.end());
        return s;
    };
    const auto sa = sorted(a);
    const auto sb = sorted(b);
    for (std::size_t i = 0; i < sa.size(); ++i)
        for (int c = 0; c < 3; ++c)
            if (std::abs(static_cast<double>(sa[i][c]) - static_cast<double>(sb[i][c])) > 1e-6) return;
    throw InvalidInput(who + ": the two strokes are identical");
}

double polyline_length(const std::vector<glm::dvec3>& points, bool closed)
{
    double len = 0.0;
    for (std::size_t i = 1; i < points.size(); ++i) len += glm::distance(points[i - 1], points[i]);
    if (closed && points.size() > 1) len += glm::distance(points.back(), points.front());
    return len;
}

double median_spacing(const std::vector<glm::dvec3>& points, bool closed)
{
    std::vector<double> d;
    for (std::size_t i = 1; i < points.size(); ++i) d.push_back(glm::distance(points[i - 1], points[i]));
    if (closed && points.size() > 1) d.push_back(glm::distance(points.back(), points.front()));
    if (d.empty()) return 0.0;
    const auto mid = d.begin() + static_cast<std::ptrdiff_t>(d.size() / 2);
    std::nth_element(d.begin(), mid, d.end());
    return *mid;
}

glm::dvec3 polyline_barycentre(const std::vector<glm::dvec3>& points, bool closed)
{
    glm::dvec3 sum(0.0);
    double total = 0.0;
    const std::size_t n = points.size();
    const std::size_t segments = closed ? n : (n > 0 ? n - 1 : 0);
    for (std::size_t i = 0; i < segments; ++i) {
        const glm::dvec3& a = points[i];
        const glm::dvec3& b = points[(i + 1) % n];
        const double w = glm::distance(a, b);
        sum += w * 0.5 * (a + b);
        total += w;
    }
    if (total > 0.0) return sum / total;
    glm::dvec3 mean(0.0);
    for (const glm::dvec3& p : points) mean += p;
    return n > 0 ? mean / static_cast<double>(n) : mean;
}

glm::dvec3 loop_vector_area(const std::vector<glm::dvec3>& points)
{
    // Relative to the first point, so large coordinates do not cancel.
    glm::dvec3 sum(0.0);
    const std::size_t n = points.size();
    for (std::size_t i = 1; i + 1 < n; ++i)
        sum += glm::cross(points[i] - points[0], points[i + 1] - points[0]);
    return 0.5 * sum;
}

glm::dvec3 catmull_rom(const glm::dvec3& p0, const glm::dvec3& p1, const glm::dvec3& p2,
                       const glm::dvec3& p3, double t)
{
    const double d12 = glm::distance(p1, p2);
    if (d12 <= 1e-12) return p1 + t * (p2 - p1);
    // Replace missing or coincident outer neighbours by reflections across the segment's ends.
    const glm::dvec3 q0 = glm::distance(p0, p1) > 1e-12 ? p0 : 2.0 * p1 - p2;
    const glm::dvec3 q3 = glm::distance(p2, p3) > 1e-12 ? p3 : 2.0 * p2 - p1;
    // Centripetal knots (exponent 1/2): no cusps or self-loops within a segment.
    const double t0 = 0.0;
    const double t1 = t0 + std::sqrt(glm::distance(q0, p1));
    const double t2 = t1 + std::sqrt(d12);
    const double t3 = t2 + std::sqrt(glm::distance(p2, q3));
    const double u = t1 + t * (t2 - t1);
    auto lerp = [](const glm::dvec3& a, const glm::dvec3& b, double ta, double tb, double x) {
        return ((tb - x) * a + (x - ta) * b) / (tb - ta);
    };
    const glm::dvec3 a1 = lerp(q0, p1, t0, t1, u);
    const glm::dvec3 a2 = lerp(p1, p2, t1, t2, u);
    const glm::dvec3 a3 = lerp(p2, q3, t2, t3, u);
    const glm::dvec3 b1 = lerp(a1, a2, t0, t2, u);
    const glm::dvec3 b2 = lerp(a2, a3, t1, t3, u);
    return lerp(b1, b2, t1, t2, u);
}

std::vector<glm::dvec3> to_double(const std::vector<glm::vec3>& points)
{
    std::vector<glm::dvec3> out;
    out.reserve(points.size());
    for (const glm::vec3& p : points) out.emplace_back(p);
    return out;
}

} // namespace lobe
