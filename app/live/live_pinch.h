#pragma once
/// \file live_pinch.h
/// The live side of a pinch deform (docs/editing.md), for the desktop and VR sessions: while
/// a hand drags under the deform tool, the lobe it started on follows the fingertip
/// (app/session/lobe_document.h, LivePinch: factored when the pinch starts, one solve per frame),
/// and after the release the deformed lobe stays on screen until the regrowth that holds the
/// finished edit arrives, so the lobe never jumps back to its old shape in between.

#include <cstdint>
#include <optional>
#include <vector>

#include "core/mesh.h"
#include "input/pipeline.h"
#include "app/session/session_builder.h"
#include "app/session/lobe_document.h"

namespace lobe {

class LivePinchView {
public:
    /// Once per frame, after the frame's actions went to the builder (and a finished drag's
    /// regrowth was asked for). `lobes`: the lobes as last built (stage space), null while
    /// there are none; `built_generation`: the regrowth generation they come from;
    /// `requested_generation`: the newest one asked for. True when what mesh_for gives
    /// changed this frame.
    bool update(const InputPipeline& pipeline, const SessionBuilder& builder, const std::vector<BuiltLobe>* lobes,
                std::uint64_t built_generation, std::uint64_t requested_generation);

    /// The lobe to show in place of lobe `lobe_id` of lobes built in `built_generation`: the
    /// deformed one while it is dragged, and after the release while that generation is
    /// older than the newest asked for. Null otherwise.
    const TriangleMesh* mesh_for(std::int64_t lobe_id, const InputPipeline& pipeline, std::uint64_t built_generation,
                                 std::uint64_t requested_generation) const;

private:
    bool dragging(const InputPipeline& pipeline) const;

    std::optional<LivePinch> live_;
    Hand hand_ = Hand::Right;
    bool in_drag_ = false; ///< a deform drag was going on at the last update
};

} // namespace lobe
