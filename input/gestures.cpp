#include "input/gestures.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

namespace lobe {

namespace {

// Fallback tip radii when a runtime reports none (or nonsense): typical adult thumb and index
// tip radii as OpenXR runtimes report them.
constexpr float kDefaultThumbTipRadius = 0.009f;
constexpr float kDefaultIndexTipRadius = 0.008f;
// A hand within this distance of the stage origin or of the head has snapped there: no real
// hand is ever that close to the floor origin, and the head pose is the centre of the skull.
constexpr float kOriginSnap = 0.02f;
constexpr float kHeadSnap = 0.06f;

// Joint chains whose bend angles make a finger's curl: metacarpal, proximal, intermediate,
// distal, tip (the thumb has no intermediate: its chain starts at the wrist).
constexpr Joint kFingerJoints[5][5] = {
    {Joint::Wrist, Joint::ThumbMetacarpal, Joint::ThumbProximal, Joint::ThumbDistal, Joint::ThumbTip},
    {Joint::IndexMetacarpal, Joint::IndexProximal, Joint::IndexIntermediate, Joint::IndexDistal, Joint::IndexTip},
    {Joint::MiddleMetacarpal, Joint::MiddleProximal, Joint::MiddleIntermediate, Joint::MiddleDistal, Joint::MiddleTip},
    {Joint::RingMetacarpal, Joint::RingProximal, Joint::RingIntermediate, Joint::RingDistal, Joint::RingTip},
    {Joint::LittleMetacarpal, Joint::LittleProximal, Joint::LittleIntermediate, Joint::LittleDistal, Joint::LittleTip},
};
// Total flexion of a fully folded finger (knuckle ~90°, middle joint ~110°, last joint ~70°).
constexpr float kFullCurlRadians = 4.712389f; // 270°

// The joints every decision here reads.
constexpr Joint kNeeded[] = {Joint::Palm, Joint::ThumbTip, Joint::IndexTip,
                             Joint::IndexMetacarpal, Joint::IndexProximal, Joint::IndexIntermediate, Joint::IndexDistal,
                             Joint::MiddleMetacarpal, Joint::MiddleProximal, Joint::MiddleIntermediate, Joint::MiddleDistal, Joint::MiddleTip,
                             Joint::RingMetacarpal, Joint::RingProximal, Joint::RingIntermediate, Joint::RingDistal, Joint::RingTip,
                             Joint::LittleMetacarpal, Joint::LittleProximal, Joint::LittleIntermediate, Joint::LittleDistal, Joint::LittleTip};

float usable_radius(float r, float fallback)
{
    return (std::isfinite(r) && r > 0.001f && r < 0.03f) ? r : fallback;
}

bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

} // namespace

float finger_curl(const HandState& hand, int finger)
{
    // Sum of the bend angles along the chain. A distance ratio (tip to knuckle over bone
    // length) misses flexion at the knuckle: in the shipped Leap grab clip the second fist
    // closes mostly there, with the distance ratio of middle/ring/little at only 0.27 while
    // their bend is 150–170°; in the pinch clip those fingers bend 55–80°.
    const Joint* j = kFingerJoints[finger];
    float bend = 0.0f;
    for (int k = 0; k + 2 < 5; ++k) {
        const glm::vec3 a = hand[j[k + 1]].pose.position - hand[j[k]].pose.position;
        const glm::vec3 b = hand[j[k + 2]].pose.position - hand[j[k + 1]].pose.position;
        const float la = glm::length(a), lb = glm::length(b);
        if (!(la > 1e-5f) || !(lb > 1e-5f)) continue;
        bend += std::acos(std::clamp(glm::dot(a, b) / (la * lb), -1.0f, 1.0f));
    }
    return std::clamp(bend / kFullCurlRadians, 0.0f, 1.0f);
}

GestureRecognizer::GestureRecognizer(const InputOptions& options) : options_(options)
{
    for (PerHand& p : per_) {
        p.index_filter = OneEuroFilter3(options.filter);
        p.index_gap_filter = OneEuroFilter3(options.gap_filter);
        p.thumb_gap_filter = OneEuroFilter3(options.gap_filter);
    }
}

void GestureRecognizer::end_all(HandGesture& g)
{
    if (g.pinching) g.pinch_ended = true;
    if (g.grabbing) g.grab_ended = true;
    if (g.pointing) g.point_ended = true;
    g.pinching = g.grabbing = g.pointing = false;
}

void GestureRecognizer::update_hand(int h, const HandFrame& frame)
{
    HandGesture& g = state_[h];
    PerHand& p = per_[h];
    const HandState& hs = frame.hands[h];
    g.pinch_started = g.pinch_ended = g.grab_started = g.grab_ended = false;
    g.point_started = g.point_ended = false;

    // 1. Is this hand really tracked this frame?
    HandLoss loss = HandLoss::None;
    if (!hs.active) {
        loss = HandLoss::Inactive;
    } else {
        for (Joint j : kNeeded)
            if (!hs[j].position_valid() || !finite(hs[j].pose.position)) loss = HandLoss::InvalidJoints;
    }
    const glm::vec3 palm = hs[Joint::Palm].pose.position;
    if (loss == HandLoss::None) {
        if (glm::length(palm) < kOriginSnap || glm::length(hs[Joint::IndexTip].pose.position) < kOriginSnap)
            loss = HandLoss::AtOrigin;
        else if (frame.head_valid && glm::distance(palm, frame.head.position) < kHeadSnap)
            loss = HandLoss::AtHead;
        else if (p.ever_tracked) {
            const double dt = frame.time - p.last_tracked_t;
            if (dt > 0 && dt < options_.bridge_loss_s &&
                glm::distance(palm, p.last_palm) / dt > options_.max_hand_speed_mps)
                loss = HandLoss::Jump;
        }
    }

    if (loss != HandLoss::None) {
        g.loss = loss;
        g.tracked = false;
        g.lost_for_s = p.ever_tracked ? frame.time - p.last_tracked_t : 0.0;
        p.index_filter.reset();
        p.index_gap_filter.reset();
        p.thumb_gap_filter.reset();
        p.below_since = -1.0;
        // A short loss is bridged: gestures hold. A long one ends them.
        if (!p.ever_tracked || g.lost_for_s > options_.bridge_loss_s) {
            end_all(g);
            p.armed = false;
        }
        return;
    }

    // 2. Tracked: filter the tips, measure the gap and the curls.
    g.loss = HandLoss::None;
    g.tracked = true;
    g.lost_for_s = 0.0;
    p.ever_tracked = true;
    p.last_tracked_t = frame.time;
    p.last_palm = palm;
    g.palm = palm;
    g.index_tip = p.index_filter.filter(hs[Joint::IndexTip].pose.position, frame.time);
    g.thumb_tip = p.thumb_gap_filter.filter(hs[Joint::ThumbTip].pose.position, frame.time);
    const glm::vec3 index_fast = p.index_gap_filter.filter(hs[Joint::IndexTip].pose.position, frame.time);
    const float r_thumb = usable_radius(hs[Joint::ThumbTip].radius, kDefaultThumbTipRadius);
    const float r_index = usable_radius(hs[Joint::IndexTip].radius, kDefaultIndexTipRadius);
    g.pinch_gap = glm::distance(index_fast, g.thumb_tip) - r_thumb - r_index;
    if (g.pinch_gap >= options_.pinch_start_m) p.armed = true;
    for (int f = 0; f < 5; ++f) g.curl[f] = finger_curl(hs, f);

    // 3. Grab: middle, ring and little all curled (hysteresis on the least curled one).
    const float others = std::min({g.curl[2], g.curl[3], g.curl[4]});
    const bool was_grabbing = g.grabbing;
    g.grabbing = was_grabbing ? others > options_.curl_release : others > options_.curl_grab;
    g.grab_started = g.grabbing && !was_grabbing;
    g.grab_ended = !g.grabbing && was_grabbing;

    // 4. Pinch: gap below the start threshold for pinch_min_hold_s while the hand is not
    // closing into a fist; released above the release threshold or when a grab begins.
    const bool was_pinching = g.pinching;
    const bool fist_forming = others > options_.curl_release;
    if (was_pinching) {
        g.pinching = g.pinch_gap < options_.pinch_release_m && !g.grabbing;
    } else if (p.armed && g.pinch_gap < options_.pinch_start_m && !fist_forming) {
        if (p.below_since < 0) p.below_since = frame.time;
        g.pinching = frame.time - p.below_since >= options_.pinch_min_hold_s - 1e-9;
    } else {
        p.below_since = -1.0;
    }
    if (!g.pinching && was_pinching) p.below_since = -1.0;
    g.pinch_started = g.pinching && !was_pinching;
    g.pinch_ended = !g.pinching && was_pinching;

    // 5. Point: index straight, the other three curled, not pinching.
    const bool was_pointing = g.pointing;
    g.pointing = !g.pinching && g.curl[1] < options_.curl_point_index_max &&
                 others > (was_pointing ? options_.curl_release : options_.curl_grab) &&
                 g.pinch_gap > options_.pinch_release_m;
    g.point_started = g.pointing && !was_pointing;
    g.point_ended = !g.pointing && was_pointing;
    if (g.pointing) {
        // Pointing and grabbing share the curled fingers: a pointing hand is not a grab.
        if (g.grab_started) g.grab_started = false;
        else if (g.grabbing && was_grabbing) g.grab_ended = true;
        g.grabbing = false;
    }
}

const std::array<HandGesture, kHandCount>& GestureRecognizer::update(const HandFrame& frame)
{
    for (int h = 0; h < kHandCount; ++h) update_hand(h, frame);
    return state_;
}

const std::array<HandGesture, kHandCount>& GestureRecognizer::finish()
{
    for (HandGesture& g : state_) {
        g.pinch_started = g.grab_started = g.point_started = false;
        g.pinch_ended = g.grab_ended = g.point_ended = false;
        end_all(g);
    }
    return state_;
}

} // namespace lobe
