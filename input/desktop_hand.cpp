#include "input/desktop_hand.h"

#include <cmath>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>

#include "input/hand_model.h"

namespace lobe {

namespace {

namespace hm = hand_model;

// Postures of the synthesizer's pinch-drawing hand (input/synth_motion.cpp): index bent about
// 0.55 while pinching, 0.25 when open; the other fingers relaxed at 0.25 (well below the grab
// threshold of 0.48). The thumb reaches the index tip from the palm side.
constexpr float kIndexCurlPinched = 0.55f, kIndexCurlOpen = 0.25f, kOtherCurl = 0.25f;
constexpr float kPinchedGap = -0.001f, kOpenGap = 0.05f;

glm::quat hand_rotation(const glm::vec3& forward_in)
{
    glm::vec3 f = glm::length(forward_in) > 1e-6f ? glm::normalize(forward_in) : glm::vec3(0, 0, -1);
    // Fingers along the view, tilted 25° down so the back of the hand faces the viewer a little.
    glm::vec3 up(0.0f, 1.0f, 0.0f);
    glm::vec3 y = up - glm::dot(up, f) * f;
    if (glm::length(y) < 1e-3f) y = glm::vec3(0.0f, 0.0f, -1.0f) - f.z * f;
    y = glm::normalize(y);
    const float tilt = glm::radians(25.0f);
    const glm::vec3 f2 = glm::normalize(f * std::cos(tilt) - y * std::sin(tilt));
    const glm::vec3 y2 = glm::normalize(y * std::cos(tilt) + f * std::sin(tilt));
    // OpenXR joint frames: -Z along the fingers, +Y out of the back of the hand, X = Y × Z.
    const glm::vec3 z = -f2;
    const glm::vec3 x = glm::cross(y2, z);
    return glm::quat_cast(glm::mat3(x, y2, z));
}

} // namespace

HandState desktop_hand(const DesktopHandPose& pose)
{
    static const hm::HandShape shape = hm::make_hand_shape(1.0f);
    hm::Articulation art;
    art.curl[hm::kIndex] = pose.pinched ? kIndexCurlPinched : kIndexCurlOpen;
    for (int f = hm::kMiddle; f <= hm::kLittle; ++f) art.curl[static_cast<std::size_t>(f)] = kOtherCurl;
    hm::LocalHand local;
    hm::pose_fingers(shape, art, local);

    const glm::vec3 idx_tip = local[idx(Joint::IndexTip)].position;
    const float radii = shape.radius[idx(Joint::ThumbTip)] + shape.radius[idx(Joint::IndexTip)];
    // From the index tip towards the thumb side and the palm (right-hand wrist frame: -X is
    // the thumb side, -Y the palm), as the synthesizer's contact and open directions.
    const glm::vec3 dir = pose.pinched ? glm::normalize(glm::vec3(-0.6f, -0.2f, 0.75f))
                                       : glm::normalize(glm::vec3(-0.85f, 0.35f, 0.4f));
    hm::pose_thumb(shape, idx_tip + dir * (radii + (pose.pinched ? kPinchedGap : kOpenGap)), local);

    const glm::quat rot = hand_rotation(pose.forward);
    const glm::vec3 translation = pose.tip - rot * idx_tip;
    return hm::place_hand(shape, local, Hand::Right, rot, translation);
}

HandFrame desktop_frame(double time, const DesktopHandPose& pose, bool tracked)
{
    HandFrame frame;
    frame.time = time;
    if (tracked) frame.hand(Hand::Right) = desktop_hand(pose);
    return frame;
}

} // namespace lobe
