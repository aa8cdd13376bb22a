#pragma once
/// \file scene_parts.h
/// Small meshes the interactive apps draw over the sketch: the tracked hand, markers, flat
/// boards and text. Shared by the desktop (app/desktop/desktop_session.cpp) and VR
/// (app/vr/vr_session.cpp) sessions.

#include <array>
#include <string>

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

#include "core/hand_frame.h"
#include "growth/tree_geometry.h"
#include "input/tools.h"

namespace lobe {

/// The fingertip marker's colour says the tool, and so what a pinch does (linear RGBA).
std::array<float, 4> tool_color(Tool t);

/// A UV sphere appended to `g`.
void append_sphere(SurfaceGeometry& g, const glm::vec3& centre, float radius, int rings = 5, int segments = 8);

/// `part` appended to `into` (indices shifted).
void append_geometry(SurfaceGeometry& into, const SurfaceGeometry& part);

/// A hand as spheres at its joints (0.45 × each joint's radius) and tubes along its fingers;
/// empty when the hand is not active.
SurfaceGeometry hand_geometry(const HandState& hand);

/// A flat rectangle centred on `centre`, spanned by `orientation`'s X (width) and Y (height)
/// axes, facing its +Z, lifted `lift` along +Z; both sides drawn. uvs (0,0) top left to (1,1).
void append_board(SurfaceGeometry& g, const glm::vec3& centre, const glm::quat& orientation, float width,
                  float height, float lift = 0.0f);

/// `text` (ASCII) as flat quads, `height` tall per line, centred on `centre` in the plane of
/// `orientation` (X right, Y up, facing +Z), lifted `lift` along +Z. Non-printable characters
/// are skipped. Returns the width of the text.
float append_text(SurfaceGeometry& g, const std::string& text, const glm::vec3& centre, const glm::quat& orientation,
                  float height, float lift = 0.0f);

} // namespace lobe
