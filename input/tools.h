#pragma once
/// \file tools.h
/// Raw key codes that select the active tool or act on what the fingertip is at. A pinch
/// means whatever the active tool says (draw, deform, select), never guessed. Codes are GLFW
/// key codes, so desktop keyboard input, synthesized scenarios and (later) in-VR panel
/// presses share one mapping. Panel settings are Setting events (input/recording.h).

#include <cstdint>

namespace lobe {

enum class Tool : std::uint8_t {
    DrawLobe = 0,  ///< pinch draws a lobe stroke (the default)
    DrawTrunk,     ///< pinch draws a trunk stroke
    DeformLobe,    ///< pinch near a lobe surface drags a handle (Laplacian editing)
    EditStroke,    ///< a drag bends a stroke segment as a Bézier curve (docs/editing.md)
    MoveLobe,      ///< a drag moves the lobe it starts on
    RotateLobe,    ///< a drag turns the lobe about its centre
    ScaleLobe,     ///< a drag scales the lobe uniformly about its centre
};

namespace keys {
inline constexpr int kDrawLobe = 76;   // GLFW_KEY_L
inline constexpr int kDrawTrunk = 84;  // GLFW_KEY_T
inline constexpr int kNewLobe = 78;    // GLFW_KEY_N: the next lobe stroke starts a new lobe
inline constexpr int kDeformLobe = 68; // GLFW_KEY_D
inline constexpr int kEditStroke = 69; // GLFW_KEY_E
inline constexpr int kMoveLobe = 77;   // GLFW_KEY_M
inline constexpr int kRotateLobe = 82; // GLFW_KEY_R
inline constexpr int kScaleLobe = 75;  // GLFW_KEY_K (S is the desktop app's save key)
inline constexpr int kGrow = 71;       // GLFW_KEY_G
inline constexpr int kUndo = 90;       // GLFW_KEY_Z
inline constexpr int kRedo = 89;       // GLFW_KEY_Y
/// GLFW_KEY_P: the L-system sketch mode on / off (app/live/lsystem_sketch_mode.h). While it is
/// on the pipeline draws nothing and acts on no other key: the hands and keys are the mode's.
inline constexpr int kLSystemSketch = 80;
// Actions on what the fingertip is at when the key is pressed (docs/editing.md, "Delete,
// duplicate, mirror"): the right hand's filtered index tip, else the left hand's.
inline constexpr int kDeleteStroke = 259; // GLFW_KEY_BACKSPACE: delete the stroke under the fingertip
inline constexpr int kDeleteLobe = 261;   // GLFW_KEY_DELETE: delete the lobe under the fingertip
inline constexpr int kDuplicate = 67;     // GLFW_KEY_C: copy the lobe (else trunk stroke) beside itself
inline constexpr int kMirror = 88;        // GLFW_KEY_X: mirror the lobe (else trunk stroke) across the trunk's plane
} // namespace keys

const char* tool_name(Tool t);

} // namespace lobe
