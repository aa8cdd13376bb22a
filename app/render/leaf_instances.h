#pragma once
/// \file leaf_instances.h
/// Leaf meshes drawn instanced: one shared quad and one instance per leaf
/// (app/render/shaders/leaf.vert; docs/rendering.md, "Leaves, instanced"). Internal to
/// app/render/.

#include <array>
#include <vector>

#include <glm/vec2.hpp>

#include "app/render/gpu_types.h"
#include "growth/tree_geometry.h"

namespace lobe::vk {

/// A leaf mesh as one instance per quad, when it is made of quads as growth/leaves.cpp emits
/// them: vertices 4q … 4q + 3 and triangles 2q = (4q, 4q + 1, 4q + 2) and 2q + 1 =
/// (4q, 4q + 2, 4q + 3) for every quad q, the four vertices of a quad with one normal, every
/// quad with the uvs of the first (or none), and each quad a parallelogram: vertex 2 is
/// 1 + (3 − 0), as leaf.vert makes it, to rounding (1e-4 of the quad's longer edge plus a few
/// float steps of its coordinates; more would move the leaf's corner on screen). Returns false
/// (and `instances` is then meaningless) for any other mesh: it is drawn as a mesh.
bool as_leaf_instances(const SurfaceGeometry& g, std::vector<LeafInstance>& instances, std::array<glm::vec2, 4>& uvs);

} // namespace lobe::vk
