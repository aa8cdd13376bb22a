#pragma once
/// \file lobe_document.h
/// Every lobe of a session document, rebuilt from what the person did: the lobe's strokes
/// (with their stroke edits, edit_ops.h) joined in drawing order (lobe.h), remeshed to the
/// attractor spacing (remesh.h), the pinch edits (Laplacian editing) re-applied in order,
/// then the lobe moved, rotated and scaled as its transform operations say. A
/// stroke that cannot join its lobe is left out of the mesh with a warning; it stays in
/// the document. See docs/lobes.md.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/document.h"
#include "core/mesh.h"
#include "meshing/lobe.h"

namespace lobe {

/// One lobe of a document, ready for growth.
struct BuiltLobe {
    std::int64_t lobe_id = 0;
    std::vector<std::int64_t> stroke_ids; ///< the strokes that joined, in order
    LobeSurface surface;                  ///< the surface through the strokes (stroke edits applied), before remeshing, in the lobe's own frame
    TriangleMesh mesh;                    ///< remeshed, pinch edits applied, moved/rotated/scaled into stage space: closed, outward
    std::size_t edits_applied = 0;
};

/// Most strokes one lobe is built from: joining compares each stroke with every stroke
/// already in the lobe, so the work grows with the square of their number. Strokes beyond
/// the first kMaxStrokesPerLobe of a lobe are left out with one warning (docs/limits.md).
inline constexpr std::size_t kMaxStrokesPerLobe = 1000;

/// Rebuilds every lobe of `doc` that has at least one stroke that can join. Warnings (a
/// stroke left out, an edit that picked nothing) are appended to `warnings` when given,
/// one line each.
std::vector<BuiltLobe> build_document_lobes(const Document& doc, std::vector<std::string>* warnings = nullptr);

/// A pinch deform while it is being dragged (docs/editing.md): factored once when the pinch
/// starts, solved for every new fingertip position (meshing/laplacian_edit.h), in the lobe's
/// own frame as the lobe builder applies the finished edit. So the lobe follows the
/// fingertip, and what the person sees at release is what the finished edit builds (the same
/// mesh, up to the rounding of mapping it out of stage space and back when the lobe was
/// moved, turned or scaled).
class LivePinch {
public:
    /// Starts a pinch at `from` (stage space) on `lobe`, the lobe as last built for `doc`
    /// (build_document_lobes: stage space, earlier pinch edits applied).
    /// \throw InvalidInput when the pinch picks no vertex (farther than the pick distance) or
    ///        the region cannot be edited (one line); SolverError for a singular system.
    LivePinch(const Document& doc, const BuiltLobe& lobe, const glm::vec3& from);
    ~LivePinch();
    LivePinch(LivePinch&&) noexcept;
    LivePinch& operator=(LivePinch&&) noexcept;

    /// The lobe with the pinch dragged to `to` (stage space): lobe.mesh with the region moved.
    /// \throw InvalidInput for a target that is not finite or farther than the editor allows.
    const TriangleMesh& drag_to(const glm::vec3& to);
    std::int64_t lobe_id() const;
    const TriangleMesh& mesh() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// Re-applies the pinch edits (edit operations of type "drag:deform-lobe") that target
/// `lobe_id` (or, with target 0, start within the pick distance of `mesh`) to `mesh`, in
/// document order. Returns how many were applied.
std::size_t apply_pinch_edits(const Document& doc, std::int64_t lobe_id, TriangleMesh& mesh,
                              std::vector<std::string>* warnings = nullptr);

} // namespace lobe
