// leapjs-playback JSON → Recording. Mapping and limits: docs/importers.md.
#include <array>
#include <cmath>
#include <limits>
#include <string>

#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "core/errors.h"
#include "input/hand_derive.h"
#include "input/import_frames.h"
#include "input/importers.h"

namespace lobe {

namespace {

using nlohmann::json;

/// Leap coordinates beyond 10 m from the device are corrupt, not a hand.
constexpr double kLeapMaxMillimetres = 10000.0;
/// Finger widths (mm) outside this range are ignored (default radii are used).
constexpr double kLeapMinWidthMm = 2.0;
constexpr double kLeapMaxWidthMm = 60.0;

constexpr const char* kFingerNames[5] = {"thumb", "index", "middle", "ring", "little"};

/// Radius of each joint of a chain relative to half the finger width: thick at the base,
/// thinner at the tip.
constexpr float kThumbTaper[4] = {1.0f, 0.95f, 0.85f, 0.75f};
constexpr float kFingerTaper[5] = {1.05f, 1.0f, 0.9f, 0.82f, 0.75f};

enum class Field { Ok, Missing, Bad };

/// Reads `key` as 3 numbers. Missing or not numbers: Missing; NaN/Inf or beyond `limit`: Bad.
Field read_vec3(const json& obj, const char* key, glm::dvec3& out, double limit)
{
    const auto it = obj.find(key);
    if (it == obj.end() || !it->is_array() || it->size() != 3) return Field::Missing;
    for (int i = 0; i < 3; ++i) {
        const json& v = (*it)[static_cast<std::size_t>(i)];
        if (!v.is_number()) return Field::Missing;
        const double d = v.get<double>();
        if (!std::isfinite(d) || std::abs(d) > limit) return Field::Bad;
        out[i] = d;
    }
    return Field::Ok;
}

/// A number field, or NaN when missing or not a number.
double read_number(const json& obj, const char* key)
{
    const auto it = obj.find(key);
    if (it == obj.end() || !it->is_number()) return std::numeric_limits<double>::quiet_NaN();
    return it->get<double>();
}

glm::vec3 to_stage(const glm::dvec3& mm) { return kLeapDeviceOrigin + glm::vec3(mm * 0.001); }

struct Finger {
    const json* pointable = nullptr;
    std::array<glm::vec3, 4> joints{}; ///< mcp, pip, dip, tip (stage, metres)
    glm::vec3 direction{0.0f};         ///< Leap's finger direction, zero when absent
    float half_width = 0.0f;           ///< metres, 0 when absent
};

/// Outcome of building one hand: `why` empty on success; `drop_frame` when the frame holds
/// corrupt numbers and must go.
struct HandResult {
    std::string why;
    bool drop_frame = false;
};

HandResult fail_hand(std::string why, bool drop = false) { return HandResult{std::move(why), drop}; }

HandResult read_finger(const json& pointable, Finger& finger, int type)
{
    static constexpr const char* keys[4] = {"mcpPosition", "pipPosition", "dipPosition", "tipPosition"};
    const std::string name = kFingerNames[type];
    for (int k = 0; k < 4; ++k) {
        glm::dvec3 mm(0.0);
        const Field f = read_vec3(pointable, keys[k], mm, kLeapMaxMillimetres);
        if (f == Field::Missing) return fail_hand(name + " " + keys[k] + " missing or not 3 numbers");
        if (f == Field::Bad) return fail_hand(name + " " + keys[k] + " not finite or beyond 10 m", true);
        finger.joints[static_cast<std::size_t>(k)] = to_stage(mm);
    }
    glm::dvec3 d(0.0);
    if (read_vec3(pointable, "direction", d, 10.0) == Field::Ok && glm::length(d) > 1e-6)
        finger.direction = glm::vec3(glm::normalize(d));
    const double width = read_number(pointable, "width");
    if (std::isfinite(width) && width >= kLeapMinWidthMm && width <= kLeapMaxWidthMm)
        finger.half_width = static_cast<float>(width * 0.0005);
    finger.pointable = &pointable;
    return {};
}

/// Sets the joints of one chain from positions: orientation along the bone to the next joint
/// (the tip keeps the last bone's), radius from the finger width or the defaults.
void set_chain(HandState& out, const std::vector<Joint>& chain, const std::vector<glm::vec3>& pos,
               const std::vector<std::uint8_t>& flags, const Finger& finger, const float* taper,
               const glm::vec3& fallback_dir, const glm::vec3& hand_x, const glm::vec3& hand_up)
{
    const std::size_t n = chain.size();
    const glm::vec3 fallback = glm::length(finger.direction) > 0.5f ? finger.direction : fallback_dir;
    glm::vec3 along = fallback;
    for (std::size_t k = 0; k < n; ++k) {
        if (k + 1 < n) along = direction_or(pos[k], pos[k + 1], along);
        JointState& j = out[chain[k]];
        j.pose.position = pos[k];
        j.pose.orientation = bone_orientation(along, finger_bone_up(along, hand_x, hand_up));
        j.radius = finger.half_width > 0.0f ? finger.half_width * taper[k] : default_joint_radius(chain[k]);
        j.flags = flags[k];
    }
}

HandResult build_hand(const json& hand, const json* pointables, HandState& out)
{
    glm::dvec3 palm_mm(0.0), dir_d(0.0), normal_d(0.0);
    const std::pair<const char*, glm::dvec3*> fields[3] = {
        {"palmPosition", &palm_mm}, {"direction", &dir_d}, {"palmNormal", &normal_d}};
    for (const auto& [key, dst] : fields) {
        const Field f = read_vec3(hand, key, *dst, kLeapMaxMillimetres);
        if (f == Field::Missing) return fail_hand(std::string(key) + " missing or not 3 numbers");
        if (f == Field::Bad) return fail_hand(std::string(key) + " not finite or beyond 10 m", true);
    }
    const double id = read_number(hand, "id");
    if (!std::isfinite(id)) return fail_hand("id missing or not a number");
    if (pointables == nullptr) return fail_hand("no pointables array");

    if (!(glm::length(dir_d) > 1e-6)) return fail_hand("direction is zero");
    const glm::vec3 dir(glm::normalize(dir_d));
    glm::vec3 up = -glm::vec3(normal_d);
    up -= glm::dot(up, dir) * dir;
    if (!(glm::length(up) > 1e-6f)) return fail_hand("palmNormal is zero or parallel to direction");
    up = glm::normalize(up);
    const glm::vec3 hand_x = glm::cross(up, -dir);

    std::array<Finger, 5> fingers{};
    for (const json& p : *pointables) {
        if (!p.is_object()) continue;
        if (read_number(p, "handId") != id) continue;
        const auto tool = p.find("tool");
        if (tool != p.end() && tool->is_boolean() && tool->get<bool>()) continue;
        const double type = read_number(p, "type");
        if (!(type >= 0.0 && type <= 4.0) || type != std::floor(type)) continue;
        Finger& f = fingers[static_cast<std::size_t>(type)];
        if (f.pointable != nullptr) continue; // a duplicate finger: the first one wins
        if (HandResult r = read_finger(p, f, static_cast<int>(type)); !r.why.empty()) return r;
    }
    for (int t = 0; t < 5; ++t)
        if (fingers[static_cast<std::size_t>(t)].pointable == nullptr)
            return fail_hand(std::string("no usable ") + kFingerNames[t] + " pointable");

    const glm::vec3 palm = to_stage(palm_mm);
    const glm::quat hand_q = bone_orientation(dir, up);

    // Wrist: kWristToKnuckleRatio middle-proximal lengths behind the middle knuckle.
    const Finger& middle = fingers[2];
    const float prox_len = glm::length(middle.joints[1] - middle.joints[0]);
    const float knuckle_ahead = glm::dot(middle.joints[0] - palm, dir);
    const float back = glm::clamp(kWristToKnuckleRatio * prox_len - knuckle_ahead, 0.03f, 0.15f);
    const glm::vec3 wrist = palm - back * dir;

    out = HandState{};
    out.active = true;
    out[Joint::Palm] = JointState{Pose{palm, hand_q}, default_joint_radius(Joint::Palm), kAllJointFlags};
    out[Joint::Wrist] = JointState{Pose{wrist, hand_q}, default_joint_radius(Joint::Wrist), kDerivedJointFlags};

    const auto& chains = finger_chains();
    {
        const Finger& thumb = fingers[0];
        const std::vector<glm::vec3> pos(thumb.joints.begin(), thumb.joints.end());
        set_chain(out, chains[0], pos, std::vector<std::uint8_t>(4, kAllJointFlags), thumb, kThumbTaper, dir,
                  hand_x, up);
    }
    for (std::size_t t = 1; t < 5; ++t) {
        const Finger& f = fingers[t];
        const glm::vec3 base = wrist + kMetacarpalBaseFraction * (f.joints[0] - wrist);
        const std::vector<glm::vec3> pos = {base, f.joints[0], f.joints[1], f.joints[2], f.joints[3]};
        std::vector<std::uint8_t> flags(5, kAllJointFlags);
        flags[0] = kDerivedJointFlags;
        set_chain(out, chains[t], pos, flags, f, kFingerTaper, dir, hand_x, up);
    }
    return {};
}

/// Parses one frame object into `frame` (time left to the caller). Returns why the frame is
/// dropped, or "".
std::string read_frame(const json& fr, std::size_t index, HandFrame& frame, ProblemLog& problems)
{
    const std::string where = "frame " + std::to_string(index) + ": ";
    const auto hands_it = fr.find("hands");
    if (hands_it == fr.end() || !hands_it->is_array()) {
        problems.add(where + "no hands array (both hands inactive)");
        return {};
    }
    const auto pts_it = fr.find("pointables");
    const json* pointables = (pts_it != fr.end() && pts_it->is_array()) ? &*pts_it : nullptr;

    // The most confident hand of each type.
    std::array<const json*, kHandCount> chosen{};
    std::array<double, kHandCount> confidence{-1.0, -1.0};
    for (const json& h : *hands_it) {
        if (!h.is_object()) {
            problems.add(where + "a hand is not an object");
            continue;
        }
        const auto type = h.find("type");
        int side = -1;
        if (type != h.end() && type->is_string()) {
            const std::string& s = type->get_ref<const std::string&>();
            side = s == "left" ? 0 : s == "right" ? 1 : -1;
        }
        if (side < 0) {
            problems.add(where + "a hand's type is not \"left\" or \"right\"");
            continue;
        }
        double c = read_number(h, "confidence");
        if (!std::isfinite(c)) c = 1.0;
        const auto s = static_cast<std::size_t>(side);
        if (chosen[s] != nullptr)
            problems.add(where + "two " + hand_name(static_cast<Hand>(side)) + " hands, the more confident kept");
        if (chosen[s] == nullptr || c > confidence[s]) {
            chosen[s] = &h;
            confidence[s] = c;
        }
    }
    for (int side = 0; side < kHandCount; ++side) {
        const json* h = chosen[static_cast<std::size_t>(side)];
        if (h == nullptr) continue;
        HandState& state = frame.hands[static_cast<std::size_t>(side)];
        const HandResult r = build_hand(*h, pointables, state);
        if (r.drop_frame) return std::string(hand_name(static_cast<Hand>(side))) + " hand: " + r.why;
        if (!r.why.empty()) {
            state = HandState{};
            problems.add(where + hand_name(static_cast<Hand>(side)) + " hand inactive: " + r.why);
        }
    }
    return {};
}

} // namespace

Recording import_leap_json_text(const std::string& text, const std::string& name, ReadReport* report)
{
    if (text.size() > kMaxImportBytes)
        throw FileError(name, "file too large (" + std::to_string(text.size()) + " bytes, limit " +
                                  std::to_string(kMaxImportBytes) + ")");
    const TopLevelKeys keys = scan_top_level_keys(text);
    if (!keys.found_object) throw FileError(name, "not a leapjs-playback recording (" + keys.problem + ")");
    const auto frames_it = keys.value_offset.find("frames");
    if (frames_it == keys.value_offset.end())
        throw FileError(name, "no frames array" + (keys.problem.empty() ? "" : " (" + keys.problem + ")"));

    Recording rec;
    rec.header.source = "import-leap";
    rec.header.device = "Leap Motion";
    FrameSource source;
    source.seconds_per_unit = 1e-6; // timestamps in µs
    source.read_time = [](const json& fr, double& t_us) -> std::string {
        if (!fr.is_object()) return "not an object";
        t_us = read_number(fr, "timestamp");
        if (!std::isfinite(t_us)) return "timestamp missing or not a number";
        return {};
    };
    source.read_frame = read_frame;
    import_frames(text, frames_it->second, name, source, rec, report);
    return rec;
}

Recording import_leap_json(const std::string& path, ReadReport* report)
{
    return import_leap_json_text(read_file_limited(path, kMaxImportBytes), path, report);
}

} // namespace lobe
