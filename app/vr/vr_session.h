#pragma once
/// \file vr_session.h
/// The VR app without OpenXR: hand frames in stage space in, a scene to draw out. A thin
/// adapter around the live session both apps share (app/live/live_session.h: pipeline,
/// session builder, recording, autosave, regrowth off the frame thread, live edits, save and
/// export); what is VR's own is the in-VR panel (poked with a fingertip), the two-handed grab
/// that scales, turns and moves the whole scene, and the reference photo. `lobesketch vr`
/// (app/cli/cli_vr.cpp, app/vr/vr_xr.cpp) feeds it xrLocateHandJointsEXT results every frame and
/// draws its scene into both eyes; tests feed it recorded frames directly. Gestures and
/// panel: docs/vr.md.

#include <array>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

#include "app/live/live_session.h"
#include "app/render/renderer.h"
#include "core/document.h"
#include "input/pipeline.h"

namespace lobe {

/// Key codes the VR app handles itself (the pipeline's keys are in input/tools.h). Like the
/// desktop's, they are recorded and the pipeline ignores them.
namespace vr_keys {
inline constexpr int kSave = 83;       // S: save the session
inline constexpr int kExport = 87;     // W: write the tree as .glb
inline constexpr int kPlacePhoto = 80; // P: place the reference photo at the right index fingertip
inline constexpr int kQuit = 256;      // Escape: end the session
} // namespace vr_keys

struct VrOptions {
    std::string session_path;  ///< Save and the end of the session write here (atomically)
    std::string autosave_path; ///< written after every change of the document (empty: none)
    std::string record_path;   ///< the session's recording (empty: not recorded)
    std::string export_path;   ///< Export writes the tree here (.glb)
    /// The L-system sketch to start from (LiveSessionOptions::lsystem_sketch_file; empty: none).
    std::string lsystem_sketch_file;
    /// Events to apply at their times, as if the panel had been pressed (the event track of
    /// a recording played through an OpenXR runtime that cannot carry it, e.g. the replay
    /// runtime). Times are seconds from the first frame of that recording; frame times fed to
    /// frame() count from the first frame too.
    std::vector<InputEvent> events;
    /// The frame times of that recording, from its first frame (increasing). A frame whose
    /// time is within half a microsecond of one of them takes that time exactly: an OpenXR
    /// runtime hands times out in whole nanoseconds, and the filters would otherwise see
    /// steps a few nanoseconds off the recording's, so the strokes would differ from replay's
    /// in the last bits.
    std::vector<double> clock;
    std::string runtime_name; ///< written into the recording's header (source)
    std::string device_name;  ///< written into the recording's header (device)
    double nominal_rate_hz = 90.0;
    /// A regrowth is asked for after every change; false runs it on this thread instead
    /// (deterministic frames for tests: the scene is current after every frame()).
    bool background_regrowth = true;
    /// A picture (PNG or JPEG) to show in the scene; placed with the panel's Photo button.
    std::string photo_path;
};

/// What the state label by the right hand says, and what the status line of the CLI prints.
struct VrStatus {
    Tool tool = Tool::DrawLobe;
    bool grown = false;
    bool drawing = false;     ///< a stroke or drag is being made
    bool scaling = false;     ///< both hands grab: the scene follows them
    bool regrowing = false;   ///< a regrowth was asked for and has not arrived yet
    bool hands_tracked[2] = {false, false};
    std::size_t strokes = 0, lobes = 0, edits = 0;
    std::uint64_t revision = 0;
    std::string label;        ///< e.g. "draw lobe", "grow: regrowing"
    std::string last_message; ///< newest warning or result line
    std::string tree_error;
};

/// One button of the in-VR panel (stage space). Pressing it sends `key` (a Key event) or a
/// Setting event (`setting` non-zero: id, and `step` added to or multiplying the value).
struct VrButton {
    std::string text;
    int key = 0;
    int setting = 0;
    double step = 0.0;
    glm::vec3 centre{0.0f}; ///< stage space
    float half_width = 0.0f, half_height = 0.0f;
};

/// The panel: a board of buttons standing in the world in front of and below where the head
/// first was, turned to face it (it does not follow the head, so it never blocks sketching).
struct VrPanel {
    glm::vec3 origin{0.0f};      ///< centre of the board, stage space
    glm::quat orientation{1.0f, 0.0f, 0.0f, 0.0f}; ///< +Z of the board points at the person
    std::vector<VrButton> buttons;
};

/// The panel's layout for a head first seen at `head` (stage space).
VrPanel vr_panel_layout(const Pose& head);

class VrSession {
public:
    /// Starts from `doc` (a loaded session or an empty one).
    /// \throw FileError when the recording cannot be created or the photo cannot be read.
    VrSession(Document doc, VrOptions options);
    ~VrSession();
    VrSession(const VrSession&) = delete;
    VrSession& operator=(const VrSession&) = delete;

    /// One frame: `frame` holds both hands and the head in stage space at `frame.time`
    /// (seconds from the first frame, increasing; a hand not tracked is inactive). Runs the
    /// panel, the scene grab, the pipeline, the document, autosave, regrowth and the scene.
    void frame(const HandFrame& frame);

    /// The scene to draw now, in document space (draw it through scene_transform(): see
    /// eye_in_document). Valid until the next frame().
    const RenderScene& scene() const;
    const SceneTransform& scene_transform() const;
    /// An eye in stage space as the same eye in document space (the picture is the same).
    EyeView eye_in_document(const EyeView& stage_eye) const;

    const Document& document() const;
    /// The L-system sketch mode (the panel's L-SYSTEM row; app/live/lsystem_sketch_mode.h).
    const LSystemSketchMode& lsystem_sketch() const { return live_->lsystem_sketch(); }
    const VrStatus& status() const { return status_; }
    const VrPanel& panel() const { return panel_; }
    /// Every warning and result line so far, oldest first (at most the last 200).
    const std::deque<std::string>& messages() const;
    /// True once the panel's Quit was pressed.
    bool quit_requested() const { return quit_; }

    /// Saves the document to session_path (atomic). False, with the reason in messages().
    bool save();
    /// Writes the current tree (.glb, 3 LODs) to export_path; false when there is none.
    bool export_tree();
    /// Waits until the lobes/tree of the current document are built.
    void wait_for_regrowth();
    /// Ends the session: finishes a stroke being drawn, applies the remaining events, flushes
    /// and closes the recording, saves the session when there is a session_path.
    void finish(double time);

private:
    struct Impl;
    std::unique_ptr<LiveSession> live_; ///< what the desktop app shares (app/live/live_session.h)
    std::unique_ptr<Impl> impl_;        ///< the VR app's own: panel, scene grab, photo, hands drawn
    VrStatus status_;
    VrPanel panel_;
    bool quit_ = false;
};

} // namespace lobe
