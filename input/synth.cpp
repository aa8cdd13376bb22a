#include "input/synth.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/mat3x3.hpp>
#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "core/errors.h"
#include "core/random.h"
#include "input/hand_model.h"
#include "input/synth_geometry.h"
#include "input/synth_motion.h"
#include "input/synth_random.h"
#include "input/synth_scenario.h"
#include "input/tools.h"

namespace lobe {

namespace synth {

namespace {

namespace hm = hand_model;
using json = nlohmann::json;

/// Tracking drop-outs: about one every 7 s per hand, 50–290 ms where the hand is between
/// gestures, 55–100 ms inside a stroke (the pipeline bridges losses up to 150 ms), none while
/// the thumb closes or opens or during distractors. At least one of each kind when possible.
struct Dropout {
    double t0 = 0.0, t1 = 0.0;
    bool quirk = false; ///< active, flags cleared, joints at the origin (instead of inactive)
};

/// True when every segment overlapping [a, b] allows a long drop-out; `from` is a segment
/// at or before `a`.
bool all_long(const Track& tr, std::size_t from, double a, double b)
{
    for (std::size_t i = from > 0 ? from - 1 : 0; i < tr.segs.size() && tr.segs[i].t0 < b; ++i) {
        const Segment& s = tr.segs[i];
        if (s.t1 <= a) continue;
        if (s.drop != DropZone::Long) return false;
    }
    return true;
}

std::array<std::vector<Dropout>, kHandCount> schedule_dropouts(const Synth& sy, std::uint64_t seed)
{
    std::array<std::vector<Dropout>, kHandCount> out;
    Rng rng(stream_seed(seed, kTagDropouts));
    bool any_short = false;
    for (int h = 0; h < kHandCount; ++h) {
        const Track& tr = sy.tracks[static_cast<std::size_t>(h)];
        auto& list = out[static_cast<std::size_t>(h)];
        const double end = tr.segs.empty() ? 0.0 : tr.segs.back().t1;
        double t = 0.5 + rng.exponential(7.0);
        std::size_t si = 0;
        while (t < end - 0.5) {
            while (si + 1 < tr.segs.size() && tr.segs[si].t1 <= t) ++si;
            const Segment& s = tr.segs[si];
            const bool quirk = rng.uniform() < 0.5;
            if (s.drop == DropZone::Short) {
                double d = rng.uniform(0.055, 0.100);
                if (t >= s.t0 + 0.25 && t + d <= s.t1 - 0.25) {
                    list.push_back({t, t + d, quirk});
                    any_short = true;
                    t += d;
                }
            } else if (s.drop == DropZone::Long) {
                double d = rng.uniform(0.05, 0.29);
                if (all_long(tr, si, t - 0.05, t + d + 0.05)) {
                    list.push_back({t, t + d, quirk});
                    t += d;
                }
            }
            t += 0.4 + rng.exponential(7.0);
        }
    }
    // Make sure both kinds show up: the middle of the longest stroke of the drawing hands,
    // and the middle of the longest free stretch of the right hand.
    if (!any_short) {
        const Segment* best = nullptr;
        int best_hand = 0;
        for (int h = 0; h < kHandCount; ++h)
            for (const Segment& s : sy.tracks[static_cast<std::size_t>(h)].segs)
                if (s.drop == DropZone::Short && (!best || s.t1 - s.t0 > best->t1 - best->t0)) {
                    best = &s;
                    best_hand = h;
                }
        if (best && best->t1 - best->t0 > 0.8) {
            double mid = 0.5 * (best->t0 + best->t1);
            auto& list = out[static_cast<std::size_t>(best_hand)];
            list.push_back({mid - 0.04, mid + 0.04, false});
            std::sort(list.begin(), list.end(), [](const Dropout& a, const Dropout& b) { return a.t0 < b.t0; });
        }
    }
    for (int h = 0; h < kHandCount; ++h) {
        auto& list = out[static_cast<std::size_t>(h)];
        bool has_long = std::any_of(list.begin(), list.end(), [](const Dropout& d) { return d.t1 - d.t0 > 0.12; });
        if (has_long || h != static_cast<int>(Hand::Right)) continue;
        const Track& tr = sy.tracks[static_cast<std::size_t>(h)];
        double best_a = 0.0, best_b = 0.0;
        for (std::size_t i = 0; i < tr.segs.size();) {
            if (tr.segs[i].drop != DropZone::Long) {
                ++i;
                continue;
            }
            std::size_t j = i;
            while (j < tr.segs.size() && tr.segs[j].drop == DropZone::Long) ++j;
            if (tr.segs[j - 1].t1 - tr.segs[i].t0 > best_b - best_a) {
                best_a = tr.segs[i].t0;
                best_b = tr.segs[j - 1].t1;
            }
            i = j;
        }
        if (best_b - best_a > 0.8) {
            double mid = 0.5 * (best_a + best_b);
            bool clash = std::any_of(list.begin(), list.end(),
                                     [&](const Dropout& d) { return d.t1 > mid - 0.2 && d.t0 < mid + 0.2; });
            if (!clash) {
                list.push_back({mid - 0.09, mid + 0.09, true});
                std::sort(list.begin(), list.end(), [](const Dropout& a, const Dropout& b) { return a.t0 < b.t0; });
            }
        }
    }
    return out;
}

// ---------------------------------------------------------------------------------------
// Frames
// ---------------------------------------------------------------------------------------

int finger_of(int joint)
{
    if (joint < idx(Joint::ThumbMetacarpal)) return -1;
    if (joint <= idx(Joint::ThumbTip)) return 0;
    return 1 + (joint - idx(Joint::IndexMetacarpal)) / 5;
}

struct TremorState {
    double phase = 0.0;
};

/// Jitter (white: hand 0.5 mm, finger 0.35 mm, joint 0.3 mm per axis, truncated at 2.5 σ,
/// about 1.2 mm per joint in all; orientations 0.3°) and physiological tremor.
void add_noise(HandState& hs, Rng& rng, const dvec3& tremor)
{
    const double k = 2.5;
    dvec3 common = normal3(rng, k);
    common *= 0.0005;
    std::array<dvec3, 5> finger{};
    for (auto& f : finger) f = 0.00035 * normal3(rng, k);
    for (int j = 0; j < kJointCount; ++j) {
        dvec3 own = 0.0003 * normal3(rng, k);
        int f = finger_of(j);
        dvec3 off = common + own + tremor + (f >= 0 ? finger[static_cast<std::size_t>(f)] : dvec3(0.0));
        JointState& js = hs.joints[static_cast<std::size_t>(j)];
        js.pose.position += glm::vec3(off);
        dvec3 r = 0.005 * normal3(rng, k);
        double angle = glm::length(r);
        if (angle > 1e-12)
            js.pose.orientation = glm::normalize(js.pose.orientation * glm::quat(glm::angleAxis(angle, r / angle)));
    }
}

HandState lost_hand(bool quirk)
{
    HandState hs; // inactive, joints zeroed, no flags
    if (quirk) {
        // Seen on real devices: "active" with every flag cleared and the joints at the origin.
        hs.active = true;
        for (JointState& js : hs.joints) {
            js.pose = Pose{};
            js.radius = 0.0f;
            js.flags = 0;
        }
    }
    return hs;
}

} // namespace

} // namespace synth

using namespace synth;

// ---------------------------------------------------------------------------------------
// Public API
// ---------------------------------------------------------------------------------------

SynthResult synthesize(const Scenario& scenario)
{
    validate_scenario(scenario);
    Synth sy;
    sy.person = make_person(scenario.seed, scenario.uniform_joint_radius_m);
    sy.surfaces = scenario.surfaces;

    // Where the work is (the head looks there between strokes).
    {
        dvec3 sum(0.0);
        std::size_t n = 0;
        for (const ScenarioStep& st : scenario.steps)
            if (st.type == ScenarioStep::Type::Stroke || st.type == ScenarioStep::Type::Drag)
                for (const glm::vec3& p : st.stroke.curve) {
                    sum += to_d(p);
                    ++n;
                }
        if (n > 0) sy.work_centre = sum / static_cast<double>(n);
    }

    for (int h = 0; h < kHandCount; ++h) {
        Track& tr = sy.tracks[static_cast<std::size_t>(h)];
        tr.hand = static_cast<Hand>(h);
        const HandPersona& hp = sy.persona(tr.hand);
        tr.tip = hp.rest + hp.rest_sway.at(0.0);
        tr.at_rest = true;
    }

    Build out;
    double now = 0.6;
    for (Track& tr : sy.tracks) idle_until(sy, tr, now);
    out.focus.push_back({0.0, Hand::Right});

    for (std::size_t i = 0; i < scenario.steps.size(); ++i) {
        const ScenarioStep& step = scenario.steps[i];
        Rng rng(stream_seed(scenario.seed, kTagStep + i));
        const bool uses_hand = step.type == ScenarioStep::Type::Stroke || step.type == ScenarioStep::Type::Drag ||
                               step.type == ScenarioStep::Type::NearPinch || step.type == ScenarioStep::Type::Grab;
        if (uses_hand) {
            const Hand h = (step.type == ScenarioStep::Type::Stroke || step.type == ScenarioStep::Type::Drag)
                               ? step.stroke.hand
                               : step.hand;
            Track& other = sy.track(h == Hand::Right ? Hand::Left : Hand::Right);
            if (!other.at_rest) go_rest(sy, other, rng);
            out.focus.push_back({now, h});
            switch (step.type) {
            case ScenarioStep::Type::Stroke:
            case ScenarioStep::Type::Drag: build_stroke(sy, out, step, rng); break;
            case ScenarioStep::Type::NearPinch: build_near_pinch(sy, out, step, rng); break;
            case ScenarioStep::Type::Grab: build_grab(sy, out, step, rng); break;
            default: break;
            }
            now = std::max(sy.track(h).t, other.t);
        } else if (step.type == ScenarioStep::Type::Key) {
            const double press = now + rng.uniform(0.08, 0.15);
            out.events.push_back({press, InputEventKind::Key, step.key, 1, 0.0f, 0.0f});
            out.events.push_back({press + rng.uniform(0.07, 0.09), InputEventKind::Key, step.key, 0, 0.0f, 0.0f});
            now += 0.35;
        } else {
            now += step.duration_s;
        }
        for (Track& tr : sy.tracks) idle_until(sy, tr, now);
        if (now > kMaxDurationS) fail("steps", "the scenario lasts more than " + num(kMaxDurationS) + " s (2 h)");
    }
    now += 0.8;
    for (Track& tr : sy.tracks) idle_until(sy, tr, now);
    out.t_end = now;
    if (out.t_end * scenario.rate_hz > static_cast<double>(kMaxRecordingFrames))
        fail("steps", "the scenario needs more than " + std::to_string(kMaxRecordingFrames) + " frames");

    const auto dropouts = scenario.dropouts ? schedule_dropouts(sy, scenario.seed)
                                            : std::array<std::vector<Dropout>, kHandCount>{};
    for (int h = 0; h < kHandCount; ++h)
        for (const Dropout& d : dropouts[static_cast<std::size_t>(h)]) {
            SynthSpan sp;
            sp.type = SynthSpan::Type::Dropout;
            sp.hand = static_cast<Hand>(h);
            sp.t_begin = sp.t_peak_begin = d.t0;
            sp.t_end = sp.t_peak_end = d.t1;
            out.spans.push_back(sp);
        }
    std::stable_sort(out.spans.begin(), out.spans.end(),
                     [](const SynthSpan& a, const SynthSpan& b) { return a.t_begin < b.t_begin; });

    // Frames.
    SynthResult result;
    Recording& rec = result.recording;
    rec.header.source = "synth";
    rec.header.device = "synthetic hand";
    rec.header.nominal_rate_hz = scenario.rate_hz;
    rec.header.created = "";
    rec.events = out.events;
    Rng noise(stream_seed(scenario.seed, kTagNoise));
    Rng clock(stream_seed(scenario.seed, kTagClock));
    std::array<TremorState, kHandCount> tremor{};
    std::array<std::size_t, kHandCount> seg_i{}, drop_i{};
    std::size_t focus_i = 0;
    dvec3 look = sy.work_centre;
    const double dt_nominal = 1.0 / scenario.rate_hz;
    rec.frames.reserve(static_cast<std::size_t>(out.t_end * scenario.rate_hz) + 2);
    double t = 0.0, last_t = -dt_nominal;
    while (t <= out.t_end) {
        HandFrame f;
        f.time = t;
        std::array<dvec3, kHandCount> clean_tip{};
        for (int h = 0; h < kHandCount; ++h) {
            const std::size_t hi = static_cast<std::size_t>(h);
            const Track& tr = sy.tracks[hi];
            const HandPersona& hp = sy.person.hand[hi];
            while (seg_i[hi] + 1 < tr.segs.size() && tr.segs[seg_i[hi]].t1 <= t) ++seg_i[hi];
            const Instant in = evaluate(sy, tr.hand, tr.segs[seg_i[hi]], t);
            HandState hs = pose_instant(sy, tr.hand, in);
            clean_tip[hi] = to_d(hs[Joint::IndexTip].pose.position);

            // Tremor: 8–12 Hz, frequency and phase drifting, mostly along the back of the hand.
            const double dt = t - last_t;
            const double freq = hp.tremor_f0 + 0.8 * std::sin(kTwoPi * t / 6.1 + hp.tremor_p1) +
                                0.4 * std::sin(kTwoPi * t / 2.3 + hp.tremor_p2);
            tremor[hi].phase += kTwoPi * freq * dt + 0.04 * noise.normal_clamped(3.0);
            const double env = 1.0 + 0.2 * std::sin(kTwoPi * 0.13 * t + hp.tremor_p3);
            const dvec3 tremor_vec = in.rot * dvec3(0.5 * std::sin(tremor[hi].phase + 1.3), std::sin(tremor[hi].phase), 0.0) *
                                     (hp.tremor_amp * env);
            if (scenario.noise) add_noise(hs, noise, tremor_vec);

            const auto& drops = dropouts[hi];
            while (drop_i[hi] < drops.size() && drops[drop_i[hi]].t1 <= t) ++drop_i[hi];
            if (drop_i[hi] < drops.size() && drops[drop_i[hi]].t0 <= t) hs = lost_hand(drops[drop_i[hi]].quirk);
            f.hands[hi] = hs;
        }

        // Head: standing, eyes at about 1.65 m, swaying slightly, watching the drawing hand and
        // the tree (smoothed with a 0.35 s time constant).
        while (focus_i + 1 < out.focus.size() && out.focus[focus_i + 1].first <= t) ++focus_i;
        const dvec3 want = 0.5 * clean_tip[static_cast<std::size_t>(out.focus[focus_i].second)] + 0.5 * sy.work_centre;
        look += (want - look) * (1.0 - std::exp(-(t - last_t) / 0.35));
        const dvec3 head = dvec3(0.0, sy.person.eye_height, 0.0) + sy.person.head_sway.at(t);
        f.head.position = glm::vec3(head);
        f.head.orientation = glm::quat(look_frame(look - head, dvec3(0.0, 1.0, 0.0)));
        f.head_valid = true;
        rec.frames.push_back(f);

        last_t = t;
        t += dt_nominal + (scenario.noise ? clock.uniform(-0.0005, 0.0005) : 0.0);
    }
    result.truth = std::move(out.truth);
    result.spans = std::move(out.spans);
    result.surfaces = scenario.surfaces;
    return result;
}

} // namespace lobe
