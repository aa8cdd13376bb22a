#pragma once
/// \file synth_motion.h
/// The synthesizer's person and hand motion (input/synth.h; not included outside input/):
/// a person with a body, two hands of one articulated shape (input/hand_model.h) and the
/// slow motions that make a hand look alive, and per hand a timeline of segments covering
/// the whole recording (hold, hover, rest, move, draw, palm hold), each blending the finger
/// articulation between its ends with minimum-jerk timing. Metres, seconds, radians.
/// What the hand does and why the numbers: docs/scenario-format.md, "What the synthesizer
/// adds".

#include <array>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>

#include "core/hand_frame.h"
#include "input/hand_model.h"
#include "input/recording.h"
#include "input/synth.h"
#include "input/synth_geometry.h"
#include "input/synth_random.h"

namespace lobe::synth {

// ---------------------------------------------------------------------------------------
// The person: body, hands and the slow motions that make a hand look alive
// ---------------------------------------------------------------------------------------

/// A sum of sines per axis (slow sway, hovering drift, head motion).
struct Sway {
    std::array<std::array<double, 2>, 3> amp{}, freq{}, phase{};

    static Sway random(Rng& rng, double amplitude, double f_lo, double f_hi)
    {
        Sway s;
        for (int a = 0; a < 3; ++a)
            for (int k = 0; k < 2; ++k) {
                s.amp[a][k] = amplitude * (k == 0 ? 0.7 : 0.3) * rng.uniform(0.6, 1.2);
                s.freq[a][k] = rng.uniform(f_lo, f_hi) * (k == 0 ? 1.0 : 2.3);
                s.phase[a][k] = rng.uniform(0.0, kTwoPi);
            }
        return s;
    }
    dvec3 at(double t) const
    {
        dvec3 v(0.0);
        for (int a = 0; a < 3; ++a)
            for (int k = 0; k < 2; ++k) v[a] += amp[a][k] * std::sin(kTwoPi * freq[a][k] * t + phase[a][k]);
        return v;
    }
};

/// One hand of the person: where it rests and how it sways, wobbles and trembles.
struct HandPersona {
    dvec3 shoulder{0.0};
    dvec3 rest{0.0};      ///< index tip of the relaxed hand
    double roll = 0.0;    ///< pronation of the drawing hand about the finger axis
    Sway rest_sway;       ///< relaxed hand
    Sway hover;           ///< hand held up, waiting
    Sway wobble;          ///< small orientation wobble (radians)
    // Physiological tremor (8–12 Hz): whole hand, drifting frequency and phase.
    double tremor_f0 = 9.8, tremor_amp = 0.0007, tremor_p1 = 0.0, tremor_p2 = 0.0, tremor_p3 = 0.0;
};

/// The person drawing: the hand shape, both hands, the eye height and the head's sway.
struct Person {
    hand_model::HandShape shape;
    std::array<HandPersona, kHandCount> hand;
    double eye_height = 1.65;
    Sway head_sway;
};

/// A person drawn from the scenario seed (its kTagPerson stream): hand size 0.94–1.06 of the
/// calibrated hand, eye height 1.61–1.69 m, rest places, sways and tremor of both hands.
/// `uniform_radius` > 0 gives every joint that radius.
Person make_person(std::uint64_t seed, double uniform_radius);

// ---------------------------------------------------------------------------------------
// The timeline: per hand, a list of segments covering the whole recording
// ---------------------------------------------------------------------------------------

/// What the fingers do (blended between the ends of a segment).
struct Artic {
    double index_curl = 0.3;
    double other_curl = 0.4;
    double spread = 0.08;     ///< radians
    double thumb_gap = 0.06;  ///< wanted thumb–index tip gap, metres (surfaces, not centres)
    double grab = 0.0;        ///< fingers: 0 as above … 1 fist
    double grab_thumb = 0.0;  ///< thumb: 0 pinch family … 1 across the curled index
    double fist_beta = 0.2;   ///< where the thumb lies in a fist (0 index middle phalanx … 1 its tip)
};

enum class Motion : std::uint8_t {
    Hold,     ///< index tip still at `a`
    Hover,    ///< index tip near `a`, drifting a few millimetres
    Rest,     ///< relaxed hand at the persona's rest position, swaying
    Move,     ///< index tip along a quadratic Bézier a → c → b, minimum-jerk timing
    Draw,     ///< index tip along a stroke curve, minimum-jerk timing
    PalmHold, ///< palm still at `a` with a fixed orientation `rot` (grabs)
};

/// Where a tracking drop-out may fall.
enum class DropZone : std::uint8_t { None, Short, Long };

/// A stretch [t0, t1] of one hand's timeline: how its anchor moves, and the articulation
/// blended from k0 to k1.
struct Segment {
    double t0 = 0.0, t1 = 0.0;
    Motion motion = Motion::Hold;
    dvec3 a{0.0}, b{0.0}, c{0.0};
    int curve = -1;
    dquat rot{1.0, 0.0, 0.0, 0.0};
    Artic k0, k1;
    double thumb_lag = 0.0; ///< > 0: the thumb starts later; < 0: it finishes earlier
    DropZone drop = DropZone::None;
};

/// One hand's timeline so far and where it ends (the next segment starts there).
struct Track {
    Hand hand = Hand::Right;
    std::vector<Segment> segs;
    dvec3 tip{0.0};
    Artic art;
    bool at_rest = true;
    double t = 0.0;
};

/// What a hand looks like at one instant, before noise.
struct Instant {
    dvec3 anchor{0.0};
    bool palm_anchor = false;
    dquat rot{1.0, 0.0, 0.0, 0.0};
    Artic art;
};

/// What the frames are made from: the person, the lobe surfaces, the densified stroke curves
/// (Segment::curve indexes them) and both hands' timelines.
struct Synth {
    Person person;
    std::vector<TruthSurface> surfaces;
    std::vector<DenseCurve> curves;
    std::array<Track, kHandCount> tracks;
    dvec3 work_centre{0.0, 1.3, -0.45};
    // Pinch family: direction from the index tip to the thumb tip (right-hand wrist frame),
    // wide open and in contact. Tuned so the thumb reaches both with the index curled 0.55.
    dvec3 dir_open = glm::normalize(dvec3(-0.85, 0.35, 0.4));
    dvec3 dir_contact = glm::normalize(dvec3(-0.6, -0.2, 0.75));
    double gap_ref = 0.065; ///< gap at which the thumb is fully in its open direction

    Track& track(Hand h) { return tracks[static_cast<std::size_t>(h)]; }
    const HandPersona& persona(Hand h) const { return person.hand[static_cast<std::size_t>(h)]; }
};

/// What the steps produce besides the hand timelines.
struct Build {
    std::vector<GroundTruthStroke> truth;
    std::vector<SynthSpan> spans;
    std::vector<InputEvent> events;
    std::vector<std::pair<double, Hand>> focus; ///< which hand the head watches, from when
    double t_end = 0.0;
};

/// The hand on segment `s` at time `t` (clamped to the segment), before noise.
Instant evaluate(const Synth& sy, Hand hand, const Segment& s, double t);

/// Every joint of the hand at an instant: the articulated hand placed so that its anchor
/// joint (index tip, or palm for a palm hold) is at `in.anchor` with rotation `in.rot`.
HandState pose_instant(const Synth& sy, Hand hand, const Instant& in);

/// Keeps the hand where it is (relaxed at its rest place, or hovering) until `t_end`.
void idle_until(Synth& sy, Track& tr, double t_end);

/// Takes the hand back to its rest place (over about a second) and lets it hang there.
void go_rest(Synth& sy, Track& tr, Rng& rng);

/// Pinch, follow the curve, release (Stroke and Drag steps): appends the hand's segments,
/// the densified curve to `sy.curves` and the ground-truth stroke to `out.truth`.
void build_stroke(Synth& sy, Build& out, const ScenarioStep& step, Rng& rng);

/// A thumb that closes to 14.5–17.5 mm of the index and opens again without pinching; the
/// span goes to `out.spans`.
void build_near_pinch(Synth& sy, Build& out, const ScenarioStep& step, Rng& rng);

/// A fist made and opened with the palm held at `step.where`; the span goes to `out.spans`.
void build_grab(Synth& sy, Build& out, const ScenarioStep& step, Rng& rng);

} // namespace lobe::synth
