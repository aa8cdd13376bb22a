#include "growth/selforg/shadow_grid.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <glm/geometric.hpp>

#include "core/errors.h"

namespace lobe {

ShadowGrid::ShadowGrid(const glm::vec3& lo, const glm::vec3& hi, double voxel_m, const ShadowParams& params)
    : lo_(lo), voxel_(static_cast<float>(voxel_m)), params_(params)
{
    if (!(voxel_m > 0.0) || !std::isfinite(voxel_m)) throw InvalidInput("self-organizing: voxel side must be > 0");
    if (!(params.a >= 0.0) || !(params.b >= 1.0) || params.q_max < 0 || params.q_max > 18 || !std::isfinite(params.c))
        throw InvalidInput("self-organizing: shadow needs a ≥ 0, b ≥ 1 and q_max in [0, 18]");
    const glm::dvec3 size = glm::dvec3(hi) - glm::dvec3(lo);
    if (!std::isfinite(size.x + size.y + size.z) || size.x < 0.0 || size.y < 0.0 || size.z < 0.0)
        throw InvalidInput("self-organizing: the shadow grid's box is empty or not finite");
    const double nx = std::floor(size.x / voxel_m) + 1.0, ny = std::floor(size.y / voxel_m) + 1.0,
                 nz = std::floor(size.z / voxel_m) + 1.0;
    const double voxels = nx * ny * nz;
    if (!(voxels <= static_cast<double>(kMaxShadowVoxels)))
        throw InvalidInput("self-organizing: a shadow grid of " + std::to_string(static_cast<long long>(std::min(nx, 1e9))) +
                           "x" + std::to_string(static_cast<long long>(std::min(ny, 1e9))) + "x" +
                           std::to_string(static_cast<long long>(std::min(nz, 1e9))) + " voxels exceeds the limit of " +
                           std::to_string(kMaxShadowVoxels) + " (use a longer internode or a smaller envelope)");
    nx_ = static_cast<int>(nx);
    ny_ = static_cast<int>(ny);
    nz_ = static_cast<int>(nz);
    s_.assign(static_cast<std::size_t>(voxels), 0.0f);
    for (int q = 0; q <= params.q_max; ++q) delta_.push_back(static_cast<float>(params.a * std::pow(params.b, -q)));
}

bool ShadowGrid::voxel_of(const glm::vec3& p, int& x, int& y, int& z) const
{
    const glm::vec3 g = (p - lo_) / voxel_;
    if (!(g.x >= 0.0f && g.y >= 0.0f && g.z >= 0.0f)) return false;
    if (!(g.x < static_cast<float>(nx_) && g.y < static_cast<float>(ny_) && g.z < static_cast<float>(nz_))) return false;
    x = std::min(static_cast<int>(g.x), nx_ - 1);
    y = std::min(static_cast<int>(g.y), ny_ - 1);
    z = std::min(static_cast<int>(g.z), nz_ - 1);
    return true;
}

void ShadowGrid::cast(const glm::vec3& p, int sign)
{
    int i, j, k;
    if (!voxel_of(p, i, j, k)) return;
    for (int q = 0; q <= params_.q_max && j - q >= 0; ++q) {
        const float d = sign > 0 ? delta_[static_cast<std::size_t>(q)] : -delta_[static_cast<std::size_t>(q)];
        const int y = j - q;
        const int x0 = std::max(i - q, 0), x1 = std::min(i + q, nx_ - 1);
        const int z0 = std::max(k - q, 0), z1 = std::min(k + q, nz_ - 1);
        for (int z = z0; z <= z1; ++z) {
            float* row = s_.data() + index(0, y, z);
            for (int x = x0; x <= x1; ++x) row[x] += d;
        }
    }
}

float ShadowGrid::shadow(const glm::vec3& p) const
{
    int x, y, z;
    return voxel_of(p, x, y, z) ? s_[index(x, y, z)] : 0.0f;
}

float ShadowGrid::light(const glm::vec3& p) const
{
    return std::max(static_cast<float>(params_.c) - shadow(p) + static_cast<float>(params_.a), 0.0f);
}

glm::vec3 ShadowGrid::least_shadowed_direction(const glm::vec3& p, const glm::vec3& axis, float min_cos) const
{
    int i, j, k;
    if (!voxel_of(p, i, j, k)) return glm::vec3(0.0f);
    glm::vec3 best_in(0.0f), best_any(0.0f);
    float s_in = std::numeric_limits<float>::max(), s_any = std::numeric_limits<float>::max();
    for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                if (dx == 0 && dy == 0 && dz == 0) continue;
                const int x = i + dx, y = j + dy, z = k + dz;
                // Outside the grid nothing casts shadow: such a neighbour is fully lit.
                const bool in = x >= 0 && y >= 0 && z >= 0 && x < nx_ && y < ny_ && z < nz_;
                const float s = in ? s_[index(x, y, z)] : 0.0f;
                const glm::vec3 d = glm::normalize(glm::vec3(static_cast<float>(dx), static_cast<float>(dy),
                                                             static_cast<float>(dz)));
                if (s < s_any) {
                    s_any = s;
                    best_any = d;
                }
                if (glm::dot(d, axis) >= min_cos && s < s_in) {
                    s_in = s;
                    best_in = d;
                }
            }
    return s_in < std::numeric_limits<float>::max() ? best_in : best_any;
}

} // namespace lobe
