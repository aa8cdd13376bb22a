#pragma once
/// \file drag_hand.h
/// Which hand's editing drag a live view follows (live_pinch.h, live_transform.h,
/// live_stroke_edit.h, drag_preview.h): the hand it already follows while that hand still
/// drags, else the first of right and left whose drag `wanted` accepts.

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

} // namespace lobe
