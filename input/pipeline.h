#pragma once
/// \file pipeline.h
/// Hand frames → pen events → raw strokes. Feeds frames and raw events through the gesture
/// recogniser and turns pinches into what the active tool says: a stroke (draw tools) or a
/// drag (editing tools); keys and panel settings become actions too. The same code runs live (VR, desktop) and on replay, so a session is
/// a deterministic function of its recording and settings.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

#include "core/settings.h"
#include "core/stroke.h"
#include "input/gestures.h"
#include "input/recording.h"
#include "input/tools.h"

namespace lobe {

/// Where the document sits in stage space: stage = R_y(yaw) · scale · document + translation.
/// Scene events (the VR app's two-handed grab) change it; it starts as the identity. Gestures
/// are recognised on the hands as tracked (stage space: pinch distances stay physical); the
/// points they make (stroke points, drag paths, fingertips of key actions) are taken into the
/// document through the inverse.
struct SceneTransform {
    float scale = 1.0f;
    float yaw = 0.0f; ///< radians about +Y
    glm::vec3 translation{0.0f};

    glm::vec3 to_stage(const glm::vec3& document_point) const;
    glm::vec3 to_document(const glm::vec3& stage_point) const;
    glm::quat rotation() const; ///< R_y(yaw)
    bool identity() const { return scale == 1.0f && yaw == 0.0f && translation == glm::vec3(0.0f); }
    /// Sets one component (a Scene event's code and value; input/recording.h).
    void set(SceneComponent component, float value);
};

/// A pinch-move-release made under an editing tool (deform a lobe, bend a stroke segment,
/// move, rotate or scale a lobe): the path of the pinch point.
struct Drag {
    Tool tool = Tool::DeformLobe;
    Hand hand = Hand::Right;
    std::vector<StrokePoint> path;
    /// EditStroke only: the other hand's filtered index tip when the drag started, present
    /// when that hand was tracked and pointing (index straight, the other fingers curled).
    /// The two fingertips then pick the ends of the stroke segment (docs/editing.md).
    std::optional<glm::vec3> other_tip;
};

/// A Setting event as the session builder applies it.
struct SettingChange {
    SettingId id = SettingId::SplitAngle;
    std::int64_t lobe = 0; ///< 0: the whole tree
    /// The event's number (a float in the recording) as the double with the same shortest
    /// decimal text, so a slider at 0.03 sets exactly 0.03.
    double value = 0.0;
};

/// Something the person did, derived from raw input, in the order it happened.
struct InputAction {
    enum class Type : std::uint8_t {
        StrokeCompleted, ///< `stroke` holds the finished stroke (already given its id)
        StrokeDiscarded, ///< `message` says why (too short, too few points)
        DragCompleted,   ///< `drag`
        ToolChanged,     ///< `tool`
        NewLobe,         ///< the next lobe stroke starts a new lobe
        Grow, Undo, Redo,
        DeleteStroke,    ///< delete the stroke at `tip`
        DeleteLobe,      ///< delete the lobe at `tip` (its strokes too)
        Duplicate,       ///< copy the lobe (else the trunk stroke) at `tip` beside itself
        Mirror,          ///< mirror the lobe (else the trunk stroke) at `tip` across the trunk's plane
        SettingChanged,  ///< `setting`
        ImportMesh,      ///< import mesh `import_number` as a lobe centred on `tip` (recording.h, InputEventKind::ImportMesh)
    } type = Type::StrokeCompleted;
    double time = 0.0;
    Stroke stroke;
    Drag drag;
    Tool tool = Tool::DrawLobe;
    std::string message;
    /// DeleteStroke, DeleteLobe, Duplicate, Mirror, ImportMesh: the filtered index tip of the right hand
    /// when the key was pressed, else the left hand's (`tip_hand` says which); absent when
    /// neither hand was tracked.
    std::optional<glm::vec3> tip;
    Hand tip_hand = Hand::Right;
    SettingChange setting;
    int import_number = 0;
};

const char* action_name(InputAction::Type t);

/// The incremental pipeline (one per session). Feed raw events and frames in time order.
class InputPipeline {
public:
    explicit InputPipeline(const InputOptions& options = {});

    void push_event(const InputEvent& event);
    void push_frame(const HandFrame& frame);
    /// End of input: finishes strokes still being drawn.
    void finish();

    /// Actions since the last call, in time order.
    std::vector<InputAction> take_actions();
    const GestureRecognizer& gestures() const { return gestures_; }
    Tool tool() const { return tool_; }
    /// The L-system sketch mode is on (keys::kLSystemSketch toggles it): pinches draw
    /// nothing and other keys do nothing here.
    bool lsystem_sketch() const { return lsystem_sketch_; }
    /// Where the document sits in stage space (Scene events).
    const SceneTransform& scene_transform() const { return scene_; }
    /// True while `hand` is drawing; `current_stroke` then holds the points so far.
    bool drawing(Hand hand) const { return pen_[static_cast<int>(hand)].down; }
    const Stroke& current_stroke(Hand hand) const { return pen_[static_cast<int>(hand)].stroke; }
    /// The editing tool of the drag `hand` is making (its path so far in current_stroke);
    /// nothing while it is not dragging.
    std::optional<Tool> drag_tool(Hand hand) const
    {
        const Pen& pen = pen_[static_cast<int>(hand)];
        return pen.down && pen.drag ? std::optional<Tool>(pen.tool) : std::nullopt;
    }
    /// While `hand` makes an edit-stroke drag: the other hand's pointing fingertip when it
    /// started (Drag::other_tip of the drag its release will complete).
    std::optional<glm::vec3> drag_other_tip(Hand hand) const { return pen_[static_cast<int>(hand)].other_tip; }

private:
    /// The right hand's filtered index tip if it is tracked, else the left hand's.
    void attach_tip(InputAction& a) const;
    struct Pen {
        bool down = false;
        bool drag = false;   ///< an editing-tool pinch rather than a drawn stroke
        Tool tool = Tool::DrawLobe;
        Stroke stroke;
        std::optional<glm::vec3> other_tip; ///< see Drag::other_tip
        double last_good_t = 0.0;
    };
    void pen_down(int h, const HandGesture& g, double t);
    void pen_move(int h, const HandGesture& g, double t);
    void pen_up(int h, double t);

    InputOptions options_;
    GestureRecognizer gestures_;
    Tool tool_ = Tool::DrawLobe;
    bool lsystem_sketch_ = false;
    std::array<Pen, kHandCount> pen_{};
    std::int64_t next_stroke_id_ = 1;
    double last_time_ = 0.0;
    SceneTransform scene_;
    std::vector<InputAction> actions_;
};

/// Everything a recording yields.
struct InputResult {
    std::vector<InputAction> actions;
    std::vector<Stroke> strokes;   ///< the completed strokes, in order
    std::vector<Drag> drags;
    std::vector<std::string> messages; ///< discarded strokes and annotation mismatches
    std::size_t pinches = 0, grabs = 0, points = 0; ///< started gestures, both hands
};

/// Replays a whole recording (events merged with frames by time) through the pipeline and
/// checks the recording's annotations against what replay derived.
InputResult run_input_pipeline(const Recording& rec, const InputOptions& options = {});

/// Annotations a live session writes beside the raw input for each derived action
/// ("stroke id=3 kind=lobe points=120"); replay compares, never applies them.
std::string annotation_for(const InputAction& action);

} // namespace lobe
