// The OpenXR replay runtime (input/openxr_replay/, docs/openxr-replay-runtime.md), driven by a
// small independent OpenXR client written from the specification: it goes through the system
// OpenXR loader (XR_RUNTIME_JSON), uses the action system, hand tracking and Vulkan swapchains
// (XR_KHR_vulkan_enable2) and runs the frame loop to the session's end.

#include <gtest/gtest.h>

#include <array>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <dlfcn.h>

#define XR_USE_GRAPHICS_API_VULKAN 1
#include <vulkan/vulkan.h>
#include <openxr/openxr.h>
#include <openxr/openxr_platform.h>

#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_STATIC
#if defined(__clang__)
#pragma clang diagnostic push
#pragma clang diagnostic ignored "-Wmissing-field-initializers"
#pragma clang diagnostic ignored "-Wconversion"
#pragma clang diagnostic ignored "-Wsign-conversion"
#pragma clang diagnostic ignored "-Wshadow"
#pragma clang diagnostic ignored "-Wunused-function"
#elif defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wconversion"
#pragma GCC diagnostic ignored "-Wsign-conversion"
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wunused-function"
#endif
#include <stb/stb_image.h>
#if defined(__clang__)
#pragma clang diagnostic pop
#elif defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

#include "app/render/loaded_libraries.h"
#include "input/recording.h"
#include "tests/support/test_data.h"
#include "tests/support/test_paths.h"

// Debian's OpenXR loader 1.0.20 leaks about 1.3 kB per instance (a do-nothing runtime shows
// the same): not ours to fix, so the leak checker (asan preset) ignores what it allocates.
extern "C" __attribute__((used)) const char* __lsan_default_suppressions()
{
    return "leak:libopenxr_loader.so\n";
}

// OpenXR and Vulkan structures are written {type} first and filled member by member.
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"

namespace {

using lobe::test::temp_dir;

// ---- checks that keep the failing call (hello_xr's CHECK_XRCMD) ------------------------------

struct CallFailed : std::runtime_error {
    CallFailed(const std::string& what, long code) : std::runtime_error(what), result(code) {}
    long result;
};

void xr_check(XrResult r, const char* expr, const char* file, int line)
{
    if (XR_FAILED(r)) {
        std::ostringstream s;
        s << expr << " failed with XrResult " << r << " at " << file << ":" << line;
        throw CallFailed(s.str(), r);
    }
}
void vk_check(VkResult r, const char* expr, const char* file, int line)
{
    if (r != VK_SUCCESS) {
        std::ostringstream s;
        s << expr << " failed with VkResult " << r << " at " << file << ":" << line;
        throw CallFailed(s.str(), r);
    }
}
#define CHECK_XR(expr) xr_check((expr), #expr, __FILE__, __LINE__)
#define CHECK_VK(expr) vk_check((expr), #expr, __FILE__, __LINE__)

/// Sets environment variables for one test and restores them after.
class ScopedEnv {
public:
    ScopedEnv& set(const std::string& name, const std::string& value)
    {
        remember(name);
        setenv(name.c_str(), value.c_str(), 1);
        return *this;
    }
    ScopedEnv& unset(const std::string& name)
    {
        remember(name);
        unsetenv(name.c_str());
        return *this;
    }
    ~ScopedEnv()
    {
        for (auto it = saved_.rbegin(); it != saved_.rend(); ++it) {
            if (it->second)
                setenv(it->first.c_str(), it->second->c_str(), 1);
            else
                unsetenv(it->first.c_str());
        }
    }

private:
    void remember(const std::string& name)
    {
        const char* v = std::getenv(name.c_str());
        saved_.emplace_back(name, v ? std::optional<std::string>(v) : std::nullopt);
    }
    std::vector<std::pair<std::string, std::optional<std::string>>> saved_;
};

/// The environment every test starts from: our runtime, no switches.
ScopedEnv replay_env(const std::string& recording)
{
    ScopedEnv env;
    env.set("XR_RUNTIME_JSON", LOBE_XR_REPLAY_MANIFEST).set("LOBESKETCH_REPLAY", recording);
    for (const char* v : {"LOBESKETCH_REPLAY_DUMP", "LOBESKETCH_REPLAY_DUMP_EVERY", "LOBESKETCH_REPLAY_MAX_FRAMES",
                          "LOBESKETCH_REPLAY_LOSE_SESSION_AT", "LOBESKETCH_REPLAY_NO_HAND_TRACKING",
                          "LOBESKETCH_REPLAY_NO_VULKAN", "LOBESKETCH_REPLAY_REALTIME", "LOBESKETCH_REPLAY_VIEW_SIZE",
                          "XR_ENABLE_API_LAYERS"})
        env.unset(v);
    if (!std::getenv("XDG_RUNTIME_DIR")) env.set("XDG_RUNTIME_DIR", temp_dir("openxr_replay_xdg"));
    return env;
}

std::vector<std::string> instance_extensions()
{
    std::uint32_t n = 0;
    CHECK_XR(xrEnumerateInstanceExtensionProperties(nullptr, 0, &n, nullptr));
    std::vector<XrExtensionProperties> props(n, XrExtensionProperties{XR_TYPE_EXTENSION_PROPERTIES});
    CHECK_XR(xrEnumerateInstanceExtensionProperties(nullptr, n, &n, props.data()));
    std::vector<std::string> out;
    for (const auto& p : props) out.emplace_back(p.extensionName);
    return out;
}

bool has(const std::vector<std::string>& list, const char* name)
{
    return std::find(list.begin(), list.end(), name) != list.end();
}

XrResult create_instance(const std::vector<const char*>& extensions, XrInstance* instance)
{
    XrInstanceCreateInfo ci{XR_TYPE_INSTANCE_CREATE_INFO};
    std::snprintf(ci.applicationInfo.applicationName, XR_MAX_APPLICATION_NAME_SIZE, "%s", "lobe_tests");
    ci.applicationInfo.apiVersion = XR_MAKE_VERSION(1, 0, 0);
    ci.enabledExtensionCount = static_cast<std::uint32_t>(extensions.size());
    ci.enabledExtensionNames = extensions.data();
    return xrCreateInstance(&ci, instance);
}

template <class F>
F proc(XrInstance instance, const char* name)
{
    PFN_xrVoidFunction fn = nullptr;
    CHECK_XR(xrGetInstanceProcAddr(instance, name, &fn));
    return reinterpret_cast<F>(fn);
}

// ---- the client -------------------------------------------------------------------------------

struct ClientOptions {
    bool hand_tracking = true;
    bool vulkan = true;          ///< else a headless session (XR_MND_headless)
    bool misuse_checks = false;  ///< also try calls the runtime must refuse
    std::array<VkClearColorValue, 2> eye_colour{{{{1.0f, 0.0f, 0.0f, 1.0f}}, {{0.0f, 0.0f, 1.0f, 1.0f}}}};
};

struct HandSample {
    bool active = false;
    std::array<XrHandJointLocationEXT, XR_HAND_JOINT_COUNT_EXT> joints{};
};

struct FrameSample {
    XrTime time = 0;
    bool rendered = false;
    std::array<HandSample, 2> hands;
    std::optional<std::array<HandSample, 2>> between; ///< located half a period later
};

struct Outcome {
    std::vector<XrSessionState> states;
    std::vector<FrameSample> frames;
    bool pose_action_ever_active = false;
    bool select_ever_active = false;
    XrResult wait_after_loss = XR_SUCCESS;
    bool supports_hand_tracking = false;
    std::vector<std::string> misuse_failures; ///< calls the runtime accepted though it must not
    bool clean_end = false;                   ///< saw EXITING and destroyed everything
};

class Client {
public:
    explicit Client(ClientOptions o) : opt_(o) {}
    ~Client() { teardown(); }
    Outcome run();

private:
    void create_vulkan();
    void create_swapchains();
    void render_eye(int eye, std::uint32_t image_index);
    void frame();
    void locate_hands(XrTime t, std::array<HandSample, 2>& out);
    void teardown();
    void expect_refused(XrResult r, XrResult want, const char* what)
    {
        if (r != want) out_.misuse_failures.push_back(std::string(what) + " gave " + std::to_string(r));
    }

    ClientOptions opt_;
    Outcome out_;
    std::vector<std::string> libs_before_ = lobe::loaded_libraries();
    XrInstance instance_ = XR_NULL_HANDLE;
    XrSystemId system_ = XR_NULL_SYSTEM_ID;
    XrSession session_ = XR_NULL_HANDLE;
    XrSpace stage_ = XR_NULL_HANDLE, view_ = XR_NULL_HANDLE;
    std::array<XrSpace, 2> hand_spaces_{};
    XrActionSet action_set_ = XR_NULL_HANDLE;
    XrAction pose_action_ = XR_NULL_HANDLE, select_action_ = XR_NULL_HANDLE;
    std::array<XrPath, 2> hand_paths_{};
    std::array<XrHandTrackerEXT, 2> trackers_{};
    PFN_xrCreateHandTrackerEXT create_tracker_ = nullptr;
    PFN_xrDestroyHandTrackerEXT destroy_tracker_ = nullptr;
    PFN_xrLocateHandJointsEXT locate_joints_ = nullptr;
    bool running_ = false;
    bool lost_ = false;
    // Vulkan
    VkInstance vk_instance_ = VK_NULL_HANDLE;
    VkPhysicalDevice vk_physical_ = VK_NULL_HANDLE;
    VkDevice vk_device_ = VK_NULL_HANDLE;
    VkQueue vk_queue_ = VK_NULL_HANDLE;
    std::uint32_t queue_family_ = 0;
    VkCommandPool pool_ = VK_NULL_HANDLE;
    VkCommandBuffer cmd_ = VK_NULL_HANDLE;
    VkFence fence_ = VK_NULL_HANDLE;
    struct Eye {
        XrSwapchain swapchain = XR_NULL_HANDLE;
        std::vector<VkImage> images;
    };
    std::array<Eye, 2> eyes_;
    static constexpr std::int32_t kSize = 64;
};

void Client::create_vulkan()
{
    auto get_requirements = proc<PFN_xrGetVulkanGraphicsRequirements2KHR>(instance_, "xrGetVulkanGraphicsRequirements2KHR");
    auto create_instance = proc<PFN_xrCreateVulkanInstanceKHR>(instance_, "xrCreateVulkanInstanceKHR");
    auto get_device = proc<PFN_xrGetVulkanGraphicsDevice2KHR>(instance_, "xrGetVulkanGraphicsDevice2KHR");
    auto create_device = proc<PFN_xrCreateVulkanDeviceKHR>(instance_, "xrCreateVulkanDeviceKHR");
    XrGraphicsRequirementsVulkan2KHR req{XR_TYPE_GRAPHICS_REQUIREMENTS_VULKAN2_KHR};
    CHECK_XR(get_requirements(instance_, system_, &req));
    if (XR_VERSION_MAJOR(req.minApiVersionSupported) > 1) throw std::runtime_error("runtime wants Vulkan > 1.x");

    VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
    app.pApplicationName = "lobe_tests";
    app.apiVersion = VK_API_VERSION_1_1;
    VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    ici.pApplicationInfo = &app;
    XrVulkanInstanceCreateInfoKHR xici{XR_TYPE_VULKAN_INSTANCE_CREATE_INFO_KHR};
    xici.systemId = system_;
    xici.pfnGetInstanceProcAddr = &vkGetInstanceProcAddr;
    xici.vulkanCreateInfo = &ici;
    VkResult vr = VK_SUCCESS;
    CHECK_XR(create_instance(instance_, &xici, &vk_instance_, &vr));
    CHECK_VK(vr);

    XrVulkanGraphicsDeviceGetInfoKHR gi{XR_TYPE_VULKAN_GRAPHICS_DEVICE_GET_INFO_KHR};
    gi.systemId = system_;
    gi.vulkanInstance = vk_instance_;
    CHECK_XR(get_device(instance_, &gi, &vk_physical_));

    std::uint32_t n = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(vk_physical_, &n, nullptr);
    std::vector<VkQueueFamilyProperties> families(n);
    vkGetPhysicalDeviceQueueFamilyProperties(vk_physical_, &n, families.data());
    bool found = false;
    for (std::uint32_t i = 0; i < n && !found; ++i)
        if (families[i].queueFlags & VK_QUEUE_GRAPHICS_BIT) {
            queue_family_ = i;
            found = true;
        }
    if (!found) throw std::runtime_error("no graphics queue");
    const float priority = 1.0f;
    VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    qci.queueFamilyIndex = queue_family_;
    qci.queueCount = 1;
    qci.pQueuePriorities = &priority;
    VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
    dci.queueCreateInfoCount = 1;
    dci.pQueueCreateInfos = &qci;
    XrVulkanDeviceCreateInfoKHR xdci{XR_TYPE_VULKAN_DEVICE_CREATE_INFO_KHR};
    xdci.systemId = system_;
    xdci.pfnGetInstanceProcAddr = &vkGetInstanceProcAddr;
    xdci.vulkanPhysicalDevice = vk_physical_;
    xdci.vulkanCreateInfo = &dci;
    CHECK_XR(create_device(instance_, &xdci, &vk_device_, &vr));
    CHECK_VK(vr);
    vkGetDeviceQueue(vk_device_, queue_family_, 0, &vk_queue_);
    // Mesa keeps global state it frees only at exit: keep the drivers loaded (see
    // app/render/loaded_libraries.h), so the leak checker does not blame their unloading.
    lobe::keep_loaded_since(libs_before_);

    VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pci.queueFamilyIndex = queue_family_;
    CHECK_VK(vkCreateCommandPool(vk_device_, &pci, nullptr, &pool_));
    VkCommandBufferAllocateInfo cai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    cai.commandPool = pool_;
    cai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    cai.commandBufferCount = 1;
    CHECK_VK(vkAllocateCommandBuffers(vk_device_, &cai, &cmd_));
    VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    CHECK_VK(vkCreateFence(vk_device_, &fci, nullptr, &fence_));
}

void Client::create_swapchains()
{
    std::uint32_t n = 0;
    CHECK_XR(xrEnumerateSwapchainFormats(session_, 0, &n, nullptr));
    std::vector<std::int64_t> formats(n);
    CHECK_XR(xrEnumerateSwapchainFormats(session_, n, &n, formats.data()));
    std::int64_t format = 0;
    for (std::int64_t want : {std::int64_t(VK_FORMAT_R8G8B8A8_UNORM), std::int64_t(VK_FORMAT_B8G8R8A8_UNORM)})
        if (!format && std::find(formats.begin(), formats.end(), want) != formats.end()) format = want;
    if (!format) throw std::runtime_error("no 8-bit UNORM swapchain format offered");

    std::uint32_t views = 0;
    CHECK_XR(xrEnumerateViewConfigurationViews(instance_, system_, XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO, 0, &views, nullptr));
    if (views != 2) throw std::runtime_error("stereo without two views");
    for (auto& eye : eyes_) {
        XrSwapchainCreateInfo sci{XR_TYPE_SWAPCHAIN_CREATE_INFO};
        sci.usageFlags = XR_SWAPCHAIN_USAGE_COLOR_ATTACHMENT_BIT | XR_SWAPCHAIN_USAGE_TRANSFER_DST_BIT;
        sci.format = format;
        sci.sampleCount = 1;
        sci.width = kSize;
        sci.height = kSize;
        sci.faceCount = 1;
        sci.arraySize = 1;
        sci.mipCount = 1;
        CHECK_XR(xrCreateSwapchain(session_, &sci, &eye.swapchain));
        std::uint32_t count = 0;
        CHECK_XR(xrEnumerateSwapchainImages(eye.swapchain, 0, &count, nullptr));
        std::vector<XrSwapchainImageVulkan2KHR> images(count, XrSwapchainImageVulkan2KHR{XR_TYPE_SWAPCHAIN_IMAGE_VULKAN2_KHR});
        CHECK_XR(xrEnumerateSwapchainImages(eye.swapchain, count, &count,
                                            reinterpret_cast<XrSwapchainImageBaseHeader*>(images.data())));
        for (const auto& img : images) eye.images.push_back(img.image);
    }
}

void Client::render_eye(int eye, std::uint32_t index)
{
    // The image arrives in COLOR_ATTACHMENT_OPTIMAL and must go back in it.
    const VkImage image = eyes_[static_cast<std::size_t>(eye)].images.at(index);
    CHECK_VK(vkResetCommandBuffer(cmd_, 0));
    VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    CHECK_VK(vkBeginCommandBuffer(cmd_, &bi));
    VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    b.srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
    b.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    b.oldLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
    b.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = image;
    b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    vkCmdPipelineBarrier(cmd_, VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr, 0,
                         nullptr, 1, &b);
    vkCmdClearColorImage(cmd_, image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &opt_.eye_colour[static_cast<std::size_t>(eye)],
                         1, &b.subresourceRange);
    b.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    b.dstAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
    b.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    b.newLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
    vkCmdPipelineBarrier(cmd_, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT, 0, 0, nullptr,
                         0, nullptr, 1, &b);
    CHECK_VK(vkEndCommandBuffer(cmd_));
    VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    si.commandBufferCount = 1;
    si.pCommandBuffers = &cmd_;
    CHECK_VK(vkResetFences(vk_device_, 1, &fence_));
    CHECK_VK(vkQueueSubmit(vk_queue_, 1, &si, fence_));
    CHECK_VK(vkWaitForFences(vk_device_, 1, &fence_, VK_TRUE, 10'000'000'000ull));
}

void Client::locate_hands(XrTime t, std::array<HandSample, 2>& out)
{
    for (int h = 0; h < 2; ++h) {
        XrHandJointsLocateInfoEXT li{XR_TYPE_HAND_JOINTS_LOCATE_INFO_EXT};
        li.baseSpace = stage_;
        li.time = t;
        XrHandJointLocationsEXT locs{XR_TYPE_HAND_JOINT_LOCATIONS_EXT};
        locs.jointCount = XR_HAND_JOINT_COUNT_EXT;
        locs.jointLocations = out[static_cast<std::size_t>(h)].joints.data();
        CHECK_XR(locate_joints_(trackers_[static_cast<std::size_t>(h)], &li, &locs));
        out[static_cast<std::size_t>(h)].active = locs.isActive == XR_TRUE;
    }
}

void Client::frame()
{
    XrFrameState fs{XR_TYPE_FRAME_STATE};
    const XrResult wr = xrWaitFrame(session_, nullptr, &fs);
    if (wr == XR_ERROR_SESSION_LOST) {
        lost_ = true;
        return;
    }
    CHECK_XR(wr);
    CHECK_XR(xrBeginFrame(session_, nullptr));
    FrameSample sample;
    sample.time = fs.predictedDisplayTime;

    XrActiveActionSet active{action_set_, XR_NULL_PATH};
    XrActionsSyncInfo sync{XR_TYPE_ACTIONS_SYNC_INFO};
    sync.countActiveActionSets = 1;
    sync.activeActionSets = &active;
    CHECK_XR(xrSyncActions(session_, &sync));
    for (std::size_t h = 0; h < 2; ++h) {
        XrActionStateGetInfo gi{XR_TYPE_ACTION_STATE_GET_INFO};
        gi.action = pose_action_;
        gi.subactionPath = hand_paths_[h];
        XrActionStatePose pose{XR_TYPE_ACTION_STATE_POSE};
        CHECK_XR(xrGetActionStatePose(session_, &gi, &pose));
        out_.pose_action_ever_active = out_.pose_action_ever_active || pose.isActive;
        gi.action = select_action_;
        XrActionStateBoolean select{XR_TYPE_ACTION_STATE_BOOLEAN};
        CHECK_XR(xrGetActionStateBoolean(session_, &gi, &select));
        out_.select_ever_active = out_.select_ever_active || select.isActive;
        XrSpaceLocation loc{XR_TYPE_SPACE_LOCATION};
        CHECK_XR(xrLocateSpace(hand_spaces_[h], stage_, fs.predictedDisplayTime, &loc));
        out_.pose_action_ever_active = out_.pose_action_ever_active || loc.locationFlags != 0;
    }
    if (locate_joints_) {
        locate_hands(fs.predictedDisplayTime, sample.hands);
        if (out_.frames.size() == 3) {
            sample.between.emplace();
            locate_hands(fs.predictedDisplayTime + fs.predictedDisplayPeriod / 2, *sample.between);
        }
    }

    std::vector<XrCompositionLayerBaseHeader*> layers;
    XrCompositionLayerProjection projection{XR_TYPE_COMPOSITION_LAYER_PROJECTION};
    std::array<XrCompositionLayerProjectionView, 2> pviews{};
    if (fs.shouldRender && opt_.vulkan) {
        XrViewLocateInfo vli{XR_TYPE_VIEW_LOCATE_INFO};
        vli.viewConfigurationType = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO;
        vli.displayTime = fs.predictedDisplayTime;
        vli.space = stage_;
        XrViewState vs{XR_TYPE_VIEW_STATE};
        std::array<XrView, 2> views{XrView{XR_TYPE_VIEW}, XrView{XR_TYPE_VIEW}};
        std::uint32_t n = 0;
        CHECK_XR(xrLocateViews(session_, &vli, &vs, 2, &n, views.data()));
        for (int eye = 0; eye < 2; ++eye) {
            Eye& e = eyes_[static_cast<std::size_t>(eye)];
            std::uint32_t index = 0;
            CHECK_XR(xrAcquireSwapchainImage(e.swapchain, nullptr, &index));
            XrSwapchainImageWaitInfo wi{XR_TYPE_SWAPCHAIN_IMAGE_WAIT_INFO};
            wi.timeout = XR_INFINITE_DURATION;
            CHECK_XR(xrWaitSwapchainImage(e.swapchain, &wi));
            render_eye(eye, index);
            CHECK_XR(xrReleaseSwapchainImage(e.swapchain, nullptr));
            auto& pv = pviews[static_cast<std::size_t>(eye)];
            pv = XrCompositionLayerProjectionView{XR_TYPE_COMPOSITION_LAYER_PROJECTION_VIEW};
            pv.pose = views[static_cast<std::size_t>(eye)].pose;
            pv.fov = views[static_cast<std::size_t>(eye)].fov;
            pv.subImage.swapchain = e.swapchain;
            pv.subImage.imageRect = {{0, 0}, {kSize, kSize}};
        }
        projection.space = stage_;
        projection.viewCount = 2;
        projection.views = pviews.data();
        layers.push_back(reinterpret_cast<XrCompositionLayerBaseHeader*>(&projection));
        sample.rendered = true;
    }
    XrFrameEndInfo end{XR_TYPE_FRAME_END_INFO};
    end.displayTime = fs.predictedDisplayTime;
    end.environmentBlendMode = XR_ENVIRONMENT_BLEND_MODE_OPAQUE;
    end.layerCount = static_cast<std::uint32_t>(layers.size());
    end.layers = layers.data();
    CHECK_XR(xrEndFrame(session_, &end));
    out_.frames.push_back(sample);
}

Outcome Client::run()
{
    std::vector<const char*> exts;
    if (opt_.hand_tracking) exts.push_back(XR_EXT_HAND_TRACKING_EXTENSION_NAME);
    exts.push_back(opt_.vulkan ? XR_KHR_VULKAN_ENABLE2_EXTENSION_NAME : XR_MND_HEADLESS_EXTENSION_NAME);
    CHECK_XR(create_instance(exts, &instance_));
    XrSystemGetInfo sgi{XR_TYPE_SYSTEM_GET_INFO};
    sgi.formFactor = XR_FORM_FACTOR_HEAD_MOUNTED_DISPLAY;
    CHECK_XR(xrGetSystem(instance_, &sgi, &system_));
    XrSystemHandTrackingPropertiesEXT htp{XR_TYPE_SYSTEM_HAND_TRACKING_PROPERTIES_EXT};
    XrSystemProperties sp{XR_TYPE_SYSTEM_PROPERTIES};
    sp.next = &htp;
    CHECK_XR(xrGetSystemProperties(instance_, system_, &sp));
    out_.supports_hand_tracking = htp.supportsHandTracking == XR_TRUE;

    // Actions: a pose and a button per hand, bound for the simple controller.
    XrActionSetCreateInfo asci{XR_TYPE_ACTION_SET_CREATE_INFO};
    std::strcpy(asci.actionSetName, "sketching");
    std::strcpy(asci.localizedActionSetName, "Sketching");
    CHECK_XR(xrCreateActionSet(instance_, &asci, &action_set_));
    CHECK_XR(xrStringToPath(instance_, "/user/hand/left", &hand_paths_[0]));
    CHECK_XR(xrStringToPath(instance_, "/user/hand/right", &hand_paths_[1]));
    XrActionCreateInfo aci{XR_TYPE_ACTION_CREATE_INFO};
    aci.actionType = XR_ACTION_TYPE_POSE_INPUT;
    std::strcpy(aci.actionName, "hand_pose");
    std::strcpy(aci.localizedActionName, "Hand pose");
    aci.countSubactionPaths = 2;
    aci.subactionPaths = hand_paths_.data();
    CHECK_XR(xrCreateAction(action_set_, &aci, &pose_action_));
    aci.actionType = XR_ACTION_TYPE_BOOLEAN_INPUT;
    std::strcpy(aci.actionName, "select");
    std::strcpy(aci.localizedActionName, "Select");
    CHECK_XR(xrCreateAction(action_set_, &aci, &select_action_));
    std::vector<XrActionSuggestedBinding> bindings;
    for (const auto& [action, path] : std::vector<std::pair<XrAction, const char*>>{
             {pose_action_, "/user/hand/left/input/grip/pose"},
             {pose_action_, "/user/hand/right/input/grip/pose"},
             {select_action_, "/user/hand/left/input/select/click"},
             {select_action_, "/user/hand/right/input/select/click"}}) {
        XrPath p;
        CHECK_XR(xrStringToPath(instance_, path, &p));
        bindings.push_back({action, p});
    }
    XrInteractionProfileSuggestedBinding suggested{XR_TYPE_INTERACTION_PROFILE_SUGGESTED_BINDING};
    CHECK_XR(xrStringToPath(instance_, "/interaction_profiles/khr/simple_controller", &suggested.interactionProfile));
    suggested.countSuggestedBindings = static_cast<std::uint32_t>(bindings.size());
    suggested.suggestedBindings = bindings.data();
    CHECK_XR(xrSuggestInteractionProfileBindings(instance_, &suggested));

    XrSessionCreateInfo sci{XR_TYPE_SESSION_CREATE_INFO};
    sci.systemId = system_;
    XrGraphicsBindingVulkan2KHR binding{XR_TYPE_GRAPHICS_BINDING_VULKAN2_KHR};
    if (opt_.vulkan) {
        create_vulkan();
        binding.instance = vk_instance_;
        binding.physicalDevice = vk_physical_;
        binding.device = vk_device_;
        binding.queueFamilyIndex = queue_family_;
        binding.queueIndex = 0;
        sci.next = &binding;
    }
    CHECK_XR(xrCreateSession(instance_, &sci, &session_));
    XrReferenceSpaceCreateInfo rsci{XR_TYPE_REFERENCE_SPACE_CREATE_INFO};
    rsci.referenceSpaceType = XR_REFERENCE_SPACE_TYPE_STAGE;
    rsci.poseInReferenceSpace.orientation.w = 1.0f;
    CHECK_XR(xrCreateReferenceSpace(session_, &rsci, &stage_));
    rsci.referenceSpaceType = XR_REFERENCE_SPACE_TYPE_VIEW;
    CHECK_XR(xrCreateReferenceSpace(session_, &rsci, &view_));
    for (std::size_t h = 0; h < 2; ++h) {
        XrActionSpaceCreateInfo ascr{XR_TYPE_ACTION_SPACE_CREATE_INFO};
        ascr.action = pose_action_;
        ascr.subactionPath = hand_paths_[h];
        ascr.poseInActionSpace.orientation.w = 1.0f;
        CHECK_XR(xrCreateActionSpace(session_, &ascr, &hand_spaces_[h]));
    }
    XrSessionActionSetsAttachInfo attach{XR_TYPE_SESSION_ACTION_SETS_ATTACH_INFO};
    attach.countActionSets = 1;
    attach.actionSets = &action_set_;
    CHECK_XR(xrAttachSessionActionSets(session_, &attach));
    if (opt_.hand_tracking) {
        create_tracker_ = proc<PFN_xrCreateHandTrackerEXT>(instance_, "xrCreateHandTrackerEXT");
        destroy_tracker_ = proc<PFN_xrDestroyHandTrackerEXT>(instance_, "xrDestroyHandTrackerEXT");
        locate_joints_ = proc<PFN_xrLocateHandJointsEXT>(instance_, "xrLocateHandJointsEXT");
        for (int h = 0; h < 2; ++h) {
            XrHandTrackerCreateInfoEXT hci{XR_TYPE_HAND_TRACKER_CREATE_INFO_EXT};
            hci.hand = h == 0 ? XR_HAND_LEFT_EXT : XR_HAND_RIGHT_EXT;
            hci.handJointSet = XR_HAND_JOINT_SET_DEFAULT_EXT;
            CHECK_XR(create_tracker_(session_, &hci, &trackers_[static_cast<std::size_t>(h)]));
        }
    }
    if (opt_.vulkan) create_swapchains();

    if (opt_.misuse_checks) {
        expect_refused(xrBeginFrame(session_, nullptr), XR_ERROR_SESSION_NOT_RUNNING, "xrBeginFrame before xrBeginSession");
        expect_refused(xrEndSession(session_), XR_ERROR_SESSION_NOT_RUNNING, "xrEndSession before xrBeginSession");
        expect_refused(xrAttachSessionActionSets(session_, &attach), XR_ERROR_ACTIONSETS_ALREADY_ATTACHED, "second attach");
        XrPath bad;
        expect_refused(xrStringToPath(instance_, "/user//hand", &bad), XR_ERROR_PATH_FORMAT_INVALID, "malformed path");
        XrReferenceSpaceCreateInfo bad_space = rsci;
        bad_space.poseInReferenceSpace.orientation.w = 0.0f;
        XrSpace unused;
        expect_refused(xrCreateReferenceSpace(session_, &bad_space, &unused), XR_ERROR_POSE_INVALID, "zero quaternion");
        XrSpaceLocation loc{XR_TYPE_SPACE_LOCATION};
        expect_refused(xrLocateSpace(view_, stage_, 0, &loc), XR_ERROR_TIME_INVALID, "time 0");
        XrSystemProperties wrong{XR_TYPE_INSTANCE_PROPERTIES};
        expect_refused(xrGetSystemProperties(instance_, system_, &wrong), XR_ERROR_VALIDATION_FAILURE, "wrong structure type");
        PFN_xrVoidFunction fn = nullptr;
        expect_refused(xrGetInstanceProcAddr(instance_, "xrNoSuchFunctionLOBE", &fn), XR_ERROR_FUNCTION_UNSUPPORTED,
                       "unknown function name");
        if (locate_joints_) {
            XrHandJointsLocateInfoEXT li{XR_TYPE_HAND_JOINTS_LOCATE_INFO_EXT};
            li.baseSpace = stage_;
            li.time = 1;
            std::array<XrHandJointLocationEXT, XR_HAND_JOINT_COUNT_EXT> joints{};
            XrHandJointLocationsEXT locs{XR_TYPE_HAND_JOINT_LOCATIONS_EXT};
            locs.jointCount = 25;
            locs.jointLocations = joints.data();
            expect_refused(locate_joints_(trackers_[0], &li, &locs), XR_ERROR_VALIDATION_FAILURE, "25 joints");
            locs.jointCount = XR_HAND_JOINT_COUNT_EXT;
            expect_refused(locate_joints_(reinterpret_cast<XrHandTrackerEXT>(0x1234), &li, &locs), XR_ERROR_HANDLE_INVALID,
                           "made-up hand tracker handle");
        }
    }

    // The event loop: run until the runtime says EXITING (or the session is lost).
    bool exiting = false;
    for (int iteration = 0; iteration < 20000 && !exiting && !lost_; ++iteration) {
        XrEventDataBuffer event{XR_TYPE_EVENT_DATA_BUFFER};
        XrResult pr;
        while ((pr = xrPollEvent(instance_, &event)) == XR_SUCCESS) {
            if (event.type == XR_TYPE_EVENT_DATA_SESSION_STATE_CHANGED) {
                const auto& sc = *reinterpret_cast<XrEventDataSessionStateChanged*>(&event);
                out_.states.push_back(sc.state);
                switch (sc.state) {
                case XR_SESSION_STATE_READY: {
                    XrSessionBeginInfo bi{XR_TYPE_SESSION_BEGIN_INFO};
                    bi.primaryViewConfigurationType = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO;
                    CHECK_XR(xrBeginSession(session_, &bi));
                    running_ = true;
                    break;
                }
                case XR_SESSION_STATE_STOPPING:
                    if (opt_.misuse_checks) {
                        // Frames are still allowed while stopping; ending twice is not.
                        expect_refused(xrBeginFrame(session_, nullptr), XR_ERROR_CALL_ORDER_INVALID,
                                       "xrBeginFrame without xrWaitFrame");
                    }
                    CHECK_XR(xrEndSession(session_));
                    running_ = false;
                    if (opt_.misuse_checks)
                        expect_refused(xrEndSession(session_), XR_ERROR_SESSION_NOT_RUNNING, "second xrEndSession");
                    break;
                case XR_SESSION_STATE_EXITING: exiting = true; break;
                case XR_SESSION_STATE_LOSS_PENDING: lost_ = true; break;
                default: break;
                }
            }
            event = XrEventDataBuffer{XR_TYPE_EVENT_DATA_BUFFER};
        }
        CHECK_XR(pr);
        if (running_ && !exiting && !lost_) frame();
    }
    if (lost_) {
        XrFrameState fs{XR_TYPE_FRAME_STATE};
        out_.wait_after_loss = xrWaitFrame(session_, nullptr, &fs);
    }
    teardown();
    out_.clean_end = exiting;
    return out_;
}

void Client::teardown()
{
    // Children first, the session before the Vulkan device it uses, the instance last.
    for (auto& eye : eyes_)
        if (eye.swapchain) xrDestroySwapchain(std::exchange(eye.swapchain, XR_NULL_HANDLE));
    for (auto& t : trackers_)
        if (t) destroy_tracker_(std::exchange(t, XR_NULL_HANDLE));
    for (auto& s : hand_spaces_)
        if (s) xrDestroySpace(std::exchange(s, XR_NULL_HANDLE));
    if (stage_) xrDestroySpace(std::exchange(stage_, XR_NULL_HANDLE));
    if (view_) xrDestroySpace(std::exchange(view_, XR_NULL_HANDLE));
    if (session_) xrDestroySession(std::exchange(session_, XR_NULL_HANDLE));
    if (action_set_) xrDestroyActionSet(std::exchange(action_set_, XR_NULL_HANDLE));
    if (vk_device_) {
        vkDeviceWaitIdle(vk_device_);
        if (fence_) vkDestroyFence(vk_device_, fence_, nullptr);
        if (pool_) vkDestroyCommandPool(vk_device_, pool_, nullptr);
        vkDestroyDevice(std::exchange(vk_device_, VK_NULL_HANDLE), nullptr);
    }
    if (vk_instance_) vkDestroyInstance(std::exchange(vk_instance_, VK_NULL_HANDLE), nullptr);
    if (instance_) xrDestroyInstance(std::exchange(instance_, XR_NULL_HANDLE));
}

/// recordings/table1-1lobe-5strokes.lrec; empty when it is missing (the test has then failed).
std::string table1_recording()
{
    return lobe::test::source_data("recordings/table1-1lobe-5strokes.lrec");
}

/// A text recording whose hands are never tracked (head only).
std::string untracked_recording(const std::string& dir, int frames)
{
    const std::string path = dir + "/untracked.txt";
    std::ofstream f(path);
    f << "lobesketch-recording-text 1\n"
         "header {\"device\":\"none\",\"nominal_rate_hz\":90.0,\"source\":\"hand-written\",\"space\":\"stage\",\"units\":\"m\"}\n";
    for (int i = 0; i < frames; ++i) f << "frame " << i / 90.0 << " head 0 1.6 0 1 0 0 0 left - right -\n";
    return path;
}

/// A text recording whose left hand is "active" with every joint invalid and at the origin
/// (what some devices send on tracking loss); the right hand is not tracked.
std::string invalid_joints_recording(const std::string& dir, int frames)
{
    const std::string path = dir + "/invalid-joints.txt";
    std::ofstream f(path);
    f << "lobesketch-recording-text 1\n";
    for (int i = 0; i < frames; ++i) {
        f << "frame " << i / 90.0 << " head 0 1.6 0 1 0 0 0 left";
        for (int j = 0; j < XR_HAND_JOINT_COUNT_EXT; ++j) f << " 0 0 0 1 0 0 0 0.01 0";
        f << " right -\n";
    }
    return path;
}

bool contains(const std::vector<XrSessionState>& states, XrSessionState s)
{
    return std::find(states.begin(), states.end(), s) != states.end();
}

} // namespace

TEST(OpenXrReplay, ExportsOnlyTheNegotiationFunction)
{
    void* lib = dlopen(LOBE_XR_REPLAY_LIBRARY, RTLD_NOW | RTLD_LOCAL);
    ASSERT_NE(lib, nullptr) << dlerror();
    EXPECT_NE(dlsym(lib, "xrNegotiateLoaderRuntimeInterface"), nullptr);
    EXPECT_EQ(dlsym(lib, "xrGetInstanceProcAddr"), nullptr);
    EXPECT_EQ(dlsym(lib, "xrCreateInstance"), nullptr);
    // Loaded once and kept (the loader loads it again for every instance).
    dlopen(LOBE_XR_REPLAY_LIBRARY, RTLD_NOW | RTLD_NOLOAD | RTLD_NODELETE);
    dlclose(lib);
}

TEST(OpenXrReplay, ClientRunsToCleanEndWithRecordedHands)
{
    const std::string rec_path = table1_recording();
    if (rec_path.empty()) return;
    const std::string dump = temp_dir("openxr_replay_dump");
    constexpr int kFrames = 24;
    ScopedEnv env = replay_env(rec_path);
    env.set("LOBESKETCH_REPLAY_MAX_FRAMES", std::to_string(kFrames))
        .set("LOBESKETCH_REPLAY_DUMP", dump)
        .set("LOBESKETCH_REPLAY_DUMP_EVERY", "10");
    const std::vector<std::string> exts = instance_extensions();
    EXPECT_TRUE(has(exts, XR_EXT_HAND_TRACKING_EXTENSION_NAME));
    EXPECT_TRUE(has(exts, XR_KHR_VULKAN_ENABLE2_EXTENSION_NAME));
    EXPECT_TRUE(has(exts, XR_MND_HEADLESS_EXTENSION_NAME));

    ClientOptions opt;
    opt.misuse_checks = true;
    Outcome out;
    try {
        out = Client(opt).run();
    } catch (const std::exception& e) {
        FAIL() << e.what();
    }
    EXPECT_TRUE(out.clean_end);
    EXPECT_TRUE(out.misuse_failures.empty()) << out.misuse_failures.front();
    EXPECT_TRUE(out.supports_hand_tracking);
    EXPECT_FALSE(out.pose_action_ever_active); // no controllers
    EXPECT_FALSE(out.select_ever_active);
    // The whole lifecycle, in the specification's order.
    const std::vector<XrSessionState> want = {XR_SESSION_STATE_IDLE,     XR_SESSION_STATE_READY,
                                              XR_SESSION_STATE_SYNCHRONIZED, XR_SESSION_STATE_VISIBLE,
                                              XR_SESSION_STATE_FOCUSED,  XR_SESSION_STATE_VISIBLE,
                                              XR_SESSION_STATE_SYNCHRONIZED, XR_SESSION_STATE_STOPPING,
                                              XR_SESSION_STATE_IDLE,     XR_SESSION_STATE_EXITING};
    EXPECT_EQ(out.states, want);

    // One recorded frame per xrWaitFrame, with the recording's time steps and hands.
    const lobe::Recording rec = lobe::read_recording(rec_path);
    ASSERT_GE(out.frames.size(), static_cast<std::size_t>(kFrames));
    int active_hands = 0;
    for (int k = 0; k < kFrames; ++k) {
        const FrameSample& f = out.frames[static_cast<std::size_t>(k)];
        EXPECT_TRUE(f.rendered) << "frame " << k;
        const double dt = rec.frames[static_cast<std::size_t>(k)].time - rec.frames[0].time;
        EXPECT_NEAR(static_cast<double>(f.time - out.frames[0].time), dt * 1e9, 1.0) << "frame " << k;
        for (int h = 0; h < 2; ++h) {
            const lobe::HandState& want_hand = rec.frames[static_cast<std::size_t>(k)].hands[static_cast<std::size_t>(h)];
            const HandSample& got = f.hands[static_cast<std::size_t>(h)];
            ASSERT_EQ(got.active, want_hand.active) << "frame " << k << " hand " << h;
            active_hands += got.active;
            for (int j = 0; j < XR_HAND_JOINT_COUNT_EXT; ++j) {
                const auto& g = got.joints[static_cast<std::size_t>(j)];
                if (!got.active) {
                    EXPECT_EQ(g.locationFlags, 0u);
                    continue;
                }
                const lobe::JointState& w = want_hand.joints[static_cast<std::size_t>(j)];
                EXPECT_EQ(g.locationFlags, static_cast<XrSpaceLocationFlags>(w.flags & 0xF));
                EXPECT_EQ(g.radius, w.radius);
                EXPECT_NEAR(g.pose.position.x, w.pose.position.x, 1e-6);
                EXPECT_NEAR(g.pose.position.y, w.pose.position.y, 1e-6);
                EXPECT_NEAR(g.pose.position.z, w.pose.position.z, 1e-6);
                EXPECT_NEAR(g.pose.orientation.w, w.pose.orientation.w, 1e-6);
                EXPECT_NEAR(g.pose.orientation.x, w.pose.orientation.x, 1e-6);
            }
        }
        // Between two frames: the last frame not after the time.
        if (f.between) {
            for (int h = 0; h < 2; ++h) {
                EXPECT_EQ((*f.between)[static_cast<std::size_t>(h)].active, f.hands[static_cast<std::size_t>(h)].active);
                EXPECT_EQ((*f.between)[static_cast<std::size_t>(h)].joints[10].pose.position.x,
                          f.hands[static_cast<std::size_t>(h)].joints[10].pose.position.x);
            }
        }
    }
    EXPECT_GT(active_hands, 0) << "the first frames of the recording should show a hand";

    // Eye images of frames 0, 10, 20 (every 10th), in the eyes' clear colours.
    for (int frame : {0, 10, 20}) {
        std::array<std::vector<unsigned char>, 2> pixels;
        for (int eye = 0; eye < 2; ++eye) {
            char name[64];
            std::snprintf(name, sizeof name, "/frame_%06d_eye%d.png", frame, eye);
            const std::string path = dump + name;
            ASSERT_TRUE(std::filesystem::exists(path)) << path;
            EXPECT_GT(std::filesystem::file_size(path), 0u);
            int w = 0, h = 0, c = 0;
            unsigned char* data = stbi_load(path.c_str(), &w, &h, &c, 4);
            ASSERT_NE(data, nullptr) << path;
            EXPECT_EQ(w, 64);
            EXPECT_EQ(h, 64);
            pixels[static_cast<std::size_t>(eye)].assign(data, data + w * h * 4);
            stbi_image_free(data);
        }
        EXPECT_NE(pixels[0], pixels[1]);
        EXPECT_EQ(pixels[0][0], 255); // left eye red
        EXPECT_EQ(pixels[0][2], 0);
        EXPECT_EQ(pixels[1][0], 0); // right eye blue
        EXPECT_EQ(pixels[1][2], 255);
    }
    EXPECT_FALSE(std::filesystem::exists(dump + "/frame_000005_eye0.png"));
}

TEST(OpenXrReplay, UntrackedHandsAreInactiveAndNoError)
{
    const std::string rec = untracked_recording(temp_dir("openxr_replay_untracked"), 12);
    ScopedEnv env = replay_env(rec);
    Outcome out;
    try {
        out = Client(ClientOptions{}).run();
    } catch (const std::exception& e) {
        FAIL() << e.what();
    }
    EXPECT_TRUE(out.clean_end);
    ASSERT_GE(out.frames.size(), 12u);
    for (const FrameSample& f : out.frames)
        for (const HandSample& h : f.hands) {
            EXPECT_FALSE(h.active);
            for (const auto& j : h.joints) EXPECT_EQ(j.locationFlags, 0u);
        }
}

TEST(OpenXrReplay, InvalidJointsAtTheOriginPassAsRecorded)
{
    const std::string rec = invalid_joints_recording(temp_dir("openxr_replay_invalid"), 5);
    ScopedEnv env = replay_env(rec);
    ClientOptions opt;
    opt.vulkan = false;
    Outcome out;
    try {
        out = Client(opt).run();
    } catch (const std::exception& e) {
        FAIL() << e.what();
    }
    EXPECT_TRUE(out.clean_end);
    ASSERT_GE(out.frames.size(), 5u);
    for (const FrameSample& f : out.frames) {
        EXPECT_TRUE(f.hands[0].active);
        EXPECT_FALSE(f.hands[1].active);
        for (const auto& j : f.hands[0].joints) {
            EXPECT_EQ(j.locationFlags, 0u); // the runtime shows what the device sent
            EXPECT_EQ(j.pose.position.x, 0.0f);
            EXPECT_EQ(j.radius, 0.01f);
        }
    }
}

TEST(OpenXrReplay, SessionLossIsReported)
{
    const std::string rec_path = table1_recording();
    if (rec_path.empty()) return;
    ScopedEnv env = replay_env(rec_path);
    env.set("LOBESKETCH_REPLAY_LOSE_SESSION_AT", "5");
    Outcome out;
    try {
        out = Client(ClientOptions{}).run();
    } catch (const std::exception& e) {
        FAIL() << e.what();
    }
    EXPECT_TRUE(contains(out.states, XR_SESSION_STATE_LOSS_PENDING));
    EXPECT_FALSE(contains(out.states, XR_SESSION_STATE_STOPPING));
    EXPECT_EQ(out.wait_after_loss, XR_ERROR_SESSION_LOST);
    EXPECT_EQ(out.frames.size(), 6u); // frames 0 … 5; the loss shows after frame 5
}

TEST(OpenXrReplay, NoHandTrackingSwitch)
{
    const std::string rec_path = table1_recording();
    if (rec_path.empty()) return;
    ScopedEnv env = replay_env(rec_path);
    env.set("LOBESKETCH_REPLAY_NO_HAND_TRACKING", "1").set("LOBESKETCH_REPLAY_MAX_FRAMES", "4");
    EXPECT_FALSE(has(instance_extensions(), XR_EXT_HAND_TRACKING_EXTENSION_NAME));
    XrInstance instance = XR_NULL_HANDLE;
    EXPECT_EQ(create_instance({XR_EXT_HAND_TRACKING_EXTENSION_NAME, XR_KHR_VULKAN_ENABLE2_EXTENSION_NAME}, &instance),
              XR_ERROR_EXTENSION_NOT_PRESENT);
    EXPECT_EQ(instance, XR_NULL_HANDLE);
    // Without it the application still runs, seeing no hands.
    ClientOptions opt;
    opt.hand_tracking = false;
    Outcome out;
    try {
        out = Client(opt).run();
    } catch (const std::exception& e) {
        FAIL() << e.what();
    }
    EXPECT_TRUE(out.clean_end);
    EXPECT_FALSE(out.supports_hand_tracking);
}

TEST(OpenXrReplay, NoVulkanSwitchLeavesHeadless)
{
    const std::string rec_path = table1_recording();
    if (rec_path.empty()) return;
    ScopedEnv env = replay_env(rec_path);
    env.set("LOBESKETCH_REPLAY_NO_VULKAN", "1").set("LOBESKETCH_REPLAY_MAX_FRAMES", "6");
    EXPECT_FALSE(has(instance_extensions(), XR_KHR_VULKAN_ENABLE2_EXTENSION_NAME));
    XrInstance instance = XR_NULL_HANDLE;
    EXPECT_EQ(create_instance({XR_KHR_VULKAN_ENABLE2_EXTENSION_NAME}, &instance), XR_ERROR_EXTENSION_NOT_PRESENT);
    ClientOptions opt;
    opt.vulkan = false; // a headless session (XR_MND_headless) with hand tracking
    Outcome out;
    try {
        out = Client(opt).run();
    } catch (const std::exception& e) {
        FAIL() << e.what();
    }
    EXPECT_TRUE(out.clean_end);
    EXPECT_EQ(out.frames.size(), 7u); // 6 recorded frames, then the xrWaitFrame that finds the end
}

TEST(OpenXrReplay, MissingCorruptOrUnsetRecordingFailsInstanceCreation)
{
    const std::string missing = temp_dir("openxr_replay_missing") + "/nowhere.lrec";
    {
        ScopedEnv env = replay_env(missing);
        XrInstance instance = XR_NULL_HANDLE;
        testing::internal::CaptureStderr();
        const XrResult r = create_instance({}, &instance);
        const std::string err = testing::internal::GetCapturedStderr();
        EXPECT_EQ(r, XR_ERROR_RUNTIME_FAILURE);
        EXPECT_NE(err.find("nowhere.lrec"), std::string::npos) << err;
    }
    {
        const std::string corrupt = temp_dir("openxr_replay_corrupt") + "/garbage.lrec";
        std::ofstream(corrupt) << "not a recording\n";
        ScopedEnv env = replay_env(corrupt);
        XrInstance instance = XR_NULL_HANDLE;
        testing::internal::CaptureStderr();
        const XrResult r = create_instance({}, &instance);
        const std::string err = testing::internal::GetCapturedStderr();
        EXPECT_EQ(r, XR_ERROR_RUNTIME_FAILURE);
        EXPECT_NE(err.find("garbage.lrec"), std::string::npos) << err;
    }
    {
        ScopedEnv env = replay_env(missing);
        env.unset("LOBESKETCH_REPLAY");
        XrInstance instance = XR_NULL_HANDLE;
        testing::internal::CaptureStderr();
        const XrResult r = create_instance({}, &instance);
        const std::string err = testing::internal::GetCapturedStderr();
        EXPECT_EQ(r, XR_ERROR_RUNTIME_FAILURE);
        EXPECT_NE(err.find("LOBESKETCH_REPLAY is not set"), std::string::npos) << err;
    }
}
