#pragma once
/// \file synth.h
/// Realistic synthetic recordings from scenarios: an articulated hand whose index tip follows
/// each stroke curve at human speed, real pinches before and after each stroke, near-pinches
/// and grabs that must not draw, jitter, tremor and tracking drop-outs. Scenario format:
/// docs/scenario-format.md.

#include <cstdint>
#include <string>
#include <vector>

#include <glm/vec3.hpp>
#include <nlohmann/json_fwd.hpp>

#include "core/stroke.h"
#include "input/recording.h"
#include "input/truth_surface.h"

namespace lobe {

/// One stroke to draw: the curve the index tip follows while pinching.
struct ScenarioStroke {
    StrokeKind kind = StrokeKind::Lobe;
    Hand hand = Hand::Right;
    std::vector<glm::vec3> curve; ///< control polyline in metres (densified by the synthesizer)
    bool closed = false;          ///< the curve returns to its start
    double speed_mps = 0.0;       ///< peak speed; 0 = chosen by the synthesizer in [0.2, 1] m/s
    /// Index into Scenario::surfaces of the lobe surface the stroke is drawn on (−1: none).
    /// The control points must lie on it (within 1 mm); the densified path is then moved
    /// radially onto it, so the hand and the ground truth follow the surface exactly.
    int surface = -1;
};

/// A scenario step: a stroke, a distractor gesture or a raw input event.
struct ScenarioStep {
    /// Stroke: pinch, follow the curve, release (draws under the draw tools).
    /// Drag: the same hand motion, meant for an editing tool selected by a Key step before it
    /// (pinch-deform a lobe surface, move a stroke's control point); it is not a drawn stroke.
    enum class Type { Stroke, Drag, NearPinch, Grab, Key, Pause } type = Type::Stroke;
    ScenarioStroke stroke;       ///< Stroke and Drag: the path of the index tip
    Hand hand = Hand::Right;     ///< NearPinch, Grab
    glm::vec3 where{0.0f};       ///< NearPinch, Grab: where the hand is
    int key = 0;                 ///< Key: GLFW key code (see docs/scenario-format.md)
    double duration_s = 0.5;     ///< Pause, NearPinch, Grab
};

struct Scenario {
    std::string name;
    std::vector<TruthSurface> surfaces; ///< the lobe surfaces ("surfaces"; strokes may be drawn on them)
    std::uint64_t seed = 1;
    double rate_hz = 90.0;
    std::vector<ScenarioStep> steps;
    double uniform_joint_radius_m = 0.0; ///< > 0: every joint reports this radius (as some runtimes do)
    bool noise = true;    ///< jitter, tremor and frame-time jitter (false: clean tracking, for unit tests)
    bool dropouts = true; ///< tracking drop-outs
};

/// \throw InvalidInput naming the field.
Scenario scenario_from_json(const nlohmann::json& j);
/// \throw FileError naming the file.
Scenario load_scenario(const std::string& path);

/// The curve a stroke really followed, for tests ("ground truth").
struct GroundTruthStroke {
    StrokeKind kind = StrokeKind::Lobe;
    Hand hand = Hand::Right;
    bool closed = false;
    std::vector<glm::vec3> points; ///< dense, ≤ 2 mm apart
    double t_begin = 0.0;          ///< recording time of the pinch start and end
    double t_end = 0.0;
    bool drag = false;             ///< from a Drag step (an edit, not a drawn stroke)
    int surface = -1;              ///< index of the lobe surface it was drawn on (−1: none)
};

/// When a distractor or a tracking drop-out happened, for tests.
struct SynthSpan {
    enum class Type { NearPinch, Grab, Dropout } type = Type::NearPinch;
    Hand hand = Hand::Right;
    double t_begin = 0.0;      ///< the whole gesture (thumb starts closing … is open again) or the loss
    double t_end = 0.0;
    double t_peak_begin = 0.0; ///< thumb at its closest / fist closed (= t_begin/t_end for drop-outs)
    double t_peak_end = 0.0;
};

struct SynthResult {
    Recording recording;
    std::vector<GroundTruthStroke> truth;
    std::vector<TruthSurface> surfaces; ///< the scenario's lobe surfaces (GroundTruthStroke::surface indexes them)
    std::vector<SynthSpan> spans; ///< sorted by t_begin
};

/// Deterministic: the same scenario gives bit-identical frames.
/// \throw InvalidInput naming the field when the scenario is out of bounds.
SynthResult synthesize(const Scenario& scenario);

/// The ground-truth file (docs/scenario-format.md, "Ground truth"): the strokes and the
/// scenario's lobe surfaces (read them back with truth_surfaces_from_json).
/// \throw InvalidInput when a stroke's `surface` indexes none of `surfaces`.
nlohmann::json ground_truth_to_json(const std::vector<GroundTruthStroke>& truth,
                                    const std::vector<TruthSurface>& surfaces = {});
/// \throw FileError (also for a stroke's "surface" index that names no surface of the file)
std::vector<GroundTruthStroke> load_ground_truth(const std::string& path);

} // namespace lobe
