#include "meshing/stroke_edit.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include <glm/geometric.hpp>

#include "core/errors.h"

namespace lobe {

namespace {

bool finite(const glm::dvec3& p) { return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z); }

std::string stroke_name(const Stroke& s) { return "stroke " + std::to_string(s.id); }

std::string cm(double m)
{
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.1f cm", m * 100.0);
    return buf;
}

[[noreturn]] void fail(const std::string& what) { throw InvalidInput("stroke edit: " + what); }

void check_options(const StrokeEditOptions& o)
{
    if (!(o.pick_distance_m > 0.0 && o.pick_distance_m <= 10.0)) fail("pick_distance_m must be in (0, 10]");
    if (!(o.half_length_m > 0.0 && o.half_length_m <= 100.0)) fail("half_length_m must be in (0, 100]");
    if (!(o.min_pick_fraction > 0.0 && o.min_pick_fraction < 0.5)) fail("min_pick_fraction must be in (0, 0.5)");
}

/// Points, finiteness, length: what every stroke edit needs.
void check_stroke(const Stroke& s)
{
    if (s.points.size() < 3)
        fail(stroke_name(s) + " has " + std::to_string(s.points.size()) + " points; a stroke edit needs at least 3");
    for (std::size_t i = 0; i < s.points.size(); ++i)
        if (!finite(glm::dvec3(s.points[i].position)))
            fail(stroke_name(s) + " has a non-finite point (index " + std::to_string(i) + ")");
    if (!(s.length() > 0.0)) fail(stroke_name(s) + " has zero length");
}

void check_tip(const glm::vec3& tip, const char* what)
{
    if (!finite(glm::dvec3(tip))) fail(std::string("non-finite ") + what);
}

/// Length of the edge from point i to the next one (wrapping on closed strokes).
double edge(const Stroke& s, std::size_t i)
{
    const std::size_t n = s.points.size();
    return glm::distance(glm::dvec3(s.points[i].position), glm::dvec3(s.points[(i + 1) % n].position));
}

std::size_t pick_point(const Stroke& s, const glm::vec3& tip, const StrokeEditOptions& o, const char* which)
{
    double d = 0.0;
    const std::size_t k = nearest_stroke_point(s, tip, &d);
    if (d > o.pick_distance_m)
        fail(std::string(which) + " is " + cm(d) + " from " + stroke_name(s) + " (pick distance " +
             cm(o.pick_distance_m) + ")");
    return k;
}

/// Parameters of the points of `seg.indices` by arc length; throws for a degenerate segment.
void parametrise(const Stroke& s, StrokeSegment& seg)
{
    if (seg.indices.size() < 3)
        fail("the segment of " + stroke_name(s) + " has " + std::to_string(seg.indices.size()) +
             " points; at least 3 are needed (one to move between two fixed ends)");
    seg.t.assign(seg.indices.size(), 0.0);
    double arc = 0.0;
    for (std::size_t j = 1; j < seg.indices.size(); ++j) {
        arc += glm::distance(glm::dvec3(s.points[std::size_t(seg.indices[j - 1])].position),
                             glm::dvec3(s.points[std::size_t(seg.indices[j])].position));
        seg.t[j] = arc;
    }
    if (!(arc > 0.0)) fail("the segment of " + stroke_name(s) + " has zero length");
    for (double& t : seg.t) t /= arc;
    seg.t.back() = 1.0;
    seg.length_m = arc;
}

void check_pick_fraction(const Stroke& s, const StrokeSegment& seg, const StrokeEditOptions& o)
{
    const double tau = seg.pick_t();
    if (tau < o.min_pick_fraction || tau > 1.0 - o.min_pick_fraction) {
        char buf[256];
        std::snprintf(buf, sizeof buf,
                      "the point that follows the drag lies %.0f%% along the segment of %s, whose ends stay fixed; "
                      "it must lie within %.0f-%.0f%% (pick farther from the stroke's end)",
                      tau * 100.0, stroke_name(s).c_str(), o.min_pick_fraction * 100.0,
                      (1.0 - o.min_pick_fraction) * 100.0);
        fail(buf);
    }
}

double b1(double t) { return 3.0 * t * (1.0 - t) * (1.0 - t); }
double b2(double t) { return 3.0 * t * t * (1.0 - t); }

} // namespace

std::size_t nearest_stroke_point(const Stroke& stroke, const glm::vec3& p, double* distance_m)
{
    if (stroke.points.empty()) fail(stroke_name(stroke) + " has no points");
    check_tip(p, "fingertip position");
    const glm::dvec3 q(p);
    std::size_t best = 0;
    double best_d2 = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < stroke.points.size(); ++i) {
        const glm::dvec3 d = glm::dvec3(stroke.points[i].position) - q;
        const double d2 = glm::dot(d, d);
        if (d2 < best_d2) {
            best_d2 = d2;
            best = i;
        }
    }
    if (distance_m) *distance_m = std::sqrt(best_d2);
    return best;
}

StrokeSegment pick_stroke_segment(const Stroke& stroke, bool closed, const glm::vec3& tip,
                                  const StrokeEditOptions& options)
{
    check_options(options);
    check_stroke(stroke);
    check_tip(tip, "fingertip position");
    const std::size_t n = stroke.points.size();
    const std::size_t k = pick_point(stroke, tip, options, "the fingertip");

    // Walk each way to the first point at least half_length_m along the stroke. On a closed
    // stroke the two walks together take at most n − 1 steps, so no point is taken twice.
    const std::size_t max_fwd = closed ? (n - 1) / 2 : n - 1 - k;
    const std::size_t max_back = closed ? (n - 1) - (n - 1) / 2 : k;
    std::size_t fwd = 0, back = 0;
    for (double arc = 0.0; fwd < max_fwd && arc < options.half_length_m; ++fwd) arc += edge(stroke, (k + fwd) % n);
    for (double arc = 0.0; back < max_back && arc < options.half_length_m; ++back)
        arc += edge(stroke, (k + n - back - 1) % n);

    StrokeSegment seg;
    for (std::size_t j = 0; j < back + fwd + 1; ++j) seg.indices.push_back(static_cast<int>((k + n - back + j) % n));
    seg.pick = back;
    parametrise(stroke, seg);
    check_pick_fraction(stroke, seg, options);
    return seg;
}

StrokeSegment pick_stroke_segment(const Stroke& stroke, bool closed, const glm::vec3& tip,
                                  const glm::vec3& other_tip, const StrokeEditOptions& options)
{
    check_options(options);
    check_stroke(stroke);
    check_tip(tip, "fingertip position");
    check_tip(other_tip, "second fingertip position");
    const std::size_t n = stroke.points.size();
    const std::size_t k = pick_point(stroke, tip, options, "the fingertip");
    const std::size_t m = pick_point(stroke, other_tip, options, "the second fingertip");
    if (k == m) fail("both fingertips pick the same point of " + stroke_name(stroke));

    std::size_t first = std::min(k, m), last = std::max(k, m);
    if (closed) {
        // The shorter of the two arcs between the picks (first → last, or last → first
        // across the stroke's closing edge); the first one on a tie.
        double inner = 0.0, total = 0.0;
        for (std::size_t i = 0; i < n; ++i) {
            total += edge(stroke, i);
            if (i >= first && i < last) inner += edge(stroke, i);
        }
        if (total - inner < inner) std::swap(first, last);
    }
    StrokeSegment seg;
    for (std::size_t i = first;; i = (i + 1) % n) {
        seg.indices.push_back(static_cast<int>(i));
        if (i == last) break;
    }
    parametrise(stroke, seg);
    // The point nearest the middle of the segment follows the drag.
    double best = 2.0;
    for (std::size_t j = 1; j + 1 < seg.t.size(); ++j)
        if (std::abs(seg.t[j] - 0.5) < best) {
            best = std::abs(seg.t[j] - 0.5);
            seg.pick = j;
        }
    check_pick_fraction(stroke, seg, options);
    return seg;
}

std::array<glm::dvec3, 2> bezier_control_offsets(double pick_t, const glm::dvec3& displacement)
{
    if (!(pick_t > 0.0 && pick_t < 1.0)) fail("the pick parameter must be inside (0, 1)");
    if (!finite(displacement)) fail("non-finite drag");
    const double a = b1(pick_t), b = b2(pick_t);
    const double den = a * a + b * b;
    return {displacement * (a / den), displacement * (b / den)};
}

glm::dvec3 bezier_displacement(double t, double pick_t, const glm::dvec3& displacement)
{
    const auto off = bezier_control_offsets(pick_t, displacement);
    return b1(t) * off[0] + b2(t) * off[1];
}

std::array<glm::dvec3, 4> fit_segment_bezier(const Stroke& stroke, const StrokeSegment& seg)
{
    auto at = [&](std::size_t j) { return glm::dvec3(stroke.points[std::size_t(seg.indices[j])].position); };
    const glm::dvec3 p0 = at(0), p3 = at(seg.indices.size() - 1);
    // Normal equations of Σ ‖b0 P0 + b1 P1 + b2 P2 + b3 P3 − qⱼ‖² in P1, P2.
    double a11 = 0, a12 = 0, a22 = 0;
    glm::dvec3 r1(0.0), r2(0.0);
    for (std::size_t j = 0; j < seg.indices.size(); ++j) {
        const double t = seg.t[j], s = 1.0 - t;
        const double c0 = s * s * s, c1 = b1(t), c2 = b2(t), c3 = t * t * t;
        const glm::dvec3 r = at(j) - c0 * p0 - c3 * p3;
        a11 += c1 * c1;
        a12 += c1 * c2;
        a22 += c2 * c2;
        r1 += c1 * r;
        r2 += c2 * r;
    }
    const double det = a11 * a22 - a12 * a12;
    if (!(det > 1e-9 * a11 * a22))
        return {p0, p0 + (p3 - p0) / 3.0, p0 + (p3 - p0) * (2.0 / 3.0), p3};
    return {p0, (a22 * r1 - a12 * r2) / det, (a11 * r2 - a12 * r1) / det, p3};
}

void bend_stroke_segment(Stroke& stroke, const StrokeSegment& seg, const glm::dvec3& displacement)
{
    if (!finite(displacement)) fail("non-finite drag");
    const std::size_t n = stroke.points.size();
    if (seg.indices.size() < 3 || seg.t.size() != seg.indices.size() || seg.pick == 0 ||
        seg.pick + 1 >= seg.indices.size())
        fail("malformed segment");
    for (int i : seg.indices)
        if (i < 0 || std::size_t(i) >= n) fail("the segment does not fit " + stroke_name(stroke));
    const double tau = seg.pick_t();
    const auto off = bezier_control_offsets(tau, displacement);
    std::vector<glm::vec3> moved(seg.indices.size());
    for (std::size_t j = 0; j < seg.indices.size(); ++j) {
        const glm::dvec3 p(stroke.points[std::size_t(seg.indices[j])].position);
        // The picked point gets the drag itself, not the (equal up to rounding) basis sum.
        const glm::dvec3 d = j == seg.pick ? displacement : b1(seg.t[j]) * off[0] + b2(seg.t[j]) * off[1];
        moved[j] = glm::vec3(p + d);
        if (!finite(glm::dvec3(moved[j]))) fail("the edit moves a point of " + stroke_name(stroke) + " out of range");
    }
    for (std::size_t j = 1; j + 1 < seg.indices.size(); ++j) stroke.points[std::size_t(seg.indices[j])].position = moved[j];
}

StrokeEditResult edit_stroke(Stroke& stroke, bool closed, const StrokeDrag& drag, const StrokeEditOptions& options)
{
    check_tip(drag.start, "drag start");
    check_tip(drag.end, "drag end");
    StrokeEditResult r;
    r.segment = drag.other_tip ? pick_stroke_segment(stroke, closed, drag.start, *drag.other_tip, options)
                               : pick_stroke_segment(stroke, closed, drag.start, options);
    const glm::dvec3 d = glm::dvec3(drag.end) - glm::dvec3(drag.start);
    r.bezier_before = fit_segment_bezier(stroke, r.segment);
    const auto off = bezier_control_offsets(r.segment.pick_t(), d);
    r.bezier_after = r.bezier_before;
    r.bezier_after[1] += off[0];
    r.bezier_after[2] += off[1];
    bend_stroke_segment(stroke, r.segment, d);
    return r;
}

} // namespace lobe
