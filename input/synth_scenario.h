#pragma once
/// \file synth_scenario.h
/// Reading and checking scenarios and ground-truth files (input/synth.h; not included
/// outside input/): the limits, the one-line errors naming the field, and the field readers
/// both files use. Format and limits: docs/scenario-format.md.

#include <cstddef>
#include <string>
#include <vector>

#include <glm/vec3.hpp>
#include <nlohmann/json_fwd.hpp>

#include "core/hand_frame.h"
#include "input/synth.h"

namespace lobe::synth {

// ---------------------------------------------------------------------------------------
// Limits (docs/scenario-format.md, "Limits")
// ---------------------------------------------------------------------------------------

inline constexpr double kMaxCoordinate = 10.0;       // metres from the origin
inline constexpr double kMinSpeed = 0.05;            // m/s
inline constexpr double kMaxSpeed = 3.0;             // m/s
inline constexpr std::size_t kMaxSteps = 10000;
inline constexpr std::size_t kMaxCurvePoints = 100000;
inline constexpr double kMaxDurationS = 7200.0;      // two hours
inline constexpr double kMaxStrokeLength = 20.0;     // metres per stroke
inline constexpr double kMaxTotalStrokeLength = 2000.0;
inline constexpr double kMinRateHz = 30.0;
inline constexpr double kMaxRateHz = 240.0;
inline constexpr std::size_t kMaxScenarioBytes = std::size_t{64} << 20;
inline constexpr std::size_t kMaxTruthBytes = std::size_t{512} << 20;
inline constexpr std::size_t kMaxDents = 8;
inline constexpr double kMaxSurfaceGap = 0.001;      // control points of a stroke on a surface, metres
inline constexpr double kMaxSectionWobble = 0.02;    // metres

inline constexpr const char* kScenarioFormat = "lobesketch-scenario";
inline constexpr const char* kTruthFormat = "lobesketch-ground-truth";

// ---------------------------------------------------------------------------------------
// Errors
// ---------------------------------------------------------------------------------------

/// `v` with 6 significant digits, in the C locale.
std::string num(double v);

/// \throw InvalidInput "field: what", always.
[[noreturn]] void fail(const std::string& field, const std::string& what);

/// Line breaks become spaces.
std::string one_line(std::string s);

// ---------------------------------------------------------------------------------------
// Checks and field readers
// ---------------------------------------------------------------------------------------

/// Checks a scenario (read from JSON or built in code) against the limits above: rate, step
/// count, curves (finite, within kMaxCoordinate, enough distinct points, lengths, on their
/// surface within kMaxSurfaceGap), speeds, durations, key codes, and the whole duration.
/// \throw InvalidInput naming the field.
void validate_scenario(const Scenario& s);

/// The number at `obj[key]`, or `fallback` when there is none.
/// \throw InvalidInput naming `field.key` when it is not a number.
double get_number(const nlohmann::json& obj, const char* key, const std::string& field, double fallback);

/// `obj["hand"]`: "left" or "right"; Right when absent.
/// \throw InvalidInput naming `field.hand` otherwise.
Hand parse_hand(const nlohmann::json& obj, const std::string& field);

/// An array of at most kMaxCurvePoints [x, y, z] points, each finite and within kMaxCoordinate.
/// \throw InvalidInput naming the field (and the point).
std::vector<glm::vec3> parse_curve(const nlohmann::json& v, const std::string& field);

} // namespace lobe::synth
