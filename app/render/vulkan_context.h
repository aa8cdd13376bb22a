#pragma once
/// \file vulkan_context.h
/// The renderer's Vulkan instance, device and queue: made by the renderer (choosing the
/// device) or by an OpenXR runtime through RendererOptions::vulkan_hooks; memory helpers and
/// one-shot submits (docs/rendering.md, "Devices"). Internal to app/render/.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "app/render/gpu_types.h"
#include "app/render/renderer.h"

namespace lobe::vk {

/// What a RenderUnavailable message tells the person to install.
inline constexpr const char* kInstallHint =
    "install mesa-vulkan-drivers for software rendering (lavapipe), or your GPU's Vulkan driver";

/// The instance, the physical device, the device with its one queue, and one command buffer
/// with its fence for submits that are waited for.
class VulkanContext {
public:
    /// Makes the instance and the device as Renderer::Renderer states (app/render/renderer.h).
    /// \throw RenderUnavailable when no instance or device can be made, an instance extension
    /// is missing, or a hook returns 0; RenderError.
    explicit VulkanContext(const RendererOptions& options);
    ~VulkanContext();
    VulkanContext(const VulkanContext&) = delete;
    VulkanContext& operator=(const VulkanContext&) = delete;

    VkInstance instance() const { return instance_; }
    VkDevice device() const { return device_; }
    VkPhysicalDevice physical() const { return physical_; }
    VkQueue queue() const { return queue_; }
    std::uint32_t queue_family() const { return queue_family_; }
    const std::string& name() const { return name_; }
    bool software() const { return software_; }
    bool presentation() const { return presentation_; }
    bool instance_extension_enabled(const std::string& name) const;
    const VkPhysicalDeviceProperties& properties() const { return properties_; }

    /// A memory type among `bits` with the `wanted` and `required` property flags, else one
    /// with the `required` ones. \throw RenderError when there is none.
    std::uint32_t memory_type(std::uint32_t bits, VkMemoryPropertyFlags wanted, VkMemoryPropertyFlags required) const;
    /// A buffer of `size` bytes in host-visible, coherent memory (`wanted` flags too when a
    /// memory type has them). \throw RenderError
    GpuBuffer create_buffer(VkDeviceSize size, VkBufferUsageFlags usage, VkMemoryPropertyFlags wanted) const;
    /// Copies `bytes` bytes of `data` into `b` at byte `offset`. \throw RenderError
    void write(const GpuBuffer& b, VkDeviceSize offset, const void* data, std::size_t bytes) const;
    /// A 2D image (one mip level, one layer, optimal tiling) in device-local memory, with a view
    /// of `aspect`. \throw RenderError
    GpuImage create_image(VkExtent2D extent, VkFormat format, VkSampleCountFlagBits samples, VkImageUsageFlags usage,
                          VkImageAspectFlags aspect) const;
    /// Frees what `b` holds (any part may be null) and empties it.
    void destroy(GpuBuffer& b) const;
    /// Frees what `im` holds (any part may be null) and empties it.
    void destroy(GpuImage& im) const;

    /// Records with `record` into the context's command buffer, submits and waits. `record_ms`
    /// and `gpu_ms`, when given, receive the milliseconds spent recording and from submit to
    /// fence. \throw RenderError
    void submit_and_wait(const std::function<void(VkCommandBuffer)>& record, double* record_ms = nullptr,
                         double* gpu_ms = nullptr, const SubmitSync& sync = {}) const;

private:
    void create(const RendererOptions& options);
    void create_instance(const RendererOptions& options);
    void choose_device(const RendererOptions& options);
    void choose_hooked_queue(bool presentation);
    void create_device(const RendererOptions::VulkanHooks& hooks);
    void create_command_buffer();
    static bool has_device_extension(VkPhysicalDevice d, const char* name);
    void destroy();

    VkInstance instance_ = VK_NULL_HANDLE;
    VkPhysicalDevice physical_ = VK_NULL_HANDLE;
    VkDevice device_ = VK_NULL_HANDLE;
    VkQueue queue_ = VK_NULL_HANDLE;
    std::uint32_t queue_family_ = 0;
    VkCommandPool command_pool_ = VK_NULL_HANDLE;
    VkCommandBuffer command_buffer_ = VK_NULL_HANDLE;
    VkFence fence_ = VK_NULL_HANDLE;
    VkPhysicalDeviceProperties properties_{};
    VkPhysicalDeviceMemoryProperties memory_{};
    std::string name_;
    bool software_ = false;
    bool presentation_ = false;
    std::vector<std::string> instance_extensions_;
};

} // namespace lobe::vk
