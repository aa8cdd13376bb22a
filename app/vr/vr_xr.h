#pragma once
/// \file vr_xr.h
/// The OpenXR host of `lobesketch vr`: the instance (through the system OpenXR loader, with
/// XR_EXT_hand_tracking and XR_KHR_vulkan_enable2), the headset, the renderer on the Vulkan
/// device the runtime asks for, the session and its state machine, one colour swapchain per
/// eye and the frame loop. Every frame it locates both hands and the head in the stage space,
/// feeds them to a VrSession (app/vr/vr_session.h) and draws the session's scene into both eyes.
/// No OpenXR or Vulkan type appears here (app/vr/vr_xr.cpp has them). Running, runtimes and
/// what happens when the headset goes away: docs/vr.md.
///
/// ```cpp
/// XrHost host(XrHostOptions{});           // refuses in one line (XrUnavailable) without a runtime, hands or Vulkan
/// VrOptions o; o.runtime_name = host.runtime_name(); o.device_name = host.system_name();
/// VrSession session(doc, o);
/// XrRunResult r = host.run(session);     // until the runtime ends the session, Quit, or SIGINT/SIGTERM
/// session.finish(r.last_time);
/// ```

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "core/errors.h"

namespace lobe {

class Renderer;
class VrSession;

/// OpenXR cannot be used for `lobesketch vr`: no runtime, no headset, no hand tracking or no
/// Vulkan. The message is one line and names what to install or set.
class XrUnavailable : public Error {
public:
    using Error::Error;
};

/// An OpenXR call failed where nothing sensible can go on; the message names the call and
/// its result.
class XrFailure : public Error {
public:
    using Error::Error;
};

/// What the frame loop has done so far (for status lines).
struct XrFrameStats {
    std::uint64_t frames = 0;   ///< frames fed to the session
    std::uint64_t rendered = 0; ///< frames with a projection layer
    double time = 0.0;          ///< seconds since the first frame (the session's clock)
    double frame_ms = 0.0;      ///< mean wall-clock time per frame over the last status period
    const char* state = "idle"; ///< the session state, lower case
};

struct XrHostOptions {
    /// Caps each side of an eye's image (0: the runtime's recommended size). The aspect ratio
    /// is kept.
    int max_view_size = 0;
    /// After the session or the instance is lost (headset unplugged, runtime restarted), how
    /// long to try to get a new one before ending cleanly. 0: end at once.
    double reconnect_seconds = 10.0;
    /// MSAA samples of the renderer (1, 2, 4, 8).
    int samples = 4;
    /// Warnings and notices, one line each (e.g. "no STAGE space: using LOCAL").
    std::function<void(const std::string&)> message;
    /// Called about once a second of wall-clock time while frames run.
    std::function<void(const VrSession&, const XrFrameStats&)> status;
    /// Install SIGINT/SIGTERM handlers while the host exists: during run() they ask the
    /// runtime to end the session (xrRequestExitSession), a second signal ends it without
    /// waiting; one that came before run() makes it end at once.
    bool handle_signals = true;
};

/// How run() ended.
struct XrRunResult {
    enum class End {
        RuntimeExit,  ///< the runtime ended the session (EXITING), e.g. its menu or the end of a replay
        Quit,         ///< VrSession::quit_requested()
        Signal,       ///< SIGINT or SIGTERM
        Lost,         ///< the session or instance was lost and did not come back in time
    } end = End::RuntimeExit;
    double last_time = 0.0; ///< the session clock at the last frame fed (for VrSession::finish)
    std::uint64_t frames = 0;
    std::uint64_t rendered = 0;
    int sessions = 0;       ///< OpenXR sessions begun (more than 1 after a reconnection)
    std::string message;    ///< one line saying why it ended
};

/// "runtime-exit", "quit", "signal", "lost".
const char* end_name(XrRunResult::End end);

class XrHost {
public:
    /// Creates the instance, finds the headset, checks hand tracking and Vulkan, and makes
    /// the renderer on the runtime's Vulkan device.
    /// \throw XrUnavailable (one line naming what to install) when there is no runtime, no
    /// headset, no hand tracking or no Vulkan; RenderUnavailable, RenderError, XrFailure.
    explicit XrHost(XrHostOptions options = {});
    ~XrHost();
    XrHost(const XrHost&) = delete;
    XrHost& operator=(const XrHost&) = delete;

    const std::string& runtime_name() const; ///< "openxr:<runtime name> <version>"
    const std::string& system_name() const;  ///< the headset's name as the runtime gives it
    Renderer& renderer();
    /// The session clock at the last frame fed (0 before any): for VrSession::finish when
    /// run() threw.
    double last_time() const;

    /// Runs sessions and frames until the runtime ends the session, `session` asks to quit,
    /// a signal arrives, or the session is lost and not back within reconnect_seconds (the
    /// document is saved when it is lost). Never waits without a bound. Does not call
    /// VrSession::finish (the caller does, on every path).
    /// \throw XrFailure, RenderError for failures that end the session; the caller finishes
    /// the VrSession and reports.
    XrRunResult run(VrSession& session);

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

} // namespace lobe
