#include "app/live/live_transform.h"

#include <algorithm>

#include "app/live/drag_hand.h"
#include "core/errors.h"
#include "app/session/edit_ops.h"

namespace lobe {

namespace {

std::optional<LobeTransformKind> kind_of(std::optional<Tool> tool)
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

bool LiveTransformView::update(const InputPipeline& pipeline, const SessionBuilder& builder,
                               const std::vector<BuiltLobe>* lobes, std::uint64_t built_generation,
                               std::uint64_t requested_generation)
{
    const std::optional<Hand> hand = dragging_hand(pipeline, in_drag_ ? std::optional<Hand>(hand_) : std::nullopt,
                                                   [](std::optional<Tool> t) { return kind_of(t).has_value(); });
    if (!hand) {
        bool changed = false;
        if (in_drag_) {
            // Released: the strokes are the document's again (moved when the edit was made).
            in_drag_ = false;
            shown_strokes_.clear();
            changed = true;
            if (live_ && !made_transform(builder.document(), live_->edits_before, live_->lobe)) live_.reset();
        }
        // The moved lobe stays until a regrowth with the finished edit is in.
        if (live_ && built_generation >= requested_generation) {
            live_.reset();
            changed = true;
        }
        return changed;
    }
    bool changed = false;
    if (!in_drag_) {
        // A new drag: it picks its lobe and centre as the finished drag will.
        in_drag_ = true;
        hand_ = *hand;
        changed = live_.has_value() || !shown_strokes_.empty();
        live_.reset();
        shown_strokes_.clear();
        moved_ids_.clear();
        const Stroke& path = pipeline.current_stroke(hand_);
        if (lobes && !path.points.empty()) {
            const glm::vec3 from = path.points.front().position;
            const SessionBuilder::LobeDragTarget target = builder.lobe_drag_target(glm::dvec3(from));
            const Document& doc = builder.document();
            for (const BuiltLobe& lobe : *lobes)
                if (target.lobe != 0 && lobe.lobe_id == target.lobe) {
                    Live l;
                    l.lobe = target.lobe;
                    l.kind = *kind_of(pipeline.drag_tool(hand_));
                    l.start = from;
                    l.centre = target.centre;
                    l.rest = lobe.mesh;
                    l.shown = lobe.mesh;
                    l.edits_before = doc.edits.size();
                    for (const LobeRecord& rec : doc.lobes)
                        if (rec.id == target.lobe) moved_ids_ = rec.stroke_ids;
                    for (Stroke& s : effective_strokes(doc))
                        if (std::find(moved_ids_.begin(), moved_ids_.end(), s.id) != moved_ids_.end())
                            l.rest_strokes.push_back(std::move(s));
                    shown_strokes_ = l.rest_strokes;
                    last_end_ = from;
                    live_ = std::move(l);
                    break;
                }
        }
    }
    if (live_ && hand_ == *hand) {
        // Not the path's last point: the path keeps one only every few millimetres.
        const glm::vec3 end = drag_end(pipeline, hand_).value_or(live_->start);
        if (end != last_end_) {
            last_end_ = end;
            try {
                // What the finished drag will record (lobe_transform of the new operation).
                const glm::dmat4 m = drag_transform(live_->kind, {live_->start, end}, live_->centre);
                TriangleMesh shown = live_->rest;
                transform_mesh(shown, m);
                std::vector<Stroke> strokes = live_->rest_strokes;
                for (Stroke& s : strokes) transform_stroke(s, m);
                live_->shown = std::move(shown);
                shown_strokes_ = std::move(strokes);
                changed = true;
            } catch (const InvalidInput&) {
                // A fingertip the transform cannot use: the lobe stays as last shown.
            }
        }
    }
    return changed;
}

const TriangleMesh* LiveTransformView::mesh_for(std::int64_t lobe_id, std::uint64_t built_generation,
                                                std::uint64_t requested_generation) const
{
    if (!live_ || live_->lobe != lobe_id) return nullptr;
    if (in_drag_ || built_generation < requested_generation) return &live_->shown;
    return nullptr;
}

void LiveTransformView::apply_to(std::vector<Stroke>& strokes) const
{
    if (!in_drag_ || shown_strokes_.empty()) return;
    for (Stroke& s : strokes)
        for (const Stroke& shown : shown_strokes_)
            if (shown.id == s.id) s = shown;
}

} // namespace lobe
