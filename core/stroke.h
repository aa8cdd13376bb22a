#pragma once
/// \file stroke.h
/// A stroke: the fingertip path between pen-down and pen-up, in metres.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "core/hand_frame.h"

namespace lobe {

/// What a stroke sketches. More kinds (branch, leaf hint) come later; the JSON names are
/// the contract (`"lobe"`, `"trunk"`).
enum class StrokeKind : std::uint8_t { Lobe = 0, Trunk = 1 };

const char* stroke_kind_name(StrokeKind k);
/// \throw InvalidInput for an unknown name.
StrokeKind stroke_kind_from_name(const std::string& name);

struct StrokePoint {
    glm::vec3 position{0.0f}; ///< metres, stage space
    double time = 0.0;        ///< seconds since the start of the recording
};

struct Stroke {
    std::int64_t id = 0;
    StrokeKind kind = StrokeKind::Lobe;
    Hand hand = Hand::Right;
    bool closed = false; ///< set by the closed/open classification (meshing)
    std::vector<StrokePoint> points;

    /// Polyline length in metres.
    double length() const;
};

/// What one stroke of a session may hold (docs/limits.md). The document reader and the
/// session builder refuse a stroke beyond them; the meshing stages have their own, tighter
/// limits (meshing/polyline.h).
inline constexpr std::size_t kMinStrokePoints = 2;
inline constexpr std::size_t kMaxStrokePoints = 1000000;
inline constexpr double kMaxStrokeCoordinateM = 1000.0; ///< along each axis, from the stage origin

/// Empty when every point of `stroke` is usable (kMinStrokePoints to kMaxStrokePoints
/// points, every coordinate and time finite, every coordinate within kMaxStrokeCoordinateM);
/// else why not, one line, e.g. "point 3 has a coordinate that is not finite".
std::string stroke_points_problem(const Stroke& stroke);

/// True when the stroke's points all coincide or all lie on one straight line (within 10⁻⁵
/// of its extent, the rule of meshing's check_stroke_points): such a stroke cannot bound a
/// lobe. Points must be finite.
bool stroke_is_straight(const Stroke& stroke);

} // namespace lobe
