#pragma once
/// \file laplacian_edit.h
/// Pinch editing of lobe meshes by Laplacian surface editing (Sorkine, Cohen-Or, Lipman,
/// Alexa, Rössl, Seidel, "Laplacian Surface Editing", SGP 2004). A pinch picks a handle
/// vertex and a region of interest (ROI) around it; everything outside the ROI stays
/// fixed, the handle follows the pinch, and the free ROI vertices keep their Laplacian
/// (differential) coordinates as well as they can. The system is factored once when the
/// pinch starts (PinchEditor) and only solved per frame (PinchEditor::drag_to).
/// See docs/pinch-editing.md.

#include <memory>
#include <vector>

#include <glm/vec3.hpp>

#include "core/mesh.h"
#include "core/settings.h"

namespace lobe {

/// Settings of pinch editing. Defaults are ours (the paper gives none for VR pinching).
struct PinchEditOptions {
    /// Weights of the Laplacian L(x)ᵢ = xᵢ − Σⱼ wᵢⱼ xⱼ / Σⱼ wᵢⱼ over the 1-ring of i.
    enum class Weights {
        Cotangent, ///< wᵢⱼ = (cot αᵢⱼ + cot βᵢⱼ) / 2 of the mesh when the pinch starts
        Uniform,   ///< wᵢⱼ = 1: Sorkine et al. 2004, Eq. 1
    };

    /// Radius of the ROI: the vertices whose shortest-path distance along edges from the
    /// handle is at most this (metres).
    double roi_radius_m = LobeSettings{}.pinch_roi_radius_m;
    Weights weights = Weights::Cotangent;
    /// Rotate each vertex's Laplacian coordinate δᵢ by the rotation its 1-ring underwent
    /// (estimated from the previous solve) and solve again, so that details turn with the
    /// surface instead of shearing (the role of Tᵢ in Sorkine et al. 2004, Eq. 5).
    bool rotation_invariant = true;
    /// Extra solves with rotated δ per frame when rotation_invariant (each one a rotation
    /// fit per row and a back-substitution with the same factorisation). Why 3: the detail
    /// error per iteration count in docs/pinch-editing.md.
    int rotation_iterations = 3;
    /// A target farther than this from the handle's start position is refused (metres).
    double max_drag_m = 1.0;
};

/// The vertex nearest to a pinch point: the handle of a pinch edit.
/// \param mesh lobe mesh (#V positions).
/// \param point pinch point, metres.
/// \param max_distance_m points farther than this from every vertex pick nothing.
/// \return index of the nearest vertex (the lowest index on ties).
/// \throw InvalidInput for an empty mesh, a non-finite point, or a point farther than
///        max_distance_m from the mesh.
int pick_handle(const TriangleMesh& mesh, const glm::vec3& point,
                double max_distance_m = LobeSettings{}.pinch_pick_distance_m);

/// Laplacian surface editing with hard constraints, factored once and solved per frame
/// (the solver-object pattern of geometry-central's HeatMethodDistanceSolver).
///
/// Energy (Sorkine et al. 2004, Eq. 5 with hard positional constraints):
///   minimise Σᵢ ‖L(x′)ᵢ − Rᵢδᵢ‖² over the free vertices F = ROI \ {handle},
///   with x′ = x outside the ROI and x′_handle = target, δ = L(x) of the mesh when the pinch
///   starts and Rᵢ = I (first solve) or the rotation fitted to i's 1-ring (later solves).
/// The sum runs over every vertex whose Laplacian involves a free vertex (the ROI and the
/// ring just outside it), which is the same as summing over the whole mesh.
class PinchEditor {
public:
    /// Starts a pinch: picks the ROI and the fixed ring around it, builds the normal
    /// equations AᵀA x_F = Aᵀ(b) of the energy above and factors AᵀA (sparse LDLᵀ).
    /// \param mesh the lobe when the pinch starts (#V positions, #F triangles); the editor
    ///        keeps what it needs and does not refer to it later.
    /// \param handle_vertex index into mesh.positions, e.g. from pick_handle.
    /// \throw InvalidInput empty mesh, handle out of range, triangle index out of range,
    ///        non-finite positions, non-positive roi_radius_m or max_drag_m, negative
    ///        rotation_iterations, or an ROI with no free vertex.
    /// \throw SolverError the system is singular (e.g. all triangles around a free vertex
    ///        are degenerate with cotangent weights).
    PinchEditor(const TriangleMesh& mesh, int handle_vertex, const PinchEditOptions& options = {});
    ~PinchEditor();
    PinchEditor(PinchEditor&&) noexcept;
    PinchEditor& operator=(PinchEditor&&) noexcept;
    PinchEditor(const PinchEditor&) = delete;
    PinchEditor& operator=(const PinchEditor&) = delete;

    /// One frame of the pinch: puts the handle exactly at handle_position and the free ROI
    /// vertices where the energy is least; writes only ROI vertices of `mesh`. Each call
    /// starts from the mesh as it was when the pinch started, so the result depends only
    /// on handle_position.
    /// \param mesh the mesh the editor was made from (same #V), edited in place.
    /// \throw InvalidInput non-finite handle_position, one farther than max_drag_m from
    ///        the handle's start position, or a mesh with a different vertex count.
    /// \throw SolverError the solve gave non-finite positions.
    /// The mesh is unchanged when it throws.
    void drag_to(const glm::vec3& handle_position, TriangleMesh& mesh) const;

    int handle() const;                       ///< the handle vertex
    const glm::vec3& handle_start() const;    ///< the handle's position when the pinch started
    const std::vector<int>& roi() const;      ///< ROI vertices (handle included), ascending
    const std::vector<int>& fixed_ring() const; ///< vertices just outside the ROI, ascending
    std::size_t free_vertex_count() const;    ///< ROI size − 1: the unknowns per coordinate

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// One-shot Laplacian surface editing: PinchEditor(mesh, handle_vertex, options) then
/// drag_to(target, mesh). Throws what they throw; the mesh is unchanged when it throws.
void laplacian_deform(TriangleMesh& mesh, int handle_vertex, const glm::vec3& target,
                      const PinchEditOptions& options = {});

} // namespace lobe
