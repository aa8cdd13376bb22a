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
#include "input/synth_random.h"
#include "input/synth_scenario.h"
#include "input/tools.h"

namespace lobe {

namespace synth {

namespace {

namespace hm = hand_model;
using json = nlohmann::json;

/// Peak speed of a stroke: the scenario's, or drawn from [0.3, 0.85] m/s and bent so that the
/// stroke takes 1–3.6 s where the range allows (drags: 0.6–3.6 s, any speed from 0.05 m/s).
double choose_speed(const ScenarioStroke& st, double length, bool drag, Rng& rng)
{
    double pick = rng.uniform(0.3, 0.85);
    if (st.speed_mps > 0.0) return st.speed_mps;
    const double min_s = drag ? 0.6 : 1.0, max_s = 3.6;
    double v = std::clamp(pick, 1.875 * length / max_s, 1.875 * length / min_s);
    return drag ? std::clamp(v, kMinSpeed, 1.0) : std::clamp(v, 0.2, 1.0);
}

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

struct Person {
    hm::HandShape shape;
    std::array<HandPersona, kHandCount> hand;
    double eye_height = 1.65;
    Sway head_sway;
};

Person make_person(std::uint64_t seed, double uniform_radius)
{
    Rng rng(stream_seed(seed, kTagPerson));
    Person p;
    p.shape = hm::make_hand_shape(static_cast<float>(rng.uniform(0.94, 1.06)), static_cast<float>(uniform_radius));
    p.eye_height = rng.uniform(1.61, 1.69);
    for (int h = 0; h < kHandCount; ++h) {
        const double side = h == static_cast<int>(Hand::Right) ? 1.0 : -1.0;
        HandPersona& hp = p.hand[static_cast<std::size_t>(h)];
        hp.shoulder = dvec3(0.18 * side, p.eye_height - 0.23, 0.02);
        // z, y, x: the order the shipped recordings were made in (see normal3).
        const double rest_z = -rng.uniform(0.18, 0.26), rest_y = p.eye_height - rng.uniform(0.60, 0.66);
        hp.rest = dvec3(side * rng.uniform(0.19, 0.24), rest_y, rest_z);
        hp.roll = side * rng.uniform(0.5, 0.7);
        hp.rest_sway = Sway::random(rng, 0.006, 0.1, 0.35);
        hp.hover = Sway::random(rng, 0.003, 0.15, 0.45);
        hp.wobble = Sway::random(rng, 0.04, 0.1, 0.4);
        hp.tremor_f0 = rng.uniform(9.3, 10.4);
        hp.tremor_amp = rng.uniform(0.0006, 0.0008);
        hp.tremor_p1 = rng.uniform(0.0, kTwoPi);
        hp.tremor_p2 = rng.uniform(0.0, kTwoPi);
        hp.tremor_p3 = rng.uniform(0.0, kTwoPi);
    }
    p.head_sway = Sway::random(rng, 0.008, 0.12, 0.3);
    return p;
}

/// Orientation of a hand whose index tip is at `tip`: the fingers point away from the
/// shoulder, the back of the hand faces up, rolled outwards (palm down and inwards, the
/// usual pinch-drawing posture).
dquat aim_rotation(const HandPersona& hp, const dvec3& tip)
{
    dvec3 f = safe_normalize(tip - hp.shoulder, dvec3(0.0, 0.0, -1.0));
    dvec3 up(0.0, 1.0, 0.0);
    dvec3 y0 = up - glm::dot(up, f) * f;
    if (glm::length(y0) < 1e-3) y0 = dvec3(0.0, 0.0, -1.0) - f.z * f;
    y0 = glm::normalize(y0);
    dvec3 y = y0 * std::cos(hp.roll) + glm::cross(f, y0) * std::sin(hp.roll);
    return look_frame(f, y);
}

/// A slow wobble of a few degrees on top of the aim.
dquat wobble_rotation(const HandPersona& hp, double t)
{
    dvec3 w = hp.wobble.at(t);
    return axis_angle(dvec3(1, 0, 0), w.x) * axis_angle(dvec3(0, 1, 0), w.y) * axis_angle(dvec3(0, 0, 1), w.z);
}

dquat hand_rotation(const HandPersona& hp, const dvec3& tip, double t)
{
    return glm::normalize(aim_rotation(hp, tip) * wobble_rotation(hp, t));
}

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

Artic blend(const Artic& a, const Artic& b, double uf, double ut)
{
    auto mix = [](double x, double y, double u) { return x + (y - x) * u; };
    Artic r;
    r.index_curl = mix(a.index_curl, b.index_curl, uf);
    r.other_curl = mix(a.other_curl, b.other_curl, uf);
    r.spread = mix(a.spread, b.spread, uf);
    r.grab = mix(a.grab, b.grab, uf);
    r.thumb_gap = mix(a.thumb_gap, b.thumb_gap, ut);
    r.grab_thumb = mix(a.grab_thumb, b.grab_thumb, ut);
    r.fist_beta = mix(a.fist_beta, b.fist_beta, ut);
    return r;
}

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

Instant evaluate(const Synth& sy, Hand hand, const Segment& s, double t)
{
    const HandPersona& hp = sy.persona(hand);
    const double span = s.t1 - s.t0;
    const double u = span > 0.0 ? std::clamp((t - s.t0) / span, 0.0, 1.0) : 1.0;
    double ut = u;
    if (s.thumb_lag > 0.0) ut = std::clamp((u - s.thumb_lag) / (1.0 - s.thumb_lag), 0.0, 1.0);
    if (s.thumb_lag < 0.0) ut = std::clamp(u / (1.0 + s.thumb_lag), 0.0, 1.0);
    Instant in;
    in.art = blend(s.k0, s.k1, min_jerk(u), min_jerk(ut));
    switch (s.motion) {
    case Motion::Hold: in.anchor = s.a; break;
    case Motion::Hover: in.anchor = s.a + hp.hover.at(t) - hp.hover.at(s.t0); break;
    case Motion::Rest: in.anchor = hp.rest + hp.rest_sway.at(t); break;
    case Motion::Move: {
        double m = min_jerk(u);
        in.anchor = (1.0 - m) * (1.0 - m) * s.a + 2.0 * (1.0 - m) * m * s.c + m * m * s.b;
        break;
    }
    case Motion::Draw: {
        const DenseCurve& c = sy.curves[static_cast<std::size_t>(s.curve)];
        in.anchor = c.at(c.length() * min_jerk(u));
        break;
    }
    case Motion::PalmHold:
        in.anchor = s.a;
        in.palm_anchor = true;
        break;
    }
    // A grab keeps its aim fixed; everything else aims from the shoulder to the index tip.
    in.rot = s.motion == Motion::PalmHold ? glm::normalize(s.rot * wobble_rotation(hp, t))
                                          : hand_rotation(hp, in.anchor, t);
    return in;
}

/// The hand in the wrist frame for an articulation (right-hand coordinates).
hm::LocalHand local_hand(const Synth& sy, const Artic& art)
{
    const hm::HandShape& shape = sy.person.shape;
    hm::Articulation a;
    const double idx_curl = art.index_curl + (1.0 - art.index_curl) * art.grab;
    const double oth_curl = art.other_curl + (1.0 - art.other_curl) * art.grab;
    static constexpr std::array<double, 5> spread_pattern = {0.0, 1.0, 0.15, 0.7, 1.4};
    for (int f = hm::kIndex; f <= hm::kLittle; ++f) {
        a.curl[f] = static_cast<float>(f == hm::kIndex ? idx_curl : oth_curl);
        a.spread[f] = static_cast<float>(art.spread * spread_pattern[static_cast<std::size_t>(f)]);
    }
    hm::LocalHand local;
    hm::pose_fingers(shape, a, local);

    const dvec3 idx_tip = to_d(local[idx(Joint::IndexTip)].position);
    const double radii = static_cast<double>(shape.radius[idx(Joint::ThumbTip)]) + shape.radius[idx(Joint::IndexTip)];
    const double s = std::clamp(1.0 - art.thumb_gap / sy.gap_ref, 0.0, 1.0);
    const dvec3 pinch = idx_tip + slerp_dir(sy.dir_open, sy.dir_contact, s) * (radii + art.thumb_gap);
    dvec3 target = pinch;
    if (art.grab_thumb > 0.0) {
        const dvec3 mid = 0.5 * (to_d(local[idx(Joint::IndexIntermediate)].position) +
                                 to_d(local[idx(Joint::IndexDistal)].position));
        const double side = static_cast<double>(shape.radius[idx(Joint::ThumbTip)]) +
                            shape.radius[idx(Joint::IndexIntermediate)];
        const dvec3 fist = mid + (idx_tip - mid) * art.fist_beta + dvec3(-0.9 * side, 0.0, 0.0);
        target = pinch + (fist - pinch) * art.grab_thumb;
    }
    hm::pose_thumb(shape, glm::vec3(target), local);
    return local;
}

HandState pose_instant(const Synth& sy, Hand hand, const Instant& in)
{
    const hm::LocalHand local = local_hand(sy, in.art);
    const Joint anchor_joint = in.palm_anchor ? Joint::Palm : Joint::IndexTip;
    const dvec3 anchor_local = to_d(hm::mirror(local[idx(anchor_joint)].position, hand));
    const dvec3 translation = in.anchor - in.rot * anchor_local;
    return hm::place_hand(sy.person.shape, local, hand, glm::quat(in.rot), glm::vec3(translation));
}

/// Appends a segment starting where the track is, and moves the track to its end.
void append(Synth& sy, Track& tr, Segment s, double duration)
{
    s.t0 = tr.t;
    s.t1 = tr.t + duration;
    s.k0 = tr.art;
    tr.t = s.t1;
    tr.art = s.k1;
    Instant end = evaluate(sy, tr.hand, s, s.t1);
    if (end.palm_anchor) {
        HandState hs = pose_instant(sy, tr.hand, end);
        tr.tip = to_d(hs[Joint::IndexTip].pose.position);
    } else {
        tr.tip = end.anchor;
    }
    tr.segs.push_back(s);
}

/// Keeps the hand where it is (relaxed at its rest place, or hovering) until `t_end`.
void idle_until(Synth& sy, Track& tr, double t_end)
{
    if (t_end <= tr.t + 1e-9) return;
    Segment s;
    s.motion = tr.at_rest ? Motion::Rest : Motion::Hover;
    s.a = tr.tip;
    s.k1 = tr.art;
    s.drop = DropZone::Long;
    append(sy, tr, s, t_end - tr.t);
}

/// Holds the index tip still while the fingers change (thumb closing or opening, settling).
void hold(Synth& sy, Track& tr, double duration, const Artic& to, DropZone drop, double thumb_lag = 0.0)
{
    Segment s;
    s.motion = Motion::Hold;
    s.a = tr.tip;
    s.k1 = to;
    s.drop = drop;
    s.thumb_lag = thumb_lag;
    append(sy, tr, s, duration);
}

/// Moves the index tip to `target` along a smooth arc that bulges up and towards the body.
void move_to(Synth& sy, Track& tr, const dvec3& target, const Artic& to, Rng& rng)
{
    const dvec3 from = tr.tip;
    const double dist = glm::distance(from, target);
    const double duration = std::clamp(0.45 + 1.3 * dist + rng.uniform(0.0, 0.15), 0.45, 2.5);
    Segment s;
    s.motion = Motion::Move;
    s.a = from;
    s.b = target;
    s.c = 0.5 * (from + target) + dvec3(0.0, 0.3, 0.5) * std::min(0.25 * dist, 0.08);
    s.k1 = to;
    s.drop = DropZone::Long;
    append(sy, tr, s, duration);
    tr.at_rest = false;
}

/// Takes the hand back to its rest place (over about a second) and lets it hang there.
void go_rest(Synth& sy, Track& tr, Rng& rng)
{
    const HandPersona& hp = sy.persona(tr.hand);
    const double duration = rng.uniform(0.8, 1.1);
    Artic relaxed;
    Segment s;
    s.motion = Motion::Move;
    s.a = tr.tip;
    s.b = hp.rest + hp.rest_sway.at(tr.t + duration);
    s.c = 0.5 * (s.a + s.b) + dvec3(0.0, 0.0, 0.03);
    s.k1 = relaxed;
    s.drop = DropZone::Long;
    append(sy, tr, s, duration);
    tr.at_rest = true;
}

Artic approach_pose(Rng& rng)
{
    Artic a;
    a.index_curl = rng.uniform(0.53, 0.58);
    // Middle, ring and little relaxed: below 0.3 both as 1 − |tip − proximal| / chain length
    // and as bend angles / 270° (the gesture recogniser refuses pinches from 0.35 up).
    a.other_curl = rng.uniform(0.18, 0.28);
    a.spread = rng.uniform(0.05, 0.09);
    a.thumb_gap = rng.uniform(0.055, 0.075);
    return a;
}

struct Build {
    std::vector<GroundTruthStroke> truth;
    std::vector<SynthSpan> spans;
    std::vector<InputEvent> events;
    std::vector<std::pair<double, Hand>> focus; ///< which hand the head watches, from when
    double t_end = 0.0;
};

/// Pinch, follow the curve, release (strokes and drags).
void build_stroke(Synth& sy, Build& out, const ScenarioStep& step, Rng& rng)
{
    const ScenarioStroke& sk = step.stroke;
    const int curve_id = static_cast<int>(sy.curves.size());
    sy.curves.push_back(densify(sk.curve, sk.closed));
    if (sk.surface >= 0) on_surface(sy.curves.back(), sy.surfaces[static_cast<std::size_t>(sk.surface)]);
    const DenseCurve& curve = sy.curves.back();
    const bool drag = step.type == ScenarioStep::Type::Drag;
    const double speed = choose_speed(sk, curve.length(), drag, rng);
    const double draw_s = std::max(1.875 * curve.length() / speed, 0.1);

    Track& tr = sy.track(sk.hand);
    Artic ready = approach_pose(rng);
    move_to(sy, tr, curve.p.front(), ready, rng);
    hold(sy, tr, rng.uniform(0.12, 0.25), ready, DropZone::Long); // settle
    Artic pinched = ready;
    pinched.thumb_gap = rng.uniform(-0.001, 0.0005); // leap-pinch.json settles at about -1…0 mm
    hold(sy, tr, rng.uniform(0.2, 0.4), pinched, DropZone::None); // thumb closes, index still
    GroundTruthStroke gt;
    gt.t_begin = tr.t;
    hold(sy, tr, rng.uniform(0.08, 0.15), pinched, DropZone::None);
    Segment d;
    d.motion = Motion::Draw;
    d.curve = curve_id;
    d.k1 = pinched;
    d.drop = DropZone::Short;
    append(sy, tr, d, draw_s);
    hold(sy, tr, rng.uniform(0.1, 0.2), pinched, DropZone::None);
    gt.t_end = tr.t;
    Artic open = pinched;
    open.thumb_gap = rng.uniform(0.055, 0.075);
    hold(sy, tr, rng.uniform(0.2, 0.4), open, DropZone::None); // thumb opens, index still

    gt.kind = sk.kind;
    gt.hand = sk.hand;
    gt.closed = sk.closed;
    gt.drag = drag;
    gt.surface = sk.surface;
    gt.points = resample(curve);
    out.truth.push_back(std::move(gt));
}

void build_near_pinch(Synth& sy, Build& out, const ScenarioStep& step, Rng& rng)
{
    Track& tr = sy.track(step.hand);
    Artic ready = approach_pose(rng);
    move_to(sy, tr, to_d(step.where), ready, rng);
    hold(sy, tr, rng.uniform(0.12, 0.25), ready, DropZone::Long);
    Artic near = ready;
    near.thumb_gap = rng.uniform(0.0145, 0.0175); // closes, but stays clear of a pinch (12–20 mm)
    SynthSpan sp;
    sp.type = SynthSpan::Type::NearPinch;
    sp.hand = step.hand;
    sp.t_begin = tr.t;
    hold(sy, tr, 0.4 * step.duration_s, near, DropZone::None);
    sp.t_peak_begin = tr.t;
    hold(sy, tr, 0.2 * step.duration_s, near, DropZone::None);
    sp.t_peak_end = tr.t;
    Artic open = ready;
    open.thumb_gap = rng.uniform(0.055, 0.075);
    hold(sy, tr, 0.4 * step.duration_s, open, DropZone::None);
    sp.t_end = tr.t;
    out.spans.push_back(sp);
}

void build_grab(Synth& sy, Build& out, const ScenarioStep& step, Rng& rng)
{
    Track& tr = sy.track(step.hand);
    const HandPersona& hp = sy.persona(step.hand);
    Artic open;
    open.index_curl = rng.uniform(0.2, 0.3);
    open.other_curl = rng.uniform(0.25, 0.35);
    open.spread = rng.uniform(0.08, 0.12);
    open.thumb_gap = rng.uniform(0.06, 0.075);
    open.fist_beta = rng.uniform(0.0, 0.4); // thumb–index tips end 6–14 mm apart (leap-grab.json: down to -6 mm)

    // Where the index tip must be so that the palm is at `where` when the grab starts: a
    // fixed point, since the aim depends on the tip.
    const dvec3 palm = to_d(step.where);
    const hm::LocalHand local = local_hand(sy, open);
    const dvec3 offset = to_d(hm::mirror(local[idx(Joint::IndexTip)].position - local[idx(Joint::Palm)].position, step.hand));
    dquat aim(1.0, 0.0, 0.0, 0.0);
    auto tip_for = [&](double t_start) {
        dvec3 tip = palm;
        for (int it = 0; it < 10; ++it) {
            aim = aim_rotation(hp, tip);
            tip = palm + glm::normalize(aim * wobble_rotation(hp, t_start)) * offset;
        }
        return tip;
    };
    move_to(sy, tr, tip_for(tr.t + 1.0), open, rng);
    // A last few millimetres to the exact spot for the moment the grab starts.
    const double settle = rng.uniform(0.12, 0.2);
    Segment fix;
    fix.motion = Motion::Move;
    fix.a = tr.tip;
    fix.b = tip_for(tr.t + settle);
    fix.c = 0.5 * (fix.a + fix.b);
    fix.k1 = open;
    fix.drop = DropZone::Long;
    append(sy, tr, fix, settle);

    Artic fist = open;
    fist.grab = 1.0;
    fist.grab_thumb = 1.0;
    auto palm_hold = [&](double duration, const Artic& to, double lag) {
        Segment s;
        s.motion = Motion::PalmHold;
        s.a = palm;
        s.rot = aim;
        s.k1 = to;
        s.thumb_lag = lag;
        append(sy, tr, s, duration);
    };
    SynthSpan sp;
    sp.type = SynthSpan::Type::Grab;
    sp.hand = step.hand;
    sp.t_begin = tr.t;
    palm_hold(0.35 * step.duration_s, fist, 0.35); // fingers first, the thumb folds over last
    sp.t_peak_begin = tr.t;
    palm_hold(0.3 * step.duration_s, fist, 0.0);
    sp.t_peak_end = tr.t;
    palm_hold(0.35 * step.duration_s, open, -0.35); // the thumb leaves first
    sp.t_end = tr.t;
    out.spans.push_back(sp);
}

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
