#include "app/live/live_stroke_edit.h"

#include "app/live/drag_hand.h"
#include "app/session/edit_ops.h"

namespace lobe {

bool LiveStrokeEditView::update(const InputPipeline& pipeline, const SessionBuilder& builder)
{
    const std::optional<Hand> hand = dragging_hand(pipeline, in_drag_ ? std::optional<Hand>(hand_) : std::nullopt,
                                                   [](std::optional<Tool> t) { return t == Tool::EditStroke; });
    if (!hand) {
        if (!in_drag_) return false;
        // Released: the document's stroke again (bent when the edit was made).
        in_drag_ = false;
        with_.reset();
        shown_.reset();
        return true;
    }
    bool changed = false;
    if (!in_drag_) {
        // A new drag: it picks its stroke (and the segment's other end) as the finished drag will.
        in_drag_ = true;
        hand_ = *hand;
        changed = shown_.has_value();
        with_.reset();
        shown_.reset();
        stroke_id_ = 0;
        const Stroke& path = pipeline.current_stroke(hand_);
        if (!path.points.empty()) {
            Drag drag;
            drag.tool = Tool::EditStroke;
            drag.hand = hand_;
            drag.path = {path.points.front(), path.points.front()};
            drag.other_tip = pipeline.drag_other_tip(hand_);
            if (std::optional<EditOperation> op = builder.drag_operation(drag)) {
                stroke_id_ = op->target;
                with_ = builder.document();
                with_->edits.push_back(std::move(*op));
                last_end_ = path.points.front().position;
            }
        }
    }
    if (with_ && hand_ == *hand) {
        const Stroke& path = pipeline.current_stroke(hand_);
        const glm::vec3 end = drag_end(pipeline, hand_).value_or(path.points.front().position);
        if (end != last_end_ || !shown_) {
            last_end_ = end;
            // Only the path's first and last points decide a stroke edit.
            EditOperation& op = with_->edits.back();
            const StrokePoint& first = path.points.front();
            op.path = {{glm::dvec3(first.position), first.time}, {glm::dvec3(end), path.points.back().time}};
            std::vector<SkippedEdit> skipped;
            std::vector<Stroke> strokes = effective_strokes(*with_, {}, &skipped);
            const bool applied = skipped.empty() || skipped.back().id != op.id;
            for (Stroke& s : strokes)
                if (s.id == stroke_id_ && applied) {
                    shown_ = std::move(s);
                    changed = true;
                }
            // A drag the edit cannot make (bent too far): the stroke stays as last shown.
        }
    }
    return changed;
}

void LiveStrokeEditView::apply_to(std::vector<Stroke>& strokes) const
{
    if (!shown_) return;
    for (Stroke& s : strokes)
        if (s.id == shown_->id) s = *shown_;
}

} // namespace lobe
