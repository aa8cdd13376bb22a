// Bézier stroke editing (meshing/stroke_edit.h).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <set>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "core/errors.h"
#include "meshing/stroke_edit.h"
#include "tests/support/expect_throw.h"

using namespace lobe;

namespace {

constexpr double kPi = 3.14159265358979323846;

/// A loop of radius 15 cm in the horizontal plane at chest height, n points, with a 2 mm
/// ripple of 40 waves (small-scale detail an edit must keep). No repeated end point.
Stroke loop(int n = 200, std::int64_t id = 7)
{
    Stroke s;
    s.id = id;
    for (int i = 0; i < n; ++i) {
        const double a = 2 * kPi * i / n;
        const double r = 0.15 + 0.002 * std::sin(40 * a);
        s.points.push_back({glm::vec3(float(0.05 + r * std::cos(a)), 1.4f, float(-0.42 + r * std::sin(a))), 0.01 * i});
    }
    return s;
}

/// An open, gently curved stroke along +X: 61 points 5 mm apart in x (30 cm).
Stroke line(std::int64_t id = 3)
{
    Stroke s;
    s.id = id;
    for (int i = 0; i <= 60; ++i) {
        const double x = 0.005 * i;
        s.points.push_back({glm::vec3(float(x), float(1.3 + 0.1 * x * x), -0.4f), 0.02 * i});
    }
    return s;
}

bool same_bits(const glm::vec3& a, const glm::vec3& b) { return std::memcmp(&a, &b, sizeof a) == 0; }

double arc(const Stroke& s, const std::vector<int>& idx, std::size_t from, std::size_t to)
{
    double len = 0;
    for (std::size_t j = from; j < to; ++j)
        len += glm::distance(glm::dvec3(s.points[std::size_t(idx[j])].position),
                             glm::dvec3(s.points[std::size_t(idx[j + 1])].position));
    return len;
}

/// Calls f, expects an InvalidInput of one line that starts "stroke edit: ", and returns it.
template <class F> std::string expect_invalid_one_line(F&& f)
{
    const std::string what = test::expect_one_line_throw<InvalidInput>(f);
    if (!what.empty()) {
        EXPECT_EQ(what.rfind("stroke edit: ", 0), 0u) << what;
    }
    return what;
}

void expect_same_stroke(const Stroke& a, const Stroke& b)
{
    ASSERT_EQ(a.points.size(), b.points.size());
    for (std::size_t i = 0; i < a.points.size(); ++i) {
        EXPECT_TRUE(same_bits(a.points[i].position, b.points[i].position)) << "point " << i;
        EXPECT_EQ(a.points[i].time, b.points[i].time);
    }
}

} // namespace

TEST(StrokeEdit, PickedPointFollowsTheDragExactly)
{
    for (const glm::vec3 d : {glm::vec3(0.0f, 0.05f, 0.0f), glm::vec3(0.03f, -0.02f, 0.04f), glm::vec3(-0.2f, 0.1f, 0.0f)}) {
        Stroke s = loop();
        const glm::vec3 picked = s.points[50].position;
        // The fingertip is 1 cm off the stroke; the point nearest to it follows the drag.
        const glm::vec3 start = picked + glm::vec3(0.0f, 0.01f, 0.0f);
        const StrokeEditResult r = edit_stroke(s, true, {start, start + d, std::nullopt});
        EXPECT_EQ(r.segment.pick_index(), 50);
        EXPECT_NEAR(glm::distance(s.points[50].position, picked + d), 0.0, 1e-4);
        EXPECT_NEAR(glm::distance(s.points[50].position, picked + d), 0.0, 1e-6); // float rounding only
        // The Bézier moved by d at the pick parameter.
        const double tau = r.segment.pick_t();
        auto bez = [](const std::array<glm::dvec3, 4>& p, double t) {
            const double u = 1 - t;
            return u * u * u * p[0] + 3 * u * u * t * p[1] + 3 * u * t * t * p[2] + t * t * t * p[3];
        };
        const glm::dvec3 drag = glm::dvec3(start + d) - glm::dvec3(start); // d as the floats give it
        EXPECT_NEAR(glm::distance(bez(r.bezier_after, tau) - bez(r.bezier_before, tau), drag), 0.0, 1e-12);
        EXPECT_EQ(r.bezier_after[0], r.bezier_before[0]);
        EXPECT_EQ(r.bezier_after[3], r.bezier_before[3]);
    }
}

TEST(StrokeEdit, EndsAndPointsOutsideTheSegmentKeepTheirBits)
{
    Stroke s = loop();
    const Stroke before = s;
    const glm::vec3 start = s.points[120].position;
    const StrokeEditResult r = edit_stroke(s, true, {start, start + glm::vec3(0.02f, 0.06f, -0.01f), std::nullopt});
    std::set<int> inner(r.segment.indices.begin() + 1, r.segment.indices.end() - 1);
    int moved = 0;
    for (std::size_t i = 0; i < s.points.size(); ++i) {
        if (inner.count(int(i))) {
            moved += !same_bits(s.points[i].position, before.points[i].position);
            continue;
        }
        EXPECT_TRUE(same_bits(s.points[i].position, before.points[i].position)) << "point " << i;
    }
    EXPECT_EQ(moved, int(inner.size()));
    EXPECT_TRUE(same_bits(s.points[std::size_t(r.segment.indices.front())].position,
                          before.points[std::size_t(r.segment.indices.front())].position));
    EXPECT_TRUE(same_bits(s.points[std::size_t(r.segment.indices.back())].position,
                          before.points[std::size_t(r.segment.indices.back())].position));
    for (std::size_t i = 0; i < s.points.size(); ++i) EXPECT_EQ(s.points[i].time, before.points[i].time);
}

TEST(StrokeEdit, SegmentReachesTheHalfLengthOnEachSide)
{
    Stroke s = loop(); // spacing about 4.9 mm (the ripple adds a little)
    StrokeEditOptions o;
    o.half_length_m = 0.05;
    const StrokeSegment seg = pick_stroke_segment(s, true, s.points[100].position, o);
    ASSERT_EQ(seg.pick_index(), 100);
    const double back = arc(s, seg.indices, 0, seg.pick), fwd = arc(s, seg.indices, seg.pick, seg.indices.size() - 1);
    // To the first point at least half_length_m along: within one spacing beyond it.
    EXPECT_GE(back, 0.05);
    EXPECT_GE(fwd, 0.05);
    EXPECT_LT(back, 0.05 + 0.0062);
    EXPECT_LT(fwd, 0.05 + 0.0062);
    EXPECT_NEAR(seg.length_m, back + fwd, 1e-12);
    EXPECT_EQ(seg.t.front(), 0.0);
    EXPECT_EQ(seg.t.back(), 1.0);
    for (std::size_t j = 1; j < seg.t.size(); ++j) EXPECT_GT(seg.t[j], seg.t[j - 1]);
    for (std::size_t j = 1; j < seg.indices.size(); ++j) EXPECT_EQ(seg.indices[j], seg.indices[j - 1] + 1);
}

TEST(StrokeEdit, ClosedStrokesWrapAroundTheirSeamAndOpenOnesClip)
{
    Stroke s = loop();
    const std::size_t n = s.points.size();
    // Picking point 3: on a loop the segment runs back across the seam (… 198, 199, 0, 1 …).
    const StrokeSegment closed = pick_stroke_segment(s, true, s.points[3].position);
    EXPECT_EQ(closed.pick_index(), 3);
    EXPECT_GT(closed.indices.front(), 150);
    EXPECT_LT(closed.indices.back(), 30);
    for (std::size_t j = 1; j < closed.indices.size(); ++j)
        EXPECT_EQ(std::size_t(closed.indices[j]), (std::size_t(closed.indices[j - 1]) + 1) % n);
    EXPECT_NEAR(closed.pick_t(), 0.5, 0.03);
    Stroke edited = s;
    const glm::vec3 d(0.0f, 0.04f, 0.0f);
    edit_stroke(edited, true, {s.points[3].position, s.points[3].position + d, std::nullopt});
    EXPECT_GT(edited.points[n - 2].position.y, s.points[n - 2].position.y + 0.01f); // across the seam
    EXPECT_NEAR(glm::distance(edited.points[3].position, s.points[3].position + d), 0.0, 1e-6);

    // The same pick on the open stroke stops at its first point.
    Stroke open = line();
    StrokeEditOptions o;
    o.half_length_m = 0.08;
    const StrokeSegment clipped = pick_stroke_segment(open, false, open.points[10].position, o);
    EXPECT_EQ(clipped.indices.front(), 0);
    EXPECT_EQ(clipped.pick_index(), 10);
    EXPECT_GE(arc(open, clipped.indices, clipped.pick, clipped.indices.size() - 1), 0.08);
    // Near the end: the point that follows would sit too close to the fixed end.
    const Stroke before = open;
    const std::string why = expect_invalid_one_line([&] {
        edit_stroke(open, false, {open.points[2].position, open.points[2].position + d, std::nullopt}, o);
    });
    EXPECT_NE(why.find("stroke's end"), std::string::npos) << why;
    expect_same_stroke(open, before);
}

TEST(StrokeEdit, TwoFingertipsPickTheSegmentEndsAndItsMiddleFollows)
{
    Stroke s = loop();
    const Stroke before = s;
    const glm::vec3 d(0.0f, 0.05f, 0.01f);
    const glm::vec3 a = s.points[40].position + glm::vec3(0.0f, 0.005f, 0.0f);
    const glm::vec3 b = s.points[80].position - glm::vec3(0.0f, 0.005f, 0.0f);
    const StrokeEditResult r = edit_stroke(s, true, {a, a + d, b});
    EXPECT_EQ(r.segment.indices.front(), 40);
    EXPECT_EQ(r.segment.indices.back(), 80);
    EXPECT_EQ(r.segment.pick_index(), 60);
    EXPECT_NEAR(r.segment.pick_t(), 0.5, 0.01);
    EXPECT_NEAR(glm::distance(s.points[60].position, before.points[60].position + d), 0.0, 1e-6);
    for (int i : {40, 80}) EXPECT_TRUE(same_bits(s.points[std::size_t(i)].position, before.points[std::size_t(i)].position));
    for (std::size_t i = 0; i < s.points.size(); ++i)
        if (i <= 40 || i >= 80) {
            EXPECT_TRUE(same_bits(s.points[i].position, before.points[i].position)) << i;
        }

    // Order does not matter, and on a loop the shorter arc is taken: 190 and 10 span the seam.
    Stroke t = loop();
    const StrokeSegment seam = pick_stroke_segment(t, true, t.points[10].position, t.points[190].position);
    EXPECT_EQ(seam.indices.front(), 190);
    EXPECT_EQ(seam.indices.back(), 10);
    EXPECT_EQ(seam.indices.size(), 21u);
    EXPECT_EQ(seam.pick_index(), 0);
    // On an open stroke there is one way between them.
    Stroke o = line();
    const StrokeSegment open = pick_stroke_segment(o, false, o.points[50].position, o.points[5].position);
    EXPECT_EQ(open.indices.front(), 5);
    EXPECT_EQ(open.indices.back(), 50);
}

TEST(StrokeEdit, DeformationIsTheBezierChangeSoDetailIsKept)
{
    Stroke s = loop();
    const Stroke before = s;
    const glm::dvec3 d(0.0, 0.06, 0.0);
    const StrokeEditResult r = edit_stroke(s, true, {s.points[100].position, s.points[100].position + glm::vec3(d), std::nullopt});
    const StrokeSegment& seg = r.segment;
    for (std::size_t j = 0; j < seg.indices.size(); ++j) {
        const std::size_t i = std::size_t(seg.indices[j]);
        const glm::dvec3 moved = glm::dvec3(s.points[i].position) - glm::dvec3(before.points[i].position);
        EXPECT_NEAR(glm::distance(moved, bezier_displacement(seg.t[j], seg.pick_t(), d)), 0.0, 2e-7) << j;
    }
    // A vertical pull moves points only vertically: the ripple (horizontal detail) is intact.
    for (std::size_t i = 0; i < s.points.size(); ++i) {
        EXPECT_EQ(s.points[i].position.x, before.points[i].position.x);
        EXPECT_EQ(s.points[i].position.z, before.points[i].position.z);
    }
    // With the pick in the middle the bump is 4t(1 − t) of the drag: no overshoot.
    for (std::size_t j = 0; j < seg.indices.size(); ++j)
        EXPECT_LE(s.points[std::size_t(seg.indices[j])].position.y - 1.4f, 0.06f * 1.001f);
}

TEST(StrokeEdit, StrokeStaysContinuousAcrossTheSegmentEnds)
{
    // C0 at the ends: the displacement goes to zero there, linearly in the parameter (the
    // tangent turns, the cubic cannot keep it with fixed ends and a moving interior).
    Stroke s = loop(800); // 1.2 mm spacing
    const Stroke before = s;
    const glm::vec3 d(0.0f, 0.05f, 0.0f);
    const StrokeEditResult r = edit_stroke(s, true, {s.points[400].position, s.points[400].position + d, std::nullopt});
    const StrokeSegment& seg = r.segment;
    // |dD/dt| is largest at the ends: 3‖ΔP1‖ at t = 0, 3‖ΔP2‖ at t = 1 (4‖d‖ for τ = 0.5).
    const auto off = bezier_control_offsets(seg.pick_t(), glm::dvec3(d));
    const double slope = 3.0 * std::max(glm::length(off[0]), glm::length(off[1]));
    EXPECT_NEAR(slope, 4.0 * 0.05, 0.005);
    for (std::size_t j : {std::size_t(1), seg.indices.size() - 2}) {
        const std::size_t i = std::size_t(seg.indices[j]);
        const double jump = glm::distance(glm::dvec3(s.points[i].position), glm::dvec3(before.points[i].position));
        const double t = std::min(seg.t[j], 1.0 - seg.t[j]);
        EXPECT_LE(jump, slope * t * 1.01 + 1e-7) << j;
        EXPECT_LT(jump, 0.002); // next to a fixed end: about 4‖d‖ × (spacing / segment length)
    }
    // Neighbouring points never move apart by more than the slope allows.
    for (std::size_t j = 1; j < seg.indices.size(); ++j) {
        const auto mv = [&](std::size_t k) {
            const std::size_t i = std::size_t(seg.indices[k]);
            return glm::dvec3(s.points[i].position) - glm::dvec3(before.points[i].position);
        };
        EXPECT_LE(glm::distance(mv(j), mv(j - 1)), slope * (seg.t[j] - seg.t[j - 1]) * 1.01 + 1e-6) << j;
    }
}

TEST(StrokeEdit, ControlPointOffsetsAreTheSmallestThatMoveThePick)
{
    const glm::dvec3 d(0.01, -0.02, 0.03);
    for (double tau : {0.2, 0.35, 0.5, 0.8}) {
        const auto off = bezier_control_offsets(tau, d);
        const double b1 = 3 * tau * (1 - tau) * (1 - tau), b2 = 3 * tau * tau * (1 - tau);
        EXPECT_NEAR(glm::distance(b1 * off[0] + b2 * off[1], d), 0.0, 1e-15);
        EXPECT_NEAR(glm::distance(bezier_displacement(tau, tau, d), d), 0.0, 1e-15);
        EXPECT_EQ(bezier_displacement(0.0, tau, d), glm::dvec3(0.0));
        EXPECT_EQ(bezier_displacement(1.0, tau, d), glm::dvec3(0.0));
        // Every other solution (ΔP1 + b2 v, ΔP2 − b1 v) is longer.
        const double norm = glm::dot(off[0], off[0]) + glm::dot(off[1], off[1]);
        for (const glm::dvec3 v : {glm::dvec3(0.001, 0, 0), glm::dvec3(0, -0.002, 0.001), d * 0.1}) {
            const glm::dvec3 p1 = off[0] + b2 * v, p2 = off[1] - b1 * v;
            EXPECT_NEAR(glm::distance(b1 * p1 + b2 * p2, d), 0.0, 1e-15);
            EXPECT_GT(glm::dot(p1, p1) + glm::dot(p2, p2), norm);
        }
    }
    expect_invalid_one_line([&] { bezier_control_offsets(0.0, d); });
    expect_invalid_one_line([&] { bezier_control_offsets(0.5, glm::dvec3(std::nan(""), 0, 0)); });
}

TEST(StrokeEdit, FittedBezierOfAnEvenlySampledLineHasItsControlPointsAtTheThirds)
{
    Stroke s;
    for (int i = 0; i <= 40; ++i) s.points.push_back({glm::vec3(0.005f * float(i), 1.2f, -0.4f), 0.0});
    StrokeEditOptions o;
    o.half_length_m = 0.1;
    const StrokeSegment seg = pick_stroke_segment(s, false, s.points[20].position, o);
    ASSERT_EQ(seg.indices.size(), 41u);
    const auto b = fit_segment_bezier(s, seg);
    EXPECT_NEAR(b[1].x, 0.2 / 3, 1e-7);
    EXPECT_NEAR(b[2].x, 0.4 / 3, 1e-7);
    EXPECT_NEAR(b[1].y, 1.2, 1e-7);
    EXPECT_NEAR(b[2].z, -0.4, 1e-7);
}

TEST(StrokeEdit, BadInputIsRefusedWithOneLineAndTheStrokeUntouched)
{
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const glm::vec3 nanv(float(nan), 0.0f, 0.0f);
    Stroke s = loop();
    const Stroke before = s;
    const glm::vec3 p = s.points[10].position;
    const glm::vec3 up(0.0f, 0.05f, 0.0f);

    // Too far from the stroke: 4 cm off with the default 3 cm pick distance.
    const glm::vec3 far = p + glm::vec3(0.0f, 0.04f, 0.0f);
    std::string why = expect_invalid_one_line([&] { edit_stroke(s, true, {far, far + up, std::nullopt}); });
    EXPECT_NE(why.find("4.0 cm from stroke 7 (pick distance 3.0 cm)"), std::string::npos) << why;
    expect_same_stroke(s, before);
    why = expect_invalid_one_line([&] { edit_stroke(s, true, {p, p + up, far}); });
    EXPECT_NE(why.find("second fingertip"), std::string::npos) << why;
    expect_same_stroke(s, before);

    // Not finite: the fingertips, the drag, the stroke.
    expect_invalid_one_line([&] { edit_stroke(s, true, {nanv, p, std::nullopt}); });
    expect_invalid_one_line([&] { edit_stroke(s, true, {p, nanv, std::nullopt}); });
    expect_invalid_one_line([&] { edit_stroke(s, true, {p, p + up, nanv}); });
    expect_same_stroke(s, before);
    Stroke holed = loop();
    holed.points[77].position.y = float(nan);
    const Stroke holed_before = holed;
    why = expect_invalid_one_line([&] { edit_stroke(holed, true, {p, p + up, std::nullopt}); });
    EXPECT_NE(why.find("non-finite"), std::string::npos) << why;
    for (std::size_t i = 0; i < holed.points.size(); ++i)
        EXPECT_EQ(std::memcmp(&holed.points[i].position, &holed_before.points[i].position, sizeof(glm::vec3)), 0);

    // Zero length, too few points.
    Stroke dot;
    dot.id = 9;
    for (int i = 0; i < 10; ++i) dot.points.push_back({p, 0.1 * i});
    const Stroke dot_before = dot;
    why = expect_invalid_one_line([&] { edit_stroke(dot, false, {p, p + up, std::nullopt}); });
    EXPECT_NE(why.find("stroke 9 has zero length"), std::string::npos) << why;
    expect_same_stroke(dot, dot_before);
    Stroke two;
    two.points = {{p, 0.0}, {p + up, 0.1}};
    expect_invalid_one_line([&] { edit_stroke(two, false, {p, p + up, std::nullopt}); });
    Stroke none;
    expect_invalid_one_line([&] { edit_stroke(none, false, {p, p + up, std::nullopt}); });

    // Both fingertips on one point; a segment with nothing between its ends.
    expect_invalid_one_line([&] { edit_stroke(s, true, {p, p + up, p}); });
    why = expect_invalid_one_line([&] { edit_stroke(s, true, {p, p + up, s.points[11].position}); });
    EXPECT_NE(why.find("at least 3"), std::string::npos) << why;

    // Bad options.
    StrokeEditOptions o;
    o.pick_distance_m = -1;
    expect_invalid_one_line([&] { edit_stroke(s, true, {p, p + up, std::nullopt}, o); });
    o = {};
    o.half_length_m = nan;
    expect_invalid_one_line([&] { edit_stroke(s, true, {p, p + up, std::nullopt}, o); });
    o = {};
    o.min_pick_fraction = 0.5;
    expect_invalid_one_line([&] { edit_stroke(s, true, {p, p + up, std::nullopt}, o); });
    expect_same_stroke(s, before);

    // A segment that does not belong to the stroke.
    StrokeSegment seg = pick_stroke_segment(s, true, p);
    Stroke small = line();
    const Stroke small_before = small;
    seg.indices.back() = 1000;
    expect_invalid_one_line([&] { bend_stroke_segment(small, seg, glm::dvec3(up)); });
    expect_same_stroke(small, small_before);
}

TEST(StrokeEdit, NearestPointIsTheLowestIndexOnTies)
{
    Stroke s;
    s.points = {{glm::vec3(0, 0, 0), 0}, {glm::vec3(1, 0, 0), 0}, {glm::vec3(0, 0, 0), 0}};
    double d = -1;
    EXPECT_EQ(nearest_stroke_point(s, glm::vec3(0, 0.5f, 0), &d), 0u);
    EXPECT_DOUBLE_EQ(d, 0.5);
    EXPECT_EQ(nearest_stroke_point(s, glm::vec3(0.9f, 0, 0)), 1u);
}
