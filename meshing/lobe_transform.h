#pragma once
/// \file lobe_transform.h
/// Moving, rotating and uniformly scaling a whole lobe with a drag (the paper's "moving
/// lobes in mid-air"). A drag recorded under the move, rotate or scale tool, plus the lobe's
/// centre when the drag was made, gives one similarity transform in stage space; the
/// transforms of a lobe compose in the order they were made. See docs/editing.md.

#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include "core/mesh.h"
#include "core/stroke.h"

namespace lobe {

/// Settings of the lobe transforms. The paper gives no numbers; these are ours.
struct LobeTransformOptions {
    /// A rotate or scale drag that starts (rotate: or ends) closer than this to the centre
    /// has no usable lever arm: it gives the identity.
    double min_lever_m = 0.02;
    /// Scale factors are clamped to [min_scale, max_scale]: one drag cannot collapse a lobe
    /// to a point (a drag ending on the centre would give 0) or blow it up without bound.
    double min_scale = 0.1;
    double max_scale = 10.0;
};

/// Which lobe tool made the drag.
enum class LobeTransformKind { Move, Rotate, Scale };

/// Translation by end − start.
/// \throw InvalidInput for a non-finite point.
glm::dmat4 move_transform(const glm::dvec3& start, const glm::dvec3& end);

/// Rotation about `centre` taking the direction of start − centre to that of end − centre,
/// about the axis perpendicular to both (the smallest such rotation). When the two are
/// opposite the axis is the one perpendicular to start − centre and to the coordinate axis
/// it is least aligned with (a fixed, documented choice). Identity when start or end is
/// closer than options.min_lever_m to the centre.
/// \throw InvalidInput for a non-finite point or bad options.
glm::dmat4 rotate_transform(const glm::dvec3& start, const glm::dvec3& end, const glm::dvec3& centre,
                            const LobeTransformOptions& options = {});

/// Uniform scale about `centre` by |end − centre| / |start − centre|, clamped to
/// [options.min_scale, options.max_scale]. Identity when start is closer than
/// options.min_lever_m to the centre.
/// \throw InvalidInput for a non-finite point or bad options.
glm::dmat4 scale_transform(const glm::dvec3& start, const glm::dvec3& end, const glm::dvec3& centre,
                           const LobeTransformOptions& options = {});

/// The factor scale_transform uses (before it builds the matrix); 1 when start is too close
/// to the centre.
double drag_scale_factor(const glm::dvec3& start, const glm::dvec3& end, const glm::dvec3& centre,
                         const LobeTransformOptions& options = {});

/// The transform of a recorded drag: its first and last path points through move_transform,
/// rotate_transform or scale_transform. Only the ends of the path matter: the lobe follows
/// the fingertip while dragging and stays where the drag was released.
/// \param path the fingertip path (at least one point), metres.
/// \param centre the lobe's centre when the drag started (unused for Move).
/// \throw InvalidInput empty path, non-finite point, bad options.
glm::dmat4 drag_transform(LobeTransformKind kind, const std::vector<glm::vec3>& path, const glm::dvec3& centre,
                          const LobeTransformOptions& options = {});

/// The uniform scale factor of a similarity transform (the length its linear part gives a
/// unit vector; the cube root of |det| for a general one).
double similarity_scale(const glm::dmat4& transform);

/// Applies `transform` to every vertex (in double, rounded to float once). Triangles and
/// feature edges are unchanged: a similarity with positive scale keeps the orientation.
/// \throw InvalidInput a non-finite matrix or one that mirrors (negative determinant); the
///        mesh is unchanged when it throws.
void transform_mesh(TriangleMesh& mesh, const glm::dmat4& transform);

/// Applies `transform` to every point of the stroke (times unchanged).
/// \throw InvalidInput a non-finite matrix; the stroke is unchanged when it throws.
void transform_stroke(Stroke& stroke, const glm::dmat4& transform);

} // namespace lobe
