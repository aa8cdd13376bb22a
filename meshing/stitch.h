#pragma once
/// \file stitch.h
/// Stitching sampled lobe strokes into triangle strips (§4.2, Fig. 3–4). The strips are
/// plain data; lobe meshes are built on top of them. See docs/lobe-strokes.md.

#include <array>
#include <vector>

#include <glm/vec3.hpp>

namespace lobe {

/// Stitching options. The paper gives no numbers for these; they are ours.
struct StitchOptions {
    /// Open–closed stitching: an end of the open stroke closer to its matched point of the
    /// closed stroke than this fraction of the closed stroke's median sample spacing is
    /// merged into that point (no sliver triangles where the cap meets the ring).
    double merge_fraction = 0.25;
    /// The start-pair search (Eq. 2) and the direction test score at most this many evenly
    /// spread pairs per candidate, which bounds their cost on long strokes.
    int max_score_pairs = 256;
};

/// Where a strip vertex comes from: `stroke` is 0 for the first stroke argument and 1 for
/// the second; `sample` indexes that stroke's sample points.
struct StripVertexSource {
    int stroke = 0;
    int sample = 0;
};

/// A triangle strip between strokes. Every vertex is one of the input sample points (its
/// position is a copy), each sample appears at most once, so strips that share a stroke
/// share its vertices when merged by source.
struct StrokeStrip {
    std::vector<glm::vec3> positions;          ///< #V vertex positions (metres)
    std::vector<StripVertexSource> sources;    ///< #V: the sample each vertex is
    std::vector<std::array<int, 3>> triangles; ///< #F vertex indices, consistently oriented
};

/// Stitches two closed sampled strokes into a band (§4.2, Fig. 3):
/// 1. the stroke with fewer points gets points inserted one at a time at its largest gap
///    (centripetal Catmull-Rom midpoint) until both have the same count;
/// 2. b is made to run the same way round as a: of both directions, the one whose pairs are
///    closer in sum;
/// 3. the start pair is chosen by barycentric direction (Eq. 2): the cyclic shift that best
///    matches each point's unit direction from its stroke's barycentre with its partner's,
///    over the whole loop (not the nearest points);
/// 4. consecutive pairs form quads, split along the shorter diagonal;
/// 5. every inserted point is snapped to the nearer of the two original samples around it,
///    so quads next to it become single triangles and all vertices are original samples.
/// Triangles run a_i → a_{i+1} → b_{i+1} → b_i along a's given order. Vertices: a's samples
/// (0 … #a − 1), then b's. Every sample of both strokes is used; boundary edges are exactly
/// the edges of the two loops.
/// \pre both strokes closed (a repeated end point is ignored), at least 4 points each,
/// finite, within 1 km of the origin, not all on one line, not identical.
/// \throw InvalidInput when the precondition does not hold (one-line message).
StrokeStrip stitch_closed_closed(const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b,
                                 const StitchOptions& options = {});

/// Caps a closed stroke with an open one (§4.2, Fig. 4). The closed stroke's two points
/// whose barycentric directions best match the directions from its barycentre towards the
/// open stroke's ends (both projected onto the closed stroke's plane, i.e. the ends
/// extended out to the ring) split it into two arcs; the open stroke is stitched to each
/// arc as in stitch_closed_closed (equal counts, pairs, shorter diagonals, snapping), with
/// the ends paired to the split points. The two sides share the open stroke's vertices: the
/// result is a disc whose boundary is exactly the closed stroke's loop. An open end close
/// to its split point (StitchOptions::merge_fraction) becomes that point's vertex.
/// Stroke 0 in the sources is `open`, stroke 1 is `closed`.
/// \pre as stitch_closed_closed, `open` taken as open; the two ends must match different
/// points of the closed stroke.
/// \throw InvalidInput when the precondition does not hold (one-line message).
StrokeStrip stitch_open_closed(const std::vector<glm::vec3>& open, const std::vector<glm::vec3>& closed,
                               const StitchOptions& options = {});

} // namespace lobe
