#pragma once
/// \file desktop_session.h
/// The desktop app without its window: a thin adapter around the live session both apps
/// share (app/live/live_session.h: pipeline, session builder, recording, autosave, regrowth
/// off the drawing thread, live edits, save and export). What is the desktop's own: an orbit
/// camera, the mouse as a simulated fingertip on a camera-facing plane, the keys the desktop
/// handles itself, the status its panel shows. The window (app/desktop/desktop_window.h)
/// feeds it GLFW's input and presents its scene; tests feed it directly. Controls:
/// docs/desktop.md.

#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "app/live/live_session.h"
#include "app/render/renderer.h"
#include "core/document.h"
#include "input/desktop_hand.h"
#include "input/pipeline.h"

namespace lobe {

/// GLFW codes of the keys the desktop app handles itself (the pipeline's keys are in
/// input/tools.h). Every key still goes into the recording; the pipeline ignores these.
namespace desktop_keys {
inline constexpr int kSave = 83;       // GLFW_KEY_S
inline constexpr int kExport = 87;     // GLFW_KEY_W: write the tree as .glb
inline constexpr int kFrame = 70;      // GLFW_KEY_F: frame the view on the scene
inline constexpr int kQuit = 256;      // GLFW_KEY_ESCAPE
inline constexpr int kLeftShift = 340, kRightShift = 344;
inline constexpr int kMouseLeft = 0, kMouseRight = 1, kMouseMiddle = 2;
} // namespace desktop_keys

/// A camera circling `target`: azimuth and elevation as ViewAngles (renderer.h).
struct OrbitCamera {
    glm::vec3 target{0.0f, 1.1f, 0.0f};
    float azimuth_deg = 0.0f;
    float elevation_deg = 10.0f;
    float distance_m = 2.2f;
    float fov_y_deg = 45.0f;

    glm::vec3 eye() const;
    glm::vec3 forward() const; ///< unit viewing direction
    Camera camera() const;
    /// The unit ray through window pixel (x, y) (origin top-left) of a width × height window.
    glm::vec3 ray(glm::vec2 pixel, int width, int height) const;
};

struct DesktopOptions {
    std::string session_path;  ///< Save writes here (atomically)
    std::string autosave_path; ///< written after every change of the document (empty: none)
    std::string record_path;   ///< the session's recording (empty: not recorded)
    std::string export_path;   ///< Export writes the tree here (.glb)
    /// The L-system sketch to start from (LiveSessionOptions::lsystem_sketch_file; empty: none).
    std::string lsystem_sketch_file;
    /// A regrowth is asked for after every change; false runs it on this thread instead
    /// (deterministic frames for tests: the scene is current after every frame()).
    bool background_regrowth = true;
};

/// What the panel shows about the session.
struct DesktopStatus {
    Tool tool = Tool::DrawLobe;
    bool grown = false;      ///< stage 3: the tree is shown and regrows after every change
    bool pinching = false;   ///< the simulated hand pinches (left button down, not over the panel)
    bool drawing = false;    ///< a stroke or drag is being made
    bool regrowing = false;  ///< a regrowth has been asked for and not yet arrived
    bool importing = false;  ///< a mesh import (import_mesh) is being made
    float depth_m = 0.0f;    ///< distance of the fingertip plane from the eye
    glm::vec3 tip{0.0f};
    std::size_t strokes = 0, lobes = 0, edits = 0;
    std::uint64_t revision = 0; ///< counts document changes
    std::string last_message;   ///< newest warning or result line
    std::string tree_error;     ///< why the last regrowth failed (empty: it did not)
    std::size_t tree_triangles = 0; ///< of the LOD drawn
    double wood_m3 = 0.0, co2_kg = 0.0; ///< of the tree shown (docs/wood-and-co2.md)
    int lod = 0;                    ///< the LOD drawn
};

class DesktopSession {
public:
    /// Starts from `doc` (a loaded session or an empty one).
    /// \throw FileError when the recording cannot be created.
    DesktopSession(Document doc, DesktopOptions options);
    ~DesktopSession();
    DesktopSession(const DesktopSession&) = delete;
    DesktopSession& operator=(const DesktopSession&) = delete;

    // Raw input, in the order it happened; applied by the next frame() at that frame's time.
    void mouse_move(float x, float y); ///< window pixels, origin top-left
    void mouse_button(int button, bool down);
    void mouse_wheel(float dy);
    void key(int key, bool down);
    /// A setting from the panel (recorded as an InputEventKind::Setting event).
    void setting(int id, std::int64_t lobe_id, double value);
    /// Imports a mesh file (OBJ, PLY, OFF) as a lobe: repaired, scaled so that its bounding
    /// box's largest side is `size_m` and remeshed to the attractor spacing on a thread of
    /// its own (a large mesh takes seconds; the frames go on), then placed centred on the
    /// fingertip by the first frame after it is done (one undo step). The mesh is written
    /// beside the recording (import_mesh_path) and recorded as an ImportMesh event, so replay
    /// makes the same lobe. False, with the reason in messages(), when the file does not
    /// exist, the size is out of range or another import is still being made; a file that
    /// cannot be made a lobe is reported in messages() when its import ends.
    bool import_mesh(const std::string& path, double size_m = 1.5);
    /// Waits until the import being made (if any) is done; the next frame places it (scripted
    /// runs, tests).
    void wait_for_import();
    /// The cursor is over the panel: the left button does not pinch while it is.
    void set_ui_capture(bool capture) { ui_capture_ = capture; }
    void set_cursor_inside(bool inside) { cursor_inside_ = inside; }

    /// One frame at `time` (seconds, increasing) in a width × height window: pending input,
    /// the simulated hand through the pipeline, the document, autosave, regrowth, the scene.
    void frame(double time, int width, int height);

    /// The scene to draw now (the tree or lobes last built, the strokes, the hand, the stroke
    /// being drawn). Valid until the next frame().
    const RenderScene& scene() const { return live_->scene(); }
    Camera camera() const { return orbit_.camera(); }
    OrbitCamera& orbit() { return orbit_; }
    const Document& document() const { return live_->document(); }
    /// The L-system sketch mode (P): its sketch, growth and tree.
    const LSystemSketchMode& lsystem_sketch() const { return live_->lsystem_sketch(); }
    const DesktopStatus& status() const { return status_; }
    /// Every warning and result line so far, oldest first (at most the last 200).
    const std::deque<std::string>& messages() const { return live_->messages(); }
    /// True once the Quit key was pressed.
    bool quit_requested() const { return quit_; }

    /// Saves the document to session_path (atomic). Returns false and says why in messages.
    bool save();
    /// Writes the current tree (.glb, 3 LODs) to export_path; false when there is no tree.
    bool export_tree();
    /// Level of detail the tree is drawn at (clamped to the LODs it has); the app lowers it
    /// when frames take too long.
    void set_lod(int lod);
    int lod() const { return live_->view().lod(); }
    /// Frames the camera on everything drawn (the strokes when nothing is built).
    void frame_view_on_scene();
    /// Waits until the lobes/tree of the current document are built (scripted runs).
    void wait_for_regrowth();
    /// Ends the session: finishes a stroke being drawn, flushes and closes the recording.
    void finish(double time);

private:
    void handle(const InputEvent& e, int height);
    void take_import(bool wait);
    void add_frame_items();

    OrbitCamera orbit_;
    std::unique_ptr<LiveSession> live_;
    std::vector<InputEvent> pending_;
    glm::vec2 cursor_{0.0f};
    bool cursor_seen_ = false, cursor_inside_ = true, ui_capture_ = false;
    bool left_down_ = false, right_down_ = false, middle_down_ = false, shift_ = false, pinch_ = false;
    bool quit_ = false;
    float depth_m_ = 0.0f; ///< fingertip plane distance from the eye (0: through the orbit target)
    double time_ = 0.0;
    HandState last_hand_; ///< the simulated hand of the last frame (drawn)
    std::uint64_t dynamic_version_ = 0;
    DesktopStatus status_;
};

} // namespace lobe
