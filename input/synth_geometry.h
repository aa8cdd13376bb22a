#pragma once
/// \file synth_geometry.h
/// The synthesizer's geometry (input/synth.h; not included outside input/): stroke curves
/// densified by centripetal Catmull–Rom with an arc-length table for timing, minimum-jerk
/// timing, and the directions and frames that aim a hand or a head. Metres and radians.

#include <algorithm>
#include <cstddef>
#include <vector>

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

#include "input/truth_surface.h"

namespace lobe::synth {

using dvec3 = glm::dvec3;
using dquat = glm::dquat;

inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kTwoPi = 2.0 * kPi;

inline dvec3 to_d(const glm::vec3& v) { return dvec3(v); }

/// Minimum-jerk profile 10u³ − 15u⁴ + 6u⁵ of u clamped to [0, 1] (Flash and Hogan 1985).
double min_jerk(double u);

/// `v` normalised, or `fallback` when |v| ≤ 1e-12.
dvec3 safe_normalize(const dvec3& v, const dvec3& fallback);

/// Spherical interpolation of unit vectors.
dvec3 slerp_dir(const dvec3& a, const dvec3& b, double s);

/// Orientation whose -Z is `forward` and +Y is `up` made perpendicular to it.
dquat look_frame(const dvec3& forward, const dvec3& up);

/// Rotation by `angle` radians about `axis` (+Y when the axis is zero).
dquat axis_angle(const dvec3& axis, double angle);

/// A curve sampled ≤ 1 mm apart with its cumulative arc length.
/// \pre at least one point (`at`).
struct DenseCurve {
    std::vector<dvec3> p;
    std::vector<double> s; ///< cumulative arc length
    double length() const { return s.empty() ? 0.0 : s.back(); }

    /// The point at arc length `arc`, clamped to the ends, linear between samples.
    dvec3 at(double arc) const
    {
        if (arc <= 0.0) return p.front();
        if (arc >= s.back()) return p.back();
        auto it = std::upper_bound(s.begin(), s.end(), arc);
        std::size_t i = static_cast<std::size_t>(it - s.begin());
        double seg = s[i] - s[i - 1];
        double u = seg > 0.0 ? (arc - s[i - 1]) / seg : 0.0;
        return p[i - 1] + (p[i] - p[i - 1]) * u;
    }
};

/// Control points without consecutive duplicates (and without a closing duplicate).
std::vector<dvec3> distinct_points(const std::vector<glm::vec3>& ctrl, bool closed);

/// Centripetal Catmull–Rom through the control points (a closed curve returns to its
/// start), sampled ≤ 1 mm apart.
/// \pre at least 2 distinct points (3 when closed), as validated scenarios have.
DenseCurve densify(const std::vector<glm::vec3>& ctrl, bool closed);

/// The curve resampled at equal arc length, at most 1.5 mm apart (the ground truth).
std::vector<glm::vec3> resample(const DenseCurve& c);

/// Moves every point of a densified curve radially onto a lobe surface (the control points
/// already lie on it; the spline between them strays by micrometres) and redoes the
/// arc-length table.
void on_surface(DenseCurve& c, const TruthSurface& surface);

/// Length of the control polyline (with the closing segment when `closed`).
double polyline_length(const std::vector<glm::vec3>& c, bool closed);

} // namespace lobe::synth
