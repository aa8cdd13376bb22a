#pragma once
/// \file frame_view.h
/// Where a frame is seen from: world to Vulkan clip space for a Camera or an OpenXR EyeView
/// (docs/rendering.md, "Drawing for a headset"). frame_view.cpp also holds the camera framing
/// of app/render/renderer.h (scene_bounds, the view angles, frame_view). Internal to
/// app/render/.

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>
#include <vulkan/vulkan.h>

#include "app/render/renderer.h"

namespace lobe::vk {

/// Where a frame is seen from: world to Vulkan clip space (x right, y down, depth 0 at the
/// near plane to 1 at the far one) and the eye's position.
struct FrameView {
    glm::mat4 view_proj{1.0f};
    glm::vec3 eye{0.0f};
};

/// A Camera's view of a frame of `extent` (its vertical field of view; the horizontal one
/// follows the aspect ratio).
FrameView camera_frame_view(const Camera& camera, VkExtent2D extent);

/// An OpenXR eye's view (checked by the caller): the view matrix is the inverse of its pose
/// (−Z forward, +Y up, as lookAtRH's), and the projection glm::perspectiveRH_ZO's with the
/// frustum's sides at the tangents of the four angles, y flipped as camera_frame_view's. With
/// left = −right and down = −up it is camera_frame_view's for a vertical field of view of
/// 2 · up and an aspect ratio of tan(right) / tan(up).
FrameView eye_frame_view(const EyeView& eye);

} // namespace lobe::vk
