#pragma once
/// \file vk_check.h
/// Checked Vulkan calls for the renderer's .cpp files (never include this from a header that
/// non-render code includes): CHECK_VKCMD(vkCreateFence(...)) throws a RenderError naming
/// the call as written, its VkResult and file:line, like hello_xr's CHECK_XRCMD.
/// CHECK_VKCMD_ALLOW(call, result) does the same but lets one error result through to the
/// caller (VK_ERROR_OUT_OF_DATE_KHR from acquire and present: the swapchain is remade).
///
/// Every Vulkan call that returns a VkResult goes through one of the two, except where a
/// failure is not a RenderError by contract (app/render/renderer.h): vkCreateInstance and
/// vkCreateDevice (and the RendererOptions::vulkan_hooks) throw RenderUnavailable naming the
/// call and its result; the extension lists are probes (a list that cannot be read has
/// nothing in it); keep_vulkan_drivers_loaded does nothing without Vulkan; and teardown
/// (vkDeviceWaitIdle in destructors) cannot throw.

#include <string>

#include <vulkan/vulkan.h>

#include "app/render/renderer.h"

namespace lobe::vk {

inline const char* result_name(VkResult r)
{
    switch (r) {
#define LOBE_VK_RESULT(name) \
    case name: return #name;
        LOBE_VK_RESULT(VK_SUCCESS)
        LOBE_VK_RESULT(VK_NOT_READY)
        LOBE_VK_RESULT(VK_TIMEOUT)
        LOBE_VK_RESULT(VK_INCOMPLETE)
        LOBE_VK_RESULT(VK_ERROR_OUT_OF_HOST_MEMORY)
        LOBE_VK_RESULT(VK_ERROR_OUT_OF_DEVICE_MEMORY)
        LOBE_VK_RESULT(VK_ERROR_INITIALIZATION_FAILED)
        LOBE_VK_RESULT(VK_ERROR_DEVICE_LOST)
        LOBE_VK_RESULT(VK_ERROR_MEMORY_MAP_FAILED)
        LOBE_VK_RESULT(VK_ERROR_LAYER_NOT_PRESENT)
        LOBE_VK_RESULT(VK_ERROR_EXTENSION_NOT_PRESENT)
        LOBE_VK_RESULT(VK_ERROR_FEATURE_NOT_PRESENT)
        LOBE_VK_RESULT(VK_ERROR_INCOMPATIBLE_DRIVER)
        LOBE_VK_RESULT(VK_ERROR_TOO_MANY_OBJECTS)
        LOBE_VK_RESULT(VK_ERROR_FORMAT_NOT_SUPPORTED)
        LOBE_VK_RESULT(VK_ERROR_FRAGMENTED_POOL)
        LOBE_VK_RESULT(VK_ERROR_OUT_OF_POOL_MEMORY)
        LOBE_VK_RESULT(VK_ERROR_SURFACE_LOST_KHR)
        LOBE_VK_RESULT(VK_ERROR_OUT_OF_DATE_KHR)
        LOBE_VK_RESULT(VK_SUBOPTIMAL_KHR)
#undef LOBE_VK_RESULT
    default: return "VK_ERROR_UNKNOWN";
    }
}

/// "render: <call> failed with <result> (<file>:<line>)".
[[noreturn]] inline void throw_vk_error(VkResult r, const char* call, const char* file, int line)
{
    throw RenderError(std::string("render: ") + call + " failed with " + result_name(r) + " (" + file + ":" +
                      std::to_string(line) + ")");
}

inline VkResult check(VkResult r, const char* call, const char* file, int line)
{
    if (r < VK_SUCCESS) throw_vk_error(r, call, file, line);
    return r;
}

/// check(), but `allowed` (an error the caller handles) is returned rather than thrown.
inline VkResult check_allowing(VkResult r, VkResult allowed, const char* call, const char* file, int line)
{
    if (r < VK_SUCCESS && r != allowed) throw_vk_error(r, call, file, line);
    return r;
}

} // namespace lobe::vk

/// Runs a Vulkan call and throws RenderError (call text, result, file:line) when it fails.
#define CHECK_VKCMD(cmd) ::lobe::vk::check((cmd), #cmd, __FILE__, __LINE__)
/// CHECK_VKCMD, but returns the error result `allowed` to the caller instead of throwing it.
#define CHECK_VKCMD_ALLOW(cmd, allowed) ::lobe::vk::check_allowing((cmd), (allowed), #cmd, __FILE__, __LINE__)
