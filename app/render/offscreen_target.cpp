// The images a frame is drawn into and read back from (app/render/offscreen_target.h).
#include "app/render/offscreen_target.h"

#include <cstring>

#include "app/render/vk_check.h"

namespace lobe::vk {

OffscreenTarget::OffscreenTarget(const VulkanContext& ctx, VkRenderPass pass, const FrameFormat& format, VkExtent2D extent)
    : ctx_(ctx), extent_(extent)
{
    try {
        const bool ms = multisampled(format);
        color_ = ctx.create_image(extent, format.color, format.samples,
                                  ms ? VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSIENT_ATTACHMENT_BIT
                                     : VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                                  VK_IMAGE_ASPECT_COLOR_BIT);
        depth_ = ctx.create_image(extent, format.depth, format.samples, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT,
                                  VK_IMAGE_ASPECT_DEPTH_BIT);
        if (ms)
            resolve_ = ctx.create_image(extent, format.color, VK_SAMPLE_COUNT_1_BIT,
                                        VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                                        VK_IMAGE_ASPECT_COLOR_BIT);
        const VkImageView views[3] = {color_.view, depth_.view, resolve_.view};
        auto fb = vk_struct<VkFramebufferCreateInfo>(VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO);
        fb.renderPass = pass;
        fb.attachmentCount = ms ? 3u : 2u;
        fb.pAttachments = views;
        fb.width = extent.width;
        fb.height = extent.height;
        fb.layers = 1;
        CHECK_VKCMD(vkCreateFramebuffer(ctx.device(), &fb, nullptr, &framebuffer_));
    } catch (...) {
        destroy();
        throw;
    }
}

OffscreenTarget::~OffscreenTarget() { destroy(); }

void OffscreenTarget::record_copy_out(VkCommandBuffer cmd)
{
    if (!readback_.buffer)
        readback_ = ctx_.create_buffer(VkDeviceSize(extent_.width) * extent_.height * 4u, VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                       VK_MEMORY_PROPERTY_HOST_CACHED_BIT);
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {extent_.width, extent_.height, 1};
    vkCmdCopyImageToBuffer(cmd, picture(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, readback_.buffer, 1, &region);
    auto barrier = vk_struct<VkBufferMemoryBarrier>(VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER);
    barrier.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    barrier.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    barrier.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    barrier.buffer = readback_.buffer;
    barrier.size = VK_WHOLE_SIZE;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 0, nullptr, 1, &barrier, 0,
                         nullptr);
}

RgbaImage OffscreenTarget::read() const
{
    RgbaImage out;
    out.width = static_cast<int>(extent_.width);
    out.height = static_cast<int>(extent_.height);
    out.pixels.resize(readback_.size);
    void* mapped = nullptr;
    CHECK_VKCMD(vkMapMemory(ctx_.device(), readback_.memory, 0, readback_.size, 0, &mapped));
    std::memcpy(out.pixels.data(), mapped, out.pixels.size());
    vkUnmapMemory(ctx_.device(), readback_.memory);
    for (std::size_t i = 3; i < out.pixels.size(); i += 4) out.pixels[i] = 255;
    return out;
}

void OffscreenTarget::destroy()
{
    if (framebuffer_) vkDestroyFramebuffer(ctx_.device(), framebuffer_, nullptr);
    framebuffer_ = VK_NULL_HANDLE;
    ctx_.destroy(color_);
    ctx_.destroy(depth_);
    ctx_.destroy(resolve_);
    ctx_.destroy(readback_);
}

} // namespace lobe::vk
