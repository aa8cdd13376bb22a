#pragma once
/// \file stroke_edit.h
/// Bézier editing of a stroke segment (Zhang et al. 2021, Fig. 6a): fingertips pick a
/// segment of a stroke, and dragging bends it as a cubic Bézier curve whose end points stay
/// fixed. The segment is deformed by the *change* of that Bézier (original points plus the
/// Bézier's displacement at their parameter), so the stroke keeps its small-scale detail.
/// Everything is decided by the drag (its start, its end and, optionally, the other hand's
/// fingertip at its start), so a recorded drag replays to the same stroke.
/// See docs/editing.md.

#include <array>
#include <optional>
#include <vector>

#include <glm/vec3.hpp>

#include "core/stroke.h"

namespace lobe {

/// Settings of stroke editing. The paper gives no numbers; these are ours.
struct StrokeEditOptions {
    /// A fingertip farther than this from every point of the stroke picks nothing (metres).
    double pick_distance_m = 0.03;
    /// One-hand edits: arc length of the segment on each side of the picked point (metres),
    /// clipped at an open stroke's ends; on closed strokes the segment wraps around.
    double half_length_m = 0.08;
    /// The point that follows the drag must lie at a parameter in [f, 1 − f] of the segment.
    /// Closer to a fixed end the Bézier would have to overshoot: at parameter τ the control
    /// points move more than 1/(3τ) times the drag, and the curve bulges past the fingertip
    /// (by 24% at τ = 0.2, 91% at τ = 0.1; not at all at τ = 0.5). It matters only where the segment is clipped at
    /// an open stroke's end (a pick within f / (1 − f) · half_length_m, 2 cm by default, of
    /// that end) or for very uneven point spacing between two fingertips.
    double min_pick_fraction = 0.2;
};

/// The part of a stroke an edit deforms.
struct StrokeSegment {
    /// Stroke point indices from one end of the segment to the other, in stroke order
    /// (wrapping past the last point on closed strokes); both ends included. At least 3.
    std::vector<int> indices;
    /// Arc-length parameter of each point along the segment: t.front() = 0, t.back() = 1.
    std::vector<double> t;
    /// Position in `indices` of the point that follows the drag.
    std::size_t pick = 0;
    /// Arc length of the segment, metres.
    double length_m = 0.0;

    int pick_index() const { return indices[pick]; } ///< stroke index of the point that follows the drag
    double pick_t() const { return t[pick]; }        ///< its parameter τ
};

/// A stroke-edit drag: where the pinch started and where it is now (or was released), and
/// the other hand's index tip at the start when it takes part.
struct StrokeDrag {
    glm::vec3 start{0.0f};
    glm::vec3 end{0.0f};
    std::optional<glm::vec3> other_tip;
};

/// What edit_stroke did, for display (the control polygon) and tests.
struct StrokeEditResult {
    StrokeSegment segment;
    /// Cubic Bézier fitted to the segment before the edit (least squares over the segment
    /// points at their parameters t, end points fixed to the segment's ends) and after it
    /// (the same with the two inner control points moved). Every segment point moved by
    /// after(t) − before(t).
    std::array<glm::dvec3, 4> bezier_before{}, bezier_after{};
};

/// Index of the stroke point nearest to `p` (the lowest index on ties) and its distance.
/// \throw InvalidInput for a stroke with no points or a non-finite `p`.
std::size_t nearest_stroke_point(const Stroke& stroke, const glm::vec3& p, double* distance_m = nullptr);

/// One fingertip: the nearest stroke point is picked and the segment runs
/// options.half_length_m of arc length each side of it (to the first stroke point at least
/// that far along; clipped at an open stroke's ends; wrapping on closed strokes, at most
/// half the points each side). The picked point follows the drag.
/// \param closed whether the stroke is a loop (its last point joins its first).
/// \throw InvalidInput (one line, starting with "stroke edit:") for a stroke with fewer than
///        3 points, non-finite points or zero length; a non-finite fingertip; a fingertip
///        farther than options.pick_distance_m from the stroke; bad options; a pick closer to
///        a fixed end than options.min_pick_fraction allows.
StrokeSegment pick_stroke_segment(const Stroke& stroke, bool closed, const glm::vec3& tip,
                                  const StrokeEditOptions& options = {});

/// Two fingertips: each picks its nearest stroke point, and those are the ends of the
/// segment (on a closed stroke, the shorter of the two arcs between them). The segment point
/// nearest to the middle of its arc length follows the drag.
/// \throw InvalidInput as the one-fingertip form, and when either fingertip is too far from
///        the stroke or the two pick fewer than 3 points.
StrokeSegment pick_stroke_segment(const Stroke& stroke, bool closed, const glm::vec3& tip,
                                  const glm::vec3& other_tip, const StrokeEditOptions& options = {});

/// The moves (ΔP1, ΔP2) of the inner control points of a cubic Bézier with fixed ends that
/// move its point at parameter τ by exactly `displacement`, with the least ‖ΔP1‖² + ‖ΔP2‖²:
/// ΔPᵢ = bᵢ(τ) d / (b₁(τ)² + b₂(τ)²), b₁ = 3t(1 − t)², b₂ = 3t²(1 − t).
/// \pre 0 < τ < 1. \throw InvalidInput otherwise or for a non-finite displacement.
std::array<glm::dvec3, 2> bezier_control_offsets(double pick_t, const glm::dvec3& displacement);

/// The Bézier displacement at parameter t when the point at τ moves by d:
/// b₁(t) ΔP1 + b₂(t) ΔP2 with the offsets above. 0 at t = 0 and t = 1, d at t = τ.
glm::dvec3 bezier_displacement(double t, double pick_t, const glm::dvec3& displacement);

/// Least-squares cubic Bézier through the segment's points at their parameters, with the
/// end control points on the segment's ends (chord thirds when the fit is singular).
std::array<glm::dvec3, 4> fit_segment_bezier(const Stroke& stroke, const StrokeSegment& segment);

/// Bends the segment: every segment point moves by bezier_displacement(t, τ, displacement);
/// the picked point moves by exactly `displacement`, the two ends and every point outside
/// the segment keep their bits. Times are unchanged. Starts from whatever the stroke holds,
/// so live editing passes the stroke as it was when the pinch started.
/// \throw InvalidInput for a segment that does not fit the stroke or a non-finite
///        displacement; the stroke is unchanged when it throws.
void bend_stroke_segment(Stroke& stroke, const StrokeSegment& segment, const glm::dvec3& displacement);

/// A whole stroke edit: picks the segment with the drag's start (and other_tip when
/// present), then bends it by end − start. The stroke is unchanged when it throws.
/// \throw InvalidInput what pick_stroke_segment and bend_stroke_segment throw, and for
///        a non-finite drag.
StrokeEditResult edit_stroke(Stroke& stroke, bool closed, const StrokeDrag& drag,
                             const StrokeEditOptions& options = {});

} // namespace lobe
