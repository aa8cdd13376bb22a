// Loader–runtime negotiation and xrGetInstanceProcAddr: the only way in.
//
// Debian's loader package (1.0.20) does not ship loader_interfaces.h, so the negotiation
// structures are declared here from the OpenXR loader specification ("Runtime Interface
// Negotiation"); their layout is fixed by interface version 1.

#include <cstring>
#include <string_view>

#include "input/openxr_replay/runtime.h"

extern "C" {

enum XrLoaderInterfaceStructs {
    XR_LOADER_INTERFACE_STRUCT_UNINTIALIZED = 0,
    XR_LOADER_INTERFACE_STRUCT_LOADER_INFO,
    XR_LOADER_INTERFACE_STRUCT_API_LAYER_REQUEST,
    XR_LOADER_INTERFACE_STRUCT_RUNTIME_REQUEST,
    XR_LOADER_INTERFACE_STRUCT_API_LAYER_CREATE_INFO,
    XR_LOADER_INTERFACE_STRUCT_API_LAYER_NEXT_INFO,
};

#define XR_LOADER_INFO_STRUCT_VERSION 1
struct XrNegotiateLoaderInfo {
    XrLoaderInterfaceStructs structType; // XR_LOADER_INTERFACE_STRUCT_LOADER_INFO
    uint32_t structVersion;              // XR_LOADER_INFO_STRUCT_VERSION
    size_t structSize;                   // sizeof(XrNegotiateLoaderInfo)
    uint32_t minInterfaceVersion;
    uint32_t maxInterfaceVersion;
    XrVersion minApiVersion;
    XrVersion maxApiVersion;
};

#define XR_RUNTIME_INFO_STRUCT_VERSION 1
struct XrNegotiateRuntimeRequest {
    XrLoaderInterfaceStructs structType; // XR_LOADER_INTERFACE_STRUCT_RUNTIME_REQUEST
    uint32_t structVersion;              // XR_RUNTIME_INFO_STRUCT_VERSION
    size_t structSize;                   // sizeof(XrNegotiateRuntimeRequest)
    uint32_t runtimeInterfaceVersion;    // out
    XrVersion runtimeApiVersion;         // out
    PFN_xrGetInstanceProcAddr getInstanceProcAddr; // out
};

#define XR_CURRENT_LOADER_RUNTIME_VERSION 1

__attribute__((visibility("default"))) XrResult XRAPI_CALL
xrNegotiateLoaderRuntimeInterface(const XrNegotiateLoaderInfo* loaderInfo, XrNegotiateRuntimeRequest* runtimeRequest)
{
    if (!loaderInfo || !runtimeRequest) return XR_ERROR_INITIALIZATION_FAILED;
    if (loaderInfo->structType != XR_LOADER_INTERFACE_STRUCT_LOADER_INFO ||
        loaderInfo->structVersion != XR_LOADER_INFO_STRUCT_VERSION ||
        loaderInfo->structSize != sizeof(XrNegotiateLoaderInfo))
        return XR_ERROR_INITIALIZATION_FAILED;
    if (runtimeRequest->structType != XR_LOADER_INTERFACE_STRUCT_RUNTIME_REQUEST ||
        runtimeRequest->structVersion != XR_RUNTIME_INFO_STRUCT_VERSION ||
        runtimeRequest->structSize != sizeof(XrNegotiateRuntimeRequest))
        return XR_ERROR_INITIALIZATION_FAILED;
    if (loaderInfo->minInterfaceVersion > XR_CURRENT_LOADER_RUNTIME_VERSION ||
        loaderInfo->maxInterfaceVersion < XR_CURRENT_LOADER_RUNTIME_VERSION)
        return XR_ERROR_INITIALIZATION_FAILED;
    // This runtime implements OpenXR 1.0 (any 1.0.x patch).
    if (XR_VERSION_MAJOR(loaderInfo->maxApiVersion) < 1 || XR_VERSION_MAJOR(loaderInfo->minApiVersion) > 1)
        return XR_ERROR_INITIALIZATION_FAILED;
    runtimeRequest->runtimeInterfaceVersion = XR_CURRENT_LOADER_RUNTIME_VERSION;
    runtimeRequest->runtimeApiVersion = XR_CURRENT_API_VERSION;
    runtimeRequest->getInstanceProcAddr = &lobe::xrr::xrGetInstanceProcAddr;
    return XR_SUCCESS;
}

} // extern "C"

namespace lobe::xrr {
namespace {

enum class Needs : std::uint8_t { Core, HandTracking, Vulkan2 };

struct Entry {
    const char* name;
    PFN_xrVoidFunction fn;
    Needs needs;
};

#define LOBE_FN(name, needs) Entry{#name, reinterpret_cast<PFN_xrVoidFunction>(&name), Needs::needs}

// Every core OpenXR 1.0 function (the loader fills its dispatch table from this list; a
// function missing here would crash an application that calls it) and the extension ones.
const Entry kEntries[] = {
    LOBE_FN(xrGetInstanceProcAddr, Core),
    LOBE_FN(xrEnumerateApiLayerProperties, Core),
    LOBE_FN(xrEnumerateInstanceExtensionProperties, Core),
    LOBE_FN(xrCreateInstance, Core),
    LOBE_FN(xrDestroyInstance, Core),
    LOBE_FN(xrGetInstanceProperties, Core),
    LOBE_FN(xrPollEvent, Core),
    LOBE_FN(xrResultToString, Core),
    LOBE_FN(xrStructureTypeToString, Core),
    LOBE_FN(xrGetSystem, Core),
    LOBE_FN(xrGetSystemProperties, Core),
    LOBE_FN(xrEnumerateEnvironmentBlendModes, Core),
    LOBE_FN(xrCreateSession, Core),
    LOBE_FN(xrDestroySession, Core),
    LOBE_FN(xrEnumerateReferenceSpaces, Core),
    LOBE_FN(xrCreateReferenceSpace, Core),
    LOBE_FN(xrGetReferenceSpaceBoundsRect, Core),
    LOBE_FN(xrCreateActionSpace, Core),
    LOBE_FN(xrLocateSpace, Core),
    LOBE_FN(xrDestroySpace, Core),
    LOBE_FN(xrEnumerateViewConfigurations, Core),
    LOBE_FN(xrGetViewConfigurationProperties, Core),
    LOBE_FN(xrEnumerateViewConfigurationViews, Core),
    LOBE_FN(xrEnumerateSwapchainFormats, Core),
    LOBE_FN(xrCreateSwapchain, Core),
    LOBE_FN(xrDestroySwapchain, Core),
    LOBE_FN(xrEnumerateSwapchainImages, Core),
    LOBE_FN(xrAcquireSwapchainImage, Core),
    LOBE_FN(xrWaitSwapchainImage, Core),
    LOBE_FN(xrReleaseSwapchainImage, Core),
    LOBE_FN(xrBeginSession, Core),
    LOBE_FN(xrEndSession, Core),
    LOBE_FN(xrRequestExitSession, Core),
    LOBE_FN(xrWaitFrame, Core),
    LOBE_FN(xrBeginFrame, Core),
    LOBE_FN(xrEndFrame, Core),
    LOBE_FN(xrLocateViews, Core),
    LOBE_FN(xrStringToPath, Core),
    LOBE_FN(xrPathToString, Core),
    LOBE_FN(xrCreateActionSet, Core),
    LOBE_FN(xrDestroyActionSet, Core),
    LOBE_FN(xrCreateAction, Core),
    LOBE_FN(xrDestroyAction, Core),
    LOBE_FN(xrSuggestInteractionProfileBindings, Core),
    LOBE_FN(xrAttachSessionActionSets, Core),
    LOBE_FN(xrGetCurrentInteractionProfile, Core),
    LOBE_FN(xrGetActionStateBoolean, Core),
    LOBE_FN(xrGetActionStateFloat, Core),
    LOBE_FN(xrGetActionStateVector2f, Core),
    LOBE_FN(xrGetActionStatePose, Core),
    LOBE_FN(xrSyncActions, Core),
    LOBE_FN(xrEnumerateBoundSourcesForAction, Core),
    LOBE_FN(xrGetInputSourceLocalizedName, Core),
    LOBE_FN(xrApplyHapticFeedback, Core),
    LOBE_FN(xrStopHapticFeedback, Core),
    LOBE_FN(xrCreateHandTrackerEXT, HandTracking),
    LOBE_FN(xrDestroyHandTrackerEXT, HandTracking),
    LOBE_FN(xrLocateHandJointsEXT, HandTracking),
    LOBE_FN(xrGetVulkanGraphicsRequirements2KHR, Vulkan2),
    LOBE_FN(xrCreateVulkanInstanceKHR, Vulkan2),
    LOBE_FN(xrCreateVulkanDeviceKHR, Vulkan2),
    LOBE_FN(xrGetVulkanGraphicsDevice2KHR, Vulkan2),
};

#undef LOBE_FN

} // namespace

XrResult XRAPI_CALL xrGetInstanceProcAddr(XrInstance instance, const char* name, PFN_xrVoidFunction* function)
{
    return guarded("xrGetInstanceProcAddr", [&]() -> XrResult {
        if (!function) return XR_ERROR_VALIDATION_FAILURE;
        *function = nullptr;
        if (!name) return XR_ERROR_VALIDATION_FAILURE;
        const std::string_view n(name);
        if (instance == XR_NULL_HANDLE) {
            // Only these three may be asked for without an instance.
            if (n != "xrEnumerateInstanceExtensionProperties" && n != "xrEnumerateApiLayerProperties" &&
                n != "xrCreateInstance")
                return XR_ERROR_HANDLE_INVALID;
        }
        const Instance* inst = nullptr;
        if (instance != XR_NULL_HANDLE) {
            inst = find<Instance>(key(instance), Kind::Instance);
            if (!inst) return XR_ERROR_HANDLE_INVALID;
        }
        for (const Entry& e : kEntries) {
            if (n != e.name) continue;
            if (inst && e.needs == Needs::HandTracking && !inst->ext_hand_tracking) return XR_ERROR_FUNCTION_UNSUPPORTED;
            if (inst && e.needs == Needs::Vulkan2 && !inst->ext_vulkan2) return XR_ERROR_FUNCTION_UNSUPPORTED;
            *function = e.fn;
            return XR_SUCCESS;
        }
        return XR_ERROR_FUNCTION_UNSUPPORTED;
    });
}

} // namespace lobe::xrr
