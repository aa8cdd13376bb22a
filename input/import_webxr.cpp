// WebXR hand capture (Immersive Web Emulation Runtime ActionRecorder) → Recording.
// Mapping and limits: docs/importers.md.
#include <array>
#include <cmath>
#include <map>
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

constexpr int kWebxrJointCount = 25;
constexpr std::size_t kFloatsPerJoint = 8; ///< pos3, quat4 (x, y, z, w), radius
constexpr std::size_t kJointArraySize = kWebxrJointCount * kFloatsPerJoint;
/// Frame row: [t_ms, head pos3, head quat4, inputs...]; input: [id, ray pos3, ray quat4, ...].
constexpr std::size_t kFrameHeaderSize = 8;
constexpr std::size_t kInputHeaderSize = 8;
/// Joint radii outside this range (metres) are replaced by the defaults.
constexpr double kMaxJointRadius = 0.1;

/// WebXR joint names (XRHandJoint), in the order of OpenXR joints 1..25.
constexpr const char* kWebxrJointNames[kWebxrJointCount] = {
    "wrist",
    "thumb-metacarpal", "thumb-phalanx-proximal", "thumb-phalanx-distal", "thumb-tip",
    "index-finger-metacarpal", "index-finger-phalanx-proximal", "index-finger-phalanx-intermediate",
    "index-finger-phalanx-distal", "index-finger-tip",
    "middle-finger-metacarpal", "middle-finger-phalanx-proximal", "middle-finger-phalanx-intermediate",
    "middle-finger-phalanx-distal", "middle-finger-tip",
    "ring-finger-metacarpal", "ring-finger-phalanx-proximal", "ring-finger-phalanx-intermediate",
    "ring-finger-phalanx-distal", "ring-finger-tip",
    "pinky-finger-metacarpal", "pinky-finger-phalanx-proximal", "pinky-finger-phalanx-intermediate",
    "pinky-finger-phalanx-distal", "pinky-finger-tip",
};

/// What the schema says about one input source.
struct InputSchema {
    bool hand = false;
    int side = -1;                 ///< 0 left, 1 right
    std::size_t joints_index = 9;  ///< element of the input row holding the joints
    std::array<int, kWebxrJointCount> slot_to_joint{}; ///< OpenXR index of each recorded joint
};

bool read_bool(const json& obj, const char* key)
{
    const auto it = obj.find(key);
    if (it == obj.end()) return false;
    if (it->is_boolean()) return it->get<bool>();
    if (it->is_number()) return it->get<double>() != 0.0;
    return false;
}

std::string join_ids(const std::vector<long>& ids)
{
    std::string out;
    for (std::size_t i = 0; i < ids.size(); ++i) out += (i ? ", " : "") + std::to_string(ids[i]);
    return out;
}

/// Input id → schema, hands only; controllers and unusable entries become problems.
std::map<long, InputSchema> read_schema(const json& schema, ProblemLog& problems)
{
    std::map<long, InputSchema> out;
    std::vector<long> controllers;
    for (const json& entry : schema) {
        if (!entry.is_array() || entry.size() != 2 || !entry[0].is_number() || !entry[1].is_object()) {
            problems.add("schema: an entry is not [id, {...}]");
            continue;
        }
        const double id_d = entry[0].get<double>();
        if (!(id_d >= 0.0 && id_d <= 1e6) || id_d != std::floor(id_d)) {
            problems.add("schema: an input id is not a small whole number");
            continue;
        }
        const long id = static_cast<long>(id_d);
        const json& s = entry[1];
        if (!read_bool(s, "hasHand")) {
            controllers.push_back(id);
            continue;
        }
        InputSchema in;
        in.hand = true;
        const auto handed = s.find("handedness");
        if (handed != s.end() && handed->is_string()) {
            const std::string& h = handed->get_ref<const std::string&>();
            in.side = h == "left" ? 0 : h == "right" ? 1 : -1;
        }
        if (in.side < 0) {
            problems.add("schema: hand input " + std::to_string(id) + " is neither left nor right: not imported");
            continue;
        }
        in.joints_index = kInputHeaderSize + (read_bool(s, "hasGrip") ? 1 : 0);
        const auto seq = s.find("jointSequence");
        bool ok = true;
        if (seq == s.end() || !seq->is_array()) {
            problems.add("schema: hand input " + std::to_string(id) + " has no jointSequence; the standard order assumed");
            for (int k = 0; k < kWebxrJointCount; ++k) in.slot_to_joint[static_cast<std::size_t>(k)] = k + 1;
        } else if (seq->size() != kWebxrJointCount) {
            ok = false;
        } else {
            std::array<bool, kWebxrJointCount> seen{};
            for (int k = 0; k < kWebxrJointCount && ok; ++k) {
                const json& name = (*seq)[static_cast<std::size_t>(k)];
                int found = -1;
                if (name.is_string())
                    for (int n = 0; n < kWebxrJointCount; ++n)
                        if (name.get_ref<const std::string&>() == kWebxrJointNames[n]) found = n;
                if (found < 0 || seen[static_cast<std::size_t>(found)]) ok = false;
                else {
                    seen[static_cast<std::size_t>(found)] = true;
                    in.slot_to_joint[static_cast<std::size_t>(k)] = found + 1;
                }
            }
        }
        if (!ok) {
            problems.add("schema: hand input " + std::to_string(id) +
                         " jointSequence is not the 25 WebXR joints: not imported");
            continue;
        }
        out[id] = in;
    }
    if (!controllers.empty())
        problems.add((controllers.size() == 1 ? "input " : "inputs ") + join_ids(controllers) +
                     (controllers.size() == 1 ? " is a controller" : " are controllers") +
                     " (hasHand false): not imported");
    return out;
}

enum class Field { Ok, Missing, Bad };

/// Reads n numbers of `arr` from `first`. Missing or not numbers: Missing; NaN/Inf: Bad.
Field read_numbers(const json& arr, std::size_t first, std::size_t n, double* out)
{
    if (!arr.is_array() || arr.size() < first + n) return Field::Missing;
    for (std::size_t i = 0; i < n; ++i) {
        const json& v = arr[first + i];
        if (!v.is_number()) return Field::Missing;
        out[i] = v.get<double>();
        if (!std::isfinite(out[i])) return Field::Bad;
    }
    return Field::Ok;
}

/// Pose from pos3 + quat4 (x, y, z, w). `orientation_ok` is false for a (near) zero
/// quaternion, which becomes identity.
Pose make_pose(const double* v, bool& orientation_ok)
{
    Pose p;
    p.position = glm::vec3(static_cast<float>(v[0]), static_cast<float>(v[1]), static_cast<float>(v[2]));
    const glm::dquat q(v[6], v[3], v[4], v[5]);
    const double n = glm::length(q);
    orientation_ok = n > 1e-6;
    p.orientation = orientation_ok ? glm::quat(q / n) : glm::quat(1.0f, 0.0f, 0.0f, 0.0f);
    return p;
}

struct HandResult {
    std::string why;
    bool drop_frame = false;
};

/// One hand from an input row: joints relative to the target ray, composed into stage space.
HandResult read_hand(const json& input, const InputSchema& schema, HandState& out, ProblemLog& problems,
                     const std::string& where)
{
    double ray_v[7];
    const Field rf = read_numbers(input, 1, 7, ray_v);
    if (rf == Field::Missing) return {"target ray missing or not 7 numbers", false};
    if (rf == Field::Bad) return {"target ray not finite", true};
    bool ray_q_ok = false;
    const Pose ray = make_pose(ray_v, ray_q_ok);
    if (!plausible_position(ray.position)) return {"target ray beyond 100 m", true};
    if (!ray_q_ok) return {"target ray orientation is a zero quaternion", false};

    const json* joints = nullptr;
    if (schema.joints_index < input.size() && input[schema.joints_index].is_array() &&
        input[schema.joints_index].size() == kJointArraySize)
        joints = &input[schema.joints_index];
    for (std::size_t k = kInputHeaderSize; joints == nullptr && k < input.size(); ++k)
        if (input[k].is_array() && input[k].size() == kJointArraySize) joints = &input[k];
    if (joints == nullptr) return {"no array of 25 joints", false};

    out = HandState{};
    bool bad_radius = false;
    for (std::size_t slot = 0; slot < static_cast<std::size_t>(kWebxrJointCount); ++slot) {
        double v[kFloatsPerJoint];
        const Field f = read_numbers(*joints, slot * kFloatsPerJoint, kFloatsPerJoint, v);
        const int joint = schema.slot_to_joint[slot];
        const std::string name = joint_name(static_cast<Joint>(joint));
        if (f == Field::Missing) return {name + " missing or not numbers", false};
        if (f == Field::Bad) return {name + " not finite", true};
        bool q_ok = false;
        const Pose local = make_pose(v, q_ok);
        JointState& j = out.joints[static_cast<std::size_t>(joint)];
        j.pose.position = ray.position + ray.orientation * local.position;
        if (!plausible_position(j.pose.position)) return {name + " beyond 100 m", true};
        j.pose.orientation = q_ok ? glm::normalize(ray.orientation * local.orientation) : glm::quat(1.0f, 0.0f, 0.0f, 0.0f);
        j.flags = q_ok ? kAllJointFlags : static_cast<std::uint8_t>(kPositionValid | kPositionTracked);
        if (v[7] > 0.0 && v[7] <= kMaxJointRadius) {
            j.radius = static_cast<float>(v[7]);
        } else {
            j.radius = default_joint_radius(static_cast<Joint>(joint));
            bad_radius = true;
        }
        if (!q_ok) problems.add(where + name + " has a zero quaternion (identity, orientation invalid)");
    }
    if (bad_radius) problems.add(where + "radius missing or out of range; default radii used");
    derive_palm_from_metacarpal(out);
    out.active = true;
    return {};
}

/// Parses one frame row (time left to the caller). Returns why the frame is dropped, or "".
std::string read_frame(const json& row, std::size_t index, const std::map<long, InputSchema>& schema,
                       HandFrame& frame, ProblemLog& problems)
{
    const std::string where = "frame " + std::to_string(index) + ": ";
    double head[7];
    const Field hf = read_numbers(row, 1, 7, head);
    if (hf == Field::Bad) return "head pose not finite";
    if (hf == Field::Missing) {
        problems.add(where + "head pose missing or not numbers");
    } else {
        bool q_ok = false;
        frame.head = make_pose(head, q_ok);
        if (!plausible_position(frame.head.position)) return "head beyond 100 m";
        frame.head_valid = q_ok;
        if (!q_ok) problems.add(where + "head orientation is a zero quaternion (head invalid)");
    }
    for (std::size_t k = kFrameHeaderSize; k < row.size(); ++k) {
        const json& input = row[k];
        if (!input.is_array() || input.empty() || !input[0].is_number()) {
            problems.add(where + "an input is not [id, ...]");
            continue;
        }
        const double id_d = input[0].get<double>();
        if (!(id_d >= 0.0 && id_d <= 1e6)) {
            problems.add(where + "an input id is not a small whole number");
            continue;
        }
        const auto it = schema.find(static_cast<long>(id_d));
        if (it == schema.end()) continue; // a controller or an input not in the schema
        const int side = it->second.side;
        HandState& hand = frame.hands[static_cast<std::size_t>(side)];
        const std::string hand_where = where + hand_name(static_cast<Hand>(side)) + " hand: ";
        if (hand.active) {
            problems.add(hand_where + "a second input for it ignored");
            continue;
        }
        const HandResult r = read_hand(input, it->second, hand, problems, hand_where);
        if (r.drop_frame) return std::string(hand_name(static_cast<Hand>(side))) + " hand: " + r.why;
        if (!r.why.empty()) {
            hand = HandState{};
            problems.add(hand_where + "inactive: " + r.why);
        }
    }
    return {};
}

} // namespace

Recording import_webxr_capture_text(const std::string& text, const std::string& name, ReadReport* report)
{
    if (text.size() > kMaxImportBytes)
        throw FileError(name, "file too large (" + std::to_string(text.size()) + " bytes, limit " +
                                  std::to_string(kMaxImportBytes) + ")");
    const TopLevelKeys keys = scan_top_level_keys(text);
    if (!keys.found_object) throw FileError(name, "not a WebXR capture (" + keys.problem + ")");
    const std::string scan_note = keys.problem.empty() ? std::string() : " (" + keys.problem + ")";
    const auto schema_it = keys.value_offset.find("schema");
    const auto frames_it = keys.value_offset.find("frames");
    if (schema_it == keys.value_offset.end()) throw FileError(name, "no schema" + scan_note);
    if (frames_it == keys.value_offset.end()) throw FileError(name, "no frames" + scan_note);

    ProblemLog schema_problems;
    json schema_json;
    try {
        std::size_t end = schema_it->second;
        skip_literal(text, end);
        if (end - schema_it->second > kMaxImportFrameBytes)
            throw FileError(name, "schema larger than " + std::to_string(kMaxImportFrameBytes >> 20) + " MiB");
        std::size_t pos = schema_it->second;
        schema_json = parse_literal(text, pos);
    } catch (const LiteralError& e) {
        throw FileError(name, std::string("schema: ") + e.what());
    }
    if (!schema_json.is_array()) throw FileError(name, "schema is not an array");
    const std::map<long, InputSchema> schema = read_schema(schema_json, schema_problems);
    if (schema.empty())
        throw FileError(name, "no hand input in the schema" +
                                  (schema_problems.count() ? " (" + schema_problems.first() + ")" : std::string()));

    Recording rec;
    rec.header.source = "import-webxr";
    rec.header.device = "Meta Quest 3 (WebXR)";
    FrameSource source;
    source.seconds_per_unit = 1e-3; // times in ms
    source.read_time = [](const json& row, double& t_ms) -> std::string {
        if (!row.is_array() || row.empty() || !row[0].is_number()) return "not an array starting with a time";
        t_ms = row[0].get<double>();
        return {};
    };
    source.read_frame = [&schema](const json& row, std::size_t index, HandFrame& frame, ProblemLog& problems) {
        return read_frame(row, index, schema, frame, problems);
    };
    import_frames(text, frames_it->second, name, source, rec, report, &schema_problems);
    return rec;
}

Recording import_webxr_capture(const std::string& path, ReadReport* report)
{
    return import_webxr_capture_text(read_file_limited(path, kMaxImportBytes), path, report);
}

} // namespace lobe
