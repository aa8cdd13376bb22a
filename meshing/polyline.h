#pragma once
/// \file polyline.h
/// Small polyline helpers shared by stroke sampling and stitching (§4). Positions come in
/// as float (as strokes store them) and are processed in double.

#include <cstddef>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "core/stroke.h"

namespace lobe {

/// Limits every meshing stage puts on one stroke; a stroke beyond them is refused with
/// InvalidInput, so no input can make a stage crash, hang or allocate without bound.
struct StrokeLimits {
    static constexpr std::size_t min_points = 4;       ///< fewer is not a stroke
    static constexpr std::size_t max_points = 100000;  ///< 500 m of stroke at 5 mm spacing
    static constexpr double max_coordinate_m = 1000.0; ///< 1 km from the stage origin
};

/// The positions of a stroke's points, in order.
std::vector<glm::vec3> stroke_positions(const Stroke& stroke);

/// Throws InvalidInput, with a one-line message starting with `who`, when `points`
/// has fewer than `min_points` or more than StrokeLimits::max_points points, a coordinate
/// that is NaN, infinite or beyond StrokeLimits::max_coordinate_m, zero length (all
/// points coincide) or all points on one straight line.
void check_stroke_points(const std::vector<glm::vec3>& points, const std::string& who,
                         std::size_t min_points = StrokeLimits::min_points);

/// Throws InvalidInput when `a` and `b` hold the same points (in any order, to within a
/// micrometre): stitching a stroke to itself has no meaning.
void check_strokes_differ(const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b,
                          const std::string& who);

/// Polyline length in metres; `closed` adds the segment from the last point to the first.
double polyline_length(const std::vector<glm::dvec3>& points, bool closed);

/// Median segment length in metres (the stroke's "normal spacing").
double median_spacing(const std::vector<glm::dvec3>& points, bool closed);

/// Barycentre of the polyline as a curve (segment midpoints weighted by segment length), so
/// that denser sampling at corners does not pull it; falls back to the vertex mean when the
/// polyline has zero length.
glm::dvec3 polyline_barycentre(const std::vector<glm::dvec3>& points, bool closed);

/// Vector area of a closed polygon (Newell): its direction is the loop's normal by the
/// right-hand rule, its length the area of the loop's projection on the plane normal to it.
glm::dvec3 loop_vector_area(const std::vector<glm::dvec3>& points);

/// Centripetal Catmull-Rom interpolation between `p1` (t = 0) and `p2` (t = 1), with `p0`
/// and `p3` as the outer neighbours. Coincident points fall back to straight lines, so the
/// result is always finite for finite input.
glm::dvec3 catmull_rom(const glm::dvec3& p0, const glm::dvec3& p1, const glm::dvec3& p2,
                       const glm::dvec3& p3, double t);

/// Float positions to double.
std::vector<glm::dvec3> to_double(const std::vector<glm::vec3>& points);

} // namespace lobe
