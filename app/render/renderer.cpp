// The Vulkan renderer behind app/render/renderer.h. Renderer::Impl (here) puts together five
// parts, each a small class with a file pair of its own in app/render/:
//  - VulkanContext (vulkan_context.h): instance (with the caller's instance extensions),
//    device choice (with VK_KHR_swapchain when presenting), queue, memory helpers, one-shot
//    submits; or the instance, physical device and device from RendererOptions::vulkan_hooks
//    (OpenXR);
//  - OffscreenTarget (offscreen_target.h): the images a frame is drawn into (MSAA colour,
//    depth, resolve) and the buffer it is read back through (made on first use);
//  - SceneDrawer (scene_drawer.h): pipelines, the leaf and photo textures, the per-mesh GPU
//    buffer cache (keyed by RenderItem::key, re-uploaded only when RenderItem::version changes;
//    leaf meshes made of leaves.cpp's quads become one instance per leaf over a shared quad,
//    leaf_instances.h) and recording the draws of one frame, seen from a FrameView (a Camera's
//    or an OpenXR EyeView's, frame_view.h), into a command buffer inside any compatible render
//    pass;
//  - OverlayDrawer (overlay_drawer.h): the 2D overlay's pipeline, font texture and host-visible
//    buffers, drawn after the scene in the same render pass;
//  - WindowTarget (window_target.h): a window's surface and swapchain. A window's frame is
//    drawn offscreen exactly as a picture is, then blitted into the acquired swapchain image
//    and presented.
// The render pass and the pipelines are made by pipelines.h, textures uploaded by textures.h;
// the small types they share are in gpu_types.h.
// render_to draws an eye's frame the same way into an offscreen target kept per size and copies
// or blits it into the caller's image (an OpenXR swapchain image).
#include "app/render/renderer.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/constants.hpp>
#include <glm/gtc/quaternion.hpp>

#include "app/render/frame_view.h"
#include "app/render/gpu_types.h"
#include "app/render/offscreen_target.h"
#include "app/render/overlay_drawer.h"
#include "app/render/pipelines.h"
#include "app/render/scene_drawer.h"
#include "app/render/vulkan_context.h"
#include "app/render/window_target.h"

namespace lobe {

using vk::camera_frame_view;
using vk::choose_frame_format;
using vk::create_offscreen_render_pass;
using vk::eye_frame_view;
using vk::FrameFormat;
using vk::FrameView;
using vk::handle_from_integer;
using vk::handle_to_integer;
using vk::kColorFormat;
using vk::multisampled;
using vk::OffscreenTarget;
using vk::OverlayDrawer;
using vk::SceneDrawer;
using vk::vk_struct;
using vk::VulkanContext;
using vk::WindowTarget;

// ---------------------------------------------------------------------------------------------
struct Renderer::Impl {
    explicit Impl(const RendererOptions& options) : ctx(options)
    {
        format = choose_frame_format(ctx, options.samples);
        pass = create_offscreen_render_pass(ctx.device(), format);
        try {
            drawer = std::make_unique<SceneDrawer>(ctx, pass, format, options.instanced_leaves);
            drawer->set_scene(RenderScene{}, stats);
            overlay = std::make_unique<OverlayDrawer>(ctx, pass, format, drawer->texture_set_layout(), drawer->sampler());
            overlay->set(Overlay{});
        } catch (...) {
            overlay.reset();
            drawer.reset();
            vkDestroyRenderPass(ctx.device(), pass, nullptr);
            throw;
        }
    }
    // Device idle, then the window (swapchain, surface), the targets, the drawers and the
    // pass; the context (device, then instance) goes last.
    ~Impl()
    {
        vkDeviceWaitIdle(ctx.device());
        window.reset();
        last = nullptr;
        target.reset();
        window_frame.reset();
        eye_targets.clear();
        overlay.reset();
        drawer.reset();
        vkDestroyRenderPass(ctx.device(), pass, nullptr);
    }

    /// `t` made for `extent` (remade when its size differs).
    OffscreenTarget& target_of(std::unique_ptr<OffscreenTarget>& t, VkExtent2D extent)
    {
        if (!t || t->extent().width != extent.width || t->extent().height != extent.height) {
            if (last == t.get()) last = nullptr;
            t.reset();
            t = std::make_unique<OffscreenTarget>(ctx, pass, format, extent);
        }
        return *t;
    }

    /// The eye target of `extent`, made when no kept one has that size (the least recently
    /// used is dropped beyond kEyeTargets sizes).
    OffscreenTarget& eye_target_of(VkExtent2D extent)
    {
        auto same = [&](const std::unique_ptr<OffscreenTarget>& t) {
            return t->extent().width == extent.width && t->extent().height == extent.height;
        };
        auto it = std::find_if(eye_targets.begin(), eye_targets.end(), same);
        if (it == eye_targets.end()) {
            eye_targets.insert(eye_targets.begin(), std::make_unique<OffscreenTarget>(ctx, pass, format, extent));
            while (eye_targets.size() > kEyeTargets) {
                if (last == eye_targets.back().get()) last = nullptr;
                eye_targets.pop_back();
            }
        } else {
            std::rotate(eye_targets.begin(), it, it + 1); // most recently used first
        }
        return *eye_targets.front();
    }

    /// The scene (and the overlay when `with_overlay`) into `t`'s render pass (clear, draw,
    /// resolve).
    void record_frame(VkCommandBuffer cmd, const OffscreenTarget& t, const FrameView& view, bool with_overlay = true) const
    {
        const VkExtent2D extent = t.extent();
        VkClearValue clears[3]{};
        clears[0].color = {{0.0f, 0.0f, 0.0f, 1.0f}};
        clears[1].depthStencil = {1.0f, 0};
        auto begin = vk_struct<VkRenderPassBeginInfo>(VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO);
        begin.renderPass = pass;
        begin.framebuffer = t.framebuffer();
        begin.renderArea = {{0, 0}, extent};
        begin.clearValueCount = multisampled(format) ? 3u : 2u;
        begin.pClearValues = clears;
        vkCmdBeginRenderPass(cmd, &begin, VK_SUBPASS_CONTENTS_INLINE);
        drawer->record(cmd, view, extent);
        if (with_overlay) overlay->record(cmd, extent);
        vkCmdEndRenderPass(cmd);
    }

    VulkanContext ctx;
    FrameFormat format;
    VkRenderPass pass = VK_NULL_HANDLE;
    std::unique_ptr<SceneDrawer> drawer;
    std::unique_ptr<OverlayDrawer> overlay;
    std::unique_ptr<OffscreenTarget> target;       // render()'s pictures
    std::unique_ptr<OffscreenTarget> window_frame; // present()'s frames, so screenshots of another size do not remake it
    std::unique_ptr<WindowTarget> window;
    static constexpr std::size_t kEyeTargets = 4;
    std::vector<std::unique_ptr<OffscreenTarget>> eye_targets; // render_to()'s, by size, most recently used first
    OffscreenTarget* last = nullptr; // the target of the last frame drawn (last_frame())
    RenderStats stats;
};

Renderer::Renderer(const RendererOptions& options) : impl_(std::make_unique<Impl>(options)) {}
Renderer::~Renderer() = default;

const std::string& Renderer::device_name() const { return impl_->ctx.name(); }
bool Renderer::is_software() const { return impl_->ctx.software(); }
int Renderer::samples() const { return static_cast<int>(impl_->format.samples); }
const RenderStats& Renderer::stats() const { return impl_->stats; }

void Renderer::set_scene(const RenderScene& scene) { impl_->drawer->set_scene(scene, impl_->stats); }

namespace {

void check_size(int width, int height, const char* what)
{
    if (width < 1 || height < 1 || width > 16384 || height > 16384)
        throw InvalidInput(std::string("render: ") + what + " of " + std::to_string(width) + "x" + std::to_string(height) +
                           " pixels (1 to 16384 on each side)");
}

} // namespace

RgbaImage Renderer::render(const Camera& camera, int width, int height)
{
    check_size(width, height, "a picture");
    Impl& im = *impl_;
    OffscreenTarget& target =
        im.target_of(im.target, {static_cast<std::uint32_t>(width), static_cast<std::uint32_t>(height)});
    im.ctx.submit_and_wait(
        [&](VkCommandBuffer cmd) {
            im.record_frame(cmd, target, camera_frame_view(camera, target.extent()));
            target.record_copy_out(cmd);
        },
        &im.stats.record_ms, &im.stats.gpu_ms);
    target.drawn = true;
    im.last = &target;
    return target.read();
}

void Renderer::set_overlay(const Overlay& overlay) { impl_->overlay->set(overlay); }

void Renderer::attach_window(const std::function<std::uint64_t(std::uint64_t vk_instance)>& create_surface)
{
    Impl& im = *impl_;
    if (!im.ctx.presentation())
        throw RenderError("render: attach_window needs a Renderer made with RendererOptions::presentation = true");
    if (!im.ctx.instance_extension_enabled(VK_KHR_SURFACE_EXTENSION_NAME))
        throw RenderError("render: attach_window needs the instance extension " VK_KHR_SURFACE_EXTENSION_NAME
                          " (pass glfwGetRequiredInstanceExtensions in RendererOptions::instance_extensions)");
    im.window.reset(); // a window has one surface at a time: the old one goes first
    const std::uint64_t surface = create_surface(reinterpret_cast<std::uint64_t>(im.ctx.instance()));
    if (!surface) throw RenderError("render: the window's Vulkan surface could not be made (create_surface returned 0)");
    im.window = std::make_unique<WindowTarget>(im.ctx, handle_from_integer<VkSurfaceKHR>(surface));
}

bool Renderer::present(const Camera& camera, int width, int height)
{
    Impl& im = *impl_;
    if (!im.window) throw RenderError("render: present needs a window (call attach_window first)");
    if (width == 0 || height == 0) return false; // minimised
    check_size(width, height, "a window frame");
    const VkExtent2D extent{static_cast<std::uint32_t>(width), static_cast<std::uint32_t>(height)};
    OffscreenTarget& target = im.target_of(im.window_frame, extent);
    std::uint32_t image = 0;
    if (!im.window->acquire(extent, &image)) return false;
    im.ctx.submit_and_wait(
        [&](VkCommandBuffer cmd) {
            im.record_frame(cmd, target, camera_frame_view(camera, target.extent()));
            im.window->record_blit(cmd, target.picture(), extent, image);
        },
        &im.stats.record_ms, &im.stats.gpu_ms, {im.window->acquired(), VK_PIPELINE_STAGE_TRANSFER_BIT, im.window->rendered(image)});
    target.drawn = true;
    im.last = &target;
    im.window->present(image);
    return true;
}

VulkanHandles Renderer::vulkan_handles() const
{
    const VulkanContext& ctx = impl_->ctx;
    VulkanHandles h;
    h.instance = handle_to_integer(ctx.instance());
    h.physical_device = handle_to_integer(ctx.physical());
    h.device = handle_to_integer(ctx.device());
    h.queue_family = ctx.queue_family();
    h.queue_index = 0; // the renderer's one queue
    return h;
}

namespace {

/// The formats render_to writes (ExternalImage::vk_format).
bool is_external_format(VkFormat f)
{
    return f == VK_FORMAT_R8G8B8A8_UNORM || f == VK_FORMAT_R8G8B8A8_SRGB || f == VK_FORMAT_B8G8R8A8_UNORM ||
           f == VK_FORMAT_B8G8R8A8_SRGB;
}

/// InvalidInput (one line) unless `eye` is finite, with 0 < near < far, every angle strictly
/// between −90° and 90°, left < right, down < up, and an orientation of non-zero length.
void check_eye(const EyeView& eye)
{
    const float values[] = {eye.position.x,    eye.position.y,    eye.position.z,      eye.orientation.w, eye.orientation.x,
                            eye.orientation.y, eye.orientation.z, eye.angle_left,      eye.angle_right,   eye.angle_up,
                            eye.angle_down,    eye.near_m,        eye.far_m};
    for (float v : values)
        if (!std::isfinite(v)) throw InvalidInput("render: an eye view with a value that is not finite");
    if (!(eye.near_m > 0.0f && eye.far_m > eye.near_m))
        throw InvalidInput("render: an eye view with near " + std::to_string(eye.near_m) + " m and far " +
                           std::to_string(eye.far_m) + " m (0 < near < far)");
    const float right_angle = 0.5f * glm::pi<float>();
    auto ordered = [&](float lo, float hi) { return -right_angle < lo && lo < hi && hi < right_angle; };
    if (!ordered(eye.angle_left, eye.angle_right) || !ordered(eye.angle_down, eye.angle_up))
        throw InvalidInput("render: an eye view with angles left " + std::to_string(eye.angle_left) + ", right " +
                           std::to_string(eye.angle_right) + ", down " + std::to_string(eye.angle_down) + ", up " +
                           std::to_string(eye.angle_up) + " rad (each between -pi/2 and pi/2, left < right, down < up)");
    if (glm::length(eye.orientation) < 1e-6f) throw InvalidInput("render: an eye view with an orientation of length 0");
}

/// After the render pass: `picture` (kColorFormat, TRANSFER_SRC_OPTIMAL, `extent`) into layer
/// `layer` of `image` (`format`, the same size, COLOR_ATTACHMENT_OPTIMAL before and after):
/// copied when the formats are the same, else blitted (the blit converts: RGBA to BGRA, and
/// sRGB to linear for a UNORM image, whose texels then hold linear colours).
void record_into_external(VkCommandBuffer cmd, VkImage picture, VkExtent2D extent, VkImage image, VkFormat format,
                          std::uint32_t layer)
{
    auto barrier = vk_struct<VkImageMemoryBarrier>(VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER);
    barrier.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    barrier.image = image;
    barrier.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, layer, 1};
    barrier.oldLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
    barrier.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    barrier.srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
    barrier.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr, 0,
                         nullptr, 1, &barrier);
    const VkImageSubresourceLayers src{VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1}, dst{VK_IMAGE_ASPECT_COLOR_BIT, 0, layer, 1};
    if (format == kColorFormat) {
        VkImageCopy region{};
        region.srcSubresource = src;
        region.dstSubresource = dst;
        region.extent = {extent.width, extent.height, 1};
        vkCmdCopyImage(cmd, picture, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
    } else {
        VkImageBlit region{};
        region.srcSubresource = src;
        region.dstSubresource = dst;
        region.srcOffsets[1] = region.dstOffsets[1] = {std::int32_t(extent.width), std::int32_t(extent.height), 1};
        vkCmdBlitImage(cmd, picture, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region,
                       VK_FILTER_NEAREST);
    }
    barrier.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    barrier.newLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
    barrier.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    barrier.dstAccessMask = VK_ACCESS_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT, 0, 0, nullptr, 0,
                         nullptr, 1, &barrier);
}

} // namespace

void Renderer::render_to(const EyeView& eye, const ExternalImage& target)
{
    check_size(target.width, target.height, "an eye's image");
    if (!target.vk_image) throw InvalidInput("render: render_to was given no image (vk_image is 0)");
    const auto format = static_cast<VkFormat>(target.vk_format);
    if (!is_external_format(format))
        throw InvalidInput("render: render_to cannot write images of VkFormat " + std::to_string(target.vk_format) +
                           " (R8G8B8A8_UNORM 37, R8G8B8A8_SRGB 43, B8G8R8A8_UNORM 44 or B8G8R8A8_SRGB 50)");
    if (target.array_layer < 0)
        throw InvalidInput("render: render_to was given array layer " + std::to_string(target.array_layer) + " (0 or more)");
    check_eye(eye);
    Impl& im = *impl_;
    if (format != im.format.color) {
        VkFormatProperties src, dst;
        vkGetPhysicalDeviceFormatProperties(im.ctx.physical(), im.format.color, &src);
        vkGetPhysicalDeviceFormatProperties(im.ctx.physical(), format, &dst);
        if (!(src.optimalTilingFeatures & VK_FORMAT_FEATURE_BLIT_SRC_BIT) || !(dst.optimalTilingFeatures & VK_FORMAT_FEATURE_BLIT_DST_BIT))
            throw RenderUnavailable("render: the Vulkan device '" + im.ctx.name() + "' cannot blit into images of VkFormat " +
                                    std::to_string(target.vk_format));
    }
    const VkExtent2D extent{static_cast<std::uint32_t>(target.width), static_cast<std::uint32_t>(target.height)};
    OffscreenTarget& t = im.eye_target_of(extent);
    const auto image = handle_from_integer<VkImage>(target.vk_image);
    im.ctx.submit_and_wait(
        [&](VkCommandBuffer cmd) {
            im.record_frame(cmd, t, eye_frame_view(eye), false);
            record_into_external(cmd, t.picture(), extent, image, format, static_cast<std::uint32_t>(target.array_layer));
        },
        &im.stats.record_ms, &im.stats.gpu_ms);
    t.drawn = true;
    im.last = &t;
}

RgbaImage Renderer::last_frame()
{
    Impl& im = *impl_;
    if (!im.last || !im.last->drawn) return {};
    OffscreenTarget& target = *im.last;
    im.ctx.submit_and_wait([&](VkCommandBuffer cmd) { target.record_copy_out(cmd); });
    return target.read();
}

} // namespace lobe
