// Lives in lobe_meshing_cgal (hence the name): it calls build_lobe_surface.
#include "meshing/lobe.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <glm/geometric.hpp>

#include "core/errors.h"
#include "meshing/polyline.h"

namespace lobe {

namespace {

/// Douglas–Peucker between consecutive samples: raw points are added where the chord
/// between two samples would leave the drawn stroke by more than `tolerance`, so the lobe
/// passes through the stroke itself, not only through its samples.
void refine_interval(const std::vector<glm::vec3>& raw, std::size_t a, std::size_t b, double tolerance,
                     std::vector<glm::vec3>& out, int depth = 0)
{
    const std::size_t n = raw.size();
    const std::size_t count = (b + n - a) % n; // raw steps from a to b (b may wrap)
    if (count < 2 || depth > 40) return;
    const glm::dvec3 p(raw[a]), q(raw[b % n]);
    const glm::dvec3 pq = q - p;
    const double len2 = glm::dot(pq, pq);
    double worst = -1;
    std::size_t worst_k = 0;
    for (std::size_t k = 1; k < count; ++k) {
        const glm::dvec3 x(raw[(a + k) % n]);
        const double t = len2 > 0 ? std::clamp(glm::dot(x - p, pq) / len2, 0.0, 1.0) : 0.0;
        const double d = glm::distance(x, p + t * pq);
        if (d > worst) {
            worst = d;
            worst_k = k;
        }
    }
    if (worst <= tolerance) return;
    const std::size_t m = (a + worst_k) % n;
    refine_interval(raw, a, m, tolerance, out, depth + 1);
    out.push_back(raw[m]);
    refine_interval(raw, m, b, tolerance, out, depth + 1);
}

std::vector<glm::vec3> refine_samples(const std::vector<glm::vec3>& raw, const std::vector<int>& indices, bool closed,
                                      double tolerance)
{
    if (tolerance <= 0) {
        std::vector<glm::vec3> out;
        for (int i : indices) out.push_back(raw[static_cast<std::size_t>(i)]);
        return out;
    }
    std::vector<glm::vec3> out;
    const std::size_t m = indices.size();
    for (std::size_t i = 0; i < m; ++i) {
        const std::size_t a = static_cast<std::size_t>(indices[i]);
        out.push_back(raw[a]);
        if (!closed && i + 1 == m) break;
        refine_interval(raw, a, static_cast<std::size_t>(indices[(i + 1) % m]), tolerance, out);
    }
    return out;
}

} // namespace

LobeStrokeSamples prepare_lobe_stroke(std::int64_t id, const std::vector<glm::vec3>& raw, const LobeOptions& options)
{
    const std::string who = "lobe stroke " + std::to_string(id);
    check_stroke_points(raw, who);
    LobeStrokeSamples out;
    out.id = id;
    out.closed = is_closed_stroke(raw, options.closure);
    const std::vector<glm::vec3> line = out.closed ? close_stroke(raw, options.closure) : raw;
    const CurvatureSampling sampling = sample_by_curvature_detailed(line, out.closed, options.sampling);
    out.points = refine_samples(line, sampling.indices, out.closed, options.max_chord_deviation_m);
    if (out.points.size() < 4) throw InvalidInput(who + " is too short to sample");
    // The same loop twice (or a path and back): every sample of the stroke's second half lies
    // within duplicate_distance_m of its first half. Checked on at most 2,000 samples.
    {
        const std::vector<glm::dvec3> q = to_double(out.points);
        std::vector<double> arc(q.size(), 0.0);
        for (std::size_t i = 1; i < q.size(); ++i) arc[i] = arc[i - 1] + glm::distance(q[i - 1], q[i]);
        const std::size_t half = static_cast<std::size_t>(
            std::lower_bound(arc.begin(), arc.end(), 0.5 * arc.back()) - arc.begin());
        const std::size_t stride = std::max<std::size_t>(1, (q.size() - half) / 2000);
        bool retraced = half >= 2 && half + 2 <= q.size();
        for (std::size_t k = half + 1; retraced && k < q.size(); k += stride) {
            double best = std::numeric_limits<double>::infinity();
            for (std::size_t i = 0; i + 1 < half && best > options.duplicate_distance_m; ++i) {
                const glm::dvec3 ab = q[i + 1] - q[i];
                const double len2 = glm::dot(ab, ab);
                const double t = len2 > 0 ? std::clamp(glm::dot(q[k] - q[i], ab) / len2, 0.0, 1.0) : 0.0;
                best = std::min(best, glm::distance(q[k], q[i] + t * ab));
            }
            retraced = best <= options.duplicate_distance_m;
        }
        // A closed stroke that encloses (almost) nothing: its ends met after it went out and came
        // back along itself, which the halves above miss when the turn falls between them. Its
        // vector area is under a thousandth of its length squared (a real loop's is about
        // 0.08; a loop 30 cm long would have to be under about 1 mm wide).
        if (!retraced && out.closed) {
            glm::dvec3 area(0.0);
            double length = 0.0;
            for (std::size_t i = 0; i < q.size(); ++i) {
                const glm::dvec3& a = q[i];
                const glm::dvec3& b = q[(i + 1) % q.size()];
                area += 0.5 * glm::cross(a - q[0], b - q[0]);
                length += glm::distance(a, b);
            }
            retraced = !(glm::length(area) >= 1e-3 * length * length);
        }
        if (retraced) throw InvalidInput(who + " retraces itself (the same loop twice, or a path and back along it)");
    }
    // A stroke that reverses (turns by more than 160° from one Eq. 1 sample to the next)
    // folds back on itself: its two legs would make a zero-width sliver of the lobe.
    std::vector<glm::vec3> samples;
    for (int i : sampling.indices) samples.push_back(line[static_cast<std::size_t>(i)]);
    const std::size_t n = samples.size();
    for (std::size_t i = out.closed ? 0 : 1; i < (out.closed ? n : n - 1); ++i) {
        const glm::dvec3 a(samples[(i + n - 1) % n]), b(samples[i]), c(samples[(i + 1) % n]);
        const glm::dvec3 u = b - a, v = c - b;
        const double lu = glm::length(u), lv = glm::length(v);
        if (lu > 0 && lv > 0 && glm::dot(u, v) < std::cos(160.0 * 3.14159265358979323846 / 180.0) * lu * lv)
            throw InvalidInput(who + " folds back on itself");
    }
    return out;
}

Lobe::Lobe(LobeOptions options) : options_(std::move(options)) {}

double Lobe::mean_radius() const
{
    double sum = 0;
    std::size_t n = 0;
    for (const auto& s : strokes_)
        for (const glm::vec3& p : s.points) {
            sum += glm::length(glm::dvec3(p) - centre_);
            ++n;
        }
    return n ? sum / static_cast<double>(n) : 0.0;
}

double Lobe::distance_to(const std::vector<glm::vec3>& points) const
{
    double best = std::numeric_limits<double>::infinity();
    for (const auto& s : strokes_)
        for (const glm::vec3& q : s.points)
            for (const glm::vec3& p : points) best = std::min(best, static_cast<double>(glm::distance(p, q)));
    return best;
}

void Lobe::add_stroke(std::int64_t id, const std::vector<glm::vec3>& raw)
{
    add_prepared(prepare_lobe_stroke(id, raw, options_));
}

void Lobe::add_prepared(LobeStrokeSamples stroke)
{
    const std::string who = "lobe stroke " + std::to_string(stroke.id);
    for (const auto& s : strokes_) {
        if (s.id == stroke.id) throw InvalidInput(who + " is already in the lobe");
        // A duplicate: every sample within duplicate_distance_m of the other stroke's samples
        // or of the segments between them.
        const auto other = to_double(s.points);
        bool all_near = true;
        for (const glm::vec3& pf : stroke.points) {
            const glm::dvec3 p(pf);
            double best = std::numeric_limits<double>::infinity();
            for (std::size_t i = 0; i + 1 < other.size() + (s.closed ? 1 : 0); ++i) {
                const glm::dvec3 a = other[i], b = other[(i + 1) % other.size()];
                const glm::dvec3 ab = b - a;
                const double len2 = glm::dot(ab, ab);
                const double t = len2 > 0 ? std::clamp(glm::dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
                best = std::min(best, glm::distance(p, a + t * ab));
            }
            if (best > options_.duplicate_distance_m) {
                all_near = false;
                break;
            }
        }
        if (all_near) throw InvalidInput(who + " retraces lobe stroke " + std::to_string(s.id));
    }
    std::vector<LobeStrokeSamples> next = strokes_;
    next.push_back(std::move(stroke));
    rebuild(std::move(next), true);
}

bool Lobe::remove_stroke(std::int64_t id)
{
    auto it = std::find_if(strokes_.begin(), strokes_.end(), [&](const LobeStrokeSamples& s) { return s.id == id; });
    if (it == strokes_.end()) return false;
    std::vector<LobeStrokeSamples> next;
    for (const auto& s : strokes_)
        if (s.id != id) next.push_back(s);
    if (next.empty()) {
        strokes_.clear();
        surface_.reset();
        centre_ = glm::dvec3(0.0);
        last_kept_ = {};
        regions_ = {};
        return true;
    }
    rebuild(std::move(next), false);
    return true;
}

void Lobe::rebuild(std::vector<LobeStrokeSamples> strokes, bool keep_regions)
{
    // The centre moves only when the strokes' centroid has drifted away from it: then
    // adding a stroke re-lays only the region around it. When the kept centre cannot see
    // the whole lobe (it would fold), the centroid is tried before giving up.
    const glm::dvec3 centroid = lobe_stroke_centroid(strokes);
    glm::dvec3 centre = centroid;
    if (surface_) {
        double sum = 0;
        std::size_t n = 0;
        for (const auto& s : strokes)
            for (const glm::vec3& p : s.points) {
                sum += glm::length(glm::dvec3(p) - centre_);
                ++n;
            }
        const double radius = n ? sum / static_cast<double>(n) : 0.0;
        if (glm::distance(centroid, centre_) <= options_.recentre_fraction * radius) centre = centre_;
    }
    // The fill density stays with the centre: the radius it was derived from is kept too.
    LobeSurfaceOptions kept = options_.surface;
    if (surface_ && centre == centre_) kept.reference_radius_m = surface_->reference_radius;
    // Regions the stroke did not reach stay as they were (with the centre and the fill
    // density they were made with): the fill of those regions would otherwise follow the
    // radius model, which every stroke refits, by up to millimetres, and nothing of the
    // lobe's remeshing could be kept. Only the regions the stroke changed are built.
    LobeSurface surface;
    KeptRegions kept_regions;
    SurfaceRegions regions;
    bool continued = false;
    try {
        if (keep_regions && surface_ && centre == centre_) {
            surface = continue_lobe_surface(*surface_, regions_, strokes, centre, kept, regions, kept_regions);
            continued = true;
        } else {
            surface = build_lobe_surface(strokes, centre, kept);
        }
    } catch (const InvalidInput&) {
        if (centre == centroid) throw;
        centre = centroid;
        surface = build_lobe_surface(strokes, centre, options_.surface);
        continued = false;
    }
    if (!continued) {
        regions = surface_regions(surface.mesh);
        kept_regions = {};
        kept_regions.regions = regions.regions.count;
    }
    strokes_ = std::move(strokes);
    surface_ = std::move(surface);
    centre_ = centre;
    last_kept_ = kept_regions;
    regions_ = std::move(regions);
}

} // namespace lobe
