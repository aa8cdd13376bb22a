#include "input/synth_motion.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include <glm/geometric.hpp>

#include "input/synth_scenario.h"

namespace lobe::synth {

namespace hm = hand_model;

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
        // z, y, x: the order the shipped recordings were made in (see normal3 in
        // synth_tracking.cpp).
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

namespace {

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

} // namespace

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

namespace {

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

} // namespace

HandState pose_instant(const Synth& sy, Hand hand, const Instant& in)
{
    const hm::LocalHand local = local_hand(sy, in.art);
    const Joint anchor_joint = in.palm_anchor ? Joint::Palm : Joint::IndexTip;
    const dvec3 anchor_local = to_d(hm::mirror(local[idx(anchor_joint)].position, hand));
    const dvec3 translation = in.anchor - in.rot * anchor_local;
    return hm::place_hand(sy.person.shape, local, hand, glm::quat(in.rot), glm::vec3(translation));
}

namespace {

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

} // namespace

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

namespace {

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

} // namespace

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

namespace {

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

} // namespace

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

} // namespace lobe::synth
