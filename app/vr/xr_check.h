#pragma once
/// \file xr_check.h
/// Checked OpenXR calls for the VR host's .cpp files (includes openxr.h: never include this
/// from a header that other code includes). LOBE_XR_CHECK(xrCreateSession(...)) throws an
/// XrFailure naming the call as written, its XrResult and file:line, like hello_xr's
/// CHECK_XRCMD (and the renderer's CHECK_VKCMD, app/render/vk_check.h). Calls whose failure
/// means something else by contract (no runtime, no headset: XrUnavailable; a lost session:
/// reconnect) check their result where they are made and name the call the same way
/// (failed_call).

#include <string>

#include <openxr/openxr.h>
#include <openxr/openxr_reflection.h>

#include "app/vr/vr_xr.h"

namespace lobe::xr {

/// The XrResult's name ("XR_ERROR_SESSION_LOST").
inline const char* result_name(XrResult r)
{
    switch (r) {
#define LOBE_XR_RESULT_CASE(name, value) \
    case name: return #name;
        XR_LIST_ENUM_XrResult(LOBE_XR_RESULT_CASE)
#undef LOBE_XR_RESULT_CASE
    default: return "an unknown XrResult";
    }
}

/// "OpenXR: <call> failed with <result> (<code>)".
inline std::string failed_call(const char* call, XrResult r)
{
    return std::string("OpenXR: ") + call + " failed with " + result_name(r) + " (" + std::to_string(int(r)) + ")";
}

/// The source file as the project names it: the build's relative prefix ("../../") dropped.
inline const char* source_name(const char* file)
{
    while (file[0] == '.' && file[1] == '.' && file[2] == '/') file += 3;
    return file;
}

inline void check(XrResult r, const char* call, const char* file, int line)
{
    if (XR_FAILED(r))
        throw XrFailure(failed_call(call, r) + " at " + source_name(file) + ":" + std::to_string(line));
}

} // namespace lobe::xr

#define LOBE_XR_CHECK(call) ::lobe::xr::check((call), #call, __FILE__, __LINE__)
