#include "growth/selforg/markers.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include <glm/common.hpp>

#include "core/errors.h"
#include "core/random.h"
#include "growth/mesh_raycast.h"

namespace lobe {

namespace {

/// Grid cells of side `spacing` over [lo, hi], refused past the marker limit.
glm::ivec3 marker_grid(const glm::vec3& lo, const glm::vec3& hi, double spacing)
{
    if (!(spacing > 0.0) || !std::isfinite(spacing)) throw InvalidInput("self-organizing: marker spacing must be > 0");
    const glm::dvec3 n = glm::ceil((glm::dvec3(hi) - glm::dvec3(lo)) / spacing);
    const double cells = std::max(n.x, 1.0) * std::max(n.y, 1.0) * std::max(n.z, 1.0);
    if (!std::isfinite(cells) || cells > static_cast<double>(kMaxSelfOrgMarkers))
        throw InvalidInput("self-organizing: the envelope holds about " + std::to_string(static_cast<long long>(
                               std::min(cells, 1e18))) + " marker cells, more than the limit of " +
                           std::to_string(kMaxSelfOrgMarkers) + " (use a longer internode)");
    return glm::ivec3(std::max(n.x, 1.0), std::max(n.y, 1.0), std::max(n.z, 1.0));
}

/// The jittered marker of grid cell (x, y, z).
glm::vec3 jittered(const glm::vec3& lo, double spacing, int x, int y, int z, std::uint64_t seed)
{
    const std::uint64_t key = splitmix64(seed ^ splitmix64((static_cast<std::uint64_t>(static_cast<std::uint32_t>(x)) << 42) ^
                                                           (static_cast<std::uint64_t>(static_cast<std::uint32_t>(y)) << 21) ^
                                                           static_cast<std::uint32_t>(z)));
    SplitMix64 rng(key);
    const double jx = rng.uniform(0.2, 0.8), jy = rng.uniform(0.2, 0.8), jz = rng.uniform(0.2, 0.8);
    return lo + glm::vec3(static_cast<float>((x + jx) * spacing), static_cast<float>((y + jy) * spacing),
                          static_cast<float>((z + jz) * spacing));
}

} // namespace

MarkerCloud::MarkerCloud(std::vector<glm::vec3> points, double cell_m) : points_(std::move(points))
{
    if (points_.size() > kMaxSelfOrgMarkers)
        throw InvalidInput("self-organizing: " + std::to_string(points_.size()) + " markers exceed the limit of " +
                           std::to_string(kMaxSelfOrgMarkers));
    if (!(cell_m > 0.0) || !std::isfinite(cell_m)) throw InvalidInput("self-organizing: marker cell side must be > 0");
    alive_.assign(points_.size(), 1);
    alive_count_ = points_.size();
    side_ = static_cast<float>(cell_m);
    if (points_.empty()) return;
    glm::vec3 lo = points_[0], hi = points_[0];
    for (const glm::vec3& p : points_) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    lo_ = lo;
    const glm::ivec3 n = marker_grid(lo, hi + glm::vec3(side_ * 0.5f), cell_m);
    nx_ = n.x;
    ny_ = n.y;
    nz_ = n.z;
    const std::size_t cells = static_cast<std::size_t>(nx_) * static_cast<std::size_t>(ny_) * static_cast<std::size_t>(nz_);
    cell_.resize(points_.size());
    std::vector<std::uint32_t> start(cells + 1, 0);
    for (std::size_t i = 0; i < points_.size(); ++i) {
        int x, y, z;
        cell_of(points_[i], x, y, z);
        cell_[i] = static_cast<std::uint32_t>((static_cast<std::size_t>(z) * static_cast<std::size_t>(ny_) +
                                               static_cast<std::size_t>(y)) * static_cast<std::size_t>(nx_) +
                                              static_cast<std::size_t>(x));
        ++start[cell_[i] + 1];
    }
    for (std::size_t c = 0; c < cells; ++c) start[c + 1] += start[c];
    cells_.resize(cells);
    for (std::size_t c = 0; c < cells; ++c) cells_[c] = {start[c], start[c + 1] - start[c]};
    order_.resize(points_.size());
    where_.resize(points_.size());
    slot_point_.resize(points_.size());
    for (std::size_t i = 0; i < points_.size(); ++i) {
        where_[i] = start[cell_[i]]++;
        order_[where_[i]] = static_cast<std::uint32_t>(i);
        slot_point_[where_[i]] = points_[i];
    }
}

void MarkerCloud::cell_of(const glm::vec3& p, int& x, int& y, int& z) const
{
    const glm::vec3 g = (p - lo_) / side_;
    x = std::clamp(static_cast<int>(std::floor(g.x)), 0, nx_ - 1);
    y = std::clamp(static_cast<int>(std::floor(g.y)), 0, ny_ - 1);
    z = std::clamp(static_cast<int>(std::floor(g.z)), 0, nz_ - 1);
}

void MarkerCloud::remove(std::size_t i)
{
    // Swap the marker with the last live one of its cell, and shorten the live part.
    Cell& cell = cells_[cell_[i]];
    const std::uint32_t last = cell.start + --cell.live;
    const std::uint32_t other = order_[last];
    std::swap(order_[where_[i]], order_[last]);
    std::swap(slot_point_[where_[i]], slot_point_[last]);
    where_[other] = where_[i];
    where_[i] = last;
    alive_[i] = 0;
    --alive_count_;
}

std::size_t MarkerCloud::remove_within(const glm::vec3& p, double radius)
{
    scratch_.clear();
    for_each_within(p, radius, [&](std::size_t i) { scratch_.push_back(static_cast<std::uint32_t>(i)); });
    for (const std::uint32_t i : scratch_) remove(i);
    return scratch_.size();
}

std::vector<glm::vec3> markers_in_meshes(const std::vector<TriangleMesh>& meshes, double spacing_m, std::uint64_t seed)
{
    glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
    for (const TriangleMesh& m : meshes)
        for (const glm::vec3& p : m.positions) {
            lo = glm::min(lo, p);
            hi = glm::max(hi, p);
        }
    std::vector<glm::vec3> out;
    if (!(lo.x <= hi.x)) return out;
    const glm::ivec3 n = marker_grid(lo, hi, spacing_m);
    std::vector<MeshRaycaster> rays;
    rays.reserve(meshes.size());
    for (const TriangleMesh& m : meshes) rays.emplace_back(m);
    std::vector<float> hits;
    std::vector<std::pair<float, float>> inside; // y intervals inside a mesh in this column
    const glm::vec3 up(0.0f, 1.0f, 0.0f);
    for (int z = 0; z < n.z; ++z)
        for (int x = 0; x < n.x; ++x) {
            const glm::vec3 base = lo + glm::vec3(static_cast<float>((x + 0.5) * spacing_m), -1.0f,
                                                  static_cast<float>((z + 0.5) * spacing_m));
            inside.clear();
            for (const MeshRaycaster& r : rays) {
                r.crossings(base, up, hits);
                for (std::size_t k = 0; k + 1 < hits.size(); k += 2)
                    inside.emplace_back(base.y + hits[k], base.y + hits[k + 1]);
            }
            if (inside.empty()) continue;
            for (int y = 0; y < n.y; ++y) {
                const glm::vec3 p = jittered(lo, spacing_m, x, y, z, seed);
                for (const auto& [a, b] : inside)
                    if (p.y > a && p.y < b) {
                        out.push_back(p);
                        break;
                    }
            }
        }
    return out;
}

std::vector<glm::vec3> markers_in_sphere(const glm::vec3& centre, double radius_m, double spacing_m, std::uint64_t seed)
{
    const glm::vec3 lo = centre - glm::vec3(static_cast<float>(radius_m));
    const glm::ivec3 n = marker_grid(lo, centre + glm::vec3(static_cast<float>(radius_m)), spacing_m);
    const float r2 = static_cast<float>(radius_m * radius_m);
    std::vector<glm::vec3> out;
    for (int z = 0; z < n.z; ++z)
        for (int y = 0; y < n.y; ++y)
            for (int x = 0; x < n.x; ++x) {
                const glm::vec3 p = jittered(lo, spacing_m, x, y, z, seed);
                const glm::vec3 d = p - centre;
                if (d.x * d.x + d.y * d.y + d.z * d.z <= r2) out.push_back(p);
            }
    return out;
}

} // namespace lobe
