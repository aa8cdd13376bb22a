#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "core/errors.h"
#include "meshing/sampling.h"

using namespace lobe;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kSpacing = 0.005; // InputOptions::min_point_distance_m

/// A horizontal ring of the given radius at 5 mm spacing, counter-clockwise seen from above.
std::vector<glm::vec3> ring(double radius, double degrees = 360.0, glm::dvec3 centre = {0.0, 1.2, -0.4})
{
    const double arc = 2.0 * kPi * radius * degrees / 360.0;
    const bool full = degrees == 360.0;
    const int n = full ? static_cast<int>(std::lround(arc / kSpacing)) : static_cast<int>(arc / kSpacing) + 1;
    std::vector<glm::vec3> out;
    for (int i = 0; i < n; ++i) {
        const double t = (full ? 2.0 * kPi * i / n : i * kSpacing / radius);
        out.emplace_back(centre + glm::dvec3(radius * std::cos(t), 0.0, -radius * std::sin(t)));
    }
    return out;
}

/// A square of the given side at 5 mm spacing in the xy plane; corners at multiples of side/5mm.
std::vector<glm::vec3> square(double side)
{
    const int m = static_cast<int>(std::lround(side / kSpacing));
    std::vector<glm::vec3> out;
    const glm::dvec3 c[4] = {{0, 0, 0}, {side, 0, 0}, {side, side, 0}, {0, side, 0}};
    for (int k = 0; k < 4; ++k)
        for (int i = 0; i < m; ++i) {
            const double u = static_cast<double>(i) / m;
            out.emplace_back(glm::dvec3(0.3, 1.0, -0.5) + c[k] + u * (c[(k + 1) % 4] - c[k]));
        }
    return out;
}

/// Per-axis Gaussian jitter of standard deviation sigma (Box-Muller on mt19937_64 so the
/// numbers are the same with every standard library).
std::vector<glm::vec3> jittered(std::vector<glm::vec3> pts, double sigma, std::uint64_t seed)
{
    std::mt19937_64 rng(seed);
    auto uniform = [&] { return (static_cast<double>(rng() >> 11) + 0.5) * 0x1.0p-53; };
    auto gauss = [&] { return std::sqrt(-2.0 * std::log(uniform())) * std::cos(2.0 * kPi * uniform()); };
    for (glm::vec3& p : pts) p += glm::vec3(glm::dvec3(gauss(), gauss(), gauss()) * sigma);
    return pts;
}

int median(std::vector<int> v)
{
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

/// A wiggly 3D open curve (a helix with a varying radius) at about 5 mm spacing.
std::vector<glm::vec3> wiggle(int n)
{
    std::vector<glm::vec3> out;
    glm::dvec3 p(0.0, 1.0, 0.0);
    for (int i = 0; i < n; ++i) {
        const double t = 0.05 * i;
        const glm::dvec3 d = glm::normalize(glm::dvec3(std::cos(t) * (1.0 + 0.5 * std::sin(3 * t)), 0.3,
                                                       std::sin(t) * (1.0 + 0.5 * std::cos(5 * t))));
        out.emplace_back(p);
        p += kSpacing * d;
    }
    return out;
}

bool one_line(const std::string& s) { return !s.empty() && s.find('\n') == std::string::npos; }

} // namespace

TEST(Sampling, RingOf30cmAt5mmGetsMedianStepAbout10)
{
    const std::vector<glm::vec3> raw = ring(0.15); // 30 cm across, 188 points
    ASSERT_EQ(raw.size(), 188u);
    const CurvatureSampling s = sample_by_curvature_detailed(raw, true);
    // κ = 2π/188 = 0.0334 rad per sample everywhere: ⌊2·log2(2 + 29.9)⌋ = 9.
    for (double k : s.curvature) EXPECT_NEAR(k, 2.0 * kPi / 188.0, 1e-4);
    const int m = median(s.step_at);
    EXPECT_GE(m, 9);
    EXPECT_LE(m, 11);
    EXPECT_GE(median(s.steps), 9);
    EXPECT_LE(median(s.steps), 11);
    // 20 steps of 9 and a closing step of 8 = 188.
    ASSERT_EQ(s.points.size(), 21u);
    ASSERT_EQ(s.steps.size(), 21u);
    EXPECT_EQ(std::count(s.steps.begin(), s.steps.end(), 9), 20);
    EXPECT_EQ(s.steps.back(), 8);
}

TEST(Sampling, SquareCornersGetSteps2To4AndStraightSidesGet13)
{
    const std::vector<glm::vec3> raw = square(0.2); // 160 points, corners at 0, 40, 80, 120
    ASSERT_EQ(raw.size(), 160u);
    const CurvatureSampling s = sample_by_curvature_detailed(raw, true);
    for (int corner : {0, 40, 80, 120}) {
        EXPECT_GE(s.step_at[static_cast<std::size_t>(corner)], 2) << "corner " << corner;
        EXPECT_LE(s.step_at[static_cast<std::size_t>(corner)], 4) << "corner " << corner;
        EXPECT_EQ(s.step_at[static_cast<std::size_t>(corner + 20)], 13) << "middle of the side after " << corner;
    }
}

TEST(Sampling, StepsAlwaysWithin2And13AndAddUpToTheStroke)
{
    struct Case {
        std::vector<glm::vec3> raw;
        bool closed;
    };
    std::vector<Case> cases = {{ring(0.15), true},
                               {ring(0.05), true},
                               {ring(0.6), true},
                               {square(0.2), true},
                               {jittered(ring(0.15), 0.0015, 7), true},
                               {ring(0.15, 270.0), false},
                               {wiggle(400), false},
                               {jittered(wiggle(200), 0.002, 3), false}};
    for (std::size_t c = 0; c < cases.size(); ++c)
        for (std::uint64_t seed = 0; seed < 8; ++seed) {
            SamplingOptions o;
            o.seed = seed;
            const CurvatureSampling s = sample_by_curvature_detailed(cases[c].raw, cases[c].closed, o);
            const int n = static_cast<int>(cases[c].raw.size());
            int sum = 0;
            for (int st : s.steps) {
                EXPECT_GE(st, 2) << "case " << c << " seed " << seed;
                EXPECT_LE(st, 13) << "case " << c << " seed " << seed;
                sum += st;
            }
            for (int st : s.step_at) {
                EXPECT_GE(st, 2);
                EXPECT_LE(st, 13);
            }
            EXPECT_EQ(sum, cases[c].closed ? n : n - 1) << "case " << c;
            EXPECT_EQ(s.steps.size(), cases[c].closed ? s.points.size() : s.points.size() - 1);
            for (std::size_t i = 0; i < s.points.size(); ++i)
                EXPECT_EQ(s.points[i], cases[c].raw[static_cast<std::size_t>(s.indices[i])]);
        }
}

TEST(Sampling, Equation1StepsMatchThePaperFormula)
{
    EXPECT_EQ(curvature_step(0.0), 13);  // ρ = 0.01: ⌊2·log2(102)⌋ = 13
    EXPECT_EQ(curvature_step(0.01), 13);
    EXPECT_EQ(curvature_step(0.0334), 9); // the 30 cm ring
    EXPECT_EQ(curvature_step(0.5), 4);   // ⌊2·log2(4)⌋
    EXPECT_EQ(curvature_step(3.0), 2);   // ⌊2·log2(2.33)⌋ = 2
    EXPECT_EQ(curvature_step(100.0), 2);
    EXPECT_EQ(curvature_step(0.0, 4.0), 13); // clamped
    EXPECT_EQ(curvature_step(std::numeric_limits<double>::quiet_NaN()), 13);
}

TEST(Sampling, OpenStrokesKeepBothEnds)
{
    for (int n : {4, 5, 6, 7, 10, 14, 15, 16, 27, 100, 271}) {
        std::vector<glm::vec3> raw = wiggle(n);
        for (std::uint64_t seed = 0; seed < 4; ++seed) {
            SamplingOptions o;
            o.seed = seed;
            const CurvatureSampling s = sample_by_curvature_detailed(raw, false, o);
            ASSERT_GE(s.points.size(), 4u) << n;
            EXPECT_EQ(s.indices.front(), 0) << n;
            EXPECT_EQ(s.indices.back(), n - 1) << n;
            EXPECT_EQ(s.points.front(), raw.front());
            EXPECT_EQ(s.points.back(), raw.back());
            EXPECT_TRUE(std::is_sorted(s.indices.begin(), s.indices.end()));
            if (n >= 7) {
                for (int st : s.steps) EXPECT_GE(st, 2) << n;
            }
        }
    }
}

TEST(Sampling, SameSeedGivesSameSamplesDifferentSeedGivesDifferentStart)
{
    const std::vector<glm::vec3> raw = jittered(ring(0.15), 0.001, 11);
    SamplingOptions a, b;
    a.seed = b.seed = 12345;
    const CurvatureSampling sa = sample_by_curvature_detailed(raw, true, a);
    const CurvatureSampling sb = sample_by_curvature_detailed(raw, true, b);
    EXPECT_EQ(sa.indices, sb.indices);
    EXPECT_EQ(sa.points, sb.points);
    b.seed = 12346;
    EXPECT_NE(sample_by_curvature_detailed(raw, true, b).indices.front(), sa.indices.front());
    std::set<int> starts;
    for (std::uint64_t seed = 0; seed < 32; ++seed) {
        SamplingOptions o;
        o.seed = seed;
        starts.insert(sample_by_curvature_detailed(raw, true, o).indices.front());
    }
    EXPECT_GE(starts.size(), 24u);
}

TEST(Sampling, OpenStrokesStartAtTheirFirstPointWhateverTheSeed)
{
    const std::vector<glm::vec3> raw = wiggle(300);
    SamplingOptions o;
    const std::vector<int> first = sample_by_curvature_detailed(raw, false, o).indices;
    o.seed = 99;
    EXPECT_EQ(sample_by_curvature_detailed(raw, false, o).indices, first);
}

TEST(Sampling, JitteredRingWith1p5mmNoiseStillGetsMedianStepAtLeast8)
{
    // 1.5 mm standard deviation on every axis (2.6 mm RMS in 3D) at 5 mm spacing.
    for (std::uint64_t seed = 1; seed <= 10; ++seed) {
        const std::vector<glm::vec3> raw = jittered(ring(0.15), 0.0015, seed);
        const CurvatureSampling s = sample_by_curvature_detailed(raw, true);
        EXPECT_GE(median(s.step_at), 8) << "seed " << seed;
        EXPECT_GE(median(s.steps), 8) << "seed " << seed;
    }
}

TEST(Sampling, NeighbourhoodOfOneReadsJitterAsCurvature)
{
    // The reason for the neighbourhood and smoothing: without them, jitter dominates κ.
    SamplingOptions raw_angles;
    raw_angles.neighbourhood = 1;
    raw_angles.smoothing_radius = 0;
    const std::vector<glm::vec3> raw = jittered(ring(0.15), 0.0015, 1);
    EXPECT_LE(median(sample_by_curvature_detailed(raw, true, raw_angles).step_at), 5);
    EXPECT_GE(median(sample_by_curvature_detailed(raw, true).step_at), 8);
}

TEST(Sampling, RepeatedEndPointOfAClosedStrokeIsIgnored)
{
    std::vector<glm::vec3> raw = ring(0.15);
    std::vector<glm::vec3> doubled = raw;
    doubled.push_back(raw.front());
    const CurvatureSampling a = sample_by_curvature_detailed(raw, true);
    const CurvatureSampling b = sample_by_curvature_detailed(doubled, true);
    EXPECT_EQ(a.indices, b.indices);
    EXPECT_EQ(b.curvature.size(), raw.size());
}

TEST(SamplingClosure, RingWith1cmGapIsClosed)
{
    std::vector<glm::vec3> raw = ring(0.15);
    raw.pop_back(); // the ends are two spacings apart: 1.0 cm
    ASSERT_NEAR(glm::distance(raw.front(), raw.back()), 0.01, 0.0002);
    EXPECT_TRUE(is_closed_stroke(raw));
    EXPECT_NEAR(closure_gap(raw), glm::distance(raw.front(), raw.back()), 1e-6);
}

TEST(SamplingClosure, RingWithOverlappingTailIsClosed)
{
    // 400°: the tail runs 40° (10.5 cm) past the start; the end-to-start distance is 10 cm.
    const std::vector<glm::vec3> raw = ring(0.151, 400.0);
    ASSERT_GT(glm::distance(raw.front(), raw.back()), 0.08);
    EXPECT_LT(closure_gap(raw), 0.001);
    EXPECT_TRUE(is_closed_stroke(raw));
}

TEST(SamplingClosure, ArcOf270DegreesIsOpen)
{
    const std::vector<glm::vec3> raw = ring(0.15, 270.0);
    EXPECT_FALSE(is_closed_stroke(raw));
    EXPECT_NEAR(closure_gap(raw), 0.15 * std::sqrt(2.0), 0.005);
}

TEST(SamplingClosure, ThresholdsAreTheStatedDefaultsAndSettable)
{
    const ClosureOptions d;
    EXPECT_DOUBLE_EQ(d.max_gap_fraction, 0.15);
    EXPECT_DOUBLE_EQ(d.max_gap_m, 0.08);
    // A 1 m ring with a 10 cm gap: 1.6% of its length but more than 8 cm.
    const double len = 2 * kPi * 1.0;
    const std::vector<glm::vec3> big = ring(1.0, 360.0 * (len - 0.1) / len);
    EXPECT_FALSE(is_closed_stroke(big));
    ClosureOptions loose;
    loose.max_gap_m = 0.2;
    EXPECT_TRUE(is_closed_stroke(big, loose));
    // A 6 cm ring with a 1.5 cm gap: under 8 cm but 40% of its length.
    const double small_len = 2 * kPi * 0.01;
    EXPECT_FALSE(is_closed_stroke(ring(0.01, 360.0 * (small_len - 0.015) / small_len)));
}

namespace {

/// No two points of the closed loop closer than 0.5 spacing, consecutive ones (the closing
/// segment included) within [0.5, 1.5] spacings.
void expect_clean_loop(const std::vector<glm::vec3>& loop, const char* what)
{
    const std::size_t n = loop.size();
    for (std::size_t i = 0; i < n; ++i) {
        const double d = glm::distance(loop[i], loop[(i + 1) % n]);
        EXPECT_GE(d, 0.5 * kSpacing) << what << " segment " << i;
        EXPECT_LE(d, 1.5 * kSpacing) << what << " segment " << i;
        for (std::size_t j = i + 1; j < n; ++j)
            EXPECT_GE(glm::distance(loop[i], loop[j]), 0.5 * kSpacing) << what << " points " << i << ", " << j;
    }
}

} // namespace

TEST(SamplingClosure, CloseStrokeLeavesNoDoubledPoint)
{
    const std::vector<glm::vec3> base = ring(0.15); // 188 points
    {
        std::vector<glm::vec3> doubled = base;
        doubled.push_back(base.front());
        const std::vector<glm::vec3> loop = close_stroke(doubled);
        EXPECT_EQ(loop.size(), 188u);
        expect_clean_loop(loop, "repeated end point");
    }
    {
        std::vector<glm::vec3> near_end = base;
        near_end.push_back(base.front() + glm::vec3(0.0005f, 0.0005f, 0.0f));
        const std::vector<glm::vec3> loop = close_stroke(near_end);
        EXPECT_EQ(loop.size(), 188u);
        expect_clean_loop(loop, "end point 0.7 mm from the start");
    }
    {
        // 189.75 spacings per turn: one turn keeps 190 points (the 191st is 1.25 mm from
        // the start and goes).
        const std::vector<glm::vec3> overlap = ring(0.151, 400.0);
        const std::vector<glm::vec3> loop = close_stroke(overlap);
        EXPECT_EQ(loop.size(), 190u);
        expect_clean_loop(loop, "overlapping tail");
    }
    {
        std::vector<glm::vec3> gap = base;
        gap.pop_back();
        const std::vector<glm::vec3> loop = close_stroke(gap);
        EXPECT_EQ(loop.size(), 188u); // one point bridges the 1 cm gap
        expect_clean_loop(loop, "1 cm gap");
    }
    {
        const std::vector<glm::vec3> noisy = jittered(ring(0.15, 380.0), 0.0005, 5);
        const std::vector<glm::vec3> loop = close_stroke(noisy);
        EXPECT_GE(loop.size(), 180u);
        EXPECT_LE(loop.size(), 190u);
        EXPECT_GE(glm::distance(loop.front(), loop.back()), 0.5 * 0.004);
    }
}

TEST(SamplingErrors, DegenerateStrokesThrowInvalidInputWithOneLineMessages)
{
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    std::vector<std::pair<const char*, std::vector<glm::vec3>>> bad = {
        {"empty", {}},
        {"three points", {{0, 0, 0}, {0.01f, 0, 0}, {0, 0.01f, 0}}},
        {"coincident", std::vector<glm::vec3>(10, glm::vec3(0.1f, 1.0f, 0.2f))},
        {"collinear", {{0, 1, 0}, {0.01f, 1, 0}, {0.02f, 1, 0}, {0.03f, 1, 0}, {0.05f, 1, 0}}},
        {"nan", {{0, 0, 0}, {0.01f, 0, 0}, {0, nan, 0}, {0, 0.01f, 0}, {0.01f, 0.01f, 0}}},
        {"inf", {{0, 0, 0}, {0.01f, 0, 0}, {0, 0.01f, inf}, {0, 0.01f, 0}, {0.01f, 0.01f, 0}}},
        {"2 km away", {{2000, 0, 0}, {2000.01f, 0, 0}, {2000, 0.01f, 0}, {2000.01f, 0.01f, 0.01f}}},
    };
    std::vector<glm::vec3> far_ring = ring(0.15);
    for (glm::vec3& p : far_ring) p.x += 1500.0f;
    bad.emplace_back("ring 1.5 km away", far_ring);
    const std::vector<std::pair<const char*, std::function<void(const std::vector<glm::vec3>&)>>> calls = {
        {"sample_by_curvature closed", [](const auto& p) { sample_by_curvature(p, true); }},
        {"sample_by_curvature open", [](const auto& p) { sample_by_curvature(p, false); }},
        {"turning_per_sample", [](const auto& p) { turning_per_sample(p, true); }},
        {"is_closed_stroke", [](const auto& p) { is_closed_stroke(p); }},
        {"closure_gap", [](const auto& p) { closure_gap(p); }},
        {"close_stroke", [](const auto& p) { close_stroke(p); }},
    };
    for (const auto& [name, pts] : bad)
        for (const auto& [call, f] : calls) {
            try {
                f(pts);
                ADD_FAILURE() << call << " accepted " << name;
            } catch (const InvalidInput& e) {
                EXPECT_TRUE(one_line(e.what())) << call << " / " << name << ": " << e.what();
            }
        }
}

TEST(SamplingErrors, BadOptionsThrowInvalidInput)
{
    const std::vector<glm::vec3> raw = ring(0.15);
    SamplingOptions o;
    o.k = 0.0;
    EXPECT_THROW(sample_by_curvature(raw, true, o), InvalidInput);
    o = {};
    o.k = std::numeric_limits<double>::quiet_NaN();
    EXPECT_THROW(sample_by_curvature(raw, true, o), InvalidInput);
    o = {};
    o.neighbourhood = 0;
    EXPECT_THROW(sample_by_curvature(raw, true, o), InvalidInput);
    o = {};
    o.smoothing_radius = -1;
    EXPECT_THROW(sample_by_curvature(raw, true, o), InvalidInput);
    ClosureOptions c;
    c.overlap_fraction = 0.6;
    EXPECT_THROW(is_closed_stroke(raw, c), InvalidInput);
    c = {};
    c.max_gap_m = -1.0;
    EXPECT_THROW(close_stroke(raw, c), InvalidInput);
}
