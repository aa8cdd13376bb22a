#pragma once
/// \file desktop_script.h
/// Scripted mouse and keyboard input for `lobesketch desktop --script FILE`: what a person
/// does with the mouse, frame by frame, so the real window and its whole input path can be
/// driven in tests. Format (docs/desktop.md): one command per line, `FRAME COMMAND ARGS…`,
/// frames non-decreasing, `#` starts a comment.

#include <cstdint>
#include <string>
#include <vector>

namespace lobe {

/// One primitive input step (the macros `circle` and `line` expand into these).
struct ScriptStep {
    enum class Kind { Move, Down, Up, Wheel, KeyPress, KeyRelease, Panel, Set, Import, Wait, Mark, Quit } kind = Kind::Move;
    int frame = 0;
    float x = 0.0f, y = 0.0f; ///< Move: pixels; Wheel: y = notches
    int code = 0;             ///< Down/Up: mouse button; Key*: GLFW key; Set: setting id
    double value = 0.0;       ///< Set: the value; Import: the size in metres
    std::int64_t lobe = 0;    ///< Set: lobe id (0 = the tree)
    std::string name;         ///< Panel: action name; Mark: label; Import: the mesh file
    int line = 0;             ///< source line, for messages
};

/// Panel buttons by name and the key each presses (draw-lobe → L, save → S, …).
struct PanelAction {
    const char* name;
    const char* label; ///< shown on the button
    int key;
};
const std::vector<PanelAction>& panel_actions();
/// The key of a panel action; -1 for an unknown name.
int panel_action_key(const std::string& name);

/// Settings the panel (and `set`) changes: name, InputEventKind::Setting id.
struct PanelSetting {
    const char* name;
    int id;
};
const std::vector<PanelSetting>& panel_settings();

/// Parses a script; steps sorted by frame (stable). At most 200,000 steps and frame 10^7.
/// \throw InvalidInput "NAME:LINE: what is wrong" (one line).
std::vector<ScriptStep> parse_desktop_script(const std::string& text, const std::string& name);

} // namespace lobe
