#pragma once
/// \file window_target.h
/// A window's surface and swapchain, which finished offscreen frames are blitted into and
/// presented from (docs/rendering.md, "Presenting to a window"). Internal to app/render/.

#include <cstdint>
#include <vector>

#include "app/render/gpu_types.h"
#include "app/render/vulkan_context.h"

namespace lobe::vk {

/// A window's surface and swapchain (FIFO). Frames are drawn offscreen and blitted (copied
/// when the swapchain's format cannot be blitted into but is the picture's own) into the
/// acquired image. One image-acquired semaphore (each frame's submit is waited for, so it is
/// free again at the next acquire) and one render-done semaphore per swapchain image (the
/// presentation engine has consumed it once the image is acquired again).
class WindowTarget {
public:
    /// Takes ownership of `surface` (destroyed here, also when this throws).
    /// \throw RenderUnavailable when the device's queue cannot present to it; RenderError.
    WindowTarget(const VulkanContext& ctx, VkSurfaceKHR surface);
    ~WindowTarget();
    WindowTarget(const WindowTarget&) = delete;
    WindowTarget& operator=(const WindowTarget&) = delete;

    VkSemaphore acquired() const { return acquired_; }
    VkSemaphore rendered(std::uint32_t image) const { return rendered_[image]; }

    /// Acquires the next image for a frame of `wanted` pixels, making or remaking the
    /// swapchain first when the size changed or the last acquire or present said it is out of
    /// date or suboptimal. False when there is none (the surface is 0 × 0, or none came in
    /// time); `acquired()` is then not signalled.
    /// \throw RenderError when acquiring fails otherwise, or the swapchain cannot be made;
    /// RenderUnavailable when its images cannot be written by transfers or blitted into.
    bool acquire(VkExtent2D wanted, std::uint32_t* image);

    /// After the render pass: `picture` (TRANSFER_SRC_OPTIMAL, `size`) into swapchain image
    /// `image`, left in PRESENT_SRC_KHR.
    void record_blit(VkCommandBuffer cmd, VkImage picture, VkExtent2D size, std::uint32_t image) const;

    /// Queues image `image` for presentation after its render-done semaphore. \throw RenderError
    void present(std::uint32_t image);

private:
    static constexpr std::uint64_t kAcquireTimeoutNs = 2'000'000'000; // 2 s: a window that never gives an image draws nothing

    /// The swapchain for a frame of `wanted` pixels (the surface's own size when it has one);
    /// false, with no swapchain, when the surface is 0 × 0.
    bool create_swapchain(VkExtent2D wanted);
    void destroy_swapchain();
    void destroy();

    const VulkanContext& ctx_;
    VkSurfaceKHR surface_ = VK_NULL_HANDLE;
    VkSwapchainKHR swapchain_ = VK_NULL_HANDLE;
    std::vector<VkImage> images_;
    std::vector<VkSemaphore> rendered_;
    VkSemaphore acquired_ = VK_NULL_HANDLE;
    VkExtent2D extent_{0, 0}, wanted_{0, 0};
    bool stale_ = false;
    bool blit_ = true;
    VkFilter filter_ = VK_FILTER_LINEAR;
};

} // namespace lobe::vk
