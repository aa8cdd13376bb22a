#pragma once
/// \file edits.h
/// Edit operations as a session document keeps them (Document::edits): what kind of edit,
/// what it picked, the fingertip drag that made it and the parameters of its kind. Read and
/// checked once when a document loads (document_from_json); re-applied whenever the thing
/// they edit is rebuilt (app/session/edit_ops.h, app/session/lobe_document.h).
/// Format: docs/session-format.md, "Edit operations"; semantics: docs/editing.md.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include <glm/vec3.hpp>

#include "core/hand_frame.h"

namespace lobe {

/// One kind per editing tool; the file names them "drag:<tool>" (edit_kind_name).
enum class EditKind : std::uint8_t {
    DeformLobe, ///< "drag:deform-lobe": a pinch deform (Laplacian editing); target = lobe id
    EditStroke, ///< "drag:edit-stroke": a Bézier stroke edit; target = stroke id
    MoveLobe,   ///< "drag:move-lobe"; target = lobe id
    RotateLobe, ///< "drag:rotate-lobe"; target = lobe id
    ScaleLobe,  ///< "drag:scale-lobe"; target = lobe id
};

/// The kind's name in session files, e.g. "drag:rotate-lobe".
const char* edit_kind_name(EditKind kind);
/// The kind named `name` (edit_kind_name's inverse); nullopt for any other text.
std::optional<EditKind> edit_kind_from_name(std::string_view name);
/// Move, rotate or scale: the kinds that compose into a lobe's transform.
bool is_lobe_transform(EditKind kind);

/// One point of a drag's fingertip path, stage space, as the file holds it: [x, y, z] or
/// [x, y, z, t]. Doubles exactly as read, so a document is written back as it was read.
struct DragPoint {
    glm::dvec3 position{0.0};
    std::optional<double> time; ///< seconds; absent for a point written without one
};

/// Parameters of each kind besides the drag (hand and path, in EditOperation). Optional
/// fields are absent from the file when unset.
struct DeformLobeParams {};

struct EditStrokeParams {
    std::optional<double> pick_distance_m; ///< as used when the edit was made (metres, > 0)
    std::optional<double> half_length_m;   ///< as used when the edit was made (metres, > 0)
    /// The other hand's pointing fingertip when the drag started: the segment's other end.
    std::optional<glm::dvec3> other_tip;
};

struct LobeTransformParams {
    /// The lobe's centre when the drag was made; required for rotate and scale.
    std::optional<glm::dvec3> centre;
    /// The lobe's stroke ids when the drag was made; absent: every stroke of the lobe.
    std::optional<std::vector<std::int64_t>> strokes;
};
struct MoveLobeParams : LobeTransformParams {};
struct RotateLobeParams : LobeTransformParams {};
struct ScaleLobeParams : LobeTransformParams {};

/// The parameters of an operation; the alternative held is its kind (alternatives in
/// EditKind order), so kind and parameters cannot disagree.
using EditParams = std::variant<DeformLobeParams, EditStrokeParams, MoveLobeParams, RotateLobeParams, ScaleLobeParams>;

/// Default parameters of `kind`.
EditParams edit_params_of(EditKind kind);

/// An edit stored as an operation, re-applied whenever the thing it edits is rebuilt.
struct EditOperation {
    std::int64_t id = 0;
    std::int64_t target = 0; ///< the stroke or lobe id the edit picked when it was made
    Hand hand = Hand::Right; ///< the hand that dragged
    std::vector<DragPoint> path; ///< the fingertip from pinch to release; first and last decide the edit
    EditParams params;           ///< its kind and kind-specific params (default: a pinch deform)

    EditKind kind() const { return static_cast<EditKind>(params.index()); }
    /// The parameters of a move, rotate or scale; null for the other kinds.
    const LobeTransformParams* transform_params() const;
    LobeTransformParams* transform_params();
    /// The parameters of a stroke edit; null for the other kinds.
    const EditStrokeParams* stroke_params() const { return std::get_if<EditStrokeParams>(&params); }
};

/// Empty when `op` is well formed, else the first problem, naming its field relative to the
/// operation (`params.path[2]: a coordinate is not finite or beyond 1 km`): an empty path or
/// one of more than kMaxStrokePoints; a coordinate (path, other_tip, centre) not finite or
/// beyond kMaxStrokeCoordinateM (core/stroke.h), as a stroke's; a time not finite; a pick
/// distance or half-length that is not a positive finite number; a rotate or scale without a
/// centre. Whether the target exists, or the edit picks anything, depends on the document and
/// is not checked here (re-application skips such an operation with a warning).
std::string edit_operation_problem(const EditOperation& op);

} // namespace lobe
