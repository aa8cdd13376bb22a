#include "app/live/drag_preview.h"

#include <glm/geometric.hpp>

#include "app/live/drag_hand.h"
#include "app/live/regrow_worker.h"

namespace lobe {

DragPreview::Step DragPreview::update(const InputPipeline& pipeline, const SessionBuilder& builder, bool may_preview)
{
    Step step;
    const std::optional<Hand> hand = dragging_hand(pipeline, active_ ? std::optional<Hand>(hand_) : std::nullopt,
                                                   [](std::optional<Tool> t) { return t.has_value(); });
    if (!hand || (active_ && *hand != hand_)) {
        // Released (or the other hand took over): the session regrows its own document.
        step.ended = active_ && previewed_;
        active_ = previewed_ = false;
        last_tip_.reset();
        if (!hand) return step;
    }
    if (!active_) {
        active_ = true;
        hand_ = *hand;
    }
    const Stroke& path = pipeline.current_stroke(hand_);
    if (!may_preview || path.points.empty()) return step;
    const glm::vec3 tip = *drag_end(pipeline, hand_);
    if (glm::distance(last_tip_.value_or(path.points.front().position), tip) < kMinMoveM) return step;
    Drag drag;
    drag.tool = *pipeline.drag_tool(hand_);
    drag.hand = hand_;
    drag.path = {path.points.front(), StrokePoint{tip, path.points.back().time}};
    drag.other_tip = pipeline.drag_other_tip(hand_);
    std::optional<EditOperation> op = builder.drag_operation(drag);
    if (!op) return step;
    last_tip_ = tip;
    previewed_ = true;
    step.preview = builder.document();
    step.preview->edits.push_back(std::move(*op));
    return step;
}

std::string preview_report(const RegrowResult& result)
{
    if (!result.error.empty()) return "if released here: tree: " + result.error;
    if (!result.tree.warnings.empty()) return "if released here: " + result.tree.warnings.front();
    return {};
}

} // namespace lobe
