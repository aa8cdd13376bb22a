#pragma once
/// \file hand_model.h
/// An articulated hand for the synthesizer (input/synth.h): palm pose, per-finger curl and
/// spread, and a thumb whose tip is placed by a planar reach chain (opposition). Joints come
/// out in OpenXR's 26-joint layout and orientation convention (-Z along the bone towards the
/// tip, +Y out of the back of the hand, +X = Y × Z), so a left hand is the mirror image of a
/// right one with the same axis convention. Joint layout, bone lengths and radii are those of a
/// real hand (the measurements: docs/scenario-format.md, "What the synthesizer adds").

#include <array>

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

#include "core/hand_frame.h"

namespace lobe::hand_model {

/// Fingers in joint order.
enum Finger : int { kThumb = 0, kIndex = 1, kMiddle = 2, kRing = 3, kLittle = 4 };
inline constexpr int kFingerCount = 5;

/// Joint layout and sizes of one hand, in the right-hand wrist frame (origin at the wrist
/// joint, -Z towards the fingers, +Y dorsal, +X towards the little finger), metres.
struct HandShape {
    float scale = 1.0f;
    /// Position of each finger's Metacarpal joint (the thumb's is its carpometacarpal joint).
    std::array<glm::vec3, kFingerCount> metacarpal_base{};
    /// Index … little: position of the Proximal joint (the knuckle); [0] is unused.
    std::array<glm::vec3, kFingerCount> knuckle{};
    /// Index … little: proximal, intermediate, distal phalanx (distal includes the pad, up to
    /// the Tip joint); thumb: metacarpal, proximal, distal.
    std::array<std::array<float, 3>, kFingerCount> bones{};
    /// Reported radius of every joint.
    std::array<float, kJointCount> radius{};
};

/// The calibrated adult hand scaled by `scale` (about 0.93–1.07 covers most adults).
/// `uniform_radius` > 0 gives every joint that radius, as some runtimes do.
HandShape make_hand_shape(float scale, float uniform_radius = 0.0f);

/// Finger articulation. Curl 0 is a straight finger, 1 a fist (MCP 90°, PIP 105°, DIP 75°).
struct Articulation {
    std::array<float, kFingerCount> curl{};   ///< [0] unused (the thumb is placed by its tip)
    std::array<float, kFingerCount> spread{}; ///< abduction in radians, + away from the middle finger
};

struct LocalJoint {
    glm::vec3 position{0.0f};
    glm::quat orientation{1.0f, 0.0f, 0.0f, 0.0f};
};
/// All joints in the right-hand wrist frame.
using LocalHand = std::array<LocalJoint, kJointCount>;

/// Wrist, palm and the four fingers by forward kinematics; the thumb joints are left for
/// pose_thumb.
void pose_fingers(const HandShape& shape, const Articulation& art, LocalHand& out);

/// Thumb joints reaching for `tip_target` (wrist frame): the three thumb bones bend in one
/// plane with fixed ratios, the bend is found by bisection and the plane is turned so that
/// the chain ends on the target; the bend faces the palm. A target out of reach gets a
/// straight thumb pointing at it. Returns how far the tip ended from the target (metres).
float pose_thumb(const HandShape& shape, const glm::vec3& tip_target, LocalHand& out);

/// Mirrors a right-hand wrist-frame position to the given hand (left: x → -x).
glm::vec3 mirror(const glm::vec3& p, Hand hand);
/// Mirrors a right-hand orientation to the given hand, keeping the OpenXR axis convention
/// (the bone and dorsal axes are mirrored, X stays Y × Z).
glm::quat mirror(const glm::quat& q, Hand hand);

/// Places a hand in the world: joint = translation + rotation · mirror(local joint), radii
/// from the shape, all flags valid and tracked, active.
HandState place_hand(const HandShape& shape, const LocalHand& local, Hand hand,
                     const glm::quat& rotation, const glm::vec3& translation);

} // namespace lobe::hand_model
