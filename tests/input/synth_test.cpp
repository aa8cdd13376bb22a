// Synthetic recordings (input/synth.h): determinism, the shipped scenarios, and that the
// frames look like real tracking (pinch gaps, curls, speeds, jitter, tremor, drop-outs).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstring>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include "core/errors.h"
#include "input/synth.h"
#include "input/tools.h"
#include "tests/support/expect_throw.h"
#include "tests/support/shapes.h"
#include "tests/support/test_data.h"
#include "tests/support/test_paths.h"

using namespace lobe;
using json = nlohmann::json;
using lobe::test::invalid_input_message;

namespace {

constexpr double kPi = 3.14159265358979323846;

struct Shipped {
    const char* file;
    int lobe_strokes;
    int trunk_strokes;
    int drags;
    std::vector<int> lobe_strokes_per_lobe; ///< one lobe surface each
};
const Shipped kShipped[] = {
    {"recordings/table1-1lobe-5strokes.scenario.json", 5, 3, 0, {5}},
    {"recordings/table1-4lobes-22strokes.scenario.json", 22, 4, 0, {6, 5, 6, 5}},
    {"recordings/table1-3lobes-16strokes.scenario.json", 16, 3, 0, {6, 5, 5}},
    {"recordings/pinch-edit.scenario.json", 5, 0, 2, {5}},
    {"recordings/edit-stroke-transform.scenario.json", 5, 0, 4, {}},
};

/// Each shipped scenario synthesized once per test run; null when its file is missing (the
/// test has then failed with one line).
const SynthResult* shipped(const std::string& file)
{
    const std::string path = test::source_data(file);
    if (path.empty()) return nullptr;
    static std::map<std::string, SynthResult> cache;
    auto it = cache.find(file);
    if (it == cache.end()) it = cache.emplace(file, synthesize(load_scenario(path))).first;
    return &it->second;
}

bool tracked(const HandState& h)
{
    if (!h.active) return false;
    for (const JointState& j : h.joints)
        if (j.flags != kAllJointFlags) return false;
    return true;
}

glm::vec3 pos(const HandState& h, Joint j) { return h[j].pose.position; }

double pinch_gap(const HandState& h)
{
    return glm::distance(pos(h, Joint::ThumbTip), pos(h, Joint::IndexTip)) - h[Joint::ThumbTip].radius -
           h[Joint::IndexTip].radius;
}

/// 1 − |tip − proximal| / chain length, for index (1) … little (4).
double curl(const HandState& h, int finger)
{
    const int j0 = idx(Joint::IndexMetacarpal) + 5 * (finger - 1);
    auto p = [&](int j) { return h.joints[static_cast<std::size_t>(j)].pose.position; };
    double chain = glm::distance(p(j0 + 1), p(j0 + 2)) + glm::distance(p(j0 + 2), p(j0 + 3)) +
                   glm::distance(p(j0 + 3), p(j0 + 4));
    return 1.0 - glm::distance(p(j0 + 1), p(j0 + 4)) / chain;
}

double min_curl_mrl(const HandState& h) { return std::min({curl(h, 2), curl(h, 3), curl(h, 4)}); }
double max_curl_mrl(const HandState& h) { return std::max({curl(h, 2), curl(h, 3), curl(h, 4)}); }

double distance_to_polyline(const glm::vec3& p, const std::vector<glm::vec3>& c)
{
    double best = 1e9;
    for (std::size_t i = 1; i < c.size(); ++i) {
        glm::vec3 ab = c[i] - c[i - 1];
        float len2 = glm::dot(ab, ab);
        float u = len2 > 0.0f ? std::clamp(glm::dot(p - c[i - 1], ab) / len2, 0.0f, 1.0f) : 0.0f;
        best = std::min(best, static_cast<double>(glm::distance(p, c[i - 1] + u * ab)));
    }
    return best;
}

bool in_span(double t, const SynthSpan& s, double margin) { return t >= s.t_begin - margin && t <= s.t_end + margin; }

/// Same bits, field by field (HandFrame has padding, so no memcmp of whole frames).
template <typename T>
bool same_bits(const T& a, const T& b)
{
    return std::memcmp(&a, &b, sizeof(T)) == 0;
}

bool identical(const HandFrame& a, const HandFrame& b)
{
    if (!same_bits(a.time, b.time) || a.head_valid != b.head_valid || !same_bits(a.head.position, b.head.position) ||
        !same_bits(a.head.orientation, b.head.orientation))
        return false;
    for (int h = 0; h < kHandCount; ++h) {
        const HandState& x = a.hands[static_cast<std::size_t>(h)];
        const HandState& y = b.hands[static_cast<std::size_t>(h)];
        if (x.active != y.active) return false;
        for (int j = 0; j < kJointCount; ++j) {
            const JointState& p = x.joints[static_cast<std::size_t>(j)];
            const JointState& q = y.joints[static_cast<std::size_t>(j)];
            if (!same_bits(p.pose.position, q.pose.position) || !same_bits(p.pose.orientation, q.pose.orientation) ||
                !same_bits(p.radius, q.radius) || p.flags != q.flags)
                return false;
        }
    }
    return true;
}

json minimal_scenario()
{
    return json{{"format", "lobesketch-scenario"},
                {"version", 1},
                {"name", "minimal"},
                {"seed", 7},
                {"steps", json::array({json{{"type", "stroke"},
                                            {"kind", "lobe"},
                                            {"curve", json::array({json::array({0.0, 1.3, -0.4}),
                                                                   json::array({0.1, 1.35, -0.4}),
                                                                   json::array({0.2, 1.3, -0.4})})}}})}};
}

Scenario idle_scenario(double seconds)
{
    Scenario s;
    s.name = "idle";
    s.seed = 99;
    s.dropouts = false;
    ScenarioStep pause;
    pause.type = ScenarioStep::Type::Pause;
    pause.duration_s = seconds;
    s.steps.push_back(pause);
    return s;
}

/// Index tip of one hand minus its centred moving average over `window` frames (odd).
std::vector<glm::dvec3> high_pass(const std::vector<glm::dvec3>& x, int window)
{
    std::vector<glm::dvec3> out;
    const int half = window / 2;
    for (int i = half; i + half < static_cast<int>(x.size()); ++i) {
        glm::dvec3 mean(0.0);
        for (int k = -half; k <= half; ++k) mean += x[static_cast<std::size_t>(i + k)];
        out.push_back(x[static_cast<std::size_t>(i)] - mean / static_cast<double>(window));
    }
    return out;
}

double rms(const std::vector<glm::dvec3>& r)
{
    double s = 0.0;
    for (const glm::dvec3& v : r) s += glm::dot(v, v);
    return std::sqrt(s / static_cast<double>(r.size()));
}

} // namespace

// ---------------------------------------------------------------------------------------
// Determinism and the shipped scenarios
// ---------------------------------------------------------------------------------------

TEST(SynthScenario, SameScenarioGivesBitIdenticalFramesTwice)
{
    const std::string path = test::source_data(kShipped[0].file);
    if (path.empty()) return;
    Scenario s = load_scenario(path);
    SynthResult a = synthesize(s);
    SynthResult b = synthesize(s);
    ASSERT_EQ(a.recording.frames.size(), b.recording.frames.size());
    for (std::size_t i = 0; i < a.recording.frames.size(); ++i)
        ASSERT_TRUE(identical(a.recording.frames[i], b.recording.frames[i])) << "frame " << i;
    ASSERT_EQ(a.recording.events.size(), b.recording.events.size());
    for (std::size_t i = 0; i < a.recording.events.size(); ++i) {
        EXPECT_TRUE(same_bits(a.recording.events[i].time, b.recording.events[i].time));
        EXPECT_EQ(a.recording.events[i].code, b.recording.events[i].code);
    }
    EXPECT_EQ(ground_truth_to_json(a.truth, a.surfaces).dump(), ground_truth_to_json(b.truth, b.surfaces).dump());

    s.seed += 1;
    SynthResult c = synthesize(s);
    EXPECT_FALSE(c.recording.frames.size() == a.recording.frames.size() &&
                 identical(c.recording.frames[100], a.recording.frames[100]))
        << "another seed should give another recording";
}

TEST(SynthScenario, EveryShippedScenarioParsesWithTheRightStrokeCounts)
{
    for (const Shipped& sc : kShipped) {
        const SynthResult* synthesized = shipped(sc.file);
        if (!synthesized) return;
        SCOPED_TRACE(sc.file);
        const SynthResult& r = *synthesized;
        int lobes = 0, trunks = 0, drags = 0;
        for (const GroundTruthStroke& g : r.truth) {
            if (g.drag) ++drags;
            else if (g.kind == StrokeKind::Lobe) ++lobes;
            else ++trunks;
            EXPECT_LT(g.t_begin, g.t_end);
            if (!g.drag) {
                // Drawable in about 1–4 s: the time between pinch and release.
                EXPECT_GE(g.t_end - g.t_begin, 1.0);
                EXPECT_LE(g.t_end - g.t_begin, 4.2);
            }
            for (std::size_t i = 1; i < g.points.size(); ++i)
                ASSERT_LE(glm::distance(g.points[i - 1], g.points[i]), 0.002f) << "ground truth is dense";
            if (g.closed) {
                EXPECT_LT(glm::distance(g.points.front(), g.points.back()), 1e-4f);
            }
        }
        EXPECT_EQ(lobes, sc.lobe_strokes);
        EXPECT_EQ(trunks, sc.trunk_strokes);
        EXPECT_EQ(drags, sc.drags);
        EXPECT_EQ(r.recording.header.source, "synth");
        EXPECT_EQ(r.recording.header.device, "synthetic hand");
        EXPECT_DOUBLE_EQ(r.recording.header.nominal_rate_hz, 90.0);
        EXPECT_GT(r.recording.frames.size(), 1000u);
    }
}

TEST(SynthScenario, ShippedStrokesAreWithinArmsReach)
{
    // Shoulders about 0.23 m below the eyes (1.61–1.69 m) and 0.18 m to the side; an arm
    // reaches about 0.7 m to the index tip.
    for (const Shipped& sc : kShipped) {
        const SynthResult* synthesized = shipped(sc.file);
        if (!synthesized) return;
        SCOPED_TRACE(sc.file);
        for (const GroundTruthStroke& g : synthesized->truth) {
            const glm::vec3 shoulder(g.hand == Hand::Right ? 0.18f : -0.18f, 1.42f, 0.02f);
            for (const glm::vec3& p : g.points) {
                ASSERT_LT(glm::distance(p, shoulder), 0.72f);
                ASSERT_LT(p.z, -0.1f) << "in front of the person";
            }
        }
    }
}

TEST(SynthScenario, KidneyLobeOfTheFourLobeTreeIsNonConvex)
{
    // Turning direction of a closed loop in its plane: a convex loop turns one way only; the
    // dented loops of the kidney lobe turn both ways.
    auto turns_both_ways = [](const GroundTruthStroke& g) {
        const auto& p = g.points;
        glm::dvec3 normal(0.0);
        for (std::size_t i = 1; i < p.size(); ++i) normal += glm::dvec3(glm::cross(p[i - 1], p[i]));
        normal = glm::normalize(normal);
        const std::size_t step = 20; // 3 cm chords, above the millimetre wobble
        int pos_turns = 0, neg_turns = 0;
        for (std::size_t i = step; i + step < p.size(); i += step / 2) {
            glm::dvec3 a = glm::dvec3(p[i] - p[i - step]), b = glm::dvec3(p[i + step] - p[i]);
            double turn = glm::dot(glm::cross(a, b), normal) / (glm::length(a) * glm::length(b));
            if (turn > 0.05) ++pos_turns;
            if (turn < -0.05) ++neg_turns;
        }
        return pos_turns > 0 && neg_turns > 0;
    };
    const SynthResult* synthesized = shipped(kShipped[1].file);
    if (!synthesized) return;
    const SynthResult& r = *synthesized;
    ASSERT_GE(r.truth.size(), 14u);
    EXPECT_FALSE(turns_both_ways(r.truth[0])) << "the first loop of the top lobe is convex";
    for (std::size_t k = 11; k <= 13; ++k) EXPECT_TRUE(turns_both_ways(r.truth[k])) << "kidney loop " << k;
}

TEST(SynthScenario, ShippedLobeStrokesAreDrawnOnOneSurfacePerLobe)
{
    for (const Shipped& sc : kShipped) {
        const SynthResult* synthesized = shipped(sc.file);
        if (!synthesized) return;
        SCOPED_TRACE(sc.file);
        const SynthResult& r = *synthesized;
        ASSERT_EQ(r.surfaces.size(), sc.lobe_strokes_per_lobe.size());
        if (sc.lobe_strokes_per_lobe.empty()) continue; // an editing scene without surfaces
        std::vector<double> new_lobe; // N presses: the next lobe stroke starts the next lobe
        for (const InputEvent& e : r.recording.events)
            if (e.kind == InputEventKind::Key && e.code == keys::kNewLobe && e.value == 1) new_lobe.push_back(e.time);
        std::vector<int> per_lobe(r.surfaces.size(), 0);
        for (const GroundTruthStroke& g : r.truth) {
            if (g.drag || g.kind != StrokeKind::Lobe) {
                EXPECT_EQ(g.surface, -1);
                continue;
            }
            ASSERT_GE(g.surface, 0);
            ASSERT_LT(static_cast<std::size_t>(g.surface), r.surfaces.size());
            ++per_lobe[static_cast<std::size_t>(g.surface)];
            const auto presses = std::count_if(new_lobe.begin(), new_lobe.end(), [&](double t) { return t < g.t_begin; });
            EXPECT_EQ(g.surface, presses) << "lobe strokes between two N keys share their surface";
            // The path the fingertip follows is on the surface (float rounding only).
            for (const glm::vec3& p : g.points)
                ASSERT_LT(std::abs(radial_gap(r.surfaces[static_cast<std::size_t>(g.surface)], glm::dvec3(p))), 1e-5);
        }
        EXPECT_EQ(per_lobe, sc.lobe_strokes_per_lobe);
    }
}

TEST(SynthScenario, ShippedLobesAreEnclosedByTheirStrokes)
{
    // A person enclosing foliage leaves no empty patch wider than about 60° of arc seen from
    // the lobe's centre: every direction is within 30° of a stroke.
    const std::vector<glm::dvec3> probes = test::sphere_directions(4000);
    for (const Shipped& sc : kShipped) {
        const SynthResult* synthesized = shipped(sc.file);
        if (!synthesized) return;
        const SynthResult& r = *synthesized;
        for (std::size_t k = 0; k < r.surfaces.size(); ++k) {
            SCOPED_TRACE(std::string(sc.file) + " lobe " + std::to_string(k));
            std::vector<glm::dvec3> dirs;
            bool closed = false, open = false;
            for (const GroundTruthStroke& g : r.truth) {
                if (g.surface != static_cast<int>(k)) continue;
                (g.closed ? closed : open) = true;
                for (std::size_t i = 0; i < g.points.size(); i += 4)
                    dirs.push_back(glm::normalize(glm::dvec3(g.points[i]) - r.surfaces[k].center));
            }
            EXPECT_TRUE(closed) << "every lobe has loops";
            double widest = 0.0;
            for (const glm::dvec3& u : probes) {
                double nearest = kPi;
                for (const glm::dvec3& d : dirs) nearest = std::min(nearest, std::acos(std::clamp(glm::dot(u, d), -1.0, 1.0)));
                widest = std::max(widest, nearest);
            }
            EXPECT_LE(widest * 180.0 / kPi, 30.0);
        }
    }
}

TEST(SynthScenario, KidneyLobeSurfaceHasADeepWideDentThatItsStrokesCross)
{
    const SynthResult* synthesized = shipped(kShipped[1].file);
    if (!synthesized) return;
    const SynthResult& r = *synthesized;
    ASSERT_EQ(r.surfaces.size(), 4u);
    const TruthSurface& kidney = r.surfaces[2];
    ASSERT_EQ(kidney.dents.size(), 1u);
    const SurfaceDent& dent = kidney.dents[0];
    EXPECT_GE(dent.depth_mm, 40.0);
    EXPECT_GE(dent.width_deg, 60.0);
    EXPECT_LT(dent.direction.x, -0.9) << "the dent faces the trunk";
    // Clearly non-convex: the chord between the surface points 50° either side of the dent
    // passes more than 1.5 cm outside the surface.
    const double side = 50.0 * kPi / 180.0;
    const glm::dvec3 a = point(kidney, glm::dvec3(-std::cos(side), 0.0, std::sin(side)));
    const glm::dvec3 b = point(kidney, glm::dvec3(-std::cos(side), 0.0, -std::sin(side)));
    EXPECT_GT(radial_gap(kidney, 0.5 * (a + b)), 0.015);
    // Its strokes cross the dent (pass well inside its width), so the dent shows in them.
    int crossing = 0;
    for (const GroundTruthStroke& g : r.truth) {
        if (g.surface != 2) continue;
        double closest = kPi;
        for (const glm::vec3& p : g.points)
            closest = std::min(closest, std::acos(std::clamp(glm::dot(glm::normalize(glm::dvec3(p) - kidney.center),
                                                                      dent.direction), -1.0, 1.0)));
        crossing += closest < 0.75 * dent.width_deg * kPi / 180.0;
    }
    EXPECT_GE(crossing, 4);
}

TEST(SynthScenario, PinchEditDragsStartOnTheLobeAndPullFiveCentimetresOutwards)
{
    const SynthResult* synthesized = shipped(kShipped[3].file);
    if (!synthesized) return;
    const SynthResult& r = *synthesized;
    ASSERT_EQ(r.surfaces.size(), 1u);
    const TruthSurface& lobe = r.surfaces[0];
    int drags = 0;
    for (const GroundTruthStroke& g : r.truth) {
        if (!g.drag) continue;
        ++drags;
        const glm::dvec3 from(g.points.front()), to(g.points.back());
        EXPECT_LT(std::abs(radial_gap(lobe, from)), 0.001) << "starts on the surface";
        EXPECT_NEAR(glm::distance(from, to), 0.05, 0.002);
        const glm::dvec3 n = normal(lobe, glm::normalize(from - lobe.center));
        EXPECT_GT(glm::dot(glm::normalize(to - from), n), std::cos(10.0 * kPi / 180.0)) << "along the normal";
        // On a drawn stroke, within its wobble.
        double nearest = 1.0;
        for (const GroundTruthStroke& s : r.truth)
            if (!s.drag) nearest = std::min(nearest, distance_to_polyline(g.points.front(), s.points));
        EXPECT_LT(nearest, 0.006);
    }
    EXPECT_EQ(drags, 2);
}

TEST(SynthScenario, SectionStrokesFollowTheirSurfaceInTheAskedDirection)
{
    json j = minimal_scenario();
    j["noise"] = false;
    j["dropouts"] = false;
    j["surfaces"] = json::array({json{{"center", {0.05, 1.35, -0.42}}, {"radii", {0.12, 0.1, 0.14}},
                                      {"dents", {{{"direction", {-1, 0, 0}}, {"depth_mm", 30}, {"width_deg", 60}}}}}});
    j["steps"] = json::array();
    for (int dir : {1, -1})
        j["steps"].push_back({{"type", "stroke"},
                              {"section", {{"surface", 0}, {"normal", {0, 1, 0}}, {"offset_m", 0.03},
                                           {"direction", dir}, {"wobble_mm", 4}}}});
    j["steps"].push_back({{"type", "stroke"},
                          {"section", {{"surface", 0}, {"normal", {0, 0, 1}}, {"start_angle_deg", 20}, {"sweep_deg", 140}}}});
    const Scenario sc = scenario_from_json(j);
    ASSERT_EQ(sc.surfaces.size(), 1u);
    const SynthResult r = synthesize(sc);
    ASSERT_EQ(r.truth.size(), 3u);
    const TruthSurface& s = r.surfaces[0];
    for (const GroundTruthStroke& g : r.truth) {
        EXPECT_EQ(g.surface, 0);
        for (const glm::vec3& p : g.points) ASSERT_LT(std::abs(radial_gap(s, glm::dvec3(p))), 1e-5);
    }
    // Normal +Y: azimuth 0 is +X and 90° is −Z (far); −1 goes the other way round.
    EXPECT_TRUE(r.truth[0].closed);
    EXPECT_GT(r.truth[0].points.front().x, 0.1f);
    EXPECT_LT(r.truth[0].points[40].z, -0.42f);
    EXPECT_GT(r.truth[1].points[40].z, -0.42f);
    // The wobble differs per step and leaves the plane by millimetres; the loop still closes.
    double off0 = 0.0, off1 = 0.0;
    for (const glm::vec3& p : r.truth[0].points) off0 = std::max(off0, std::abs(p.y - 1.38));
    for (const glm::vec3& p : r.truth[1].points) off1 = std::max(off1, std::abs(p.y - 1.38));
    EXPECT_GT(off0, 0.001);
    EXPECT_LT(off0, 0.008);
    EXPECT_NE(off0, off1);
    EXPECT_LT(glm::distance(r.truth[0].points.front(), r.truth[0].points.back()), 1e-4f);
    // An arc over the top is open and ends where asked.
    EXPECT_FALSE(r.truth[2].closed);
    EXPECT_GT(r.truth[2].points[r.truth[2].points.size() / 2].y, 1.44f);
}

// ---------------------------------------------------------------------------------------
// Frames
// ---------------------------------------------------------------------------------------

TEST(SynthFrames, TimesStrictlyIncreaseAtNinetyHertz)
{
    for (const Shipped& sc : kShipped) {
        const SynthResult* synthesized = shipped(sc.file);
        if (!synthesized) return;
        SCOPED_TRACE(sc.file);
        const auto& frames = synthesized->recording.frames;
        EXPECT_EQ(frames.front().time, 0.0);
        for (std::size_t i = 1; i < frames.size(); ++i) {
            double dt = frames[i].time - frames[i - 1].time;
            ASSERT_GT(dt, 0.0);
            ASSERT_NEAR(dt, 1.0 / 90.0, 0.0006) << "frame " << i;
        }
        double mean = (frames.back().time - frames.front().time) / static_cast<double>(frames.size() - 1);
        EXPECT_NEAR(1.0 / mean, 90.0, 0.5);
        for (const HandFrame& f : frames) ASSERT_TRUE(f.head_valid);
    }
}

TEST(SynthFrames, HeadStandsAtEyeHeightAndLooksAtTheWork)
{
    const SynthResult* synthesized = shipped(kShipped[0].file);
    if (!synthesized) return;
    const auto& frames = synthesized->recording.frames;
    for (std::size_t i = 0; i < frames.size(); i += 30) {
        const Pose& head = frames[i].head;
        EXPECT_NEAR(head.position.y, 1.65f, 0.07f);
        EXPECT_NEAR(head.position.x, 0.0f, 0.05f);
        glm::vec3 forward = head.orientation * glm::vec3(0.0f, 0.0f, -1.0f);
        EXPECT_LT(forward.z, -0.5f) << "looks ahead";
        EXPECT_LT(forward.y, 0.0f) << "looks down at chest height";
    }
}

TEST(SynthFrames, JointsFollowTheOpenXrConventionForBothHands)
{
    Scenario s = idle_scenario(1.0);
    s.noise = false;
    const SynthResult result = synthesize(s);
    const HandFrame& f = result.recording.frames[45];
    for (Hand hand : {Hand::Left, Hand::Right}) {
        SCOPED_TRACE(hand_name(hand));
        const HandState& h = f.hand(hand);
        ASSERT_TRUE(tracked(h));
        // -Z of each finger joint points along its bone, to the next joint.
        for (int finger = 0; finger < 5; ++finger) {
            const int first = finger == 0 ? idx(Joint::ThumbMetacarpal) : idx(Joint::IndexMetacarpal) + 5 * (finger - 1);
            const int last = finger == 0 ? idx(Joint::ThumbTip) : first + 4;
            for (int j = first; j < last; ++j) {
                const JointState& a = h.joints[static_cast<std::size_t>(j)];
                const JointState& b = h.joints[static_cast<std::size_t>(j + 1)];
                glm::vec3 bone = glm::normalize(b.pose.position - a.pose.position);
                glm::vec3 z = a.pose.orientation * glm::vec3(0.0f, 0.0f, -1.0f);
                EXPECT_GT(glm::dot(bone, z), 0.999f) << joint_name(static_cast<Joint>(j));
                EXPECT_NEAR(glm::length(a.pose.orientation), 1.0f, 1e-5f);
            }
        }
        // Mirrored hands, same axes: +X of the palm points away from the thumb on the right
        // hand and towards it on the left; +Y is the back of the hand (the nails' side).
        glm::vec3 x = h[Joint::Palm].pose.orientation * glm::vec3(1.0f, 0.0f, 0.0f);
        glm::vec3 across = pos(h, Joint::IndexProximal) - pos(h, Joint::LittleProximal);
        if (hand == Hand::Right) {
            EXPECT_LT(glm::dot(x, across), 0.0f);
        } else {
            EXPECT_GT(glm::dot(x, across), 0.0f);
        }
        // Anatomical lengths (scaled 0.94–1.06): index proximal phalanx 39 mm, middle metacarpal.
        float prox = glm::distance(pos(h, Joint::IndexProximal), pos(h, Joint::IndexIntermediate));
        EXPECT_NEAR(prox, 0.039f, 0.003f);
        float meta = glm::distance(pos(h, Joint::MiddleMetacarpal), pos(h, Joint::MiddleProximal));
        EXPECT_NEAR(meta, 0.061f, 0.005f);
        // Palm at the middle of the middle metacarpal.
        glm::vec3 mid = 0.5f * (pos(h, Joint::MiddleMetacarpal) + pos(h, Joint::MiddleProximal));
        EXPECT_LT(glm::distance(pos(h, Joint::Palm), mid), 1e-5f);
        // Radii: the tips about 8–9 mm, as the Leap's ~19 mm wide fingers.
        EXPECT_NEAR(h[Joint::IndexTip].radius, 0.008f, 0.001f);
        EXPECT_NEAR(h[Joint::ThumbTip].radius, 0.009f, 0.001f);
    }
}

TEST(SynthFrames, OtherHandIsPresentAndTracked)
{
    for (const Shipped& sc : kShipped) {
        const SynthResult* synthesized = shipped(sc.file);
        if (!synthesized) return;
        SCOPED_TRACE(sc.file);
        const auto& frames = synthesized->recording.frames;
        std::size_t both = 0;
        for (const HandFrame& f : frames)
            if (tracked(f.hand(Hand::Left)) && tracked(f.hand(Hand::Right))) ++both;
        EXPECT_GT(static_cast<double>(both) / static_cast<double>(frames.size()), 0.9);
    }
}

TEST(SynthFrames, UniformRadiusOptionGivesEveryJointOneRadiusAndStillPinches)
{
    const std::string path = test::source_data(kShipped[0].file);
    if (path.empty()) return;
    Scenario s = load_scenario(path);
    s.uniform_joint_radius_m = 0.01;
    SynthResult r = synthesize(s);
    const HandState& h = r.recording.frames[10].hand(Hand::Right);
    for (const JointState& j : h.joints) EXPECT_FLOAT_EQ(j.radius, 0.01f);
    const GroundTruthStroke& g = r.truth[0];
    for (const HandFrame& f : r.recording.frames)
        if (f.time >= g.t_begin && f.time <= g.t_end && tracked(f.hand(g.hand))) {
            ASSERT_LE(pinch_gap(f.hand(g.hand)), 0.004);
        }
}

// ---------------------------------------------------------------------------------------
// Strokes
// ---------------------------------------------------------------------------------------

TEST(SynthStrokes, IndexTipFollowsTheGroundTruthWithinFourMillimetres)
{
    for (const Shipped& sc : kShipped) {
        const SynthResult* synthesized = shipped(sc.file);
        if (!synthesized) return;
        SCOPED_TRACE(sc.file);
        const SynthResult& r = *synthesized;
        for (std::size_t k = 0; k < r.truth.size(); ++k) {
            const GroundTruthStroke& g = r.truth[k];
            int n = 0;
            for (const HandFrame& f : r.recording.frames) {
                if (f.time < g.t_begin || f.time > g.t_end || !tracked(f.hand(g.hand))) continue;
                ++n;
                ASSERT_LE(distance_to_polyline(pos(f.hand(g.hand), Joint::IndexTip), g.points), 0.004)
                    << "stroke " << k << " at t=" << f.time;
            }
            EXPECT_GT(n, 60) << "stroke " << k;
        }
    }
}

TEST(SynthStrokes, IndexTipStaysOnTheCurveEndsWhileTheThumbCloses)
{
    // The thumb moves onto the still index tip (0.2–0.4 s), never the other way round.
    for (const Shipped& sc : kShipped) {
        const SynthResult* synthesized = shipped(sc.file);
        if (!synthesized) return;
        SCOPED_TRACE(sc.file);
        const SynthResult& r = *synthesized;
        for (const GroundTruthStroke& g : r.truth)
            for (const HandFrame& f : r.recording.frames) {
                if (!tracked(f.hand(g.hand))) continue;
                const glm::vec3 tip = pos(f.hand(g.hand), Joint::IndexTip);
                if (f.time >= g.t_begin - 0.2 && f.time <= g.t_begin) {
                    ASSERT_LE(glm::distance(tip, g.points.front()), 0.004f) << "t=" << f.time;
                }
                if (f.time >= g.t_end && f.time <= g.t_end + 0.2) {
                    ASSERT_LE(glm::distance(tip, g.points.back()), 0.004f) << "t=" << f.time;
                }
            }
    }
}

TEST(SynthStrokes, PeakTipSpeedIsBetweenPointTwoAndOneMetrePerSecond)
{
    // Speed over ±4 frames (89 ms, about one tremor period), skipping drop-outs.
    for (const Shipped& sc : kShipped) {
        const SynthResult* synthesized = shipped(sc.file);
        if (!synthesized) return;
        SCOPED_TRACE(sc.file);
        const SynthResult& r = *synthesized;
        const auto& fr = r.recording.frames;
        for (std::size_t k = 0; k < r.truth.size(); ++k) {
            const GroundTruthStroke& g = r.truth[k];
            if (g.drag) continue; // drags are slow edits (5 cm pulls)
            double peak = 0.0;
            for (std::size_t i = 4; i + 4 < fr.size(); ++i) {
                if (fr[i].time < g.t_begin || fr[i].time > g.t_end) continue;
                const HandState& a = fr[i - 4].hand(g.hand);
                const HandState& b = fr[i + 4].hand(g.hand);
                if (!tracked(a) || !tracked(b)) continue;
                double v = glm::distance(pos(a, Joint::IndexTip), pos(b, Joint::IndexTip)) / (fr[i + 4].time - fr[i - 4].time);
                peak = std::max(peak, v);
            }
            EXPECT_GE(peak, 0.2) << "stroke " << k;
            EXPECT_LE(peak, 1.0) << "stroke " << k;
        }
    }
}

// ---------------------------------------------------------------------------------------
// Pinches and distractors
// ---------------------------------------------------------------------------------------

TEST(SynthPinch, GapIsClosedDuringStrokesAndOpenWellBetweenThem)
{
    for (const Shipped& sc : kShipped) {
        const SynthResult* synthesized = shipped(sc.file);
        if (!synthesized) return;
        SCOPED_TRACE(sc.file);
        const SynthResult& r = *synthesized;
        const auto& fr = r.recording.frames;
        for (std::size_t k = 0; k < r.truth.size(); ++k) {
            const GroundTruthStroke& g = r.truth[k];
            for (const HandFrame& f : fr)
                if (f.time >= g.t_begin && f.time <= g.t_end && tracked(f.hand(g.hand))) {
                    ASSERT_LE(pinch_gap(f.hand(g.hand)), 0.004) << "stroke " << k << " t=" << f.time;
                }
            if (k + 1 == r.truth.size() || r.truth[k + 1].hand != g.hand) continue;
            const double from = g.t_end + 0.5, to = r.truth[k + 1].t_begin - 0.7;
            for (const HandFrame& f : fr) {
                if (f.time < from || f.time > to || !tracked(f.hand(g.hand))) continue;
                bool distractor = std::any_of(r.spans.begin(), r.spans.end(), [&](const SynthSpan& s) {
                    return s.type != SynthSpan::Type::Dropout && s.hand == g.hand && in_span(f.time, s, 0.2);
                });
                if (!distractor) {
                    ASSERT_GE(pinch_gap(f.hand(g.hand)), 0.030) << "after stroke " << k << " t=" << f.time;
                }
            }
        }
    }
}

TEST(SynthPinch, ThumbClosesFromAnOpenGapLikeTheLeapClip)
{
    // shared/data/real/leap-pinch.json: about 77 mm open, settling near -1 mm pinched.
    for (const Shipped& sc : kShipped) {
        const SynthResult* synthesized = shipped(sc.file);
        if (!synthesized) return;
        SCOPED_TRACE(sc.file);
        const SynthResult& r = *synthesized;
        for (const GroundTruthStroke& g : r.truth) {
            double open = 0.0, closed = 1.0;
            for (const HandFrame& f : r.recording.frames) {
                if (!tracked(f.hand(g.hand))) continue;
                if (f.time >= g.t_begin - 0.6 && f.time <= g.t_begin) open = std::max(open, pinch_gap(f.hand(g.hand)));
                if (f.time >= g.t_begin && f.time <= g.t_begin + 0.05) closed = std::min(closed, pinch_gap(f.hand(g.hand)));
            }
            EXPECT_GE(open, 0.050);
            EXPECT_LE(open, 0.082);
            EXPECT_GE(closed, -0.004);
            EXPECT_LE(closed, 0.003);
        }
    }
}

TEST(SynthDistractors, NearPinchClosestGapIsTwelveToTwentyMillimetres)
{
    int count = 0;
    for (const Shipped& sc : kShipped) {
        const SynthResult* synthesized = shipped(sc.file);
        if (!synthesized) return;
        SCOPED_TRACE(sc.file);
        const SynthResult& r = *synthesized;
        for (const SynthSpan& s : r.spans) {
            if (s.type != SynthSpan::Type::NearPinch) continue;
            ++count;
            double closest = 1.0;
            for (const HandFrame& f : r.recording.frames)
                if (in_span(f.time, s, 0.0) && tracked(f.hand(s.hand))) closest = std::min(closest, pinch_gap(f.hand(s.hand)));
            EXPECT_GE(closest, 0.012) << "near-pinch at " << s.t_begin;
            EXPECT_LE(closest, 0.020) << "near-pinch at " << s.t_begin;
        }
    }
    EXPECT_GE(count, 4);
}

TEST(SynthDistractors, GrabCurlsMiddleRingLittleAndStrokesDoNot)
{
    int grabs = 0;
    for (const Shipped& sc : kShipped) {
        const SynthResult* synthesized = shipped(sc.file);
        if (!synthesized) return;
        SCOPED_TRACE(sc.file);
        const SynthResult& r = *synthesized;
        for (const SynthSpan& s : r.spans) {
            if (s.type != SynthSpan::Type::Grab) continue;
            ++grabs;
            double closest = 1.0;
            for (const HandFrame& f : r.recording.frames) {
                if (!tracked(f.hand(s.hand))) continue;
                if (f.time >= s.t_peak_begin && f.time <= s.t_peak_end) {
                    ASSERT_GE(min_curl_mrl(f.hand(s.hand)), 0.6);
                }
                if (in_span(f.time, s, 0.0)) closest = std::min(closest, pinch_gap(f.hand(s.hand)));
            }
            // As in leap-grab.json, the thumb comes close to the index tip: a grab is not a pinch.
            EXPECT_LT(closest, 0.016) << "grab at " << s.t_begin;
        }
        for (const GroundTruthStroke& g : r.truth)
            for (const HandFrame& f : r.recording.frames)
                if (f.time >= g.t_begin && f.time <= g.t_end && tracked(f.hand(g.hand))) {
                    ASSERT_LE(max_curl_mrl(f.hand(g.hand)), 0.3);
                }
    }
    EXPECT_GE(grabs, 4);
}

TEST(SynthKeys, KeyStepsBecomePressAndReleaseEvents)
{
    const SynthResult* one_lobe = shipped(kShipped[0].file);
    if (!one_lobe) return;
    const SynthResult* pinch_edit = shipped(kShipped[3].file);
    if (!pinch_edit) return;
    const auto& events = one_lobe->recording.events;
    ASSERT_EQ(events.size(), 2u);
    EXPECT_EQ(events[0].kind, InputEventKind::Key);
    EXPECT_EQ(events[0].code, keys::kDrawTrunk);
    EXPECT_EQ(events[0].value, 1);
    EXPECT_EQ(events[1].code, keys::kDrawTrunk);
    EXPECT_EQ(events[1].value, 0);
    EXPECT_NEAR(events[1].time - events[0].time, 0.08, 0.011);
    // The trunk strokes come after the key.
    for (const GroundTruthStroke& g : one_lobe->truth)
        EXPECT_EQ(g.kind == StrokeKind::Trunk, g.t_begin > events[0].time);

    const auto& edit = pinch_edit->recording.events;
    std::vector<int> pressed;
    for (const InputEvent& e : edit)
        if (e.value == 1) pressed.push_back(e.code);
    EXPECT_EQ(pressed, (std::vector<int>{keys::kDeformLobe, keys::kDrawLobe}));
}

// ---------------------------------------------------------------------------------------
// Noise
// ---------------------------------------------------------------------------------------

TEST(SynthNoise, HighPassJitterOfATipAtRestIsHalfToTwoAndAHalfMillimetres)
{
    // A relaxed hand (slow sway only) for 6 s; residual after a 9-frame (0.1 s) moving average.
    SynthResult r = synthesize(idle_scenario(6.0));
    for (Hand hand : {Hand::Left, Hand::Right}) {
        std::vector<glm::dvec3> tip;
        for (const HandFrame& f : r.recording.frames)
            if (f.time > 0.5 && f.time < 6.0) tip.push_back(glm::dvec3(pos(f.hand(hand), Joint::IndexTip)));
        double residual = rms(high_pass(tip, 9));
        EXPECT_GE(residual, 0.0005) << hand_name(hand);
        EXPECT_LE(residual, 0.0025) << hand_name(hand);
    }
    // The same on a shipped recording: the idle left hand while the right hand draws.
    const SynthResult* synthesized = shipped(kShipped[0].file);
    if (!synthesized) return;
    const SynthResult& s = *synthesized;
    const GroundTruthStroke& g = s.truth[0];
    std::vector<glm::dvec3> tip;
    for (const HandFrame& f : s.recording.frames)
        if (f.time >= g.t_begin && f.time <= g.t_end && tracked(f.hand(Hand::Left)))
            tip.push_back(glm::dvec3(pos(f.hand(Hand::Left), Joint::IndexTip)));
    ASSERT_GT(tip.size(), 200u);
    double residual = rms(high_pass(tip, 9));
    EXPECT_GE(residual, 0.0005);
    EXPECT_LE(residual, 0.0025);
}

TEST(SynthNoise, TremorShowsASpectralPeakBetweenEightAndTwelveHertz)
{
    SynthResult r = synthesize(idle_scenario(6.0));
    for (Hand hand : {Hand::Left, Hand::Right}) {
        SCOPED_TRACE(hand_name(hand));
        std::vector<glm::dvec3> tip;
        std::vector<double> time;
        for (const HandFrame& f : r.recording.frames)
            if (f.time > 0.5 && f.time < 6.0) {
                tip.push_back(glm::dvec3(pos(f.hand(hand), Joint::IndexTip)));
                time.push_back(f.time);
            }
        // Remove the slow sway (31-frame moving average), then a DFT at the frame times.
        std::vector<glm::dvec3> x = high_pass(tip, 31);
        time.erase(time.begin(), time.begin() + 15);
        double best_f = 0.0, best_p = 0.0, band = 0.0, high = 0.0;
        int band_n = 0, high_n = 0;
        for (double freq = 3.0; freq <= 40.0; freq += 0.25) {
            double power = 0.0;
            for (int a = 0; a < 3; ++a) {
                std::complex<double> sum(0.0, 0.0);
                for (std::size_t i = 0; i < x.size(); ++i)
                    sum += x[i][a] * std::polar(1.0, -2.0 * kPi * freq * time[i]);
                power += std::norm(sum);
            }
            if (power > best_p) {
                best_p = power;
                best_f = freq;
            }
            if (freq >= 8.0 && freq <= 12.0) {
                band += power;
                ++band_n;
            }
            if (freq >= 15.0) {
                high += power;
                ++high_n;
            }
        }
        EXPECT_GE(best_f, 8.0);
        EXPECT_LE(best_f, 12.0);
        EXPECT_GT(band / band_n, 3.0 * high / high_n) << "tremor stands out of the white jitter";
    }
}

TEST(SynthDropouts, ExistLastFiftyToThreeHundredMsAndStayShortInsideStrokes)
{
    int inactive = 0, quirk = 0;
    for (const Shipped& sc : kShipped) {
        const SynthResult* synthesized = shipped(sc.file);
        if (!synthesized) return;
        SCOPED_TRACE(sc.file);
        const SynthResult& r = *synthesized;
        const auto& fr = r.recording.frames;
        int runs = 0, in_stroke = 0;
        for (Hand hand : {Hand::Left, Hand::Right}) {
            for (std::size_t i = 1; i < fr.size(); ++i) {
                if (tracked(fr[i].hand(hand)) || !tracked(fr[i - 1].hand(hand))) continue;
                std::size_t j = i;
                while (j < fr.size() && !tracked(fr[j].hand(hand))) ++j;
                ASSERT_LT(j, fr.size()) << "the hand comes back";
                // The lost stretch, and the gap between the tracked frames around it.
                const double lost = fr[j].time - fr[i].time;
                const double bridge = fr[j].time - fr[i - 1].time;
                ++runs;
                EXPECT_GE(lost, 0.040);
                EXPECT_LE(lost, 0.300);
                const HandState& h = fr[i].hand(hand);
                if (h.active) {
                    ++quirk;
                    EXPECT_EQ(h[Joint::Palm].pose.position, glm::vec3(0.0f)) << "snapped to the origin";
                } else {
                    ++inactive;
                }
                for (const GroundTruthStroke& g : r.truth)
                    if (g.hand == hand && fr[i].time < g.t_end && fr[j].time > g.t_begin) {
                        ++in_stroke;
                        EXPECT_LE(lost, 0.120) << "inside a stroke at " << fr[i].time;
                        EXPECT_LE(bridge, 0.150) << "the pipeline bridges 150 ms";
                    }
                i = j;
            }
        }
        EXPECT_GE(runs, 2);
        EXPECT_GE(in_stroke, 1);
    }
    EXPECT_GT(inactive, 0);
    EXPECT_GT(quirk, 0);
}

// ---------------------------------------------------------------------------------------
// Bad scenarios
// ---------------------------------------------------------------------------------------

TEST(SynthScenarioErrors, MinimalScenarioIsValid)
{
    Scenario s = scenario_from_json(minimal_scenario());
    ASSERT_EQ(s.steps.size(), 1u);
    EXPECT_EQ(s.seed, 7u);
    EXPECT_DOUBLE_EQ(s.rate_hz, 90.0);
    EXPECT_EQ(synthesize(s).truth.size(), 1u);
}

TEST(SynthScenarioErrors, BadScenariosGiveOneLineInvalidInputNamingTheField)
{
    struct Case {
        const char* what;
        json scenario;
        const char* field;
    };
    std::vector<Case> cases;
    {
        json j = minimal_scenario();
        j["steps"][0]["type"] = "wave";
        cases.push_back({"unknown step type", j, "steps[0].type"});
    }
    {
        json j = minimal_scenario();
        j["steps"][0]["curve"][1][1] = std::nan("");
        cases.push_back({"NaN coordinate", j, "steps[0].curve[1]"});
    }
    {
        json j = minimal_scenario();
        j["steps"][0]["speed"] = 50.0;
        cases.push_back({"speed 50 m/s", j, "steps[0].speed"});
    }
    {
        json j = minimal_scenario();
        j["steps"] = json::array();
        for (int i = 0; i < 20000; ++i) j["steps"].push_back({{"type", "pause"}, {"duration", 0.1}});
        cases.push_back({"20,000 steps", j, "steps"});
    }
    {
        json j = minimal_scenario();
        j["format"] = "lobesketch-recording";
        cases.push_back({"wrong format", j, "format"});
    }
    {
        json j = minimal_scenario();
        j["version"] = 2;
        cases.push_back({"future version", j, "version"});
    }
    {
        json j = minimal_scenario();
        j["steps"][0]["curve"][2][0] = 12.0;
        cases.push_back({"coordinate beyond 10 m", j, "steps[0].curve[2]"});
    }
    {
        json j = minimal_scenario();
        json curve = json::array();
        for (int i = 0; i < 100001; ++i) curve.push_back({0.0, 1.3, -0.4 - 1e-5 * i});
        j["steps"][0]["curve"] = curve;
        cases.push_back({"100,001 curve points", j, "steps[0].curve"});
    }
    {
        json j = minimal_scenario();
        for (int i = 0; i < 3; ++i) j["steps"].push_back({{"type", "pause"}, {"duration", 3000.0}});
        cases.push_back({"longer than 2 h", j, "steps"});
    }
    {
        json j = minimal_scenario();
        j["steps"][0]["hand"] = "middle";
        cases.push_back({"unknown hand", j, "steps[0].hand"});
    }
    {
        json j = minimal_scenario();
        j["steps"].push_back({{"type", "key"}, {"key", "F12"}});
        cases.push_back({"unknown key", j, "steps[1].key"});
    }
    {
        json j = minimal_scenario();
        j["steps"][0]["sped"] = 0.5;
        cases.push_back({"misspelt field", j, "steps[0]"});
    }
    {
        json j = minimal_scenario();
        j["steps"][0].erase("curve");
        j["steps"][0]["ellipse"] = {{"center", {0.0, 1.3, -0.4}}, {"radii", {0.1, 0.5}},
                                    {"dents", {{{"angle_deg", 0}, {"depth_mm", 90}, {"width_deg", 40}}}}};
        cases.push_back({"dent deeper than the ellipse", j, "steps[0].ellipse.dents[0].depth_mm"});
    }
    auto with_section = [](json section) {
        json j = minimal_scenario();
        j["surfaces"] = json::array({json{{"center", {0.0, 1.3, -0.4}}, {"radii", {0.12, 0.1, 0.14}}}});
        j["steps"][0].erase("curve");
        j["steps"][0]["section"] = std::move(section);
        return j;
    };
    cases.push_back({"section without surfaces",
                     [&] { json j = with_section({{"surface", 0}}); j.erase("surfaces"); return j; }(),
                     "steps[0].section.surface"});
    cases.push_back({"section on surface 1 of 1", with_section({{"surface", 1}}), "steps[0].section.surface"});
    cases.push_back({"section without a surface", with_section({{"normal", {0, 1, 0}}}), "steps[0].section"});
    cases.push_back({"section misspelt field", with_section({{"surface", 0}, {"ofset_m", 0.02}}), "steps[0].section"});
    cases.push_back({"section plane misses", with_section({{"surface", 0}, {"offset_m", 0.15}}), "steps[0].section.offset_m"});
    cases.push_back({"section direction 2", with_section({{"surface", 0}, {"direction", 2}}), "steps[0].section.direction"});
    cases.push_back({"section zero normal", with_section({{"surface", 0}, {"normal", {0, 0, 0}}}), "steps[0].section.normal"});
    cases.push_back({"section sweep 400°", with_section({{"surface", 0}, {"sweep_deg", 400}}), "steps[0].section.sweep_deg"});
    cases.push_back({"section wobble 30 mm", with_section({{"surface", 0}, {"wobble_mm", 30}}), "steps[0].section.wobble_mm"});
    {
        json j = with_section({{"surface", 0}});
        j["steps"][0]["curve"] = json::array({json::array({0.0, 1.3, -0.4}), json::array({0.1, 1.3, -0.4})});
        cases.push_back({"section and curve", j, "steps[0]"});
    }
    {
        json j = with_section({{"surface", 0}});
        j["surfaces"][0]["radii"] = {0.12, 0.1, 3.0};
        cases.push_back({"surface radius 3 m", j, "surfaces[0].radii"});
    }
    {
        json j = with_section({{"surface", 0}});
        j["surfaces"][0]["dents"] = {{{"direction", {1, 0, 0}}, {"depth_mm", 100}}};
        cases.push_back({"dent leaving 17 %", j, "surfaces[0].dents"});
    }
    {
        json j = with_section({{"surface", 0}});
        j["surfaces"] = json::object();
        cases.push_back({"surfaces not an array", j, "surfaces"});
    }
    for (const Case& c : cases) {
        SCOPED_TRACE(c.what);
        std::string msg = invalid_input_message([&] { scenario_from_json(c.scenario); });
        ASSERT_FALSE(msg.empty()) << "should be refused";
        EXPECT_EQ(msg.rfind(std::string(c.field) + ":", 0), 0u) << msg;
        EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    }
}

TEST(SynthScenarioErrors, ScenariosBuiltInCodeAreCheckedToo)
{
    Scenario s = scenario_from_json(minimal_scenario());
    s.steps[0].stroke.speed_mps = 50.0;
    EXPECT_NE(invalid_input_message([&] { synthesize(s); }).find("steps[0].speed"), std::string::npos);
    s = scenario_from_json(minimal_scenario());
    s.steps[0].stroke.curve[0].x = std::numeric_limits<float>::infinity();
    EXPECT_NE(invalid_input_message([&] { synthesize(s); }).find("steps[0].curve[0]"), std::string::npos);
    s = scenario_from_json(minimal_scenario());
    s.rate_hz = 0.0;
    EXPECT_NE(invalid_input_message([&] { synthesize(s); }).find("rate_hz"), std::string::npos);
    // A stroke said to lie on a surface must name one and lie on it.
    s = scenario_from_json(minimal_scenario());
    s.steps[0].stroke.surface = 0;
    EXPECT_NE(invalid_input_message([&] { synthesize(s); }).find("steps[0].surface"), std::string::npos);
    s.surfaces.push_back(TruthSurface{});
    s.surfaces[0].center = glm::dvec3(0.1, 1.3, -0.4);
    EXPECT_NE(invalid_input_message([&] { synthesize(s); }).find("off surface 0"), std::string::npos);
    s.surfaces[0].radii.y = 0.01;
    EXPECT_NE(invalid_input_message([&] { synthesize(s); }).find("surfaces[0].radii"), std::string::npos);
}

TEST(SynthScenarioErrors, BadFilesGiveOneLineFileErrorsNamingTheFile)
{
    const std::string dir = test::temp_dir("synth-bad-files");
    auto expect_file_error = [](const std::string& path, const std::string& part) {
        try {
            load_scenario(path);
            ADD_FAILURE() << path << " should be refused";
        } catch (const FileError& e) {
            std::string msg = e.what();
            EXPECT_EQ(msg.rfind(path + ":", 0), 0u) << msg;
            EXPECT_NE(msg.find(part), std::string::npos) << msg;
            EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
        }
    };
    expect_file_error(dir + "/missing.scenario.json", "no such file");
    {
        std::ofstream(dir + "/nan.scenario.json") << R"({"format":"lobesketch-scenario","version":1,"steps":[NaN]})";
        expect_file_error(dir + "/nan.scenario.json", "not valid JSON");
    }
    {
        json j = minimal_scenario();
        j["format"] = "something-else";
        std::ofstream(dir + "/format.scenario.json") << j.dump();
        expect_file_error(dir + "/format.scenario.json", "format:");
    }
    {
        json j = minimal_scenario();
        j["steps"][0]["type"] = "jump";
        std::ofstream(dir + "/type.scenario.json") << j.dump();
        expect_file_error(dir + "/type.scenario.json", "steps[0].type");
    }
}

// ---------------------------------------------------------------------------------------
// Ground truth files
// ---------------------------------------------------------------------------------------

TEST(SynthGroundTruth, JsonRoundTripKeepsEveryField)
{
    const SynthResult* synthesized = shipped(kShipped[3].file);
    if (!synthesized) return;
    const SynthResult& r = *synthesized;
    const std::string dir = test::temp_dir("synth-truth");
    const std::string path = dir + "/pinch-edit.truth.json";
    json j = ground_truth_to_json(r.truth, r.surfaces);
    EXPECT_EQ(j["format"], "lobesketch-ground-truth");
    EXPECT_EQ(j["version"], 1);
    const std::vector<TruthSurface> surfaces = truth_surfaces_from_json(j);
    ASSERT_EQ(surfaces.size(), r.surfaces.size());
    for (std::size_t k = 0; k < surfaces.size(); ++k) EXPECT_EQ(truth_surface_to_json(surfaces[k]), truth_surface_to_json(r.surfaces[k]));
    std::ofstream(path) << j.dump();
    std::vector<GroundTruthStroke> back = load_ground_truth(path);
    ASSERT_EQ(back.size(), r.truth.size());
    for (std::size_t k = 0; k < back.size(); ++k) {
        EXPECT_EQ(back[k].kind, r.truth[k].kind);
        EXPECT_EQ(back[k].hand, r.truth[k].hand);
        EXPECT_EQ(back[k].closed, r.truth[k].closed);
        EXPECT_EQ(back[k].drag, r.truth[k].drag);
        EXPECT_EQ(back[k].t_begin, r.truth[k].t_begin);
        EXPECT_EQ(back[k].t_end, r.truth[k].t_end);
        EXPECT_EQ(back[k].surface, r.truth[k].surface);
        ASSERT_EQ(back[k].points.size(), r.truth[k].points.size());
        for (std::size_t i = 0; i < back[k].points.size(); ++i) ASSERT_EQ(back[k].points[i], r.truth[k].points[i]);
    }
    EXPECT_TRUE(back[5].drag);
    EXPECT_EQ(back[0].surface, 0);
    EXPECT_EQ(back[5].surface, -1);
    // A stroke naming a surface the file does not have cannot be written.
    EXPECT_THROW(ground_truth_to_json(r.truth), InvalidInput);
}

TEST(SynthGroundTruth, BadTruthFilesGiveFileErrors)
{
    const std::string dir = test::temp_dir("synth-truth-bad");
    std::ofstream(dir + "/a.json") << R"({"format":"lobesketch-ground-truth","version":1,"strokes":[{"kind":"leaf","points":[]}]})";
    std::ofstream(dir + "/b.json") << R"({"format":"lobesketch-ground-truth","version":1,"strokes":[{"kind":"lobe","points":[[0,1]]}]})";
    std::ofstream(dir + "/c.json") << "{\"format\":";
    std::ofstream(dir + "/d.json")
        << R"({"format":"lobesketch-ground-truth","version":1,"strokes":[{"kind":"lobe","surface":0,"points":[[0,1,0]]}]})";
    std::ofstream(dir + "/e.json") << R"({"format":"lobesketch-ground-truth","version":1,"surfaces":[{"center":[0,1,0],"radii":[0.1,0.1,5]}],"strokes":[]})";
    for (const char* name : {"/a.json", "/b.json", "/c.json", "/d.json", "/e.json", "/missing.json"}) {
        const std::string path = dir + name;
        try {
            load_ground_truth(path);
            ADD_FAILURE() << name << " should be refused";
        } catch (const FileError& e) {
            EXPECT_EQ(std::string(e.what()).rfind(path + ":", 0), 0u) << e.what();
        }
    }
}
