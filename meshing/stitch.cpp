#include "meshing/stitch.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <queue>
#include <string>
#include <tuple>

#include <glm/geometric.hpp>

#include "core/errors.h"
#include "meshing/polyline.h"

namespace lobe {

namespace {

using Index = std::size_t;

/// A stroke with points inserted to reach a given count, and for each entry the original
/// sample it snaps to.
struct Equalised {
    std::vector<glm::dvec3> positions;
    std::vector<int> snapped;
};

/// Inserts `extra` points, one at a time, at the currently largest gap (§4.2) by centripetal
/// Catmull-Rom midpoints, then snaps each inserted point to the nearer of the two original
/// samples around it, measured along the curve (which keeps the snapped indices in order).
/// With `single_ends` (open polylines of 3 or more points), points inserted next to an end
/// snap to the interior sample instead, so each end appears exactly once.
Equalised equalise(const std::vector<glm::dvec3>& p, bool closed, std::size_t extra, bool single_ends = false)
{
    const int n = static_cast<int>(p.size());
    const int total = n + static_cast<int>(extra);
    std::vector<glm::dvec3> pos(p.begin(), p.end());
    std::vector<int> next(static_cast<Index>(n)), prev(static_cast<Index>(n));
    for (int i = 0; i < n; ++i) {
        next[static_cast<Index>(i)] = closed ? (i + 1) % n : (i + 1 < n ? i + 1 : -1);
        prev[static_cast<Index>(i)] = closed ? (i + n - 1) % n : i - 1;
    }
    pos.reserve(static_cast<Index>(total));
    // Max-heap of segments (length, from, to); stale entries are skipped when popped.
    using Segment = std::tuple<double, int, int>;
    std::priority_queue<Segment> heap;
    for (int i = 0; i < n; ++i)
        if (next[static_cast<Index>(i)] >= 0)
            heap.emplace(glm::distance(pos[static_cast<Index>(i)], pos[static_cast<Index>(next[static_cast<Index>(i)])]),
                         i, next[static_cast<Index>(i)]);
    for (std::size_t added = 0; added < extra && !heap.empty();) {
        const auto [len, from, to] = heap.top();
        heap.pop();
        if (next[static_cast<Index>(from)] != to) continue;
        const int before = prev[static_cast<Index>(from)];
        const int after = next[static_cast<Index>(to)];
        const glm::dvec3& p1 = pos[static_cast<Index>(from)];
        const glm::dvec3& p2 = pos[static_cast<Index>(to)];
        const glm::dvec3 p0 = before >= 0 ? pos[static_cast<Index>(before)] : p1;
        const glm::dvec3 p3 = after >= 0 ? pos[static_cast<Index>(after)] : p2;
        const glm::dvec3 x = catmull_rom(p0, p1, p2, p3, 0.5);
        const int k = static_cast<int>(pos.size());
        pos.push_back(x);
        next.push_back(to);
        prev.push_back(from);
        next[static_cast<Index>(from)] = k;
        prev[static_cast<Index>(to)] = k;
        heap.emplace(glm::distance(p1, x), from, k);
        heap.emplace(glm::distance(x, pos[static_cast<Index>(to)]), k, to);
        ++added;
    }

    Equalised out;
    out.positions.reserve(pos.size());
    out.snapped.reserve(pos.size());
    std::vector<int> order;
    order.reserve(pos.size());
    for (int v = 0;;) {
        order.push_back(v);
        v = next[static_cast<Index>(v)];
        if (v < 0 || v == 0) break;
    }
    for (std::size_t i = 0; i < order.size();) {
        const int u = order[i];
        out.positions.push_back(pos[static_cast<Index>(u)]);
        out.snapped.push_back(u);
        // The run of inserted points after original u, up to the next original v.
        std::size_t j = i + 1;
        while (j < order.size() && order[j] >= n) ++j;
        if (j > i + 1) {
            const int v = j < order.size() ? order[j] : order[0];
            std::vector<double> cum{0.0};
            for (std::size_t m = i + 1; m <= j; ++m) {
                const int a = order[m - 1];
                const int b = m < order.size() ? order[m] : v;
                cum.push_back(cum.back() + glm::distance(pos[static_cast<Index>(a)], pos[static_cast<Index>(b)]));
            }
            const double half = 0.5 * cum.back();
            const bool to_v = single_ends && !closed && n >= 3 && u == 0;
            const bool to_u = single_ends && !closed && n >= 3 && v == n - 1;
            for (std::size_t m = i + 1; m < j; ++m) {
                out.positions.push_back(pos[static_cast<Index>(order[m])]);
                out.snapped.push_back(to_v ? v : (to_u ? u : (cum[m - i] <= half ? u : v)));
            }
        }
        i = j;
    }
    return out;
}

/// Unit direction from the barycentre, or zero when the point sits on it.
glm::dvec3 direction_from(const glm::dvec3& centre, const glm::dvec3& p)
{
    const glm::dvec3 d = p - centre;
    const double len = glm::length(d);
    return len > 1e-12 ? d / len : glm::dvec3(0.0);
}

double triangle_area(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c)
{
    return 0.5 * glm::length(glm::cross(b - a, c - a));
}

/// Collects triangles; positions are looked up by vertex index.
struct StripBuilder {
    StrokeStrip strip;
    std::vector<glm::dvec3> pos; // double copies of strip.positions

    int add_vertex(const glm::vec3& p, int stroke, int sample)
    {
        strip.positions.push_back(p);
        strip.sources.push_back({stroke, sample});
        pos.emplace_back(p);
        return static_cast<int>(strip.positions.size()) - 1;
    }

    /// The quad v0 → v1 → v2 → v3 (its orientation is kept). Repeated vertices (from
    /// snapping) reduce it to one triangle or nothing; otherwise it is split along the
    /// diagonal `forced` (Diagonal::V0V2 or V1V3) or, by default, the shorter diagonal,
    /// unless that leaves a zero-area triangle and the other does not.
    enum class Diagonal { Shorter, V0V2, V1V3 };
    void add_quad(int v0, int v1, int v2, int v3, Diagonal forced = Diagonal::Shorter)
    {
        // The corners with repeats next to each other dropped (a fixed array: this runs for
        // every quad of every strip).
        std::array<int, 4> q{v0, v1, v2, v3};
        std::size_t size = 4;
        for (bool changed = true; changed && size > 1;) {
            changed = false;
            for (std::size_t i = 0; i < size; ++i)
                if (q[i] == q[(i + 1) % size]) {
                    std::copy(q.begin() + static_cast<std::ptrdiff_t>(i) + 1, q.begin() + static_cast<std::ptrdiff_t>(size),
                              q.begin() + static_cast<std::ptrdiff_t>(i));
                    --size;
                    changed = true;
                    break;
                }
        }
        if (size == 3) {
            strip.triangles.push_back({q[0], q[1], q[2]});
            return;
        }
        if (size != 4 || q[0] == q[2] || q[1] == q[3]) return;
        auto P = [&](int v) { return pos[static_cast<Index>(v)]; };
        const double d02 = glm::distance(P(q[0]), P(q[2]));
        const double d13 = glm::distance(P(q[1]), P(q[3]));
        const double a02 = std::min(triangle_area(P(q[0]), P(q[1]), P(q[2])), triangle_area(P(q[0]), P(q[2]), P(q[3])));
        const double a13 = std::min(triangle_area(P(q[0]), P(q[1]), P(q[3])), triangle_area(P(q[1]), P(q[2]), P(q[3])));
        constexpr double tiny = 1e-14; // m²
        bool use02 = d02 <= d13;
        if (use02 && a02 <= tiny && a13 > tiny) use02 = false;
        if (!use02 && a13 <= tiny && a02 > tiny) use02 = true;
        if (forced != Diagonal::Shorter) use02 = forced == Diagonal::V0V2;
        if (use02) {
            strip.triangles.push_back({q[0], q[1], q[2]});
            strip.triangles.push_back({q[0], q[2], q[3]});
        } else {
            strip.triangles.push_back({q[0], q[1], q[3]});
            strip.triangles.push_back({q[1], q[2], q[3]});
        }
    }
};

void check_options(const StitchOptions& o, const std::string& who)
{
    if (!(o.merge_fraction >= 0.0 && o.merge_fraction <= 1.0))
        throw InvalidInput(who + ": merge_fraction must be in [0, 1]");
    if (o.max_score_pairs < 1) throw InvalidInput(who + ": max_score_pairs must be at least 1");
}

/// Validated double positions of a closed stroke, without a repeated end point.
std::vector<glm::dvec3> closed_points(const std::vector<glm::vec3>& s, const std::string& who)
{
    check_stroke_points(s, who);
    std::vector<glm::dvec3> p = to_double(s);
    if (glm::distance(p.front(), p.back()) <= 1e-6) p.pop_back();
    if (p.size() < StrokeLimits::min_points)
        throw InvalidInput(who + ": closed stroke has " + std::to_string(p.size()) +
                           " distinct points, at least 4 are needed");
    return p;
}

/// Evenly spread pair indices used for scoring.
std::vector<int> score_indices(int count, int max_pairs)
{
    const int m = std::min(count, max_pairs);
    std::vector<int> out;
    out.reserve(static_cast<Index>(m));
    for (int k = 0; k < m; ++k)
        out.push_back(static_cast<int>(static_cast<long long>(k) * count / m));
    return out;
}

} // namespace

StrokeStrip stitch_closed_closed(const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b,
                                 const StitchOptions& options)
{
    const std::string who = "stitch_closed_closed";
    check_options(options, who);
    const std::vector<glm::dvec3> pa = closed_points(a, who + " (first stroke)");
    const std::vector<glm::dvec3> pb = closed_points(b, who + " (second stroke)");
    check_strokes_differ(a, b, who);

    // Equal counts: insert on the stroke with fewer points.
    const std::size_t count = std::max(pa.size(), pb.size());
    const Equalised ea = equalise(pa, true, count - pa.size());
    const Equalised eb = equalise(pb, true, count - pb.size());
    const int N = static_cast<int>(count);

    // Barycentric directions (Eq. 2).
    const glm::dvec3 ca = polyline_barycentre(pa, true);
    const glm::dvec3 cb = polyline_barycentre(pb, true);
    std::vector<glm::dvec3> da, db;
    for (const glm::dvec3& p : ea.positions) da.push_back(direction_from(ca, p));
    for (const glm::dvec3& p : eb.positions) db.push_back(direction_from(cb, p));

    // For each direction of b: the cyclic shift whose pairs agree best in barycentric
    // direction, then the summed distance of those pairs. Pair i is (a_i, b_{σ(i)}).
    const std::vector<int> probe = score_indices(N, options.max_score_pairs);
    auto partner = [N](bool reversed, int shift, int i) {
        const int j = (i + shift) % N;
        return reversed ? (N - j) % N : j;
    };
    int best_shift[2] = {0, 0};
    double distance_sum[2] = {0.0, 0.0};
    // The scores of all shifts at once, a probe at a time: b's directions in partner order,
    // written out twice so that shift i + shift needs no wrapping, so the inner loop runs over
    // consecutive shifts (and vectorises). Every score still sums its probes in their order,
    // each term as glm::dot forms it: the same numbers as a loop over shifts.
    std::vector<double> bx(2 * static_cast<Index>(N)), by(bx.size()), bz(bx.size()), score(static_cast<Index>(N));
    for (int r = 0; r < 2; ++r) {
        const bool reversed = r == 1;
        for (int k = 0; k < 2 * N; ++k) {
            const glm::dvec3& d = db[static_cast<Index>(partner(reversed, 0, k % N))];
            bx[static_cast<Index>(k)] = d.x;
            by[static_cast<Index>(k)] = d.y;
            bz[static_cast<Index>(k)] = d.z;
        }
        std::fill(score.begin(), score.end(), 0.0);
        for (int i : probe) {
            const glm::dvec3& d = da[static_cast<Index>(i)];
            const double* x = bx.data() + i;
            const double* y = by.data() + i;
            const double* z = bz.data() + i;
            for (Index shift = 0; shift < static_cast<Index>(N); ++shift)
                score[shift] += d.x * x[shift] + d.y * y[shift] + d.z * z[shift];
        }
        double best = -std::numeric_limits<double>::infinity();
        for (int shift = 0; shift < N; ++shift)
            if (score[static_cast<Index>(shift)] > best + 1e-12) {
                best = score[static_cast<Index>(shift)];
                best_shift[r] = shift;
            }
        for (int i : probe)
            distance_sum[r] += glm::distance(ea.positions[static_cast<Index>(i)],
                                             eb.positions[static_cast<Index>(partner(reversed, best_shift[r], i))]);
    }
    const bool reversed = distance_sum[1] < distance_sum[0];
    const int shift = best_shift[reversed ? 1 : 0];

    StripBuilder sb;
    const int offset_b = static_cast<int>(pa.size());
    for (std::size_t i = 0; i < pa.size(); ++i) sb.add_vertex(a[i], 0, static_cast<int>(i));
    for (std::size_t j = 0; j < pb.size(); ++j) sb.add_vertex(b[j], 1, static_cast<int>(j));
    auto va = [&](int i) { return ea.snapped[static_cast<Index>(i)]; };
    auto vb = [&](int i) { return offset_b + eb.snapped[static_cast<Index>(partner(reversed, shift, i))]; };
    for (int i = 0; i < N; ++i) {
        const int i1 = (i + 1) % N;
        sb.add_quad(va(i), va(i1), vb(i1), vb(i));
    }
    return std::move(sb.strip);
}

StrokeStrip stitch_open_closed(const std::vector<glm::vec3>& open, const std::vector<glm::vec3>& closed,
                               const StitchOptions& options)
{
    const std::string who = "stitch_open_closed";
    check_options(options, who);
    check_stroke_points(open, who + " (open stroke)");
    const std::vector<glm::dvec3> po = to_double(open);
    const std::vector<glm::dvec3> pc = closed_points(closed, who + " (closed stroke)");
    check_strokes_differ(open, closed, who);
    const int nc = static_cast<int>(pc.size());
    const int no = static_cast<int>(po.size());

    // Split points: barycentric directions in the closed stroke's plane (the open stroke's
    // ends extended out to the ring).
    const glm::dvec3 centre = polyline_barycentre(pc, true);
    const glm::dvec3 area = loop_vector_area(pc);
    const double area_len = glm::length(area);
    const glm::dvec3 normal = area_len > 1e-12 ? area / area_len : glm::dvec3(0.0);
    auto planar_direction = [&](const glm::dvec3& p) {
        const glm::dvec3 d = p - centre;
        const glm::dvec3 in_plane = d - normal * glm::dot(d, normal);
        return glm::length(in_plane) > 1e-9 * glm::length(d) ? direction_from(glm::dvec3(0.0), in_plane)
                                                             : direction_from(glm::dvec3(0.0), d);
    };
    auto best_match = [&](const glm::dvec3& end) {
        const glm::dvec3 d = planar_direction(end);
        int best = 0;
        double best_dot = -std::numeric_limits<double>::infinity();
        for (int j = 0; j < nc; ++j) {
            const double s = glm::dot(d, planar_direction(pc[static_cast<Index>(j)]));
            if (s > best_dot + 1e-12) { best_dot = s; best = j; }
        }
        return best;
    };
    const int j0 = best_match(po.front());
    const int j1 = best_match(po.back());
    if (j0 == j1)
        throw InvalidInput(who + ": both ends of the open stroke point to the same sample of the closed stroke");

    // Vertices: open samples (unless merged into their split point), then closed samples.
    StripBuilder sb;
    const double merge = options.merge_fraction * median_spacing(pc, true);
    const bool merge_front = glm::distance(po.front(), pc[static_cast<Index>(j0)]) < merge;
    const bool merge_back = glm::distance(po.back(), pc[static_cast<Index>(j1)]) < merge;
    std::vector<int> vo(static_cast<Index>(no), -1), vc(static_cast<Index>(nc), -1);
    for (int i = 0; i < no; ++i) {
        if ((i == 0 && merge_front) || (i == no - 1 && merge_back)) continue;
        vo[static_cast<Index>(i)] = sb.add_vertex(open[static_cast<Index>(i)], 0, i);
    }
    for (int j = 0; j < nc; ++j) vc[static_cast<Index>(j)] = sb.add_vertex(closed[static_cast<Index>(j)], 1, j);
    if (merge_front) vo.front() = vc[static_cast<Index>(j0)];
    if (merge_back) vo.back() = vc[static_cast<Index>(j1)];

    // The two arcs from j0 to j1: forward and backward around the closed stroke.
    for (int side = 0; side < 2; ++side) {
        std::vector<int> arc{j0};
        while (arc.back() != j1) arc.push_back(side == 0 ? (arc.back() + 1) % nc : (arc.back() + nc - 1) % nc);
        std::vector<glm::dvec3> arc_pos;
        for (int j : arc) arc_pos.push_back(pc[static_cast<Index>(j)]);
        const std::size_t count = std::max(po.size(), arc.size());
        const Equalised eo = equalise(po, false, count - po.size());
        // The split points belong to both arcs: each appears once per arc, and the end quads
        // are split from the open stroke's end, so no open-stroke edge is fanned to a split
        // point from both sides (that would put the same triangle on both sides).
        const Equalised ea = equalise(arc_pos, false, count - arc.size(), true);
        auto o = [&](std::size_t i) { return vo[static_cast<Index>(eo.snapped[i])]; };
        auto c = [&](std::size_t i) { return vc[static_cast<Index>(arc[static_cast<Index>(ea.snapped[i])])]; };
        using D = StripBuilder::Diagonal;
        for (std::size_t i = 0; i + 1 < count; ++i) {
            const bool first = i == 0;
            const bool last = i + 2 == count;
            // Opposite orientations on the two sides, so the disc is consistently oriented.
            if (side == 0)
                sb.add_quad(o(i), o(i + 1), c(i + 1), c(i), first ? D::V0V2 : (last ? D::V1V3 : D::Shorter));
            else
                sb.add_quad(o(i + 1), o(i), c(i), c(i + 1), first ? D::V1V3 : (last ? D::V0V2 : D::Shorter));
        }
    }
    return std::move(sb.strip);
}

} // namespace lobe
