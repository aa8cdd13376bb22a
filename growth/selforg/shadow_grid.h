#pragma once
/// \file shadow_grid.h
/// Shadow propagation (Palubicki et al. 2009, §4.1): a voxel grid over the space a tree may
/// grow in. A bud in voxel (I, J, K) adds Δs = a·b^(−q) to every voxel (I±p, J−q, K±p),
/// 0 ≤ p ≤ q ≤ q_max (a pyramid opening downwards); its light is Q = max(C − s + a, 0), where
/// s is the shadow of its voxel (the +a takes its own shadow out), and its optimal direction
/// points to the least shadowed of the 26 neighbouring voxels. Voxel side: one internode.

#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>
#include <glm/ext/vector_int3.hpp>

namespace lobe {

/// Most voxels of one grid (4 bytes each: 128 MiB); a larger grid is refused in one line.
inline constexpr std::size_t kMaxShadowVoxels = std::size_t{32} << 20;

struct ShadowParams {
    double a = 0.1;    ///< shadow a bud casts into its own voxel
    double b = 1.75;   ///< attenuation base, > 1 … or 1 for no attenuation
    int q_max = 6;     ///< pyramid depth in voxels
    double c = 1.0;    ///< full light C
};

class ShadowGrid {
public:
    /// A grid of voxels of side `voxel_m` covering the box [lo, hi] (metres).
    /// \throw InvalidInput when it would hold more than kMaxShadowVoxels voxels, or on a
    /// non-finite box, voxel_m ≤ 0, a < 0, b < 1 or q_max outside [0, 18].
    ShadowGrid(const glm::vec3& lo, const glm::vec3& hi, double voxel_m, const ShadowParams& params);

    /// Adds (sign = +1) or takes away (sign = −1) the shadow pyramid of a bud at `p`.
    /// Points outside the grid cast nothing.
    void cast(const glm::vec3& p, int sign = 1);

    /// Shadow s of the voxel holding `p` (0 outside the grid).
    float shadow(const glm::vec3& p) const;
    /// Light Q = max(C − s + a, 0) at `p`; C outside the grid.
    float light(const glm::vec3& p) const;
    /// Unit direction from `p`'s voxel centre to the least shadowed of its 26 neighbours
    /// within the cone around `axis` (unit) of half-angle with cosine `min_cos` (all 26 when
    /// none lies in it); ties go to the first in z, y, x order. Zero outside the grid.
    glm::vec3 least_shadowed_direction(const glm::vec3& p, const glm::vec3& axis, float min_cos) const;

    glm::ivec3 dims() const { return {nx_, ny_, nz_}; }
    /// Shadow of voxel (x, y, z). \pre inside dims().
    float at(int x, int y, int z) const { return s_[index(x, y, z)]; }
    /// The voxel holding `p`; false outside the grid.
    bool voxel_of(const glm::vec3& p, int& x, int& y, int& z) const;

private:
    std::size_t index(int x, int y, int z) const
    {
        return (static_cast<std::size_t>(z) * static_cast<std::size_t>(ny_) + static_cast<std::size_t>(y)) *
                   static_cast<std::size_t>(nx_) + static_cast<std::size_t>(x);
    }
    glm::vec3 lo_{0.0f};
    float voxel_ = 1.0f;
    int nx_ = 0, ny_ = 0, nz_ = 0;
    ShadowParams params_;
    std::vector<float> delta_; ///< a·b^(−q) for q = 0 … q_max
    std::vector<float> s_;
};

} // namespace lobe
