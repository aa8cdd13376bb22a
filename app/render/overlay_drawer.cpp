// The 2D overlay's pipeline, font, buffers and draws (app/render/overlay_drawer.h).
#include "app/render/overlay_drawer.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "app/render/pipelines.h"
#include "app/render/textures.h"

namespace lobe::vk {

OverlayDrawer::OverlayDrawer(const VulkanContext& ctx, VkRenderPass pass, const FrameFormat& format,
                             VkDescriptorSetLayout set_layout, VkSampler sampler)
    : ctx_(ctx), sampler_(sampler)
{
    try {
        create(pass, format, set_layout);
    } catch (...) {
        destroy();
        throw;
    }
}

OverlayDrawer::~OverlayDrawer() { destroy(); }

void OverlayDrawer::set(const Overlay& overlay)
{
    const std::uint64_t nv = overlay.vertices.size(), ni = overlay.indices.size();
    for (std::size_t c = 0; c < overlay.commands.size(); ++c) {
        const OverlayCommand& cmd = overlay.commands[c];
        const std::string which = "render: overlay command " + std::to_string(c);
        const std::uint64_t first = cmd.first_index, end = first + cmd.index_count;
        if (end > ni)
            throw InvalidInput(which + " draws indices " + std::to_string(first) + " to " + std::to_string(end) + " of " +
                               std::to_string(ni));
        for (float v : cmd.clip)
            if (!std::isfinite(v)) throw InvalidInput(which + " has a clip rectangle that is not finite");
        for (std::uint64_t i = first; i < end; ++i) {
            const std::int64_t v = std::int64_t(overlay.indices[i]) + cmd.vertex_offset;
            if (v < 0 || std::uint64_t(v) >= nv)
                throw InvalidInput(which + ": index " + std::to_string(overlay.indices[i]) + " + vertex offset " +
                                   std::to_string(cmd.vertex_offset) + " is outside the " + std::to_string(nv) +
                                   " vertices");
        }
    }
    const bool has_font = check_rgba(overlay.font, "an overlay font");

    const std::uint64_t font_version = has_font ? overlay.font_version : 0;
    if (!font_ready_ || has_font != font_is_real_ || font_version != font_version_) {
        GpuImage fresh = upload_rgba_texture(ctx_, has_font ? overlay.font : kWhiteTexel);
        ctx_.destroy(font_);
        font_ = fresh;
        write_texture_descriptor(ctx_.device(), descriptor_set_, sampler_, font_);
        font_version_ = font_version;
        font_is_real_ = has_font;
        font_ready_ = true;
    }
    commands_.clear();
    if (overlay.commands.empty()) return;
    static_assert(sizeof(OverlayVertex) == 20 && offsetof(OverlayVertex, u) == 8 && offsetof(OverlayVertex, rgba) == 16);
    const std::size_t vertex_bytes = overlay.vertices.size() * sizeof(OverlayVertex);
    const std::size_t index_bytes = overlay.indices.size() * sizeof(std::uint32_t);
    reserve(vertices_, vertex_bytes, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
    reserve(indices_, index_bytes, VK_BUFFER_USAGE_INDEX_BUFFER_BIT);
    ctx_.write(vertices_, 0, overlay.vertices.data(), vertex_bytes);
    ctx_.write(indices_, 0, overlay.indices.data(), index_bytes);
    commands_ = overlay.commands;
}

void OverlayDrawer::record(VkCommandBuffer cmd, VkExtent2D extent) const
{
    if (commands_.empty()) return;
    const float w = float(extent.width), h = float(extent.height);
    VkViewport viewport{0.0f, 0.0f, w, h, 0.0f, 1.0f};
    vkCmdSetViewport(cmd, 0, 1, &viewport);
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline_);
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, layout_, 0, 1, &descriptor_set_, 0, nullptr);
    const VkDeviceSize offset = 0;
    vkCmdBindVertexBuffers(cmd, 0, 1, &vertices_.buffer, &offset);
    vkCmdBindIndexBuffer(cmd, indices_.buffer, 0, VK_INDEX_TYPE_UINT32);
    // Pixels (origin top-left, y down) to Vulkan's NDC (-1 at the top-left, y down).
    const float push[4] = {2.0f / w, 2.0f / h, -1.0f, -1.0f};
    vkCmdPushConstants(cmd, layout_, VK_SHADER_STAGE_VERTEX_BIT, 0, sizeof(push), push);
    // A pixel is drawn when its centre lies in the clip rectangle: pixels ceil(x0 - 0.5) to
    // ceil(x1 - 0.5) (exclusive), clamped to the frame.
    auto edge = [](float v, std::uint32_t size) {
        return static_cast<std::uint32_t>(std::clamp(std::ceil(double(v) - 0.5), 0.0, double(size)));
    };
    for (const OverlayCommand& c : commands_) {
        if (c.index_count == 0) continue;
        const std::uint32_t x0 = edge(c.clip[0], extent.width), y0 = edge(c.clip[1], extent.height);
        const std::uint32_t x1 = edge(c.clip[2], extent.width), y1 = edge(c.clip[3], extent.height);
        if (x1 <= x0 || y1 <= y0) continue;
        const VkRect2D scissor{{std::int32_t(x0), std::int32_t(y0)}, {x1 - x0, y1 - y0}};
        vkCmdSetScissor(cmd, 0, 1, &scissor);
        vkCmdDrawIndexed(cmd, c.index_count, 1, c.first_index, c.vertex_offset, 0);
    }
    const VkRect2D full{{0, 0}, extent};
    vkCmdSetScissor(cmd, 0, 1, &full);
}

void OverlayDrawer::reserve(GpuBuffer& b, std::size_t bytes, VkBufferUsageFlags usage) const
{
    if (b.buffer && b.size >= bytes) return;
    const VkDeviceSize size = std::max<VkDeviceSize>({VkDeviceSize(bytes), 2 * b.size, 4096});
    ctx_.destroy(b);
    b = ctx_.create_buffer(size, usage, 0);
}

void OverlayDrawer::create(VkRenderPass pass, const FrameFormat& format, VkDescriptorSetLayout set_layout)
{
    const VkDevice dev = ctx_.device();
    layout_ = create_pipeline_layout(dev, set_layout, {VK_SHADER_STAGE_VERTEX_BIT, 0, 4 * sizeof(float)});
    allocate_sampler_set(dev, set_layout, descriptor_pool_, descriptor_set_);

    VkVertexInputBindingDescription binding{0, sizeof(OverlayVertex), VK_VERTEX_INPUT_RATE_VERTEX};
    const VkVertexInputAttributeDescription attributes[3] = {
        {0, 0, VK_FORMAT_R32G32_SFLOAT, offsetof(OverlayVertex, x)},
        {1, 0, VK_FORMAT_R32G32_SFLOAT, offsetof(OverlayVertex, u)},
        {2, 0, VK_FORMAT_R8G8B8A8_UNORM, offsetof(OverlayVertex, rgba)}, // bytes R, G, B, A
    };
    auto input = vk_struct<VkPipelineVertexInputStateCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO);
    input.vertexBindingDescriptionCount = 1;
    input.pVertexBindingDescriptions = &binding;
    input.vertexAttributeDescriptionCount = 3;
    input.pVertexAttributeDescriptions = attributes;
    pipeline_ = create_pipeline(dev, pass, format, layout_, {"ui.vert", "ui.frag", &input, VK_CULL_MODE_NONE, false, false, true});
}

void OverlayDrawer::destroy()
{
    const VkDevice dev = ctx_.device();
    ctx_.destroy(vertices_);
    ctx_.destroy(indices_);
    ctx_.destroy(font_);
    if (pipeline_) vkDestroyPipeline(dev, pipeline_, nullptr);
    if (descriptor_pool_) vkDestroyDescriptorPool(dev, descriptor_pool_, nullptr);
    if (layout_) vkDestroyPipelineLayout(dev, layout_, nullptr);
}

} // namespace lobe::vk
