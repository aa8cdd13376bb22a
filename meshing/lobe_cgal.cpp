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

LobeStrokeSamples prepare_lobe_stroke(std::int64_t id, const std::vector<glm::vec3>& raw, const LobeOptions& options)
{
    const std::string who = "lobe stroke " + std::to_string(id);
    check_stroke_points(raw, who);
    LobeStrokeSamples out;
    out.id = id;
    out.closed = is_closed_stroke(raw, options.closure);
    if (out.closed) {
        const std::vector<glm::vec3> loop = close_stroke(raw, options.closure);
        out.points = sample_by_curvature(loop, true, options.sampling);
    } else {
        out.points = sample_by_curvature(raw, false, options.sampling);
    }
    if (out.points.size() < 4) throw InvalidInput(who + " is too short to sample");
    // A stroke that reverses (turns by more than 160° from one sample to the next) folds back
    // on itself: its two legs would make a zero-width sliver of the lobe.
    const std::size_t n = out.points.size();
    for (std::size_t i = out.closed ? 0 : 1; i < (out.closed ? n : n - 1); ++i) {
        const glm::dvec3 a(out.points[(i + n - 1) % n]), b(out.points[i]), c(out.points[(i + 1) % n]);
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
    rebuild(std::move(next));
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
        return true;
    }
    rebuild(std::move(next));
    return true;
}

void Lobe::rebuild(std::vector<LobeStrokeSamples> strokes)
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
    LobeSurface surface;
    try {
        surface = build_lobe_surface(strokes, centre, kept);
    } catch (const InvalidInput&) {
        if (centre == centroid) throw;
        centre = centroid;
        surface = build_lobe_surface(strokes, centre, options_.surface);
    }
    strokes_ = std::move(strokes);
    surface_ = std::move(surface);
    centre_ = centre;
}

} // namespace lobe
