#pragma once
// Minimal hand poses for unit tests of the gesture and stroke logic (the realistic hands come
// from the synthesizer and the real captures).
#include <glm/geometric.hpp>

#include "core/hand_frame.h"

namespace lobe::test {

/// A right hand whose index tip is at `tip`, the thumb tip `gap` metres (surface to surface)
/// from it, the middle/ring/little fingers straight (curl 0) or folded into a fist.
inline HandState make_hand(glm::vec3 tip, float gap, bool fist = false, float radius = 0.008f)
{
    HandState h;
    h.active = true;
    for (JointState& j : h.joints) {
        j.flags = kAllJointFlags;
        j.radius = radius;
    }
    const glm::vec3 fwd(0, 0, -1), side(1, 0, 0);
    // Index finger: straight, pointing forward, ending at tip.
    const float bones[3] = {0.040f, 0.023f, 0.018f};
    auto place_finger = [&](int first, glm::vec3 finger_tip, bool folded) {
        // first = proximal joint index; joints proximal, intermediate, distal, tip
        glm::vec3 p = finger_tip;
        h.joints[first + 3].pose.position = p;
        for (int b = 2; b >= 0; --b) {
            glm::vec3 dir = folded ? (b == 0 ? fwd : (b == 1 ? glm::vec3(0, -1, 0) : -fwd)) : fwd;
            p -= dir * bones[b];
            h.joints[first + b].pose.position = p;
        }
        h.joints[first - 1].pose.position = h.joints[first].pose.position - fwd * 0.065f;
    };
    place_finger(idx(Joint::IndexProximal), tip, false);
    const glm::vec3 base = h[Joint::IndexProximal].pose.position;
    for (int f = 0; f < 3; ++f) {
        const int first = idx(Joint::MiddleProximal) + 5 * f;
        const glm::vec3 knuckle = base + side * (0.02f * static_cast<float>(f + 1));
        if (fist) {
            // Folded: proximal forward, intermediate down, distal back towards the palm.
            h.joints[first].pose.position = knuckle;
            h.joints[first + 1].pose.position = knuckle + fwd * 0.040f;
            h.joints[first + 2].pose.position = knuckle + fwd * 0.040f + glm::vec3(0, -0.023f, 0);
            h.joints[first + 3].pose.position = knuckle + fwd * 0.022f + glm::vec3(0, -0.023f, 0);
            h.joints[first - 1].pose.position = knuckle - fwd * 0.065f;
        } else {
            place_finger(first, knuckle + fwd * 0.081f, false);
        }
    }
    // Thumb tip beside the index tip, gap measured between the joint surfaces.
    const glm::vec3 thumb_tip = tip + glm::vec3(0, -1, 0) * (gap + 2 * radius);
    h[Joint::ThumbTip].pose.position = thumb_tip;
    h[Joint::ThumbDistal].pose.position = thumb_tip + glm::vec3(0, -0.01f, 0.03f);
    h[Joint::ThumbProximal].pose.position = thumb_tip + glm::vec3(0, -0.02f, 0.06f);
    h[Joint::ThumbMetacarpal].pose.position = thumb_tip + glm::vec3(0, -0.03f, 0.09f);
    h[Joint::Palm].pose.position = base - fwd * 0.035f;
    h[Joint::Wrist].pose.position = base - fwd * 0.08f;
    return h;
}

inline HandFrame make_frame(double t, const HandState& right)
{
    HandFrame f;
    f.time = t;
    f.head.position = {0, 1.65f, 0};
    f.head_valid = true;
    f.hand(Hand::Right) = right;
    return f;
}

} // namespace lobe::test
