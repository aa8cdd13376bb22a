#pragma once
/// \file overlay_drawer.h
/// The 2D overlay drawn over the scene (a desktop panel; docs/rendering.md, "The 2D
/// overlay"). Internal to app/render/.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "app/render/gpu_types.h"
#include "app/render/vulkan_context.h"

namespace lobe::vk {

/// The 2D overlay (app/render/shaders/ui.*): its pipeline, font texture, host-visible vertex and index
/// buffers (grown geometrically, reused across frames) and the commands of the last
/// set_overlay. Every submit of the renderer is waited for, so set() may write the buffers.
class OverlayDrawer {
public:
    /// The overlay's pipeline for `pass` (made with `format`) and its font's descriptor set of
    /// `set_layout`, sampled through `sampler` (SceneDrawer's). \throw RenderError
    OverlayDrawer(const VulkanContext& ctx, VkRenderPass pass, const FrameFormat& format, VkDescriptorSetLayout set_layout,
                  VkSampler sampler);
    ~OverlayDrawer();
    OverlayDrawer(const OverlayDrawer&) = delete;
    OverlayDrawer& operator=(const OverlayDrawer&) = delete;

    /// Checks everything first: a bad overlay throws InvalidInput and leaves the last one.
    /// \throw InvalidInput as Renderer::set_overlay (app/render/renderer.h); RenderError.
    void set(const Overlay& overlay);

    /// The overlay's draws, inside a begun render pass of `extent` (after the scene's).
    void record(VkCommandBuffer cmd, VkExtent2D extent) const;

private:
    /// Makes `b` hold at least `bytes`, growing it to twice its size (or more) when it must.
    void reserve(GpuBuffer& b, std::size_t bytes, VkBufferUsageFlags usage) const;
    void create(VkRenderPass pass, const FrameFormat& format, VkDescriptorSetLayout set_layout);
    void destroy();

    const VulkanContext& ctx_;
    VkSampler sampler_;
    VkPipelineLayout layout_ = VK_NULL_HANDLE;
    VkPipeline pipeline_ = VK_NULL_HANDLE;
    VkDescriptorPool descriptor_pool_ = VK_NULL_HANDLE;
    VkDescriptorSet descriptor_set_ = VK_NULL_HANDLE;
    GpuImage font_;
    std::uint64_t font_version_ = 0;
    bool font_ready_ = false;
    bool font_is_real_ = false;
    GpuBuffer vertices_, indices_;
    std::vector<OverlayCommand> commands_;
};

} // namespace lobe::vk
