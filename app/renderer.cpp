// The Vulkan renderer behind app/renderer.h. Three parts, each a small class:
//  - VulkanContext: instance, device choice, queue, memory helpers, one-shot submits;
//  - OffscreenTarget: the images a frame is drawn into (MSAA colour, depth, resolve) and the
//    buffer it is read back through. A swapchain target would bring its own images and a
//    render pass of the same formats and sample count (compatible with the pipelines, which
//    only need compatibility), and reuse SceneDrawer unchanged;
//  - SceneDrawer: pipelines, the leaf texture, the per-mesh GPU buffer cache (keyed by
//    RenderItem::key, re-uploaded only when RenderItem::version changes) and recording the
//    draws of one frame into a command buffer inside any compatible render pass.
#include "app/renderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <functional>
#include <unordered_map>
#include <unordered_set>

#include <glm/ext/matrix_clip_space.hpp>
#include <glm/ext/matrix_transform.hpp>
#include <glm/geometric.hpp>
#include <glm/mat4x4.hpp>
#include <glm/matrix.hpp>
#include <glm/vec4.hpp>

#include <dlfcn.h>
#include <link.h>
#include <unistd.h>

#include "app/embedded_shaders.h"
#include "app/vk_check.h"

namespace lobe {

void Bounds::add(const glm::vec3& p)
{
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
}

Bounds scene_bounds(const RenderScene& scene)
{
    Bounds b;
    for (const RenderItem& item : scene.items)
        for (const glm::vec3& p : item.geometry.positions) b.add(p);
    return b;
}

ViewAngles front_view() { return {0.0f, 0.0f}; }
ViewAngles side_view() { return {90.0f, 0.0f}; }
ViewAngles top_view() { return {0.0f, 90.0f}; }

Camera frame_view(const Bounds& bounds_in, const ViewAngles& view, float aspect, float fov_y_deg, float margin)
{
    Bounds b = bounds_in;
    if (b.empty()) b = Bounds{glm::vec3(-0.5f), glm::vec3(0.5f)};
    const glm::vec3 centre = 0.5f * (b.lo + b.hi);
    const float az = glm::radians(view.azimuth_deg), el = glm::radians(view.elevation_deg);
    // Towards the camera, and the picture's right and up.
    const glm::vec3 back(std::cos(el) * std::sin(az), std::sin(el), std::cos(el) * std::cos(az));
    const glm::vec3 up_hint = std::abs(back.y) > 0.999f ? glm::vec3(-std::sin(az), 0.0f, -std::cos(az)) : glm::vec3(0, 1, 0);
    const glm::vec3 right = glm::normalize(glm::cross(up_hint, back));
    const glm::vec3 up = glm::cross(back, right);
    const float tan_y = std::tan(glm::radians(fov_y_deg) * 0.5f) * (1.0f - 2.0f * margin);
    const float tan_x = std::tan(glm::radians(fov_y_deg) * 0.5f) * aspect * (1.0f - 2.0f * margin);
    float distance = 0.0f, radius = 0.0f;
    for (int i = 0; i < 8; ++i) {
        const glm::vec3 corner((i & 1) ? b.hi.x : b.lo.x, (i & 2) ? b.hi.y : b.lo.y, (i & 4) ? b.hi.z : b.lo.z);
        const glm::vec3 p = corner - centre;
        const float z = glm::dot(p, back);
        distance = std::max({distance, z + std::abs(glm::dot(p, right)) / tan_x, z + std::abs(glm::dot(p, up)) / tan_y});
        radius = std::max(radius, glm::length(p));
    }
    distance = std::max(distance, 1e-3f);
    Camera c;
    c.eye = centre + back * distance;
    c.target = centre;
    c.up = up;
    c.fov_y_deg = fov_y_deg;
    c.near_m = std::max(1e-3f, (distance - radius) * 0.5f);
    c.far_m = distance + 40.0f * std::max(radius, 0.5f);
    return c;
}

namespace {

/// A zero-initialised Vulkan info struct with its sType set.
template <class T>
T vk_struct(VkStructureType type)
{
    T s{};
    s.sType = type;
    return s;
}

constexpr VkFormat kColorFormat = VK_FORMAT_R8G8B8A8_SRGB;

/// What every pipeline gets (app/shaders/*: the same 112-byte block, read per shader).
struct PushBlock {
    glm::mat4 matrix;   // view-projection (sky: its inverse)
    glm::vec4 color;    // material colour (ground: centre and half size)
    glm::vec4 eye;      // camera position
    glm::vec4 params;   // x: material (mesh) or cell size (ground)
};
static_assert(sizeof(PushBlock) == 112);

struct Vertex {
    float position[3];
    float normal[3];
    float uv[2];
};
static_assert(sizeof(Vertex) == 32);

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

/// Paths of the shared libraries loaded in the process now.
std::vector<std::string> loaded_libraries()
{
    std::vector<std::string> out;
    dl_iterate_phdr(
        [](dl_phdr_info* info, std::size_t, void* data) {
            if (info->dlpi_name && info->dlpi_name[0]) static_cast<std::vector<std::string>*>(data)->push_back(info->dlpi_name);
            return 0;
        },
        &out);
    return out;
}

/// Keeps the libraries that creating an instance loaded (the Vulkan drivers and what they
/// need, e.g. lavapipe and LLVM) loaded until the process ends. Mesa's drivers keep global
/// state that they do not free when the loader unloads them with the last instance; loaded
/// once, they are not loaded again for the next Renderer either.
void keep_drivers_loaded(const std::vector<std::string>& before)
{
    for (const std::string& lib : loaded_libraries())
        if (std::find(before.begin(), before.end(), lib) == before.end())
            dlopen(lib.c_str(), RTLD_NOW | RTLD_NOLOAD | RTLD_NODELETE);
}

const char* const kInstallHint =
    "install mesa-vulkan-drivers for software rendering (lavapipe), or your GPU's Vulkan driver";

struct GpuBuffer {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkDeviceSize size = 0;
};

struct GpuImage {
    VkImage image = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkImageView view = VK_NULL_HANDLE;
};

// ---------------------------------------------------------------------------------------------
class VulkanContext {
public:
    explicit VulkanContext(const RendererOptions& options)
    {
        try {
            create(options);
        } catch (...) {
            destroy();
            throw;
        }
    }
    ~VulkanContext() { destroy(); }
    VulkanContext(const VulkanContext&) = delete;
    VulkanContext& operator=(const VulkanContext&) = delete;

    VkDevice device() const { return device_; }
    VkPhysicalDevice physical() const { return physical_; }
    VkQueue queue() const { return queue_; }
    std::uint32_t queue_family() const { return queue_family_; }
    const std::string& name() const { return name_; }
    bool software() const { return software_; }
    const VkPhysicalDeviceProperties& properties() const { return properties_; }

    std::uint32_t memory_type(std::uint32_t bits, VkMemoryPropertyFlags wanted, VkMemoryPropertyFlags required) const
    {
        for (VkMemoryPropertyFlags flags : {wanted | required, required})
            for (std::uint32_t i = 0; i < memory_.memoryTypeCount; ++i)
                if ((bits & (1u << i)) && (memory_.memoryTypes[i].propertyFlags & flags) == flags) return i;
        throw RenderError("render: no Vulkan memory type fits (bits " + std::to_string(bits) + ")");
    }

    GpuBuffer create_buffer(VkDeviceSize size, VkBufferUsageFlags usage, VkMemoryPropertyFlags wanted) const
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

    void write(const GpuBuffer& b, VkDeviceSize offset, const void* data, std::size_t bytes) const
    {
        if (bytes == 0) return;
        void* mapped = nullptr;
        CHECK_VKCMD(vkMapMemory(device_, b.memory, offset, bytes, 0, &mapped));
        std::memcpy(mapped, data, bytes);
        vkUnmapMemory(device_, b.memory);
    }

    GpuImage create_image(VkExtent2D extent, VkFormat format, VkSampleCountFlagBits samples, VkImageUsageFlags usage,
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

    void destroy(GpuBuffer& b) const
    {
        if (b.buffer) vkDestroyBuffer(device_, b.buffer, nullptr);
        if (b.memory) vkFreeMemory(device_, b.memory, nullptr);
        b = {};
    }
    void destroy(GpuImage& im) const
    {
        if (im.view) vkDestroyImageView(device_, im.view, nullptr);
        if (im.image) vkDestroyImage(device_, im.image, nullptr);
        if (im.memory) vkFreeMemory(device_, im.memory, nullptr);
        im = {};
    }

    /// Records with `record` into the context's command buffer, submits and waits.
    void submit_and_wait(const std::function<void(VkCommandBuffer)>& record, double* record_ms = nullptr,
                         double* gpu_ms = nullptr) const
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
        CHECK_VKCMD(vkQueueSubmit(queue_, 1, &submit, fence_));
        CHECK_VKCMD(vkWaitForFences(device_, 1, &fence_, VK_TRUE, UINT64_MAX));
        const auto t2 = std::chrono::steady_clock::now();
        if (record_ms) *record_ms = std::chrono::duration<double, std::milli>(t1 - t0).count();
        if (gpu_ms) *gpu_ms = std::chrono::duration<double, std::milli>(t2 - t1).count();
    }

private:
    void create(const RendererOptions& options)
    {
        ensure_runtime_dir();
        auto app = vk_struct<VkApplicationInfo>(VK_STRUCTURE_TYPE_APPLICATION_INFO);
        app.pApplicationName = "lobesketch";
        app.applicationVersion = VK_MAKE_VERSION(0, 1, 0);
        app.pEngineName = "lobesketch";
        app.apiVersion = VK_API_VERSION_1_1;
        auto info = vk_struct<VkInstanceCreateInfo>(VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO);
        info.pApplicationInfo = &app;
        // LOBE_VK_VALIDATION=1 turns on the Khronos validation layer (package vulkan-validationlayers).
        const char* validation = "VK_LAYER_KHRONOS_validation";
        if (const char* v = std::getenv("LOBE_VK_VALIDATION"); v && std::string(v) == "1") {
            info.enabledLayerCount = 1;
            info.ppEnabledLayerNames = &validation;
        }
        const std::vector<std::string> libraries = loaded_libraries();
        const VkResult created = vkCreateInstance(&info, nullptr, &instance_);
        keep_drivers_loaded(libraries);
        if (VkResult r = created; r != VK_SUCCESS) {
            instance_ = VK_NULL_HANDLE;
            throw RenderUnavailable(std::string("render: no Vulkan driver (vkCreateInstance: ") + vk::result_name(r) +
                                    "); " + kInstallHint);
        }
        std::uint32_t count = 0;
        vkEnumeratePhysicalDevices(instance_, &count, nullptr);
        std::vector<VkPhysicalDevice> devices(count);
        if (count) vkEnumeratePhysicalDevices(instance_, &count, devices.data());
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
            throw RenderUnavailable(std::string("render: no Vulkan device with graphics (") + std::to_string(count) +
                                    " device(s) found); " + kInstallHint);
        vkGetPhysicalDeviceProperties(physical_, &properties_);
        vkGetPhysicalDeviceMemoryProperties(physical_, &memory_);
        name_ = properties_.deviceName;
        software_ = properties_.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;

        const float priority = 1.0f;
        auto queue = vk_struct<VkDeviceQueueCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO);
        queue.queueFamilyIndex = queue_family_;
        queue.queueCount = 1;
        queue.pQueuePriorities = &priority;
        auto dev = vk_struct<VkDeviceCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO);
        dev.queueCreateInfoCount = 1;
        dev.pQueueCreateInfos = &queue;
        if (VkResult r = vkCreateDevice(physical_, &dev, nullptr, &device_); r != VK_SUCCESS) {
            device_ = VK_NULL_HANDLE;
            throw RenderUnavailable("render: cannot open the Vulkan device '" + name_ + "' (vkCreateDevice: " +
                                    vk::result_name(r) + "); " + kInstallHint);
        }
        vkGetDeviceQueue(device_, queue_family_, 0, &queue_);
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

    void destroy()
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
};

// ---------------------------------------------------------------------------------------------
/// Formats and sample count shared by the render pass, the targets and the pipelines.
struct FrameFormat {
    VkFormat color = kColorFormat;
    VkFormat depth = VK_FORMAT_D32_SFLOAT;
    VkSampleCountFlagBits samples = VK_SAMPLE_COUNT_4_BIT;
};

FrameFormat choose_frame_format(const VulkanContext& ctx, int requested_samples)
{
    FrameFormat f;
    VkFormatProperties props;
    vkGetPhysicalDeviceFormatProperties(ctx.physical(), kColorFormat, &props);
    const VkFormatFeatureFlags color_needs = VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT | VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BLEND_BIT |
                                             VK_FORMAT_FEATURE_TRANSFER_SRC_BIT;
    if ((props.optimalTilingFeatures & color_needs) != color_needs)
        throw RenderUnavailable("render: the Vulkan device '" + ctx.name() + "' cannot draw into RGBA8 sRGB images; " +
                                kInstallHint);
    f.depth = VK_FORMAT_UNDEFINED;
    for (VkFormat d : {VK_FORMAT_D32_SFLOAT, VK_FORMAT_D24_UNORM_S8_UINT, VK_FORMAT_D16_UNORM}) {
        vkGetPhysicalDeviceFormatProperties(ctx.physical(), d, &props);
        if (props.optimalTilingFeatures & VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT) {
            f.depth = d;
            break;
        }
    }
    if (f.depth == VK_FORMAT_UNDEFINED)
        throw RenderUnavailable("render: the Vulkan device '" + ctx.name() + "' has no depth format; " + kInstallHint);
    const VkSampleCountFlags counts = ctx.properties().limits.framebufferColorSampleCounts &
                                      ctx.properties().limits.framebufferDepthSampleCounts;
    f.samples = VK_SAMPLE_COUNT_1_BIT;
    for (int s : {8, 4, 2})
        if (s <= requested_samples && (counts & static_cast<VkSampleCountFlags>(s))) {
            f.samples = static_cast<VkSampleCountFlagBits>(s);
            break;
        }
    return f;
}

bool multisampled(const FrameFormat& f) { return f.samples != VK_SAMPLE_COUNT_1_BIT; }

/// The offscreen render pass: clear, draw, resolve (when multisampled), leave the picture
/// ready to be copied out.
VkRenderPass create_offscreen_render_pass(VkDevice device, const FrameFormat& f)
{
    const bool ms = multisampled(f);
    VkAttachmentDescription att[3]{};
    att[0].format = f.color;
    att[0].samples = f.samples;
    att[0].loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
    att[0].storeOp = ms ? VK_ATTACHMENT_STORE_OP_DONT_CARE : VK_ATTACHMENT_STORE_OP_STORE;
    att[0].stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
    att[0].stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
    att[0].initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    att[0].finalLayout = ms ? VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL : VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
    att[1].format = f.depth;
    att[1].samples = f.samples;
    att[1].loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
    att[1].storeOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
    att[1].stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
    att[1].stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
    att[1].initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    att[1].finalLayout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
    att[2].format = f.color;
    att[2].samples = VK_SAMPLE_COUNT_1_BIT;
    att[2].loadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
    att[2].storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    att[2].stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
    att[2].stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
    att[2].initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    att[2].finalLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
    VkAttachmentReference color_ref{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
    VkAttachmentReference depth_ref{1, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
    VkAttachmentReference resolve_ref{2, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
    VkSubpassDescription sub{};
    sub.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
    sub.colorAttachmentCount = 1;
    sub.pColorAttachments = &color_ref;
    sub.pResolveAttachments = ms ? &resolve_ref : nullptr;
    sub.pDepthStencilAttachment = &depth_ref;
    VkSubpassDependency deps[2]{};
    deps[0].srcSubpass = VK_SUBPASS_EXTERNAL;
    deps[0].dstSubpass = 0;
    deps[0].srcStageMask = VK_PIPELINE_STAGE_TRANSFER_BIT;
    deps[0].dstStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT;
    deps[0].srcAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
    deps[0].dstAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
    deps[1].srcSubpass = 0;
    deps[1].dstSubpass = VK_SUBPASS_EXTERNAL;
    deps[1].srcStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
    deps[1].dstStageMask = VK_PIPELINE_STAGE_TRANSFER_BIT;
    deps[1].srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
    deps[1].dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
    auto info = vk_struct<VkRenderPassCreateInfo>(VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO);
    info.attachmentCount = ms ? 3u : 2u;
    info.pAttachments = att;
    info.subpassCount = 1;
    info.pSubpasses = &sub;
    info.dependencyCount = 2;
    info.pDependencies = deps;
    VkRenderPass pass = VK_NULL_HANDLE;
    CHECK_VKCMD(vkCreateRenderPass(device, &info, nullptr, &pass));
    return pass;
}

// ---------------------------------------------------------------------------------------------
/// The images one offscreen frame is drawn into and the host buffer it is read back through.
class OffscreenTarget {
public:
    OffscreenTarget(const VulkanContext& ctx, VkRenderPass pass, const FrameFormat& format, VkExtent2D extent)
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
            readback_ = ctx.create_buffer(VkDeviceSize(extent.width) * extent.height * 4u, VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                          VK_MEMORY_PROPERTY_HOST_CACHED_BIT);
        } catch (...) {
            destroy();
            throw;
        }
    }
    ~OffscreenTarget() { destroy(); }
    OffscreenTarget(const OffscreenTarget&) = delete;
    OffscreenTarget& operator=(const OffscreenTarget&) = delete;

    VkExtent2D extent() const { return extent_; }
    VkFramebuffer framebuffer() const { return framebuffer_; }

    /// After the render pass: copies the picture into the readback buffer.
    void record_copy_out(VkCommandBuffer cmd) const
    {
        VkBufferImageCopy region{};
        region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
        region.imageExtent = {extent_.width, extent_.height, 1};
        vkCmdCopyImageToBuffer(cmd, resolve_.image ? resolve_.image : color_.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                               readback_.buffer, 1, &region);
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

    RgbaImage read() const
    {
        RgbaImage out;
        out.width = static_cast<int>(extent_.width);
        out.height = static_cast<int>(extent_.height);
        out.pixels.resize(readback_.size);
        void* mapped = nullptr;
        CHECK_VKCMD(vkMapMemory(ctx_.device(), readback_.memory, 0, readback_.size, 0, &mapped));
        std::memcpy(out.pixels.data(), mapped, out.pixels.size());
        vkUnmapMemory(ctx_.device(), readback_.memory);
        return out;
    }

private:
    void destroy()
    {
        if (framebuffer_) vkDestroyFramebuffer(ctx_.device(), framebuffer_, nullptr);
        framebuffer_ = VK_NULL_HANDLE;
        ctx_.destroy(color_);
        ctx_.destroy(depth_);
        ctx_.destroy(resolve_);
        ctx_.destroy(readback_);
    }

    const VulkanContext& ctx_;
    VkExtent2D extent_;
    GpuImage color_, depth_, resolve_;
    VkFramebuffer framebuffer_ = VK_NULL_HANDLE;
    GpuBuffer readback_;
};

// ---------------------------------------------------------------------------------------------
/// Pipelines, the leaf texture, the mesh cache, and the draws of one frame.
class SceneDrawer {
public:
    SceneDrawer(const VulkanContext& ctx, VkRenderPass pass, const FrameFormat& format) : ctx_(ctx)
    {
        try {
            create(pass, format);
        } catch (...) {
            destroy();
            throw;
        }
    }
    ~SceneDrawer() { destroy(); }
    SceneDrawer(const SceneDrawer&) = delete;
    SceneDrawer& operator=(const SceneDrawer&) = delete;

    void set_scene(const RenderScene& scene, RenderStats& stats)
    {
        // Check everything before touching the GPU: a bad scene leaves the last one drawn.
        std::unordered_set<std::uint64_t> keys;
        for (const RenderItem& item : scene.items) {
            if (!keys.insert(item.key).second)
                throw InvalidInput("render: mesh key " + std::to_string(item.key) + " appears twice in the scene");
            const SurfaceGeometry& g = item.geometry;
            const std::size_t n = g.positions.size();
            if (g.normals.size() != n || (!g.uvs.empty() && g.uvs.size() != n))
                throw InvalidInput("render: mesh " + std::to_string(item.key) + " has " + std::to_string(n) +
                                   " positions but " + std::to_string(g.normals.size()) + " normals and " +
                                   std::to_string(g.uvs.size()) + " uvs");
            for (const auto& t : g.triangles)
                for (std::uint32_t i : t)
                    if (i >= n)
                        throw InvalidInput("render: mesh " + std::to_string(item.key) + " has a triangle index " +
                                           std::to_string(i) + " out of range (" + std::to_string(n) + " vertices)");
        }
        const RgbaImage& tex = scene.leaf_texture;
        const bool has_texture = tex.width > 0 && tex.height > 0;
        if (has_texture && tex.pixels.size() != std::size_t(tex.width) * std::size_t(tex.height) * 4u)
            throw InvalidInput("render: a leaf texture of " + std::to_string(tex.width) + "x" + std::to_string(tex.height) +
                               " with " + std::to_string(tex.pixels.size()) + " bytes");

        stats.meshes_uploaded = stats.meshes_kept = stats.bytes_uploaded = 0;
        for (auto it = cache_.begin(); it != cache_.end();) {
            if (!keys.count(it->first)) {
                ctx_.destroy(it->second.buffer);
                it = cache_.erase(it);
            } else {
                ++it;
            }
        }
        draws_.clear();
        for (const RenderItem& item : scene.items) {
            auto it = cache_.find(item.key);
            if (it != cache_.end() && it->second.version == item.version) {
                ++stats.meshes_kept;
            } else {
                if (it != cache_.end()) ctx_.destroy(it->second.buffer);
                it = cache_.insert_or_assign(item.key, upload(item, stats)).first;
                ++stats.meshes_uploaded;
            }
            it->second.material = item.material;
            it->second.color = glm::vec4(item.color[0], item.color[1], item.color[2], item.color[3]);
            if (it->second.index_count > 0) draws_.push_back(item.key);
        }
        const std::uint64_t texture_version = has_texture ? scene.leaf_texture_version : 0;
        if (!texture_ready_ || texture_version != texture_version_) {
            if (has_texture)
                upload_texture(tex, stats);
            else
                upload_texture(RgbaImage{1, 1, {255, 255, 255, 255}}, stats);
            texture_version_ = texture_version;
            texture_ready_ = true;
        }
        ground_ = scene.ground;
        bounds_ = scene.ground_area.empty() ? scene_bounds(scene) : scene.ground_area;
        ground_y_ = scene.ground_y;
    }

    /// The draws of one frame, inside a begun render pass of `extent`.
    void record(VkCommandBuffer cmd, const Camera& camera, VkExtent2D extent) const
    {
        const float aspect = float(extent.width) / float(extent.height);
        glm::mat4 proj = glm::perspectiveRH_ZO(glm::radians(camera.fov_y_deg), aspect, camera.near_m, camera.far_m);
        proj[1][1] *= -1.0f; // Vulkan's framebuffer y points down
        const glm::mat4 view = glm::lookAtRH(camera.eye, camera.target, camera.up);
        const glm::mat4 view_proj = proj * view;
        const glm::vec4 eye(camera.eye, 1.0f);

        VkViewport viewport{0.0f, 0.0f, float(extent.width), float(extent.height), 0.0f, 1.0f};
        VkRect2D scissor{{0, 0}, extent};
        vkCmdSetViewport(cmd, 0, 1, &viewport);
        vkCmdSetScissor(cmd, 0, 1, &scissor);
        vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, layout_, 0, 1, &descriptor_set_, 0, nullptr);
        auto push = [&](const PushBlock& p) {
            vkCmdPushConstants(cmd, layout_, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0, sizeof(PushBlock), &p);
        };

        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, sky_);
        push({glm::inverse(view_proj), glm::vec4(0.0f), eye, glm::vec4(0.0f)});
        vkCmdDraw(cmd, 3, 1, 0, 0);

        if (ground_) {
            Bounds b = bounds_;
            if (b.empty()) b = Bounds{glm::vec3(-0.5f), glm::vec3(0.5f)};
            const glm::vec3 size = b.hi - b.lo;
            const float extent_m = std::max({size.x, size.y, size.z, 0.1f});
            const float half = std::max(8.0f * extent_m, 4.0f);
            const float cell = extent_m > 3.0f ? 1.0f : 0.1f; // 10 cm cells (1 m for big scenes), a stronger line every 10
            vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, ground_pipeline_);
            push({view_proj, glm::vec4(0.5f * (b.lo.x + b.hi.x), ground_y_, 0.5f * (b.lo.z + b.hi.z), half), eye,
                  glm::vec4(cell, 0.0f, 0.0f, 0.0f)});
            vkCmdDraw(cmd, 6, 1, 0, 0);
        }

        auto draw = [&](const GpuMesh& m) {
            const VkDeviceSize offset = 0;
            vkCmdBindVertexBuffers(cmd, 0, 1, &m.buffer.buffer, &offset);
            vkCmdBindIndexBuffer(cmd, m.buffer.buffer, m.index_offset, VK_INDEX_TYPE_UINT32);
            push({view_proj, m.color, eye, glm::vec4(float(static_cast<int>(m.material)), 0.0f, 0.0f, 0.0f)});
            vkCmdDrawIndexed(cmd, m.index_count, 1, 0, 0, 0);
        };
        auto draw_all = [&](VkPipeline pipeline, std::initializer_list<RenderMaterial> materials) {
            bool bound = false;
            for (std::uint64_t key : draws_) {
                const GpuMesh& m = cache_.at(key);
                if (std::find(materials.begin(), materials.end(), m.material) == materials.end()) continue;
                if (!bound) vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline);
                bound = true;
                draw(m);
            }
        };
        draw_all(opaque_, {RenderMaterial::Bark, RenderMaterial::Stroke});
        draw_all(leaf_, {RenderMaterial::Leaf});
        // Translucent lobes last, far to near (by their centres), without depth writes.
        std::vector<std::pair<float, std::uint64_t>> lobes;
        for (std::uint64_t key : draws_) {
            const GpuMesh& m = cache_.at(key);
            if (m.material == RenderMaterial::Lobe) lobes.emplace_back(-glm::length(m.centre - camera.eye), key);
        }
        std::sort(lobes.begin(), lobes.end());
        if (!lobes.empty()) vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, lobe_);
        for (const auto& [distance, key] : lobes) draw(cache_.at(key));
    }

private:
    struct GpuMesh {
        std::uint64_t version = 0;
        GpuBuffer buffer; // vertices (Vertex), then uint32 indices at index_offset
        VkDeviceSize index_offset = 0;
        std::uint32_t index_count = 0;
        RenderMaterial material = RenderMaterial::Bark;
        glm::vec4 color{1.0f};
        glm::vec3 centre{0.0f};
    };

    GpuMesh upload(const RenderItem& item, RenderStats& stats) const
    {
        const SurfaceGeometry& g = item.geometry;
        GpuMesh m;
        m.version = item.version;
        m.index_count = static_cast<std::uint32_t>(g.triangles.size() * 3u);
        if (g.triangles.empty()) return m;
        std::vector<Vertex> vertices(g.positions.size());
        Bounds b;
        for (std::size_t i = 0; i < vertices.size(); ++i) {
            const glm::vec3& p = g.positions[i];
            const glm::vec3& n = g.normals[i];
            const glm::vec2 uv = g.uvs.empty() ? glm::vec2(0.0f) : g.uvs[i];
            vertices[i] = {{p.x, p.y, p.z}, {n.x, n.y, n.z}, {uv.x, uv.y}};
            b.add(p);
        }
        m.centre = 0.5f * (b.lo + b.hi);
        const std::size_t vertex_bytes = vertices.size() * sizeof(Vertex);
        m.index_offset = (vertex_bytes + 15u) & ~VkDeviceSize(15u);
        const std::size_t index_bytes = g.triangles.size() * sizeof(g.triangles[0]);
        m.buffer = ctx_.create_buffer(m.index_offset + index_bytes,
                                      VK_BUFFER_USAGE_VERTEX_BUFFER_BIT | VK_BUFFER_USAGE_INDEX_BUFFER_BIT,
                                      VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
        try {
            ctx_.write(m.buffer, 0, vertices.data(), vertex_bytes);
            ctx_.write(m.buffer, m.index_offset, g.triangles.data(), index_bytes);
        } catch (...) {
            ctx_.destroy(m.buffer);
            throw;
        }
        stats.bytes_uploaded += vertex_bytes + index_bytes;
        return m;
    }

    void upload_texture(const RgbaImage& tex, RenderStats& stats)
    {
        ctx_.destroy(texture_);
        const VkExtent2D extent{static_cast<std::uint32_t>(tex.width), static_cast<std::uint32_t>(tex.height)};
        texture_ = ctx_.create_image(extent, VK_FORMAT_R8G8B8A8_SRGB, VK_SAMPLE_COUNT_1_BIT,
                                     VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT, VK_IMAGE_ASPECT_COLOR_BIT);
        GpuBuffer staging = ctx_.create_buffer(tex.pixels.size(), VK_BUFFER_USAGE_TRANSFER_SRC_BIT, 0);
        try {
            ctx_.write(staging, 0, tex.pixels.data(), tex.pixels.size());
            ctx_.submit_and_wait([&](VkCommandBuffer cmd) {
                auto barrier = vk_struct<VkImageMemoryBarrier>(VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER);
                barrier.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
                barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
                barrier.image = texture_.image;
                barrier.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
                barrier.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
                barrier.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
                barrier.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
                vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr, 0,
                                     nullptr, 1, &barrier);
                VkBufferImageCopy region{};
                region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
                region.imageExtent = {extent.width, extent.height, 1};
                vkCmdCopyBufferToImage(cmd, staging.buffer, texture_.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
                barrier.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
                barrier.newLayout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
                barrier.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
                barrier.dstAccessMask = VK_ACCESS_SHADER_READ_BIT;
                vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT, 0, 0, nullptr,
                                     0, nullptr, 1, &barrier);
            });
        } catch (...) {
            ctx_.destroy(staging);
            throw;
        }
        ctx_.destroy(staging);
        stats.bytes_uploaded += tex.pixels.size();
        VkDescriptorImageInfo image{sampler_, texture_.view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
        auto write = vk_struct<VkWriteDescriptorSet>(VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET);
        write.dstSet = descriptor_set_;
        write.dstBinding = 0;
        write.descriptorCount = 1;
        write.descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
        write.pImageInfo = &image;
        vkUpdateDescriptorSets(ctx_.device(), 1, &write, 0, nullptr);
    }

    VkShaderModule shader(const char* name) const
    {
        const std::span<const std::uint32_t> code = embedded_shader(name);
        if (code.empty()) throw RenderError(std::string("render: shader ") + name + " is not embedded");
        auto info = vk_struct<VkShaderModuleCreateInfo>(VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO);
        info.codeSize = code.size_bytes();
        info.pCode = code.data();
        VkShaderModule m = VK_NULL_HANDLE;
        CHECK_VKCMD(vkCreateShaderModule(ctx_.device(), &info, nullptr, &m));
        return m;
    }

    struct PipelineState {
        const char* vert;
        const char* frag;
        bool vertices = true; // mesh vertex input
        VkCullModeFlags cull = VK_CULL_MODE_NONE;
        bool depth_test = true;
        bool depth_write = true;
        bool blend = false;
    };

    VkPipeline pipeline(VkRenderPass pass, const FrameFormat& format, const PipelineState& s) const
    {
        VkShaderModule vert = shader(s.vert), frag = VK_NULL_HANDLE;
        VkPipeline p = VK_NULL_HANDLE;
        try {
            frag = shader(s.frag);
            VkPipelineShaderStageCreateInfo stages[2]{};
            stages[0].sType = stages[1].sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
            stages[0].stage = VK_SHADER_STAGE_VERTEX_BIT;
            stages[0].module = vert;
            stages[0].pName = "main";
            stages[1].stage = VK_SHADER_STAGE_FRAGMENT_BIT;
            stages[1].module = frag;
            stages[1].pName = "main";
            VkVertexInputBindingDescription binding{0, sizeof(Vertex), VK_VERTEX_INPUT_RATE_VERTEX};
            VkVertexInputAttributeDescription attributes[3] = {
                {0, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(Vertex, position)},
                {1, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(Vertex, normal)},
                {2, 0, VK_FORMAT_R32G32_SFLOAT, offsetof(Vertex, uv)},
            };
            auto input = vk_struct<VkPipelineVertexInputStateCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO);
            if (s.vertices) {
                input.vertexBindingDescriptionCount = 1;
                input.pVertexBindingDescriptions = &binding;
                input.vertexAttributeDescriptionCount = 3;
                input.pVertexAttributeDescriptions = attributes;
            }
            auto assembly = vk_struct<VkPipelineInputAssemblyStateCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO);
            assembly.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
            auto viewport = vk_struct<VkPipelineViewportStateCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO);
            viewport.viewportCount = 1;
            viewport.scissorCount = 1;
            auto raster = vk_struct<VkPipelineRasterizationStateCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO);
            raster.polygonMode = VK_POLYGON_MODE_FILL;
            raster.cullMode = s.cull;
            raster.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE; // with the projection's y flip
            raster.lineWidth = 1.0f;
            auto ms = vk_struct<VkPipelineMultisampleStateCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO);
            ms.rasterizationSamples = format.samples;
            auto depth = vk_struct<VkPipelineDepthStencilStateCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO);
            depth.depthTestEnable = s.depth_test ? VK_TRUE : VK_FALSE;
            depth.depthWriteEnable = s.depth_write ? VK_TRUE : VK_FALSE;
            depth.depthCompareOp = VK_COMPARE_OP_LESS_OR_EQUAL;
            VkPipelineColorBlendAttachmentState blend{};
            blend.colorWriteMask = VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT | VK_COLOR_COMPONENT_B_BIT | VK_COLOR_COMPONENT_A_BIT;
            if (s.blend) {
                blend.blendEnable = VK_TRUE;
                blend.srcColorBlendFactor = VK_BLEND_FACTOR_SRC_ALPHA;
                blend.dstColorBlendFactor = VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA;
                blend.colorBlendOp = VK_BLEND_OP_ADD;
                blend.srcAlphaBlendFactor = VK_BLEND_FACTOR_ZERO;
                blend.dstAlphaBlendFactor = VK_BLEND_FACTOR_ONE;
                blend.alphaBlendOp = VK_BLEND_OP_ADD;
            }
            auto blending = vk_struct<VkPipelineColorBlendStateCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO);
            blending.attachmentCount = 1;
            blending.pAttachments = &blend;
            const VkDynamicState dynamic_states[2] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
            auto dynamic = vk_struct<VkPipelineDynamicStateCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO);
            dynamic.dynamicStateCount = 2;
            dynamic.pDynamicStates = dynamic_states;
            auto info = vk_struct<VkGraphicsPipelineCreateInfo>(VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO);
            info.stageCount = 2;
            info.pStages = stages;
            info.pVertexInputState = &input;
            info.pInputAssemblyState = &assembly;
            info.pViewportState = &viewport;
            info.pRasterizationState = &raster;
            info.pMultisampleState = &ms;
            info.pDepthStencilState = &depth;
            info.pColorBlendState = &blending;
            info.pDynamicState = &dynamic;
            info.layout = layout_;
            info.renderPass = pass;
            info.subpass = 0;
            CHECK_VKCMD(vkCreateGraphicsPipelines(ctx_.device(), VK_NULL_HANDLE, 1, &info, nullptr, &p));
        } catch (...) {
            vkDestroyShaderModule(ctx_.device(), vert, nullptr);
            if (frag) vkDestroyShaderModule(ctx_.device(), frag, nullptr);
            throw;
        }
        vkDestroyShaderModule(ctx_.device(), vert, nullptr);
        vkDestroyShaderModule(ctx_.device(), frag, nullptr);
        return p;
    }

    void create(VkRenderPass pass, const FrameFormat& format)
    {
        const VkDevice dev = ctx_.device();
        VkDescriptorSetLayoutBinding binding{0, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, VK_SHADER_STAGE_FRAGMENT_BIT, nullptr};
        auto set_layout = vk_struct<VkDescriptorSetLayoutCreateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO);
        set_layout.bindingCount = 1;
        set_layout.pBindings = &binding;
        CHECK_VKCMD(vkCreateDescriptorSetLayout(dev, &set_layout, nullptr, &set_layout_));
        VkPushConstantRange range{VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0, sizeof(PushBlock)};
        auto layout = vk_struct<VkPipelineLayoutCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO);
        layout.setLayoutCount = 1;
        layout.pSetLayouts = &set_layout_;
        layout.pushConstantRangeCount = 1;
        layout.pPushConstantRanges = &range;
        CHECK_VKCMD(vkCreatePipelineLayout(dev, &layout, nullptr, &layout_));
        VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1};
        auto pool = vk_struct<VkDescriptorPoolCreateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO);
        pool.maxSets = 1;
        pool.poolSizeCount = 1;
        pool.pPoolSizes = &size;
        CHECK_VKCMD(vkCreateDescriptorPool(dev, &pool, nullptr, &descriptor_pool_));
        auto alloc = vk_struct<VkDescriptorSetAllocateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO);
        alloc.descriptorPool = descriptor_pool_;
        alloc.descriptorSetCount = 1;
        alloc.pSetLayouts = &set_layout_;
        CHECK_VKCMD(vkAllocateDescriptorSets(dev, &alloc, &descriptor_set_));
        auto sampler = vk_struct<VkSamplerCreateInfo>(VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO);
        sampler.magFilter = VK_FILTER_LINEAR;
        sampler.minFilter = VK_FILTER_LINEAR;
        sampler.mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST;
        sampler.addressModeU = sampler.addressModeV = sampler.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
        sampler.maxLod = 0.0f;
        CHECK_VKCMD(vkCreateSampler(dev, &sampler, nullptr, &sampler_));

        sky_ = pipeline(pass, format, {"sky.vert", "sky.frag", false, VK_CULL_MODE_NONE, false, false, false});
        ground_pipeline_ = pipeline(pass, format, {"ground.vert", "ground.frag", false, VK_CULL_MODE_NONE, true, true, false});
        opaque_ = pipeline(pass, format, {"mesh.vert", "mesh.frag", true, VK_CULL_MODE_BACK_BIT, true, true, false});
        leaf_ = pipeline(pass, format, {"mesh.vert", "mesh.frag", true, VK_CULL_MODE_NONE, true, true, false});
        lobe_ = pipeline(pass, format, {"mesh.vert", "mesh.frag", true, VK_CULL_MODE_NONE, true, false, true});
    }

    void destroy()
    {
        const VkDevice dev = ctx_.device();
        for (auto& [key, mesh] : cache_) ctx_.destroy(mesh.buffer);
        cache_.clear();
        ctx_.destroy(texture_);
        for (VkPipeline p : {sky_, ground_pipeline_, opaque_, leaf_, lobe_})
            if (p) vkDestroyPipeline(dev, p, nullptr);
        if (sampler_) vkDestroySampler(dev, sampler_, nullptr);
        if (descriptor_pool_) vkDestroyDescriptorPool(dev, descriptor_pool_, nullptr);
        if (layout_) vkDestroyPipelineLayout(dev, layout_, nullptr);
        if (set_layout_) vkDestroyDescriptorSetLayout(dev, set_layout_, nullptr);
    }

    const VulkanContext& ctx_;
    VkDescriptorSetLayout set_layout_ = VK_NULL_HANDLE;
    VkPipelineLayout layout_ = VK_NULL_HANDLE;
    VkDescriptorPool descriptor_pool_ = VK_NULL_HANDLE;
    VkDescriptorSet descriptor_set_ = VK_NULL_HANDLE;
    VkSampler sampler_ = VK_NULL_HANDLE;
    VkPipeline sky_ = VK_NULL_HANDLE, ground_pipeline_ = VK_NULL_HANDLE, opaque_ = VK_NULL_HANDLE, leaf_ = VK_NULL_HANDLE,
               lobe_ = VK_NULL_HANDLE;
    GpuImage texture_;
    std::uint64_t texture_version_ = 0;
    bool texture_ready_ = false;
    std::unordered_map<std::uint64_t, GpuMesh> cache_;
    std::vector<std::uint64_t> draws_; // keys in scene order
    bool ground_ = true;
    float ground_y_ = 0.0f;
    Bounds bounds_;
};

} // namespace

// ---------------------------------------------------------------------------------------------
struct Renderer::Impl {
    explicit Impl(const RendererOptions& options) : ctx(options)
    {
        format = choose_frame_format(ctx, options.samples);
        pass = create_offscreen_render_pass(ctx.device(), format);
        try {
            drawer = std::make_unique<SceneDrawer>(ctx, pass, format);
            drawer->set_scene(RenderScene{}, stats);
        } catch (...) {
            drawer.reset();
            vkDestroyRenderPass(ctx.device(), pass, nullptr);
            throw;
        }
    }
    ~Impl()
    {
        vkDeviceWaitIdle(ctx.device());
        target.reset();
        drawer.reset();
        vkDestroyRenderPass(ctx.device(), pass, nullptr);
    }

    VulkanContext ctx;
    FrameFormat format;
    VkRenderPass pass = VK_NULL_HANDLE;
    std::unique_ptr<SceneDrawer> drawer;
    std::unique_ptr<OffscreenTarget> target;
    RenderStats stats;
};

Renderer::Renderer(const RendererOptions& options) : impl_(std::make_unique<Impl>(options)) {}
Renderer::~Renderer() = default;

const std::string& Renderer::device_name() const { return impl_->ctx.name(); }
bool Renderer::is_software() const { return impl_->ctx.software(); }
int Renderer::samples() const { return static_cast<int>(impl_->format.samples); }
const RenderStats& Renderer::stats() const { return impl_->stats; }

void Renderer::set_scene(const RenderScene& scene) { impl_->drawer->set_scene(scene, impl_->stats); }

RgbaImage Renderer::render(const Camera& camera, int width, int height)
{
    if (width < 1 || height < 1 || width > 16384 || height > 16384)
        throw InvalidInput("render: a picture of " + std::to_string(width) + "x" + std::to_string(height) +
                           " pixels (1 to 16384 on each side)");
    Impl& im = *impl_;
    const VkExtent2D extent{static_cast<std::uint32_t>(width), static_cast<std::uint32_t>(height)};
    if (!im.target || im.target->extent().width != extent.width || im.target->extent().height != extent.height) {
        im.target.reset();
        im.target = std::make_unique<OffscreenTarget>(im.ctx, im.pass, im.format, extent);
    }
    im.ctx.submit_and_wait(
        [&](VkCommandBuffer cmd) {
            VkClearValue clears[3]{};
            clears[0].color = {{0.0f, 0.0f, 0.0f, 1.0f}};
            clears[1].depthStencil = {1.0f, 0};
            auto begin = vk_struct<VkRenderPassBeginInfo>(VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO);
            begin.renderPass = im.pass;
            begin.framebuffer = im.target->framebuffer();
            begin.renderArea = {{0, 0}, extent};
            begin.clearValueCount = multisampled(im.format) ? 3u : 2u;
            begin.pClearValues = clears;
            vkCmdBeginRenderPass(cmd, &begin, VK_SUBPASS_CONTENTS_INLINE);
            im.drawer->record(cmd, camera, extent);
            vkCmdEndRenderPass(cmd);
            im.target->record_copy_out(cmd);
        },
        &im.stats.record_ms, &im.stats.gpu_ms);
    RgbaImage out = im.target->read();
    for (std::size_t i = 3; i < out.pixels.size(); i += 4) out.pixels[i] = 255;
    return out;
}

} // namespace lobe
