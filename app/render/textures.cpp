// Checking, uploading and binding the renderer's RGBA8 textures (app/render/textures.h).
#include "app/render/textures.h"

#include <string>


namespace lobe::vk {

bool check_rgba(const RgbaImage& tex, const char* what)
{
    if (tex.width == 0 && tex.height == 0 && tex.pixels.empty()) return false;
    if (tex.width < 1 || tex.height < 1 || tex.width > 16384 || tex.height > 16384 ||
        tex.pixels.size() != std::size_t(tex.width) * std::size_t(tex.height) * 4u)
        throw InvalidInput(std::string("render: ") + what + " of " + std::to_string(tex.width) + "x" +
                           std::to_string(tex.height) + " with " + std::to_string(tex.pixels.size()) +
                           " bytes (expected width x height x 4, each side 1 to 16384)");
    return true;
}

GpuImage upload_rgba_texture(const VulkanContext& ctx, const RgbaImage& tex)
{
    const VkExtent2D extent{static_cast<std::uint32_t>(tex.width), static_cast<std::uint32_t>(tex.height)};
    GpuImage texture = ctx.create_image(extent, VK_FORMAT_R8G8B8A8_SRGB, VK_SAMPLE_COUNT_1_BIT,
                                        VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT, VK_IMAGE_ASPECT_COLOR_BIT);
    GpuBuffer staging;
    try {
        staging = ctx.create_buffer(tex.pixels.size(), VK_BUFFER_USAGE_TRANSFER_SRC_BIT, 0);
        ctx.write(staging, 0, tex.pixels.data(), tex.pixels.size());
        ctx.submit_and_wait([&](VkCommandBuffer cmd) {
            auto barrier = vk_struct<VkImageMemoryBarrier>(VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER);
            barrier.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
            barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
            barrier.image = texture.image;
            barrier.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
            barrier.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
            barrier.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
            barrier.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
            vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr, 0, nullptr,
                                 1, &barrier);
            VkBufferImageCopy region{};
            region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
            region.imageExtent = {extent.width, extent.height, 1};
            vkCmdCopyBufferToImage(cmd, staging.buffer, texture.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
            barrier.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
            barrier.newLayout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
            barrier.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
            barrier.dstAccessMask = VK_ACCESS_SHADER_READ_BIT;
            vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT, 0, 0, nullptr, 0,
                                 nullptr, 1, &barrier);
        });
    } catch (...) {
        ctx.destroy(staging);
        ctx.destroy(texture);
        throw;
    }
    ctx.destroy(staging);
    return texture;
}

void write_texture_descriptor(VkDevice device, VkDescriptorSet set, VkSampler sampler, const GpuImage& texture,
                              std::uint32_t binding)
{
    VkDescriptorImageInfo image{sampler, texture.view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
    auto write = vk_struct<VkWriteDescriptorSet>(VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET);
    write.dstSet = set;
    write.dstBinding = binding;
    write.descriptorCount = 1;
    write.descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
    write.pImageInfo = &image;
    vkUpdateDescriptorSets(device, 1, &write, 0, nullptr);
}

} // namespace lobe::vk
