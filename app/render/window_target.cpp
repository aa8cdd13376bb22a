// A window's surface and swapchain (app/render/window_target.h).
#include "app/render/window_target.h"

#include <algorithm>
#include <string>

#include "app/render/vk_check.h"

namespace lobe::vk {

WindowTarget::WindowTarget(const VulkanContext& ctx, VkSurfaceKHR surface) : ctx_(ctx), surface_(surface)
{
    try {
        VkBool32 supported = VK_FALSE;
        CHECK_VKCMD(vkGetPhysicalDeviceSurfaceSupportKHR(ctx.physical(), ctx.queue_family(), surface_, &supported));
        if (!supported)
            throw RenderUnavailable("render: the Vulkan device '" + ctx.name() + "' cannot present to this window (queue family " +
                                    std::to_string(ctx.queue_family()) + " has no present support)");
        auto info = vk_struct<VkSemaphoreCreateInfo>(VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO);
        CHECK_VKCMD(vkCreateSemaphore(ctx.device(), &info, nullptr, &acquired_));
    } catch (...) {
        destroy();
        throw;
    }
}

WindowTarget::~WindowTarget() { destroy(); }

bool WindowTarget::acquire(VkExtent2D wanted, std::uint32_t* image)
{
    for (int attempt = 0; attempt < 2; ++attempt) {
        if (!swapchain_ || stale_ || wanted.width != wanted_.width || wanted.height != wanted_.height)
            if (!create_swapchain(wanted)) return false;
        const VkResult r = CHECK_VKCMD_ALLOW(
            vkAcquireNextImageKHR(ctx_.device(), swapchain_, kAcquireTimeoutNs, acquired_, VK_NULL_HANDLE, image),
            VK_ERROR_OUT_OF_DATE_KHR);
        if (r == VK_SUCCESS) return true;
        if (r == VK_SUBOPTIMAL_KHR) { // acquired (the semaphore will be signalled): use it, remake next frame
            stale_ = true;
            return true;
        }
        if (r == VK_TIMEOUT || r == VK_NOT_READY) return false;
        stale_ = true; // out of date: remake and try once more
    }
    return false;
}

void WindowTarget::record_blit(VkCommandBuffer cmd, VkImage picture, VkExtent2D size, std::uint32_t image) const
{
    auto barrier = vk_struct<VkImageMemoryBarrier>(VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER);
    barrier.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    barrier.image = images_[image];
    barrier.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    barrier.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    barrier.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    barrier.srcAccessMask = 0;
    barrier.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    // TRANSFER is the stage the submit waits for the image-acquired semaphore at.
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr, 0, nullptr, 1,
                         &barrier);
    if (blit_) {
        VkImageBlit region{};
        region.srcSubresource = region.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
        region.srcOffsets[1] = {std::int32_t(size.width), std::int32_t(size.height), 1};
        region.dstOffsets[1] = {std::int32_t(extent_.width), std::int32_t(extent_.height), 1};
        const bool same = size.width == extent_.width && size.height == extent_.height;
        vkCmdBlitImage(cmd, picture, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, images_[image], VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                       1, &region, same ? VK_FILTER_NEAREST : filter_);
    } else {
        VkImageCopy region{};
        region.srcSubresource = region.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
        region.extent = {std::min(size.width, extent_.width), std::min(size.height, extent_.height), 1};
        vkCmdCopyImage(cmd, picture, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, images_[image], VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1,
                       &region);
    }
    barrier.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    barrier.newLayout = VK_IMAGE_LAYOUT_PRESENT_SRC_KHR;
    barrier.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    barrier.dstAccessMask = 0;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, 0, 0, nullptr, 0, nullptr, 1,
                         &barrier);
}

void WindowTarget::present(std::uint32_t image)
{
    auto info = vk_struct<VkPresentInfoKHR>(VK_STRUCTURE_TYPE_PRESENT_INFO_KHR);
    info.waitSemaphoreCount = 1;
    info.pWaitSemaphores = &rendered_[image];
    info.swapchainCount = 1;
    info.pSwapchains = &swapchain_;
    info.pImageIndices = &image;
    const VkResult r = CHECK_VKCMD_ALLOW(vkQueuePresentKHR(ctx_.queue(), &info), VK_ERROR_OUT_OF_DATE_KHR);
    if (r == VK_SUBOPTIMAL_KHR || r == VK_ERROR_OUT_OF_DATE_KHR) stale_ = true;
}

bool WindowTarget::create_swapchain(VkExtent2D wanted)
{
    const VkDevice dev = ctx_.device();
    VkSurfaceCapabilitiesKHR caps;
    CHECK_VKCMD(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(ctx_.physical(), surface_, &caps));
    VkExtent2D extent = caps.currentExtent;
    if (extent.width == 0xFFFFFFFFu)
        extent = {std::clamp(wanted.width, caps.minImageExtent.width, caps.maxImageExtent.width),
                  std::clamp(wanted.height, caps.minImageExtent.height, caps.maxImageExtent.height)};
    if (extent.width == 0 || extent.height == 0) return false;
    if (!(caps.supportedUsageFlags & VK_IMAGE_USAGE_TRANSFER_DST_BIT))
        throw RenderUnavailable("render: the window's swapchain images of '" + ctx_.name() +
                                "' cannot be written by transfers (no TRANSFER_DST usage)");
    std::uint32_t n = 0;
    CHECK_VKCMD(vkGetPhysicalDeviceSurfaceFormatsKHR(ctx_.physical(), surface_, &n, nullptr));
    std::vector<VkSurfaceFormatKHR> formats(n);
    if (n) CHECK_VKCMD(vkGetPhysicalDeviceSurfaceFormatsKHR(ctx_.physical(), surface_, &n, formats.data()));
    formats.resize(n);
    if (formats.empty()) throw RenderError("render: the window's surface offers no format");
    VkSurfaceFormatKHR format = formats[0];
    if (format.format == VK_FORMAT_UNDEFINED) format = {VK_FORMAT_B8G8R8A8_SRGB, VK_COLOR_SPACE_SRGB_NONLINEAR_KHR};
    for (VkFormat preferred : {VK_FORMAT_R8G8B8A8_SRGB, VK_FORMAT_B8G8R8A8_SRGB}) // the last found wins: B8G8R8A8 first
        for (const VkSurfaceFormatKHR& f : formats)
            if (f.format == preferred && f.colorSpace == VK_COLOR_SPACE_SRGB_NONLINEAR_KHR) format = f;
    VkFormatProperties src, dst;
    vkGetPhysicalDeviceFormatProperties(ctx_.physical(), kColorFormat, &src);
    vkGetPhysicalDeviceFormatProperties(ctx_.physical(), format.format, &dst);
    blit_ = (src.optimalTilingFeatures & VK_FORMAT_FEATURE_BLIT_SRC_BIT) && (dst.optimalTilingFeatures & VK_FORMAT_FEATURE_BLIT_DST_BIT);
    filter_ = (src.optimalTilingFeatures & VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT) ? VK_FILTER_LINEAR : VK_FILTER_NEAREST;
    if (!blit_ && format.format != kColorFormat)
        throw RenderUnavailable("render: the Vulkan device '" + ctx_.name() + "' cannot blit into the window's format (" +
                                std::to_string(int(format.format)) + ")");

    std::uint32_t count = caps.minImageCount + 1;
    if (caps.maxImageCount > 0) count = std::min(count, caps.maxImageCount);
    VkCompositeAlphaFlagBitsKHR alpha = VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR;
    if (!(caps.supportedCompositeAlpha & alpha))
        for (std::uint32_t bit = 1; bit <= VK_COMPOSITE_ALPHA_INHERIT_BIT_KHR; bit <<= 1)
            if (caps.supportedCompositeAlpha & bit) {
                alpha = static_cast<VkCompositeAlphaFlagBitsKHR>(bit);
                break;
            }
    auto info = vk_struct<VkSwapchainCreateInfoKHR>(VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR);
    info.surface = surface_;
    info.minImageCount = count;
    info.imageFormat = format.format;
    info.imageColorSpace = format.colorSpace;
    info.imageExtent = extent;
    info.imageArrayLayers = 1;
    info.imageUsage = VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    info.imageSharingMode = VK_SHARING_MODE_EXCLUSIVE;
    info.preTransform = (caps.supportedTransforms & VK_SURFACE_TRANSFORM_IDENTITY_BIT_KHR) ? VK_SURFACE_TRANSFORM_IDENTITY_BIT_KHR
                                                                                           : caps.currentTransform;
    info.compositeAlpha = alpha;
    info.presentMode = VK_PRESENT_MODE_FIFO_KHR;
    info.clipped = VK_TRUE;
    info.oldSwapchain = swapchain_;
    // Every frame's submit was waited for; the presentation engine may still read the old
    // images until the device is idle.
    CHECK_VKCMD(vkDeviceWaitIdle(dev));
    // The old swapchain is retired whether or not the new one is made: it goes either way.
    VkSwapchainKHR fresh = VK_NULL_HANDLE;
    try {
        CHECK_VKCMD(vkCreateSwapchainKHR(dev, &info, nullptr, &fresh));
    } catch (...) {
        destroy_swapchain();
        throw;
    }
    destroy_swapchain();
    swapchain_ = fresh;
    CHECK_VKCMD(vkGetSwapchainImagesKHR(dev, swapchain_, &n, nullptr));
    images_.resize(n);
    CHECK_VKCMD(vkGetSwapchainImagesKHR(dev, swapchain_, &n, images_.data()));
    rendered_.assign(n, VK_NULL_HANDLE);
    auto semaphore = vk_struct<VkSemaphoreCreateInfo>(VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO);
    for (VkSemaphore& s : rendered_) CHECK_VKCMD(vkCreateSemaphore(dev, &semaphore, nullptr, &s));
    extent_ = extent;
    wanted_ = wanted;
    stale_ = false;
    return true;
}

void WindowTarget::destroy_swapchain()
{
    for (VkSemaphore s : rendered_)
        if (s) vkDestroySemaphore(ctx_.device(), s, nullptr);
    rendered_.clear();
    images_.clear();
    if (swapchain_) vkDestroySwapchainKHR(ctx_.device(), swapchain_, nullptr);
    swapchain_ = VK_NULL_HANDLE;
}

void WindowTarget::destroy()
{
    vkDeviceWaitIdle(ctx_.device());
    destroy_swapchain();
    if (acquired_) vkDestroySemaphore(ctx_.device(), acquired_, nullptr);
    acquired_ = VK_NULL_HANDLE;
    if (surface_) vkDestroySurfaceKHR(ctx_.instance(), surface_, nullptr);
    surface_ = VK_NULL_HANDLE;
}

} // namespace lobe::vk
