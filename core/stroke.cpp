#include "core/stroke.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <glm/geometric.hpp>

#include "core/errors.h"

namespace lobe {

const char* stroke_kind_name(StrokeKind k)
{
    switch (k) {
    case StrokeKind::Lobe: return "lobe";
    case StrokeKind::Trunk: return "trunk";
    }
    return "unknown";
}

StrokeKind stroke_kind_from_name(const std::string& name)
{
    if (name == "lobe") return StrokeKind::Lobe;
    if (name == "trunk") return StrokeKind::Trunk;
    throw InvalidInput("unknown stroke kind '" + name + "' (expected lobe or trunk)");
}

double Stroke::length() const
{
    double len = 0.0;
    for (std::size_t i = 1; i < points.size(); ++i)
        len += static_cast<double>(glm::distance(points[i - 1].position, points[i].position));
    return len;
}

std::string stroke_points_problem(const Stroke& stroke)
{
    const std::size_t n = stroke.points.size();
    if (n < kMinStrokePoints)
        return std::to_string(n) + (n == 1 ? " point" : " points") + ", a stroke needs at least " +
               std::to_string(kMinStrokePoints);
    if (n > kMaxStrokePoints)
        return std::to_string(n) + " points, more than the " + std::to_string(kMaxStrokePoints) + " a stroke may have";
    for (std::size_t i = 0; i < n; ++i) {
        for (int c = 0; c < 3; ++c) {
            const double v = static_cast<double>(stroke.points[i].position[c]);
            if (!std::isfinite(v)) return "point " + std::to_string(i) + " has a coordinate that is not finite";
            if (std::abs(v) > kMaxStrokeCoordinateM) {
                char buf[160];
                std::snprintf(buf, sizeof buf, "point %zu lies %g m from the origin along an axis (limit %g m)", i,
                              std::abs(v), kMaxStrokeCoordinateM);
                return buf;
            }
        }
        if (!std::isfinite(stroke.points[i].time))
            return "point " + std::to_string(i) + " has a time that is not finite";
    }
    return {};
}

bool stroke_is_straight(const Stroke& stroke)
{
    const std::size_t n = stroke.points.size();
    if (n < 3) return true;
    auto at = [&](std::size_t i) { return glm::dvec3(stroke.points[i].position); };
    double max_abs = 0.0;
    for (const StrokePoint& p : stroke.points)
        for (int c = 0; c < 3; ++c) max_abs = std::max(max_abs, std::abs(static_cast<double>(p.position[c])));
    // Extent: the point farthest from the first, then the point farthest from that one.
    auto farthest_from = [&](const glm::dvec3& q) {
        std::size_t best = 0;
        double best_d = -1.0;
        for (std::size_t i = 0; i < n; ++i) {
            const double d = glm::distance(at(i), q);
            if (d > best_d) {
                best_d = d;
                best = i;
            }
        }
        return best;
    };
    const std::size_t e0 = farthest_from(at(0));
    const std::size_t e1 = farthest_from(at(e0));
    const double extent = glm::distance(at(e0), at(e1));
    // Float positions carry about 1e-7 relative error: below that nothing is distinguishable.
    const double resolution = std::max(1e-6, 4e-7 * max_abs);
    if (extent <= resolution) return true;
    const glm::dvec3 axis = (at(e1) - at(e0)) / extent;
    for (std::size_t i = 0; i < n; ++i) {
        const glm::dvec3 d = at(i) - at(e0);
        if (glm::length(d - axis * glm::dot(d, axis)) > std::max(1e-5 * extent, resolution)) return false;
    }
    return true;
}

} // namespace lobe
