// Instance, system, view configurations, events, paths and the recording behind them.

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string_view>

#include <openxr/openxr_reflection.h>

#include "core/errors.h"
#include "input/openxr_replay/runtime.h"

namespace lobe::xrr {
namespace {

struct ExtensionInfo {
    const char* name;
    std::uint32_t version;
};

std::vector<XrExtensionProperties> offered_extensions(const Switches& sw)
{
    std::vector<ExtensionInfo> list = {{XR_MND_HEADLESS_EXTENSION_NAME, XR_MND_headless_SPEC_VERSION}};
    if (sw.hand_tracking) list.push_back({XR_EXT_HAND_TRACKING_EXTENSION_NAME, XR_EXT_hand_tracking_SPEC_VERSION});
    if (sw.vulkan) list.push_back({XR_KHR_VULKAN_ENABLE2_EXTENSION_NAME, XR_KHR_vulkan_enable2_SPEC_VERSION});
    std::vector<XrExtensionProperties> out;
    for (const ExtensionInfo& e : list) {
        XrExtensionProperties p{XR_TYPE_EXTENSION_PROPERTIES};
        std::snprintf(p.extensionName, sizeof p.extensionName, "%s", e.name);
        p.extensionVersion = e.version;
        out.push_back(p);
    }
    return out;
}

bool instance_checks(XrInstance instance, Instance*& inst, XrResult& r)
{
    inst = find<Instance>(key(instance), Kind::Instance);
    r = inst ? XR_SUCCESS : XR_ERROR_HANDLE_INVALID;
    return inst != nullptr;
}

XrResult system_checks(XrInstance instance, XrSystemId system, Instance*& inst)
{
    XrResult r;
    if (!instance_checks(instance, inst, r)) return r;
    if (system != kSystemId) return XR_ERROR_SYSTEM_INVALID;
    return XR_SUCCESS;
}

/// Yaw-only part of an orientation (rotation about +Y).
XrQuaternionf yaw_only(const XrQuaternionf& q)
{
    const float len = std::sqrt(q.y * q.y + q.w * q.w);
    if (len < 1e-6f) return {0, 0, 0, 1};
    return {0, q.y / len, 0, q.w / len};
}

/// Loads the recording and derives frame times, head poses and the LOCAL origin.
void load_recording(Instance& inst)
{
    ReadReport report;
    inst.recording = read_recording(inst.sw.recording_path, &report);
    if (report.frames_dropped > 0)
        log_line(inst.sw.recording_path + ": " + std::to_string(report.frames_dropped) + " damaged frames skipped" +
                 (report.problems.empty() ? std::string() : " (first problem: " + report.problems.front() + ")"));
    const auto& frames = inst.recording.frames;
    if (frames.empty()) throw FileError(inst.sw.recording_path, "no hand frames to replay (events only)");
    inst.frame_count = frames.size();
    if (inst.sw.max_frames > 0 && static_cast<std::size_t>(inst.sw.max_frames) < inst.frame_count)
        inst.frame_count = static_cast<std::size_t>(inst.sw.max_frames);
    const double t0 = frames.front().time;
    inst.frame_times.resize(inst.frame_count);
    inst.heads.resize(inst.frame_count);
    // Head: the recorded head where valid, else the last valid one (first valid one before it
    // appears), else standing at 1.6 m looking along -Z. Only recorded heads are "tracked".
    Located last;
    last.pose.position = {0.0f, 1.6f, 0.0f};
    last.flags = XR_SPACE_LOCATION_ORIENTATION_VALID_BIT | XR_SPACE_LOCATION_POSITION_VALID_BIT;
    for (std::size_t i = 0; i < inst.frame_count; ++i)
        if (frames[i].head_valid) {
            const Pose& h = frames[i].head;
            last.pose.position = {h.position.x, h.position.y, h.position.z};
            last.pose.orientation = {h.orientation.x, h.orientation.y, h.orientation.z, h.orientation.w};
            break;
        }
    for (std::size_t i = 0; i < inst.frame_count; ++i) {
        inst.frame_times[i] = kEpochNs + static_cast<XrTime>(std::llround((frames[i].time - t0) * 1e9));
        Located h = last;
        h.flags = XR_SPACE_LOCATION_ORIENTATION_VALID_BIT | XR_SPACE_LOCATION_POSITION_VALID_BIT;
        if (frames[i].head_valid) {
            const Pose& p = frames[i].head;
            h.pose.position = {p.position.x, p.position.y, p.position.z};
            h.pose.orientation = {p.orientation.x, p.orientation.y, p.orientation.z, p.orientation.w};
            h.flags |= XR_SPACE_LOCATION_ORIENTATION_TRACKED_BIT | XR_SPACE_LOCATION_POSITION_TRACKED_BIT;
            last = h;
        }
        inst.heads[i] = h;
    }
    inst.local_origin.position = inst.heads.front().pose.position;
    inst.local_origin.orientation = yaw_only(inst.heads.front().pose.orientation);
}

template <class T>
const char* enum_name(T value)
{
    switch (value) {
#define LOBE_ENUM_CASE(name, val) \
    case name: return #name;
        XR_LIST_ENUM_XrResult(LOBE_ENUM_CASE)
#undef LOBE_ENUM_CASE
    default: return nullptr;
    }
}

const char* structure_type_name(XrStructureType value)
{
    switch (value) {
#define LOBE_ENUM_CASE(name, val) \
    case name: return #name;
        XR_LIST_ENUM_XrStructureType(LOBE_ENUM_CASE)
#undef LOBE_ENUM_CASE
    default: return nullptr;
    }
}

/// Path grammar of the specification: '/'-separated components of [a-z0-9-_.], no empty
/// component, no "." or ".." component, no trailing '/'.
bool well_formed_path(std::string_view p)
{
    if (p.size() < 2 || p.size() >= XR_MAX_PATH_LENGTH || p[0] != '/' || p.back() == '/') return false;
    std::size_t start = 1;
    while (start <= p.size()) {
        std::size_t end = p.find('/', start);
        if (end == std::string_view::npos) end = p.size();
        const std::string_view c = p.substr(start, end - start);
        if (c.empty() || c == "." || c == "..") return false;
        for (char ch : c)
            if (!((ch >= 'a' && ch <= 'z') || (ch >= '0' && ch <= '9') || ch == '-' || ch == '_' || ch == '.')) return false;
        start = end + 1;
    }
    return true;
}

} // namespace

bool top_level_user_path(const std::string& p)
{
    return p == "/user/hand/left" || p == "/user/hand/right" || p == "/user/head" || p == "/user/gamepad" ||
           p == "/user/treadmill";
}

std::string path_string(const Instance& inst, XrPath p)
{
    if (p == XR_NULL_PATH || p > inst.path_strings.size()) return {};
    return inst.path_strings[p - 1];
}

XrResult XRAPI_CALL xrEnumerateApiLayerProperties(uint32_t capacity, uint32_t* count, XrApiLayerProperties* props)
{
    return guarded("xrEnumerateApiLayerProperties", [&] {
        return enumerate(std::vector<XrApiLayerProperties>{}, capacity, count, props);
    });
}

XrResult XRAPI_CALL xrEnumerateInstanceExtensionProperties(const char* layer, uint32_t capacity, uint32_t* count,
                                                           XrExtensionProperties* props)
{
    return guarded("xrEnumerateInstanceExtensionProperties", [&]() -> XrResult {
        if (layer && *layer) return XR_ERROR_API_LAYER_NOT_PRESENT;
        const auto list = offered_extensions(read_switches());
        if (capacity > 0 && props)
            for (std::uint32_t i = 0; i < capacity && i < list.size(); ++i)
                if (props[i].type != XR_TYPE_EXTENSION_PROPERTIES) return XR_ERROR_VALIDATION_FAILURE;
        return enumerate(list, capacity, count, props);
    });
}

XrResult XRAPI_CALL xrCreateInstance(const XrInstanceCreateInfo* info, XrInstance* out)
{
    return guarded("xrCreateInstance", [&]() -> XrResult {
        if (!info || !out || info->type != XR_TYPE_INSTANCE_CREATE_INFO) return XR_ERROR_VALIDATION_FAILURE;
        if (info->createFlags != 0) return XR_ERROR_VALIDATION_FAILURE;
        const XrVersion api = info->applicationInfo.apiVersion;
        if (XR_VERSION_MAJOR(api) != 1 || XR_VERSION_MINOR(api) != 0) return XR_ERROR_API_VERSION_UNSUPPORTED;
        // API layers are the loader's business: it passes the application's list down unchanged.
        if (strnlen(info->applicationInfo.applicationName, XR_MAX_APPLICATION_NAME_SIZE) == 0 ||
            strnlen(info->applicationInfo.applicationName, XR_MAX_APPLICATION_NAME_SIZE) == XR_MAX_APPLICATION_NAME_SIZE)
            return XR_ERROR_NAME_INVALID;
        auto inst = std::make_unique<Instance>();
        inst->sw = read_switches(true);
        const auto offered = offered_extensions(inst->sw);
        if (info->enabledExtensionCount > 0 && !info->enabledExtensionNames) return XR_ERROR_VALIDATION_FAILURE;
        for (std::uint32_t i = 0; i < info->enabledExtensionCount; ++i) {
            const char* name = info->enabledExtensionNames[i];
            if (!name) return XR_ERROR_VALIDATION_FAILURE;
            bool found = false;
            for (const auto& e : offered) found = found || std::strcmp(e.extensionName, name) == 0;
            if (!found) return XR_ERROR_EXTENSION_NOT_PRESENT;
            const std::string_view n(name);
            if (n == XR_EXT_HAND_TRACKING_EXTENSION_NAME) inst->ext_hand_tracking = true;
            if (n == XR_MND_HEADLESS_EXTENSION_NAME) inst->ext_headless = true;
            if (n == XR_KHR_VULKAN_ENABLE2_EXTENSION_NAME) inst->ext_vulkan2 = true;
        }
        if (inst->sw.recording_path.empty()) {
            log_line("LOBESKETCH_REPLAY is not set: it names the recording to replay (docs/openxr-replay-runtime.md)");
            return XR_ERROR_RUNTIME_FAILURE;
        }
        try {
            load_recording(*inst);
        } catch (const std::exception& e) {
            log_line(e.what());
            return XR_ERROR_RUNTIME_FAILURE;
        }
        if (!inst->sw.dump_dir.empty()) {
            std::error_code ec;
            std::filesystem::create_directories(inst->sw.dump_dir, ec);
            if (ec) {
                log_line(inst->sw.dump_dir + ": cannot create the dump folder (" + ec.message() + "); no images are written");
                inst->sw.dump_dir.clear();
            }
        }
        *out = as_handle<XrInstance>(add_object(std::move(inst), 0));
        return XR_SUCCESS;
    });
}

XrResult XRAPI_CALL xrDestroyInstance(XrInstance instance)
{
    return guarded("xrDestroyInstance", [&]() -> XrResult {
        Instance* inst;
        XrResult r;
        if (!instance_checks(instance, inst, r)) return r;
        destroy_object(inst->handle);
        return XR_SUCCESS;
    });
}

XrResult XRAPI_CALL xrGetInstanceProperties(XrInstance instance, XrInstanceProperties* props)
{
    return guarded("xrGetInstanceProperties", [&]() -> XrResult {
        Instance* inst;
        XrResult r;
        if (!instance_checks(instance, inst, r)) return r;
        if (!props || props->type != XR_TYPE_INSTANCE_PROPERTIES) return XR_ERROR_VALIDATION_FAILURE;
        props->runtimeVersion = XR_MAKE_VERSION(0, 1, 0);
        std::snprintf(props->runtimeName, sizeof props->runtimeName, "%s", "Lobesketch replay");
        return XR_SUCCESS;
    });
}

XrResult XRAPI_CALL xrPollEvent(XrInstance instance, XrEventDataBuffer* event)
{
    return guarded("xrPollEvent", [&]() -> XrResult {
        Instance* inst;
        XrResult r;
        if (!instance_checks(instance, inst, r)) return r;
        if (!event || event->type != XR_TYPE_EVENT_DATA_BUFFER) return XR_ERROR_VALIDATION_FAILURE;
        if (inst->events.empty()) return XR_EVENT_UNAVAILABLE;
        *event = inst->events.front();
        inst->events.pop_front();
        return XR_SUCCESS;
    });
}

XrResult XRAPI_CALL xrResultToString(XrInstance instance, XrResult value, char buffer[XR_MAX_RESULT_STRING_SIZE])
{
    return guarded("xrResultToString", [&]() -> XrResult {
        Instance* inst;
        XrResult r;
        if (!instance_checks(instance, inst, r)) return r;
        if (!buffer) return XR_ERROR_VALIDATION_FAILURE;
        if (const char* n = enum_name(value))
            std::snprintf(buffer, XR_MAX_RESULT_STRING_SIZE, "%s", n);
        else
            std::snprintf(buffer, XR_MAX_RESULT_STRING_SIZE, "XR_UNKNOWN_%s_%d", value >= 0 ? "SUCCESS" : "FAILURE",
                          static_cast<int>(value));
        return XR_SUCCESS;
    });
}

XrResult XRAPI_CALL xrStructureTypeToString(XrInstance instance, XrStructureType value, char buffer[XR_MAX_STRUCTURE_NAME_SIZE])
{
    return guarded("xrStructureTypeToString", [&]() -> XrResult {
        Instance* inst;
        XrResult r;
        if (!instance_checks(instance, inst, r)) return r;
        if (!buffer) return XR_ERROR_VALIDATION_FAILURE;
        if (const char* n = structure_type_name(value))
            std::snprintf(buffer, XR_MAX_STRUCTURE_NAME_SIZE, "%s", n);
        else
            std::snprintf(buffer, XR_MAX_STRUCTURE_NAME_SIZE, "XR_UNKNOWN_STRUCTURE_TYPE_%d", static_cast<int>(value));
        return XR_SUCCESS;
    });
}

XrResult XRAPI_CALL xrGetSystem(XrInstance instance, const XrSystemGetInfo* info, XrSystemId* system)
{
    return guarded("xrGetSystem", [&]() -> XrResult {
        Instance* inst;
        XrResult r;
        if (!instance_checks(instance, inst, r)) return r;
        if (!info || !system || info->type != XR_TYPE_SYSTEM_GET_INFO) return XR_ERROR_VALIDATION_FAILURE;
        if (info->formFactor == XR_FORM_FACTOR_HANDHELD_DISPLAY) return XR_ERROR_FORM_FACTOR_UNSUPPORTED;
        if (info->formFactor != XR_FORM_FACTOR_HEAD_MOUNTED_DISPLAY) return XR_ERROR_VALIDATION_FAILURE;
        *system = kSystemId;
        return XR_SUCCESS;
    });
}

XrResult XRAPI_CALL xrGetSystemProperties(XrInstance instance, XrSystemId system, XrSystemProperties* props)
{
    return guarded("xrGetSystemProperties", [&]() -> XrResult {
        Instance* inst;
        if (XrResult r = system_checks(instance, system, inst); r != XR_SUCCESS) return r;
        if (!props || props->type != XR_TYPE_SYSTEM_PROPERTIES) return XR_ERROR_VALIDATION_FAILURE;
        props->systemId = kSystemId;
        props->vendorId = 0x10BE;
        std::snprintf(props->systemName, sizeof props->systemName, "Lobesketch replay (%s)",
                      std::filesystem::path(inst->sw.recording_path).filename().string().c_str());
        props->graphicsProperties.maxSwapchainImageWidth = 4096;
        props->graphicsProperties.maxSwapchainImageHeight = 4096;
        props->graphicsProperties.maxLayerCount = kMaxLayers;
        props->trackingProperties.orientationTracking = XR_TRUE;
        props->trackingProperties.positionTracking = XR_TRUE;
        if (auto* ht = static_cast<XrSystemHandTrackingPropertiesEXT*>(
                find_in_chain_mut(props->next, XR_TYPE_SYSTEM_HAND_TRACKING_PROPERTIES_EXT)))
            ht->supportsHandTracking = inst->sw.hand_tracking ? XR_TRUE : XR_FALSE;
        return XR_SUCCESS;
    });
}

XrResult XRAPI_CALL xrEnumerateEnvironmentBlendModes(XrInstance instance, XrSystemId system, XrViewConfigurationType type,
                                                     uint32_t capacity, uint32_t* count, XrEnvironmentBlendMode* modes)
{
    return guarded("xrEnumerateEnvironmentBlendModes", [&]() -> XrResult {
        Instance* inst;
        if (XrResult r = system_checks(instance, system, inst); r != XR_SUCCESS) return r;
        if (type != XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO) return XR_ERROR_VIEW_CONFIGURATION_TYPE_UNSUPPORTED;
        return enumerate(std::vector<XrEnvironmentBlendMode>{XR_ENVIRONMENT_BLEND_MODE_OPAQUE}, capacity, count, modes);
    });
}

XrResult XRAPI_CALL xrEnumerateViewConfigurations(XrInstance instance, XrSystemId system, uint32_t capacity,
                                                  uint32_t* count, XrViewConfigurationType* types)
{
    return guarded("xrEnumerateViewConfigurations", [&]() -> XrResult {
        Instance* inst;
        if (XrResult r = system_checks(instance, system, inst); r != XR_SUCCESS) return r;
        return enumerate(std::vector<XrViewConfigurationType>{XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO}, capacity, count, types);
    });
}

XrResult XRAPI_CALL xrGetViewConfigurationProperties(XrInstance instance, XrSystemId system, XrViewConfigurationType type,
                                                     XrViewConfigurationProperties* props)
{
    return guarded("xrGetViewConfigurationProperties", [&]() -> XrResult {
        Instance* inst;
        if (XrResult r = system_checks(instance, system, inst); r != XR_SUCCESS) return r;
        if (!props || props->type != XR_TYPE_VIEW_CONFIGURATION_PROPERTIES) return XR_ERROR_VALIDATION_FAILURE;
        if (type != XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO) return XR_ERROR_VIEW_CONFIGURATION_TYPE_UNSUPPORTED;
        props->viewConfigurationType = type;
        props->fovMutable = XR_TRUE;
        return XR_SUCCESS;
    });
}

XrResult XRAPI_CALL xrEnumerateViewConfigurationViews(XrInstance instance, XrSystemId system, XrViewConfigurationType type,
                                                      uint32_t capacity, uint32_t* count, XrViewConfigurationView* views)
{
    return guarded("xrEnumerateViewConfigurationViews", [&]() -> XrResult {
        Instance* inst;
        if (XrResult r = system_checks(instance, system, inst); r != XR_SUCCESS) return r;
        if (type != XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO) return XR_ERROR_VIEW_CONFIGURATION_TYPE_UNSUPPORTED;
        if (!count) return XR_ERROR_VALIDATION_FAILURE;
        *count = kViewCount;
        if (capacity == 0) return XR_SUCCESS;
        if (!views) return XR_ERROR_VALIDATION_FAILURE;
        if (capacity < kViewCount) return XR_ERROR_SIZE_INSUFFICIENT;
        for (std::uint32_t i = 0; i < kViewCount; ++i) {
            if (views[i].type != XR_TYPE_VIEW_CONFIGURATION_VIEW) return XR_ERROR_VALIDATION_FAILURE;
            views[i].recommendedImageRectWidth = inst->sw.view_width;
            views[i].recommendedImageRectHeight = inst->sw.view_height;
            views[i].maxImageRectWidth = 4096;
            views[i].maxImageRectHeight = 4096;
            views[i].recommendedSwapchainSampleCount = 1;
            views[i].maxSwapchainSampleCount = 1;
        }
        return XR_SUCCESS;
    });
}

XrResult XRAPI_CALL xrStringToPath(XrInstance instance, const char* string, XrPath* path)
{
    return guarded("xrStringToPath", [&]() -> XrResult {
        Instance* inst;
        XrResult r;
        if (!instance_checks(instance, inst, r)) return r;
        if (!string || !path) return XR_ERROR_VALIDATION_FAILURE;
        const std::string_view s(string, strnlen(string, XR_MAX_PATH_LENGTH));
        if (!well_formed_path(s)) return XR_ERROR_PATH_FORMAT_INVALID;
        auto it = inst->path_ids.find(std::string(s));
        if (it != inst->path_ids.end()) {
            *path = it->second;
            return XR_SUCCESS;
        }
        if (inst->path_strings.size() >= 100000) return XR_ERROR_PATH_COUNT_EXCEEDED;
        inst->path_strings.emplace_back(s);
        const XrPath id = inst->path_strings.size();
        inst->path_ids.emplace(std::string(s), id);
        *path = id;
        return XR_SUCCESS;
    });
}

XrResult XRAPI_CALL xrPathToString(XrInstance instance, XrPath path, uint32_t capacity, uint32_t* count, char* buffer)
{
    return guarded("xrPathToString", [&]() -> XrResult {
        Instance* inst;
        XrResult r;
        if (!instance_checks(instance, inst, r)) return r;
        const std::string s = path_string(*inst, path);
        if (s.empty()) return XR_ERROR_PATH_INVALID;
        return copy_string(s, capacity, count, buffer);
    });
}

} // namespace lobe::xrr
