// The renderer's Vulkan instance and device (app/render/vulkan_context.h), and
// keep_vulkan_drivers_loaded (app/render/renderer.h).
#include "app/render/vulkan_context.h"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>

#include <unistd.h>

#include "app/render/loaded_libraries.h"
#include "app/render/vk_check.h"

namespace lobe {
namespace vk {
namespace {

/// A VkResult a hook reported, by name ("VkResult -1000" when it has none here).
std::string hook_result_text(int result)
{
    const auto r = static_cast<VkResult>(result);
    const std::string name = vk::result_name(r);
    if (name == "VK_ERROR_UNKNOWN" && r != VK_ERROR_UNKNOWN) return "VkResult " + std::to_string(result);
    return name;
}

/// Why a hook returned no handle: "VK_ERROR_…", or a note that it gave no VkResult.
std::string hook_failure(const char* hook, int result)
{
    return std::string("RendererOptions::vulkan_hooks.") + hook + " returned 0 (" +
           (result == VK_SUCCESS ? std::string("with no VkResult") : hook_result_text(result)) + ")";
}

// lavapipe warns on every start without XDG_RUNTIME_DIR; give it a private folder.
void ensure_runtime_dir()
{
    if (std::getenv("XDG_RUNTIME_DIR")) return;
    std::error_code ec;
    const std::filesystem::path dir = std::filesystem::temp_directory_path(ec) / ("lobesketch-runtime-" + std::to_string(::getuid()));
    if (ec) return;
    std::filesystem::create_directories(dir, ec);
    std::filesystem::permissions(dir, std::filesystem::perms::owner_all, std::filesystem::perm_options::replace, ec);
    if (!ec) ::setenv("XDG_RUNTIME_DIR", dir.c_str(), 0);
}

} // namespace

VulkanContext::VulkanContext(const RendererOptions& options)
{
    try {
        create(options);
    } catch (...) {
        destroy();
        throw;
    }
}

VulkanContext::~VulkanContext() { destroy(); }

bool VulkanContext::instance_extension_enabled(const std::string& name) const
{
    return std::find(instance_extensions_.begin(), instance_extensions_.end(), name) != instance_extensions_.end();
}

std::uint32_t VulkanContext::memory_type(std::uint32_t bits, VkMemoryPropertyFlags wanted, VkMemoryPropertyFlags required) const
{
    for (VkMemoryPropertyFlags flags : {wanted | required, required})
        for (std::uint32_t i = 0; i < memory_.memoryTypeCount; ++i)
            if ((bits & (1u << i)) && (memory_.memoryTypes[i].propertyFlags & flags) == flags) return i;
    throw RenderError("render: no Vulkan memory type fits (bits " + std::to_string(bits) + ")");
}

GpuBuffer VulkanContext::create_buffer(VkDeviceSize size, VkBufferUsageFlags usage, VkMemoryPropertyFlags wanted) const
{
    GpuBuffer b;
    b.size = size;
    auto info = vk_struct<VkBufferCreateInfo>(VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO);
    info.size = size;
    info.usage = usage;
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    CHECK_VKCMD(vkCreateBuffer(device_, &info, nullptr, &b.buffer));
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(device_, b.buffer, &req);
    auto alloc = vk_struct<VkMemoryAllocateInfo>(VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO);
    alloc.allocationSize = req.size;
    try {
        alloc.memoryTypeIndex = memory_type(req.memoryTypeBits, wanted,
                                            VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
        CHECK_VKCMD(vkAllocateMemory(device_, &alloc, nullptr, &b.memory));
        CHECK_VKCMD(vkBindBufferMemory(device_, b.buffer, b.memory, 0));
    } catch (...) {
        destroy(b);
        throw;
    }
    return b;
}

void VulkanContext::write(const GpuBuffer& b, VkDeviceSize offset, const void* data, std::size_t bytes) const
{
    if (bytes == 0) return;
    void* mapped = nullptr;
    CHECK_VKCMD(vkMapMemory(device_, b.memory, offset, bytes, 0, &mapped));
    std::memcpy(mapped, data, bytes);
    vkUnmapMemory(device_, b.memory);
}

GpuImage VulkanContext::create_image(VkExtent2D extent, VkFormat format, VkSampleCountFlagBits samples, VkImageUsageFlags usage,
                                     VkImageAspectFlags aspect) const
{
    GpuImage im;
    try {
        auto info = vk_struct<VkImageCreateInfo>(VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO);
        info.imageType = VK_IMAGE_TYPE_2D;
        info.format = format;
        info.extent = {extent.width, extent.height, 1};
        info.mipLevels = 1;
        info.arrayLayers = 1;
        info.samples = samples;
        info.tiling = VK_IMAGE_TILING_OPTIMAL;
        info.usage = usage;
        info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
        info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
        CHECK_VKCMD(vkCreateImage(device_, &info, nullptr, &im.image));
        VkMemoryRequirements req;
        vkGetImageMemoryRequirements(device_, im.image, &req);
        auto alloc = vk_struct<VkMemoryAllocateInfo>(VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO);
        alloc.allocationSize = req.size;
        alloc.memoryTypeIndex = memory_type(req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, 0);
        CHECK_VKCMD(vkAllocateMemory(device_, &alloc, nullptr, &im.memory));
        CHECK_VKCMD(vkBindImageMemory(device_, im.image, im.memory, 0));
        auto view = vk_struct<VkImageViewCreateInfo>(VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO);
        view.image = im.image;
        view.viewType = VK_IMAGE_VIEW_TYPE_2D;
        view.format = format;
        view.subresourceRange = {aspect, 0, 1, 0, 1};
        CHECK_VKCMD(vkCreateImageView(device_, &view, nullptr, &im.view));
    } catch (...) {
        destroy(im);
        throw;
    }
    return im;
}

void VulkanContext::destroy(GpuBuffer& b) const
{
    if (b.buffer) vkDestroyBuffer(device_, b.buffer, nullptr);
    if (b.memory) vkFreeMemory(device_, b.memory, nullptr);
    b = {};
}

void VulkanContext::destroy(GpuImage& im) const
{
    if (im.view) vkDestroyImageView(device_, im.view, nullptr);
    if (im.image) vkDestroyImage(device_, im.image, nullptr);
    if (im.memory) vkFreeMemory(device_, im.memory, nullptr);
    im = {};
}

void VulkanContext::submit_and_wait(const std::function<void(VkCommandBuffer)>& record, double* record_ms, double* gpu_ms,
                                    const SubmitSync& sync) const
{
    const auto t0 = std::chrono::steady_clock::now();
    CHECK_VKCMD(vkResetCommandBuffer(command_buffer_, 0));
    auto begin = vk_struct<VkCommandBufferBeginInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO);
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    CHECK_VKCMD(vkBeginCommandBuffer(command_buffer_, &begin));
    record(command_buffer_);
    CHECK_VKCMD(vkEndCommandBuffer(command_buffer_));
    const auto t1 = std::chrono::steady_clock::now();
    CHECK_VKCMD(vkResetFences(device_, 1, &fence_));
    auto submit = vk_struct<VkSubmitInfo>(VK_STRUCTURE_TYPE_SUBMIT_INFO);
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &command_buffer_;
    if (sync.wait) {
        submit.waitSemaphoreCount = 1;
        submit.pWaitSemaphores = &sync.wait;
        submit.pWaitDstStageMask = &sync.wait_stage;
    }
    if (sync.signal) {
        submit.signalSemaphoreCount = 1;
        submit.pSignalSemaphores = &sync.signal;
    }
    CHECK_VKCMD(vkQueueSubmit(queue_, 1, &submit, fence_));
    CHECK_VKCMD(vkWaitForFences(device_, 1, &fence_, VK_TRUE, UINT64_MAX));
    const auto t2 = std::chrono::steady_clock::now();
    if (record_ms) *record_ms = std::chrono::duration<double, std::milli>(t1 - t0).count();
    if (gpu_ms) *gpu_ms = std::chrono::duration<double, std::milli>(t2 - t1).count();
}

void VulkanContext::create(const RendererOptions& options)
{
    // With hooks (an OpenXR runtime's XR_KHR_vulkan_enable2), the instance, the physical
    // device and the device come from them, made from the create infos filled here.
    const RendererOptions::VulkanHooks& hooks = options.vulkan_hooks;
    const bool hooked = !hooks.empty();
    if (bool(hooks.create_instance) != bool(hooks.physical_device) || bool(hooks.create_instance) != bool(hooks.create_device))
        throw RenderError("render: RendererOptions::vulkan_hooks needs all three of create_instance, physical_device and "
                          "create_device, or none");
    ensure_runtime_dir();
    create_instance(options);
    if (hooked) {
        physical_ = handle_from_integer<VkPhysicalDevice>(hooks.physical_device(handle_to_integer(instance_)));
        if (!physical_)
            throw RenderUnavailable("render: no Vulkan device from the OpenXR runtime: "
                                    "RendererOptions::vulkan_hooks.physical_device returned 0");
        choose_hooked_queue(options.presentation);
    } else {
        choose_device(options);
    }
    presentation_ = options.presentation;
    vkGetPhysicalDeviceProperties(physical_, &properties_);
    vkGetPhysicalDeviceMemoryProperties(physical_, &memory_);
    name_ = properties_.deviceName;
    software_ = properties_.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
    create_device(hooks);
    create_command_buffer();
}

/// The instance, with the caller's instance extensions (and the validation layer when asked),
/// made by the loader or by the hooks.
void VulkanContext::create_instance(const RendererOptions& options)
{
    const RendererOptions::VulkanHooks& hooks = options.vulkan_hooks;
    auto app = vk_struct<VkApplicationInfo>(VK_STRUCTURE_TYPE_APPLICATION_INFO);
    app.pApplicationName = "lobesketch";
    app.applicationVersion = VK_MAKE_VERSION(0, 1, 0);
    app.pEngineName = "lobesketch";
    app.apiVersion = VK_API_VERSION_1_1;
    auto info = vk_struct<VkInstanceCreateInfo>(VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO);
    info.pApplicationInfo = &app;
    // The caller's instance extensions (a window's surface extensions), checked first so a
    // missing one is named rather than reported as a missing driver.
    const std::vector<std::string> libraries = loaded_libraries();
    instance_extensions_ = options.instance_extensions;
    std::vector<const char*> extension_names;
    if (!instance_extensions_.empty()) {
        std::uint32_t n = 0;
        const VkResult listed = vkEnumerateInstanceExtensionProperties(nullptr, &n, nullptr);
        std::vector<VkExtensionProperties> available(n);
        if (listed == VK_SUCCESS && n && vkEnumerateInstanceExtensionProperties(nullptr, &n, available.data()) < VK_SUCCESS)
            available.clear(); // a list that cannot be read has nothing in it
        keep_loaded_since(libraries);
        for (const std::string& e : instance_extensions_) {
            const bool found = std::any_of(available.begin(), available.end(),
                                           [&](const VkExtensionProperties& p) { return e == p.extensionName; });
            if (!found)
                throw RenderUnavailable("render: the Vulkan instance extension " + e +
                                        " is not available (a window needs the Vulkan loader and a driver with surface support); " +
                                        kInstallHint);
            extension_names.push_back(e.c_str());
        }
        info.enabledExtensionCount = static_cast<std::uint32_t>(extension_names.size());
        info.ppEnabledExtensionNames = extension_names.data();
    }
    // LOBE_VK_VALIDATION=1 turns on the Khronos validation layer (package vulkan-validationlayers).
    const char* validation = "VK_LAYER_KHRONOS_validation";
    if (const char* v = std::getenv("LOBE_VK_VALIDATION"); v && std::string(v) == "1") {
        info.enabledLayerCount = 1;
        info.ppEnabledLayerNames = &validation;
    }
    if (!hooks.empty()) {
        int result = VK_SUCCESS;
        const std::uint64_t made = hooks.create_instance(&info, result);
        keep_loaded_since(libraries);
        instance_ = handle_from_integer<VkInstance>(made);
        if (!instance_)
            throw RenderUnavailable("render: no Vulkan instance from the OpenXR runtime: " +
                                    hook_failure("create_instance", result));
    } else {
        const VkResult created = vkCreateInstance(&info, nullptr, &instance_);
        keep_loaded_since(libraries);
        if (VkResult r = created; r != VK_SUCCESS) {
            instance_ = VK_NULL_HANDLE;
            throw RenderUnavailable(std::string("render: no Vulkan driver (vkCreateInstance: ") + vk::result_name(r) +
                                    "); " + kInstallHint);
        }
    }
}

/// The device with one queue of the chosen family (and VK_KHR_swapchain when presenting).
void VulkanContext::create_device(const RendererOptions::VulkanHooks& hooks)
{
    const float priority = 1.0f;
    auto queue = vk_struct<VkDeviceQueueCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO);
    queue.queueFamilyIndex = queue_family_;
    queue.queueCount = 1;
    queue.pQueuePriorities = &priority;
    auto dev = vk_struct<VkDeviceCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO);
    dev.queueCreateInfoCount = 1;
    dev.pQueueCreateInfos = &queue;
    const char* swapchain = VK_KHR_SWAPCHAIN_EXTENSION_NAME;
    if (presentation_) {
        dev.enabledExtensionCount = 1;
        dev.ppEnabledExtensionNames = &swapchain;
    }
    if (!hooks.empty()) {
        int result = VK_SUCCESS;
        device_ = handle_from_integer<VkDevice>(hooks.create_device(handle_to_integer(physical_), &dev, result));
        if (!device_)
            throw RenderUnavailable("render: cannot open the Vulkan device '" + name_ + "' through the OpenXR runtime: " +
                                    hook_failure("create_device", result));
    } else if (VkResult r = vkCreateDevice(physical_, &dev, nullptr, &device_); r != VK_SUCCESS) {
        device_ = VK_NULL_HANDLE;
        throw RenderUnavailable("render: cannot open the Vulkan device '" + name_ + "' (vkCreateDevice: " +
                                vk::result_name(r) + "); " + kInstallHint);
    }
    vkGetDeviceQueue(device_, queue_family_, 0, &queue_);
}

/// The command pool, the one command buffer and its fence.
void VulkanContext::create_command_buffer()
{
    auto pool = vk_struct<VkCommandPoolCreateInfo>(VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO);
    pool.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pool.queueFamilyIndex = queue_family_;
    CHECK_VKCMD(vkCreateCommandPool(device_, &pool, nullptr, &command_pool_));
    auto cb = vk_struct<VkCommandBufferAllocateInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO);
    cb.commandPool = command_pool_;
    cb.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    cb.commandBufferCount = 1;
    CHECK_VKCMD(vkAllocateCommandBuffers(device_, &cb, &command_buffer_));
    auto fence = vk_struct<VkFenceCreateInfo>(VK_STRUCTURE_TYPE_FENCE_CREATE_INFO);
    CHECK_VKCMD(vkCreateFence(device_, &fence, nullptr, &fence_));
}

/// The first discrete GPU, else integrated, virtual, other, CPU (CPU first with
/// prefer_software), with a graphics queue (and VK_KHR_swapchain when presenting).
void VulkanContext::choose_device(const RendererOptions& options)
{
    std::uint32_t count = 0;
    CHECK_VKCMD(vkEnumeratePhysicalDevices(instance_, &count, nullptr));
    std::vector<VkPhysicalDevice> devices(count);
    if (count) CHECK_VKCMD(vkEnumeratePhysicalDevices(instance_, &count, devices.data()));
    // Preference: discrete GPU, integrated GPU, virtual GPU, other, CPU (or CPU first).
    auto rank = [&](VkPhysicalDeviceType t) {
        int r = 0;
        switch (t) {
        case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: r = 4; break;
        case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: r = 3; break;
        case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: r = 2; break;
        case VK_PHYSICAL_DEVICE_TYPE_CPU: r = 0; break;
        default: r = 1; break;
        }
        if (options.prefer_software) r = t == VK_PHYSICAL_DEVICE_TYPE_CPU ? 5 : r;
        return r;
    };
    int best_rank = -1;
    for (VkPhysicalDevice d : devices) {
        if (options.presentation && !has_device_extension(d, VK_KHR_SWAPCHAIN_EXTENSION_NAME)) continue;
        std::uint32_t families = 0;
        vkGetPhysicalDeviceQueueFamilyProperties(d, &families, nullptr);
        std::vector<VkQueueFamilyProperties> props(families);
        vkGetPhysicalDeviceQueueFamilyProperties(d, &families, props.data());
        for (std::uint32_t f = 0; f < families; ++f) {
            if (!(props[f].queueFlags & VK_QUEUE_GRAPHICS_BIT)) continue;
            VkPhysicalDeviceProperties p;
            vkGetPhysicalDeviceProperties(d, &p);
            if (rank(p.deviceType) > best_rank) {
                best_rank = rank(p.deviceType);
                physical_ = d;
                queue_family_ = f;
            }
            break;
        }
    }
    if (!physical_)
        throw RenderUnavailable(std::string("render: no Vulkan device with graphics") +
                                (options.presentation ? " and VK_KHR_swapchain (presentation to a window)" : "") + " (" +
                                std::to_string(count) + " device(s) found); " + kInstallHint);
}

/// The device the hooks gave: its first queue family with graphics (and, when presenting,
/// VK_KHR_swapchain), or RenderUnavailable.
void VulkanContext::choose_hooked_queue(bool presentation)
{
    VkPhysicalDeviceProperties p;
    vkGetPhysicalDeviceProperties(physical_, &p);
    const std::string name = p.deviceName;
    if (presentation && !has_device_extension(physical_, VK_KHR_SWAPCHAIN_EXTENSION_NAME))
        throw RenderUnavailable("render: the Vulkan device '" + name +
                                "' the OpenXR runtime chose has no VK_KHR_swapchain (presentation to a window)");
    std::uint32_t families = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(physical_, &families, nullptr);
    std::vector<VkQueueFamilyProperties> props(families);
    vkGetPhysicalDeviceQueueFamilyProperties(physical_, &families, props.data());
    props.resize(families);
    for (std::uint32_t f = 0; f < families; ++f)
        if (props[f].queueFlags & VK_QUEUE_GRAPHICS_BIT) {
            queue_family_ = f;
            return;
        }
    throw RenderUnavailable("render: the Vulkan device '" + name + "' the OpenXR runtime chose has no graphics queue");
}

bool VulkanContext::has_device_extension(VkPhysicalDevice d, const char* name)
{
    std::uint32_t n = 0;
    if (vkEnumerateDeviceExtensionProperties(d, nullptr, &n, nullptr) != VK_SUCCESS) return false;
    std::vector<VkExtensionProperties> props(n);
    if (n && vkEnumerateDeviceExtensionProperties(d, nullptr, &n, props.data()) < VK_SUCCESS) return false;
    return std::any_of(props.begin(), props.end(), [&](const VkExtensionProperties& p) { return std::strcmp(p.extensionName, name) == 0; });
}

void VulkanContext::destroy()
{
    if (device_) {
        vkDeviceWaitIdle(device_);
        if (fence_) vkDestroyFence(device_, fence_, nullptr);
        if (command_pool_) vkDestroyCommandPool(device_, command_pool_, nullptr);
        vkDestroyDevice(device_, nullptr);
    }
    if (instance_) vkDestroyInstance(instance_, nullptr);
    instance_ = VK_NULL_HANDLE;
    device_ = VK_NULL_HANDLE;
}

} // namespace vk

void keep_vulkan_drivers_loaded()
{
    vk::ensure_runtime_dir();
    const std::vector<std::string> before = loaded_libraries();
    auto app = vk::vk_struct<VkApplicationInfo>(VK_STRUCTURE_TYPE_APPLICATION_INFO);
    app.pApplicationName = "lobesketch";
    app.apiVersion = VK_API_VERSION_1_1;
    auto info = vk::vk_struct<VkInstanceCreateInfo>(VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO);
    info.pApplicationInfo = &app;
    VkInstance instance = VK_NULL_HANDLE;
    if (vkCreateInstance(&info, nullptr, &instance) != VK_SUCCESS) return;
    std::uint32_t count = 0;
    vkEnumeratePhysicalDevices(instance, &count, nullptr); // drivers finish loading here, whatever it returns
    keep_loaded_since(before);
    vkDestroyInstance(instance, nullptr);
}

} // namespace lobe
