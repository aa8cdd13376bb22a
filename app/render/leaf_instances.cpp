// A leaf mesh as one instance per leaf quad (app/render/leaf_instances.h).
#include "app/render/leaf_instances.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include <glm/geometric.hpp>

namespace lobe::vk {

bool as_leaf_instances(const SurfaceGeometry& g, std::vector<LeafInstance>& instances, std::array<glm::vec2, 4>& uvs)
{
    const std::size_t n = g.positions.size();
    if (n == 0 || n % 4 != 0 || g.triangles.size() != n / 2 || g.normals.size() != n) return false;
    uvs = {};
    if (!g.uvs.empty()) {
        if (g.uvs.size() != n) return false;
        std::copy(g.uvs.begin(), g.uvs.begin() + 4, uvs.begin());
    }
    instances.clear();
    instances.reserve(n / 4);
    for (std::size_t q = 0; q < n / 4; ++q) {
        const auto f = static_cast<std::uint32_t>(4 * q);
        const std::array<std::uint32_t, 3> first{f, f + 1, f + 2}, second{f, f + 2, f + 3};
        if (g.triangles[2 * q] != first || g.triangles[2 * q + 1] != second) return false;
        const glm::vec3& normal = g.normals[f];
        for (std::uint32_t k = 1; k < 4; ++k)
            if (g.normals[f + k] != normal) return false;
        if (!g.uvs.empty())
            for (std::uint32_t k = 0; k < 4; ++k)
                if (g.uvs[f + k] != uvs[k]) return false;
        const glm::vec3 &p0 = g.positions[f], &p1 = g.positions[f + 1], &p2 = g.positions[f + 2], &p3 = g.positions[f + 3];
        const float edge = std::max(glm::length(p1 - p0), glm::length(p3 - p0));
        float magnitude = 0.0f;
        for (const glm::vec3* p : {&p0, &p1, &p2, &p3})
            magnitude = std::max({magnitude, std::abs(p->x), std::abs(p->y), std::abs(p->z)});
        const float error = glm::length(p1 + (p3 - p0) - p2);
        // Written so that NaN and infinite coordinates fail it.
        if (!(error <= 1e-4f * edge + 8.0f * std::numeric_limits<float>::epsilon() * magnitude)) return false;
        instances.push_back({{p0.x, p0.y, p0.z}, {p1.x, p1.y, p1.z}, {p3.x, p3.y, p3.z}, {normal.x, normal.y, normal.z}});
    }
    return true;
}

} // namespace lobe::vk
