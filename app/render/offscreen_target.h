#pragma once
/// \file offscreen_target.h
/// The images one frame is drawn into (MSAA colour, depth, the resolved picture) and the host
/// buffer it is read back through. Internal to app/render/.

#include "app/render/gpu_types.h"
#include "app/render/vulkan_context.h"
#include "growth/tree_geometry.h"

namespace lobe::vk {

/// The images one offscreen frame is drawn into and the host buffer it is read back through.
class OffscreenTarget {
public:
    /// The target of `extent` pixels for `pass` (made with `format`). \throw RenderError
    OffscreenTarget(const VulkanContext& ctx, VkRenderPass pass, const FrameFormat& format, VkExtent2D extent);
    ~OffscreenTarget();
    OffscreenTarget(const OffscreenTarget&) = delete;
    OffscreenTarget& operator=(const OffscreenTarget&) = delete;

    VkExtent2D extent() const { return extent_; }
    VkFramebuffer framebuffer() const { return framebuffer_; }
    /// The single-sample picture (the resolve image, or the colour image when not
    /// multisampled), in TRANSFER_SRC_OPTIMAL after the render pass.
    VkImage picture() const { return resolve_.image ? resolve_.image : color_.image; }
    /// Whether a frame has been drawn into it (set by the caller after a submit).
    bool drawn = false;

    /// After the render pass: copies the picture into the readback buffer (made on first use:
    /// a window's target never needs one unless last_frame() is called).
    void record_copy_out(VkCommandBuffer cmd);

    /// The readback buffer's pixels, alpha set to 255 (after a submitted record_copy_out).
    /// \throw RenderError
    RgbaImage read() const;

private:
    void destroy();

    const VulkanContext& ctx_;
    VkExtent2D extent_;
    GpuImage color_, depth_, resolve_;
    VkFramebuffer framebuffer_ = VK_NULL_HANDLE;
    GpuBuffer readback_;
};

} // namespace lobe::vk
