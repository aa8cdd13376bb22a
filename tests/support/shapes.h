#pragma once
/// \file shapes.h
/// Small generated shapes for the tests and benchmarks: closed triangle meshes with exact
/// counts, ellipsoidal lobe surfaces, evenly spread directions, and raw lobe strokes as a
/// hand draws them. Every function is deterministic: the same arguments give the same bytes.

#include <functional>
#include <vector>

#include <glm/vec3.hpp>

#include "core/mesh.h"
#include "input/truth_surface.h"

namespace lobe::test {

/// Radius of a sphere-like surface along a unit direction, metres.
using RadiusOfDirection = std::function<double(const glm::dvec3& unit_dir)>;

// ---- Closed meshes (outward oriented, closed, 2-manifold) ----------------------------------

/// Icosphere: the icosahedron (12 vertices, 20 triangles) after `levels` rounds of 4-to-1
/// midpoint subdivision, its vertices pushed out to `radius` around `centre`:
/// 10·4^levels + 2 vertices, 20·4^levels triangles. Vertices 0–11 are the icosahedron's;
/// each round appends its edge midpoints in the order the triangles meet them.
/// \pre levels ≥ 0, radius > 0.
TriangleMesh icosphere(int levels, double radius, glm::dvec3 centre = glm::dvec3(0.0));
/// The same icosphere with the radius given per unit direction (a bumpy, star-shaped lobe):
/// vertex = centre + radius(u)·u.
TriangleMesh icosphere(int levels, const RadiusOfDirection& radius, glm::dvec3 centre = glm::dvec3(0.0));

/// Geodesic sphere: each icosahedron face split into frequency² triangles on a regular grid,
/// projected out to `radius` around `centre`: 10·frequency² + 2 vertices, 20·frequency²
/// triangles (frequency 22: 4,842 vertices). Its edges are more even than an icosphere's.
/// \pre frequency ≥ 1, radius > 0.
TriangleMesh geodesic_sphere(int frequency, glm::dvec3 centre, double radius);
/// The same geodesic sphere with the radius given per unit direction: vertex = centre + radius(u)·u.
TriangleMesh geodesic_sphere(int frequency, glm::dvec3 centre, const RadiusOfDirection& radius);

/// UV sphere of `radius` around the origin, poles on ±Y: `rings` latitude bands and `segments`
/// longitudes, (rings − 1)·segments + 2 vertices and 2·(rings − 1)·segments triangles.
/// Vertex 0 is the north pole, the last the south pole. With `rings` even the equator is a
/// loop of mesh edges: its `segments` vertex indices go to `equator`, and its edges are the
/// mesh's feature edges (a stroke the remeshing keeps).
/// \pre rings ≥ 2 and even, segments ≥ 3, radius > 0.
TriangleMesh uv_sphere(int rings, int segments, double radius, std::vector<int>& equator);

/// Octahedron of circumradius `radius` around `centre`: 6 vertices (+X, −X, +Y, −Y, +Z, −Z
/// in that order), 8 triangles.
TriangleMesh octahedron(glm::vec3 centre, float radius);

// ---- Ellipsoidal lobes ---------------------------------------------------------------------

/// An axis-aligned ellipsoid with semi-axes `radii` (metres) around `centre`, no dents, as a
/// ground-truth lobe surface (input/truth_surface.h).
TruthSurface ellipsoid_surface(glm::dvec3 centre, glm::dvec3 radii);
/// That ellipsoid meshed by truth_surface_mesh: an icosphere `subdivisions` times subdivided
/// (10·4^subdivisions + 2 vertices, 20·4^subdivisions triangles; 3: 642 and 1,280).
/// \pre 0 ≤ subdivisions ≤ 7.
TriangleMesh ellipsoid(glm::dvec3 centre, glm::dvec3 radii, int subdivisions = 3);

// ---- Directions and strokes ----------------------------------------------------------------

/// `n` unit vectors spread evenly over the sphere (a Fibonacci lattice), from near +Z to near −Z.
std::vector<glm::dvec3> sphere_directions(int n);

/// A closed lobe stroke as the input pipeline leaves it: ⌊2π·radius / 5 mm⌋ points about 5 mm
/// apart (its minimum point spacing) round the circle of radius `radius` about `centre` in the
/// plane of the orthonormal `u`, `v`, starting near centre + radius·u, with 1 mm of wobble
/// (radius + 1 mm · sin(7t + seed) at angle t).
/// \pre radius > 0.
std::vector<glm::vec3> raw_loop(const glm::dvec3& centre, const glm::dvec3& u, const glm::dvec3& v, double radius,
                                int seed);

/// The ten strokes of a lobe as a person sketches one: a sphere of radius 20 cm about (0, 1.4, −0.45)
/// drawn as six raw loops through its centre at 30° steps of longitude, then four stacked
/// rings at heights −15, −8, +8 and +15 cm.
std::vector<std::vector<glm::vec3>> ten_stroke_lobe();

} // namespace lobe::test
