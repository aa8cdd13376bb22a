// Importers of real captures: Leap Motion (leapjs-playback JSON) and WebXR (IWER capture).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <string>

#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "core/errors.h"
#include "input/hand_derive.h"
#include "input/importers.h"
#include "tests/support/test_data.h"
#include "tests/support/test_paths.h"

using namespace lobe;

namespace {

// The real captures (../shared/data/real), each imported once. A missing capture gives null
// and fails the test with one line.

const Recording* leap_pinch()
{
    const std::string path = test::shared_data("data/real/leap-pinch.json");
    if (path.empty()) return nullptr;
    static const Recording rec = import_leap_json(path);
    return &rec;
}

const Recording* leap_grab()
{
    const std::string path = test::shared_data("data/real/leap-grab.json");
    if (path.empty()) return nullptr;
    static const Recording rec = import_leap_json(path);
    return &rec;
}

const Recording* webxr()
{
    const std::string path = test::shared_data("data/real/quest3-webxr-capture.min.js");
    if (path.empty()) return nullptr;
    static const Recording rec = import_webxr_capture(path);
    return &rec;
}

std::string read_text(const std::string& path) { return read_file_limited(path, std::size_t{64} << 20); }

Joint next(Joint j, int k = 1) { return static_cast<Joint>(idx(j) + k); }
glm::vec3 at(const HandState& h, Joint j) { return h[j].pose.position; }

/// Thumb-tip to index-tip distance minus both radii (metres).
float pinch_gap(const HandState& h)
{
    return glm::distance(at(h, Joint::ThumbTip), at(h, Joint::IndexTip)) - h[Joint::ThumbTip].radius -
           h[Joint::IndexTip].radius;
}

/// 1 − |tip − proximal| / (proximal → intermediate → distal → tip): 0 straight, → 1 folded.
float curl(const HandState& h, Joint proximal)
{
    float chain = 0.0f;
    for (int k = 0; k < 3; ++k) chain += glm::distance(at(h, next(proximal, k)), at(h, next(proximal, k + 1)));
    return 1.0f - glm::distance(at(h, next(proximal, 3)), at(h, proximal)) / chain;
}

float min_curl_mrl(const HandState& h)
{
    return std::min({curl(h, Joint::MiddleProximal), curl(h, Joint::RingProximal), curl(h, Joint::LittleProximal)});
}

float max_curl_mrl(const HandState& h)
{
    return std::max({curl(h, Joint::MiddleProximal), curl(h, Joint::RingProximal), curl(h, Joint::LittleProximal)});
}

const HandState& right(const HandFrame& f) { return f.hand(Hand::Right); }

/// Every joint of an active hand is oriented by a unit quaternion whose -Z points along the
/// bone to the next joint of its finger (the tip along the last bone); returns the worst dot.
float worst_bone_alignment(const HandState& h)
{
    float worst = 1.0f;
    for (const auto& chain : finger_chains()) {
        for (std::size_t k = 0; k < chain.size(); ++k) {
            const JointState& j = h[chain[k]];
            if ((j.flags & kOrientationValid) == 0) continue;
            EXPECT_NEAR(glm::length(j.pose.orientation), 1.0f, 1e-4f);
            const glm::vec3 a = k + 1 < chain.size() ? at(h, chain[k]) : at(h, chain[k - 1]);
            const glm::vec3 b = k + 1 < chain.size() ? at(h, chain[k + 1]) : at(h, chain[k]);
            if (glm::distance(a, b) < 1e-4f) continue;
            const glm::vec3 minus_z = j.pose.orientation * glm::vec3(0.0f, 0.0f, -1.0f);
            worst = std::min(worst, glm::dot(minus_z, glm::normalize(b - a)));
        }
    }
    return worst;
}

/// Runs `import`, which must throw a FileError of one line naming `path`.
void expect_one_line_file_error(const std::function<void()>& import, const std::string& path)
{
    try {
        import();
        ADD_FAILURE() << "no FileError for " << path;
    } catch (const FileError& e) {
        const std::string what = e.what();
        EXPECT_EQ(what.rfind(path + ": ", 0), 0u) << what;
        EXPECT_EQ(what.find('\n'), std::string::npos) << what;
        EXPECT_LT(what.size(), 400u) << what;
    }
}

std::string write_temp(const std::string& dir, const std::string& name, const std::string& content)
{
    const std::string path = dir + "/" + name;
    std::ofstream(path, std::ios::binary) << content;
    return path;
}

/// The first `n` frames of leap-pinch as a JSON document to edit (null when it is missing:
/// the test has failed).
nlohmann::json leap_excerpt(std::size_t n)
{
    const std::string path = test::shared_data("data/real/leap-pinch.json");
    if (path.empty()) return nullptr;
    nlohmann::json doc = nlohmann::json::parse(read_text(path));
    doc["frames"].erase(doc["frames"].begin() + static_cast<std::ptrdiff_t>(n), doc["frames"].end());
    return doc;
}

// ---- A tiny synthetic WebXR capture ----------------------------------------------------

constexpr const char* kWebxrSchema =
    "schema:[[0,{handedness:'left',targetRayMode:'tracked-pointer',hasGrip:!0,hasHand:!1,hasGamepad:!0}],"
    "[1,{handedness:'right',targetRayMode:'tracked-pointer',profiles:['oculus-hand'],hasGrip:!0,hasHand:!0,"
    "hasGamepad:!0,jointSequence:['wrist','thumb-metacarpal','thumb-phalanx-proximal','thumb-phalanx-distal',"
    "'thumb-tip','index-finger-metacarpal','index-finger-phalanx-proximal','index-finger-phalanx-intermediate',"
    "'index-finger-phalanx-distal','index-finger-tip','middle-finger-metacarpal','middle-finger-phalanx-proximal',"
    "'middle-finger-phalanx-intermediate','middle-finger-phalanx-distal','middle-finger-tip',"
    "'ring-finger-metacarpal','ring-finger-phalanx-proximal','ring-finger-phalanx-intermediate',"
    "'ring-finger-phalanx-distal','ring-finger-tip','pinky-finger-metacarpal','pinky-finger-phalanx-proximal',"
    "'pinky-finger-phalanx-intermediate','pinky-finger-phalanx-distal','pinky-finger-tip'],"
    "mapping:'xr-standard',numButtons:1,numAxes:0}]]";

/// A flat right hand relative to its target ray: fingers along -Z, identity orientations.
/// `zero_quat_slot` (0..24) gets an all-zero quaternion.
std::string webxr_joints(int zero_quat_slot = -1)
{
    std::string out = "[";
    for (int slot = 0; slot < 25; ++slot) {
        float x = 0, z = 0;
        if (slot > 0) {
            const int finger = (slot - 1) < 4 ? 0 : 1 + (slot - 5) / 5;
            const int k = finger == 0 ? slot - 1 : (slot - 5) % 5;
            x = -0.04f + 0.02f * static_cast<float>(finger);
            z = -0.03f - 0.025f * static_cast<float>(k);
        }
        const char* q = slot == zero_quat_slot ? "0,0,0,0" : "0,0,0,1";
        if (slot > 0) out += ',';
        out += std::to_string(x);
        out += ",0,";
        out += std::to_string(z);
        out += ',';
        out += q;
        out += ",0.01";
    }
    return out + "]";
}

std::string webxr_row(double t_ms, const std::string& joints)
{
    return "[" + std::to_string(t_ms) + ",0,1.6,0,0,0,0,1,[0,0.1,1,-0.3,0,0,0,1,[0,0,0,0,0,0,1],[0]]," +
           "[1,0.2,1.1,-0.3,0,0,0,1,[0,0,0,0,0,0,1]," + joints + ",[[0,0,0]]]]";
}

std::string webxr_capture(const std::vector<std::string>& rows)
{
    std::string frames;
    for (std::size_t i = 0; i < rows.size(); ++i) frames += (i ? "," : "") + rows[i];
    return std::string("var a={") + kWebxrSchema + ",frames:[" + frames + "]};export{a as capture};";
}

} // namespace

// ---- Leap Motion -----------------------------------------------------------------------

TEST(ImportLeap, PinchClipGives307RightHandFramesFromTimeZeroAt115Hz)
{
    const std::string path = test::shared_data("data/real/leap-pinch.json");
    if (path.empty()) return;
    ReadReport report;
    const Recording rec = import_leap_json(path, &report);
    ASSERT_EQ(rec.frames.size(), 307u);
    EXPECT_EQ(report.frames_read, 307u);
    EXPECT_EQ(report.frames_dropped, 0u);
    EXPECT_TRUE(report.problems.empty()) << report.problems.front();
    EXPECT_EQ(rec.header.source, "import-leap");
    EXPECT_EQ(rec.header.device, "Leap Motion");
    EXPECT_EQ(rec.header.units, "m");
    EXPECT_NEAR(rec.header.nominal_rate_hz, 115.0, 2.0);
    EXPECT_EQ(rec.frames.front().time, 0.0);
    for (std::size_t i = 0; i < rec.frames.size(); ++i) {
        EXPECT_TRUE(right(rec.frames[i]).active) << i;
        EXPECT_FALSE(rec.frames[i].hand(Hand::Left).active) << i;
        if (i > 0) {
            EXPECT_GT(rec.frames[i].time, rec.frames[i - 1].time) << i;
        }
    }
    EXPECT_NEAR(rec.frames.back().time, 2.69, 0.02);
}

TEST(ImportLeap, DevicePlacementPutsHandsAtDeskHeightInFrontOfTheUser)
{
    const Recording* pinch = leap_pinch();
    if (!pinch) return;
    for (const HandFrame& f : pinch->frames) {
        const glm::vec3 palm = at(right(f), Joint::Palm);
        EXPECT_GT(palm.y, kLeapDeviceOrigin.y + 0.05f);
        EXPECT_LT(palm.y, kLeapDeviceOrigin.y + 0.5f);
        EXPECT_LT(std::abs(palm.z - kLeapDeviceOrigin.z), 0.3f);
    }
}

TEST(ImportLeap, PinchGapClosesBelow5mmAndIsWideOpenAtStartAndEnd)
{
    const Recording* pinch = leap_pinch();
    if (!pinch) return;
    const auto& frames = pinch->frames;
    float closest = 1.0f;
    for (const HandFrame& f : frames) closest = std::min(closest, pinch_gap(right(f)));
    EXPECT_LT(closest, 0.005f);
    EXPECT_GT(pinch_gap(right(frames.front())), 0.030f);
    EXPECT_GT(pinch_gap(right(frames.back())), 0.030f);
}

TEST(ImportLeap, GrabCurlsMiddleRingLittleWhileThePinchKeepsThemStraight)
{
    const Recording* grab = leap_grab();
    if (!grab) return;
    const Recording* pinch = leap_pinch();
    if (!pinch) return;
    // Grab: the most closed frames have all three fingers strongly curled.
    std::size_t curled = 0;
    float most = 0.0f;
    for (const HandFrame& f : grab->frames) {
        const float c = min_curl_mrl(right(f));
        most = std::max(most, c);
        if (c > 0.35f) ++curled;
    }
    EXPECT_GT(most, 0.45f);
    EXPECT_GE(curled, 20u);
    // Pinch: while the thumb and index touch, the other fingers stay nearly straight.
    std::size_t pinching = 0;
    for (const HandFrame& f : pinch->frames) {
        if (pinch_gap(right(f)) > 0.005f) continue;
        ++pinching;
        EXPECT_LT(max_curl_mrl(right(f)), 0.2f);
    }
    EXPECT_GE(pinching, 20u);
}

TEST(ImportLeap, BoneLengthsArePlausibleAndConstantOverTheClip)
{
    struct Bone {
        Joint a, b;
        float min_m, max_m;
    };
    const Bone bones[] = {
        {Joint::IndexProximal, Joint::IndexIntermediate, 0.030f, 0.060f},
        {Joint::IndexIntermediate, Joint::IndexDistal, 0.015f, 0.040f},
        {Joint::IndexDistal, Joint::IndexTip, 0.010f, 0.030f},
        {Joint::IndexMetacarpal, Joint::IndexProximal, 0.040f, 0.090f},
        {Joint::MiddleProximal, Joint::MiddleIntermediate, 0.030f, 0.065f},
        {Joint::LittleProximal, Joint::LittleIntermediate, 0.020f, 0.050f},
        {Joint::ThumbMetacarpal, Joint::ThumbProximal, 0.025f, 0.060f},
        {Joint::ThumbDistal, Joint::ThumbTip, 0.012f, 0.035f},
        {Joint::Wrist, Joint::MiddleProximal, 0.070f, 0.130f},
    };
    const Recording* pinch = leap_pinch();
    if (!pinch) return;
    const Recording* grab = leap_grab();
    if (!grab) return;
    for (const Recording* rec : {pinch, grab}) {
        for (const Bone& bone : bones) {
            float lo = 1.0f, hi = 0.0f;
            for (const HandFrame& f : rec->frames) {
                const float len = glm::distance(at(right(f), bone.a), at(right(f), bone.b));
                lo = std::min(lo, len);
                hi = std::max(hi, len);
            }
            EXPECT_GE(lo, bone.min_m) << joint_name(bone.a) << " → " << joint_name(bone.b);
            EXPECT_LE(hi, bone.max_m) << joint_name(bone.a) << " → " << joint_name(bone.b);
            EXPECT_LT(hi - lo, 0.003f) << joint_name(bone.a) << " → " << joint_name(bone.b);
        }
    }
}

TEST(ImportLeap, OrientationsAreUnitAndPointAlongTheBonesTowardsTheTip)
{
    const Recording* pinch = leap_pinch();
    if (!pinch) return;
    const Recording* grab = leap_grab();
    if (!grab) return;
    for (const Recording* rec : {pinch, grab}) {
        for (const HandFrame& f : rec->frames) {
            const HandState& h = right(f);
            EXPECT_GT(worst_bone_alignment(h), 0.9f);
            // The palm and wrist point along the hand, towards the middle knuckle.
            const glm::vec3 knuckle = at(h, Joint::MiddleProximal);
            for (Joint j : {Joint::Palm, Joint::Wrist}) {
                const glm::vec3 minus_z = h[j].pose.orientation * glm::vec3(0.0f, 0.0f, -1.0f);
                EXPECT_GT(glm::dot(minus_z, glm::normalize(knuckle - at(h, j))), 0.9f) << joint_name(j);
            }
        }
    }
}

TEST(ImportLeap, BackOfTheHandIsPlusYOppositeThePalmNormal)
{
    // Frame 0 of leap-pinch: palmNormal = (0.021, -0.690, -0.724).
    const glm::vec3 palm_normal(0.0210362f, -0.689633f, -0.723854f);
    const Recording* pinch = leap_pinch();
    if (!pinch) return;
    const HandState& h = right(pinch->frames.front());
    const glm::vec3 plus_y = h[Joint::Palm].pose.orientation * glm::vec3(0.0f, 1.0f, 0.0f);
    EXPECT_LT(glm::dot(plus_y, palm_normal), -0.99f);
}

TEST(ImportLeap, SourceJointsAreTrackedAndDerivedJointsOnlyValid)
{
    const Recording* pinch = leap_pinch();
    if (!pinch) return;
    const HandState& h = right(pinch->frames[100]);
    EXPECT_EQ(h[Joint::Palm].flags, kAllJointFlags);
    EXPECT_EQ(h[Joint::Wrist].flags, kDerivedJointFlags);
    for (Joint j : {Joint::IndexMetacarpal, Joint::MiddleMetacarpal, Joint::RingMetacarpal, Joint::LittleMetacarpal})
        EXPECT_EQ(h[j].flags, kDerivedJointFlags) << joint_name(j);
    for (Joint j : {Joint::ThumbMetacarpal, Joint::ThumbTip, Joint::IndexProximal, Joint::LittleTip})
        EXPECT_EQ(h[j].flags, kAllJointFlags) << joint_name(j);
}

TEST(ImportLeap, RadiiComeFromFingerWidthAndTaperTowardsTheTip)
{
    const Recording* pinch = leap_pinch();
    if (!pinch) return;
    const HandState& h = right(pinch->frames.front());
    // Index width is 18.8 mm in this clip.
    EXPECT_NEAR(h[Joint::IndexProximal].radius, 0.0094f, 0.0005f);
    EXPECT_LT(h[Joint::IndexTip].radius, h[Joint::IndexIntermediate].radius);
    EXPECT_LT(h[Joint::IndexIntermediate].radius, h[Joint::IndexProximal].radius);
    for (const JointState& j : h.joints) {
        EXPECT_GT(j.radius, 0.004f);
        EXPECT_LT(j.radius, 0.025f);
    }
}

TEST(ImportLeap, DropsNonFiniteAbsurdAndBackwardFramesWithReasons)
{
    nlohmann::json doc = leap_excerpt(30);
    if (doc.is_null()) return;
    auto& frames = doc["frames"];
    frames[5]["hands"][0]["palmPosition"][0] = 123456.75; // becomes 1e999 below
    frames[8]["pointables"][1]["tipPosition"][1] = 5.0e7;  // 50 km
    frames[12]["timestamp"] = frames[11]["timestamp"].get<double>() - 1000.0;
    std::string text = doc.dump();
    const std::size_t at_pos = text.find("123456.75");
    ASSERT_NE(at_pos, std::string::npos);
    text.replace(at_pos, 9, "1e999");

    ReadReport report;
    const Recording rec = import_leap_json_text(text, "edited.json", &report);
    EXPECT_EQ(rec.frames.size(), 27u);
    EXPECT_EQ(report.frames_dropped, 3u);
    ASSERT_EQ(report.problems.size(), 3u);
    EXPECT_NE(report.problems[0].find("frame 5"), std::string::npos) << report.problems[0];
    EXPECT_NE(report.problems[1].find("frame 8"), std::string::npos) << report.problems[1];
    EXPECT_NE(report.problems[2].find("backwards"), std::string::npos) << report.problems[2];
    for (std::size_t i = 1; i < rec.frames.size(); ++i) EXPECT_GT(rec.frames[i].time, rec.frames[i - 1].time);
}

TEST(ImportLeap, ProblemListStaysBoundedWithACount)
{
    nlohmann::json doc = leap_excerpt(100);
    if (doc.is_null()) return;
    for (std::size_t i = 1; i < 100; ++i) doc["frames"][i]["timestamp"] = 1.0; // all go backwards
    ReadReport report;
    const Recording rec = import_leap_json_text(doc.dump(), "backwards.json", &report);
    EXPECT_EQ(rec.frames.size(), 1u);
    EXPECT_EQ(report.frames_dropped, 99u);
    ASSERT_EQ(report.problems.size(), kMaxReportedProblems + 1);
    EXPECT_NE(report.problems.back().find("79 more"), std::string::npos) << report.problems.back();
}

TEST(ImportLeap, MissingFieldMakesThatHandInactiveInThatFrameOnly)
{
    nlohmann::json doc = leap_excerpt(10);
    if (doc.is_null()) return;
    doc["frames"][4]["hands"][0].erase("palmNormal");
    doc["frames"][6]["pointables"][2]["tipPosition"][0] = "12.5"; // a string, not a number
    ReadReport report;
    const Recording rec = import_leap_json_text(doc.dump(), "missing.json", &report);
    ASSERT_EQ(rec.frames.size(), 10u);
    for (std::size_t i = 0; i < 10; ++i) EXPECT_EQ(right(rec.frames[i]).active, i != 4 && i != 6) << i;
    ASSERT_EQ(report.problems.size(), 2u);
    EXPECT_NE(report.problems[0].find("palmNormal"), std::string::npos) << report.problems[0];
    EXPECT_NE(report.problems[1].find("middle tipPosition"), std::string::npos) << report.problems[1];
}

TEST(ImportLeap, KeepsTheMoreConfidentOfTwoHandsOfTheSameType)
{
    for (const double other_confidence : {0.2, 1.0}) {
        nlohmann::json doc = leap_excerpt(3);
        if (doc.is_null()) return;
        nlohmann::json& frame = doc["frames"][1];
        nlohmann::json twin = frame["hands"][0];
        twin["id"] = 99;
        twin["confidence"] = other_confidence;
        frame["hands"][0]["confidence"] = 0.6;
        for (int i = 0; i < 3; ++i) twin["palmPosition"][i] = twin["palmPosition"][i].get<double>() + 100.0;
        frame["hands"].push_back(twin);
        const nlohmann::json pointables = frame["pointables"];
        for (nlohmann::json p : pointables) {
            p["handId"] = 99;
            for (const char* key : {"mcpPosition", "pipPosition", "dipPosition", "tipPosition"})
                for (int i = 0; i < 3; ++i) p[key][i] = p[key][i].get<double>() + 100.0;
            frame["pointables"].push_back(p);
        }
        ReadReport report;
        const Recording rec = import_leap_json_text(doc.dump(), "twins.json", &report);
        ASSERT_EQ(rec.frames.size(), 3u);
        const float shift = glm::distance(at(right(rec.frames[1]), Joint::Palm), at(right(rec.frames[0]), Joint::Palm));
        if (other_confidence > 0.6) {
            EXPECT_GT(shift, 0.15f);
        } else {
            EXPECT_LT(shift, 0.01f);
        }
        EXPECT_FALSE(rec.frames[1].hand(Hand::Left).active);
        EXPECT_EQ(report.problems.size(), 1u);
    }
}

TEST(ImportLeap, FramesWithoutHandsAreKeptWithBothHandsInactive)
{
    nlohmann::json doc = leap_excerpt(5);
    if (doc.is_null()) return;
    doc["frames"][2]["hands"] = nlohmann::json::array();
    doc["frames"][2]["pointables"] = nlohmann::json::array();
    ReadReport report;
    const Recording rec = import_leap_json_text(doc.dump(), "gap.json", &report);
    ASSERT_EQ(rec.frames.size(), 5u);
    EXPECT_FALSE(right(rec.frames[2]).active);
    EXPECT_FALSE(rec.frames[2].hand(Hand::Left).active);
    EXPECT_TRUE(report.problems.empty());
}

TEST(ImportLeap, TruncatedFileKeepsEveryCompleteFrame)
{
    const std::string path = test::shared_data("data/real/leap-pinch.json");
    if (path.empty()) return;
    const std::string text = read_text(path);
    ReadReport report;
    const Recording rec = import_leap_json_text(text.substr(0, text.size() / 2), "half.json", &report);
    EXPECT_GT(rec.frames.size(), 140u);
    EXPECT_LT(rec.frames.size(), 170u);
    ASSERT_FALSE(report.problems.empty());
    EXPECT_NE(report.problems.back().find("end early"), std::string::npos) << report.problems.back();
}

TEST(ImportLeap, GarbageGivesAOneLineFileErrorNamingTheFile)
{
    const std::string pinch_path = test::shared_data("data/real/leap-pinch.json");
    if (pinch_path.empty()) return;
    const std::string dir = test::temp_dir("import-leap-garbage");
    const std::string pinch = read_text(pinch_path);
    nlohmann::json one = leap_excerpt(1);
    one["frames"][0]["pointables"][1]["tipPosition"][0] = "oops";
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"empty.json", ""},
        {"empty-object.json", "{}"},
        {"truncated.json", pinch.substr(0, 1500)},
        {"frames-number.json", "{\"frames\": 5}"},
        {"frames-object.json", "{\"frames\": {\"a\": 1}}"},
        {"frames-empty.json", "{\"frames\": []}"},
        {"frames-strings.json", "{\"frames\": [\"a\", \"b\"]}"},
        {"pointable-string.json", one.dump()},
        {"deep.json", "{\"frames\":" + std::string(100000, '[') + std::string(100000, ']') + "}"},
        {"deep-open.json", "{\"frames\":[" + std::string(100000, '[')},
        {"deep-object.json", "{\"frames\":[" + [] {
             std::string s;
             for (int i = 0; i < 100000; ++i) s += "{\"a\":";
             return s;
         }()},
        {"binary.json", std::string("\x00\xff{\x01\"frames\x00", 12)},
        {"not-json.json", "this is not a Leap recording"},
    };
    for (const auto& [name, content] : cases) {
        SCOPED_TRACE(name);
        const std::string path = write_temp(dir, name, content);
        expect_one_line_file_error([&] { import_leap_json(path); }, path);
    }
    expect_one_line_file_error([&] { import_leap_json(dir + "/missing.json"); }, dir + "/missing.json");
}

// ---- WebXR -----------------------------------------------------------------------------

TEST(ImportWebxr, QuestCaptureGives1796FramesWithBothHandsForHundredsOfFrames)
{
    const std::string path = test::shared_data("data/real/quest3-webxr-capture.min.js");
    if (path.empty()) return;
    ReadReport report;
    const Recording rec = import_webxr_capture(path, &report);
    ASSERT_EQ(rec.frames.size(), 1796u);
    EXPECT_EQ(report.frames_dropped, 0u);
    // Only the controller note.
    ASSERT_EQ(report.problems.size(), 1u);
    EXPECT_NE(report.problems[0].find("controllers"), std::string::npos) << report.problems[0];
    EXPECT_EQ(rec.header.source, "import-webxr");
    EXPECT_EQ(rec.header.device, "Meta Quest 3 (WebXR)");
    EXPECT_NEAR(rec.header.nominal_rate_hz, 90.0, 3.0);
    EXPECT_EQ(rec.frames.front().time, 0.0);
    EXPECT_NEAR(rec.frames.back().time, 20.07, 0.01);
    std::size_t left = 0, right_n = 0, both = 0;
    for (std::size_t i = 0; i < rec.frames.size(); ++i) {
        const HandFrame& f = rec.frames[i];
        EXPECT_TRUE(f.head_valid);
        if (i > 0) {
            EXPECT_GT(f.time, rec.frames[i - 1].time);
        }
        left += f.hand(Hand::Left).active;
        right_n += f.hand(Hand::Right).active;
        both += f.hand(Hand::Left).active && f.hand(Hand::Right).active;
    }
    EXPECT_EQ(left, 667u);
    EXPECT_EQ(right_n, 756u);
    EXPECT_EQ(both, 666u);
}

TEST(ImportWebxr, JointsStayNearTheHeadAndPalmsLieBetweenWristAndKnuckles)
{
    const Recording* capture = webxr();
    if (!capture) return;
    for (const HandFrame& f : capture->frames) {
        for (const HandState& h : f.hands) {
            if (!h.active) continue;
            for (const JointState& j : h.joints) {
                EXPECT_LT(glm::distance(j.pose.position, f.head.position), 1.0f);
                EXPECT_GE(j.radius, 0.004f);
                EXPECT_LE(j.radius, 0.025f);
            }
            const glm::vec3 wrist = at(h, Joint::Wrist);
            const glm::vec3 axis = at(h, Joint::MiddleProximal) - wrist;
            const float s = glm::dot(at(h, Joint::Palm) - wrist, axis) / glm::dot(axis, axis);
            EXPECT_GT(s, 0.4f);
            EXPECT_LT(s, 0.95f);
            EXPECT_LT(glm::length(at(h, Joint::Palm) - (wrist + s * axis)), 0.02f);
            EXPECT_EQ(h[Joint::Palm].flags, kDerivedJointFlags);
            EXPECT_EQ(h[Joint::IndexTip].flags, kAllJointFlags);
        }
    }
}

TEST(ImportWebxr, OrientationsAreUnitAndPointAlongTheBonesTowardsTheTip)
{
    const Recording* capture = webxr();
    if (!capture) return;
    for (const HandFrame& f : capture->frames)
        for (const HandState& h : f.hands)
            if (h.active) {
                EXPECT_GT(worst_bone_alignment(h), 0.9f);
            }
}

TEST(ImportWebxr, ThumbAndIndexTipsTouchWhenPinching)
{
    const Recording* capture = webxr();
    if (!capture) return;
    float closest = 1.0f;
    for (const HandFrame& f : capture->frames)
        for (const HandState& h : f.hands)
            if (h.active) closest = std::min(closest, pinch_gap(h));
    EXPECT_LT(closest, 0.01f);
}

TEST(ImportWebxr, ComposesJointsWithTheTargetRayPose)
{
    ReadReport report;
    const Recording rec = import_webxr_capture_text(webxr_capture({webxr_row(1000.0, webxr_joints())}), "one.js", &report);
    ASSERT_EQ(rec.frames.size(), 1u);
    const HandState& h = right(rec.frames[0]);
    ASSERT_TRUE(h.active);
    EXPECT_FALSE(rec.frames[0].hand(Hand::Left).active); // input 0 is a controller
    // Target ray at (0.2, 1.1, -0.3) with identity orientation; wrist at its origin.
    EXPECT_NEAR(glm::distance(at(h, Joint::Wrist), glm::vec3(0.2f, 1.1f, -0.3f)), 0.0f, 1e-5f);
    EXPECT_NEAR(glm::distance(at(h, Joint::IndexTip), glm::vec3(0.18f, 1.1f, -0.43f)), 0.0f, 1e-5f);
    EXPECT_NEAR(h[Joint::IndexTip].radius, 0.01f, 1e-6f);
    EXPECT_NEAR(glm::distance(rec.frames[0].head.position, glm::vec3(0.0f, 1.6f, 0.0f)), 0.0f, 1e-6f);
}

TEST(ImportWebxr, ZeroQuaternionBecomesIdentityWithOrientationInvalid)
{
    ReadReport report;
    const Recording rec = import_webxr_capture_text(
        webxr_capture({webxr_row(0.0, webxr_joints(9)), webxr_row(11.0, webxr_joints())}), "zero.js", &report);
    ASSERT_EQ(rec.frames.size(), 2u);
    const JointState& tip = right(rec.frames[0])[Joint::IndexTip];
    EXPECT_EQ(tip.flags, kPositionValid | kPositionTracked);
    EXPECT_EQ(tip.pose.orientation, glm::quat(1.0f, 0.0f, 0.0f, 0.0f));
    EXPECT_EQ(right(rec.frames[1])[Joint::IndexTip].flags, kAllJointFlags);
    bool mentioned = false;
    for (const std::string& p : report.problems) mentioned |= p.find("zero quaternion") != std::string::npos;
    EXPECT_TRUE(mentioned);
}

TEST(ImportWebxr, DropsBackwardAndNonFiniteFramesAndInactivatesBrokenHands)
{
    std::string nan_joints = webxr_joints();
    nan_joints.replace(1, nan_joints.find(',') - 1, "NaN");
    std::string short_joints = "[0,0,0,0,0,0,1,0.01]"; // one joint instead of 25
    ReadReport report;
    const Recording rec = import_webxr_capture_text(
        webxr_capture({webxr_row(0.0, webxr_joints()), webxr_row(11.0, webxr_joints()),
                       webxr_row(5.0, webxr_joints()), // backwards
                       "[22,0,NaN,0,0,0,0,1]",            // non-finite head
                       webxr_row(33.0, short_joints), webxr_row(40.0, nan_joints), webxr_row(44.0, webxr_joints())}),
        "broken.js", &report);
    ASSERT_EQ(rec.frames.size(), 4u);
    EXPECT_EQ(report.frames_dropped, 3u);
    EXPECT_TRUE(right(rec.frames[1]).active);
    EXPECT_FALSE(right(rec.frames[2]).active);
    EXPECT_TRUE(right(rec.frames[3]).active);
    EXPECT_NEAR(rec.frames[3].time, 0.044, 1e-9);
}

TEST(ImportWebxr, GarbageGivesAOneLineFileErrorNamingTheFile)
{
    const std::string capture_path = test::shared_data("data/real/quest3-webxr-capture.min.js");
    if (capture_path.empty()) return;
    const std::string leap_path = test::shared_data("data/real/leap-pinch.json");
    if (leap_path.empty()) return;
    const std::string dir = test::temp_dir("import-webxr-garbage");
    const std::string capture = read_text(capture_path);
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"empty.js", ""},
        {"no-object.js", "export{a as capture};"},
        {"empty-object.js", "var a={};export{a as capture};"},
        {"no-frames.js", std::string("var a={") + kWebxrSchema + "};export{a as capture};"},
        {"frames-number.js", std::string("var a={") + kWebxrSchema + ",frames:7};"},
        {"frames-empty.js", std::string("var a={") + kWebxrSchema + ",frames:[]};"},
        {"controllers-only.js",
         "var a={schema:[[0,{handedness:'left',hasHand:!1}]],frames:[[0,0,1,0,0,0,0,1,[0,0,0,0,0,0,0,1]]]};"},
        {"schema-truncated.js", capture.substr(0, 1000)},
        {"frames-truncated.js", capture.substr(0, 4000)},
        {"deep-schema.js", "var a={schema:" + std::string(100000, '[')},
        {"deep-frames.js", std::string("var a={") + kWebxrSchema + ",frames:" + std::string(100000, '[') +
                               std::string(100000, ']') + "};"},
        {"bad-strings.js", "var a={schema:[[0,{handedness:'left\\u12"},
        {"leap.js", read_text(leap_path).substr(0, 5000)},
    };
    for (const auto& [name, content] : cases) {
        SCOPED_TRACE(name);
        const std::string path = write_temp(dir, name, content);
        expect_one_line_file_error([&] { import_webxr_capture(path); }, path);
    }
}

TEST(ImportWebxr, TruncatedCaptureKeepsEveryCompleteFrame)
{
    const Recording* capture = webxr();
    if (!capture) return;
    const std::string text = read_text(test::shared_data("data/real/quest3-webxr-capture.min.js"));
    ReadReport report;
    const Recording rec = import_webxr_capture_text(text.substr(0, text.size() / 2), "half.js", &report);
    ASSERT_GT(rec.frames.size(), 500u);
    ASSERT_LT(rec.frames.size(), capture->frames.size());
    const std::size_t last = rec.frames.size() - 1;
    EXPECT_EQ(rec.frames[last].time, capture->frames[last].time);
    EXPECT_EQ(at(right(rec.frames[last]), Joint::IndexTip), at(right(capture->frames[last]), Joint::IndexTip));
    ASSERT_FALSE(report.problems.empty());
    EXPECT_NE(report.problems.back().find("end early"), std::string::npos) << report.problems.back();
}

// ---- Literal reader --------------------------------------------------------------------

TEST(ImportLiteralReader, ReadsJsObjectLiteralsAsJson)
{
    const std::string text = "{a:'x\\'y',\"b\":[!0,!1,void 0,null,-1.5e3,.25,NaN,-Infinity],c:{d:[]},}";
    std::size_t pos = 0;
    const nlohmann::json v = parse_literal(text, pos);
    EXPECT_EQ(pos, text.size());
    EXPECT_EQ(v["a"], "x'y");
    EXPECT_EQ(v["b"][0], true);
    EXPECT_EQ(v["b"][1], false);
    EXPECT_TRUE(v["b"][2].is_null());
    EXPECT_DOUBLE_EQ(v["b"][4].get<double>(), -1500.0);
    EXPECT_DOUBLE_EQ(v["b"][5].get<double>(), 0.25);
    EXPECT_TRUE(std::isnan(v["b"][6].get<double>()));
    EXPECT_TRUE(std::isinf(v["b"][7].get<double>()));
    EXPECT_TRUE(v["c"]["d"].is_array());
}

TEST(ImportLiteralReader, RejectsDeepNestingWithoutRecursingIntoIt)
{
    const std::string deep = std::string(100000, '[') + std::string(100000, ']');
    std::size_t pos = 0;
    EXPECT_THROW((void)parse_literal(deep, pos), LiteralError);
    pos = 0;
    EXPECT_THROW(skip_literal(deep, pos), LiteralError);
    const std::string ok = std::string(kMaxLiteralDepth, '[') + std::string(kMaxLiteralDepth, ']');
    pos = 0;
    EXPECT_NO_THROW((void)parse_literal(ok, pos));
}

// ---- Round trip through the recording format -------------------------------------------

TEST(ImportRoundTrip, BothCapturesSurviveBinaryWriteAndRead)
{
    const Recording* pinch = leap_pinch();
    if (!pinch) return;
    const Recording* capture = webxr();
    if (!capture) return;
    const std::string dir = test::temp_dir("import-roundtrip");
    for (const Recording* rec : {pinch, capture}) {
        const std::string path = dir + "/" + rec->header.source + ".lrec";
        write_recording_binary(path, *rec);
        ReadReport report;
        const Recording back = read_recording(path, &report);
        EXPECT_EQ(report.frames_dropped, 0u);
        EXPECT_EQ(back.header.source, rec->header.source);
        EXPECT_EQ(back.header.device, rec->header.device);
        EXPECT_NEAR(back.header.nominal_rate_hz, rec->header.nominal_rate_hz, 1e-6);
        ASSERT_EQ(back.frames.size(), rec->frames.size());
        for (std::size_t i = 0; i < back.frames.size(); ++i) {
            const HandFrame& a = rec->frames[i];
            const HandFrame& b = back.frames[i];
            EXPECT_NEAR(a.time, b.time, 1e-9);
            EXPECT_EQ(a.head_valid, b.head_valid);
            for (int s = 0; s < kHandCount; ++s) {
                ASSERT_EQ(a.hands[s].active, b.hands[s].active) << i;
                if (!a.hands[s].active) continue;
                for (int j = 0; j < kJointCount; ++j) {
                    const JointState& ja = a.hands[s].joints[j];
                    const JointState& jb = b.hands[s].joints[j];
                    EXPECT_LT(glm::distance(ja.pose.position, jb.pose.position), 1e-5f);
                    EXPECT_GT(std::abs(glm::dot(ja.pose.orientation, jb.pose.orientation)), 0.9999f);
                    EXPECT_NEAR(ja.radius, jb.radius, 1e-5f);
                    EXPECT_EQ(ja.flags, jb.flags);
                }
            }
        }
    }
}
