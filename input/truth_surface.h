#pragma once
/// \file truth_surface.h
/// Ground-truth lobe surfaces of synthetic scenarios: star-shaped surfaces around a centre
/// (an ellipsoid pushed in by Gaussian dents), their plane sections (the "section" stroke
/// generator) and a triangle mesh of each, for tests that compare a lobe mesh with the
/// surface the strokes were drawn on. No CGAL, no OpenMesh: plain data and free functions.
/// JSON form: docs/scenario-format.md, "Lobe surfaces".

#include <array>
#include <functional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>
#include <nlohmann/json_fwd.hpp>

#include "core/mesh.h"

namespace lobe {

/// A Gaussian push towards the centre: depth · exp(−(angle(u, direction) / width)²).
/// Kept in the units of the JSON form, so a surface written and read back is bit-identical.
struct SurfaceDent {
    glm::dvec3 direction{1.0, 0.0, 0.0}; ///< unit, world frame
    double depth_mm = 0.0;               ///< millimetres
    double width_deg = 60.0;             ///< angular width: the angle at which the push falls to 1/e
};

/// A star-shaped lobe surface: every ray from `center` meets it once, at radius(u).
struct TruthSurface {
    glm::dvec3 center{0.0};
    glm::dvec3 radii{0.1};                  ///< ellipsoid semi-axes a, b, c along axes[0..2], metres
    std::array<glm::dvec3, 3> axes = {glm::dvec3(1, 0, 0), glm::dvec3(0, 1, 0), glm::dvec3(0, 0, 1)};
                                            ///< orthonormal, right-handed ellipsoid frame
    std::vector<SurfaceDent> dents;
};

/// Limits of the JSON form (docs/scenario-format.md).
inline constexpr double kMinSurfaceRadius = 0.02;  ///< metres
inline constexpr double kMaxSurfaceRadius = 2.0;   ///< metres
inline constexpr std::size_t kMaxSurfaceDents = 8;
inline constexpr double kMinDentWidthDeg = 5.0;
inline constexpr double kMaxDentWidthDeg = 90.0;
inline constexpr double kMinDentedRadiusFraction = 0.3; ///< dents leave r ≥ 30 % of the ellipsoid radius
inline constexpr int kMaxSurfaceMeshSubdivisions = 7;

/// Radius of the plain ellipsoid along the unit direction `u`: 1 / sqrt(Σ (u·axisᵢ / aᵢ)²).
double ellipsoid_radius(const TruthSurface& s, const glm::dvec3& unit_dir);
/// r(u) = ellipsoid_radius(u) − Σ depth · exp(−(angle(u, dir) / width)²), metres.
/// \pre `unit_dir` has length 1.
double radius(const TruthSurface& s, const glm::dvec3& unit_dir);
/// The surface point along `unit_dir`: center + r(u) · u.
glm::dvec3 point(const TruthSurface& s, const glm::dvec3& unit_dir);
/// Outward unit normal of the surface at point(s, unit_dir) (central differences of point()).
glm::dvec3 normal(const TruthSurface& s, const glm::dvec3& unit_dir);
/// Signed radial gap of `p`: |p − center| − r(direction of p), positive outside. Its absolute
/// value bounds the distance from `p` to the surface from above (the surface point on the
/// same ray is one point of the surface).
double radial_gap(const TruthSurface& s, const glm::dvec3& p);
/// `p` moved along its ray from the centre onto the surface.
/// \throw InvalidInput when `p` is the centre (it has no ray).
glm::dvec3 project_radially(const TruthSurface& s, const glm::dvec3& p);

/// Checks a surface built in code as the JSON reader does: finite centre, radii 0.02–2 m,
/// orthonormal right-handed axes, at most 8 dents with unit directions, depth ≥ 0, width
/// 5–90°, and r ≥ 30 % of the ellipsoid radius in every direction.
/// \throw InvalidInput starting with `field` (for example "surfaces[1].dents[0].depth_mm").
void validate_truth_surface(const TruthSurface& s, const std::string& field);

/// One surface from its JSON object {"center", "radii", "axes"?, "dents"?} (unknown fields
/// are errors; "comment" is allowed). The axes are orthonormalised (Gram–Schmidt, the third
/// is their cross product) and dent directions normalised.
/// \throw InvalidInput naming the field, one line.
TruthSurface truth_surface_from_json(const nlohmann::json& j, const std::string& field);
/// The normalised JSON object of a surface (reads back to the same surface).
nlohmann::json truth_surface_to_json(const TruthSurface& s);
/// The "surfaces" array of a scenario or of a ground-truth file (empty when it has none).
/// \throw InvalidInput naming the field ("surfaces[2].radii"), one line.
std::vector<TruthSurface> truth_surfaces_from_json(const nlohmann::json& truth_or_scenario);

/// An icosphere subdivided `subdivisions` times (0 = the icosahedron: 12 vertices, 20
/// triangles; each level ×4 triangles), its vertices moved radially onto the surface.
/// Closed, 2-manifold, triangles counter-clockwise seen from outside.
/// \pre 0 ≤ subdivisions ≤ 7 (327,680 triangles). \throw InvalidInput otherwise.
TriangleMesh truth_surface_mesh(const TruthSurface& s, int subdivisions);

/// A plane section of a surface, as the "section" stroke generator draws it.
///
/// The plane has unit normal `n` and passes through center + offset_m · n. Azimuth φ is
/// measured in the plane from `u` towards `v = n × u`, where `u` is world +X projected into
/// the plane, or −Z when n is (nearly) along X (as for the "ellipse" generator). For each φ
/// the point is the surface point on the meridian half-plane spanned by n and
/// w(φ) = cos φ u + sin φ v that lies in the plane: with offset 0 simply point(s, w(φ)).
struct SurfaceSection {
    glm::dvec3 plane_normal{0.0, 1.0, 0.0};
    double offset_m = 0.0;
    double start_angle_deg = 0.0;
    double sweep_deg = 360.0;  ///< (0, 360]; 360 is the whole closed loop
    int direction = 1;         ///< +1 counter-clockwise about the normal, −1 clockwise
    double step_deg = 2.0;     ///< control point spacing in azimuth
};

/// The in-plane frame (u, v) of a section's azimuth (see SurfaceSection).
/// \pre `plane_normal` has length 1.
std::array<glm::dvec3, 2> section_frame(const glm::dvec3& plane_normal);

/// Optional displacement across the curve, in metres, as a function of the azimuth φ
/// (radians): the point slides along the surface's meridian by about that much (elevation
/// changed by across(φ) / distance from the centre), so it stays exactly on the surface.
using SectionAcross = std::function<double(double azimuth_rad)>;

/// Points of the section every `step_deg` of azimuth from start_angle_deg along `direction`
/// (a full loop does not repeat its first point; an arc ends exactly at start + sweep). Every
/// point lies on the surface (radial_gap ≈ 1e-12 m). With a nonzero offset the elevation on
/// each meridian is a bracketed root of (height above the centre − offset), refined by
/// bisection.
/// \throw InvalidInput starting with `field` when the plane misses the surface, only grazes
/// it (a loop less than 1 cm across from its axis), or cuts some meridian more than once (the
/// section is not a single loop around the plane's axis), or when the parameters are out of
/// range (zero normal, sweep outside (0, 360], step outside [0.25, 15]°, direction not ±1).
std::vector<glm::dvec3> section_points(const TruthSurface& s, const SurfaceSection& section,
                                       const std::string& field, const SectionAcross& across = {});

} // namespace lobe
