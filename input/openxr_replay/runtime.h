#pragma once
/// \file runtime.h
/// Internals of the OpenXR replay runtime (docs/openxr-replay-runtime.md): the objects behind
/// the handles, the registry that validates handles, and the entry points each topic file
/// implements. Nothing here is exported: the library's only visible symbol is
/// xrNegotiateLoaderRuntimeInterface (negotiate.cpp).

#include <chrono>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#define XR_NO_PROTOTYPES 1
#define XR_USE_GRAPHICS_API_VULKAN 1
#include <vulkan/vulkan.h>
#include <openxr/openxr.h>
#include <openxr/openxr_platform.h>

#include "input/recording.h"

// Vulkan and OpenXR structures are written {type} first and then filled member by member.
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"

namespace lobe::xrr {

// ---- objects behind the handles -------------------------------------------------------------

enum class Kind : std::uint8_t { Instance, Session, Space, ActionSet, Action, Swapchain, HandTracker };

/// Every handle is a registry key; an object knows its kind and its parent's key, so a handle of
/// the wrong kind, a destroyed handle or garbage is refused with XR_ERROR_HANDLE_INVALID.
struct Object {
    explicit Object(Kind k) : kind(k) {}
    virtual ~Object() = default;
    Kind kind;
    std::uint64_t handle = 0;
    std::uint64_t parent = 0;
};

/// What the environment asked for when the instance was created (docs: "Environment").
struct Switches {
    std::string recording_path;   ///< LOBESKETCH_REPLAY
    std::string dump_dir;         ///< LOBESKETCH_REPLAY_DUMP ("" = no dump)
    long dump_every = 1;          ///< LOBESKETCH_REPLAY_DUMP_EVERY
    long max_frames = 0;          ///< LOBESKETCH_REPLAY_MAX_FRAMES (0 = all)
    long lose_session_at = -1;    ///< LOBESKETCH_REPLAY_LOSE_SESSION_AT (-1 = never)
    bool hand_tracking = true;    ///< LOBESKETCH_REPLAY_NO_HAND_TRACKING unset
    bool vulkan = true;           ///< LOBESKETCH_REPLAY_NO_VULKAN unset
    bool realtime = false;        ///< LOBESKETCH_REPLAY_REALTIME=1
    std::uint32_t view_width = 960, view_height = 1080; ///< LOBESKETCH_REPLAY_VIEW_SIZE=WxH
};

/// Reads the switches that decide which extensions exist (hand tracking, Vulkan): these are
/// read again on every enumeration, so a process can change them between instances. Values
/// that make no sense are ignored, with one line each when `report_problems` (instance creation).
Switches read_switches(bool report_problems = false);

/// A rigid transform in stage space.
struct RigidPose {
    XrQuaternionf orientation{0, 0, 0, 1};
    XrVector3f position{0, 0, 0};
};

/// A pose and whether it is known (XrSpaceLocationFlags).
struct Located {
    RigidPose pose;
    XrSpaceLocationFlags flags = 0;
};

struct Instance;

struct Session : Object {
    Session() : Object(Kind::Session) {}
    std::uint64_t instance = 0;
    bool headless = false;
    XrSessionState state = XR_SESSION_STATE_IDLE;
    bool running = false;          ///< between xrBeginSession and xrEndSession
    bool exit_requested = false;   ///< the recording ended or the app asked
    bool loss_pending = false;     ///< LOSS_PENDING was queued; from the next xrWaitFrame on, lost
    bool lost = false;             ///< session calls answer XR_ERROR_SESSION_LOST
    std::chrono::steady_clock::time_point wall_start{}; ///< LOBESKETCH_REPLAY_REALTIME pacing
    bool frame_waited = false;     ///< xrWaitFrame returned and xrBeginFrame not yet called
    bool frame_begun = false;      ///< xrBeginFrame called and xrEndFrame not yet
    std::int64_t frame_index = -1; ///< recording frame of the last xrWaitFrame
    XrTime frame_time = 0;         ///< its predicted display time
    std::vector<std::uint64_t> attached_action_sets;
    // Vulkan binding (XR_KHR_vulkan_enable2); null for headless sessions.
    VkInstance vk_instance = VK_NULL_HANDLE;
    VkPhysicalDevice vk_physical_device = VK_NULL_HANDLE;
    VkDevice vk_device = VK_NULL_HANDLE;
    std::uint32_t queue_family = 0, queue_index = 0;
    struct VulkanState;            ///< device functions, command pool (vulkan.cpp)
    std::shared_ptr<VulkanState> vk;
};

struct Space : Object {
    Space() : Object(Kind::Space) {}
    std::uint64_t session = 0;
    XrReferenceSpaceType reference = XR_REFERENCE_SPACE_TYPE_STAGE; ///< when action == 0
    std::uint64_t action = 0;      ///< an action space when set
    XrPath subaction = XR_NULL_PATH;
    RigidPose offset;              ///< poseInReferenceSpace / poseInActionSpace
};

struct ActionSet : Object {
    ActionSet() : Object(Kind::ActionSet) {}
    std::string name, localized_name;
    std::uint32_t priority = 0;
    bool attached = false;
};

struct Action : Object {
    Action() : Object(Kind::Action) {}
    std::string name, localized_name;
    XrActionType type = XR_ACTION_TYPE_BOOLEAN_INPUT;
    std::vector<XrPath> subactions;
};

struct Swapchain : Object {
    Swapchain() : Object(Kind::Swapchain) {}
    std::uint64_t session = 0;
    XrSwapchainCreateInfo info{};
    VkFormat format = VK_FORMAT_UNDEFINED;
    bool depth = false;
    struct Image {
        VkImage image = VK_NULL_HANDLE;
        VkDeviceMemory memory = VK_NULL_HANDLE;
        bool ready = false; ///< moved to its attachment layout (at its first acquire)
    };
    std::vector<Image> images;
    std::deque<std::uint32_t> acquired;  ///< acquired, in order; the front one is waited on next
    bool waited = false;                 ///< the front of `acquired` was waited on
    std::uint32_t next_acquire = 0;
    std::int64_t last_released = -1;
    bool static_image_released = false;
};

struct HandTracker : Object {
    HandTracker() : Object(Kind::HandTracker) {}
    std::uint64_t session = 0;
    XrHandEXT hand = XR_HAND_LEFT_EXT;
};

/// A queued event (the largest payload any event here has).
using Event = XrEventDataBuffer;

struct Instance : Object {
    Instance() : Object(Kind::Instance) {}
    Switches sw;
    Recording recording;
    std::size_t frame_count = 0;        ///< frames played (recording size, capped)
    std::vector<XrTime> frame_times;    ///< XrTime of each played frame
    std::vector<Located> heads;         ///< head pose per played frame (stage space)
    RigidPose local_origin;             ///< LOCAL space in stage space
    bool ext_hand_tracking = false, ext_headless = false, ext_vulkan2 = false;
    bool graphics_requirements_queried = false;
    std::uint64_t session = 0;          ///< the one session, 0 when none
    std::int64_t next_frame = 0;        ///< the recording frame the next xrWaitFrame hands out
    bool lost_once = false;             ///< the loss switch fired
    std::deque<Event> events;
    std::map<std::string, XrPath> path_ids;
    std::vector<std::string> path_strings; ///< index = XrPath - 1
    std::map<VkInstance, PFN_vkGetInstanceProcAddr> vk_instances; ///< made by xrCreateVulkanInstanceKHR
    VkPhysicalDevice vk_physical_device = VK_NULL_HANDLE; ///< from xrGetVulkanGraphicsDevice2KHR
    VkInstance vk_physical_device_instance = VK_NULL_HANDLE; ///< the VkInstance it came from
    bool dump_failed_reported = false;
};

inline constexpr XrSystemId kSystemId = 0x10BE;
inline constexpr std::uint32_t kViewCount = 2;
inline constexpr std::uint32_t kMaxLayers = 16;
inline constexpr float kHalfIpd = 0.032f;
/// XrTime of recording time 0 (the first played frame): 1 s, so every time is positive.
inline constexpr XrTime kEpochNs = 1'000'000'000;

// ---- the registry ---------------------------------------------------------------------------

/// Guards every object and the registry. Each entry point takes it for its whole call (the
/// runtime has no threads of its own); xrWaitFrame drops it while it paces in real time.
std::recursive_mutex& api_mutex();

std::uint64_t add_object(std::unique_ptr<Object> obj, std::uint64_t parent);
Object* find_object(std::uint64_t handle, Kind kind);
/// Destroys the object and everything created from it (children first).
void destroy_object(std::uint64_t handle);
template <class T>
T* find(std::uint64_t handle, Kind kind)
{
    return static_cast<T*>(find_object(handle, kind));
}
template <class H>
std::uint64_t key(H handle)
{
    return reinterpret_cast<std::uint64_t>(handle);
}
template <class H>
H as_handle(std::uint64_t k)
{
    return reinterpret_cast<H>(k);
}
std::vector<std::uint64_t> children_of(std::uint64_t parent, Kind kind);

// ---- helpers --------------------------------------------------------------------------------

/// One line on stderr, prefixed with "lobesketch_xr_replay: ".
void log_line(const std::string& line);

/// The two-call idiom: writes `count` to *countOutput and copies when capacity suffices.
template <class T>
XrResult enumerate(const std::vector<T>& items, std::uint32_t capacity, std::uint32_t* count_out, T* out)
{
    if (!count_out) return XR_ERROR_VALIDATION_FAILURE;
    *count_out = static_cast<std::uint32_t>(items.size());
    if (capacity == 0) return XR_SUCCESS;
    if (!out) return XR_ERROR_VALIDATION_FAILURE;
    if (capacity < items.size()) return XR_ERROR_SIZE_INSUFFICIENT;
    for (std::size_t i = 0; i < items.size(); ++i) out[i] = items[i];
    return XR_SUCCESS;
}
XrResult copy_string(const std::string& s, std::uint32_t capacity, std::uint32_t* count_out, char* buffer);

/// Walks a `next` chain for a structure of the given type.
const void* find_in_chain(const void* next, XrStructureType type);
void* find_in_chain_mut(void* next, XrStructureType type);

RigidPose compose(const RigidPose& a, const RigidPose& b); ///< a ∘ b (b expressed in a)
RigidPose inverse(const RigidPose& a);
bool pose_valid(const XrPosef& p); ///< finite, unit quaternion within 1 %
RigidPose to_rigid(const XrPosef& p);
XrPosef to_xr(const RigidPose& p);

/// Session lifecycle (session.cpp).
void queue_state(Instance& inst, Session& s, XrSessionState state, XrTime time);
/// Index of the played frame shown at `time`: the last frame not after it (the first frame
/// before the recording starts).
std::size_t frame_at(const Instance& inst, XrTime time);
/// Where a space is in stage space at a time (session.cpp).
Located locate_in_stage(const Instance& inst, const Space& space, XrTime time);
bool session_checks(XrSession session, Session*& s, Instance*& inst, XrResult& r);
XrResult validate_time(XrTime t);

/// Paths (instance.cpp).
std::string path_string(const Instance& inst, XrPath p); ///< "" when unknown
bool top_level_user_path(const std::string& p);

/// Vulkan side (vulkan.cpp).
XrResult bind_vulkan_session(Instance& inst, Session& s, const XrGraphicsBindingVulkanKHR& binding);
void release_vulkan_session(Session& s);
void destroy_swapchain_images(Session& s, Swapchain& sc);
/// Writes the projection views of a frame as PNG when the dump is on.
void dump_projection(Instance& inst, Session& s, const XrCompositionLayerProjection& layer, std::int64_t frame);

// ---- entry points ---------------------------------------------------------------------------

#define LOBE_XR_ENTRY(name) XrResult XRAPI_CALL name

// instance.cpp
LOBE_XR_ENTRY(xrEnumerateApiLayerProperties)(uint32_t, uint32_t*, XrApiLayerProperties*);
LOBE_XR_ENTRY(xrEnumerateInstanceExtensionProperties)(const char*, uint32_t, uint32_t*, XrExtensionProperties*);
LOBE_XR_ENTRY(xrCreateInstance)(const XrInstanceCreateInfo*, XrInstance*);
LOBE_XR_ENTRY(xrDestroyInstance)(XrInstance);
LOBE_XR_ENTRY(xrGetInstanceProperties)(XrInstance, XrInstanceProperties*);
LOBE_XR_ENTRY(xrPollEvent)(XrInstance, XrEventDataBuffer*);
LOBE_XR_ENTRY(xrResultToString)(XrInstance, XrResult, char[XR_MAX_RESULT_STRING_SIZE]);
LOBE_XR_ENTRY(xrStructureTypeToString)(XrInstance, XrStructureType, char[XR_MAX_STRUCTURE_NAME_SIZE]);
LOBE_XR_ENTRY(xrGetSystem)(XrInstance, const XrSystemGetInfo*, XrSystemId*);
LOBE_XR_ENTRY(xrGetSystemProperties)(XrInstance, XrSystemId, XrSystemProperties*);
LOBE_XR_ENTRY(xrEnumerateEnvironmentBlendModes)(XrInstance, XrSystemId, XrViewConfigurationType, uint32_t, uint32_t*, XrEnvironmentBlendMode*);
LOBE_XR_ENTRY(xrEnumerateViewConfigurations)(XrInstance, XrSystemId, uint32_t, uint32_t*, XrViewConfigurationType*);
LOBE_XR_ENTRY(xrGetViewConfigurationProperties)(XrInstance, XrSystemId, XrViewConfigurationType, XrViewConfigurationProperties*);
LOBE_XR_ENTRY(xrEnumerateViewConfigurationViews)(XrInstance, XrSystemId, XrViewConfigurationType, uint32_t, uint32_t*, XrViewConfigurationView*);
LOBE_XR_ENTRY(xrStringToPath)(XrInstance, const char*, XrPath*);
LOBE_XR_ENTRY(xrPathToString)(XrInstance, XrPath, uint32_t, uint32_t*, char*);

// session.cpp
LOBE_XR_ENTRY(xrCreateSession)(XrInstance, const XrSessionCreateInfo*, XrSession*);
LOBE_XR_ENTRY(xrDestroySession)(XrSession);
LOBE_XR_ENTRY(xrBeginSession)(XrSession, const XrSessionBeginInfo*);
LOBE_XR_ENTRY(xrEndSession)(XrSession);
LOBE_XR_ENTRY(xrRequestExitSession)(XrSession);
LOBE_XR_ENTRY(xrWaitFrame)(XrSession, const XrFrameWaitInfo*, XrFrameState*);
LOBE_XR_ENTRY(xrBeginFrame)(XrSession, const XrFrameBeginInfo*);
LOBE_XR_ENTRY(xrEndFrame)(XrSession, const XrFrameEndInfo*);
LOBE_XR_ENTRY(xrLocateViews)(XrSession, const XrViewLocateInfo*, XrViewState*, uint32_t, uint32_t*, XrView*);
LOBE_XR_ENTRY(xrEnumerateReferenceSpaces)(XrSession, uint32_t, uint32_t*, XrReferenceSpaceType*);
LOBE_XR_ENTRY(xrCreateReferenceSpace)(XrSession, const XrReferenceSpaceCreateInfo*, XrSpace*);
LOBE_XR_ENTRY(xrGetReferenceSpaceBoundsRect)(XrSession, XrReferenceSpaceType, XrExtent2Df*);
LOBE_XR_ENTRY(xrLocateSpace)(XrSpace, XrSpace, XrTime, XrSpaceLocation*);
LOBE_XR_ENTRY(xrDestroySpace)(XrSpace);

// actions.cpp
LOBE_XR_ENTRY(xrCreateActionSet)(XrInstance, const XrActionSetCreateInfo*, XrActionSet*);
LOBE_XR_ENTRY(xrDestroyActionSet)(XrActionSet);
LOBE_XR_ENTRY(xrCreateAction)(XrActionSet, const XrActionCreateInfo*, XrAction*);
LOBE_XR_ENTRY(xrDestroyAction)(XrAction);
LOBE_XR_ENTRY(xrSuggestInteractionProfileBindings)(XrInstance, const XrInteractionProfileSuggestedBinding*);
LOBE_XR_ENTRY(xrAttachSessionActionSets)(XrSession, const XrSessionActionSetsAttachInfo*);
LOBE_XR_ENTRY(xrGetCurrentInteractionProfile)(XrSession, XrPath, XrInteractionProfileState*);
LOBE_XR_ENTRY(xrGetActionStateBoolean)(XrSession, const XrActionStateGetInfo*, XrActionStateBoolean*);
LOBE_XR_ENTRY(xrGetActionStateFloat)(XrSession, const XrActionStateGetInfo*, XrActionStateFloat*);
LOBE_XR_ENTRY(xrGetActionStateVector2f)(XrSession, const XrActionStateGetInfo*, XrActionStateVector2f*);
LOBE_XR_ENTRY(xrGetActionStatePose)(XrSession, const XrActionStateGetInfo*, XrActionStatePose*);
LOBE_XR_ENTRY(xrSyncActions)(XrSession, const XrActionsSyncInfo*);
LOBE_XR_ENTRY(xrEnumerateBoundSourcesForAction)(XrSession, const XrBoundSourcesForActionEnumerateInfo*, uint32_t, uint32_t*, XrPath*);
LOBE_XR_ENTRY(xrGetInputSourceLocalizedName)(XrSession, const XrInputSourceLocalizedNameGetInfo*, uint32_t, uint32_t*, char*);
LOBE_XR_ENTRY(xrApplyHapticFeedback)(XrSession, const XrHapticActionInfo*, const XrHapticBaseHeader*);
LOBE_XR_ENTRY(xrStopHapticFeedback)(XrSession, const XrHapticActionInfo*);
LOBE_XR_ENTRY(xrCreateActionSpace)(XrSession, const XrActionSpaceCreateInfo*, XrSpace*);

// hand_tracking.cpp
LOBE_XR_ENTRY(xrCreateHandTrackerEXT)(XrSession, const XrHandTrackerCreateInfoEXT*, XrHandTrackerEXT*);
LOBE_XR_ENTRY(xrDestroyHandTrackerEXT)(XrHandTrackerEXT);
LOBE_XR_ENTRY(xrLocateHandJointsEXT)(XrHandTrackerEXT, const XrHandJointsLocateInfoEXT*, XrHandJointLocationsEXT*);

// vulkan.cpp
LOBE_XR_ENTRY(xrGetVulkanGraphicsRequirements2KHR)(XrInstance, XrSystemId, XrGraphicsRequirementsVulkanKHR*);
LOBE_XR_ENTRY(xrCreateVulkanInstanceKHR)(XrInstance, const XrVulkanInstanceCreateInfoKHR*, VkInstance*, VkResult*);
LOBE_XR_ENTRY(xrCreateVulkanDeviceKHR)(XrInstance, const XrVulkanDeviceCreateInfoKHR*, VkDevice*, VkResult*);
LOBE_XR_ENTRY(xrGetVulkanGraphicsDevice2KHR)(XrInstance, const XrVulkanGraphicsDeviceGetInfoKHR*, VkPhysicalDevice*);
LOBE_XR_ENTRY(xrEnumerateSwapchainFormats)(XrSession, uint32_t, uint32_t*, int64_t*);
LOBE_XR_ENTRY(xrCreateSwapchain)(XrSession, const XrSwapchainCreateInfo*, XrSwapchain*);
LOBE_XR_ENTRY(xrDestroySwapchain)(XrSwapchain);
LOBE_XR_ENTRY(xrEnumerateSwapchainImages)(XrSwapchain, uint32_t, uint32_t*, XrSwapchainImageBaseHeader*);
LOBE_XR_ENTRY(xrAcquireSwapchainImage)(XrSwapchain, const XrSwapchainImageAcquireInfo*, uint32_t*);
LOBE_XR_ENTRY(xrWaitSwapchainImage)(XrSwapchain, const XrSwapchainImageWaitInfo*);
LOBE_XR_ENTRY(xrReleaseSwapchainImage)(XrSwapchain, const XrSwapchainImageReleaseInfo*);

// negotiate.cpp
LOBE_XR_ENTRY(xrGetInstanceProcAddr)(XrInstance, const char*, PFN_xrVoidFunction*);

/// Runs an entry point's body under the API lock; an exception becomes
/// XR_ERROR_RUNTIME_FAILURE with one line on stderr (nothing crosses the C boundary).
template <class F>
XrResult guarded(const char* name, F&& body)
{
    try {
        std::lock_guard<std::recursive_mutex> lock(api_mutex());
        return body();
    } catch (const std::exception& e) {
        log_line(std::string(name) + ": " + e.what());
    } catch (...) {
        log_line(std::string(name) + ": unknown error");
    }
    return XR_ERROR_RUNTIME_FAILURE;
}

} // namespace lobe::xrr
