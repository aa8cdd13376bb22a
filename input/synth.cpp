// The synthesizer's top level: the scenario's steps become both hands' timelines
// (synth_motion.cpp), drop-outs are scheduled over them (synth_tracking.cpp), and the frames
// are sampled at the scenario's rate with noise, tremor and a head that watches the work.
// Scenario files: synth_scenario.cpp; ground truth: synth_truth.cpp.
#include "input/synth.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include <glm/gtc/quaternion.hpp>

#include "input/synth_geometry.h"
#include "input/synth_motion.h"
#include "input/synth_random.h"
#include "input/synth_scenario.h"
#include "input/synth_tracking.h"

namespace lobe {

namespace {

using namespace synth;

using Dropouts = std::array<std::vector<Dropout>, kHandCount>;

/// Where the work is (the head looks there between strokes): the mean control point of the
/// strokes and drags; the default when there are none.
void find_work_centre(Synth& sy, const Scenario& scenario)
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

/// Both hands' timelines, step by step (each step from its own random stream): the hand a
/// step uses does it while the other goes to rest; keys are pressed and released; pauses
/// pass. Both hands start at rest and idle 0.6 s before the first step and 0.8 s after the
/// last.
/// \throw InvalidInput when the scenario lasts more than kMaxDurationS or needs more than
///        kMaxRecordingFrames frames.
Build plan_timelines(Synth& sy, const Scenario& scenario)
{
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
    return out;
}

/// Adds a span per drop-out to `spans` and sorts them all by start (stably).
void add_dropout_spans(std::vector<SynthSpan>& spans, const Dropouts& dropouts)
{
    for (int h = 0; h < kHandCount; ++h)
        for (const Dropout& d : dropouts[static_cast<std::size_t>(h)]) {
            SynthSpan sp;
            sp.type = SynthSpan::Type::Dropout;
            sp.hand = static_cast<Hand>(h);
            sp.t_begin = sp.t_peak_begin = d.t0;
            sp.t_end = sp.t_peak_end = d.t1;
            spans.push_back(sp);
        }
    std::stable_sort(spans.begin(), spans.end(),
                     [](const SynthSpan& a, const SynthSpan& b) { return a.t_begin < b.t_begin; });
}

/// The frames, every 1/rate (± 0.5 ms with noise) from t = 0 to `out.t_end`: both hands posed
/// from their timelines, with tremor, jitter and drop-outs; the head standing, eyes at about
/// 1.65 m, swaying slightly, watching the drawing hand and the work (smoothed with a 0.35 s
/// time constant).
void sample_frames(const Synth& sy, const Build& out, const Scenario& scenario, const Dropouts& dropouts,
                   Recording& rec)
{
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

            const dvec3 tremor_vec = tremor_offset(tremor[hi], hp, in.rot, t, t - last_t, noise);
            if (scenario.noise) add_noise(hs, noise, tremor_vec);

            const auto& drops = dropouts[hi];
            while (drop_i[hi] < drops.size() && drops[drop_i[hi]].t1 <= t) ++drop_i[hi];
            if (drop_i[hi] < drops.size() && drops[drop_i[hi]].t0 <= t) hs = lost_hand(drops[drop_i[hi]].quirk);
            f.hands[hi] = hs;
        }

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
}

} // namespace

SynthResult synthesize(const Scenario& scenario)
{
    validate_scenario(scenario);
    Synth sy;
    sy.person = make_person(scenario.seed, scenario.uniform_joint_radius_m);
    sy.surfaces = scenario.surfaces;
    find_work_centre(sy, scenario);
    Build out = plan_timelines(sy, scenario);

    const Dropouts dropouts = scenario.dropouts ? schedule_dropouts(sy, scenario.seed) : Dropouts{};
    add_dropout_spans(out.spans, dropouts);

    SynthResult result;
    Recording& rec = result.recording;
    rec.header.source = "synth";
    rec.header.device = "synthetic hand";
    rec.header.nominal_rate_hz = scenario.rate_hz;
    rec.header.created = "";
    rec.events = out.events;
    sample_frames(sy, out, scenario, dropouts, rec);
    result.truth = std::move(out.truth);
    result.spans = std::move(out.spans);
    result.surfaces = scenario.surfaces;
    return result;
}

} // namespace lobe
