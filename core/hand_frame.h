#pragma once
/// \file hand_frame.h
/// One tracked instant of both hands and the head, in OpenXR's 26-joint layout.
/// Units are metres, stage space (+Y up, right-handed), as in OpenXR and glTF.

#include <array>
#include <cstdint>

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

namespace lobe {

/// Joint indices, identical to XrHandJointEXT (XR_HAND_JOINT_PALM_EXT = 0 …
/// XR_HAND_JOINT_LITTLE_TIP_EXT = 25).
enum class Joint : std::uint8_t {
    Palm = 0, Wrist,
    ThumbMetacarpal, ThumbProximal, ThumbDistal, ThumbTip,
    IndexMetacarpal, IndexProximal, IndexIntermediate, IndexDistal, IndexTip,
    MiddleMetacarpal, MiddleProximal, MiddleIntermediate, MiddleDistal, MiddleTip,
    RingMetacarpal, RingProximal, RingIntermediate, RingDistal, RingTip,
    LittleMetacarpal, LittleProximal, LittleIntermediate, LittleDistal, LittleTip,
};
inline constexpr int kJointCount = 26;
constexpr int idx(Joint j) { return static_cast<int>(j); }

/// Location flags, bit-compatible with XrSpaceLocationFlags.
enum JointFlag : std::uint8_t {
    kOrientationValid = 0x1,
    kPositionValid = 0x2,
    kOrientationTracked = 0x4,
    kPositionTracked = 0x8,
};
inline constexpr std::uint8_t kAllJointFlags = 0xF;

/// A rigid pose. OpenXR joint convention: -Z points along the bone towards the finger tip,
/// +Y out of the back of the hand.
struct Pose {
    glm::vec3 position{0.0f};
    glm::quat orientation{1.0f, 0.0f, 0.0f, 0.0f}; ///< w, x, y, z (glm order)
};

struct JointState {
    Pose pose;
    float radius = 0.0f; ///< metres
    std::uint8_t flags = 0;
    bool position_valid() const { return (flags & kPositionValid) != 0; }
};

enum class Hand : std::uint8_t { Left = 0, Right = 1 };
inline constexpr int kHandCount = 2;

struct HandState {
    bool active = false; ///< XrHandJointLocationsEXT::isActive
    std::array<JointState, kJointCount> joints{};
    const JointState& operator[](Joint j) const { return joints[idx(j)]; }
    JointState& operator[](Joint j) { return joints[idx(j)]; }
};

/// Both hands and the head at one time.
struct HandFrame {
    double time = 0.0; ///< seconds since the start of the recording
    Pose head;
    bool head_valid = false;
    std::array<HandState, kHandCount> hands{};
    const HandState& hand(Hand h) const { return hands[static_cast<int>(h)]; }
    HandState& hand(Hand h) { return hands[static_cast<int>(h)]; }
};

const char* joint_name(Joint j);
const char* hand_name(Hand h);

} // namespace lobe
