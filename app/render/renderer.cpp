// The Vulkan renderer behind app/render/renderer.h. Five parts, each a small class:
//  - VulkanContext: instance (with the caller's instance extensions), device choice (with
//    VK_KHR_swapchain when presenting), queue, memory helpers, one-shot submits; or the
//    instance, physical device and device from RendererOptions::vulkan_hooks (OpenXR);
//  - OffscreenTarget: the images a frame is drawn into (MSAA colour, depth, resolve) and the
//    buffer it is read back through (made on first use);
//  - SceneDrawer: pipelines, the leaf and photo textures, the per-mesh GPU buffer cache (keyed
//    by RenderItem::key, re-uploaded only when RenderItem::version changes; leaf meshes made
//    of leaves.cpp's quads become one instance per leaf over a shared quad) and recording the
//    draws of one frame, seen from a FrameView (a Camera's or an OpenXR EyeView's), into a
//    command buffer inside any compatible render pass;
//  - OverlayDrawer: the 2D overlay's pipeline, font texture and host-visible buffers, drawn
//    after the scene in the same render pass;
//  - WindowTarget: a window's surface and swapchain. A window's frame is drawn offscreen
//    exactly as a picture is, then blitted into the acquired swapchain image and presented.
// render_to draws an eye's frame the same way into an offscreen target kept per size and copies
// or blits it into the caller's image (an OpenXR swapchain image).
// Every submit is waited for (one frame in flight), so buffers may be rewritten between frames.
#include "app/render/renderer.h"
#include "app/render/loaded_libraries.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <functional>
#include <limits>
#include <unordered_map>
#include <type_traits>
#include <unordered_set>

#include <glm/ext/matrix_clip_space.hpp>
#include <glm/ext/matrix_transform.hpp>
#include <glm/geometric.hpp>
#include <glm/gtc/constants.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/mat4x4.hpp>
#include <glm/matrix.hpp>
#include <glm/vec4.hpp>

#include <dlfcn.h>
#include <link.h>
#include <unistd.h>

#include "app/render/embedded_shaders.h"
#include "app/render/vk_check.h"

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

/// A Vulkan handle from an integer, e.g. the VkSurfaceKHR attach_window's callback returns or
/// the VkInstance a RendererOptions::vulkan_hooks function returns (handles are pointers on
/// 64-bit builds; non-dispatchable ones are 64-bit integers on 32-bit ones).
template <class Handle>
Handle handle_from_integer(std::uint64_t v)
{
    if constexpr (std::is_pointer_v<Handle>)
        return reinterpret_cast<Handle>(static_cast<std::uintptr_t>(v));
    else
        return static_cast<Handle>(v);
}

/// The integer of a Vulkan handle (the inverse of handle_from_integer).
template <class Handle>
std::uint64_t handle_to_integer(Handle h)
{
    if constexpr (std::is_pointer_v<Handle>)
        return static_cast<std::uint64_t>(reinterpret_cast<std::uintptr_t>(h));
    else
        return static_cast<std::uint64_t>(h);
}

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

/// One leaf quad drawn instanced (app/render/shaders/leaf.vert): corners 0, 1 and 3 of its four
/// vertices (corner 2 is 1 + (3 − 0)) and its normal.
struct LeafInstance {
    float corner0[3];
    float corner1[3];
    float corner3[3];
    float normal[3];
};
static_assert(sizeof(LeafInstance) == 48);

/// A leaf mesh as one instance per quad, when it is made of quads as growth/leaves.cpp emits
/// them: vertices 4q … 4q + 3 and triangles 2q = (4q, 4q + 1, 4q + 2) and 2q + 1 =
/// (4q, 4q + 2, 4q + 3) for every quad q, the four vertices of a quad with one normal, every
/// quad with the uvs of the first (or none), and each quad a parallelogram: vertex 2 is
/// 1 + (3 − 0), as leaf.vert makes it, to rounding (1e-4 of the quad's longer edge plus a few
/// float steps of its coordinates; more would move the leaf's corner on screen). Returns false
/// (and `instances` is then meaningless) for any other mesh: it is drawn as a mesh.
bool as_leaf_instances(const SurfaceGeometry& g, std::vector<LeafInstance>& instances, std::array<glm::vec2, 4>& uvs)
{
    const std::size_t n = g.positions.size();
    if (n == 0 || n % 4 != 0 || g.triangles.size() != n / 2 || g.normals.size() != n) return false;
    uvs = {};
    if (!g.uvs.empty()) {
        if (g.uvs.size() != n) return false;
        std::copy(g.uvs.begin(), g.uvs.begin() + 4, uvs.begin());
    }
    instances.clear();
    instances.reserve(n / 4);
    for (std::size_t q = 0; q < n / 4; ++q) {
        const auto f = static_cast<std::uint32_t>(4 * q);
        const std::array<std::uint32_t, 3> first{f, f + 1, f + 2}, second{f, f + 2, f + 3};
        if (g.triangles[2 * q] != first || g.triangles[2 * q + 1] != second) return false;
        const glm::vec3& normal = g.normals[f];
        for (std::uint32_t k = 1; k < 4; ++k)
            if (g.normals[f + k] != normal) return false;
        if (!g.uvs.empty())
            for (std::uint32_t k = 0; k < 4; ++k)
                if (g.uvs[f + k] != uvs[k]) return false;
        const glm::vec3 &p0 = g.positions[f], &p1 = g.positions[f + 1], &p2 = g.positions[f + 2], &p3 = g.positions[f + 3];
        const float edge = std::max(glm::length(p1 - p0), glm::length(p3 - p0));
        float magnitude = 0.0f;
        for (const glm::vec3* p : {&p0, &p1, &p2, &p3})
            magnitude = std::max({magnitude, std::abs(p->x), std::abs(p->y), std::abs(p->z)});
        const float error = glm::length(p1 + (p3 - p0) - p2);
        // Written so that NaN and infinite coordinates fail it.
        if (!(error <= 1e-4f * edge + 8.0f * std::numeric_limits<float>::epsilon() * magnitude)) return false;
        instances.push_back({{p0.x, p0.y, p0.z}, {p1.x, p1.y, p1.z}, {p3.x, p3.y, p3.z}, {normal.x, normal.y, normal.z}});
    }
    return true;
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

/// Semaphores of a submit: waited on at `wait_stage` before it runs, signalled after it.
struct SubmitSync {
    VkSemaphore wait = VK_NULL_HANDLE;
    VkPipelineStageFlags wait_stage = VK_PIPELINE_STAGE_TRANSFER_BIT;
    VkSemaphore signal = VK_NULL_HANDLE;
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

    VkInstance instance() const { return instance_; }
    VkDevice device() const { return device_; }
    VkPhysicalDevice physical() const { return physical_; }
    VkQueue queue() const { return queue_; }
    std::uint32_t queue_family() const { return queue_family_; }
    const std::string& name() const { return name_; }
    bool software() const { return software_; }
    bool presentation() const { return presentation_; }
    bool instance_extension_enabled(const std::string& name) const
    {
        return std::find(instance_extensions_.begin(), instance_extensions_.end(), name) != instance_extensions_.end();
    }
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
                         double* gpu_ms = nullptr, const SubmitSync& sync = {}) const
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

private:
    void create(const RendererOptions& options)
    {
        // With hooks (an OpenXR runtime's XR_KHR_vulkan_enable2), the instance, the physical
        // device and the device come from them, made from the create infos filled here.
        const RendererOptions::VulkanHooks& hooks = options.vulkan_hooks;
        const bool hooked = !hooks.empty();
        if (bool(hooks.create_instance) != bool(hooks.physical_device) || bool(hooks.create_instance) != bool(hooks.create_device))
            throw RenderError("render: RendererOptions::vulkan_hooks needs all three of create_instance, physical_device and "
                              "create_device, or none");
        ensure_runtime_dir();
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
        if (hooked) {
            int result = VK_SUCCESS;
            const std::uint64_t made = hooks.create_instance(&info, result);
            keep_loaded_since(libraries);
            instance_ = handle_from_integer<VkInstance>(made);
            if (!instance_)
                throw RenderUnavailable("render: no Vulkan instance from the OpenXR runtime: " +
                                        hook_failure("create_instance", result));
            physical_ = handle_from_integer<VkPhysicalDevice>(hooks.physical_device(handle_to_integer(instance_)));
            if (!physical_)
                throw RenderUnavailable("render: no Vulkan device from the OpenXR runtime: "
                                        "RendererOptions::vulkan_hooks.physical_device returned 0");
            choose_hooked_queue(options.presentation);
        } else {
            const VkResult created = vkCreateInstance(&info, nullptr, &instance_);
            keep_loaded_since(libraries);
            if (VkResult r = created; r != VK_SUCCESS) {
                instance_ = VK_NULL_HANDLE;
                throw RenderUnavailable(std::string("render: no Vulkan driver (vkCreateInstance: ") + vk::result_name(r) +
                                        "); " + kInstallHint);
            }
            choose_device(options);
        }
        presentation_ = options.presentation;
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
        const char* swapchain = VK_KHR_SWAPCHAIN_EXTENSION_NAME;
        if (presentation_) {
            dev.enabledExtensionCount = 1;
            dev.ppEnabledExtensionNames = &swapchain;
        }
        if (hooked) {
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
    void choose_device(const RendererOptions& options)
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
    void choose_hooked_queue(bool presentation)
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

    static bool has_device_extension(VkPhysicalDevice d, const char* name)
    {
        std::uint32_t n = 0;
        if (vkEnumerateDeviceExtensionProperties(d, nullptr, &n, nullptr) != VK_SUCCESS) return false;
        std::vector<VkExtensionProperties> props(n);
        if (n && vkEnumerateDeviceExtensionProperties(d, nullptr, &n, props.data()) < VK_SUCCESS) return false;
        return std::any_of(props.begin(), props.end(), [&](const VkExtensionProperties& p) { return std::strcmp(p.extensionName, name) == 0; });
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
    bool presentation_ = false;
    std::vector<std::string> instance_extensions_;
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

/// A pipeline layout of one descriptor set and one push-constant range.
VkPipelineLayout create_pipeline_layout(VkDevice dev, VkDescriptorSetLayout set_layout, VkPushConstantRange range)
{
    auto layout = vk_struct<VkPipelineLayoutCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO);
    layout.setLayoutCount = 1;
    layout.pSetLayouts = &set_layout;
    layout.pushConstantRangeCount = 1;
    layout.pPushConstantRanges = &range;
    VkPipelineLayout out = VK_NULL_HANDLE;
    CHECK_VKCMD(vkCreatePipelineLayout(dev, &layout, nullptr, &out));
    return out;
}

/// A pool holding one set of `samplers` combined image samplers, and that set.
void allocate_sampler_set(VkDevice dev, VkDescriptorSetLayout set_layout, VkDescriptorPool& pool_out, VkDescriptorSet& set_out,
                          std::uint32_t samplers = 1)
{
    VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, samplers};
    auto pool = vk_struct<VkDescriptorPoolCreateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO);
    pool.maxSets = 1;
    pool.poolSizeCount = 1;
    pool.pPoolSizes = &size;
    CHECK_VKCMD(vkCreateDescriptorPool(dev, &pool, nullptr, &pool_out));
    auto alloc = vk_struct<VkDescriptorSetAllocateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO);
    alloc.descriptorPool = pool_out;
    alloc.descriptorSetCount = 1;
    alloc.pSetLayouts = &set_layout;
    CHECK_VKCMD(vkAllocateDescriptorSets(dev, &alloc, &set_out));
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
    /// The single-sample picture (the resolve image, or the colour image when not
    /// multisampled), in TRANSFER_SRC_OPTIMAL after the render pass.
    VkImage picture() const { return resolve_.image ? resolve_.image : color_.image; }
    /// Whether a frame has been drawn into it (set by the caller after a submit).
    bool drawn = false;

    /// After the render pass: copies the picture into the readback buffer (made on first use:
    /// a window's target never needs one unless last_frame() is called).
    void record_copy_out(VkCommandBuffer cmd)
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

    /// The readback buffer's pixels, alpha set to 255 (after a submitted record_copy_out).
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
        for (std::size_t i = 3; i < out.pixels.size(); i += 4) out.pixels[i] = 255;
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

/// An RGBA8 sRGB texture (`tex` checked by the caller), uploaded through a staging buffer and
/// left in SHADER_READ_ONLY_OPTIMAL.
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

/// Points `binding` of `set` at `texture` through `sampler`.
void write_texture_descriptor(VkDevice device, VkDescriptorSet set, VkSampler sampler, const GpuImage& texture,
                              std::uint32_t binding = 0)
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

/// "an RGBA8 image" check shared by the leaf texture and the overlay's font: throws
/// InvalidInput naming `what` unless it is empty (0 × 0) or has width × height × 4 bytes.
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

const RgbaImage kWhiteTexel{1, 1, {255, 255, 255, 255}};

/// What a pipeline differs in (app/render/renderer.cpp's pipelines share everything else: triangle
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

VkShaderModule create_shader(VkDevice device, const char* name)
{
    const std::span<const std::uint32_t> code = embedded_shader(name);
    if (code.empty()) throw RenderError(std::string("render: shader ") + name + " is not embedded");
    auto info = vk_struct<VkShaderModuleCreateInfo>(VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO);
    info.codeSize = code.size_bytes();
    info.pCode = code.data();
    VkShaderModule m = VK_NULL_HANDLE;
    CHECK_VKCMD(vkCreateShaderModule(device, &info, nullptr, &m));
    return m;
}

VkPipeline create_pipeline(VkDevice device, VkRenderPass pass, const FrameFormat& format, VkPipelineLayout layout,
                           const PipelineState& s)
{
    VkShaderModule vert = create_shader(device, s.vert), frag = VK_NULL_HANDLE;
    VkPipeline p = VK_NULL_HANDLE;
    try {
        frag = create_shader(device, s.frag);
        VkPipelineShaderStageCreateInfo stages[2]{};
        stages[0].sType = stages[1].sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
        stages[0].stage = VK_SHADER_STAGE_VERTEX_BIT;
        stages[0].module = vert;
        stages[0].pName = "main";
        stages[1].stage = VK_SHADER_STAGE_FRAGMENT_BIT;
        stages[1].module = frag;
        stages[1].pName = "main";
        const auto no_input = vk_struct<VkPipelineVertexInputStateCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO);
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
        info.pVertexInputState = s.input ? s.input : &no_input;
        info.pInputAssemblyState = &assembly;
        info.pViewportState = &viewport;
        info.pRasterizationState = &raster;
        info.pMultisampleState = &ms;
        info.pDepthStencilState = &depth;
        info.pColorBlendState = &blending;
        info.pDynamicState = &dynamic;
        info.layout = layout;
        info.renderPass = pass;
        info.subpass = 0;
        CHECK_VKCMD(vkCreateGraphicsPipelines(device, VK_NULL_HANDLE, 1, &info, nullptr, &p));
    } catch (...) {
        vkDestroyShaderModule(device, vert, nullptr);
        if (frag) vkDestroyShaderModule(device, frag, nullptr);
        throw;
    }
    vkDestroyShaderModule(device, vert, nullptr);
    vkDestroyShaderModule(device, frag, nullptr);
    return p;
}

// ---------------------------------------------------------------------------------------------
/// Where a frame is seen from: world to Vulkan clip space (x right, y down, depth 0 at the
/// near plane to 1 at the far one) and the eye's position.
struct FrameView {
    glm::mat4 view_proj{1.0f};
    glm::vec3 eye{0.0f};
};

/// A Camera's view of a frame of `extent` (its vertical field of view; the horizontal one
/// follows the aspect ratio).
FrameView camera_frame_view(const Camera& camera, VkExtent2D extent)
{
    const float aspect = float(extent.width) / float(extent.height);
    glm::mat4 proj = glm::perspectiveRH_ZO(glm::radians(camera.fov_y_deg), aspect, camera.near_m, camera.far_m);
    proj[1][1] *= -1.0f; // Vulkan's framebuffer y points down
    const glm::mat4 view = glm::lookAtRH(camera.eye, camera.target, camera.up);
    return {proj * view, camera.eye};
}

/// An OpenXR eye's view (checked by the caller): the view matrix is the inverse of its pose
/// (−Z forward, +Y up, as lookAtRH's), and the projection glm::perspectiveRH_ZO's with the
/// frustum's sides at the tangents of the four angles, y flipped as camera_frame_view's. With
/// left = −right and down = −up it is camera_frame_view's for a vertical field of view of
/// 2 · up and an aspect ratio of tan(right) / tan(up).
FrameView eye_frame_view(const EyeView& eye)
{
    const float l = std::tan(eye.angle_left), r = std::tan(eye.angle_right);
    const float d = std::tan(eye.angle_down), u = std::tan(eye.angle_up);
    const float n = eye.near_m, f = eye.far_m;
    glm::mat4 proj(0.0f);
    proj[0][0] = 2.0f / (r - l);
    proj[2][0] = (r + l) / (r - l);
    proj[1][1] = -2.0f / (u - d);       // y flipped: Vulkan's framebuffer y points down
    proj[2][1] = -(u + d) / (u - d);
    proj[2][2] = f / (n - f);           // depth 0 at the near plane, 1 at the far one
    proj[2][3] = -1.0f;
    proj[3][2] = -(f * n) / (f - n);
    const glm::quat q = glm::normalize(eye.orientation);
    const glm::mat4 view = glm::mat4_cast(glm::conjugate(q)) * glm::translate(glm::mat4(1.0f), -eye.position);
    return {proj * view, eye.position};
}

// ---------------------------------------------------------------------------------------------
/// Pipelines, the leaf texture, the mesh cache, and the draws of one frame.
class SceneDrawer {
public:
    SceneDrawer(const VulkanContext& ctx, VkRenderPass pass, const FrameFormat& format, bool instanced_leaves)
        : ctx_(ctx), instanced_leaves_(instanced_leaves)
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
        // Check everything before touching the GPU: a bad scene leaves the last one drawn. A
        // mesh the cache holds under the same key and version was checked when it was uploaded
        // (the interactive apps pass their whole scene every frame).
        std::unordered_set<std::uint64_t> keys;
        for (const RenderItem& item : scene.items) {
            if (!keys.insert(item.key).second)
                throw InvalidInput("render: mesh key " + std::to_string(item.key) + " appears twice in the scene");
            if (auto cached = cache_.find(item.key); cached != cache_.end() && cached->second.version == item.version)
                continue;
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
        const bool has_leaf_texture = check_rgba(scene.leaf_texture, "a leaf texture");
        const bool has_photo_texture = check_rgba(scene.photo_texture, "a photo texture");

        stats.meshes_uploaded = stats.meshes_kept = stats.bytes_uploaded = stats.leaf_instances = 0;
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
            // Instances are drawn by the leaf pipeline only: an instanced mesh given another
            // material is uploaded again, as a mesh.
            if (it != cache_.end() && it->second.version == item.version &&
                (it->second.instance_count == 0 || item.material == RenderMaterial::Leaf)) {
                ++stats.meshes_kept;
            } else {
                if (it != cache_.end()) ctx_.destroy(it->second.buffer);
                it = cache_.insert_or_assign(item.key, upload(item, stats)).first;
                ++stats.meshes_uploaded;
            }
            it->second.material = item.material;
            it->second.color = glm::vec4(item.color[0], item.color[1], item.color[2], item.color[3]);
            if (it->second.index_count > 0) draws_.push_back(item.key);
            stats.leaf_instances += it->second.instance_count;
        }
        update_texture(leaf_texture_, kLeafTextureBinding, has_leaf_texture ? scene.leaf_texture : kWhiteTexel, has_leaf_texture,
                       scene.leaf_texture_version, stats);
        update_texture(photo_texture_, kPhotoTextureBinding, has_photo_texture ? scene.photo_texture : kWhiteTexel,
                       has_photo_texture, scene.photo_texture_version, stats);
        ground_ = scene.ground;
        bounds_ = scene.ground_area.empty() ? scene_bounds(scene) : scene.ground_area;
        ground_y_ = scene.ground_y;
    }

    /// A set layout of one texture at binding 0 (the overlay's font).
    VkDescriptorSetLayout texture_set_layout() const { return set_layout_; }
    VkSampler sampler() const { return sampler_; }

    /// The draws of one frame, inside a begun render pass of `extent`.
    void record(VkCommandBuffer cmd, const FrameView& frame, VkExtent2D extent) const
    {
        const glm::mat4& view_proj = frame.view_proj;
        const glm::vec4 eye(frame.eye, 1.0f);

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
            if (m.instance_count > 0) {
                // The shared quad's uvs (binding 0) and the leaves (binding 1) in one buffer.
                const VkBuffer buffers[2] = {m.buffer.buffer, m.buffer.buffer};
                const VkDeviceSize offsets[2] = {0, m.instance_offset};
                vkCmdBindVertexBuffers(cmd, 0, 2, buffers, offsets);
            } else {
                const VkDeviceSize offset = 0;
                vkCmdBindVertexBuffers(cmd, 0, 1, &m.buffer.buffer, &offset);
            }
            vkCmdBindIndexBuffer(cmd, m.buffer.buffer, m.index_offset, VK_INDEX_TYPE_UINT32);
            push({view_proj, m.color, eye, glm::vec4(float(static_cast<int>(m.material)), 0.0f, 0.0f, 0.0f)});
            vkCmdDrawIndexed(cmd, m.index_count, std::max(m.instance_count, 1u), 0, 0, 0);
        };
        // The meshes of `materials` in scene order; instanced leaves with leaf_instanced_.
        auto draw_all = [&](VkPipeline pipeline, std::initializer_list<RenderMaterial> materials) {
            VkPipeline bound = VK_NULL_HANDLE;
            for (std::uint64_t key : draws_) {
                const GpuMesh& m = cache_.at(key);
                if (std::find(materials.begin(), materials.end(), m.material) == materials.end()) continue;
                const VkPipeline wanted = m.instance_count > 0 ? leaf_instanced_ : pipeline;
                if (wanted != bound) vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, wanted);
                bound = wanted;
                draw(m);
            }
        };
        draw_all(opaque_, {RenderMaterial::Bark, RenderMaterial::Stroke});
        // Leaves and photos: opaque and two-sided (mesh.frag tells them apart).
        draw_all(leaf_, {RenderMaterial::Leaf, RenderMaterial::Photo});
        // Translucent lobes last, far to near (by their centres), without depth writes.
        std::vector<std::pair<float, std::uint64_t>> lobes;
        for (std::uint64_t key : draws_) {
            const GpuMesh& m = cache_.at(key);
            if (m.material == RenderMaterial::Lobe) lobes.emplace_back(-glm::length(m.centre - frame.eye), key);
        }
        std::sort(lobes.begin(), lobes.end());
        if (!lobes.empty()) vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, lobe_);
        for (const auto& [distance, key] : lobes) draw(cache_.at(key));
    }

private:
    struct GpuMesh {
        std::uint64_t version = 0;
        // Vertices (Vertex), then uint32 indices at index_offset. Instanced leaves: the shared
        // quad's four uvs (vec2), its 6 indices at index_offset, the leaves (LeafInstance) at
        // instance_offset.
        GpuBuffer buffer;
        VkDeviceSize index_offset = 0;
        std::uint32_t index_count = 0;
        VkDeviceSize instance_offset = 0;
        std::uint32_t instance_count = 0; // 0: drawn as a mesh
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
        if (instanced_leaves_ && item.material == RenderMaterial::Leaf) {
            std::vector<LeafInstance> instances;
            std::array<glm::vec2, 4> uvs;
            if (as_leaf_instances(g, instances, uvs)) return upload_leaf_instances(item, instances, uvs, stats);
        }
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

    /// A leaf mesh as instances (see as_leaf_instances): 32 bytes of uvs and 24 of indices
    /// for the shared quad, 48 bytes per leaf, instead of 4 vertices (128 bytes) and 2
    /// triangles (24 bytes) per leaf.
    GpuMesh upload_leaf_instances(const RenderItem& item, const std::vector<LeafInstance>& instances,
                                  const std::array<glm::vec2, 4>& uvs, RenderStats& stats) const
    {
        GpuMesh m;
        m.version = item.version;
        Bounds b;
        for (const glm::vec3& p : item.geometry.positions) b.add(p);
        m.centre = 0.5f * (b.lo + b.hi);
        static constexpr std::uint32_t kQuad[6] = {0, 1, 2, 0, 2, 3}; // leaves.cpp's two triangles
        static_assert(sizeof(uvs) == 32);
        m.index_offset = sizeof(uvs);
        m.index_count = 6;
        m.instance_offset = 64;
        m.instance_count = static_cast<std::uint32_t>(instances.size());
        const std::size_t instance_bytes = instances.size() * sizeof(LeafInstance);
        m.buffer = ctx_.create_buffer(m.instance_offset + instance_bytes,
                                      VK_BUFFER_USAGE_VERTEX_BUFFER_BIT | VK_BUFFER_USAGE_INDEX_BUFFER_BIT,
                                      VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
        try {
            ctx_.write(m.buffer, 0, uvs.data(), sizeof(uvs));
            ctx_.write(m.buffer, m.index_offset, kQuad, sizeof(kQuad));
            ctx_.write(m.buffer, m.instance_offset, instances.data(), instance_bytes);
        } catch (...) {
            ctx_.destroy(m.buffer);
            throw;
        }
        stats.bytes_uploaded += sizeof(uvs) + sizeof(kQuad) + instance_bytes;
        return m;
    }

    /// A texture of the scene and what it was made from.
    struct TextureSlot {
        GpuImage image;
        std::uint64_t version = 0;
        bool ready = false;
        bool is_real = false; // false: the white texel
    };
    static constexpr std::uint32_t kLeafTextureBinding = 0, kPhotoTextureBinding = 1; // app/render/shaders/mesh.frag

    /// Uploads `tex` into `slot` (and points `binding` at it) unless it holds that version
    /// already. The white texel stands for "no texture": a texture replacing it (or replaced
    /// by it) is uploaded whatever its version.
    void update_texture(TextureSlot& slot, std::uint32_t binding, const RgbaImage& tex, bool is_real, std::uint64_t version,
                        RenderStats& stats)
    {
        if (!is_real) version = 0;
        if (slot.ready && slot.is_real == is_real && slot.version == version) return;
        GpuImage fresh = upload_rgba_texture(ctx_, tex);
        ctx_.destroy(slot.image);
        slot.image = fresh;
        slot.version = version;
        slot.is_real = is_real;
        slot.ready = true;
        stats.bytes_uploaded += tex.pixels.size();
        write_texture_descriptor(ctx_.device(), descriptor_set_, sampler_, slot.image, binding);
    }

    void create(VkRenderPass pass, const FrameFormat& format)
    {
        const VkDevice dev = ctx_.device();
        // One texture (the overlay's font), and the scene's two: the leaf texture and the photo.
        const VkDescriptorSetLayoutBinding bindings[2] = {
            {kLeafTextureBinding, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, VK_SHADER_STAGE_FRAGMENT_BIT, nullptr},
            {kPhotoTextureBinding, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, VK_SHADER_STAGE_FRAGMENT_BIT, nullptr},
        };
        auto set_layout = vk_struct<VkDescriptorSetLayoutCreateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO);
        set_layout.bindingCount = 1;
        set_layout.pBindings = bindings;
        CHECK_VKCMD(vkCreateDescriptorSetLayout(dev, &set_layout, nullptr, &set_layout_));
        set_layout.bindingCount = 2;
        CHECK_VKCMD(vkCreateDescriptorSetLayout(dev, &set_layout, nullptr, &scene_set_layout_));
        layout_ = create_pipeline_layout(dev, scene_set_layout_,
                                         {VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0, sizeof(PushBlock)});
        allocate_sampler_set(dev, scene_set_layout_, descriptor_pool_, descriptor_set_, 2);
        auto sampler = vk_struct<VkSamplerCreateInfo>(VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO);
        sampler.magFilter = VK_FILTER_LINEAR;
        sampler.minFilter = VK_FILTER_LINEAR;
        sampler.mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST;
        sampler.addressModeU = sampler.addressModeV = sampler.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
        sampler.maxLod = 0.0f;
        CHECK_VKCMD(vkCreateSampler(dev, &sampler, nullptr, &sampler_));

        VkVertexInputBindingDescription vertex_binding{0, sizeof(Vertex), VK_VERTEX_INPUT_RATE_VERTEX};
        const VkVertexInputAttributeDescription attributes[3] = {
            {0, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(Vertex, position)},
            {1, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(Vertex, normal)},
            {2, 0, VK_FORMAT_R32G32_SFLOAT, offsetof(Vertex, uv)},
        };
        auto mesh = vk_struct<VkPipelineVertexInputStateCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO);
        mesh.vertexBindingDescriptionCount = 1;
        mesh.pVertexBindingDescriptions = &vertex_binding;
        mesh.vertexAttributeDescriptionCount = 3;
        mesh.pVertexAttributeDescriptions = attributes;
        auto make = [&](const PipelineState& state) { return create_pipeline(dev, pass, format, layout_, state); };
        sky_ = make({"sky.vert", "sky.frag", nullptr, VK_CULL_MODE_NONE, false, false, false});
        ground_pipeline_ = make({"ground.vert", "ground.frag", nullptr, VK_CULL_MODE_NONE, true, true, false});
        opaque_ = make({"mesh.vert", "mesh.frag", &mesh, VK_CULL_MODE_BACK_BIT, true, true, false});
        leaf_ = make({"mesh.vert", "mesh.frag", &mesh, VK_CULL_MODE_NONE, true, true, false});
        // Instanced leaves: the shared quad's uvs per vertex, the leaves per instance.
        const VkVertexInputBindingDescription leaf_bindings[2] = {
            {0, sizeof(glm::vec2), VK_VERTEX_INPUT_RATE_VERTEX},
            {1, sizeof(LeafInstance), VK_VERTEX_INPUT_RATE_INSTANCE},
        };
        const VkVertexInputAttributeDescription leaf_attributes[5] = {
            {0, 0, VK_FORMAT_R32G32_SFLOAT, 0},
            {1, 1, VK_FORMAT_R32G32B32_SFLOAT, offsetof(LeafInstance, corner0)},
            {2, 1, VK_FORMAT_R32G32B32_SFLOAT, offsetof(LeafInstance, corner1)},
            {3, 1, VK_FORMAT_R32G32B32_SFLOAT, offsetof(LeafInstance, corner3)},
            {4, 1, VK_FORMAT_R32G32B32_SFLOAT, offsetof(LeafInstance, normal)},
        };
        auto leaf_input = vk_struct<VkPipelineVertexInputStateCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO);
        leaf_input.vertexBindingDescriptionCount = 2;
        leaf_input.pVertexBindingDescriptions = leaf_bindings;
        leaf_input.vertexAttributeDescriptionCount = 5;
        leaf_input.pVertexAttributeDescriptions = leaf_attributes;
        leaf_instanced_ = make({"leaf.vert", "mesh.frag", &leaf_input, VK_CULL_MODE_NONE, true, true, false});
        lobe_ = make({"mesh.vert", "mesh.frag", &mesh, VK_CULL_MODE_NONE, true, false, true});
    }

    void destroy()
    {
        const VkDevice dev = ctx_.device();
        for (auto& [key, mesh] : cache_) ctx_.destroy(mesh.buffer);
        cache_.clear();
        ctx_.destroy(leaf_texture_.image);
        ctx_.destroy(photo_texture_.image);
        for (VkPipeline p : {sky_, ground_pipeline_, opaque_, leaf_, leaf_instanced_, lobe_})
            if (p) vkDestroyPipeline(dev, p, nullptr);
        if (sampler_) vkDestroySampler(dev, sampler_, nullptr);
        if (descriptor_pool_) vkDestroyDescriptorPool(dev, descriptor_pool_, nullptr);
        if (layout_) vkDestroyPipelineLayout(dev, layout_, nullptr);
        if (set_layout_) vkDestroyDescriptorSetLayout(dev, set_layout_, nullptr);
        if (scene_set_layout_) vkDestroyDescriptorSetLayout(dev, scene_set_layout_, nullptr);
    }

    const VulkanContext& ctx_;
    VkDescriptorSetLayout set_layout_ = VK_NULL_HANDLE;       // one texture (the overlay's set)
    VkDescriptorSetLayout scene_set_layout_ = VK_NULL_HANDLE; // leaf texture and photo
    VkPipelineLayout layout_ = VK_NULL_HANDLE;
    VkDescriptorPool descriptor_pool_ = VK_NULL_HANDLE;
    VkDescriptorSet descriptor_set_ = VK_NULL_HANDLE;
    VkSampler sampler_ = VK_NULL_HANDLE;
    VkPipeline sky_ = VK_NULL_HANDLE, ground_pipeline_ = VK_NULL_HANDLE, opaque_ = VK_NULL_HANDLE, leaf_ = VK_NULL_HANDLE,
               leaf_instanced_ = VK_NULL_HANDLE, lobe_ = VK_NULL_HANDLE;
    bool instanced_leaves_ = true;
    TextureSlot leaf_texture_, photo_texture_;
    std::unordered_map<std::uint64_t, GpuMesh> cache_;
    std::vector<std::uint64_t> draws_; // keys in scene order
    bool ground_ = true;
    float ground_y_ = 0.0f;
    Bounds bounds_;
};

// ---------------------------------------------------------------------------------------------
/// The 2D overlay (app/shaders/ui.*): its pipeline, font texture, host-visible vertex and index
/// buffers (grown geometrically, reused across frames) and the commands of the last
/// set_overlay. Every submit of the renderer is waited for, so set() may write the buffers.
class OverlayDrawer {
public:
    OverlayDrawer(const VulkanContext& ctx, VkRenderPass pass, const FrameFormat& format, VkDescriptorSetLayout set_layout,
                  VkSampler sampler)
        : ctx_(ctx), sampler_(sampler)
    {
        try {
            create(pass, format, set_layout);
        } catch (...) {
            destroy();
            throw;
        }
    }
    ~OverlayDrawer() { destroy(); }
    OverlayDrawer(const OverlayDrawer&) = delete;
    OverlayDrawer& operator=(const OverlayDrawer&) = delete;

    /// Checks everything first: a bad overlay throws InvalidInput and leaves the last one.
    void set(const Overlay& overlay)
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

    /// The overlay's draws, inside a begun render pass of `extent` (after the scene's).
    void record(VkCommandBuffer cmd, VkExtent2D extent) const
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

private:
    /// Makes `b` hold at least `bytes`, growing it to twice its size (or more) when it must.
    void reserve(GpuBuffer& b, std::size_t bytes, VkBufferUsageFlags usage) const
    {
        if (b.buffer && b.size >= bytes) return;
        const VkDeviceSize size = std::max<VkDeviceSize>({VkDeviceSize(bytes), 2 * b.size, 4096});
        ctx_.destroy(b);
        b = ctx_.create_buffer(size, usage, 0);
    }

    void create(VkRenderPass pass, const FrameFormat& format, VkDescriptorSetLayout set_layout)
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

    void destroy()
    {
        const VkDevice dev = ctx_.device();
        ctx_.destroy(vertices_);
        ctx_.destroy(indices_);
        ctx_.destroy(font_);
        if (pipeline_) vkDestroyPipeline(dev, pipeline_, nullptr);
        if (descriptor_pool_) vkDestroyDescriptorPool(dev, descriptor_pool_, nullptr);
        if (layout_) vkDestroyPipelineLayout(dev, layout_, nullptr);
    }

    const VulkanContext& ctx_;
    VkSampler sampler_;
    VkPipelineLayout layout_ = VK_NULL_HANDLE;
    VkPipeline pipeline_ = VK_NULL_HANDLE;
    VkDescriptorPool descriptor_pool_ = VK_NULL_HANDLE;
    VkDescriptorSet descriptor_set_ = VK_NULL_HANDLE;
    GpuImage font_;
    std::uint64_t font_version_ = 0;
    bool font_ready_ = false;
    bool font_is_real_ = false;
    GpuBuffer vertices_, indices_;
    std::vector<OverlayCommand> commands_;
};

// ---------------------------------------------------------------------------------------------
/// A window's surface and swapchain (FIFO). Frames are drawn offscreen and blitted (copied
/// when the swapchain's format cannot be blitted into but is the picture's own) into the
/// acquired image. One image-acquired semaphore (each frame's submit is waited for, so it is
/// free again at the next acquire) and one render-done semaphore per swapchain image (the
/// presentation engine has consumed it once the image is acquired again).
class WindowTarget {
public:
    /// Takes ownership of `surface` (destroyed here, also when this throws).
    WindowTarget(const VulkanContext& ctx, VkSurfaceKHR surface) : ctx_(ctx), surface_(surface)
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
    ~WindowTarget() { destroy(); }
    WindowTarget(const WindowTarget&) = delete;
    WindowTarget& operator=(const WindowTarget&) = delete;

    VkSemaphore acquired() const { return acquired_; }
    VkSemaphore rendered(std::uint32_t image) const { return rendered_[image]; }

    /// Acquires the next image for a frame of `wanted` pixels, making or remaking the
    /// swapchain first when the size changed or the last acquire or present said it is out of
    /// date or suboptimal. False when there is none (the surface is 0 × 0, or none came in
    /// time); `acquired()` is then not signalled.
    bool acquire(VkExtent2D wanted, std::uint32_t* image)
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

    /// After the render pass: `picture` (TRANSFER_SRC_OPTIMAL, `size`) into swapchain image
    /// `image`, left in PRESENT_SRC_KHR.
    void record_blit(VkCommandBuffer cmd, VkImage picture, VkExtent2D size, std::uint32_t image) const
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

    /// Queues image `image` for presentation after its render-done semaphore.
    void present(std::uint32_t image)
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

private:
    static constexpr std::uint64_t kAcquireTimeoutNs = 2'000'000'000; // 2 s: a window that never gives an image draws nothing

    /// The swapchain for a frame of `wanted` pixels (the surface's own size when it has one);
    /// false, with no swapchain, when the surface is 0 × 0.
    bool create_swapchain(VkExtent2D wanted)
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

    void destroy_swapchain()
    {
        for (VkSemaphore s : rendered_)
            if (s) vkDestroySemaphore(ctx_.device(), s, nullptr);
        rendered_.clear();
        images_.clear();
        if (swapchain_) vkDestroySwapchainKHR(ctx_.device(), swapchain_, nullptr);
        swapchain_ = VK_NULL_HANDLE;
    }

    void destroy()
    {
        vkDeviceWaitIdle(ctx_.device());
        destroy_swapchain();
        if (acquired_) vkDestroySemaphore(ctx_.device(), acquired_, nullptr);
        acquired_ = VK_NULL_HANDLE;
        if (surface_) vkDestroySurfaceKHR(ctx_.instance(), surface_, nullptr);
        surface_ = VK_NULL_HANDLE;
    }

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

} // namespace

void keep_vulkan_drivers_loaded()
{
    ensure_runtime_dir();
    const std::vector<std::string> before = loaded_libraries();
    auto app = vk_struct<VkApplicationInfo>(VK_STRUCTURE_TYPE_APPLICATION_INFO);
    app.pApplicationName = "lobesketch";
    app.apiVersion = VK_API_VERSION_1_1;
    auto info = vk_struct<VkInstanceCreateInfo>(VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO);
    info.pApplicationInfo = &app;
    VkInstance instance = VK_NULL_HANDLE;
    if (vkCreateInstance(&info, nullptr, &instance) != VK_SUCCESS) return;
    std::uint32_t count = 0;
    vkEnumeratePhysicalDevices(instance, &count, nullptr); // drivers finish loading here, whatever it returns
    keep_loaded_since(before);
    vkDestroyInstance(instance, nullptr);
}

// ---------------------------------------------------------------------------------------------
struct Renderer::Impl {
    explicit Impl(const RendererOptions& options) : ctx(options)
    {
        format = choose_frame_format(ctx, options.samples);
        pass = create_offscreen_render_pass(ctx.device(), format);
        try {
            drawer = std::make_unique<SceneDrawer>(ctx, pass, format, options.instanced_leaves);
            drawer->set_scene(RenderScene{}, stats);
            overlay = std::make_unique<OverlayDrawer>(ctx, pass, format, drawer->texture_set_layout(), drawer->sampler());
            overlay->set(Overlay{});
        } catch (...) {
            overlay.reset();
            drawer.reset();
            vkDestroyRenderPass(ctx.device(), pass, nullptr);
            throw;
        }
    }
    // Device idle, then the window (swapchain, surface), the targets, the drawers and the
    // pass; the context (device, then instance) goes last.
    ~Impl()
    {
        vkDeviceWaitIdle(ctx.device());
        window.reset();
        last = nullptr;
        target.reset();
        window_frame.reset();
        eye_targets.clear();
        overlay.reset();
        drawer.reset();
        vkDestroyRenderPass(ctx.device(), pass, nullptr);
    }

    /// `t` made for `extent` (remade when its size differs).
    OffscreenTarget& target_of(std::unique_ptr<OffscreenTarget>& t, VkExtent2D extent)
    {
        if (!t || t->extent().width != extent.width || t->extent().height != extent.height) {
            if (last == t.get()) last = nullptr;
            t.reset();
            t = std::make_unique<OffscreenTarget>(ctx, pass, format, extent);
        }
        return *t;
    }

    /// The eye target of `extent`, made when no kept one has that size (the least recently
    /// used is dropped beyond kEyeTargets sizes).
    OffscreenTarget& eye_target_of(VkExtent2D extent)
    {
        auto same = [&](const std::unique_ptr<OffscreenTarget>& t) {
            return t->extent().width == extent.width && t->extent().height == extent.height;
        };
        auto it = std::find_if(eye_targets.begin(), eye_targets.end(), same);
        if (it == eye_targets.end()) {
            eye_targets.insert(eye_targets.begin(), std::make_unique<OffscreenTarget>(ctx, pass, format, extent));
            while (eye_targets.size() > kEyeTargets) {
                if (last == eye_targets.back().get()) last = nullptr;
                eye_targets.pop_back();
            }
        } else {
            std::rotate(eye_targets.begin(), it, it + 1); // most recently used first
        }
        return *eye_targets.front();
    }

    /// The scene (and the overlay when `with_overlay`) into `t`'s render pass (clear, draw,
    /// resolve).
    void record_frame(VkCommandBuffer cmd, const OffscreenTarget& t, const FrameView& view, bool with_overlay = true) const
    {
        const VkExtent2D extent = t.extent();
        VkClearValue clears[3]{};
        clears[0].color = {{0.0f, 0.0f, 0.0f, 1.0f}};
        clears[1].depthStencil = {1.0f, 0};
        auto begin = vk_struct<VkRenderPassBeginInfo>(VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO);
        begin.renderPass = pass;
        begin.framebuffer = t.framebuffer();
        begin.renderArea = {{0, 0}, extent};
        begin.clearValueCount = multisampled(format) ? 3u : 2u;
        begin.pClearValues = clears;
        vkCmdBeginRenderPass(cmd, &begin, VK_SUBPASS_CONTENTS_INLINE);
        drawer->record(cmd, view, extent);
        if (with_overlay) overlay->record(cmd, extent);
        vkCmdEndRenderPass(cmd);
    }

    VulkanContext ctx;
    FrameFormat format;
    VkRenderPass pass = VK_NULL_HANDLE;
    std::unique_ptr<SceneDrawer> drawer;
    std::unique_ptr<OverlayDrawer> overlay;
    std::unique_ptr<OffscreenTarget> target;       // render()'s pictures
    std::unique_ptr<OffscreenTarget> window_frame; // present()'s frames, so screenshots of another size do not remake it
    std::unique_ptr<WindowTarget> window;
    static constexpr std::size_t kEyeTargets = 4;
    std::vector<std::unique_ptr<OffscreenTarget>> eye_targets; // render_to()'s, by size, most recently used first
    OffscreenTarget* last = nullptr; // the target of the last frame drawn (last_frame())
    RenderStats stats;
};

Renderer::Renderer(const RendererOptions& options) : impl_(std::make_unique<Impl>(options)) {}
Renderer::~Renderer() = default;

const std::string& Renderer::device_name() const { return impl_->ctx.name(); }
bool Renderer::is_software() const { return impl_->ctx.software(); }
int Renderer::samples() const { return static_cast<int>(impl_->format.samples); }
const RenderStats& Renderer::stats() const { return impl_->stats; }

void Renderer::set_scene(const RenderScene& scene) { impl_->drawer->set_scene(scene, impl_->stats); }

namespace {

void check_size(int width, int height, const char* what)
{
    if (width < 1 || height < 1 || width > 16384 || height > 16384)
        throw InvalidInput(std::string("render: ") + what + " of " + std::to_string(width) + "x" + std::to_string(height) +
                           " pixels (1 to 16384 on each side)");
}

} // namespace

RgbaImage Renderer::render(const Camera& camera, int width, int height)
{
    check_size(width, height, "a picture");
    Impl& im = *impl_;
    OffscreenTarget& target =
        im.target_of(im.target, {static_cast<std::uint32_t>(width), static_cast<std::uint32_t>(height)});
    im.ctx.submit_and_wait(
        [&](VkCommandBuffer cmd) {
            im.record_frame(cmd, target, camera_frame_view(camera, target.extent()));
            target.record_copy_out(cmd);
        },
        &im.stats.record_ms, &im.stats.gpu_ms);
    target.drawn = true;
    im.last = &target;
    return target.read();
}

void Renderer::set_overlay(const Overlay& overlay) { impl_->overlay->set(overlay); }

void Renderer::attach_window(const std::function<std::uint64_t(std::uint64_t vk_instance)>& create_surface)
{
    Impl& im = *impl_;
    if (!im.ctx.presentation())
        throw RenderError("render: attach_window needs a Renderer made with RendererOptions::presentation = true");
    if (!im.ctx.instance_extension_enabled(VK_KHR_SURFACE_EXTENSION_NAME))
        throw RenderError("render: attach_window needs the instance extension " VK_KHR_SURFACE_EXTENSION_NAME
                          " (pass glfwGetRequiredInstanceExtensions in RendererOptions::instance_extensions)");
    im.window.reset(); // a window has one surface at a time: the old one goes first
    const std::uint64_t surface = create_surface(reinterpret_cast<std::uint64_t>(im.ctx.instance()));
    if (!surface) throw RenderError("render: the window's Vulkan surface could not be made (create_surface returned 0)");
    im.window = std::make_unique<WindowTarget>(im.ctx, handle_from_integer<VkSurfaceKHR>(surface));
}

bool Renderer::present(const Camera& camera, int width, int height)
{
    Impl& im = *impl_;
    if (!im.window) throw RenderError("render: present needs a window (call attach_window first)");
    if (width == 0 || height == 0) return false; // minimised
    check_size(width, height, "a window frame");
    const VkExtent2D extent{static_cast<std::uint32_t>(width), static_cast<std::uint32_t>(height)};
    OffscreenTarget& target = im.target_of(im.window_frame, extent);
    std::uint32_t image = 0;
    if (!im.window->acquire(extent, &image)) return false;
    im.ctx.submit_and_wait(
        [&](VkCommandBuffer cmd) {
            im.record_frame(cmd, target, camera_frame_view(camera, target.extent()));
            im.window->record_blit(cmd, target.picture(), extent, image);
        },
        &im.stats.record_ms, &im.stats.gpu_ms, {im.window->acquired(), VK_PIPELINE_STAGE_TRANSFER_BIT, im.window->rendered(image)});
    target.drawn = true;
    im.last = &target;
    im.window->present(image);
    return true;
}

VulkanHandles Renderer::vulkan_handles() const
{
    const VulkanContext& ctx = impl_->ctx;
    VulkanHandles h;
    h.instance = handle_to_integer(ctx.instance());
    h.physical_device = handle_to_integer(ctx.physical());
    h.device = handle_to_integer(ctx.device());
    h.queue_family = ctx.queue_family();
    h.queue_index = 0; // the renderer's one queue
    return h;
}

namespace {

/// The formats render_to writes (ExternalImage::vk_format).
bool is_external_format(VkFormat f)
{
    return f == VK_FORMAT_R8G8B8A8_UNORM || f == VK_FORMAT_R8G8B8A8_SRGB || f == VK_FORMAT_B8G8R8A8_UNORM ||
           f == VK_FORMAT_B8G8R8A8_SRGB;
}

/// InvalidInput (one line) unless `eye` is finite, with 0 < near < far, every angle strictly
/// between −90° and 90°, left < right, down < up, and an orientation of non-zero length.
void check_eye(const EyeView& eye)
{
    const float values[] = {eye.position.x,    eye.position.y,    eye.position.z,      eye.orientation.w, eye.orientation.x,
                            eye.orientation.y, eye.orientation.z, eye.angle_left,      eye.angle_right,   eye.angle_up,
                            eye.angle_down,    eye.near_m,        eye.far_m};
    for (float v : values)
        if (!std::isfinite(v)) throw InvalidInput("render: an eye view with a value that is not finite");
    if (!(eye.near_m > 0.0f && eye.far_m > eye.near_m))
        throw InvalidInput("render: an eye view with near " + std::to_string(eye.near_m) + " m and far " +
                           std::to_string(eye.far_m) + " m (0 < near < far)");
    const float right_angle = 0.5f * glm::pi<float>();
    auto ordered = [&](float lo, float hi) { return -right_angle < lo && lo < hi && hi < right_angle; };
    if (!ordered(eye.angle_left, eye.angle_right) || !ordered(eye.angle_down, eye.angle_up))
        throw InvalidInput("render: an eye view with angles left " + std::to_string(eye.angle_left) + ", right " +
                           std::to_string(eye.angle_right) + ", down " + std::to_string(eye.angle_down) + ", up " +
                           std::to_string(eye.angle_up) + " rad (each between -pi/2 and pi/2, left < right, down < up)");
    if (glm::length(eye.orientation) < 1e-6f) throw InvalidInput("render: an eye view with an orientation of length 0");
}

/// After the render pass: `picture` (kColorFormat, TRANSFER_SRC_OPTIMAL, `extent`) into layer
/// `layer` of `image` (`format`, the same size, COLOR_ATTACHMENT_OPTIMAL before and after):
/// copied when the formats are the same, else blitted (the blit converts: RGBA to BGRA, and
/// sRGB to linear for a UNORM image, whose texels then hold linear colours).
void record_into_external(VkCommandBuffer cmd, VkImage picture, VkExtent2D extent, VkImage image, VkFormat format,
                          std::uint32_t layer)
{
    auto barrier = vk_struct<VkImageMemoryBarrier>(VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER);
    barrier.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    barrier.image = image;
    barrier.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, layer, 1};
    barrier.oldLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
    barrier.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    barrier.srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
    barrier.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr, 0,
                         nullptr, 1, &barrier);
    const VkImageSubresourceLayers src{VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1}, dst{VK_IMAGE_ASPECT_COLOR_BIT, 0, layer, 1};
    if (format == kColorFormat) {
        VkImageCopy region{};
        region.srcSubresource = src;
        region.dstSubresource = dst;
        region.extent = {extent.width, extent.height, 1};
        vkCmdCopyImage(cmd, picture, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
    } else {
        VkImageBlit region{};
        region.srcSubresource = src;
        region.dstSubresource = dst;
        region.srcOffsets[1] = region.dstOffsets[1] = {std::int32_t(extent.width), std::int32_t(extent.height), 1};
        vkCmdBlitImage(cmd, picture, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region,
                       VK_FILTER_NEAREST);
    }
    barrier.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    barrier.newLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
    barrier.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    barrier.dstAccessMask = VK_ACCESS_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT, 0, 0, nullptr, 0,
                         nullptr, 1, &barrier);
}

} // namespace

void Renderer::render_to(const EyeView& eye, const ExternalImage& target)
{
    check_size(target.width, target.height, "an eye's image");
    if (!target.vk_image) throw InvalidInput("render: render_to was given no image (vk_image is 0)");
    const auto format = static_cast<VkFormat>(target.vk_format);
    if (!is_external_format(format))
        throw InvalidInput("render: render_to cannot write images of VkFormat " + std::to_string(target.vk_format) +
                           " (R8G8B8A8_UNORM 37, R8G8B8A8_SRGB 43, B8G8R8A8_UNORM 44 or B8G8R8A8_SRGB 50)");
    if (target.array_layer < 0)
        throw InvalidInput("render: render_to was given array layer " + std::to_string(target.array_layer) + " (0 or more)");
    check_eye(eye);
    Impl& im = *impl_;
    if (format != im.format.color) {
        VkFormatProperties src, dst;
        vkGetPhysicalDeviceFormatProperties(im.ctx.physical(), im.format.color, &src);
        vkGetPhysicalDeviceFormatProperties(im.ctx.physical(), format, &dst);
        if (!(src.optimalTilingFeatures & VK_FORMAT_FEATURE_BLIT_SRC_BIT) || !(dst.optimalTilingFeatures & VK_FORMAT_FEATURE_BLIT_DST_BIT))
            throw RenderUnavailable("render: the Vulkan device '" + im.ctx.name() + "' cannot blit into images of VkFormat " +
                                    std::to_string(target.vk_format));
    }
    const VkExtent2D extent{static_cast<std::uint32_t>(target.width), static_cast<std::uint32_t>(target.height)};
    OffscreenTarget& t = im.eye_target_of(extent);
    const auto image = handle_from_integer<VkImage>(target.vk_image);
    im.ctx.submit_and_wait(
        [&](VkCommandBuffer cmd) {
            im.record_frame(cmd, t, eye_frame_view(eye), false);
            record_into_external(cmd, t.picture(), extent, image, format, static_cast<std::uint32_t>(target.array_layer));
        },
        &im.stats.record_ms, &im.stats.gpu_ms);
    t.drawn = true;
    im.last = &t;
}

RgbaImage Renderer::last_frame()
{
    Impl& im = *impl_;
    if (!im.last || !im.last->drawn) return {};
    OffscreenTarget& target = *im.last;
    im.ctx.submit_and_wait([&](VkCommandBuffer cmd) { target.record_copy_out(cmd); });
    return target.read();
}

} // namespace lobe
