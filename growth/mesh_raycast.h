#pragma once
/// \file mesh_raycast.h
/// Rays against a closed triangle mesh (a lobe), through a bounding volume hierarchy: every
/// crossing along a ray, inside/outside by parity, and the signed distance along a direction
/// that growth (§5.2) scales subtrees by. Why not CGAL's AABB tree: docs/growth.md, "Ray casting".

#include <limits>
#include <vector>

#include <glm/vec3.hpp>

#include "core/mesh.h"

namespace lobe {

class MeshRaycaster {
public:
    /// Builds the hierarchy over `mesh` (copied). \pre the mesh is closed for inside() and
    /// signed_distance() to be meaningful; an empty mesh answers "outside, no hit".
    explicit MeshRaycaster(const TriangleMesh& mesh);

    /// Distances t > 0 of every crossing of the ray origin + t·dir with the mesh, ascending.
    /// \pre dir is unit length.
    void crossings(const glm::vec3& origin, const glm::vec3& dir, std::vector<float>& out) const;
    /// Nearest crossing with 0 < t < t_max, or a negative number when there is none. A short
    /// t_max (a branch segment) only visits the boxes the segment touches.
    float first_hit(const glm::vec3& origin, const glm::vec3& dir,
                    float t_max = std::numeric_limits<float>::max()) const;
    /// True when `p` is inside the closed mesh (parity of the crossings of a fixed ray).
    bool inside(const glm::vec3& p) const;

    /// Signed distance from `p` to the surface along `dir` (unit):
    /// - inside the lobe: the distance to where the ray leaves it (> 0);
    /// - outside, the ray entering the lobe: the distance to where it leaves it again (> 0),
    ///   so branches that enter a lobe from below keep growing through it;
    /// - outside, the ray missing the lobe: minus the distance from `p` to the nearest vertex.
    /// `inside` (when given) receives whether `p` is inside the lobe.
    float signed_distance_along(const glm::vec3& p, const glm::vec3& dir, bool* inside = nullptr) const;

    const TriangleMesh& mesh() const { return mesh_; }

private:
    struct Node {
        glm::vec3 lo, hi;
        int first = 0; ///< leaf: first triangle in order_; inner: index of the right child (left is next)
        int count = 0; ///< triangles in a leaf; 0 for an inner node
    };
    int build(int begin, int end, std::vector<glm::vec3>& centroids);
    template <typename Visit>
    void traverse(const glm::vec3& origin, const glm::vec3& dir, float t_max, Visit&& visit) const;

    TriangleMesh mesh_;
    std::vector<Node> nodes_;
    std::vector<int> order_;
};

} // namespace lobe
