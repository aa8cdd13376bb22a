#pragma once
/// \file markers.h
/// Space colonization markers (Palubicki et al. 2009, §4.1, after Runions et al. 2007): points
/// of free space. A bud perceives the markers within distance r inside its cone of opening
/// angle θ; each marker goes to the nearest bud that perceives it; markers within the
/// occupancy radius ρ of a new node are removed for good.
///
/// Index: a uniform grid of cells of side r over the markers, built once, each cell's live
/// markers kept at the front of its slice (a removal swaps the marker behind them). Markers
/// are only ever removed, so the index never needs rebuilding (a static k-d tree such as
/// nanoflann's would need a rebuild, or tombstones it keeps visiting, after every removal); a
/// fixed-radius query visits only the cells the ball overlaps and only live markers in them,
/// so the cost follows the markers left near the growing front; and the visiting order is
/// fixed, which keeps results bit-identical per seed.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "core/mesh.h"

namespace lobe {

/// Most markers one tree may use (about 40 bytes each): more is refused in one line.
inline constexpr std::size_t kMaxSelfOrgMarkers = 8000000;

class MarkerCloud {
public:
    /// \param points marker positions, metres. \param cell_m the grid's cell side (the
    /// grower uses the perception radius r: measured fastest against r/2, r/3 and r/4). \throw InvalidInput when points exceed kMaxSelfOrgMarkers or cell_m ≤ 0.
    MarkerCloud(std::vector<glm::vec3> points, double cell_m);

    std::size_t size() const { return points_.size(); }
    std::size_t alive_count() const { return alive_count_; }
    bool alive(std::size_t i) const { return alive_[i] != 0; }
    const glm::vec3& point(std::size_t i) const { return points_[i]; }

    /// Removes every live marker within `radius` of `p`; returns how many.
    std::size_t remove_within(const glm::vec3& p, double radius);

    /// Calls visit(index) for every live marker within `radius` of `p`, in a fixed order.
    /// \pre visit removes nothing.
    template <typename Visit>
    void for_each_within(const glm::vec3& p, double radius, Visit&& visit) const;

    /// For up to two cones at `p` (the terminal and the axillary bud of one node): calls
    /// visit(index, squared distance, k) for every live marker q within `radius` of `p`
    /// inside cone k, around axes[k] (unit) with half-angle of cosine `cos_half`:
    /// (q − p)·axes[k] ≥ cos_half·|q − p|, q ≠ p; cone 0 before cone 1 for each marker. Cells
    /// outside the ball, or wholly behind `p` for every cone when cos_half ≥ 0, are skipped.
    /// Fixed order. \pre 1 ≤ axes.size() ≤ 2; visit removes nothing.
    template <typename Visit>
    void for_each_in_cones(const glm::vec3& p, double radius, std::span<const glm::vec3> axes, float cos_half,
                           Visit&& visit) const;

private:
    void cell_of(const glm::vec3& p, int& x, int& y, int& z) const;
    void remove(std::size_t i);
    std::vector<glm::vec3> points_;
    std::vector<std::uint8_t> alive_;
    std::size_t alive_count_ = 0;
    glm::vec3 lo_{0.0f};
    float side_ = 1.0f;
    int nx_ = 0, ny_ = 0, nz_ = 0;
    struct Cell {
        std::uint32_t start = 0; ///< the cell's markers are slots start … start + its size
        std::uint32_t live = 0;  ///< its live markers are the first `live` of them
    };
    std::vector<Cell> cells_;
    std::vector<std::uint32_t> order_;      ///< per slot: the marker in it
    std::vector<glm::vec3> slot_point_;     ///< per slot: that marker's position (scanned in order)
    std::vector<std::uint32_t> where_;      ///< per marker: its place in order_
    std::vector<std::uint32_t> cell_;       ///< per marker: its cell
    std::vector<std::uint32_t> scratch_;    ///< remove_within's hits
};

template <typename Visit>
void MarkerCloud::for_each_within(const glm::vec3& p, double radius, Visit&& visit) const
{
    if (points_.empty() || !(radius >= 0.0)) return;
    const float r = static_cast<float>(radius), r2 = r * r;
    const glm::vec3 a = (p - glm::vec3(r) - lo_) / side_, b = (p + glm::vec3(r) - lo_) / side_;
    const int x0 = std::max(static_cast<int>(std::floor(a.x)), 0), x1 = std::min(static_cast<int>(std::floor(b.x)), nx_ - 1);
    const int y0 = std::max(static_cast<int>(std::floor(a.y)), 0), y1 = std::min(static_cast<int>(std::floor(b.y)), ny_ - 1);
    const int z0 = std::max(static_cast<int>(std::floor(a.z)), 0), z1 = std::min(static_cast<int>(std::floor(b.z)), nz_ - 1);
    for (int z = z0; z <= z1; ++z)
        for (int y = y0; y <= y1; ++y)
            for (int x = x0; x <= x1; ++x) {
                const std::size_t c = (static_cast<std::size_t>(z) * static_cast<std::size_t>(ny_) + static_cast<std::size_t>(y)) *
                                          static_cast<std::size_t>(nx_) + static_cast<std::size_t>(x);
                const std::uint32_t begin = cells_[c].start, end = begin + cells_[c].live;
                for (std::uint32_t k = begin; k < end; ++k) {
                    const std::uint32_t i = order_[k];
                    const glm::vec3 d = slot_point_[k] - p;
                    if (d.x * d.x + d.y * d.y + d.z * d.z <= r2) visit(static_cast<std::size_t>(i));
                }
            }
}

template <typename Visit>
void MarkerCloud::for_each_in_cones(const glm::vec3& p, double radius, std::span<const glm::vec3> axes, float cos_half,
                                    Visit&& visit) const
{
    if (points_.empty() || !(radius >= 0.0)) return;
    const float r = static_cast<float>(radius), r2 = r * r;
    const float half_diag = 0.8660254f * side_;
    const float cos2 = cos_half * cos_half;
    const glm::vec3 a = (p - glm::vec3(r) - lo_) / side_, b = (p + glm::vec3(r) - lo_) / side_;
    const int x0 = std::max(static_cast<int>(std::floor(a.x)), 0), x1 = std::min(static_cast<int>(std::floor(b.x)), nx_ - 1);
    const int y0 = std::max(static_cast<int>(std::floor(a.y)), 0), y1 = std::min(static_cast<int>(std::floor(b.y)), ny_ - 1);
    const int z0 = std::max(static_cast<int>(std::floor(a.z)), 0), z1 = std::min(static_cast<int>(std::floor(b.z)), nz_ - 1);
    for (int z = z0; z <= z1; ++z)
        for (int y = y0; y <= y1; ++y)
            for (int x = x0; x <= x1; ++x) {
                const std::size_t c = (static_cast<std::size_t>(z) * static_cast<std::size_t>(ny_) + static_cast<std::size_t>(y)) *
                                          static_cast<std::size_t>(nx_) + static_cast<std::size_t>(x);
                const std::uint32_t begin = cells_[c].start, end = begin + cells_[c].live;
                if (begin == end) continue;
                const glm::vec3 centre = lo_ + (glm::vec3(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z)) +
                                                glm::vec3(0.5f)) * side_;
                const glm::vec3 to = centre - p;
                const float reach = r + half_diag;
                if (to.x * to.x + to.y * to.y + to.z * to.z > reach * reach) continue;
                if (cos_half >= 0.0f) {
                    bool ahead = false;
                    for (const glm::vec3& axis : axes) ahead = ahead || to.x * axis.x + to.y * axis.y + to.z * axis.z >= -half_diag;
                    if (!ahead) continue;
                }
                for (std::uint32_t k = begin; k < end; ++k) {
                    const glm::vec3 d = slot_point_[k] - p;
                    const float d2 = d.x * d.x + d.y * d.y + d.z * d.z;
                    if (d2 > r2 || d2 <= 0.0f) continue;
                    for (std::size_t cone = 0; cone < axes.size(); ++cone) {
                        const glm::vec3& axis = axes[cone];
                        const float along = d.x * axis.x + d.y * axis.y + d.z * axis.z;
                        // along ≥ cos_half·|d| without a square root.
                        if (cos_half >= 0.0f ? (along < 0.0f || along * along < cos2 * d2)
                                             : (along < 0.0f && along * along > cos2 * d2))
                            continue;
                        visit(static_cast<std::size_t>(order_[k]), d2, cone);
                    }
                }
            }
}

/// Markers filling closed meshes' volumes: one per cell of a grid of side `spacing_m`,
/// jittered within its cell by a stream keyed by `seed`, kept when inside any of the meshes
/// (parity of crossings along one vertical ray per grid column).
/// \throw InvalidInput when more than kMaxSelfOrgMarkers grid cells would be tested.
std::vector<glm::vec3> markers_in_meshes(const std::vector<TriangleMesh>& meshes, double spacing_m, std::uint64_t seed);

/// Markers filling a sphere (the default envelope of free growth), same jittered grid.
/// \throw InvalidInput as markers_in_meshes.
std::vector<glm::vec3> markers_in_sphere(const glm::vec3& centre, double radius_m, double spacing_m,
                                         std::uint64_t seed);

} // namespace lobe
