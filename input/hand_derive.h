#pragma once
/// \file hand_derive.h
/// Shared by the capture importers (input/import_*.cpp):
/// - joint geometry the sources lack: bone orientations in the OpenXR convention, the palm,
///   the wrist and metacarpal bases, default radii;
/// - a bounded reader for JSON and for the JavaScript object literals that browser capture
///   tools write (unquoted keys, single-quoted strings, `!0`/`!1`, `void 0`, NaN/Infinity);
/// - the bounded problem list every importer fills in its ReadReport.
/// Mapping details and limits: docs/importers.md.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>
#include <nlohmann/json_fwd.hpp>

#include "core/hand_frame.h"
#include "input/recording.h"

namespace lobe {

// ---------------------------------------------------------------------------------------
// Limits and constants
// ---------------------------------------------------------------------------------------

/// Largest capture file an importer reads.
inline constexpr std::size_t kMaxImportBytes = std::size_t{512} << 20;
/// Largest single frame (one element of `frames`) an importer parses.
inline constexpr std::size_t kMaxImportFrameBytes = std::size_t{4} << 20;
/// Deepest nesting of arrays/objects the literal reader accepts.
inline constexpr int kMaxLiteralDepth = 64;
/// Stage-space coordinates further than this from the origin (metres) are absurd: the
/// frame holding them is dropped.
inline constexpr double kMaxImportCoordinate = 100.0;
/// A frame more than this after the previous one (seconds) has a corrupt time: dropped.
inline constexpr double kMaxFrameGapSeconds = 3600.0;
/// Problems kept in a ReadReport; the rest are counted in one last line.
inline constexpr std::size_t kMaxReportedProblems = 20;

/// Where the Leap device sits in stage space (metres): on a desk 0.8 m high, 0.4 m in front
/// of the user standing or sitting at the origin and looking down -Z. Leap's axes already
/// match stage space (+X right, +Y up, +Z towards the user), so there is no rotation.
inline const glm::vec3 kLeapDeviceOrigin{0.0f, 0.8f, -0.4f};

/// Metacarpal base (the carpometacarpal joint) as a fraction of the wrist → proximal-knuckle
/// segment (the measurements behind it: docs/importers.md, "Joint mapping").
inline constexpr float kMetacarpalBaseFraction = 0.4f;
/// Wrist → middle knuckle distance in units of the middle proximal phalanx length (as above).
inline constexpr float kWristToKnuckleRatio = 2.2f;

/// Flags of a joint computed from other joints: valid, not tracked.
inline constexpr std::uint8_t kDerivedJointFlags = kOrientationValid | kPositionValid;

// ---------------------------------------------------------------------------------------
// Joint geometry (OpenXR convention: -Z along the bone towards the tip, +Y out of the back
// of the hand, +X = Y × Z)
// ---------------------------------------------------------------------------------------

/// Orientation of a bone pointing along `along`, with +Y as close to `up` as the bone
/// allows. Degenerate input (zero `along`, or `up` parallel to it) still gives a unit
/// quaternion with -Z along the bone (or identity when `along` is zero).
glm::quat bone_orientation(const glm::vec3& along, const glm::vec3& up);

/// The "up" (+Y) of a finger bone pointing along `along` in a hand whose +X axis is
/// `hand_x` and +Y is `hand_up`: fingers flex about the hand's X axis, so the bone's +Y is
/// perpendicular to both; near the degenerate case (bone along X) it falls back to
/// `hand_up`.
glm::vec3 finger_bone_up(const glm::vec3& along, const glm::vec3& hand_x, const glm::vec3& hand_up);

/// Unit direction from `from` to `to`, or `fallback` when they (nearly) coincide.
glm::vec3 direction_or(const glm::vec3& from, const glm::vec3& to, const glm::vec3& fallback);

/// Radius (metres) a joint gets when the source gives none, from typical adult hands (the
/// per-joint radii Meta Quest 3 reports).
float default_joint_radius(Joint j);

/// Sets the palm from the middle finger: OpenXR's palm lies at the centre of the middle
/// metacarpal (between the MiddleMetacarpal and MiddleProximal joints), oriented like it.
/// Flags: derived (valid, not tracked); orientation invalid when the metacarpal's is.
/// \pre both middle joints have valid positions.
void derive_palm_from_metacarpal(HandState& hand);

/// True when every coordinate is finite and within kMaxImportCoordinate of the origin.
bool plausible_position(const glm::vec3& p);

/// Joint chain of each finger, thumb first, base → tip (4 joints for the thumb, 5 else).
const std::vector<std::vector<Joint>>& finger_chains();

// ---------------------------------------------------------------------------------------
// Reading JSON and JavaScript object literals
// ---------------------------------------------------------------------------------------

/// A syntax error, a truncated text or a too deep nesting at byte `offset`.
class LiteralError : public std::runtime_error {
public:
    LiteralError(std::size_t offset, const std::string& what, bool truncated)
        : std::runtime_error(what + " at byte " + std::to_string(offset)), offset_(offset),
          truncated_(truncated)
    {
    }
    std::size_t offset() const { return offset_; }
    bool truncated() const { return truncated_; }

private:
    std::size_t offset_;
    bool truncated_;
};

/// Parses one JSON or JS-literal value starting at `pos` (leading whitespace allowed) and
/// moves `pos` past it. Numbers become doubles (NaN and ±Infinity included), `undefined` and
/// `void 0` become null. Recursion is bounded by `max_depth`.
/// \throw LiteralError
nlohmann::json parse_literal(std::string_view text, std::size_t& pos, int max_depth = kMaxLiteralDepth);

/// Moves `pos` past one value without building it (brackets and quotes matched, nothing
/// else checked; no recursion).
/// \throw LiteralError
void skip_literal(std::string_view text, std::size_t& pos, int max_depth = kMaxLiteralDepth);

/// The top-level keys of the object starting at the first `{` of `text`, with the offset
/// of each value (first occurrence wins). Scanning stops at the first error, which is
/// returned in `problem` (the keys found before it are kept).
struct TopLevelKeys {
    std::map<std::string, std::size_t> value_offset;
    std::string problem;
    bool found_object = false;
};
TopLevelKeys scan_top_level_keys(std::string_view text);

/// Calls `fn(element, index)` for each element of the array starting at `pos`, parsing one
/// element at a time. An element that is too large or fails to parse is passed to `bad`
/// (with the reason) and skipped. Returns an empty string when the array ended normally,
/// else why it stopped early (truncation, a syntax error between elements).
/// \throw LiteralError when `pos` does not start an array.
std::string for_each_array_element(
    std::string_view text, std::size_t pos,
    const std::function<bool(const nlohmann::json& element, std::size_t index)>& fn,
    const std::function<void(std::size_t index, const std::string& why)>& bad);

// ---------------------------------------------------------------------------------------
// Reporting
// ---------------------------------------------------------------------------------------

/// At most kMaxReportedProblems lines, then a count of the others.
class ProblemLog {
public:
    void add(std::string line);
    std::size_t count() const { return count_; }
    /// The first problem, or "" when there is none.
    std::string first() const { return lines_.empty() ? std::string() : lines_.front(); }
    /// Appends the kept lines (and "… and N more") to `report`; null is fine.
    void write_to(ReadReport* report) const;

private:
    std::vector<std::string> lines_;
    std::size_t count_ = 0;
};

} // namespace lobe
