#include "input/pipeline.h"

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <map>

#include <glm/geometric.hpp>

namespace lobe {

const char* action_name(InputAction::Type t)
{
    switch (t) {
    case InputAction::Type::StrokeCompleted: return "stroke";
    case InputAction::Type::StrokeDiscarded: return "stroke-discarded";
    case InputAction::Type::DragCompleted: return "drag";
    case InputAction::Type::ToolChanged: return "tool";
    case InputAction::Type::NewLobe: return "new-lobe";
    case InputAction::Type::Grow: return "grow";
    case InputAction::Type::Undo: return "undo";
    case InputAction::Type::Redo: return "redo";
    case InputAction::Type::DeleteStroke: return "delete-stroke";
    case InputAction::Type::DeleteLobe: return "delete-lobe";
    case InputAction::Type::Duplicate: return "duplicate";
    case InputAction::Type::Mirror: return "mirror";
    case InputAction::Type::SettingChanged: return "setting";
    case InputAction::Type::ImportMesh: return "import-mesh";
    }
    return "unknown";
}

InputPipeline::InputPipeline(const InputOptions& options) : options_(options), gestures_(options) {}

namespace {

/// The double whose shortest decimal text is the float's (0.03f → 0.03).
double shortest_double(float x)
{
    char buf[32];
    const auto r = std::to_chars(buf, buf + sizeof buf, x);
    double d = static_cast<double>(x);
    if (r.ec == std::errc()) std::from_chars(buf, r.ptr, d);
    return d;
}

} // namespace

glm::quat SceneTransform::rotation() const { return glm::angleAxis(yaw, glm::vec3(0.0f, 1.0f, 0.0f)); }

glm::vec3 SceneTransform::to_stage(const glm::vec3& p) const { return rotation() * (scale * p) + translation; }

glm::vec3 SceneTransform::to_document(const glm::vec3& p) const
{
    if (identity()) return p; // bit-exact for sessions that never move the scene
    return (glm::inverse(rotation()) * (p - translation)) / scale;
}

void SceneTransform::set(SceneComponent component, float value)
{
    switch (component) {
    case SceneComponent::Scale: scale = value; break;
    case SceneComponent::Yaw: yaw = value; break;
    case SceneComponent::TranslationX: translation.x = value; break;
    case SceneComponent::TranslationY: translation.y = value; break;
    case SceneComponent::TranslationZ: translation.z = value; break;
    }
}

void InputPipeline::attach_tip(InputAction& a) const
{
    for (Hand h : {Hand::Right, Hand::Left}) {
        const HandGesture& g = gestures_.hand(h);
        if (!g.tracked) continue;
        a.tip = scene_.to_document(g.index_tip);
        a.tip_hand = h;
        return;
    }
}

void InputPipeline::push_event(const InputEvent& event)
{
    last_time_ = std::max(last_time_, event.time);
    InputAction a;
    a.time = event.time;
    if (event.kind == InputEventKind::Setting) {
        a.type = InputAction::Type::SettingChanged;
        a.setting.id = static_cast<SettingId>(event.code);
        a.setting.lobe = event.value;
        a.setting.value = shortest_double(event.x);
        actions_.push_back(std::move(a));
        return;
    }
    if (event.kind == InputEventKind::Scene) {
        if (valid_scene_event(event.code, event.x)) scene_.set(static_cast<SceneComponent>(event.code), event.x);
        return;
    }
    if (event.kind == InputEventKind::ImportMesh) {
        a.type = InputAction::Type::ImportMesh;
        a.import_number = event.code;
        attach_tip(a);
        actions_.push_back(std::move(a));
        return;
    }
    if (event.kind != InputEventKind::Key || event.value != 1) return; // act on key presses
    if (event.code == keys::kLSystemSketch) {
        // The mode takes the hands: a stroke being drawn ends where it is.
        lsystem_sketch_ = !lsystem_sketch_;
        for (int h = 0; h < kHandCount; ++h)
            if (pen_[h].down) pen_up(h, pen_[h].last_good_t);
        return;
    }
    if (lsystem_sketch_) return;
    auto set_tool = [&](Tool t) {
        tool_ = t;
        a.type = InputAction::Type::ToolChanged;
        a.tool = t;
    };
    switch (event.code) {
    case keys::kDrawLobe: set_tool(Tool::DrawLobe); break;
    case keys::kDrawTrunk: set_tool(Tool::DrawTrunk); break;
    case keys::kDeformLobe: set_tool(Tool::DeformLobe); break;
    case keys::kEditStroke: set_tool(Tool::EditStroke); break;
    case keys::kMoveLobe: set_tool(Tool::MoveLobe); break;
    case keys::kRotateLobe: set_tool(Tool::RotateLobe); break;
    case keys::kScaleLobe: set_tool(Tool::ScaleLobe); break;
    case keys::kNewLobe:
        // Starting a new lobe also returns to lobe drawing.
        tool_ = Tool::DrawLobe;
        a.type = InputAction::Type::NewLobe;
        a.tool = tool_;
        break;
    case keys::kGrow: a.type = InputAction::Type::Grow; break;
    case keys::kUndo: a.type = InputAction::Type::Undo; break;
    case keys::kRedo: a.type = InputAction::Type::Redo; break;
    case keys::kDeleteStroke: a.type = InputAction::Type::DeleteStroke; break;
    case keys::kDeleteLobe: a.type = InputAction::Type::DeleteLobe; break;
    case keys::kDuplicate: a.type = InputAction::Type::Duplicate; break;
    case keys::kMirror: a.type = InputAction::Type::Mirror; break;
    default: return; // other keys mean nothing to the pipeline
    }
    if (a.type == InputAction::Type::DeleteStroke || a.type == InputAction::Type::DeleteLobe ||
        a.type == InputAction::Type::Duplicate || a.type == InputAction::Type::Mirror)
        attach_tip(a);
    actions_.push_back(std::move(a));
}

void InputPipeline::pen_down(int h, const HandGesture& g, double t)
{
    Pen& pen = pen_[h];
    pen = Pen{};
    pen.down = true;
    pen.tool = tool_;
    pen.drag = !(tool_ == Tool::DrawLobe || tool_ == Tool::DrawTrunk);
    pen.stroke.kind = tool_ == Tool::DrawTrunk ? StrokeKind::Trunk : StrokeKind::Lobe;
    pen.stroke.hand = static_cast<Hand>(h);
    pen.stroke.points.push_back({scene_.to_document(g.index_tip), t});
    pen.last_good_t = t;
    // Stroke edits with two fingertips: the other hand points at the segment's other end.
    const HandGesture& other = gestures_.hand(static_cast<Hand>(1 - h));
    if (tool_ == Tool::EditStroke && other.tracked && other.pointing) pen.other_tip = scene_.to_document(other.index_tip);
}

void InputPipeline::pen_move(int h, const HandGesture& g, double t)
{
    Pen& pen = pen_[h];
    pen.last_good_t = t;
    // The paper keeps a point only when the fingertip moved at least the minimum distance
    // (in the document: a scaled scene keeps the spacing that meshing expects).
    const glm::vec3 tip = scene_.to_document(g.index_tip);
    if (glm::distance(tip, pen.stroke.points.back().position) >= options_.min_point_distance_m)
        pen.stroke.points.push_back({tip, t});
}

void InputPipeline::pen_up(int h, double t)
{
    Pen& pen = pen_[h];
    if (!pen.down) return;
    pen.down = false;
    // Keep where the stroke really ended when the last movement was shorter than the spacing.
    // A drag always keeps it: its end decides the edit (a move, a Bézier displacement).
    const HandGesture& g = gestures_.hand(static_cast<Hand>(h));
    const double min_last = pen.drag ? 0.0 : 0.5 * options_.min_point_distance_m;
    const glm::vec3 tip = scene_.to_document(g.index_tip);
    if (g.tracked && pen.stroke.points.size() >= 1 && glm::distance(tip, pen.stroke.points.back().position) > min_last)
        pen.stroke.points.push_back({tip, std::max(t, pen.stroke.points.back().time)});

    InputAction a;
    a.time = t;
    if (pen.drag) {
        a.type = InputAction::Type::DragCompleted;
        a.drag.tool = pen.tool;
        a.drag.hand = pen.stroke.hand;
        a.drag.path = std::move(pen.stroke.points);
        a.drag.other_tip = pen.other_tip;
        actions_.push_back(std::move(a));
        return;
    }
    const double len = pen.stroke.length();
    const int n = static_cast<int>(pen.stroke.points.size());
    if (len < options_.min_stroke_length_m || n < options_.min_stroke_points) {
        char buf[200];
        std::snprintf(buf, sizeof buf, "%s stroke at t=%.2fs discarded: too short (%.1f cm, %d points; need %.1f cm and %d points)",
                      stroke_kind_name(pen.stroke.kind), pen.stroke.points.front().time, len * 100.0, n,
                      options_.min_stroke_length_m * 100.0, options_.min_stroke_points);
        a.type = InputAction::Type::StrokeDiscarded;
        a.message = buf;
        a.stroke = std::move(pen.stroke);
        actions_.push_back(std::move(a));
        return;
    }
    a.type = InputAction::Type::StrokeCompleted;
    a.stroke = std::move(pen.stroke);
    a.stroke.id = next_stroke_id_++;
    actions_.push_back(std::move(a));
}

void InputPipeline::push_frame(const HandFrame& frame)
{
    last_time_ = std::max(last_time_, frame.time);
    const auto& gs = gestures_.update(frame);
    for (int h = 0; h < kHandCount; ++h) {
        const HandGesture& g = gs[h];
        Pen& pen = pen_[h];
        if (lsystem_sketch_) continue; // the L-system sketch mode's hands
        if (g.pinch_ended) {
            // A long loss ends the stroke at its last tracked point, the release where it was.
            pen_up(h, g.tracked ? frame.time : pen.last_good_t);
        }
        if (g.pinch_started) pen_down(h, g, frame.time);
        else if (pen.down && g.tracked && g.pinching) pen_move(h, g, frame.time);
    }
}

void InputPipeline::finish()
{
    gestures_.finish();
    for (int h = 0; h < kHandCount; ++h)
        if (pen_[h].down) pen_up(h, pen_[h].last_good_t);
}

std::vector<InputAction> InputPipeline::take_actions()
{
    std::vector<InputAction> out;
    out.swap(actions_);
    return out;
}

std::string annotation_for(const InputAction& a)
{
    switch (a.type) {
    case InputAction::Type::StrokeCompleted:
        return "stroke id=" + std::to_string(a.stroke.id) + " kind=" + stroke_kind_name(a.stroke.kind) +
               " points=" + std::to_string(a.stroke.points.size());
    case InputAction::Type::DragCompleted:
        return std::string("drag tool=") + tool_name(a.drag.tool) + " points=" + std::to_string(a.drag.path.size());
    case InputAction::Type::ToolChanged: return std::string("tool ") + tool_name(a.tool);
    default: return action_name(a.type);
    }
}

InputResult run_input_pipeline(const Recording& rec, const InputOptions& options)
{
    InputPipeline pipe(options);
    InputResult result;
    std::size_t e = 0;
    std::array<bool, kHandCount> pinch{}, grab{}, point{};
    auto count_edges = [&] {
        for (int h = 0; h < kHandCount; ++h) {
            const HandGesture& g = pipe.gestures().hand(static_cast<Hand>(h));
            if (g.pinching && !pinch[h]) ++result.pinches;
            if (g.grabbing && !grab[h]) ++result.grabs;
            if (g.pointing && !point[h]) ++result.points;
            pinch[h] = g.pinching;
            grab[h] = g.grabbing;
            point[h] = g.pointing;
        }
    };
    for (const HandFrame& f : rec.frames) {
        while (e < rec.events.size() && rec.events[e].time <= f.time) pipe.push_event(rec.events[e++]);
        pipe.push_frame(f);
        count_edges();
    }
    while (e < rec.events.size()) pipe.push_event(rec.events[e++]);
    pipe.finish();
    result.actions = pipe.take_actions();
    for (const InputAction& a : result.actions) {
        if (a.type == InputAction::Type::StrokeCompleted) result.strokes.push_back(a.stroke);
        else if (a.type == InputAction::Type::DragCompleted) result.drags.push_back(a.drag);
        else if (a.type == InputAction::Type::StrokeDiscarded) result.messages.push_back(a.message);
    }

    // Annotations are checked, never applied: each must match a derived action, in order.
    std::vector<std::string> derived;
    for (const InputAction& a : result.actions)
        if (a.type == InputAction::Type::StrokeCompleted || a.type == InputAction::Type::DragCompleted)
            derived.push_back(annotation_for(a));
    std::size_t k = 0;
    std::size_t mismatches = 0;
    for (const Annotation& an : rec.annotations) {
        if (an.text.rfind("stroke ", 0) != 0 && an.text.rfind("drag ", 0) != 0) continue;
        if (k < derived.size() && derived[k] == an.text) {
            ++k;
            continue;
        }
        if (++mismatches <= 10) {
            char buf[64];
            std::snprintf(buf, sizeof buf, "annotation at t=%.2fs: recorded '", an.time);
            result.messages.push_back(buf + an.text.substr(0, 200) + "', replay derived '" +
                                      (k < derived.size() ? derived[k] : std::string("nothing")) + "'");
        }
        if (k < derived.size()) ++k;
    }
    if (mismatches > 10)
        result.messages.push_back("... and " + std::to_string(mismatches - 10) + " more annotation mismatches");
    return result;
}

} // namespace lobe
