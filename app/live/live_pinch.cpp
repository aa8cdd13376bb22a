#include "app/live/live_pinch.h"

#include "app/live/drag_hand.h"
#include "core/errors.h"

namespace lobe {

bool LivePinchView::dragging(const InputPipeline& pipeline) const
{
    return pipeline.drag_tool(hand_) == Tool::DeformLobe;
}

bool LivePinchView::update(const InputPipeline& pipeline, const SessionBuilder& builder,
                           const std::vector<BuiltLobe>* lobes, std::uint64_t built_generation,
                           std::uint64_t requested_generation)
{
    const std::optional<Hand> hand = dragging_hand(pipeline, in_drag_ ? std::optional<Hand>(hand_) : std::nullopt,
                                                   [](std::optional<Tool> t) { return t == Tool::DeformLobe; });
    if (!hand) {
        in_drag_ = false;
        // Released: the deformed lobe stays until a regrowth with the finished edit is in
        // (or at once when the finished drag edited nothing and none was asked for).
        if (live_ && built_generation >= requested_generation) {
            live_.reset();
            return true;
        }
        return false;
    }
    bool changed = false;
    if (!in_drag_) {
        // A new pinch: it picks its lobe as the finished drag will (SessionBuilder::lobe_at).
        in_drag_ = true;
        hand_ = *hand;
        if (live_) {
            live_.reset();
            changed = true;
        }
        const Stroke& path = pipeline.current_stroke(hand_);
        if (lobes && !path.points.empty()) {
            const glm::vec3 from = path.points.front().position;
            const std::int64_t id = builder.lobe_at(glm::dvec3(from));
            for (const BuiltLobe& lobe : *lobes)
                if (lobe.lobe_id == id) {
                    try {
                        live_.emplace(builder.document(), lobe, from);
                    } catch (const Error&) {
                        // Picks nothing or cannot be solved: the finished drag says why.
                    }
                    break;
                }
        }
    }
    if (live_ && hand_ == *hand) {
        const glm::vec3 tip = pipeline.scene_transform().to_document(pipeline.gestures().hand(hand_).index_tip);
        try {
            live_->drag_to(tip);
            changed = true;
        } catch (const Error&) {
            // A fingertip farther than a deform may pull: the lobe stays as last shown.
        }
    }
    return changed;
}

const TriangleMesh* LivePinchView::mesh_for(std::int64_t lobe_id, const InputPipeline& pipeline,
                                            std::uint64_t built_generation, std::uint64_t requested_generation) const
{
    if (!live_ || live_->lobe_id() != lobe_id) return nullptr;
    if (dragging(pipeline) || built_generation < requested_generation) return &live_->mesh();
    return nullptr;
}

} // namespace lobe
