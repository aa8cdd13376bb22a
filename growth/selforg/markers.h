#pragma once
/// \file markers.h
/// Space colonization markers (Palubicki et al. 2009, §4.1, after Runions et al. 2007): points
/// of free space. A bud perceives the markers within distance r inside its cone of opening
/// angle θ; each marker goes to the nearest bud that perceives it; markers within the
/// occupancy radius ρ of a new node are removed for good.
///
/// Index: a uniform grid of cells of side r/2 over the markers, built once, each cell's live
/// markers kept at the front of its slice (a removal swaps the marker behind them). Markers
/// are only ever removed, so the index never needs rebuilding (a static k-d tree such as
/// nanoflann's would need a rebuild, or tombstones it keeps visiting, after every removal); a
/// fixed-radius query visits only the cells the ball overlaps and only live markers in them,
/// so the cost follows the markers left near the growing front; and the visiting order is
/// fixed, which keeps results bit-identical per seed.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "core/mesh.h"

namespace lobe {

/// Most markers one tree may use (about 40 bytes each): more is refused in one line.
inline constexpr std::size_t kMaxSelfOrgMarkers = 8000000;

class MarkerCloud {
public:
    /// \param points marker positions, metres. \param cell_m the grid's cell side (about half
    /// the usual query radius). \throw InvalidInput when points exceed kMaxSelfOrgMarkers or cell_m ≤ 0.
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

private:
    void cell_of(const glm::vec3& p, int& x, int& y, int& z) const;
    void remove(std::size_t i);
    std::vector<glm::vec3> points_;
    std::vector<std::uint8_t> alive_;
    std::size_t alive_count_ = 0;
    glm::vec3 lo_{0.0f};
    float side_ = 1.0f;
    int nx_ = 0, ny_ = 0, nz_ = 0;
    std::vector<std::uint32_t> cell_start_; ///< CSR: markers of cell c are order_[cell_start_[c] … cell_start_[c+1])
    std::vector<std::uint32_t> cell_live_;  ///< live markers of cell c: the first cell_live_[c] of its slice
    std::vector<std::uint32_t> order_;
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
                const std::uint32_t begin = cell_start_[c], end = begin + cell_live_[c];
                for (std::uint32_t k = begin; k < end; ++k) {
                    const std::uint32_t i = order_[k];
                    const glm::vec3 d = points_[i] - p;
                    if (d.x * d.x + d.y * d.y + d.z * d.z <= r2) visit(static_cast<std::size_t>(i));
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
