#pragma once
/// \file live_transform.h
/// The live side of moving, turning and scaling a lobe (docs/editing.md), for the desktop
/// and VR sessions: while a hand drags under the move, rotate or scale tool, the lobe the
/// drag started on and its strokes are shown moved by the transform the drag would make if
/// it were released now (meshing/lobe_transform.h: drag_transform of the path's first point
/// and the fingertip, which the release adds as its last, about the centre the drag records). After the release the moved lobe stays on
/// screen until the regrowth that holds the finished edit arrives, so it never jumps back in
/// between; a drag that edited nothing puts it back at once.

#include <cstdint>
#include <optional>
#include <vector>

#include "core/mesh.h"
#include "input/pipeline.h"
#include "app/session/session_builder.h"
#include "app/session/lobe_document.h"
#include "meshing/lobe_transform.h"

namespace lobe {

class LiveTransformView {
public:
    /// Once per frame, after the frame's actions went to the builder (and a finished drag's
    /// regrowth was asked for). `lobes`: the lobes as last built (stage space), null while
    /// there are none; `built_generation`: the regrowth generation they come from;
    /// `requested_generation`: the newest one asked for. True when what mesh_for or
    /// apply_to give changed this frame.
    bool update(const InputPipeline& pipeline, const SessionBuilder& builder, const std::vector<BuiltLobe>* lobes,
                std::uint64_t built_generation, std::uint64_t requested_generation);

    /// The lobe to show in place of lobe `lobe_id` of lobes built in `built_generation`: the
    /// moved one while it is dragged, and after a release that made the edit while that
    /// generation is older than the newest asked for. Null otherwise.
    const TriangleMesh* mesh_for(std::int64_t lobe_id, std::uint64_t built_generation,
                                 std::uint64_t requested_generation) const;

    /// While a lobe is dragged: its strokes as shown (stage space, the document's effective
    /// strokes moved by the drag). Empty otherwise: the document's strokes are right then.
    const std::vector<Stroke>& strokes() const { return shown_strokes_; }
    /// Replaces the dragged lobe's strokes in `strokes` (effective_strokes of the document)
    /// by the ones shown; does nothing while no lobe is dragged.
    void apply_to(std::vector<Stroke>& strokes) const;
    /// The ids of the strokes the last drag moved (to put back when it ends).
    const std::vector<std::int64_t>& moved_stroke_ids() const { return moved_ids_; }

private:
    struct Live {
        std::int64_t lobe = 0;
        LobeTransformKind kind = LobeTransformKind::Move;
        glm::vec3 start{0.0f};
        glm::dvec3 centre{0.0};
        TriangleMesh rest;               ///< the lobe as built when the drag started
        std::vector<Stroke> rest_strokes; ///< its strokes then (effective, stage space)
        TriangleMesh shown;
        std::size_t edits_before = 0;    ///< the document's operations when the drag started
    };
    std::optional<Live> live_;
    std::vector<Stroke> shown_strokes_;
    std::vector<std::int64_t> moved_ids_;
    Hand hand_ = Hand::Right;
    bool in_drag_ = false;
    glm::vec3 last_end_{0.0f};
};

} // namespace lobe
