#pragma once
/// \file stroke.h
/// A stroke: the fingertip path between pen-down and pen-up, in metres.

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

} // namespace lobe
