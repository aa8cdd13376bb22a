#pragma once
/// \file desktop_window.h
/// The window host of `lobesketch desktop`, shaped like the VR app's OpenXR host
/// (app/vr/vr_xr.h): a GLFW window, the renderer presenting into it, the Dear ImGui panel
/// (app/desktop/desktop_panel.h) drawn as the renderer's overlay, and the frame loop that
/// feeds the mouse and keys (or a script's steps) to a DesktopSession
/// (app/desktop/desktop_session.h) and presents its scene. No GLFW, ImGui or Vulkan type
/// appears here. Controls and scripts: docs/desktop.md.
///
/// ```cpp
/// DesktopWindow window(DesktopWindowOptions{});   // RenderUnavailable in one line without a display or Vulkan
/// DesktopSession session(doc, options);
/// DesktopRunResult r = window.run(session);       // until the window closes, Quit, the script ends or --frames
/// session.finish(0.0);
/// ```

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "app/desktop/desktop_script.h"

namespace lobe {

class DesktopSession;
class Renderer;

struct DesktopWindowOptions {
    int width = 1280, height = 800; ///< the window's size in pixels
    std::string title = "Lobesketch";
    bool software = false; ///< render with lavapipe even when a GPU is present
    int samples = 4;       ///< MSAA samples (1, 2, 4, 8)
    /// The tree's level of detail; -1: the finest that keeps frames under 40 ms (adaptive).
    int lod = -1;
    /// Close after this many frames (0: when the window is closed).
    int frames = 0;
    /// Scripted mouse and keys instead of the real ones (parse_desktop_script): frames are
    /// then exactly 60 Hz and each `wait` lets the regrowth finish, so a run is the same every
    /// time. The run ends after the last step.
    std::vector<ScriptStep> script;
    /// With a script: receives one JSON line per `mark` step (the document's summary).
    std::function<void(const std::string&)> mark;
};

/// What run() did.
struct DesktopRunResult {
    std::size_t frames = 0;
    double median_session_ms = 0.0; ///< input, session and scene per frame
    double median_present_ms = 0.0; ///< drawing and presenting per frame
};

class DesktopWindow {
public:
    /// Opens the window and makes the renderer for it.
    /// \throw RenderUnavailable (one line: set DISPLAY or use xvfb-run; install the Vulkan
    /// loader) when there is no display or no Vulkan; RenderError.
    explicit DesktopWindow(DesktopWindowOptions options);
    ~DesktopWindow();
    DesktopWindow(const DesktopWindow&) = delete;
    DesktopWindow& operator=(const DesktopWindow&) = delete;

    Renderer& renderer();

    /// Runs frames until the window is closed, `session` asks to quit, the script ends or the
    /// frame count is reached. Does not call DesktopSession::finish (the caller does).
    DesktopRunResult run(DesktopSession& session, const std::string& session_name);

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// The script log's line for a `mark` step: the document's strokes, lobes, edits, settings,
/// seed, and the tree's triangles, error and last message, as JSON.
std::string desktop_mark_json(const DesktopSession& session, const std::string& label, int frame);

} // namespace lobe
