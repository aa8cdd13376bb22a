#pragma once
/// \file live_edit_view.h
/// The live side of an editing drag (docs/editing.md), for the live session both apps share
/// (live_session.h): while a hand drags under an editing tool, what it edits is shown frame
/// by frame as the drag would leave it if the pinch opened now.
///
/// - Deform (pinch, Laplacian editing): the lobe the drag started on follows the fingertip
///   (app/session/lobe_document.h, LivePinch: factored when the pinch starts, one solve per
///   frame).
/// - Transform (move, rotate, scale): the lobe and its strokes moved by the transform the
///   drag would record (meshing/lobe_transform.h: drag_transform of the path's first point
///   and the fingertip, about the centre the drag records).
/// - Bend (edit stroke, Fig. 6a of the paper): the stroke the drag picked, bent by the
///   operation the session builder would append, applied as every edit is
///   (app/session/edit_ops.h); its lobe follows at the regrowth's pace (drag_preview.h).
///
/// After the release, a deformed or moved lobe stays on screen until the regrowth that holds
/// the finished edit arrives, so it never jumps back in between; a move that edited nothing
/// puts it back at once, and a bent stroke is the document's again at once.

#include <cstdint>
#include <optional>
#include <vector>

#include <glm/vec3.hpp>

#include "app/session/lobe_document.h"
#include "app/session/session_builder.h"
#include "core/document.h"
#include "core/mesh.h"
#include "input/pipeline.h"
#include "meshing/lobe_transform.h"

namespace lobe {

/// Which editing drags a LiveEditView follows.
enum class LiveEditKind : std::uint8_t {
    Deform,    ///< Tool::DeformLobe
    Transform, ///< Tool::MoveLobe, RotateLobe, ScaleLobe
    Bend,      ///< Tool::EditStroke
};

class LiveEditView {
public:
    explicit LiveEditView(LiveEditKind kind) : kind_(kind) {}

    /// Once per frame, after the frame's actions went to the builder (and a finished drag's
    /// regrowth was asked for). `lobes`: the lobes as last built (stage space), null while
    /// there are none; `built_generation`: the regrowth generation they come from;
    /// `requested_generation`: the newest one asked for. True when what mesh_for, strokes
    /// or apply_to give changed this frame.
    bool update(const InputPipeline& pipeline, const SessionBuilder& builder, const std::vector<BuiltLobe>* lobes,
                std::uint64_t built_generation, std::uint64_t requested_generation);

    /// The lobe to show in place of lobe `lobe_id` of lobes built in `built_generation`: the
    /// edited one while it is dragged, and after a release that made the edit while that
    /// generation is older than the newest asked for. Null otherwise (and always for Bend).
    const TriangleMesh* mesh_for(std::int64_t lobe_id, const InputPipeline& pipeline, std::uint64_t built_generation,
                                 std::uint64_t requested_generation) const;

    /// While dragged: the strokes shown in place of the document's (stage space; a moved
    /// lobe's strokes, or the bent stroke). Empty otherwise: the document's are right then.
    const std::vector<Stroke>& strokes() const { return shown_strokes_; }
    /// The ids of the strokes the last drag showed (to put back when it ends).
    const std::vector<std::int64_t>& stroke_ids() const { return stroke_ids_; }
    /// Replaces the strokes shown in `strokes` (effective_strokes of the document); nothing
    /// while none are.
    void apply_to(std::vector<Stroke>& strokes) const;

private:
    bool follows(std::optional<Tool> tool) const;
    bool release(const SessionBuilder& builder, std::uint64_t built_generation, std::uint64_t requested_generation);
    void start(const InputPipeline& pipeline, const SessionBuilder& builder, const std::vector<BuiltLobe>* lobes);
    bool follow(const InputPipeline& pipeline);

    LiveEditKind kind_;
    Hand hand_ = Hand::Right;
    bool in_drag_ = false; ///< a drag this view follows was going on at the last update
    glm::vec3 last_end_{0.0f};

    // Deform: the solver of the pinched lobe.
    std::optional<LivePinch> pinch_;
    // Transform: the lobe as built when the drag started and as shown.
    struct Moved {
        std::int64_t lobe = 0;
        LobeTransformKind kind = LobeTransformKind::Move;
        glm::vec3 start{0.0f};
        glm::dvec3 centre{0.0};
        TriangleMesh rest;                ///< the lobe as built when the drag started
        std::vector<Stroke> rest_strokes; ///< its strokes then (effective, stage space)
        TriangleMesh shown;
        std::size_t edits_before = 0;     ///< the document's operations when the drag started
    };
    std::optional<Moved> moved_;
    // Bend: the document with the drag's operation appended.
    std::optional<Document> bent_;

    std::vector<Stroke> shown_strokes_;
    std::vector<std::int64_t> stroke_ids_;
};

} // namespace lobe
