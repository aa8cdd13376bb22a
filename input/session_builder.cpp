#include "input/session_builder.h"

#include <algorithm>

namespace lobe {

namespace {
// Undo depth: a document snapshot per change; sessions have tens to hundreds of changes.
constexpr std::size_t kMaxUndo = 256;
} // namespace

SessionBuilder::SessionBuilder(Document doc) : doc_(std::move(doc))
{
    for (const LobeRecord& l : doc_.lobes) next_lobe_id_ = std::max(next_lobe_id_, l.id + 1);
    for (const EditOperation& e : doc_.edits) next_edit_id_ = std::max(next_edit_id_, e.id + 1);
}

void SessionBuilder::add_stroke(const Stroke& stroke)
{
    doc_.strokes.push_back(stroke);
    if (stroke.kind != StrokeKind::Lobe) return;
    if (doc_.lobes.empty() || new_lobe_pending_) {
        doc_.lobes.push_back(LobeRecord{next_lobe_id_++, {}, {}});
        new_lobe_pending_ = false;
    }
    doc_.lobes.back().stroke_ids.push_back(stroke.id);
}

bool SessionBuilder::apply(const InputAction& a)
{
    auto snapshot = [&] {
        undo_.push_back(doc_);
        if (undo_.size() > kMaxUndo) undo_.erase(undo_.begin());
        redo_.clear();
    };
    switch (a.type) {
    case InputAction::Type::StrokeCompleted:
        snapshot();
        add_stroke(a.stroke);
        return true;
    case InputAction::Type::DragCompleted: {
        snapshot();
        EditOperation op;
        op.id = next_edit_id_++;
        op.type = std::string("drag:") + tool_name(a.drag.tool);
        op.target = 0; // resolved against the lobes/strokes when the edit is applied
        nlohmann::json path = nlohmann::json::array();
        for (const StrokePoint& p : a.drag.path) path.push_back({p.position.x, p.position.y, p.position.z, p.time});
        op.params = {{"hand", hand_name(a.drag.hand)}, {"path", std::move(path)}};
        doc_.edits.push_back(std::move(op));
        return true;
    }
    case InputAction::Type::NewLobe:
        // Only a pending flag: an empty lobe is never created.
        new_lobe_pending_ = !doc_.lobes.empty();
        return false;
    case InputAction::Type::Undo:
        if (undo_.empty()) return false;
        redo_.push_back(std::move(doc_));
        doc_ = std::move(undo_.back());
        undo_.pop_back();
        return true;
    case InputAction::Type::Redo:
        if (redo_.empty()) return false;
        undo_.push_back(std::move(doc_));
        doc_ = std::move(redo_.back());
        redo_.pop_back();
        return true;
    case InputAction::Type::StrokeDiscarded:
    case InputAction::Type::ToolChanged:
    case InputAction::Type::Grow:
        return false;
    }
    return false;
}

void SessionBuilder::apply(const std::vector<InputAction>& actions)
{
    for (const InputAction& a : actions) apply(a);
}

} // namespace lobe
