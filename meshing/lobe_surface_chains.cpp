// Stage 4 of a lobe surface build (lobe_surface_builder.h): each stroke's vertices in order,
// its crossings with other strokes among them. No CGAL.
#include "meshing/lobe_surface_builder.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>
#include <utility>

#include <glm/geometric.hpp>

#include "core/errors.h"

namespace lobe {

namespace lobe_surface_detail {

namespace {

/// The point at parameter `t` of segment `seg` of a stroke (`points`; the last segment of a
/// closed stroke ends at its first point).
glm::dvec3 point_on_segment(const std::vector<glm::vec3>& pts, int seg, double t)
{
    const glm::dvec3 p0(pts[static_cast<Index>(seg)]);
    const glm::dvec3 p1(pts[(static_cast<Index>(seg) + 1) % pts.size()]);
    return p0 + t * (p1 - p0);
}

/// The parameter s of the point p0 + s (p1 − p0) in direction `dir` from the centre (the
/// origin here), clamped to the segment; `fallback` where there is none.
double parameter_along(const glm::dvec3& p0, const glm::dvec3& p1, const glm::dvec3& dir, double fallback)
{
    // p0 + s (p1 − p0) parallel to dir: cross(p0, dir) + s cross(p1 − p0, dir) = 0.
    const glm::dvec3 u = glm::cross(p0, dir), w = glm::cross(p1 - p0, dir);
    const double ww = glm::dot(w, w);
    const double s = ww > 0.0 ? -glm::dot(u, w) / ww : fallback;
    return std::isfinite(s) ? std::clamp(s, 0.0, 1.0) : fallback;
}

} // namespace

void LobeSurfaceBuilder::build_chains()
{
    // Nodes: every sample, then every crossing.
    add_sample_nodes();
    add_crossing_nodes();
    merge_close_crossings();
    // Per stroke: (segment, parameter, node) of every crossing on it.
    std::vector<std::vector<CrossingOnStroke>> on(strokes_.size());
    for (const Crossing& c : crossings_) {
        on[static_cast<Index>(c.a)].push_back({c.seg, c.s, c.node});
        on[static_cast<Index>(c.b)].push_back({c.other_seg, c.t, c.node});
    }
    chains_.assign(strokes_.size(), {});
    for (Index s = 0; s < strokes_.size(); ++s) chains_[s] = subdivided_chain(s, stroke_chain(s, std::move(on[s])));
}

void LobeSurfaceBuilder::add_sample_nodes()
{
    sample_offset_.assign(strokes_.size() + 1, 0);
    for (Index s = 0; s < strokes_.size(); ++s) sample_offset_[s + 1] = sample_offset_[s] + strokes_[s].points.size();
    sample_node_.assign(sample_offset_.back(), -1);
    for (Index s = 0; s < strokes_.size(); ++s)
        for (Index i = 0; i < dirs_[s].size(); ++i) {
            Node n;
            n.dir = dirs_[s][i];
            n.radius = radii_[s][i];
            n.origin = {LobeVertexKind::Sample, static_cast<int>(s), static_cast<int>(i), -1};
            sample_node_[sample_offset_[s] + i] = add_node(n);
        }
}

void LobeSurfaceBuilder::add_crossing_nodes()
{
    for (Crossing& c : crossings_) {
        const auto& a_points = strokes_[static_cast<Index>(c.a)].points;
        const auto& b_points = strokes_[static_cast<Index>(c.b)].points;
        // Where the two segments cross seen from the centre: the direction common to the
        // planes through the centre and each segment, and on each segment the point in that
        // direction. Found in 3D rather than in the projection, so that it does not depend on
        // the pole: a stroke that moves the pole leaves the crossings of other strokes (and
        // with them the regions they bound) where they were.
        const glm::dvec3 a0 = point_on_segment(a_points, c.seg, 0.0) - centre_, a1 = point_on_segment(a_points, c.seg, 1.0) - centre_;
        const glm::dvec3 b0 = point_on_segment(b_points, c.other_seg, 0.0) - centre_,
                         b1 = point_on_segment(b_points, c.other_seg, 1.0) - centre_;
        glm::dvec3 d = glm::cross(glm::cross(a0, a1), glm::cross(b0, b1));
        double sa = c.s, sb = c.t;
        const double dl = glm::length(d);
        if (dl > 1e-12 * glm::length(a1 - a0) * glm::length(b1 - b0) * (glm::length(a0) + glm::length(b0))) {
            d /= dl;
            if (glm::dot(d, a0 + a1 + b0 + b1) < 0.0) d = -d;
            sa = parameter_along(a0, a1, d, c.s);
            sb = parameter_along(b0, b1, d, c.t);
        }
        c.s = sa; // the chains order crossings along each segment by these
        c.t = sb;
        const glm::dvec3 pa = point_on_segment(a_points, c.seg, sa), pb = point_on_segment(b_points, c.other_seg, sb);
        const glm::dvec3 mid = 0.5 * (pa + pb);
        Node n;
        n.dir = glm::normalize(mid - centre_);
        n.radius = glm::length(mid - centre_);
        n.origin = {LobeVertexKind::Crossing, c.a, -1, c.b};
        c.node = add_node(n);
    }
}

void LobeSurfaceBuilder::merge_close_crossings()
{
    // Crossings closer together than the merge distance (several strokes through about one
    // point, or two strokes crossing twice in quick succession) become one vertex, so no
    // sliver is left between them.
    if (crossings_.size() > 4000) return;
    std::vector<int> parent(nodes_.size());
    for (Index i = 0; i < parent.size(); ++i) parent[i] = static_cast<int>(i);
    auto find = [&](int x) {
        while (parent[static_cast<Index>(x)] != x) x = parent[static_cast<Index>(x)] = parent[static_cast<Index>(parent[static_cast<Index>(x)])];
        return x;
    };
    auto pos = [&](int id) { return centre_ + nodes_[static_cast<Index>(id)].radius * nodes_[static_cast<Index>(id)].dir; };
    for (Index i = 0; i < crossings_.size(); ++i)
        for (Index j = i + 1; j < crossings_.size(); ++j) {
            const Crossing& x = crossings_[i];
            const Crossing& y = crossings_[j];
            const double merge = options_.crossing_merge_fraction *
                                 std::min({spacing_[static_cast<Index>(x.a)], spacing_[static_cast<Index>(x.b)],
                                           spacing_[static_cast<Index>(y.a)], spacing_[static_cast<Index>(y.b)]});
            if (glm::distance(pos(x.node), pos(y.node)) < merge) parent[static_cast<Index>(find(x.node))] = find(y.node);
        }
    std::map<int, std::pair<glm::dvec3, int>> sums; // root → (sum of positions, count)
    for (const Crossing& c : crossings_) {
        auto& e = sums[find(c.node)];
        e.first += pos(c.node);
        e.second += 1;
    }
    for (auto& [root, e] : sums) {
        const glm::dvec3 p = e.first / static_cast<double>(e.second) - centre_;
        nodes_[static_cast<Index>(root)].radius = glm::length(p);
        nodes_[static_cast<Index>(root)].dir = p / glm::length(p);
    }
    for (Crossing& c : crossings_) c.node = find(c.node);
}

std::vector<int> LobeSurfaceBuilder::stroke_chain(Index s, std::vector<CrossingOnStroke> list) const
{
    std::sort(list.begin(), list.end(), [](const CrossingOnStroke& x, const CrossingOnStroke& y) {
        return std::tie(x.seg, x.t) < std::tie(y.seg, y.t);
    });
    const auto& pts = strokes_[s].points;
    const Index n = pts.size();
    const bool closed = strokes_[s].closed;
    // Drop samples too close to a crossing on the same stroke (never an open stroke's ends).
    const double merge = options_.crossing_merge_fraction * spacing_[s];
    std::vector<char> keep(n, 1);
    for (const CrossingOnStroke& c : list) {
        const glm::dvec3 x = glm::dvec3(nodes_[static_cast<Index>(c.node)].dir) *
                                 nodes_[static_cast<Index>(c.node)].radius + centre_;
        for (Index k : {static_cast<Index>(c.seg), (static_cast<Index>(c.seg) + 1) % n}) {
            if (!closed && (k == 0 || k + 1 == n)) continue;
            if (glm::distance(glm::dvec3(pts[k]), x) < merge) keep[k] = 0;
        }
    }
    std::vector<int> chain;
    Index next = 0;
    auto push = [&](int id) {
        if (chain.empty() || chain.back() != id) chain.push_back(id);
    };
    for (Index i = 0; i < n; ++i) {
        if (keep[i]) push(sample_node_[sample_offset_[s] + i]);
        while (next < list.size() && static_cast<Index>(list[next].seg) == i) push(list[next++].node);
    }
    if (closed && chain.size() > 1 && chain.front() == chain.back()) chain.pop_back();
    if (chain.size() < (closed ? 3u : 2u))
        throw InvalidInput(stroke_name(static_cast<int>(s)) + " is crossed too densely by other strokes to mesh");
    return chain;
}

std::vector<int> LobeSurfaceBuilder::subdivided_chain(Index s, const std::vector<int>& chain)
{
    // Long segments are subdivided along the straight 3D segment, so that seen from the
    // centre every piece is short and the planar constraint follows the great arc.
    const bool closed = strokes_[s].closed;
    std::vector<int> fine;
    const Index m = chain.size();
    for (Index i = 0; i < m; ++i) {
        fine.push_back(chain[i]);
        if (!closed && i + 1 == m) break;
        const Node a = nodes_[static_cast<Index>(chain[i])];
        const Node b = nodes_[static_cast<Index>(chain[(i + 1) % m])];
        const int pieces = static_cast<int>(std::ceil(angle_between(a.dir, b.dir) / max_piece_angle_));
        const glm::dvec3 pa = centre_ + a.radius * a.dir, pb = centre_ + b.radius * b.dir;
        for (int k = 1; k < pieces; ++k) {
            const glm::dvec3 p = pa + (pb - pa) * (static_cast<double>(k) / pieces);
            Node piece;
            piece.radius = glm::length(p - centre_);
            piece.dir = (p - centre_) / piece.radius;
            piece.origin = {LobeVertexKind::Segment, static_cast<int>(s), a.origin.sample, -1};
            fine.push_back(add_node(piece));
        }
    }
    return fine;
}

} // namespace lobe_surface_detail

} // namespace lobe
