#pragma once
/// \file live_session.h
/// What the desktop and VR apps share: one live sketching session. Input events and hand
/// frames go in, in the order they happened; they are recorded, run through the same input
/// pipeline and session builder as replay, and every change of the document is autosaved
/// and regrown off the frame thread. The session keeps the scene of the document (lobes,
/// tree, strokes, and what an editing drag shows live), the messages, and saves and exports.
///
/// The apps are thin adapters around it: the desktop (app/desktop/desktop_session.h) turns the
/// mouse into a simulated fingertip and moves an orbit camera; the VR app
/// (app/vr/vr_session.h) takes tracked hands, runs the in-VR panel and the two-handed scene
/// grab. Each frame an adapter calls, in order: push_event for the frame's raw events,
/// push_frame, apply_actions, its own commands (save, export, …), update, then appends its
/// own items to begin_frame_items().

#include <cstdint>
#include <deque>
#include <functional>
#include <future>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "app/live/autosave.h"
#include "app/live/drag_preview.h"
#include "app/live/live_edit_view.h"
#include "app/live/lsystem_sketch_mode.h"
#include "app/live/lsystem_sketch_view.h"
#include "app/live/regrow_worker.h"
#include "app/live/session_scene.h"
#include "app/session/session_builder.h"
#include "core/document.h"
#include "input/pipeline.h"
#include "input/recording.h"

namespace lobe {

struct LiveSessionOptions {
    std::string session_path;  ///< save() writes here (atomically)
    std::string autosave_path; ///< written after every change of the document (empty: none)
    std::string record_path;   ///< the session's recording (empty: not recorded)
    std::string export_path;   ///< export_tree() writes the tree here (.glb)
    RecordingHeader recording_header; ///< source, device and frame rate of the recording
    /// The recording is flushed every this many frames: a crash loses at most that much input.
    int recording_flush_frames = 9;
    /// A regrowth is asked for after every change; false runs it on the frame thread instead
    /// (deterministic frames for tests: the scene is current after every update()).
    bool background_regrowth = true;
    int lod = 0; ///< the tree's level of detail shown
    /// The app's words in messages: its command ("desktop", "vr"), how to grow ("G", "GROW on
    /// the panel") and where the export file comes from (empty: nothing said).
    std::string app = "desktop";
    std::string grow_hint = "G";
    std::string export_file_hint;
    /// Why meshes cannot be imported into this app (empty: they can; import_mesh).
    std::string imports_refused;
    /// Where the L-system sketch mode's platform stands (keys::kLSystemSketch turns it on).
    SketchPlatform lsystem_platform;
    /// A sketch file the L-system sketch mode starts from (the one saved beside an opened
    /// session, or an autosave's): empty or missing, none. Untrusted: one that does not load
    /// is one message line, the mode starts empty and the file is left as it is.
    std::string lsystem_sketch_file;
};

class LiveSession {
public:
    /// Starts from `doc` (a loaded session or an empty one), and the L-system sketch of
    /// options.lsystem_sketch_file when there is one.
    /// \throw FileError when the recording cannot be created.
    LiveSession(Document doc, LiveSessionOptions options);
    /// Finishes the session (finish_input, close) when the app did not.
    ~LiveSession();
    LiveSession(const LiveSession&) = delete;
    LiveSession& operator=(const LiveSession&) = delete;

    // --- Input, in the order it happened --------------------------------------------------
    /// A raw event (key, setting, mouse, scene move, import) at its time: recorded, then to the
    /// pipeline (which acts on keys, settings, scene moves and imports).
    void push_event(const InputEvent& e);
    /// A frame of both hands (document space for the pipeline: the adapter applies its scene
    /// transform through the pipeline): to the pipeline, then recorded.
    void push_frame(const HandFrame& frame);
    /// The actions the pipeline derived go to the session builder; every change is one
    /// revision, autosaved and regrown.
    void apply_actions();
    /// Once per frame after the commands: the newest regrowth taken (when in the background),
    /// the live edit views and drag previews, autosave failures reported.
    void update();

    // --- Imports (mesh files as lobes) ----------------------------------------------------
    /// Imports a mesh file (OBJ, PLY, OFF) as a lobe: repaired, scaled so that its bounding
    /// box's largest side is `size_m` and remeshed to the attractor spacing on a thread of its
    /// own, then placed centred on the fingertip by the ImportMesh event that take_import
    /// makes (one undo step). The mesh is written beside the recording (import_mesh_path), so
    /// replay makes the same lobe. False, with the reason in messages(), when the app takes
    /// no imports, the file does not exist, the size is out of range or another import is
    /// being made; a file that cannot be made a lobe is reported when its import ends.
    bool import_mesh(const std::string& path, double size_m = 1.5);
    /// The import being made, if it is done (or at once with `wait`): its ImportMesh event,
    /// for the adapter to push at the frame's time. Nothing while none is done.
    std::optional<InputEvent> take_import(bool wait);
    bool importing() const { return import_.has_value(); }

    // --- Regrowth -------------------------------------------------------------------------
    /// Waits until the lobes/tree of the current document are built and taken.
    void wait_for_regrowth();
    bool grown() const { return grown_; }
    /// A regrowth was asked for and has not arrived yet.
    bool regrowing() const;
    /// The newest regrowth result taken (its scene items are in scene()).
    const RegrowResult* built() const { return built_ ? &*built_ : nullptr; }
    /// The lobe shown in place of lobe `lobe_id` while it is edited live; null: the built one.
    const TriangleMesh* live_lobe(std::int64_t lobe_id) const;

    // --- Scene ----------------------------------------------------------------------------
    SessionScene& view() { return scene_; }
    const SessionScene& view() const { return scene_; }
    const RenderScene& scene() const { return scene_.scene(); }
    /// The scene cut back to the document's items and the L-system sketch mode's, for the
    /// adapter to add this frame's own.
    RenderScene& begin_frame_items();
    /// The L-system sketch mode (its sketch and tree; it reads the same raw input as the
    /// pipeline, and save() writes its sketch beside the session).
    const LSystemSketchMode& lsystem_sketch() const { return lsystem_sketch_; }
    /// Shows the tree at `lod` (the desktop lowers it when frames take too long).
    void set_lod(int lod);

    // --- The document and what was said ---------------------------------------------------
    const Document& document() const { return builder_->document(); }
    const InputPipeline& pipeline() const { return pipeline_; }
    std::uint64_t revision() const { return revision_; }
    /// Every warning and result line so far, oldest first (at most the last 200).
    const std::deque<std::string>& messages() const { return messages_; }
    /// The newest line of messages(), or a drag preview's report (see take_regrowth).
    const std::string& last_message() const { return last_message_; }
    /// Why the last regrowth of the document failed (empty: it did not).
    const std::string& tree_error() const { return tree_error_; }
    void note(std::string line);

    // --- Saving ---------------------------------------------------------------------------
    /// Saves the document to session_path (atomic), and an L-system sketch (of at least one
    /// trunk section) beside it as lsystem_sketch_path(). False, with the reason in messages().
    bool save();
    /// Writes the current tree (.glb, every LOD, with lobes and strokes) to export_path;
    /// false, with the reason in messages(), when there is no tree or no file.
    bool export_tree();

    // --- The end --------------------------------------------------------------------------
    /// Ends the input: strokes being drawn are finished and their actions applied; autosaves
    /// from here on hold the end of the recording. Returns the revision before.
    std::uint64_t finish_input();
    /// Closes the session after finish_input and the app's last commands: the last autosave
    /// is written again when the end changed nothing since `revision_before` (so `recover`
    /// sees that nothing is left to replay), autosaves are waited for, the recording closed.
    void close(std::uint64_t revision_before);
    bool finished() const { return finished_; }

private:
    void document_changed();
    /// Loads options_.lsystem_sketch_file into the sketch mode (a failure is one message line).
    void load_lsystem_sketch();
    void autosave();
    void report_autosave_failures();
    /// The L-system sketch beside the autosave (lsystem_sketch_path(autosave_path); removed
    /// when there is none) when it changed since it was last handed over. Called by autosave()
    /// `with_document` just submitted; else (every update) a sketch changed before this
    /// session's first autosave makes that autosave, with the document.
    void autosave_lsystem_sketch(bool with_document);
    /// The sketch file's text as save() writes it beside the session; "" when there is no
    /// sketch (fewer than two trunk nodes).
    std::string lsystem_sketch_text() const;
    /// Notes the sketch mode's messages not noted yet.
    void note_lsystem_messages();
    void request_regrowth();
    void submit_preview(Document doc);
    void take_regrowth(std::optional<RegrowResult> result);
    void update_live_edits();
    /// The lobe an editing drag shows goes into the grown items in place of the built one
    /// (when it `changed`, or the items are a new regrowth's).
    void place_live_lobe(bool changed);
    void show_strokes();

    LiveSessionOptions options_;
    InputPipeline pipeline_;
    std::unique_ptr<SessionBuilder> builder_;
    std::unique_ptr<RecordingWriter> recording_;
    std::unique_ptr<AutosaveWriter> autosaver_;
    SessionScene scene_;
    std::unique_ptr<RegrowWorker> worker_; ///< after scene_: its thread uses it until joined

    std::map<int, std::shared_ptr<const LobeModel>> imports_; ///< this session's imports by number
    /// The import being made on its own thread: its number, file and result.
    struct PendingImport {
        int number = 0;
        std::string path;
        std::future<std::shared_ptr<const LobeModel>> model;
    };
    std::optional<PendingImport> import_;

    bool finished_ = false, closed_ = false;
    std::uint64_t frames_recorded_ = 0; ///< hand frames appended to the recording (Document::recording_frames)
    bool grown_ = false;
    std::uint64_t revision_ = 0, requested_generation_ = 0, preview_generation_ = 0;
    std::optional<RegrowResult> built_;
    std::size_t builder_messages_seen_ = 0;

    LiveEditView deform_{LiveEditKind::Deform};
    LiveEditView transform_{LiveEditKind::Transform};
    LiveEditView bend_{LiveEditKind::Bend};
    DragPreview drag_preview_; ///< the document as an editing drag would leave it, regrown while it goes on
    std::optional<std::size_t> live_shown_; ///< the grown lobe item showing a live lobe
    std::uint64_t live_shown_generation_ = 0;

    std::deque<std::string> messages_;
    std::string last_message_, tree_error_;

    LSystemSketchMode lsystem_sketch_;
    LSystemSketchView lsystem_view_;
    std::size_t lsystem_messages_seen_ = 0;
    /// The sketch file text last handed to the autosave (empty: removed); none before the first.
    std::optional<std::string> lsystem_autosaved_;
    bool document_autosaved_ = false; ///< this session has submitted an autosave of its document
    std::uint64_t lsystem_autosaved_generation_ = 0;
};

/// Where save() writes the L-system sketch of the session saved at `session_path`:
/// "NAME.lsystem-sketch.json" beside "NAME.json" (docs/lsystem-sketch.md); the autosave
/// keeps its own beside the autosave, and `recover` puts it beside the recovered session.
std::string lsystem_sketch_path(const std::string& session_path);

} // namespace lobe
