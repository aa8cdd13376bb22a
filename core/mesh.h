#pragma once
/// \file mesh.h
/// A plain indexed triangle mesh: the interchange type between stages (lobes, imported
/// models, exports). Algorithms that need connectivity (OpenMesh, CGAL) convert at their
/// boundary; nothing else sees those libraries.

#include <array>
#include <vector>

#include <glm/vec3.hpp>

namespace lobe {

struct TriangleMesh {
    std::vector<glm::vec3> positions;              ///< #V vertex positions, metres
    std::vector<std::array<int, 3>> triangles;     ///< #F triangles, counter-clockwise seen from outside
    std::vector<std::array<int, 2>> feature_edges; ///< optional: edges that lie on a stroke (remeshing constraints)

    std::size_t vertex_count() const { return positions.size(); }
    std::size_t triangle_count() const { return triangles.size(); }
};

} // namespace lobe
