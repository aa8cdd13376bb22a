#pragma once
/// \file lobe_surface.h
/// The closed surface of one lobe through all of its strokes (§4.2, Fig. 5 and 9). CGAL
/// works behind this plain interface (lobe_surface_cgal.cpp; the stages of a build are listed
/// in lobe_surface_builder.h). See docs/lobes.md.
///
/// A lobe is star-shaped around its centre: every point of a foliage envelope is seen from
/// inside it. The strokes, seen from the centre, are curves on the sphere of directions.
/// Their constrained Delaunay triangulation on that sphere (stereographic projection from a
/// direction no stroke comes near, so the planar CDT is the spherical one) connects each
/// stroke to its neighbours: between two strokes it is a strip, over a region a single
/// stroke bounds it is a cap. Where two strokes cross, the crossing becomes a vertex of
/// both. Lifting every vertex back to its distance from the centre gives a closed,
/// outward-oriented 2-manifold that passes through every sample and cannot fold, because
/// each triangle covers its own piece of the sphere of directions.
///
/// Regions bounded by exactly two closed strokes that cross nothing (stacked loops, Fig.
/// 5) are stitched with the paper's strip (stitch_closed_closed), which depends on those
/// two strokes only. Where the strokes leave a gap wider than the attractor spacing (caps,
/// far-apart strokes), interpolated vertices fill it: their distance from the centre is
/// the harmonic interpolation of the strokes' distances, so a cap is a smooth dome.

#include <cstdint>
#include <memory>
#include <vector>

#include <glm/vec3.hpp>

#include "core/mesh.h"
#include "core/settings.h"

namespace lobe {

/// A lobe stroke ready for the surface: sampled (Eq. 1), closed cleanly when closed.
struct LobeStrokeSamples {
    std::int64_t id = 0;             ///< the stroke's id in the document
    std::vector<glm::vec3> points;   ///< samples in drawing order, no repeated end point
    bool closed = false;
};

/// Options of the lobe surface. The paper gives no numbers for these; they are ours.
struct LobeSurfaceOptions {
    /// Gaps between strokes are filled until every triangle's circumscribed circle, seen
    /// from the centre, spans at most the angle at which a flat facet departs from a sphere
    /// of the local radius by `fill_sagitta_m` …
    double fill_sagitta_m = 0.0015;
    /// … and at most the angle of this edge length (the attractor spacing).
    double fill_edge_m = LobeSettings{}.edge_length_m;
    /// The fill is laid this many times coarser than the two bounds above (in angle; 1 to
    /// 4). Remeshing puts the attractors at the target spacing and lifts every vertex it makes
    /// along its ray from the centre to the distance interpolated across the fill's triangles
    /// (RemeshOptions::radial_centre), so the remeshed lobe keeps its curvature between fill
    /// vertices (what 2 saves: docs/lobes.md, step 6 and "Measured").
    /// A lobe that is not remeshed (remesh_iterations 0) keeps 1: its fill is its attractors.
    double fill_coarseness = 2.0;
    /// A stroke sample closer than this fraction of its stroke's median spacing to a
    /// crossing with another stroke is dropped in favour of the crossing vertex (no
    /// sliver triangles at crossings). Stroke end points are never dropped.
    double crossing_merge_fraction = 0.25;
    /// Stitch regions bounded by exactly two uncrossed closed strokes with the paper's
    /// strip (stitch_closed_closed) instead of the Delaunay triangulation.
    bool paper_strips = true;
    /// The lobe radius the fill density is derived from; 0: the strokes' mean distance from
    /// the centre. A progressive lobe keeps it with its centre, so that adding a stroke does
    /// not re-lay the fill elsewhere.
    double reference_radius_m = 0.0;
    /// Upper bound on interpolated vertices (bounds time and memory on any input).
    int max_fill_vertices = 20000;
};

/// Where a surface vertex comes from.
enum class LobeVertexKind : std::uint8_t {
    Sample,   ///< a stroke sample: `stroke` indexes the input strokes, `sample` its points
    Segment,  ///< on the straight segment of `stroke` after sample `sample` (long segments
              ///< are subdivided so that, seen from the centre, every piece is short)
    Crossing, ///< where two strokes cross: `stroke` and `other_stroke`
    Fill,     ///< interpolated (caps, wide gaps)
};

struct LobeVertexOrigin {
    LobeVertexKind kind = LobeVertexKind::Fill;
    int stroke = -1;
    int sample = -1;
    int other_stroke = -1;
};

/// What a build found over all of its strokes (the pole and its search, the crossings, the
/// radius model's normal equations per stroke), kept so that the build after one more stroke
/// looks only at that stroke where the answer cannot differ (lobe_surface_builder.h). Never
/// changes the result.
struct LobeBuildMemo;

/// The surface and how it was made.
struct LobeSurface {
    /// Closed, outward-oriented 2-manifold; feature_edges are the stroke segments (split at
    /// crossings): the constraints of remeshing.
    TriangleMesh mesh;
    std::vector<LobeVertexOrigin> origins; ///< #V
    glm::dvec3 centre{0.0};
    double reference_radius = 0;           ///< see LobeSurfaceOptions::reference_radius_m
    std::size_t paper_strip_triangles = 0; ///< triangles from stitch_closed_closed strips
    std::vector<std::uint8_t> paper_strip_faces; ///< #F: 1 for those triangles
    std::size_t crossings = 0;             ///< crossing vertices (crossings closer than the merge distance share one)
    std::shared_ptr<const LobeBuildMemo> memo; ///< for continue_lobe_surface; may be null
};

/// The length-weighted centroid of the strokes (of the closed ones when there is any).
/// \pre at least one stroke with at least one point.
glm::dvec3 lobe_stroke_centroid(const std::vector<LobeStrokeSamples>& strokes);

/// Builds the surface of a lobe around `centre`.
/// \pre every stroke has ≥ 4 finite samples (see prepare_lobe_stroke in lobe.h).
/// \throw InvalidInput (one line) when the strokes cannot make a valid lobe around
/// `centre`: a stroke folds back over itself or over the centre as seen from it, a stroke
/// passes through the centre, two strokes retrace each other, or the lifted surface would
/// fold (the lobe is not star-shaped around `centre`).
LobeSurface build_lobe_surface(const std::vector<LobeStrokeSamples>& strokes, const glm::dvec3& centre,
                               const LobeSurfaceOptions& options = {});

} // namespace lobe
