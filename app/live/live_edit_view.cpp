#include "app/live/live_edit_view.h"

#include <algorithm>

#include "app/live/drag_hand.h"
#include "app/session/edit_ops.h"
#include "core/errors.h"

namespace lobe {

namespace {

std::optional<LobeTransformKind> transform_kind(std::optional<Tool> tool)
{
    if (tool == Tool::MoveLobe) return LobeTransformKind::Move;
    if (tool == Tool::RotateLobe) return LobeTransformKind::Rotate;
    if (tool == Tool::ScaleLobe) return LobeTransformKind::Scale;
    return std::nullopt;
}

/// Whether the operations after the first `before` hold a transform of `lobe`: the drag
/// that just ended made its edit.
bool made_transform(const Document& doc, std::size_t before, std::int64_t lobe)
{
    for (std::size_t k = before; k < doc.edits.size(); ++k) {
        const EditOperation& op = doc.edits[k];
        if (op.target == lobe && is_lobe_transform(op.kind())) return true;
    }
    return false;
}

} // namespace

bool LiveEditView::follows(std::optional<Tool> tool) const
{
    switch (kind_) {
    case LiveEditKind::Deform: return tool == Tool::DeformLobe;
    case LiveEditKind::Transform: return transform_kind(tool).has_value();
    case LiveEditKind::Bend: return tool == Tool::EditStroke;
    }
    return false;
}

bool LiveEditView::update(const InputPipeline& pipeline, const SessionBuilder& builder,
                          const std::vector<BuiltLobe>* lobes, std::uint64_t built_generation,
                          std::uint64_t requested_generation)
{
    const std::optional<Hand> hand = dragging_hand(pipeline, in_drag_ ? std::optional<Hand>(hand_) : std::nullopt,
                                                   [this](std::optional<Tool> t) { return follows(t); });
    if (!hand) return release(builder, built_generation, requested_generation);
    bool changed = false;
    if (!in_drag_) {
        // A new drag: it picks what it edits as the finished drag will.
        in_drag_ = true;
        hand_ = *hand;
        changed = pinch_.has_value() || moved_.has_value() || !shown_strokes_.empty();
        pinch_.reset();
        moved_.reset();
        bent_.reset();
        shown_strokes_.clear();
        stroke_ids_.clear();
        start(pipeline, builder, lobes);
    }
    if (hand_ == *hand && follow(pipeline)) changed = true;
    return changed;
}

bool LiveEditView::release(const SessionBuilder& builder, std::uint64_t built_generation,
                           std::uint64_t requested_generation)
{
    bool changed = false;
    if (in_drag_) {
        in_drag_ = false;
        if (kind_ != LiveEditKind::Deform) {
            // The strokes are the document's again (moved or bent when the edit was made).
            changed = true;
            shown_strokes_.clear();
            bent_.reset();
        }
        // A move that edited nothing goes back at once.
        if (moved_ && !made_transform(builder.document(), moved_->edits_before, moved_->lobe)) moved_.reset();
    }
    // An edited lobe stays until a regrowth with the finished edit is in (or at once when the
    // drag edited nothing and none was asked for).
    if ((pinch_ || moved_) && built_generation >= requested_generation) {
        pinch_.reset();
        moved_.reset();
        changed = true;
    }
    return changed;
}

void LiveEditView::start(const InputPipeline& pipeline, const SessionBuilder& builder,
                         const std::vector<BuiltLobe>* lobes)
{
    const Stroke& path = pipeline.current_stroke(hand_);
    if (path.points.empty()) return;
    const glm::vec3 from = path.points.front().position;
    const Document& doc = builder.document();
    last_end_ = from;
    if (kind_ == LiveEditKind::Bend) {
        Drag drag;
        drag.tool = Tool::EditStroke;
        drag.hand = hand_;
        drag.path = {path.points.front(), path.points.front()};
        drag.other_tip = pipeline.drag_other_tip(hand_);
        if (std::optional<EditOperation> op = builder.drag_operation(drag)) {
            stroke_ids_ = {op->target};
            bent_ = doc;
            bent_->edits.push_back(std::move(*op));
        }
        return;
    }
    if (!lobes) return;
    if (kind_ == LiveEditKind::Deform) {
        const std::int64_t id = builder.lobe_at(glm::dvec3(from));
        for (const BuiltLobe& lobe : *lobes)
            if (lobe.lobe_id == id) {
                try {
                    pinch_.emplace(doc, lobe, from);
                } catch (const Error&) {
                    // Picks nothing or cannot be solved: the finished drag says why.
                }
                return;
            }
        return;
    }
    const SessionBuilder::LobeDragTarget target = builder.lobe_drag_target(glm::dvec3(from));
    if (target.lobe == 0) return;
    for (const BuiltLobe& lobe : *lobes) {
        if (lobe.lobe_id != target.lobe) continue;
        Moved m;
        m.lobe = target.lobe;
        m.kind = *transform_kind(pipeline.drag_tool(hand_));
        m.start = from;
        m.centre = target.centre;
        m.rest = lobe.mesh;
        m.shown = lobe.mesh;
        m.edits_before = doc.edits.size();
        for (const LobeRecord& rec : doc.lobes)
            if (rec.id == target.lobe) stroke_ids_ = rec.stroke_ids;
        for (Stroke& s : effective_strokes(doc))
            if (std::find(stroke_ids_.begin(), stroke_ids_.end(), s.id) != stroke_ids_.end())
                m.rest_strokes.push_back(std::move(s));
        shown_strokes_ = m.rest_strokes;
        moved_ = std::move(m);
        return;
    }
}

bool LiveEditView::follow(const InputPipeline& pipeline)
{
    if (pinch_) {
        const glm::vec3 tip = pipeline.scene_transform().to_document(pipeline.gestures().hand(hand_).index_tip);
        try {
            pinch_->drag_to(tip);
            return true;
        } catch (const Error&) {
            return false; // a fingertip farther than a deform may pull: the lobe stays as last shown
        }
    }
    if (moved_) {
        // Not the path's last point: the path keeps one only every few millimetres.
        const glm::vec3 end = drag_end(pipeline, hand_).value_or(moved_->start);
        if (end == last_end_) return false;
        last_end_ = end;
        try {
            // What the finished drag will record (lobe_transform of the new operation).
            const glm::dmat4 m = drag_transform(moved_->kind, {moved_->start, end}, moved_->centre);
            TriangleMesh shown = moved_->rest;
            transform_mesh(shown, m);
            std::vector<Stroke> strokes = moved_->rest_strokes;
            for (Stroke& s : strokes) transform_stroke(s, m);
            moved_->shown = std::move(shown);
            shown_strokes_ = std::move(strokes);
            return true;
        } catch (const InvalidInput&) {
            return false; // a fingertip the transform cannot use: the lobe stays as last shown
        }
    }
    if (bent_) {
        const Stroke& path = pipeline.current_stroke(hand_);
        const glm::vec3 end = drag_end(pipeline, hand_).value_or(path.points.front().position);
        if (end == last_end_ && !shown_strokes_.empty()) return false;
        last_end_ = end;
        // Only the path's first and last points decide a stroke edit.
        EditOperation& op = bent_->edits.back();
        const StrokePoint& first = path.points.front();
        op.path = {{glm::dvec3(first.position), first.time}, {glm::dvec3(end), path.points.back().time}};
        std::vector<SkippedEdit> skipped;
        std::vector<Stroke> strokes = effective_strokes(*bent_, {}, &skipped);
        const bool applied = skipped.empty() || skipped.back().id != op.id;
        bool changed = false;
        for (Stroke& s : strokes)
            if (s.id == op.target && applied) {
                shown_strokes_ = {std::move(s)};
                changed = true;
            }
        // A drag the edit cannot make (bent too far): the stroke stays as last shown.
        return changed;
    }
    return false;
}

const TriangleMesh* LiveEditView::mesh_for(std::int64_t lobe_id, const InputPipeline& pipeline,
                                           std::uint64_t built_generation, std::uint64_t requested_generation) const
{
    if (pinch_ && pinch_->lobe_id() == lobe_id) {
        if (pipeline.drag_tool(hand_) == Tool::DeformLobe || built_generation < requested_generation)
            return &pinch_->mesh();
    }
    if (moved_ && moved_->lobe == lobe_id) {
        if (in_drag_ || built_generation < requested_generation) return &moved_->shown;
    }
    return nullptr;
}

void LiveEditView::apply_to(std::vector<Stroke>& strokes) const
{
    if (shown_strokes_.empty()) return;
    for (Stroke& s : strokes)
        for (const Stroke& shown : shown_strokes_)
            if (shown.id == s.id) s = shown;
}

} // namespace lobe
