#pragma once
/// \file drag_preview.h
/// While an editing drag is made (deform, bend, move, rotate, scale; docs/editing.md), the
/// document as it would be if the pinch opened now: the session's document with the
/// operation the session builder would append for the drag so far (the path's first point to
/// the fingertip). The desktop and VR sessions hand it to their regrowth worker, so the lobes
/// and the tree follow the drag at the worker's pace, not only after the release; the live
/// edit views (live_edit_view.h) follow it every frame.
/// Nothing of it enters the document, the recording or the autosave.

#include <optional>
#include <string>

#include <glm/vec3.hpp>

#include "core/document.h"
#include "input/pipeline.h"
#include "app/session/session_builder.h"

namespace lobe {

struct RegrowResult; // app/live/regrow_worker.h

class DragPreview {
public:
    /// The fingertip must have moved this far since the last preview for another one.
    static constexpr float kMinMoveM = 0.002f;

    struct Step {
        std::optional<Document> preview; ///< a document to regrow for, when there is a new one
        bool ended = false;              ///< a drag that had previews ended this frame
    };

    /// Once per frame, after the frame's actions went to the builder. With `may_preview`
    /// false (the worker still has a preview waiting) no new one is made this frame.
    Step update(const InputPipeline& pipeline, const SessionBuilder& builder, bool may_preview = true);

private:
    bool active_ = false;
    bool previewed_ = false;
    Hand hand_ = Hand::Right;
    std::optional<glm::vec3> last_tip_;
};

/// What the sessions' status line says of a preview's regrowth: "if released here: " and its
/// error or first warning; empty when it has neither. The message list keeps nothing of a
/// preview: what it reports is the document's only once the drag made its edit.
std::string preview_report(const RegrowResult& result);

} // namespace lobe
