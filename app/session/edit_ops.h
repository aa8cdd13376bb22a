#pragma once
/// \file edit_ops.h
/// Re-applying a session's edit operations (Document::edits) to its strokes: stroke edits
/// (meshing/stroke_edit.h) and lobe transforms (meshing/lobe_transform.h), in the order they
/// were made. The strokes in the document stay exactly as drawn; these functions derive the
/// edited geometry from them whenever it is needed (a lobe rebuilt, a session reloaded,
/// undo/redo). Operation kinds and params: core/edits.h, docs/session-format.md; semantics:
/// docs/editing.md.
///
/// Frames. Every drag is recorded in stage space as the person saw the scene at that moment.
/// A lobe's transform operations compose into one similarity T (lobe_transform), applied by
/// the lobe builder after meshing (together with the pinch deforms). edited_strokes
/// therefore returns each lobe's strokes in the lobe's own frame, the one T maps to stage
/// space: a stroke edit made after the lobe was moved is mapped back through the transform
/// the lobe had then, and a stroke drawn into a lobe after it was moved is mapped back
/// through the transforms made before it was drawn (each transform operation lists the
/// strokes the lobe had when it was made). effective_strokes gives the strokes in stage
/// space, as the person sees them.

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <glm/mat4x4.hpp>

#include "core/document.h"
#include "meshing/lobe_transform.h"
#include "meshing/stroke_edit.h"

namespace lobe {

/// Settings used when operations are re-applied. A stroke edit's pick distance and
/// half-length come from its params when present (SessionBuilder records them), else from
/// `stroke`.
struct EditApplyOptions {
    StrokeEditOptions stroke;
    LobeTransformOptions transform;
};

/// An operation that could not be applied (a target that does not exist, a stroke edit that
/// picks nothing, or, for an operation made in code rather than read from a file, params that
/// edit_operation_problem refuses): it is skipped, the others still apply.
struct SkippedEdit {
    std::int64_t id = 0;
    std::string message; ///< one line: "edit 7 (drag:edit-stroke): …"
};

/// Whether stroke edits treat `stroke` as a loop (segments wrap past its last point):
/// stroke.closed, or the closed/open classification of §4.1 (is_closed_stroke with the
/// default ClosureOptions) of its points as drawn. Degenerate strokes count as open.
bool stroke_edit_closed(const Stroke& stroke);

/// Every stroke of the document (same order, ids, times and point counts) with all
/// stroke-edit operations applied in order; lobe strokes in their lobe's frame (see above),
/// trunk strokes and strokes of lobes never transformed in stage space. Operations that
/// cannot be applied are skipped and, when `skipped` is given, reported there.
std::vector<Stroke> edited_strokes(const Document& doc, const EditApplyOptions& options = {},
                                   std::vector<SkippedEdit>* skipped = nullptr);

/// The composition of the move/rotate/scale operations of lobe `lobe_id` among the first
/// `edit_count` operations of the document, in order (the later one on the left):
/// T = Mₙ ⋯ M₂ M₁. Each Mᵢ is drag_transform of its path about its recorded centre.
/// The identity when there are none (or no such lobe).
glm::dmat4 lobe_transform(const Document& doc, std::int64_t lobe_id,
                          std::size_t edit_count = std::numeric_limits<std::size_t>::max(),
                          const EditApplyOptions& options = {}, std::vector<SkippedEdit>* skipped = nullptr);

/// The strokes as the person sees them now, in stage space: edited_strokes with each lobe
/// stroke mapped by its lobe's lobe_transform.
std::vector<Stroke> effective_strokes(const Document& doc, const EditApplyOptions& options = {},
                                      std::vector<SkippedEdit>* skipped = nullptr);

/// Empty when `op`, appended to the document's operations, applies; otherwise why not (one
/// line, e.g. "stroke edit: the fingertip is 4.2 cm from stroke 3 (pick distance 3.0 cm)").
/// Pinch deforms are not checked here (empty).
std::string check_edit_operation(const Document& doc, const EditOperation& op, const EditApplyOptions& options = {});

} // namespace lobe
