// The first stages of a lobe surface build (lobe_surface_builder.h): the strokes checked and
// seen from the centre, the previous build's memo, and, after one more stroke, which regions
// change; and the check that the result is closed. No CGAL.
#include "meshing/lobe_surface_builder.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>

#include <glm/geometric.hpp>

#include "core/errors.h"
#include "meshing/polyline.h"

namespace lobe {

namespace lobe_surface_detail {

void LobeSurfaceBuilder::plan()
{
    check_strokes();
    make_directions();
    old_memo_ = usable_memo();
    remember_strokes();
    choose_pole();
    find_crossings();
    build_chains();
    if (previous_ && changed_only_) plan_partial();
}

LobeSurface LobeSurfaceBuilder::start_surface() const
{
    LobeSurface out;
    out.memo = memo_;
    out.centre = centre_;
    out.reference_radius = options_.reference_radius_m > 0 ? options_.reference_radius_m : mean_radius_;
    return out;
}

void LobeSurfaceBuilder::check_strokes() const
{
    if (strokes_.empty()) throw InvalidInput("a lobe needs at least one stroke");
    std::size_t total = 0;
    for (Index s = 0; s < strokes_.size(); ++s) {
        if (strokes_[s].points.size() < 4)
            throw InvalidInput(stroke_name(static_cast<int>(s)) + " has fewer than 4 samples");
        total += strokes_[s].points.size();
        for (const glm::vec3& p : strokes_[s].points)
            if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z) ||
                std::abs(p.x) > StrokeLimits::max_coordinate_m || std::abs(p.y) > StrokeLimits::max_coordinate_m ||
                std::abs(p.z) > StrokeLimits::max_coordinate_m)
                throw InvalidInput(stroke_name(static_cast<int>(s)) + " has a coordinate that is not finite or beyond 1 km");
    }
    if (total > 200000) throw InvalidInput("a lobe's strokes have more than 200,000 samples");
    if (!std::isfinite(centre_.x) || !std::isfinite(centre_.y) || !std::isfinite(centre_.z))
        throw InvalidInput("the lobe's centre is not finite");
}

void LobeSurfaceBuilder::make_directions()
{
    const Index n = strokes_.size();
    dirs_.resize(n);
    radii_.resize(n);
    spacing_.resize(n);
    double sum_r = 0;
    std::size_t count = 0;
    double largest = 0;
    for (Index s = 0; s < n; ++s) {
        const auto pts = to_double(strokes_[s].points);
        spacing_[s] = median_spacing(pts, strokes_[s].closed);
        for (const glm::dvec3& p : pts) largest = std::max(largest, glm::length(p - centre_));
    }
    const double too_close = std::max(1e-4, 1e-3 * largest);
    for (Index s = 0; s < n; ++s) {
        for (const glm::vec3& pf : strokes_[s].points) {
            const glm::dvec3 v = glm::dvec3(pf) - centre_;
            const double r = glm::length(v);
            if (!(r > too_close))
                throw InvalidInput(stroke_name(static_cast<int>(s)) + " passes through the lobe's centre");
            dirs_[s].push_back(v / r);
            radii_[s].push_back(r);
            sum_r += r;
            ++count;
        }
    }
    mean_radius_ = sum_r / static_cast<double>(count);
    // Seen from the centre, consecutive samples of a stroke drawn around the lobe are close;
    // a segment spanning more than 90° cuts through the lobe's inside.
    for (Index s = 0; s < n; ++s) {
        const auto& d = dirs_[s];
        const Index m = d.size();
        for (Index i = 0; i + (strokes_[s].closed ? 0 : 1) < m; ++i)
            if (angle_between(d[i], d[(i + 1) % m]) > M_PI / 2.0)
                throw InvalidInput(stroke_name(static_cast<int>(s)) + " cuts through the lobe's inside, near its centre");
    }
}

const LobeBuildMemo* LobeSurfaceBuilder::usable_memo()
{
    if (!previous_ || !previous_->memo) return nullptr;
    const LobeBuildMemo& m = *previous_->memo;
    if (m.centre != centre_ || m.points.size() > strokes_.size() || m.points.empty()) return nullptr;
    for (Index s = 0; s < m.points.size(); ++s) {
        const auto& was = m.points[s];
        const auto& now = strokes_[s].points;
        if (was.size() != now.size() || (m.closed[s] != 0) != strokes_[s].closed ||
            std::memcmp(was.data(), now.data(), was.size() * sizeof(glm::vec3)) != 0)
            return nullptr;
    }
    old_strokes_ = m.points.size();
    return &m;
}

void LobeSurfaceBuilder::remember_strokes()
{
    memo_->centre = centre_;
    memo_->points.resize(strokes_.size());
    for (Index s = 0; s < strokes_.size(); ++s) memo_->points[s] = strokes_[s].points;
    memo_->closed.resize(strokes_.size());
    for (Index s = 0; s < strokes_.size(); ++s) memo_->closed[s] = strokes_[s].closed ? 1 : 0;
}

void LobeSurfaceBuilder::plan_partial()
{
    partial_ = false;
    const double reference = options_.reference_radius_m > 0 ? options_.reference_radius_m : mean_radius_;
    if (previous_->centre != centre_ || previous_->reference_radius != reference) return;
    std::vector<RegionChain> chains(chains_.size());
    for (Index s = 0; s < chains_.size(); ++s) {
        chains[s].points.reserve(chains_[s].size());
        for (int id : chains_[s]) chains[s].points.push_back(emitted_position(id));
        chains[s].closed = strokes_[s].closed;
        chains[s].crossed = crossing_count_[s] > 0;
    }
    changed_ = find_changed_regions(*previous_, *previous_regions_, chains);
    partial_ = !changed_.everything;
    if (!partial_) return;
    // A cap of directions around each changed region of the previous surface. The changed
    // regions of this build cover what those did (the same border edges bound both), so a
    // lattice point outside every cap cannot fall into one: seed_fill neither tests it nor
    // the stroke edges that only such points could be near.
    const TriangleMesh& mesh = previous_->mesh;
    const auto& face_region = previous_regions_->regions.face_region;
    std::vector<int> cap_of(changed_.keep.size(), -1);
    std::vector<glm::dvec3> dir(mesh.positions.size(), glm::dvec3(0.0));
    std::vector<char> have(mesh.positions.size(), 0);
    std::vector<glm::dvec3> sum;
    for (Index f = 0; f < mesh.triangles.size(); ++f) {
        const Index r = static_cast<Index>(face_region[f]);
        if (changed_.keep[r]) continue;
        if (cap_of[r] < 0) {
            cap_of[r] = static_cast<int>(sum.size());
            sum.emplace_back(0.0);
        }
        for (int v : mesh.triangles[f]) {
            const Index i = static_cast<Index>(v);
            if (!have[i]) {
                have[i] = 1;
                dir[i] = glm::normalize(glm::dvec3(mesh.positions[i]) - centre_);
            }
            sum[static_cast<Index>(cap_of[r])] += dir[i];
        }
    }
    caps_.assign(sum.size(), {glm::dvec3(0.0), 1.0});
    for (Index c = 0; c < sum.size(); ++c) {
        const double len = glm::length(sum[c]);
        caps_[c].first = len > 1e-12 ? sum[c] / len : glm::dvec3(0, 0, 1);
        if (!(len > 1e-12)) caps_[c].second = -1.0; // a region round the whole sphere: everything
    }
    for (Index f = 0; f < mesh.triangles.size(); ++f) {
        const Index r = static_cast<Index>(face_region[f]);
        if (changed_.keep[r]) continue;
        auto& cap = caps_[static_cast<Index>(cap_of[r])];
        for (int v : mesh.triangles[f]) cap.second = std::min(cap.second, glm::dot(dir[static_cast<Index>(v)], cap.first));
    }
}

/// Whether a surface has no hole. Every triangle of a build faces away from the centre, but
/// strokes that run over themselves (a loop whose ends met after it folded back, so that it
/// encloses nothing) give the triangulation regions without area, and the surface an open
/// border there. Each edge a → b adds ±hash(min, max) (+ when a < b), so a closed surface,
/// where every edge is run once each way, sums to zero; an open border edge leaves its hash
/// (a sum of such hashes is zero with a chance of 2⁻⁶⁴). One pass over the triangles, far
/// cheaper than matching the edges up.
bool closed_surface(const TriangleMesh& mesh)
{
    std::uint64_t sum = 0;
    for (const auto& t : mesh.triangles)
        for (std::size_t k = 0; k < 3; ++k) {
            const auto a = static_cast<std::uint32_t>(t[k]), b = static_cast<std::uint32_t>(t[(k + 1) % 3]);
            // A 64-bit mix of the undirected edge (two multiplications: nonlinear enough that
            // the hashes of an open border do not cancel but by chance), negated when a > b.
            std::uint64_t h = (std::uint64_t{std::min(a, b)} << 32 | std::max(a, b)) * 0x9E3779B97F4A7C15ull;
            h = (h ^ (h >> 29)) * 0xBF58476D1CE4E5B9ull;
            h ^= h >> 32;
            const std::uint64_t negate = std::uint64_t{0} - static_cast<std::uint64_t>(a > b);
            sum += (h ^ negate) - negate;
        }
    return sum == 0 && !mesh.triangles.empty();
}

void require_closed(const TriangleMesh& mesh)
{
    if (!closed_surface(mesh))
        throw InvalidInput("the lobe's strokes leave its surface open (a stroke folds back or runs over itself)");
}

} // namespace lobe_surface_detail

glm::dvec3 lobe_stroke_centroid(const std::vector<LobeStrokeSamples>& strokes)
{
    bool any_closed = false;
    for (const auto& s : strokes) any_closed = any_closed || s.closed;
    glm::dvec3 sum(0.0);
    double weight = 0;
    for (const auto& s : strokes) {
        if (any_closed && !s.closed) continue;
        const auto pts = to_double(s.points);
        const double len = polyline_length(pts, s.closed);
        sum += len * polyline_barycentre(pts, s.closed);
        weight += len;
    }
    if (weight > 0) return sum / weight;
    glm::dvec3 mean(0.0);
    std::size_t n = 0;
    for (const auto& s : strokes)
        for (const glm::vec3& p : s.points) {
            mean += glm::dvec3(p);
            ++n;
        }
    return n ? mean / static_cast<double>(n) : mean;
}

} // namespace lobe
