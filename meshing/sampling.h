#pragma once
/// \file sampling.h
/// Preparing raw lobe strokes for stitching (§4.1): closed/open classification, clean
/// closing, and curvature-weighted sampling (Eq. 1). See docs/lobe-strokes.md.

#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "core/settings.h"

namespace lobe {

/// Curvature-weighted sampling (Eq. 1). The defaults are the paper's where it gives them.
struct SamplingOptions {
    /// k of Eq. 1 (paper: 2). Steps are ⌊k·log2(2 + 1/ρ)⌋ raw samples, ρ = max(κ, 0.01),
    /// clamped to [min_step, max_step] = [2, 13] (the range k = 2 gives).
    double k = 2.0;
    /// Picks the start sample of a closed stroke (the paper starts at a random point).
    /// Open strokes always start at their first point, so the seed does not affect them.
    std::uint64_t seed = 0;
    /// κᵢ is the turning angle between the directions from point i−h to i and from i to
    /// i+h, divided by h (radians per raw sample), with h = neighbourhood.
    int neighbourhood = 3;
    /// Radius of the binomial smoothing applied to a copy of the stroke before κ is
    /// estimated (4: weights 1 8 28 56 70 56 28 8 1, a standard deviation of √2 samples),
    /// so millimetre jitter does not read as curvature.
    /// Samples are always original raw points. 0 turns it off.
    int smoothing_radius = 4;
};

/// Step bounds and the curvature floor of Eq. 1.
struct CurvatureSteps {
    static constexpr int min_step = 2;
    static constexpr int max_step = 13;
    static constexpr double min_rho = 0.01;
};

/// Everything sample_by_curvature_detailed computes, for tests and tools.
struct CurvatureSampling {
    std::vector<glm::vec3> points; ///< the samples (copies of raw points), in stroke order
    std::vector<int> indices;      ///< raw index of each sample
    /// steps[i]: raw samples from sample i to sample i + 1. Closed strokes: the last entry
    /// wraps to the first sample, so the steps add up to the raw count; open strokes: one
    /// entry fewer than samples, adding up to the raw count − 1.
    std::vector<int> steps;
    std::vector<double> curvature; ///< κ of each raw point, radians per raw sample
    std::vector<int> step_at;      ///< the Eq. 1 step at each raw point
};

/// κ of each raw point (radians per raw sample; see SamplingOptions::neighbourhood).
/// Open strokes shrink the neighbourhood towards their ends; end points copy their
/// neighbour's κ. \throw InvalidInput for degenerate strokes (see check_stroke_points).
std::vector<double> turning_per_sample(const std::vector<glm::vec3>& raw, bool closed,
                                       const SamplingOptions& options = {});

/// Eq. 1: ⌊k·log2(2 + 1/max(κ, 0.01))⌋ clamped to [2, 13].
int curvature_step(double kappa, double k = 2.0);

/// Curvature-weighted sampling (Eq. 1): walk along the raw stroke from a start point,
/// each time advancing by the step computed at the current point.
/// - Closed strokes (`closed`, no repeated end point; a repeated one is ignored): the walk
///   starts at a raw index drawn from `options.seed` and wraps around to it.
/// - Open strokes start at the first point and always keep both end points.
/// - A closing (or final) step shorter than half the step before it is merged into that
///   step, or the two are split evenly when the merged step would exceed 13: no step of 1,
///   no short last segment.
/// Strokes too short for four Eq. 1 samples get four evenly spaced ones.
/// \pre at least 4 raw points, finite, within 1 km of the origin, not all on one line.
/// \throw InvalidInput when the precondition does not hold (one-line message).
CurvatureSampling sample_by_curvature_detailed(const std::vector<glm::vec3>& raw, bool closed,
                                               const SamplingOptions& options = {});

/// The samples of sample_by_curvature_detailed.
std::vector<glm::vec3> sample_by_curvature(const std::vector<glm::vec3>& raw, bool closed,
                                           const SamplingOptions& options = {});

/// When a raw stroke counts as closed (§4.1). The paper does not give numbers; these are
/// ours.
struct ClosureOptions {
    /// Closed when the gap is below this fraction of the stroke's length …
    double max_gap_fraction = LobeSettings{}.closed_gap_fraction;
    /// … and below this many metres.
    double max_gap_m = LobeSettings{}.closed_gap_max_m;
    /// An overlapping tail is looked for within this fraction of the length at each end
    /// (at most 2,000 points each).
    double overlap_fraction = 0.25;
};

/// The gap between a stroke's ends, in metres: the smaller of the distance from the last
/// point to the first `overlap_fraction` of the polyline and from the first point to its
/// last `overlap_fraction`. A tail drawn past the start point has a gap of about zero.
/// \throw InvalidInput for degenerate strokes.
double closure_gap(const std::vector<glm::vec3>& points, const ClosureOptions& options = {});

/// Whether the person closed the stroke: closure_gap < max_gap_fraction · length and
/// < max_gap_m. \throw InvalidInput for degenerate strokes.
bool is_closed_stroke(const std::vector<glm::vec3>& points, const ClosureOptions& options = {});

/// The stroke as a clean closed loop, with no repeated end point: an overlapping tail
/// (or head) is cut at the closest pair of points between the stroke's two ends; an end
/// point closer to the start than half the stroke's median spacing is dropped; a gap
/// longer than 1.5 spacings is bridged with Catmull-Rom points about one spacing apart.
/// Meant for strokes is_closed_stroke accepts; on others it bridges the whole gap.
/// \throw InvalidInput for degenerate strokes, or when fewer than 4 points remain.
std::vector<glm::vec3> close_stroke(const std::vector<glm::vec3>& points, const ClosureOptions& options = {});

} // namespace lobe
