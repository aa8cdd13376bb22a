// XR_KHR_vulkan_enable2 and swapchains: images made by the runtime on the application's
// VkDevice, handed out in VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL (depth formats:
// DEPTH_STENCIL_ATTACHMENT_OPTIMAL), and, when LOBESKETCH_REPLAY_DUMP is set, the projection
// views of each frame copied back and written as PNG.

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>

#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STB_IMAGE_WRITE_STATIC
#if defined(__clang__)
#pragma clang diagnostic push
#pragma clang diagnostic ignored "-Wmissing-field-initializers"
#elif defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wconversion"
#pragma GCC diagnostic ignored "-Wsign-conversion"
#endif
#include <stb/stb_image_write.h>
#if defined(__clang__)
#pragma clang diagnostic pop
#elif defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

#include "input/openxr_replay/runtime.h"

namespace lobe::xrr {

/// Device functions and the runtime's own command buffer on the application's queue.
struct Session::VulkanState {
    VkDevice device = VK_NULL_HANDLE;
    VkQueue queue = VK_NULL_HANDLE;
    VkCommandPool pool = VK_NULL_HANDLE;
    VkCommandBuffer cmd = VK_NULL_HANDLE;
    VkFence fence = VK_NULL_HANDLE;
    bool broken = false; ///< a submission did not finish in time: nothing more is submitted
    VkPhysicalDeviceMemoryProperties memory{};
#define LOBE_VK_FN(name) PFN_##name name = nullptr;
    LOBE_VK_FN(vkGetImageMemoryRequirements)
    LOBE_VK_FN(vkCreateImage)
    LOBE_VK_FN(vkDestroyImage)
    LOBE_VK_FN(vkAllocateMemory)
    LOBE_VK_FN(vkFreeMemory)
    LOBE_VK_FN(vkBindImageMemory)
    LOBE_VK_FN(vkCreateBuffer)
    LOBE_VK_FN(vkDestroyBuffer)
    LOBE_VK_FN(vkGetBufferMemoryRequirements)
    LOBE_VK_FN(vkBindBufferMemory)
    LOBE_VK_FN(vkMapMemory)
    LOBE_VK_FN(vkUnmapMemory)
    LOBE_VK_FN(vkCreateCommandPool)
    LOBE_VK_FN(vkDestroyCommandPool)
    LOBE_VK_FN(vkAllocateCommandBuffers)
    LOBE_VK_FN(vkFreeCommandBuffers)
    LOBE_VK_FN(vkBeginCommandBuffer)
    LOBE_VK_FN(vkEndCommandBuffer)
    LOBE_VK_FN(vkResetCommandBuffer)
    LOBE_VK_FN(vkCmdPipelineBarrier)
    LOBE_VK_FN(vkCmdCopyImageToBuffer)
    LOBE_VK_FN(vkQueueSubmit)
    LOBE_VK_FN(vkCreateFence)
    LOBE_VK_FN(vkDestroyFence)
    LOBE_VK_FN(vkWaitForFences)
    LOBE_VK_FN(vkResetFences)
    LOBE_VK_FN(vkGetDeviceQueue)
    PFN_vkGetPhysicalDeviceImageFormatProperties vkGetPhysicalDeviceImageFormatProperties = nullptr;
    VkPhysicalDevice physical = VK_NULL_HANDLE;
#undef LOBE_VK_FN
};

namespace {

using VulkanState = Session::VulkanState;

constexpr std::uint64_t kFenceTimeoutNs = 10'000'000'000ull; // a GPU that takes longer is not waited for

const VkFormat kColorFormats[] = {VK_FORMAT_R8G8B8A8_SRGB, VK_FORMAT_B8G8R8A8_SRGB, VK_FORMAT_R8G8B8A8_UNORM,
                                  VK_FORMAT_B8G8R8A8_UNORM};
const VkFormat kDepthFormats[] = {VK_FORMAT_D32_SFLOAT, VK_FORMAT_D16_UNORM};

bool is_color(VkFormat f)
{
    return std::find(std::begin(kColorFormats), std::end(kColorFormats), f) != std::end(kColorFormats);
}
bool is_depth(VkFormat f)
{
    return std::find(std::begin(kDepthFormats), std::end(kDepthFormats), f) != std::end(kDepthFormats);
}

PFN_vkGetInstanceProcAddr instance_proc_addr(const Instance& inst, VkInstance vk)
{
    auto it = inst.vk_instances.find(vk);
    return it != inst.vk_instances.end() ? it->second : &vkGetInstanceProcAddr;
}

XrResult instance_system_checks(XrInstance instance, XrSystemId system, Instance*& inst)
{
    inst = find<Instance>(key(instance), Kind::Instance);
    if (!inst) return XR_ERROR_HANDLE_INVALID;
    if (!inst->ext_vulkan2) return XR_ERROR_FUNCTION_UNSUPPORTED;
    if (system != kSystemId) return XR_ERROR_SYSTEM_INVALID;
    return XR_SUCCESS;
}

std::uint32_t memory_type(const VulkanState& vk, std::uint32_t bits, VkMemoryPropertyFlags want)
{
    for (std::uint32_t i = 0; i < vk.memory.memoryTypeCount; ++i)
        if ((bits & (1u << i)) && (vk.memory.memoryTypes[i].propertyFlags & want) == want) return i;
    return UINT32_MAX;
}

/// Runs the recorded command buffer and waits for it (bounded).
bool submit_and_wait(VulkanState& vk)
{
    VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &vk.cmd;
    if (vk.vkResetFences(vk.device, 1, &vk.fence) != VK_SUCCESS) return false;
    if (vk.vkQueueSubmit(vk.queue, 1, &submit, vk.fence) != VK_SUCCESS) return false;
    if (vk.vkWaitForFences(vk.device, 1, &vk.fence, VK_TRUE, kFenceTimeoutNs) != VK_SUCCESS) {
        vk.broken = true;
        log_line("the GPU did not finish the runtime's copy within 10 s; no more images are copied");
        return false;
    }
    return true;
}

bool begin_commands(VulkanState& vk)
{
    if (vk.broken) return false;
    if (vk.vkResetCommandBuffer(vk.cmd, 0) != VK_SUCCESS) return false;
    VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    return vk.vkBeginCommandBuffer(vk.cmd, &begin) == VK_SUCCESS;
}

void image_barrier(VulkanState& vk, VkImage image, VkImageAspectFlags aspect, std::uint32_t layer, std::uint32_t layers,
                   std::uint32_t mips, VkImageLayout from, VkImageLayout to, VkAccessFlags src, VkAccessFlags dst)
{
    VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    b.srcAccessMask = src;
    b.dstAccessMask = dst;
    b.oldLayout = from;
    b.newLayout = to;
    b.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = image;
    b.subresourceRange = {aspect, 0, mips, layer, layers};
    vk.vkCmdPipelineBarrier(vk.cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 0,
                            nullptr, 0, nullptr, 1, &b);
}

bool swapchain_checks(XrSwapchain swapchain, Swapchain*& sc, Session*& s, XrResult& r)
{
    sc = find<Swapchain>(key(swapchain), Kind::Swapchain);
    if (!sc) {
        r = XR_ERROR_HANDLE_INVALID;
        return false;
    }
    Instance* inst;
    return session_checks(as_handle<XrSession>(sc->session), s, inst, r);
}

} // namespace

XrResult bind_vulkan_session(Instance& inst, Session& s, const XrGraphicsBindingVulkanKHR& binding)
{
    if (!binding.instance || !binding.physicalDevice || !binding.device) return XR_ERROR_GRAPHICS_DEVICE_INVALID;
    if (inst.vk_physical_device && binding.physicalDevice != inst.vk_physical_device)
        return XR_ERROR_GRAPHICS_DEVICE_INVALID;
    const PFN_vkGetInstanceProcAddr gipa = instance_proc_addr(inst, binding.instance);
    auto vk = std::make_shared<VulkanState>();
    vk->device = binding.device;
    vk->physical = binding.physicalDevice;
    auto get_queue_families = reinterpret_cast<PFN_vkGetPhysicalDeviceQueueFamilyProperties>(
        gipa(binding.instance, "vkGetPhysicalDeviceQueueFamilyProperties"));
    auto get_memory = reinterpret_cast<PFN_vkGetPhysicalDeviceMemoryProperties>(
        gipa(binding.instance, "vkGetPhysicalDeviceMemoryProperties"));
    vk->vkGetPhysicalDeviceImageFormatProperties = reinterpret_cast<PFN_vkGetPhysicalDeviceImageFormatProperties>(
        gipa(binding.instance, "vkGetPhysicalDeviceImageFormatProperties"));
    auto gdpa = reinterpret_cast<PFN_vkGetDeviceProcAddr>(gipa(binding.instance, "vkGetDeviceProcAddr"));
    if (!get_queue_families || !get_memory || !gdpa || !vk->vkGetPhysicalDeviceImageFormatProperties)
        return XR_ERROR_GRAPHICS_DEVICE_INVALID;
    std::uint32_t families = 0;
    get_queue_families(binding.physicalDevice, &families, nullptr);
    std::vector<VkQueueFamilyProperties> props(families);
    get_queue_families(binding.physicalDevice, &families, props.data());
    if (binding.queueFamilyIndex >= families || binding.queueIndex >= props[binding.queueFamilyIndex].queueCount)
        return XR_ERROR_GRAPHICS_DEVICE_INVALID;
    get_memory(binding.physicalDevice, &vk->memory);
    bool all = true;
#define LOBE_VK_LOAD(name) \
    vk->name = reinterpret_cast<PFN_##name>(gdpa(binding.device, #name)); \
    all = all && vk->name != nullptr;
    LOBE_VK_LOAD(vkGetImageMemoryRequirements)
    LOBE_VK_LOAD(vkCreateImage)
    LOBE_VK_LOAD(vkDestroyImage)
    LOBE_VK_LOAD(vkAllocateMemory)
    LOBE_VK_LOAD(vkFreeMemory)
    LOBE_VK_LOAD(vkBindImageMemory)
    LOBE_VK_LOAD(vkCreateBuffer)
    LOBE_VK_LOAD(vkDestroyBuffer)
    LOBE_VK_LOAD(vkGetBufferMemoryRequirements)
    LOBE_VK_LOAD(vkBindBufferMemory)
    LOBE_VK_LOAD(vkMapMemory)
    LOBE_VK_LOAD(vkUnmapMemory)
    LOBE_VK_LOAD(vkCreateCommandPool)
    LOBE_VK_LOAD(vkDestroyCommandPool)
    LOBE_VK_LOAD(vkAllocateCommandBuffers)
    LOBE_VK_LOAD(vkFreeCommandBuffers)
    LOBE_VK_LOAD(vkBeginCommandBuffer)
    LOBE_VK_LOAD(vkEndCommandBuffer)
    LOBE_VK_LOAD(vkResetCommandBuffer)
    LOBE_VK_LOAD(vkCmdPipelineBarrier)
    LOBE_VK_LOAD(vkCmdCopyImageToBuffer)
    LOBE_VK_LOAD(vkQueueSubmit)
    LOBE_VK_LOAD(vkCreateFence)
    LOBE_VK_LOAD(vkDestroyFence)
    LOBE_VK_LOAD(vkWaitForFences)
    LOBE_VK_LOAD(vkResetFences)
    LOBE_VK_LOAD(vkGetDeviceQueue)
#undef LOBE_VK_LOAD
    if (!all) return XR_ERROR_GRAPHICS_DEVICE_INVALID;
    vk->vkGetDeviceQueue(binding.device, binding.queueFamilyIndex, binding.queueIndex, &vk->queue);
    if (!vk->queue) return XR_ERROR_GRAPHICS_DEVICE_INVALID;
    VkCommandPoolCreateInfo pool{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pool.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pool.queueFamilyIndex = binding.queueFamilyIndex;
    if (vk->vkCreateCommandPool(binding.device, &pool, nullptr, &vk->pool) != VK_SUCCESS) return XR_ERROR_RUNTIME_FAILURE;
    s.vk = vk; // from here on release_vulkan_session cleans up
    VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    alloc.commandPool = vk->pool;
    alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    alloc.commandBufferCount = 1;
    if (vk->vkAllocateCommandBuffers(binding.device, &alloc, &vk->cmd) != VK_SUCCESS) return XR_ERROR_RUNTIME_FAILURE;
    VkFenceCreateInfo fence{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    if (vk->vkCreateFence(binding.device, &fence, nullptr, &vk->fence) != VK_SUCCESS) return XR_ERROR_RUNTIME_FAILURE;
    s.vk_instance = binding.instance;
    s.vk_physical_device = binding.physicalDevice;
    s.vk_device = binding.device;
    s.queue_family = binding.queueFamilyIndex;
    s.queue_index = binding.queueIndex;
    return XR_SUCCESS;
}

void release_vulkan_session(Session& s)
{
    if (!s.vk) return;
    VulkanState& vk = *s.vk;
    if (vk.fence) {
        if (!vk.broken) vk.vkWaitForFences(vk.device, 1, &vk.fence, VK_TRUE, kFenceTimeoutNs);
        vk.vkDestroyFence(vk.device, vk.fence, nullptr);
    }
    if (vk.cmd) vk.vkFreeCommandBuffers(vk.device, vk.pool, 1, &vk.cmd);
    if (vk.pool) vk.vkDestroyCommandPool(vk.device, vk.pool, nullptr);
    s.vk.reset();
}

void destroy_swapchain_images(Session& s, Swapchain& sc)
{
    if (!s.vk) return;
    for (auto& img : sc.images) {
        if (img.image) s.vk->vkDestroyImage(s.vk->device, img.image, nullptr);
        if (img.memory) s.vk->vkFreeMemory(s.vk->device, img.memory, nullptr);
    }
    sc.images.clear();
}

void dump_projection(Instance& inst, Session& s, const XrCompositionLayerProjection& layer, std::int64_t frame)
{
    if (!s.vk || s.vk->broken) return;
    VulkanState& vk = *s.vk;
    struct Copy {
        VkBuffer buffer = VK_NULL_HANDLE;
        VkDeviceMemory memory = VK_NULL_HANDLE;
        std::uint32_t width = 0, height = 0;
        bool bgra = false;
    };
    std::vector<Copy> copies(layer.viewCount);
    auto cleanup = [&] {
        for (Copy& c : copies) {
            if (c.buffer) vk.vkDestroyBuffer(vk.device, c.buffer, nullptr);
            if (c.memory) vk.vkFreeMemory(vk.device, c.memory, nullptr);
        }
    };
    if (!begin_commands(vk)) return;
    for (std::uint32_t v = 0; v < layer.viewCount; ++v) {
        const XrSwapchainSubImage& sub = layer.views[v].subImage;
        const Swapchain* sc = find<Swapchain>(key(sub.swapchain), Kind::Swapchain);
        if (!sc || sc->depth || sc->last_released < 0) continue;
        Copy& c = copies[v];
        c.width = static_cast<std::uint32_t>(sub.imageRect.extent.width);
        c.height = static_cast<std::uint32_t>(sub.imageRect.extent.height);
        c.bgra = sc->format == VK_FORMAT_B8G8R8A8_SRGB || sc->format == VK_FORMAT_B8G8R8A8_UNORM;
        VkBufferCreateInfo bi{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
        bi.size = VkDeviceSize(c.width) * c.height * 4;
        bi.usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT;
        bi.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
        if (vk.vkCreateBuffer(vk.device, &bi, nullptr, &c.buffer) != VK_SUCCESS) continue;
        VkMemoryRequirements req;
        vk.vkGetBufferMemoryRequirements(vk.device, c.buffer, &req);
        VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
        ai.allocationSize = req.size;
        ai.memoryTypeIndex = memory_type(vk, req.memoryTypeBits,
                                         VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
        if (ai.memoryTypeIndex == UINT32_MAX || vk.vkAllocateMemory(vk.device, &ai, nullptr, &c.memory) != VK_SUCCESS ||
            vk.vkBindBufferMemory(vk.device, c.buffer, c.memory, 0) != VK_SUCCESS) {
            c.width = 0;
            continue;
        }
        const VkImage image = sc->images[static_cast<std::size_t>(sc->last_released)].image;
        image_barrier(vk, image, VK_IMAGE_ASPECT_COLOR_BIT, sub.imageArrayIndex, 1, 1,
                      VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                      VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_SHADER_WRITE_BIT,
                      VK_ACCESS_TRANSFER_READ_BIT);
        VkBufferImageCopy region{};
        region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, sub.imageArrayIndex, 1};
        region.imageOffset = {sub.imageRect.offset.x, sub.imageRect.offset.y, 0};
        region.imageExtent = {c.width, c.height, 1};
        vk.vkCmdCopyImageToBuffer(vk.cmd, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, c.buffer, 1, &region);
        image_barrier(vk, image, VK_IMAGE_ASPECT_COLOR_BIT, sub.imageArrayIndex, 1, 1, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                      VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_ACCESS_TRANSFER_READ_BIT,
                      VK_ACCESS_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT);
    }
    VkMemoryBarrier host{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    host.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    vk.vkCmdPipelineBarrier(vk.cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &host, 0, nullptr, 0,
                            nullptr);
    if (vk.vkEndCommandBuffer(vk.cmd) != VK_SUCCESS || !submit_and_wait(vk)) {
        if (!vk.broken) cleanup(); // a copy still running keeps its buffers
        return;
    }
    for (std::uint32_t v = 0; v < layer.viewCount; ++v) {
        Copy& c = copies[v];
        if (!c.memory || c.width == 0) continue;
        void* mapped = nullptr;
        if (vk.vkMapMemory(vk.device, c.memory, 0, VK_WHOLE_SIZE, 0, &mapped) != VK_SUCCESS) continue;
        std::vector<unsigned char> pixels(static_cast<const unsigned char*>(mapped),
                                          static_cast<const unsigned char*>(mapped) + std::size_t(c.width) * c.height * 4);
        vk.vkUnmapMemory(vk.device, c.memory);
        if (c.bgra)
            for (std::size_t i = 0; i + 3 < pixels.size(); i += 4) std::swap(pixels[i], pixels[i + 2]);
        char name[64];
        std::snprintf(name, sizeof name, "frame_%06lld_eye%u.png", static_cast<long long>(frame), v);
        const std::string path = (std::filesystem::path(inst.sw.dump_dir) / name).string();
        if (!stbi_write_png(path.c_str(), static_cast<int>(c.width), static_cast<int>(c.height), 4, pixels.data(),
                            static_cast<int>(c.width * 4))) {
            if (!inst.dump_failed_reported) log_line(path + ": cannot write the image; no more images are written");
            inst.dump_failed_reported = true;
            inst.sw.dump_dir.clear();
            break;
        }
    }
    cleanup();
}

XrResult XRAPI_CALL xrGetVulkanGraphicsRequirements2KHR(XrInstance instance, XrSystemId system,
                                                        XrGraphicsRequirementsVulkanKHR* requirements)
{
    return guarded("xrGetVulkanGraphicsRequirements2KHR", [&]() -> XrResult {
        Instance* inst;
        if (XrResult r = instance_system_checks(instance, system, inst); r != XR_SUCCESS) return r;
        if (!requirements || requirements->type != XR_TYPE_GRAPHICS_REQUIREMENTS_VULKAN2_KHR) return XR_ERROR_VALIDATION_FAILURE;
        requirements->minApiVersionSupported = XR_MAKE_VERSION(1, 0, 0);
        requirements->maxApiVersionSupported = XR_MAKE_VERSION(1, 3, 0);
        inst->graphics_requirements_queried = true;
        return XR_SUCCESS;
    });
}

XrResult XRAPI_CALL xrCreateVulkanInstanceKHR(XrInstance instance, const XrVulkanInstanceCreateInfoKHR* info,
                                              VkInstance* vk_instance, VkResult* vk_result)
{
    return guarded("xrCreateVulkanInstanceKHR", [&]() -> XrResult {
        Instance* inst;
        if (!info) return XR_ERROR_VALIDATION_FAILURE;
        if (XrResult r = instance_system_checks(instance, info->systemId, inst); r != XR_SUCCESS) return r;
        if (info->type != XR_TYPE_VULKAN_INSTANCE_CREATE_INFO_KHR || info->createFlags != 0 || !info->pfnGetInstanceProcAddr ||
            !info->vulkanCreateInfo || !vk_instance || !vk_result)
            return XR_ERROR_VALIDATION_FAILURE;
        auto create = reinterpret_cast<PFN_vkCreateInstance>(info->pfnGetInstanceProcAddr(VK_NULL_HANDLE, "vkCreateInstance"));
        if (!create) return XR_ERROR_RUNTIME_FAILURE;
        // The runtime needs no instance extension of its own: the application's request goes as it is.
        *vk_result = create(info->vulkanCreateInfo, info->vulkanAllocator, vk_instance);
        if (*vk_result == VK_SUCCESS) inst->vk_instances[*vk_instance] = info->pfnGetInstanceProcAddr;
        return XR_SUCCESS;
    });
}

XrResult XRAPI_CALL xrGetVulkanGraphicsDevice2KHR(XrInstance instance, const XrVulkanGraphicsDeviceGetInfoKHR* info,
                                                  VkPhysicalDevice* device)
{
    return guarded("xrGetVulkanGraphicsDevice2KHR", [&]() -> XrResult {
        Instance* inst;
        if (!info) return XR_ERROR_VALIDATION_FAILURE;
        if (XrResult r = instance_system_checks(instance, info->systemId, inst); r != XR_SUCCESS) return r;
        if (info->type != XR_TYPE_VULKAN_GRAPHICS_DEVICE_GET_INFO_KHR || !info->vulkanInstance || !device)
            return XR_ERROR_VALIDATION_FAILURE;
        const PFN_vkGetInstanceProcAddr gipa = instance_proc_addr(*inst, info->vulkanInstance);
        auto enum_devices = reinterpret_cast<PFN_vkEnumeratePhysicalDevices>(gipa(info->vulkanInstance, "vkEnumeratePhysicalDevices"));
        auto get_props = reinterpret_cast<PFN_vkGetPhysicalDeviceProperties>(gipa(info->vulkanInstance, "vkGetPhysicalDeviceProperties"));
        if (!enum_devices || !get_props) return XR_ERROR_RUNTIME_FAILURE;
        std::uint32_t n = 0;
        if (enum_devices(info->vulkanInstance, &n, nullptr) != VK_SUCCESS || n == 0) {
            log_line("no Vulkan device found (install a driver, e.g. mesa-vulkan-drivers)");
            return XR_ERROR_RUNTIME_FAILURE;
        }
        std::vector<VkPhysicalDevice> devices(n);
        if (enum_devices(info->vulkanInstance, &n, devices.data()) < 0) return XR_ERROR_RUNTIME_FAILURE;
        devices.resize(n);
        // A real GPU if there is one, else the first device (lavapipe on a machine without GPU).
        VkPhysicalDevice pick = devices.front();
        for (VkPhysicalDevice d : devices) {
            VkPhysicalDeviceProperties p;
            get_props(d, &p);
            if (p.deviceType == VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU || p.deviceType == VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU) {
                pick = d;
                break;
            }
        }
        inst->vk_physical_device = pick;
        inst->vk_physical_device_instance = info->vulkanInstance;
        *device = pick;
        return XR_SUCCESS;
    });
}

XrResult XRAPI_CALL xrCreateVulkanDeviceKHR(XrInstance instance, const XrVulkanDeviceCreateInfoKHR* info, VkDevice* vk_device,
                                            VkResult* vk_result)
{
    return guarded("xrCreateVulkanDeviceKHR", [&]() -> XrResult {
        Instance* inst;
        if (!info) return XR_ERROR_VALIDATION_FAILURE;
        if (XrResult r = instance_system_checks(instance, info->systemId, inst); r != XR_SUCCESS) return r;
        if (info->type != XR_TYPE_VULKAN_DEVICE_CREATE_INFO_KHR || info->createFlags != 0 || !info->pfnGetInstanceProcAddr ||
            !info->vulkanPhysicalDevice || !info->vulkanCreateInfo || !vk_device || !vk_result)
            return XR_ERROR_VALIDATION_FAILURE;
        // The device must be the one xrGetVulkanGraphicsDevice2KHR chose.
        if (!inst->vk_physical_device || info->vulkanPhysicalDevice != inst->vk_physical_device)
            return XR_ERROR_VALIDATION_FAILURE;
        auto create = reinterpret_cast<PFN_vkCreateDevice>(
            info->pfnGetInstanceProcAddr(inst->vk_physical_device_instance, "vkCreateDevice"));
        if (!create) return XR_ERROR_RUNTIME_FAILURE;
        *vk_result = create(info->vulkanPhysicalDevice, info->vulkanCreateInfo, info->vulkanAllocator, vk_device);
        return XR_SUCCESS;
    });
}

XrResult XRAPI_CALL xrEnumerateSwapchainFormats(XrSession session, uint32_t capacity, uint32_t* count, int64_t* formats)
{
    return guarded("xrEnumerateSwapchainFormats", [&]() -> XrResult {
        Session* s;
        Instance* inst;
        XrResult r;
        if (!session_checks(session, s, inst, r)) return r;
        std::vector<int64_t> list;
        if (!s->headless) {
            for (VkFormat f : kColorFormats) list.push_back(f);
            for (VkFormat f : kDepthFormats) list.push_back(f);
        }
        return enumerate(list, capacity, count, formats);
    });
}

XrResult XRAPI_CALL xrCreateSwapchain(XrSession session, const XrSwapchainCreateInfo* info, XrSwapchain* out)
{
    return guarded("xrCreateSwapchain", [&]() -> XrResult {
        Session* s;
        Instance* inst;
        XrResult r;
        if (!session_checks(session, s, inst, r)) return r;
        if (!info || !out || info->type != XR_TYPE_SWAPCHAIN_CREATE_INFO) return XR_ERROR_VALIDATION_FAILURE;
        if (s->headless || !s->vk) return XR_ERROR_SWAPCHAIN_FORMAT_UNSUPPORTED; // headless: no formats at all
        if (info->createFlags & XR_SWAPCHAIN_CREATE_PROTECTED_CONTENT_BIT) return XR_ERROR_FEATURE_UNSUPPORTED;
        if (info->createFlags & ~XrSwapchainCreateFlags(XR_SWAPCHAIN_CREATE_STATIC_IMAGE_BIT)) return XR_ERROR_VALIDATION_FAILURE;
        const auto format = static_cast<VkFormat>(info->format);
        const bool depth = is_depth(format);
        if (!is_color(format) && !depth) return XR_ERROR_SWAPCHAIN_FORMAT_UNSUPPORTED;
        if (info->width == 0 || info->height == 0 || info->width > 4096 || info->height > 4096 || info->sampleCount != 1 ||
            info->faceCount != 1 || info->arraySize == 0 || info->arraySize > 16 || info->mipCount == 0 || info->mipCount > 13)
            return XR_ERROR_VALIDATION_FAILURE;
        const XrSwapchainUsageFlags u = info->usageFlags;
        if ((depth && (u & XR_SWAPCHAIN_USAGE_COLOR_ATTACHMENT_BIT)) ||
            (!depth && (u & XR_SWAPCHAIN_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT)))
            return XR_ERROR_VALIDATION_FAILURE;
        VkImageUsageFlags usage = 0;
        if (u & XR_SWAPCHAIN_USAGE_COLOR_ATTACHMENT_BIT) usage |= VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT;
        if (u & XR_SWAPCHAIN_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT) usage |= VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT;
        if (u & XR_SWAPCHAIN_USAGE_UNORDERED_ACCESS_BIT) usage |= VK_IMAGE_USAGE_STORAGE_BIT;
        if (u & XR_SWAPCHAIN_USAGE_TRANSFER_SRC_BIT) usage |= VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
        if (u & XR_SWAPCHAIN_USAGE_TRANSFER_DST_BIT) usage |= VK_IMAGE_USAGE_TRANSFER_DST_BIT;
        if (u & XR_SWAPCHAIN_USAGE_SAMPLED_BIT) usage |= VK_IMAGE_USAGE_SAMPLED_BIT;
        if (u & XR_SWAPCHAIN_USAGE_INPUT_ATTACHMENT_BIT_MND) usage |= VK_IMAGE_USAGE_INPUT_ATTACHMENT_BIT;
        if (!depth) usage |= VK_IMAGE_USAGE_TRANSFER_SRC_BIT; // the PNG dump copies from it
        const VkImageCreateFlags flags = (u & XR_SWAPCHAIN_USAGE_MUTABLE_FORMAT_BIT) ? VK_IMAGE_CREATE_MUTABLE_FORMAT_BIT : 0;
        VulkanState& vk = *s->vk;
        VkImageFormatProperties fp;
        if (vk.vkGetPhysicalDeviceImageFormatProperties(vk.physical, format, VK_IMAGE_TYPE_2D, VK_IMAGE_TILING_OPTIMAL, usage,
                                                        flags, &fp) != VK_SUCCESS ||
            fp.maxExtent.width < info->width || fp.maxExtent.height < info->height || fp.maxArrayLayers < info->arraySize ||
            fp.maxMipLevels < info->mipCount)
            return XR_ERROR_SWAPCHAIN_FORMAT_UNSUPPORTED;

        auto sc = std::make_unique<Swapchain>();
        sc->session = s->handle;
        sc->info = *info;
        sc->info.next = nullptr;
        sc->format = format;
        sc->depth = depth;
        const std::uint32_t count = (info->createFlags & XR_SWAPCHAIN_CREATE_STATIC_IMAGE_BIT) ? 1 : 3;
        Swapchain& ref = *sc;
        const std::uint64_t h = add_object(std::move(sc), s->handle);
        auto fail = [&](XrResult e) {
            destroy_object(h);
            return e;
        };
        for (std::uint32_t i = 0; i < count; ++i) {
            VkImageCreateInfo ci{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
            ci.flags = flags;
            ci.imageType = VK_IMAGE_TYPE_2D;
            ci.format = format;
            ci.extent = {info->width, info->height, 1};
            ci.mipLevels = info->mipCount;
            ci.arrayLayers = info->arraySize;
            ci.samples = VK_SAMPLE_COUNT_1_BIT;
            ci.tiling = VK_IMAGE_TILING_OPTIMAL;
            ci.usage = usage;
            ci.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
            ci.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
            Swapchain::Image img;
            if (vk.vkCreateImage(vk.device, &ci, nullptr, &img.image) != VK_SUCCESS) return fail(XR_ERROR_RUNTIME_FAILURE);
            ref.images.push_back(img);
            VkMemoryRequirements req;
            vk.vkGetImageMemoryRequirements(vk.device, img.image, &req);
            VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
            ai.allocationSize = req.size;
            ai.memoryTypeIndex = memory_type(vk, req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
            if (ai.memoryTypeIndex == UINT32_MAX) ai.memoryTypeIndex = memory_type(vk, req.memoryTypeBits, 0);
            if (ai.memoryTypeIndex == UINT32_MAX) return fail(XR_ERROR_RUNTIME_FAILURE);
            if (vk.vkAllocateMemory(vk.device, &ai, nullptr, &ref.images.back().memory) != VK_SUCCESS)
                return fail(XR_ERROR_RUNTIME_FAILURE);
            if (vk.vkBindImageMemory(vk.device, img.image, ref.images.back().memory, 0) != VK_SUCCESS)
                return fail(XR_ERROR_RUNTIME_FAILURE);
        }
        *out = as_handle<XrSwapchain>(h);
        return XR_SUCCESS;
    });
}

XrResult XRAPI_CALL xrDestroySwapchain(XrSwapchain swapchain)
{
    return guarded("xrDestroySwapchain", [&]() -> XrResult {
        Swapchain* sc = find<Swapchain>(key(swapchain), Kind::Swapchain);
        if (!sc) return XR_ERROR_HANDLE_INVALID;
        destroy_object(sc->handle);
        return XR_SUCCESS;
    });
}

XrResult XRAPI_CALL xrEnumerateSwapchainImages(XrSwapchain swapchain, uint32_t capacity, uint32_t* count,
                                               XrSwapchainImageBaseHeader* images)
{
    return guarded("xrEnumerateSwapchainImages", [&]() -> XrResult {
        Swapchain* sc;
        Session* s;
        XrResult r;
        if (!swapchain_checks(swapchain, sc, s, r)) return r;
        if (!count) return XR_ERROR_VALIDATION_FAILURE;
        *count = static_cast<std::uint32_t>(sc->images.size());
        if (capacity == 0) return XR_SUCCESS;
        if (!images) return XR_ERROR_VALIDATION_FAILURE;
        if (capacity < sc->images.size()) return XR_ERROR_SIZE_INSUFFICIENT;
        auto* out = reinterpret_cast<XrSwapchainImageVulkanKHR*>(images);
        for (std::size_t i = 0; i < sc->images.size(); ++i)
            if (out[i].type != XR_TYPE_SWAPCHAIN_IMAGE_VULKAN2_KHR) return XR_ERROR_VALIDATION_FAILURE;
        for (std::size_t i = 0; i < sc->images.size(); ++i) out[i].image = sc->images[i].image;
        return XR_SUCCESS;
    });
}

XrResult XRAPI_CALL xrAcquireSwapchainImage(XrSwapchain swapchain, const XrSwapchainImageAcquireInfo* info, uint32_t* index)
{
    return guarded("xrAcquireSwapchainImage", [&]() -> XrResult {
        Swapchain* sc;
        Session* s;
        XrResult r;
        if (!swapchain_checks(swapchain, sc, s, r)) return r;
        if ((info && info->type != XR_TYPE_SWAPCHAIN_IMAGE_ACQUIRE_INFO) || !index) return XR_ERROR_VALIDATION_FAILURE;
        if (sc->acquired.size() >= sc->images.size()) return XR_ERROR_CALL_ORDER_INVALID;
        if ((sc->info.createFlags & XR_SWAPCHAIN_CREATE_STATIC_IMAGE_BIT) && sc->static_image_released)
            return XR_ERROR_CALL_ORDER_INVALID;
        Swapchain::Image& img = sc->images[sc->next_acquire];
        if (!img.ready) {
            if (!s->vk) return XR_ERROR_RUNTIME_FAILURE;
            // Hand the image out in the layout the Vulkan binding promises. This is done here,
            // not in xrCreateSwapchain, because the binding's queue may be used only in the
            // calls the specification lists (acquire, release, xrBeginFrame, xrEndFrame).
            VulkanState& vk = *s->vk;
            const bool depth = sc->depth;
            if (!begin_commands(vk)) return XR_ERROR_RUNTIME_FAILURE;
            image_barrier(vk, img.image, depth ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT, 0, sc->info.arraySize,
                          sc->info.mipCount, VK_IMAGE_LAYOUT_UNDEFINED,
                          depth ? VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL : VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, 0,
                          depth ? VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT : VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT);
            if (vk.vkEndCommandBuffer(vk.cmd) != VK_SUCCESS || !submit_and_wait(vk)) return XR_ERROR_RUNTIME_FAILURE;
            img.ready = true;
        }
        *index = sc->next_acquire;
        sc->acquired.push_back(sc->next_acquire);
        sc->next_acquire = (sc->next_acquire + 1) % static_cast<std::uint32_t>(sc->images.size());
        return XR_SUCCESS;
    });
}

XrResult XRAPI_CALL xrWaitSwapchainImage(XrSwapchain swapchain, const XrSwapchainImageWaitInfo* info)
{
    return guarded("xrWaitSwapchainImage", [&]() -> XrResult {
        Swapchain* sc;
        Session* s;
        XrResult r;
        if (!swapchain_checks(swapchain, sc, s, r)) return r;
        if (!info || info->type != XR_TYPE_SWAPCHAIN_IMAGE_WAIT_INFO) return XR_ERROR_VALIDATION_FAILURE;
        if (sc->acquired.empty() || sc->waited) return XR_ERROR_CALL_ORDER_INVALID;
        sc->waited = true; // the compositor never holds an image: it is ready at once
        return XR_SUCCESS;
    });
}

XrResult XRAPI_CALL xrReleaseSwapchainImage(XrSwapchain swapchain, const XrSwapchainImageReleaseInfo* info)
{
    return guarded("xrReleaseSwapchainImage", [&]() -> XrResult {
        Swapchain* sc;
        Session* s;
        XrResult r;
        if (!swapchain_checks(swapchain, sc, s, r)) return r;
        if (info && info->type != XR_TYPE_SWAPCHAIN_IMAGE_RELEASE_INFO) return XR_ERROR_VALIDATION_FAILURE;
        if (sc->acquired.empty() || !sc->waited) return XR_ERROR_CALL_ORDER_INVALID;
        sc->last_released = sc->acquired.front();
        sc->acquired.pop_front();
        sc->waited = false;
        if (sc->info.createFlags & XR_SWAPCHAIN_CREATE_STATIC_IMAGE_BIT) sc->static_image_released = true;
        return XR_SUCCESS;
    });
}

} // namespace lobe::xrr
