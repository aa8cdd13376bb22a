// The OpenXR host of `lobesketch vr` (app/vr/vr_xr.h, docs/vr.md): instance, system, renderer on
// the runtime's Vulkan device, session state machine, swapchains, hand trackers, frame loop.
#include "app/vr/vr_xr.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#define XR_USE_GRAPHICS_API_VULKAN 1
#include <vulkan/vulkan.h>
#include <openxr/openxr.h>
#include <openxr/openxr_platform.h>
#include <openxr/openxr_reflection.h>

#include "app/render/renderer.h"
#include "app/vr/vr_session.h"
#include "app/vr/xr_check.h"
#include "core/hand_frame.h"

// OpenXR and Vulkan structures are written {type} first and filled member by member.
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"

namespace lobe {

namespace {

using Clock = std::chrono::steady_clock;

const char* state_name(XrSessionState s)
{
    switch (s) {
    case XR_SESSION_STATE_IDLE: return "idle";
    case XR_SESSION_STATE_READY: return "ready";
    case XR_SESSION_STATE_SYNCHRONIZED: return "synchronized";
    case XR_SESSION_STATE_VISIBLE: return "visible";
    case XR_SESSION_STATE_FOCUSED: return "focused";
    case XR_SESSION_STATE_STOPPING: return "stopping";
    case XR_SESSION_STATE_LOSS_PENDING: return "loss pending";
    case XR_SESSION_STATE_EXITING: return "exiting";
    default: return "unknown";
    }
}

using xr::failed_call;
using xr::result_name;

// What each refusal tells a person to do (one line each; docs/vr.md says more).
const char* const kRuntimesHint = "e.g. Monado, SteamVR or Meta Quest Link";

std::string no_runtime_message(XrResult r)
{
    const char* json = std::getenv("XR_RUNTIME_JSON");
    std::string where = json && *json ? std::string("XR_RUNTIME_JSON=") + json + " names no runtime that loads"
                                      : "no OpenXR runtime is installed and active";
    return "vr: " + where + " (" + result_name(r) + "): install a runtime (" + kRuntimesHint +
           ") and make it the active one, or set XR_RUNTIME_JSON to a runtime's manifest; XR_LOADER_DEBUG=error "
           "shows the loader's reasons (docs/vr.md)";
}

std::string no_hands_message(const std::string& runtime)
{
    return "vr: the OpenXR runtime" + (runtime.empty() ? std::string() : " '" + runtime + "'") +
           " offers no hand tracking (XR_EXT_hand_tracking): install Ultraleap's OpenXR hand-tracking layer "
           "(Leap Motion), or use Monado, SteamVR with hand tracking enabled, or Meta Quest Link (docs/vr.md)";
}

std::string no_vulkan_message(const std::string& runtime)
{
    return "vr: the OpenXR runtime" + (runtime.empty() ? std::string() : " '" + runtime + "'") +
           " offers no Vulkan rendering (XR_KHR_vulkan_enable2), which lobesketch vr draws with: use " +
           "Monado, SteamVR or Meta Quest Link (docs/vr.md)";
}

std::string version_string(XrVersion v)
{
    return std::to_string(XR_VERSION_MAJOR(v)) + "." + std::to_string(XR_VERSION_MINOR(v)) + "." +
           std::to_string(XR_VERSION_PATCH(v));
}

// SIGINT and SIGTERM while run() runs: counted; the loop asks the runtime to end the session.
std::atomic<int> g_signals{0};
static_assert(std::atomic<int>::is_always_lock_free);

extern "C" void lobe_vr_on_signal(int) { g_signals.fetch_add(1, std::memory_order_relaxed); }

class SignalScope {
public:
    explicit SignalScope(bool install) : installed_(install)
    {
        if (!installed_) return;
        struct sigaction sa {};
        sa.sa_handler = &lobe_vr_on_signal;
        sigemptyset(&sa.sa_mask);
        sigaction(SIGINT, &sa, &old_int_);
        sigaction(SIGTERM, &sa, &old_term_);
    }
    ~SignalScope()
    {
        if (!installed_) return;
        sigaction(SIGINT, &old_int_, nullptr);
        sigaction(SIGTERM, &old_term_, nullptr);
    }
    SignalScope(const SignalScope&) = delete;
    SignalScope& operator=(const SignalScope&) = delete;

private:
    bool installed_;
    struct sigaction old_int_ {}, old_term_ {};
};

bool has_extension(const std::vector<XrExtensionProperties>& exts, const char* name)
{
    return std::any_of(exts.begin(), exts.end(),
                       [&](const XrExtensionProperties& e) { return std::strcmp(e.extensionName, name) == 0; });
}

// How long the loop waits for things that may never come.
constexpr auto kExitGrace = std::chrono::seconds(3);           // after xrRequestExitSession
constexpr XrDuration kImageWaitTimeout = 1'000'000'000;         // one xrWaitSwapchainImage (1 s)
constexpr int kImageWaitTries = 5;                              // then the frame fails
constexpr auto kIdlePoll = std::chrono::milliseconds(5);        // between event polls when not running
constexpr auto kReconnectPoll = std::chrono::milliseconds(250); // between reconnection attempts

HandState hand_state(const std::array<XrHandJointLocationEXT, XR_HAND_JOINT_COUNT_EXT>& joints, bool active)
{
    HandState hs;
    hs.active = active;
    bool any_valid = false, all_origin = true;
    for (int j = 0; j < kJointCount; ++j) {
        const XrHandJointLocationEXT& src = joints[static_cast<std::size_t>(j)];
        JointState& dst = hs.joints[static_cast<std::size_t>(j)];
        dst.pose.position = glm::vec3(src.pose.position.x, src.pose.position.y, src.pose.position.z);
        dst.pose.orientation =
            glm::quat(src.pose.orientation.w, src.pose.orientation.x, src.pose.orientation.y, src.pose.orientation.z);
        dst.radius = src.radius;
        dst.flags = static_cast<std::uint8_t>(src.locationFlags & kAllJointFlags);
        any_valid = any_valid || dst.position_valid();
        all_origin = all_origin && dst.pose.position == glm::vec3(0.0f);
    }
    // A hand the runtime calls active but whose joints are all invalid or all at the origin
    // (tracking just lost on some devices) is not tracked this frame.
    if (hs.active && (!any_valid || all_origin)) hs.active = false;
    return hs;
}

} // namespace

const char* end_name(XrRunResult::End end)
{
    switch (end) {
    case XrRunResult::End::RuntimeExit: return "runtime-exit";
    case XrRunResult::End::Quit: return "quit";
    case XrRunResult::End::Signal: return "signal";
    case XrRunResult::End::Lost: return "lost";
    }
    return "unknown";
}

struct XrHost::Impl {
    XrHostOptions opt;
    std::optional<SignalScope> signals; ///< first: a signal while connecting ends run() at once

    XrInstance instance = XR_NULL_HANDLE;
    XrSystemId system = XR_NULL_SYSTEM_ID;
    std::string runtime_name, system_name;
    XrEnvironmentBlendMode blend = XR_ENVIRONMENT_BLEND_MODE_OPAQUE;
    std::array<XrViewConfigurationView, 2> view_config{};
    std::unique_ptr<Renderer> renderer;
    std::string hook_failure; ///< an OpenXR failure inside a renderer hook

    PFN_xrCreateHandTrackerEXT create_hand_tracker = nullptr;
    PFN_xrDestroyHandTrackerEXT destroy_hand_tracker = nullptr;
    PFN_xrLocateHandJointsEXT locate_hand_joints = nullptr;
    PFN_xrGetVulkanGraphicsRequirements2KHR get_requirements = nullptr;
    PFN_xrCreateVulkanInstanceKHR create_vk_instance = nullptr;
    PFN_xrGetVulkanGraphicsDevice2KHR get_vk_device = nullptr;
    PFN_xrCreateVulkanDeviceKHR create_vk_device = nullptr;

    // One OpenXR session and what hangs off it.
    struct Eye {
        XrSwapchain swapchain = XR_NULL_HANDLE;
        std::vector<VkImage> images;
        std::int32_t width = 0, height = 0;
    };
    XrSession session = XR_NULL_HANDLE;
    XrSpace world = XR_NULL_HANDLE, head = XR_NULL_HANDLE;
    std::array<XrHandTrackerEXT, 2> hands{XR_NULL_HANDLE, XR_NULL_HANDLE};
    std::array<Eye, 2> eyes;
    std::int64_t format = 0;
    XrSessionState state = XR_SESSION_STATE_UNKNOWN;
    bool running = false;      ///< between xrBeginSession and xrEndSession
    bool stage_warned = false;

    // What the loop has seen.
    bool session_lost = false, instance_lost = false, exiting = false;
    bool locate_warned = false;
    std::optional<XrTime> first_time;
    double last_time = -1.0;
    bool rebase_clock = false; ///< a new instance: its times may count from elsewhere
    XrFrameStats stats;

    void message(const std::string& line) const
    {
        if (opt.message) opt.message(line);
    }

    template <class F> F proc(const char* name)
    {
        PFN_xrVoidFunction f = nullptr;
        LOBE_XR_CHECK(xrGetInstanceProcAddr(instance, name, &f));
        return reinterpret_cast<F>(f);
    }

    void connect();
    void create_instance();
    void find_system();
    void make_renderer();
    void disconnect();

    void create_session();
    void destroy_session();
    void create_swapchains();

    /// False (and session_lost / instance_lost set) when `r` says the session or instance
    /// is gone; throws for other failures.
    bool alive(XrResult r, const char* call);
    void poll_events();
    void frame(VrSession& vr);
    HandFrame locate(XrTime t);
    bool reconnect(VrSession& vr);
};

// ---- instance, system, renderer ----------------------------------------------------------------

void XrHost::Impl::create_instance()
{
    // The loader writes several lines of its own for a missing runtime; the refusal below
    // says it in one. XR_LOADER_DEBUG set by the person wins.
    if (!std::getenv("XR_LOADER_DEBUG")) setenv("XR_LOADER_DEBUG", "none", 0);
    std::uint32_t n = 0;
    XrResult r = xrEnumerateInstanceExtensionProperties(nullptr, 0, &n, nullptr);
    if (XR_FAILED(r)) throw XrUnavailable(no_runtime_message(r));
    std::vector<XrExtensionProperties> exts(n, XrExtensionProperties{XR_TYPE_EXTENSION_PROPERTIES});
    r = xrEnumerateInstanceExtensionProperties(nullptr, n, &n, exts.data());
    if (XR_FAILED(r)) throw XrUnavailable(no_runtime_message(r));
    exts.resize(n);
    if (!has_extension(exts, XR_EXT_HAND_TRACKING_EXTENSION_NAME)) throw XrUnavailable(no_hands_message(""));
    if (!has_extension(exts, XR_KHR_VULKAN_ENABLE2_EXTENSION_NAME)) throw XrUnavailable(no_vulkan_message(""));

    const std::array<const char*, 2> enabled{XR_EXT_HAND_TRACKING_EXTENSION_NAME, XR_KHR_VULKAN_ENABLE2_EXTENSION_NAME};
    XrInstanceCreateInfo ci{XR_TYPE_INSTANCE_CREATE_INFO};
    std::strncpy(ci.applicationInfo.applicationName, "Lobesketch", XR_MAX_APPLICATION_NAME_SIZE - 1);
    ci.applicationInfo.applicationVersion = 1;
    std::strncpy(ci.applicationInfo.engineName, "Lobesketch", XR_MAX_ENGINE_NAME_SIZE - 1);
    ci.applicationInfo.engineVersion = 1;
    ci.applicationInfo.apiVersion = XR_MAKE_VERSION(1, 0, 0);
    ci.enabledExtensionCount = static_cast<std::uint32_t>(enabled.size());
    ci.enabledExtensionNames = enabled.data();
    r = xrCreateInstance(&ci, &instance);
    if (r == XR_ERROR_RUNTIME_UNAVAILABLE) throw XrUnavailable(no_runtime_message(r));
    if (r == XR_ERROR_RUNTIME_FAILURE || r == XR_ERROR_INSTANCE_LOST)
        throw XrUnavailable(std::string("vr: the OpenXR runtime could not start (") + result_name(r) +
                            "): see its message above, or check that its service is running (docs/vr.md)");
    if (r == XR_ERROR_EXTENSION_NOT_PRESENT) throw XrUnavailable(no_hands_message(""));
    if (XR_FAILED(r)) {
        instance = XR_NULL_HANDLE;
        throw XrFailure(failed_call("xrCreateInstance", r));
    }
    XrInstanceProperties ip{XR_TYPE_INSTANCE_PROPERTIES};
    LOBE_XR_CHECK(xrGetInstanceProperties(instance, &ip));
    runtime_name = std::string("openxr:") + ip.runtimeName + " " + version_string(ip.runtimeVersion);

    create_hand_tracker = proc<PFN_xrCreateHandTrackerEXT>("xrCreateHandTrackerEXT");
    destroy_hand_tracker = proc<PFN_xrDestroyHandTrackerEXT>("xrDestroyHandTrackerEXT");
    locate_hand_joints = proc<PFN_xrLocateHandJointsEXT>("xrLocateHandJointsEXT");
    get_requirements = proc<PFN_xrGetVulkanGraphicsRequirements2KHR>("xrGetVulkanGraphicsRequirements2KHR");
    create_vk_instance = proc<PFN_xrCreateVulkanInstanceKHR>("xrCreateVulkanInstanceKHR");
    get_vk_device = proc<PFN_xrGetVulkanGraphicsDevice2KHR>("xrGetVulkanGraphicsDevice2KHR");
    create_vk_device = proc<PFN_xrCreateVulkanDeviceKHR>("xrCreateVulkanDeviceKHR");
}

void XrHost::Impl::find_system()
{
    XrSystemGetInfo sgi{XR_TYPE_SYSTEM_GET_INFO};
    sgi.formFactor = XR_FORM_FACTOR_HEAD_MOUNTED_DISPLAY;
    const XrResult r = xrGetSystem(instance, &sgi, &system);
    if (r == XR_ERROR_FORM_FACTOR_UNAVAILABLE)
        throw XrUnavailable("vr: no headset is connected to '" + runtime_name +
                            "' (XR_ERROR_FORM_FACTOR_UNAVAILABLE): connect and switch on the headset, then start again");
    if (r == XR_ERROR_FORM_FACTOR_UNSUPPORTED)
        throw XrUnavailable("vr: the OpenXR runtime '" + runtime_name +
                            "' drives no head-mounted display: use a headset runtime (" + kRuntimesHint + ")");
    xr::check(r, "xrGetSystem", __FILE__, __LINE__);

    XrSystemHandTrackingPropertiesEXT htp{XR_TYPE_SYSTEM_HAND_TRACKING_PROPERTIES_EXT};
    XrSystemProperties sp{XR_TYPE_SYSTEM_PROPERTIES};
    sp.next = &htp;
    LOBE_XR_CHECK(xrGetSystemProperties(instance, system, &sp));
    system_name = sp.systemName;
    if (htp.supportsHandTracking != XR_TRUE) throw XrUnavailable(no_hands_message(runtime_name));

    std::uint32_t n = 0;
    LOBE_XR_CHECK(xrEnumerateViewConfigurations(instance, system, 0, &n, nullptr));
    std::vector<XrViewConfigurationType> configs(n);
    LOBE_XR_CHECK(xrEnumerateViewConfigurations(instance, system, n, &n, configs.data()));
    if (std::find(configs.begin(), configs.begin() + n, XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO) == configs.begin() + n)
        throw XrUnavailable("vr: '" + system_name + "' has no stereo view configuration (PRIMARY_STEREO)");
    std::uint32_t views = 0;
    LOBE_XR_CHECK(xrEnumerateViewConfigurationViews(instance, system, XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO, 0,
                                                    &views, nullptr));
    if (views != 2) throw XrFailure("OpenXR: PRIMARY_STEREO of '" + system_name + "' has " + std::to_string(views) + " views");
    view_config.fill(XrViewConfigurationView{XR_TYPE_VIEW_CONFIGURATION_VIEW});
    LOBE_XR_CHECK(xrEnumerateViewConfigurationViews(instance, system, XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO, 2,
                                                    &views, view_config.data()));

    LOBE_XR_CHECK(xrEnumerateEnvironmentBlendModes(instance, system, XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO, 0, &n,
                                                   nullptr));
    std::vector<XrEnvironmentBlendMode> modes(n);
    LOBE_XR_CHECK(xrEnumerateEnvironmentBlendModes(instance, system, XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO, n, &n,
                                                   modes.data()));
    modes.resize(n);
    if (modes.empty()) throw XrFailure("OpenXR: '" + system_name + "' offers no environment blend mode");
    blend = std::find(modes.begin(), modes.end(), XR_ENVIRONMENT_BLEND_MODE_OPAQUE) != modes.end()
                ? XR_ENVIRONMENT_BLEND_MODE_OPAQUE
                : modes.front();
}

void XrHost::Impl::make_renderer()
{
    // Required before the Vulkan instance and the session (XR_KHR_vulkan_enable2).
    XrGraphicsRequirementsVulkan2KHR req{XR_TYPE_GRAPHICS_REQUIREMENTS_VULKAN2_KHR};
    LOBE_XR_CHECK(get_requirements(instance, system, &req));
    // The renderer asks for Vulkan 1.1.
    const XrVersion ours = XR_MAKE_VERSION(1, 1, 0);
    if (XR_MAKE_VERSION(XR_VERSION_MAJOR(req.minApiVersionSupported), XR_VERSION_MINOR(req.minApiVersionSupported), 0) > ours)
        message("vr: '" + runtime_name + "' asks for Vulkan " + version_string(req.minApiVersionSupported) +
                " or newer; the renderer uses 1.1 (it may fail)");

    RendererOptions ro;
    ro.samples = opt.samples;
    hook_failure.clear();
    ro.vulkan_hooks.create_instance = [this](const void* info, int& vk_result) -> std::uint64_t {
        XrVulkanInstanceCreateInfoKHR ci{XR_TYPE_VULKAN_INSTANCE_CREATE_INFO_KHR};
        ci.systemId = system;
        ci.pfnGetInstanceProcAddr = &vkGetInstanceProcAddr;
        ci.vulkanCreateInfo = static_cast<const VkInstanceCreateInfo*>(info);
        VkInstance vk = VK_NULL_HANDLE;
        VkResult vr = VK_SUCCESS;
        const XrResult r = create_vk_instance(instance, &ci, &vk, &vr);
        if (XR_FAILED(r)) {
            hook_failure = failed_call("xrCreateVulkanInstanceKHR", r);
            vk_result = VK_ERROR_INITIALIZATION_FAILED;
            return 0;
        }
        vk_result = vr;
        return vr == VK_SUCCESS ? reinterpret_cast<std::uint64_t>(vk) : 0;
    };
    ro.vulkan_hooks.physical_device = [this](std::uint64_t vk_instance) -> std::uint64_t {
        XrVulkanGraphicsDeviceGetInfoKHR gi{XR_TYPE_VULKAN_GRAPHICS_DEVICE_GET_INFO_KHR};
        gi.systemId = system;
        gi.vulkanInstance = reinterpret_cast<VkInstance>(vk_instance);
        VkPhysicalDevice pd = VK_NULL_HANDLE;
        const XrResult r = get_vk_device(instance, &gi, &pd);
        if (XR_FAILED(r)) {
            hook_failure = failed_call("xrGetVulkanGraphicsDevice2KHR", r);
            return 0;
        }
        return reinterpret_cast<std::uint64_t>(pd);
    };
    ro.vulkan_hooks.create_device = [this](std::uint64_t physical, const void* info, int& vk_result) -> std::uint64_t {
        XrVulkanDeviceCreateInfoKHR ci{XR_TYPE_VULKAN_DEVICE_CREATE_INFO_KHR};
        ci.systemId = system;
        ci.pfnGetInstanceProcAddr = &vkGetInstanceProcAddr;
        ci.vulkanPhysicalDevice = reinterpret_cast<VkPhysicalDevice>(physical);
        ci.vulkanCreateInfo = static_cast<const VkDeviceCreateInfo*>(info);
        VkDevice dev = VK_NULL_HANDLE;
        VkResult vr = VK_SUCCESS;
        const XrResult r = create_vk_device(instance, &ci, &dev, &vr);
        if (XR_FAILED(r)) {
            hook_failure = failed_call("xrCreateVulkanDeviceKHR", r);
            vk_result = VK_ERROR_INITIALIZATION_FAILED;
            return 0;
        }
        vk_result = vr;
        return vr == VK_SUCCESS ? reinterpret_cast<std::uint64_t>(dev) : 0;
    };
    try {
        renderer = std::make_unique<Renderer>(ro);
    } catch (const RenderError& e) {
        if (!hook_failure.empty()) throw XrFailure(hook_failure + " while making the renderer (" + e.what() + ")");
        throw;
    }
}

void XrHost::Impl::connect()
{
    try {
        create_instance();
        find_system();
        make_renderer();
    } catch (...) {
        disconnect();
        throw;
    }
}

void XrHost::Impl::disconnect()
{
    destroy_session();
    renderer.reset(); // the VkDevice and VkInstance the runtime made, before the XrInstance
    if (instance != XR_NULL_HANDLE) xrDestroyInstance(instance);
    instance = XR_NULL_HANDLE;
    system = XR_NULL_SYSTEM_ID;
}

// ---- session -----------------------------------------------------------------------------------

void XrHost::Impl::create_session()
{
    const VulkanHandles vk = renderer->vulkan_handles();
    XrGraphicsBindingVulkan2KHR binding{XR_TYPE_GRAPHICS_BINDING_VULKAN2_KHR};
    binding.instance = reinterpret_cast<VkInstance>(vk.instance);
    binding.physicalDevice = reinterpret_cast<VkPhysicalDevice>(vk.physical_device);
    binding.device = reinterpret_cast<VkDevice>(vk.device);
    binding.queueFamilyIndex = vk.queue_family;
    binding.queueIndex = vk.queue_index;
    XrSessionCreateInfo sci{XR_TYPE_SESSION_CREATE_INFO};
    sci.next = &binding;
    sci.systemId = system;
    LOBE_XR_CHECK(xrCreateSession(instance, &sci, &session));
    state = XR_SESSION_STATE_UNKNOWN;
    running = false;
    session_lost = false;
    exiting = false;

    try {
        std::uint32_t n = 0;
        LOBE_XR_CHECK(xrEnumerateReferenceSpaces(session, 0, &n, nullptr));
        std::vector<XrReferenceSpaceType> spaces(n);
        LOBE_XR_CHECK(xrEnumerateReferenceSpaces(session, n, &n, spaces.data()));
        spaces.resize(n);
        const bool has_stage = std::find(spaces.begin(), spaces.end(), XR_REFERENCE_SPACE_TYPE_STAGE) != spaces.end();
        if (!has_stage && !stage_warned) {
            message("vr: '" + system_name + "' has no STAGE space (no play area set up?): using LOCAL, so the floor "
                    "is not at y = 0 and sessions drawn in it sit where the headset started");
            stage_warned = true;
        }
        XrReferenceSpaceCreateInfo rsci{XR_TYPE_REFERENCE_SPACE_CREATE_INFO};
        rsci.poseInReferenceSpace.orientation.w = 1.0f;
        rsci.referenceSpaceType = has_stage ? XR_REFERENCE_SPACE_TYPE_STAGE : XR_REFERENCE_SPACE_TYPE_LOCAL;
        LOBE_XR_CHECK(xrCreateReferenceSpace(session, &rsci, &world));
        rsci.referenceSpaceType = XR_REFERENCE_SPACE_TYPE_VIEW;
        LOBE_XR_CHECK(xrCreateReferenceSpace(session, &rsci, &head));

        create_swapchains();

        for (int h = 0; h < 2; ++h) {
            XrHandTrackerCreateInfoEXT hci{XR_TYPE_HAND_TRACKER_CREATE_INFO_EXT};
            hci.hand = h == 0 ? XR_HAND_LEFT_EXT : XR_HAND_RIGHT_EXT;
            hci.handJointSet = XR_HAND_JOINT_SET_DEFAULT_EXT;
            LOBE_XR_CHECK(create_hand_tracker(session, &hci, &hands[static_cast<std::size_t>(h)]));
        }
    } catch (...) {
        destroy_session();
        throw;
    }
}

void XrHost::Impl::create_swapchains()
{
    std::uint32_t n = 0;
    LOBE_XR_CHECK(xrEnumerateSwapchainFormats(session, 0, &n, nullptr));
    std::vector<std::int64_t> formats(n);
    LOBE_XR_CHECK(xrEnumerateSwapchainFormats(session, n, &n, formats.data()));
    formats.resize(n);
    // The runtime's order is its preference: the first sRGB format the renderer can draw
    // into, else the first UNORM one.
    const auto ours = [](std::int64_t f, bool srgb) {
        return srgb ? (f == VK_FORMAT_R8G8B8A8_SRGB || f == VK_FORMAT_B8G8R8A8_SRGB)
                    : (f == VK_FORMAT_R8G8B8A8_UNORM || f == VK_FORMAT_B8G8R8A8_UNORM);
    };
    format = 0;
    for (bool srgb : {true, false})
        for (std::int64_t f : formats)
            if (!format && ours(f, srgb)) format = f;
    if (!format)
        throw XrFailure("OpenXR: '" + runtime_name + "' offers no 8-bit RGBA or BGRA colour swapchain format (" +
                        std::to_string(formats.size()) + " formats offered)");

    for (std::size_t e = 0; e < 2; ++e) {
        const XrViewConfigurationView& vc = view_config[e];
        std::int32_t w = static_cast<std::int32_t>(std::max<std::uint32_t>(1, vc.recommendedImageRectWidth));
        std::int32_t h = static_cast<std::int32_t>(std::max<std::uint32_t>(1, vc.recommendedImageRectHeight));
        if (vc.maxImageRectWidth > 0) w = std::min(w, static_cast<std::int32_t>(vc.maxImageRectWidth));
        if (vc.maxImageRectHeight > 0) h = std::min(h, static_cast<std::int32_t>(vc.maxImageRectHeight));
        if (opt.max_view_size > 0 && std::max(w, h) > opt.max_view_size) {
            const double s = double(opt.max_view_size) / double(std::max(w, h));
            w = std::max(1, static_cast<std::int32_t>(std::lround(w * s)));
            h = std::max(1, static_cast<std::int32_t>(std::lround(h * s)));
        }
        XrSwapchainCreateInfo sci{XR_TYPE_SWAPCHAIN_CREATE_INFO};
        sci.usageFlags = XR_SWAPCHAIN_USAGE_COLOR_ATTACHMENT_BIT | XR_SWAPCHAIN_USAGE_TRANSFER_DST_BIT;
        sci.format = format;
        sci.sampleCount = 1;
        sci.width = static_cast<std::uint32_t>(w);
        sci.height = static_cast<std::uint32_t>(h);
        sci.faceCount = 1;
        sci.arraySize = 1;
        sci.mipCount = 1;
        Eye& eye = eyes[e];
        LOBE_XR_CHECK(xrCreateSwapchain(session, &sci, &eye.swapchain));
        eye.width = w;
        eye.height = h;
        std::uint32_t count = 0;
        LOBE_XR_CHECK(xrEnumerateSwapchainImages(eye.swapchain, 0, &count, nullptr));
        std::vector<XrSwapchainImageVulkan2KHR> images(count, XrSwapchainImageVulkan2KHR{XR_TYPE_SWAPCHAIN_IMAGE_VULKAN2_KHR});
        LOBE_XR_CHECK(xrEnumerateSwapchainImages(eye.swapchain, count, &count,
                                                 reinterpret_cast<XrSwapchainImageBaseHeader*>(images.data())));
        eye.images.clear();
        for (std::uint32_t i = 0; i < count; ++i) eye.images.push_back(images[i].image);
    }
}

void XrHost::Impl::destroy_session()
{
    // Children first; every call here is allowed on a lost session.
    for (XrHandTrackerEXT& h : hands) {
        if (h != XR_NULL_HANDLE && destroy_hand_tracker) destroy_hand_tracker(h);
        h = XR_NULL_HANDLE;
    }
    for (Eye& e : eyes) {
        if (e.swapchain != XR_NULL_HANDLE) xrDestroySwapchain(e.swapchain);
        e = Eye{};
    }
    for (XrSpace* s : {&world, &head}) {
        if (*s != XR_NULL_HANDLE) xrDestroySpace(*s);
        *s = XR_NULL_HANDLE;
    }
    if (session != XR_NULL_HANDLE) xrDestroySession(session);
    session = XR_NULL_HANDLE;
    running = false;
    state = XR_SESSION_STATE_UNKNOWN;
}

bool XrHost::Impl::alive(XrResult r, const char* call)
{
    if (r == XR_ERROR_SESSION_LOST) {
        session_lost = true;
        return false;
    }
    if (r == XR_ERROR_INSTANCE_LOST) {
        instance_lost = true;
        return false;
    }
    xr::check(r, call, __FILE__, __LINE__);
    return true;
}

void XrHost::Impl::poll_events()
{
    for (int guard = 0; guard < 256 && instance != XR_NULL_HANDLE; ++guard) {
        XrEventDataBuffer ev{XR_TYPE_EVENT_DATA_BUFFER};
        const XrResult r = xrPollEvent(instance, &ev);
        if (r == XR_EVENT_UNAVAILABLE) return;
        if (!alive(r, "xrPollEvent")) return;
        switch (ev.type) {
        case XR_TYPE_EVENT_DATA_INSTANCE_LOSS_PENDING: instance_lost = true; break;
        case XR_TYPE_EVENT_DATA_EVENTS_LOST:
            message("vr: the runtime dropped " +
                    std::to_string(reinterpret_cast<const XrEventDataEventsLost&>(ev).lostEventCount) + " event(s)");
            break;
        case XR_TYPE_EVENT_DATA_SESSION_STATE_CHANGED: {
            const auto& sc = reinterpret_cast<const XrEventDataSessionStateChanged&>(ev);
            if (sc.session != session) break;
            state = sc.state;
            switch (sc.state) {
            case XR_SESSION_STATE_READY: {
                XrSessionBeginInfo bi{XR_TYPE_SESSION_BEGIN_INFO};
                bi.primaryViewConfigurationType = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO;
                if (!alive(xrBeginSession(session, &bi), "xrBeginSession")) return;
                running = true;
                break;
            }
            case XR_SESSION_STATE_STOPPING:
                running = false;
                if (!alive(xrEndSession(session), "xrEndSession")) return;
                break;
            case XR_SESSION_STATE_LOSS_PENDING: session_lost = true; break;
            case XR_SESSION_STATE_EXITING: exiting = true; break;
            default: break;
            }
            break;
        }
        default: break; // reference space changes, interaction profiles: nothing to do
        }
    }
}

HandFrame XrHost::Impl::locate(XrTime t)
{
    HandFrame f;
    XrSpaceLocation loc{XR_TYPE_SPACE_LOCATION};
    XrResult r = xrLocateSpace(head, world, t, &loc);
    if (!alive(r, "xrLocateSpace")) return f;
    const XrSpaceLocationFlags both = XR_SPACE_LOCATION_ORIENTATION_VALID_BIT | XR_SPACE_LOCATION_POSITION_VALID_BIT;
    f.head_valid = (loc.locationFlags & both) == both;
    if (f.head_valid) {
        f.head.position = glm::vec3(loc.pose.position.x, loc.pose.position.y, loc.pose.position.z);
        f.head.orientation = glm::quat(loc.pose.orientation.w, loc.pose.orientation.x, loc.pose.orientation.y,
                                       loc.pose.orientation.z);
    }
    for (std::size_t h = 0; h < 2; ++h) {
        std::array<XrHandJointLocationEXT, XR_HAND_JOINT_COUNT_EXT> joints{};
        XrHandJointsLocateInfoEXT li{XR_TYPE_HAND_JOINTS_LOCATE_INFO_EXT};
        li.baseSpace = world;
        li.time = t;
        XrHandJointLocationsEXT locs{XR_TYPE_HAND_JOINT_LOCATIONS_EXT};
        locs.jointCount = XR_HAND_JOINT_COUNT_EXT;
        locs.jointLocations = joints.data();
        r = locate_hand_joints(hands[h], &li, &locs);
        if (r == XR_ERROR_SESSION_LOST || r == XR_ERROR_INSTANCE_LOST) {
            alive(r, "xrLocateHandJointsEXT");
            return f;
        }
        if (XR_FAILED(r)) {
            // One hand that cannot be located is a hand not tracked, not the end of the session.
            if (!locate_warned) message("vr: " + failed_call("xrLocateHandJointsEXT", r) + "; the hand counts as not tracked");
            locate_warned = true;
            continue;
        }
        f.hands[h] = hand_state(joints, locs.isActive == XR_TRUE);
    }
    return f;
}

void XrHost::Impl::frame(VrSession& vr)
{
    XrFrameState fs{XR_TYPE_FRAME_STATE};
    if (!alive(xrWaitFrame(session, nullptr, &fs), "xrWaitFrame")) return;
    if (!alive(xrBeginFrame(session, nullptr), "xrBeginFrame")) return;

    std::array<XrCompositionLayerProjectionView, 2> pviews{};
    XrCompositionLayerProjection projection{XR_TYPE_COMPOSITION_LAYER_PROJECTION};
    std::vector<XrCompositionLayerBaseHeader*> layers;
    if (fs.shouldRender == XR_TRUE) {
        HandFrame hf = locate(fs.predictedDisplayTime);
        if (session_lost || instance_lost) return;
        if (!first_time) first_time = fs.predictedDisplayTime;
        if (rebase_clock) {
            // The session's clock goes on one frame after where the lost instance left it.
            const double step = fs.predictedDisplayPeriod > 0 ? double(fs.predictedDisplayPeriod) * 1e-9 : 1.0 / 90.0;
            first_time = last_time < 0.0 ? fs.predictedDisplayTime
                                         : fs.predictedDisplayTime -
                                               static_cast<XrTime>(std::llround((last_time + step) * 1e9));
            rebase_clock = false;
        }
        const double t = double(fs.predictedDisplayTime - *first_time) / 1e9;
        // The session's clock only moves forwards (a runtime may repeat a display time).
        if (t > last_time) {
            hf.time = t;
            vr.frame(hf);
            last_time = t;
            ++stats.frames;
            stats.time = t;
            renderer->set_scene(vr.scene());
        }

        XrViewLocateInfo vli{XR_TYPE_VIEW_LOCATE_INFO};
        vli.viewConfigurationType = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO;
        vli.displayTime = fs.predictedDisplayTime;
        vli.space = world;
        XrViewState vs{XR_TYPE_VIEW_STATE};
        std::array<XrView, 2> views{XrView{XR_TYPE_VIEW}, XrView{XR_TYPE_VIEW}};
        std::uint32_t n = 0;
        if (!alive(xrLocateViews(session, &vli, &vs, 2, &n, views.data()), "xrLocateViews")) return;
        const XrViewStateFlags needed = XR_VIEW_STATE_ORIENTATION_VALID_BIT | XR_VIEW_STATE_POSITION_VALID_BIT;
        if (n == 2 && (vs.viewStateFlags & needed) == needed) {
            for (std::size_t e = 0; e < 2; ++e) {
                Eye& eye = eyes[e];
                std::uint32_t index = 0;
                if (!alive(xrAcquireSwapchainImage(eye.swapchain, nullptr, &index), "xrAcquireSwapchainImage")) return;
                XrSwapchainImageWaitInfo wi{XR_TYPE_SWAPCHAIN_IMAGE_WAIT_INFO};
                wi.timeout = kImageWaitTimeout;
                XrResult wr = XR_TIMEOUT_EXPIRED;
                for (int tries = 0; tries < kImageWaitTries && wr == XR_TIMEOUT_EXPIRED; ++tries)
                    wr = xrWaitSwapchainImage(eye.swapchain, &wi);
                if (!alive(wr, "xrWaitSwapchainImage")) return;
                if (wr == XR_TIMEOUT_EXPIRED)
                    throw XrFailure("OpenXR: a swapchain image did not become ready in " +
                                    std::to_string(kImageWaitTries) + " s");
                const XrView& v = views[e];
                EyeView ev;
                ev.position = glm::vec3(v.pose.position.x, v.pose.position.y, v.pose.position.z);
                ev.orientation = glm::quat(v.pose.orientation.w, v.pose.orientation.x, v.pose.orientation.y,
                                           v.pose.orientation.z);
                ev.angle_left = v.fov.angleLeft;
                ev.angle_right = v.fov.angleRight;
                ev.angle_up = v.fov.angleUp;
                ev.angle_down = v.fov.angleDown;
                ExternalImage target;
                target.vk_image = reinterpret_cast<std::uint64_t>(eye.images.at(index));
                target.vk_format = static_cast<int>(format);
                target.width = eye.width;
                target.height = eye.height;
                renderer->render_to(vr.eye_in_document(ev), target);
                if (!alive(xrReleaseSwapchainImage(eye.swapchain, nullptr), "xrReleaseSwapchainImage")) return;
                XrCompositionLayerProjectionView& pv = pviews[e];
                pv = XrCompositionLayerProjectionView{XR_TYPE_COMPOSITION_LAYER_PROJECTION_VIEW};
                pv.pose = v.pose;
                pv.fov = v.fov;
                pv.subImage.swapchain = eye.swapchain;
                pv.subImage.imageRect = {{0, 0}, {eye.width, eye.height}};
                pv.subImage.imageArrayIndex = 0;
            }
            projection.space = world;
            projection.viewCount = 2;
            projection.views = pviews.data();
            layers.push_back(reinterpret_cast<XrCompositionLayerBaseHeader*>(&projection));
            ++stats.rendered;
        }
    }
    XrFrameEndInfo end{XR_TYPE_FRAME_END_INFO};
    end.displayTime = fs.predictedDisplayTime;
    end.environmentBlendMode = blend;
    end.layerCount = static_cast<std::uint32_t>(layers.size());
    end.layers = layers.data();
    alive(xrEndFrame(session, &end), "xrEndFrame");
}

bool XrHost::Impl::reconnect(VrSession& vr)
{
    const bool whole_instance = instance_lost;
    // What was made so far is kept before anything else is tried.
    const bool saved = vr.save();
    message(std::string("vr: the OpenXR ") + (whole_instance ? "runtime" : "session") +
            " was lost (headset unplugged or runtime stopped?)" +
            (saved ? "; the session is saved" : "; the session could not be saved: " +
                                                     (vr.messages().empty() ? std::string("no session file")
                                                                            : vr.messages().back())));
    destroy_session();
    if (whole_instance) {
        disconnect();
        rebase_clock = true;
    }
    session_lost = instance_lost = false;
    if (opt.reconnect_seconds <= 0.0) return false;

    message("vr: waiting up to " + std::to_string(int(std::ceil(opt.reconnect_seconds))) + " s for the headset to come back");
    const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                             std::chrono::duration<double>(opt.reconnect_seconds));
    std::string last_error;
    while (Clock::now() < deadline && g_signals.load() == 0) {
        try {
            if (instance == XR_NULL_HANDLE) {
                connect();
            } else {
                // The same headset again: the session goes on with the same renderer.
                XrSystemGetInfo sgi{XR_TYPE_SYSTEM_GET_INFO};
                sgi.formFactor = XR_FORM_FACTOR_HEAD_MOUNTED_DISPLAY;
                XrSystemId again = XR_NULL_SYSTEM_ID;
                const XrResult r = xrGetSystem(instance, &sgi, &again);
                if (r == XR_ERROR_INSTANCE_LOST) {
                    disconnect();
                    rebase_clock = true;
                    continue;
                }
                xr::check(r, "xrGetSystem", __FILE__, __LINE__);
                if (again != system) {
                    disconnect(); // another system: everything is made anew
                    rebase_clock = true;
                    connect();
                }
            }
            create_session();
            message("vr: the headset is back; the session goes on");
            return true;
        } catch (const Error& e) {
            last_error = e.what();
        }
        std::this_thread::sleep_for(kReconnectPoll);
    }
    if (!last_error.empty()) message("vr: last reconnection attempt: " + last_error);
    return false;
}

// ---- XrHost ------------------------------------------------------------------------------------

XrHost::XrHost(XrHostOptions options) : impl_(std::make_unique<Impl>())
{
    impl_->opt = std::move(options);
    g_signals.store(0);
    impl_->signals.emplace(impl_->opt.handle_signals);
    impl_->connect();
}

XrHost::~XrHost()
{
    if (impl_) impl_->disconnect();
}

const std::string& XrHost::runtime_name() const { return impl_->runtime_name; }
const std::string& XrHost::system_name() const { return impl_->system_name; }
Renderer& XrHost::renderer() { return *impl_->renderer; }
double XrHost::last_time() const { return std::max(0.0, impl_->last_time); }

XrRunResult XrHost::run(VrSession& vr)
{
    Impl& m = *impl_;
    XrRunResult result;
    auto finish = [&](XrRunResult::End end, std::string why) {
        result.end = end;
        result.message = std::move(why);
        result.last_time = std::max(0.0, m.last_time);
        result.frames = m.stats.frames;
        result.rendered = m.stats.rendered;
        return result;
    };

    if (m.instance == XR_NULL_HANDLE) m.connect();
    if (m.session == XR_NULL_HANDLE) m.create_session();
    ++result.sessions;

    bool exit_requested = false, nothing_to_stop = false;
    XrRunResult::End requested_end = XrRunResult::End::RuntimeExit;
    Clock::time_point exit_requested_at{};
    auto status_at = Clock::now();
    std::uint64_t status_frames = m.stats.frames;
    auto request_exit = [&](XrRunResult::End why) {
        if (exit_requested) return;
        exit_requested = true;
        requested_end = why;
        exit_requested_at = Clock::now();
        nothing_to_stop = !m.running;
        if (m.running) m.alive(xrRequestExitSession(m.session), "xrRequestExitSession");
    };

    for (;;) {
        const int signalled = g_signals.load();
        if (signalled > 0) request_exit(XrRunResult::End::Signal);
        if (exit_requested && (nothing_to_stop || signalled > 1 || Clock::now() - exit_requested_at > kExitGrace)) {
            // Nothing to stop, a second signal, or a runtime that does not end the session
            // (else the runtime goes through STOPPING to EXITING, below).
            m.destroy_session();
            return finish(requested_end, requested_end == XrRunResult::End::Signal ? "vr: stopped by a signal"
                                                                                   : "vr: quit");
        }

        m.poll_events();
        if (m.session_lost || m.instance_lost) {
            if (!m.reconnect(vr))
                return finish(XrRunResult::End::Lost,
                              m.opt.reconnect_seconds > 0.0
                                  ? "vr: the headset did not come back within " +
                                        std::to_string(int(std::ceil(m.opt.reconnect_seconds))) + " s; ending"
                                  : "vr: the OpenXR session was lost; ending (--reconnect-seconds 0)");
            ++result.sessions;
            continue;
        }
        if (m.exiting) {
            m.destroy_session();
            if (exit_requested)
                return finish(requested_end, requested_end == XrRunResult::End::Signal ? "vr: stopped by a signal"
                                                                                       : "vr: quit");
            return finish(XrRunResult::End::RuntimeExit, "vr: the runtime ended the session");
        }
        if (!m.running) {
            std::this_thread::sleep_for(kIdlePoll);
            continue;
        }

        m.frame(vr);
        if (vr.quit_requested()) request_exit(XrRunResult::End::Quit);

        const auto now = Clock::now();
        if (now - status_at >= std::chrono::seconds(1)) {
            const double secs = std::chrono::duration<double>(now - status_at).count();
            const std::uint64_t n = m.stats.frames - status_frames;
            m.stats.frame_ms = n ? secs * 1000.0 / double(n) : 0.0;
            m.stats.state = state_name(m.state);
            if (m.opt.status) m.opt.status(vr, m.stats);
            status_at = now;
            status_frames = m.stats.frames;
        }
    }
}

} // namespace lobe
