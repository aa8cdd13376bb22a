#pragma once
/// \file pipelines.h
/// The offscreen render pass and what the drawers build their pipelines from: the frame's
/// formats on a device, pipeline layouts, descriptor sets of combined image samplers, and one
/// graphics pipeline per PipelineState (shaders from app/render/embedded_shaders.h).
/// Internal to app/render/.

#include <cstdint>

#include "app/render/gpu_types.h"
#include "app/render/vulkan_context.h"

namespace lobe::vk {

/// The frame's formats on `ctx`'s device: RGBA8 sRGB colour, the first of D32, D24S8 and D16
/// it can draw depth into, and the most samples up to `requested_samples` (8, 4, 2, else 1)
/// that colour and depth targets both support.
/// \throw RenderUnavailable when the device cannot draw into RGBA8 sRGB or has no depth format.
FrameFormat choose_frame_format(const VulkanContext& ctx, int requested_samples);

/// The offscreen render pass: clear, draw, resolve (when multisampled), leave the picture
/// ready to be copied out.
/// \throw RenderError
VkRenderPass create_offscreen_render_pass(VkDevice device, const FrameFormat& f);

/// A pipeline layout of one descriptor set and one push-constant range. \throw RenderError
VkPipelineLayout create_pipeline_layout(VkDevice dev, VkDescriptorSetLayout set_layout, VkPushConstantRange range);

/// A pool holding one set of `samplers` combined image samplers, and that set.
/// \throw RenderError
void allocate_sampler_set(VkDevice dev, VkDescriptorSetLayout set_layout, VkDescriptorPool& pool_out, VkDescriptorSet& set_out,
                          std::uint32_t samplers = 1);

/// What a pipeline differs in (the renderer's pipelines share everything else: triangle
/// lists, dynamic viewport and scissor, the target's sample count).
struct PipelineState {
    const char* vert;
    const char* frag;
    const VkPipelineVertexInputStateCreateInfo* input = nullptr; // none: no vertex input
    VkCullModeFlags cull = VK_CULL_MODE_NONE;
    bool depth_test = true;
    bool depth_write = true;
    bool blend = false;
};

/// The graphics pipeline of `s` for subpass 0 of `pass`, at `format`'s sample count.
/// \throw RenderError when a shader is not embedded or a Vulkan call fails.
VkPipeline create_pipeline(VkDevice device, VkRenderPass pass, const FrameFormat& format, VkPipelineLayout layout,
                           const PipelineState& s);

} // namespace lobe::vk
