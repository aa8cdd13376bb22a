#include "meshing/sampling.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <glm/geometric.hpp>

#include "core/errors.h"
#include "core/random.h"
#include "meshing/polyline.h"

namespace lobe {

namespace {

void check_options(const SamplingOptions& o, const std::string& who)
{
    if (!std::isfinite(o.k) || o.k <= 0.0 || o.k > 100.0)
        throw InvalidInput(who + ": k must be a number in (0, 100], got " + std::to_string(o.k));
    if (o.neighbourhood < 1 || o.neighbourhood > 1000)
        throw InvalidInput(who + ": neighbourhood must be in [1, 1000], got " + std::to_string(o.neighbourhood));
    if (o.smoothing_radius < 0 || o.smoothing_radius > 100)
        throw InvalidInput(who + ": smoothing_radius must be in [0, 100], got " +
                           std::to_string(o.smoothing_radius));
}

void check_options(const ClosureOptions& o, const std::string& who)
{
    if (!(o.max_gap_fraction > 0.0) || !std::isfinite(o.max_gap_fraction))
        throw InvalidInput(who + ": max_gap_fraction must be positive");
    if (!(o.max_gap_m > 0.0) || !std::isfinite(o.max_gap_m))
        throw InvalidInput(who + ": max_gap_m must be positive");
    if (!(o.overlap_fraction > 0.0 && o.overlap_fraction < 0.5))
        throw InvalidInput(who + ": overlap_fraction must be in (0, 0.5)");
}

/// Validated double positions; a closed stroke's repeated end point is dropped.
std::vector<glm::dvec3> prepare(const std::vector<glm::vec3>& raw, bool closed, const std::string& who)
{
    check_stroke_points(raw, who);
    std::vector<glm::dvec3> p = to_double(raw);
    if (closed && glm::distance(p.front(), p.back()) <= 1e-6) {
        p.pop_back();
        if (p.size() < StrokeLimits::min_points)
            throw InvalidInput(who + ": closed stroke has " + std::to_string(p.size()) +
                               " distinct points, at least 4 are needed");
    }
    return p;
}

/// Binomial weights C(2r, r + j), j = −r … r.
std::vector<double> binomial_weights(int r)
{
    std::vector<double> w(static_cast<std::size_t>(2 * r + 1));
    double c = 1.0;
    for (int j = 0; j <= 2 * r; ++j) {
        w[static_cast<std::size_t>(j)] = c;
        c = c * static_cast<double>(2 * r - j) / static_cast<double>(j + 1);
    }
    return w;
}

/// A smoothed copy, used only to estimate κ. Open strokes shrink the kernel symmetrically
/// towards their ends (the end points stay put).
std::vector<glm::dvec3> smoothed(const std::vector<glm::dvec3>& p, bool closed, int radius)
{
    const int n = static_cast<int>(p.size());
    if (radius <= 0) return p;
    std::vector<glm::dvec3> q(p.size());
    std::vector<std::vector<double>> weights(static_cast<std::size_t>(radius + 1));
    for (int r = 0; r <= radius; ++r) weights[static_cast<std::size_t>(r)] = binomial_weights(r);
    for (int i = 0; i < n; ++i) {
        const int r = closed ? std::min(radius, (n - 1) / 2) : std::min({radius, i, n - 1 - i});
        const std::vector<double>& w = weights[static_cast<std::size_t>(r)];
        glm::dvec3 sum(0.0);
        double total = 0.0;
        for (int j = -r; j <= r; ++j) {
            const int k = closed ? ((i + j) % n + n) % n : i + j;
            const double wj = w[static_cast<std::size_t>(j + r)];
            // Relative to p[i] so that large coordinates keep their precision.
            sum += wj * (p[static_cast<std::size_t>(k)] - p[static_cast<std::size_t>(i)]);
            total += wj;
        }
        q[static_cast<std::size_t>(i)] = p[static_cast<std::size_t>(i)] + sum / total;
    }
    return q;
}

std::vector<double> turning(const std::vector<glm::dvec3>& p, bool closed, const SamplingOptions& o)
{
    const int n = static_cast<int>(p.size());
    const std::vector<glm::dvec3> q = smoothed(p, closed, o.smoothing_radius);
    std::vector<double> kappa(p.size(), 0.0);
    for (int i = 0; i < n; ++i) {
        const int h = closed ? std::min(o.neighbourhood, (n - 1) / 2) : std::min({o.neighbourhood, i, n - 1 - i});
        if (h < 1) continue; // open end points: filled in below
        const int before = closed ? ((i - h) % n + n) % n : i - h;
        const int after = closed ? (i + h) % n : i + h;
        const glm::dvec3 a = q[static_cast<std::size_t>(i)] - q[static_cast<std::size_t>(before)];
        const glm::dvec3 b = q[static_cast<std::size_t>(after)] - q[static_cast<std::size_t>(i)];
        const double la = glm::length(a);
        const double lb = glm::length(b);
        if (la <= 1e-12 || lb <= 1e-12) continue; // coincident points tell nothing about turning
        const double angle = std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
        kappa[static_cast<std::size_t>(i)] = angle / static_cast<double>(h);
    }
    if (!closed) {
        kappa.front() = kappa[1];
        kappa.back() = kappa[kappa.size() - 2];
    }
    return kappa;
}

} // namespace

int curvature_step(double kappa, double k)
{
    const double rho = std::isfinite(kappa) ? std::max(kappa, CurvatureSteps::min_rho) : CurvatureSteps::min_rho;
    const double s = std::floor(k * std::log2(2.0 + 1.0 / rho));
    if (!(s >= CurvatureSteps::min_step)) return CurvatureSteps::min_step; // also catches NaN
    if (s >= CurvatureSteps::max_step) return CurvatureSteps::max_step;
    return static_cast<int>(s);
}

std::vector<double> turning_per_sample(const std::vector<glm::vec3>& raw, bool closed, const SamplingOptions& options)
{
    const std::string who = "turning_per_sample";
    check_options(options, who);
    return turning(prepare(raw, closed, who), closed, options);
}

CurvatureSampling sample_by_curvature_detailed(const std::vector<glm::vec3>& raw, bool closed,
                                               const SamplingOptions& options)
{
    const std::string who = "sample_by_curvature";
    check_options(options, who);
    const std::vector<glm::dvec3> p = prepare(raw, closed, who);
    const int n = static_cast<int>(p.size());

    CurvatureSampling out;
    out.curvature = turning(p, closed, options);
    out.step_at.reserve(p.size());
    for (double kappa : out.curvature) out.step_at.push_back(curvature_step(kappa, options.k));
    auto step_at = [&](int i) { return out.step_at[static_cast<std::size_t>(i)]; };

    // Positions of the samples along the walk, as raw-index offsets from the start.
    std::vector<int> offsets{0};
    int start = 0;
    if (closed) {
        start = static_cast<int>(splitmix64(options.seed) % static_cast<std::uint64_t>(n));
        int pos = 0;
        for (;;) {
            const int s = step_at((start + pos) % n);
            if (pos + s >= n) break;
            pos += s;
            offsets.push_back(pos);
        }
        offsets.push_back(n); // the start again: closes the loop, removed below
    } else {
        int pos = 0;
        for (;;) {
            const int s = step_at(pos);
            if (pos + s >= n - 1) break;
            pos += s;
            offsets.push_back(pos);
        }
        offsets.push_back(n - 1); // open strokes keep their last point
    }
    // A last step shorter than half the one before (at least any step of 1): merge the two,
    // or split them evenly when the merged step would exceed max_step.
    const std::size_t m = offsets.size();
    if (m >= 3 && 2 * (offsets[m - 1] - offsets[m - 2]) < offsets[m - 2] - offsets[m - 3]) {
        const int joined = offsets[m - 1] - offsets[m - 3];
        if (joined <= CurvatureSteps::max_step)
            offsets.erase(offsets.end() - 2);
        else
            offsets[m - 2] = offsets[m - 3] + joined / 2;
    }
    const std::size_t samples = closed ? offsets.size() - 1 : offsets.size();
    if (samples < 4) {
        // Too short for four Eq. 1 samples: four evenly spaced ones.
        const int span = closed ? n : n - 1;
        const int count = closed ? 4 : 3;
        offsets.clear();
        for (int j = 0; j <= count; ++j) offsets.push_back(j * span / count);
    }
    const std::size_t kept = closed ? offsets.size() - 1 : offsets.size();
    for (std::size_t i = 0; i < kept; ++i) {
        const int idx = (start + offsets[i]) % n;
        out.indices.push_back(idx);
        out.points.push_back(raw[static_cast<std::size_t>(idx)]);
    }
    for (std::size_t i = 1; i < offsets.size(); ++i) out.steps.push_back(offsets[i] - offsets[i - 1]);
    return out;
}

std::vector<glm::vec3> sample_by_curvature(const std::vector<glm::vec3>& raw, bool closed, const SamplingOptions& options)
{
    return sample_by_curvature_detailed(raw, closed, options).points;
}

namespace {

double point_segment_distance(const glm::dvec3& x, const glm::dvec3& a, const glm::dvec3& b)
{
    const glm::dvec3 ab = b - a;
    const double len2 = glm::dot(ab, ab);
    const double t = len2 > 0.0 ? std::clamp(glm::dot(x - a, ab) / len2, 0.0, 1.0) : 0.0;
    return glm::distance(x, a + t * ab);
}

constexpr int kMaxEndPoints = 2000;

/// The index ranges [0, head_end] and [tail_begin, n − 1] covering `fraction` of the length
/// at each end (at least one point, at most kMaxEndPoints).
struct EndRanges {
    int head_end = 0;
    int tail_begin = 0;
};

EndRanges end_ranges(const std::vector<glm::dvec3>& p, double fraction)
{
    const int n = static_cast<int>(p.size());
    std::vector<double> cum(p.size(), 0.0);
    for (std::size_t i = 1; i < p.size(); ++i) cum[i] = cum[i - 1] + glm::distance(p[i - 1], p[i]);
    const double limit = fraction * cum.back();
    EndRanges r;
    while (r.head_end + 1 < n && r.head_end + 1 < kMaxEndPoints && cum[static_cast<std::size_t>(r.head_end + 1)] <= limit)
        ++r.head_end;
    r.tail_begin = n - 1;
    while (r.tail_begin - 1 > r.head_end && n - r.tail_begin < kMaxEndPoints &&
           cum.back() - cum[static_cast<std::size_t>(r.tail_begin - 1)] <= limit)
        --r.tail_begin;
    return r;
}

double gap_of(const std::vector<glm::dvec3>& p, const ClosureOptions& o)
{
    const EndRanges r = end_ranges(p, o.overlap_fraction);
    const int n = static_cast<int>(p.size());
    double gap = glm::distance(p.front(), p.back());
    for (int i = 0; i < r.head_end; ++i)
        gap = std::min(gap, point_segment_distance(p.back(), p[static_cast<std::size_t>(i)], p[static_cast<std::size_t>(i + 1)]));
    for (int i = r.tail_begin; i + 1 < n; ++i)
        gap = std::min(gap, point_segment_distance(p.front(), p[static_cast<std::size_t>(i)], p[static_cast<std::size_t>(i + 1)]));
    return gap;
}

} // namespace

double closure_gap(const std::vector<glm::vec3>& points, const ClosureOptions& options)
{
    const std::string who = "closure_gap";
    check_options(options, who);
    check_stroke_points(points, who);
    return gap_of(to_double(points), options);
}

bool is_closed_stroke(const std::vector<glm::vec3>& points, const ClosureOptions& options)
{
    const std::string who = "is_closed_stroke";
    check_options(options, who);
    check_stroke_points(points, who);
    const std::vector<glm::dvec3> p = to_double(points);
    const double gap = gap_of(p, options);
    return gap < options.max_gap_fraction * polyline_length(p, false) && gap < options.max_gap_m;
}

std::vector<glm::vec3> close_stroke(const std::vector<glm::vec3>& points, const ClosureOptions& options)
{
    const std::string who = "close_stroke";
    check_options(options, who);
    check_stroke_points(points, who);
    const std::vector<glm::dvec3> p = to_double(points);
    const double spacing = median_spacing(p, false);
    const EndRanges r = end_ranges(p, options.overlap_fraction);
    const int n = static_cast<int>(p.size());

    // Cut where the two ends come closest: the ends themselves for a gap, the crossing for
    // an overlapping tail. Ties keep the longer loop.
    int cut_head = 0;
    int cut_tail = n - 1;
    double best = std::numeric_limits<double>::infinity();
    for (int i = 0; i <= r.head_end; ++i)
        for (int j = n - 1; j >= r.tail_begin; --j) {
            const double d = glm::distance(p[static_cast<std::size_t>(i)], p[static_cast<std::size_t>(j)]);
            if (d < best) { best = d; cut_head = i; cut_tail = j; }
        }
    std::vector<glm::dvec3> loop(p.begin() + cut_head, p.begin() + cut_tail + 1);
    // No doubled point: drop end points that sit on top of the start.
    while (loop.size() > StrokeLimits::min_points && glm::distance(loop.back(), loop.front()) < 0.5 * spacing)
        loop.pop_back();
    // A gap: bridge it with points about one spacing apart.
    const double gap = glm::distance(loop.back(), loop.front());
    if (spacing > 0.0 && gap > 1.5 * spacing && loop.size() >= 2) {
        const double wanted = std::round(gap / spacing) - 1.0;
        if (wanted + static_cast<double>(loop.size()) > static_cast<double>(StrokeLimits::max_points))
            throw InvalidInput(who + ": the gap between the ends is too long to bridge at the stroke's spacing");
        const int insert = static_cast<int>(wanted);
        const glm::dvec3 p0 = loop[loop.size() - 2];
        const glm::dvec3 p1 = loop.back();
        const glm::dvec3 p2 = loop.front();
        const glm::dvec3 p3 = loop[1];
        for (int k = 1; k <= insert; ++k)
            loop.push_back(catmull_rom(p0, p1, p2, p3, static_cast<double>(k) / static_cast<double>(insert + 1)));
    }
    std::vector<glm::vec3> out;
    out.reserve(loop.size());
    for (const glm::dvec3& q : loop) out.emplace_back(q);
    check_stroke_points(out, who + " (closed result)");
    return out;
}

} // namespace lobe
