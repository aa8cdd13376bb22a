#pragma once
/// \file drag_hand.h
/// Which hand's editing drag a live view follows (live_edit_view.h,
/// drag_preview.h): the hand it already follows while that hand still
/// drags, else the first of right and left whose drag `wanted` accepts; and where that drag
/// ends now.

#include <optional>

#include "input/pipeline.h"

namespace lobe {

template <class Wanted>
std::optional<Hand> dragging_hand(const InputPipeline& pipeline, std::optional<Hand> current, Wanted&& wanted)
{
    if (current && wanted(pipeline.drag_tool(*current))) return current;
    for (Hand h : {Hand::Right, Hand::Left})
        if (wanted(pipeline.drag_tool(h))) return h;
    return std::nullopt;
}

/// Where the drag `hand` is making would end if the pinch opened now: the fingertip (document
/// space), which the release adds as the path's last point, or the path's last kept point
/// while the hand is not tracked. Nothing while the path is empty.
inline std::optional<glm::vec3> drag_end(const InputPipeline& pipeline, Hand hand)
{
    const HandGesture& g = pipeline.gestures().hand(hand);
    if (g.tracked) return pipeline.scene_transform().to_document(g.index_tip);
    const Stroke& path = pipeline.current_stroke(hand);
    if (path.points.empty()) return std::nullopt;
    return path.points.back().position;
}

} // namespace lobe
