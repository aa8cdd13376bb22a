#pragma once
/// \file desktop_panel.h
/// The desktop app's panel (Dear ImGui, drawn by the renderer's overlay): status, stages and
/// tools, edits under the fingertip, appearance settings for the tree or one lobe, mesh
/// import, file. Buttons press the keys the keyboard has, so the recording holds key events
/// either way; settings are sent as Setting events when a slider is let go. The panel is the
/// desktop's half of the in-app controls; the VR panel (app/vr/vr_session.h) has the same
/// actions as buttons. Controls: docs/desktop.md.

#include <array>
#include <optional>
#include <string>

#include "core/grower_choice.h"

namespace lobe {

class DesktopSession;

/// What the panel keeps between frames.
struct DesktopPanelState {
    int target_lobe = 0; ///< the lobe the appearance settings go to (0: the whole tree)
    std::array<char, 1024> import_path{};
    float import_size_m = 1.5f;
    /// The growth steps shown for the grower choice `steps_of` (growth_steps; worked out once
    /// per choice: for an L-system it means parsing it). The default grower has no steps.
    GrowerChoice steps_of;
    std::optional<int> steps;
};

/// Width of the panel in pixels (the sketch is drawn right of it).
inline constexpr float kDesktopPanelWidth = 250.0f;

/// Draws the panel into the current ImGui frame (between ImGui::NewFrame and ImGui::Render)
/// for a window `height` pixels tall; what it presses goes to `session`.
void draw_desktop_panel(DesktopSession& session, const std::string& session_name, DesktopPanelState& state,
                        float height);

} // namespace lobe
