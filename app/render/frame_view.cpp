// Camera framing (app/render/renderer.h) and the views a frame is drawn from
// (app/render/frame_view.h).
#include "app/render/frame_view.h"

#include <algorithm>
#include <cmath>

#include <glm/ext/matrix_clip_space.hpp>
#include <glm/ext/matrix_transform.hpp>
#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/matrix.hpp>

namespace lobe {

void Bounds::add(const glm::vec3& p)
{
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
}

Bounds scene_bounds(const RenderScene& scene)
{
    Bounds b;
    for (const RenderItem& item : scene.items)
        for (const glm::vec3& p : item.geometry.positions) b.add(p);
    return b;
}

ViewAngles front_view() { return {0.0f, 0.0f}; }
ViewAngles side_view() { return {90.0f, 0.0f}; }
ViewAngles top_view() { return {0.0f, 90.0f}; }

Camera frame_view(const Bounds& bounds_in, const ViewAngles& view, float aspect, float fov_y_deg, float margin)
{
    Bounds b = bounds_in;
    if (b.empty()) b = Bounds{glm::vec3(-0.5f), glm::vec3(0.5f)};
    const glm::vec3 centre = 0.5f * (b.lo + b.hi);
    const float az = glm::radians(view.azimuth_deg), el = glm::radians(view.elevation_deg);
    // Towards the camera, and the picture's right and up.
    const glm::vec3 back(std::cos(el) * std::sin(az), std::sin(el), std::cos(el) * std::cos(az));
    const glm::vec3 up_hint = std::abs(back.y) > 0.999f ? glm::vec3(-std::sin(az), 0.0f, -std::cos(az)) : glm::vec3(0, 1, 0);
    const glm::vec3 right = glm::normalize(glm::cross(up_hint, back));
    const glm::vec3 up = glm::cross(back, right);
    const float tan_y = std::tan(glm::radians(fov_y_deg) * 0.5f) * (1.0f - 2.0f * margin);
    const float tan_x = std::tan(glm::radians(fov_y_deg) * 0.5f) * aspect * (1.0f - 2.0f * margin);
    float distance = 0.0f, radius = 0.0f;
    for (int i = 0; i < 8; ++i) {
        const glm::vec3 corner((i & 1) ? b.hi.x : b.lo.x, (i & 2) ? b.hi.y : b.lo.y, (i & 4) ? b.hi.z : b.lo.z);
        const glm::vec3 p = corner - centre;
        const float z = glm::dot(p, back);
        distance = std::max({distance, z + std::abs(glm::dot(p, right)) / tan_x, z + std::abs(glm::dot(p, up)) / tan_y});
        radius = std::max(radius, glm::length(p));
    }
    distance = std::max(distance, 1e-3f);
    Camera c;
    c.eye = centre + back * distance;
    c.target = centre;
    c.up = up;
    c.fov_y_deg = fov_y_deg;
    c.near_m = std::max(1e-3f, (distance - radius) * 0.5f);
    c.far_m = distance + 40.0f * std::max(radius, 0.5f);
    return c;
}

namespace vk {

FrameView camera_frame_view(const Camera& camera, VkExtent2D extent)
{
    const float aspect = float(extent.width) / float(extent.height);
    glm::mat4 proj = glm::perspectiveRH_ZO(glm::radians(camera.fov_y_deg), aspect, camera.near_m, camera.far_m);
    proj[1][1] *= -1.0f; // Vulkan's framebuffer y points down
    const glm::mat4 view = glm::lookAtRH(camera.eye, camera.target, camera.up);
    return {proj * view, camera.eye};
}

FrameView eye_frame_view(const EyeView& eye)
{
    const float l = std::tan(eye.angle_left), r = std::tan(eye.angle_right);
    const float d = std::tan(eye.angle_down), u = std::tan(eye.angle_up);
    const float n = eye.near_m, f = eye.far_m;
    glm::mat4 proj(0.0f);
    proj[0][0] = 2.0f / (r - l);
    proj[2][0] = (r + l) / (r - l);
    proj[1][1] = -2.0f / (u - d);       // y flipped: Vulkan's framebuffer y points down
    proj[2][1] = -(u + d) / (u - d);
    proj[2][2] = f / (n - f);           // depth 0 at the near plane, 1 at the far one
    proj[2][3] = -1.0f;
    proj[3][2] = -(f * n) / (f - n);
    const glm::quat q = glm::normalize(eye.orientation);
    const glm::mat4 view = glm::mat4_cast(glm::conjugate(q)) * glm::translate(glm::mat4(1.0f), -eye.position);
    return {proj * view, eye.position};
}

} // namespace vk
} // namespace lobe
