#pragma once
/// \file live_stroke_edit.h
/// The live side of bending a stroke (docs/editing.md, Fig. 6a of the paper), for the desktop
/// and VR sessions: while a hand drags under the edit-stroke tool, the stroke the drag picked
/// is shown bent as the drag would bend it if it were released now: the operation the
/// session builder would append (SessionBuilder::drag_operation, from the path's first point
/// to the fingertip), applied to the document as every edit is (app/session/edit_ops.h). The
/// lobe through the stroke follows at the regrowth thread's pace (drag_preview.h).

#include <cstdint>
#include <optional>
#include <vector>

#include "core/document.h"
#include "input/pipeline.h"
#include "app/session/session_builder.h"

namespace lobe {

class LiveStrokeEditView {
public:
    /// Once per frame, after the frame's actions went to the builder. True when what stroke()
    /// or apply_to give changed this frame.
    bool update(const InputPipeline& pipeline, const SessionBuilder& builder);

    /// While a stroke is bent: it as shown (stage space); null otherwise.
    const Stroke* stroke() const { return shown_ ? &*shown_ : nullptr; }
    /// The stroke the last drag bent (to put back when it ends); 0 when none.
    std::int64_t bent_stroke_id() const { return stroke_id_; }
    /// Replaces the bent stroke in `strokes` (effective_strokes of the document) by the one
    /// shown; does nothing while no stroke is bent.
    void apply_to(std::vector<Stroke>& strokes) const;

private:
    std::optional<Document> with_; ///< the document with the drag's operation appended
    std::optional<Stroke> shown_;
    std::int64_t stroke_id_ = 0;
    Hand hand_ = Hand::Right;
    bool in_drag_ = false;
    glm::vec3 last_end_{0.0f};
};

} // namespace lobe
