#include "input/truth_surface.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <locale>
#include <map>
#include <sstream>
#include <utility>

#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include "core/errors.h"

namespace lobe {

namespace {

using json = nlohmann::json;
using dvec3 = glm::dvec3;

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180.0;
constexpr double kMaxCenterCoordinate = 10.0; // metres, as for every scenario coordinate
constexpr double kUnitTolerance = 1e-9;

std::string num(double v)
{
    std::ostringstream os;
    os.imbue(std::locale::classic());
    os.precision(6);
    os << v;
    return os.str();
}

std::string vec_text(const dvec3& v)
{
    std::ostringstream os;
    os.imbue(std::locale::classic());
    os.precision(4);
    os << '(' << v.x << ", " << v.y << ", " << v.z << ')';
    return os.str();
}

[[noreturn]] void fail(const std::string& field, const std::string& what) { throw InvalidInput(field + ": " + what); }

/// Angle between two unit vectors, accurate near 0 and π (unlike acos of the dot product).
double angle_between(const dvec3& a, const dvec3& b)
{
    return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
}

/// `v` scaled to length 1, left bit-identical when it already is (so normalised JSON reads
/// back to the same numbers).
dvec3 unit_or_same(const dvec3& v)
{
    const double len = glm::length(v);
    if (std::abs(len - 1.0) <= 1e-15) return v;
    return v / len;
}

/// Any unit vector perpendicular to the unit vector `u`.
dvec3 any_perpendicular(const dvec3& u)
{
    const dvec3 ref = std::abs(u.x) < 0.6 ? dvec3(1.0, 0.0, 0.0) : dvec3(0.0, 1.0, 0.0);
    return glm::normalize(ref - glm::dot(ref, u) * u);
}

// ---------------------------------------------------------------------------------------
// JSON helpers (the scenario reader's conventions: a "comment" is allowed everywhere,
// anything else unknown is an error)
// ---------------------------------------------------------------------------------------

void allow_only(const json& obj, const std::string& field, std::initializer_list<const char*> keys)
{
    for (auto it = obj.begin(); it != obj.end(); ++it) {
        bool known = it.key() == "comment";
        for (const char* k : keys) known = known || it.key() == k;
        if (!known) fail(field, "unknown field '" + it.key() + "'");
    }
}

dvec3 parse_vec3(const json& v, const std::string& field)
{
    if (!v.is_array() || v.size() != 3) fail(field, "expected [x, y, z]");
    dvec3 p;
    for (int a = 0; a < 3; ++a) {
        const json& c = v[static_cast<std::size_t>(a)];
        if (!c.is_number()) fail(field, "expected [x, y, z] numbers");
        p[a] = c.get<double>();
        if (!std::isfinite(p[a])) fail(field, "coordinate is not finite");
    }
    return p;
}

double required_number(const json& obj, const char* key, const std::string& field)
{
    auto it = obj.find(key);
    if (it == obj.end()) fail(field, std::string("missing '") + key + "'");
    if (!it->is_number()) fail(field + "." + key, "expected a number");
    const double v = it->get<double>();
    if (!std::isfinite(v)) fail(field + "." + key, "expected a finite number");
    return v;
}

/// Directions spread evenly over the sphere (a Fibonacci lattice).
std::vector<dvec3> sphere_samples(std::size_t n)
{
    std::vector<dvec3> out;
    out.reserve(n);
    const double golden = kPi * (3.0 - std::sqrt(5.0));
    for (std::size_t i = 0; i < n; ++i) {
        const double z = 1.0 - (2.0 * static_cast<double>(i) + 1.0) / static_cast<double>(n);
        const double rho = std::sqrt(std::max(0.0, 1.0 - z * z));
        const double phi = golden * static_cast<double>(i);
        out.emplace_back(rho * std::cos(phi), rho * std::sin(phi), z);
    }
    return out;
}

/// The smallest r(u) / ellipsoid_radius(u) over all directions and where it is: the best
/// of 20,000 even samples and the dent centres, refined by a shrinking pattern search.
std::pair<double, dvec3> smallest_radius_fraction(const TruthSurface& s)
{
    auto fraction = [&](const dvec3& u) { return radius(s, u) / ellipsoid_radius(s, u); };
    std::vector<dvec3> candidates = sphere_samples(20000);
    for (const SurfaceDent& d : s.dents) candidates.push_back(d.direction);
    dvec3 best = candidates.front();
    double best_f = fraction(best);
    for (const dvec3& u : candidates) {
        const double f = fraction(u);
        if (f < best_f) {
            best_f = f;
            best = u;
        }
    }
    double step = 2.0 * kDeg;
    while (step > 1e-4 * kDeg) {
        const dvec3 t1 = any_perpendicular(best);
        const dvec3 t2 = glm::cross(best, t1);
        bool moved = false;
        for (const dvec3& t : {t1, -t1, t2, -t2}) {
            const dvec3 u = glm::normalize(best * std::cos(step) + t * std::sin(step));
            const double f = fraction(u);
            if (f < best_f) {
                best_f = f;
                best = u;
                moved = true;
            }
        }
        if (!moved) step *= 0.5;
    }
    return {best_f, best};
}

} // namespace

// ---------------------------------------------------------------------------------------
// The radial function
// ---------------------------------------------------------------------------------------

double ellipsoid_radius(const TruthSurface& s, const glm::dvec3& unit_dir)
{
    double q = 0.0;
    for (int i = 0; i < 3; ++i) {
        const double c = glm::dot(unit_dir, s.axes[static_cast<std::size_t>(i)]) / s.radii[i];
        q += c * c;
    }
    return 1.0 / std::sqrt(q);
}

double radius(const TruthSurface& s, const glm::dvec3& unit_dir)
{
    double r = ellipsoid_radius(s, unit_dir);
    for (const SurfaceDent& d : s.dents) {
        const double x = angle_between(unit_dir, d.direction) / (d.width_deg * kDeg);
        r -= 0.001 * d.depth_mm * std::exp(-x * x);
    }
    return r;
}

glm::dvec3 point(const TruthSurface& s, const glm::dvec3& unit_dir) { return s.center + radius(s, unit_dir) * unit_dir; }

glm::dvec3 normal(const TruthSurface& s, const glm::dvec3& unit_dir)
{
    const dvec3 t1 = any_perpendicular(unit_dir);
    const dvec3 t2 = glm::cross(unit_dir, t1);
    const double h = 1e-5; // radians
    auto at = [&](const dvec3& t, double sign) {
        return point(s, glm::normalize(unit_dir * std::cos(h) + t * (sign * std::sin(h))));
    };
    dvec3 n = glm::cross(at(t1, 1.0) - at(t1, -1.0), at(t2, 1.0) - at(t2, -1.0));
    if (glm::dot(n, unit_dir) < 0.0) n = -n;
    return glm::normalize(n);
}

double radial_gap(const TruthSurface& s, const glm::dvec3& p)
{
    const dvec3 d = p - s.center;
    const double len = glm::length(d);
    if (len == 0.0) return -radius(s, s.axes[0]);
    return len - radius(s, d / len);
}

glm::dvec3 project_radially(const TruthSurface& s, const glm::dvec3& p)
{
    const dvec3 d = p - s.center;
    const double len = glm::length(d);
    if (!(len > 0.0)) throw InvalidInput("project_radially: the point is the surface's centre");
    return point(s, d / len);
}

// ---------------------------------------------------------------------------------------
// Validation and JSON
// ---------------------------------------------------------------------------------------

void validate_truth_surface(const TruthSurface& s, const std::string& field)
{
    for (int a = 0; a < 3; ++a) {
        if (!std::isfinite(s.center[a])) fail(field + ".center", "coordinate is not finite");
        if (std::abs(s.center[a]) > kMaxCenterCoordinate)
            fail(field + ".center", "coordinate " + num(s.center[a]) + " m is beyond " + num(kMaxCenterCoordinate) + " m");
    }
    for (int a = 0; a < 3; ++a)
        if (!(s.radii[a] >= kMinSurfaceRadius && s.radii[a] <= kMaxSurfaceRadius))
            fail(field + ".radii", num(s.radii[a]) + " m is outside [" + num(kMinSurfaceRadius) + ", " +
                                       num(kMaxSurfaceRadius) + "]");
    for (std::size_t i = 0; i < 3; ++i)
        if (!(std::abs(glm::length(s.axes[i]) - 1.0) <= kUnitTolerance))
            fail(field + ".axes", "axis " + std::to_string(i) + " is not a unit vector");
    if (!(std::abs(glm::dot(s.axes[0], s.axes[1])) <= kUnitTolerance &&
          std::abs(glm::dot(s.axes[0], s.axes[2])) <= kUnitTolerance &&
          std::abs(glm::dot(s.axes[1], s.axes[2])) <= kUnitTolerance))
        fail(field + ".axes", "the axes are not orthogonal");
    if (!(glm::dot(glm::cross(s.axes[0], s.axes[1]), s.axes[2]) > 0.0))
        fail(field + ".axes", "the axes are not right-handed");
    if (s.dents.size() > kMaxSurfaceDents)
        fail(field + ".dents", std::to_string(s.dents.size()) + " dents exceed the limit of " +
                                   std::to_string(kMaxSurfaceDents));
    for (std::size_t k = 0; k < s.dents.size(); ++k) {
        const SurfaceDent& d = s.dents[k];
        const std::string f = field + ".dents[" + std::to_string(k) + "]";
        if (!(std::abs(glm::length(d.direction) - 1.0) <= kUnitTolerance))
            fail(f + ".direction", "is not a unit vector");
        if (!(d.depth_mm >= 0.0 && d.depth_mm <= kMaxSurfaceRadius * 1000.0))
            fail(f + ".depth_mm", num(d.depth_mm) + " mm is outside [0, " + num(kMaxSurfaceRadius * 1000.0) + "]");
        if (!(d.width_deg >= kMinDentWidthDeg && d.width_deg <= kMaxDentWidthDeg))
            fail(f + ".width_deg", num(d.width_deg) + "° is outside [" + num(kMinDentWidthDeg) + ", " +
                                       num(kMaxDentWidthDeg) + "]");
    }
    if (!s.dents.empty()) {
        const auto [fraction, where] = smallest_radius_fraction(s);
        if (fraction < kMinDentedRadiusFraction)
            fail(field + ".dents", "the dents leave " + num(100.0 * fraction) + " % of the ellipsoid radius towards " +
                                       vec_text(where) + "; at least " + num(100.0 * kMinDentedRadiusFraction) +
                                       " % must remain");
    }
}

TruthSurface truth_surface_from_json(const nlohmann::json& j, const std::string& field)
{
    if (!j.is_object()) fail(field, "expected an object {center, radii, axes, dents}");
    allow_only(j, field, {"center", "radii", "axes", "dents"});
    TruthSurface s;
    auto cit = j.find("center");
    if (cit == j.end()) fail(field, "missing 'center'");
    s.center = parse_vec3(*cit, field + ".center");
    auto rit = j.find("radii");
    if (rit == j.end()) fail(field, "missing 'radii'");
    s.radii = parse_vec3(*rit, field + ".radii");
    if (j.contains("axes")) {
        const json& ax = j["axes"];
        const std::string f = field + ".axes";
        if (!ax.is_array() || ax.size() != 2) fail(f, "expected the first two axes [[x, y, z], [x, y, z]]");
        const dvec3 a0 = parse_vec3(ax[0], f + "[0]");
        const dvec3 a1 = parse_vec3(ax[1], f + "[1]");
        if (!(glm::length(a0) > 1e-9)) fail(f + "[0]", "must not be zero");
        if (!(glm::length(a1) > 1e-9)) fail(f + "[1]", "must not be zero");
        const dvec3 e0 = unit_or_same(a0);
        dvec3 e1 = a1 / glm::length(a1);
        if (!(glm::length(glm::cross(e0, e1)) > 1e-3)) fail(f, "the two axes are parallel");
        if (std::abs(glm::dot(e0, a1)) > 1e-15 || std::abs(glm::length(a1) - 1.0) > 1e-15)
            e1 = glm::normalize(a1 - glm::dot(a1, e0) * e0);
        else
            e1 = a1;
        s.axes = {e0, e1, glm::cross(e0, e1)};
    }
    if (j.contains("dents")) {
        const json& d = j["dents"];
        if (!d.is_array()) fail(field + ".dents", "expected an array of {direction, depth_mm, width_deg}");
        if (d.size() > kMaxSurfaceDents)
            fail(field + ".dents", std::to_string(d.size()) + " dents exceed the limit of " + std::to_string(kMaxSurfaceDents));
        for (std::size_t k = 0; k < d.size(); ++k) {
            const std::string f = field + ".dents[" + std::to_string(k) + "]";
            if (!d[k].is_object()) fail(f, "expected {direction, depth_mm, width_deg}");
            allow_only(d[k], f, {"direction", "depth_mm", "width_deg"});
            SurfaceDent dent;
            auto dit = d[k].find("direction");
            if (dit == d[k].end()) fail(f, "missing 'direction'");
            const dvec3 dir = parse_vec3(*dit, f + ".direction");
            if (!(glm::length(dir) > 1e-9)) fail(f + ".direction", "must not be zero");
            dent.direction = unit_or_same(dir);
            const double depth_mm = required_number(d[k], "depth_mm", f);
            if (!(depth_mm >= 0.0 && depth_mm <= kMaxSurfaceRadius * 1000.0))
                fail(f + ".depth_mm", num(depth_mm) + " mm is outside [0, " + num(kMaxSurfaceRadius * 1000.0) + "]");
            dent.depth_mm = depth_mm;
            double width_deg = 60.0;
            if (d[k].contains("width_deg")) width_deg = required_number(d[k], "width_deg", f);
            if (!(width_deg >= kMinDentWidthDeg && width_deg <= kMaxDentWidthDeg))
                fail(f + ".width_deg", num(width_deg) + "° is outside [" + num(kMinDentWidthDeg) + ", " +
                                           num(kMaxDentWidthDeg) + "]");
            dent.width_deg = width_deg;
            s.dents.push_back(dent);
        }
    }
    validate_truth_surface(s, field);
    return s;
}

nlohmann::json truth_surface_to_json(const TruthSurface& s)
{
    auto arr = [](const dvec3& v) { return json::array({v.x, v.y, v.z}); };
    json j = {{"center", arr(s.center)},
              {"radii", arr(s.radii)},
              {"axes", json::array({arr(s.axes[0]), arr(s.axes[1])})}};
    if (!s.dents.empty()) {
        json dents = json::array();
        for (const SurfaceDent& d : s.dents)
            dents.push_back({{"direction", arr(d.direction)},
                             {"depth_mm", d.depth_mm},
                             {"width_deg", d.width_deg}});
        j["dents"] = std::move(dents);
    }
    return j;
}

std::vector<TruthSurface> truth_surfaces_from_json(const nlohmann::json& truth_or_scenario)
{
    std::vector<TruthSurface> out;
    if (!truth_or_scenario.is_object()) fail("surfaces", "the document is not a JSON object");
    auto it = truth_or_scenario.find("surfaces");
    if (it == truth_or_scenario.end()) return out;
    if (!it->is_array()) fail("surfaces", "expected an array of surfaces");
    if (it->size() > 1000) fail("surfaces", std::to_string(it->size()) + " surfaces exceed the limit of 1000");
    out.reserve(it->size());
    for (std::size_t i = 0; i < it->size(); ++i)
        out.push_back(truth_surface_from_json((*it)[i], "surfaces[" + std::to_string(i) + "]"));
    return out;
}

// ---------------------------------------------------------------------------------------
// Mesh
// ---------------------------------------------------------------------------------------

TriangleMesh truth_surface_mesh(const TruthSurface& s, int subdivisions)
{
    if (subdivisions < 0 || subdivisions > kMaxSurfaceMeshSubdivisions)
        throw InvalidInput("truth_surface_mesh: subdivisions must be 0–" + std::to_string(kMaxSurfaceMeshSubdivisions) +
                           ", got " + std::to_string(subdivisions));
    validate_truth_surface(s, "truth_surface_mesh");
    // The regular icosahedron, faces counter-clockwise seen from outside.
    const double t = (1.0 + std::sqrt(5.0)) / 2.0;
    std::vector<dvec3> v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                            {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
    for (dvec3& p : v) p = glm::normalize(p);
    std::vector<std::array<int, 3>> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                         {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                         {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                         {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
    for (int level = 0; level < subdivisions; ++level) {
        std::map<std::pair<int, int>, int> midpoint;
        auto mid = [&](int a, int b) {
            const std::pair<int, int> key = a < b ? std::make_pair(a, b) : std::make_pair(b, a);
            auto it = midpoint.find(key);
            if (it != midpoint.end()) return it->second;
            const int id = static_cast<int>(v.size());
            v.push_back(glm::normalize(v[static_cast<std::size_t>(a)] + v[static_cast<std::size_t>(b)]));
            midpoint.emplace(key, id);
            return id;
        };
        std::vector<std::array<int, 3>> next;
        next.reserve(f.size() * 4);
        for (const auto& tri : f) {
            const int ab = mid(tri[0], tri[1]), bc = mid(tri[1], tri[2]), ca = mid(tri[2], tri[0]);
            next.push_back({tri[0], ab, ca});
            next.push_back({tri[1], bc, ab});
            next.push_back({tri[2], ca, bc});
            next.push_back({ab, bc, ca});
        }
        f = std::move(next);
    }
    TriangleMesh mesh;
    mesh.positions.reserve(v.size());
    for (const dvec3& u : v) mesh.positions.push_back(glm::vec3(point(s, u)));
    mesh.triangles = std::move(f);
    return mesh;
}

// ---------------------------------------------------------------------------------------
// Plane sections
// ---------------------------------------------------------------------------------------

std::array<glm::dvec3, 2> section_frame(const glm::dvec3& plane_normal)
{
    const dvec3 n = plane_normal;
    const dvec3 ref = std::abs(n.x) < 0.9 ? dvec3(1.0, 0.0, 0.0) : dvec3(0.0, 0.0, -1.0);
    const dvec3 u = glm::normalize(ref - glm::dot(ref, n) * n);
    return {u, glm::cross(n, u)};
}

std::vector<glm::dvec3> section_points(const TruthSurface& s, const SurfaceSection& section, const std::string& field,
                                       const SectionAcross& across)
{
    const double nlen = glm::length(section.plane_normal);
    if (!(nlen > 1e-9) || !std::isfinite(nlen)) fail(field + ".normal", "must be a finite nonzero vector");
    if (!std::isfinite(section.offset_m)) fail(field + ".offset_m", "expected a finite number");
    if (!(std::abs(section.start_angle_deg) <= 3600.0))
        fail(field + ".start_angle_deg", "expected a finite angle within ±3600°");
    if (!(section.sweep_deg > 0.0 && section.sweep_deg <= 360.0))
        fail(field + ".sweep_deg", num(section.sweep_deg) + "° is outside (0, 360]");
    if (section.direction != 1 && section.direction != -1) fail(field + ".direction", "expected +1 or -1");
    if (!(section.step_deg >= 0.25 && section.step_deg <= 15.0))
        fail(field, "control point step " + num(section.step_deg) + "° is outside [0.25, 15]");

    const dvec3 n = section.plane_normal / nlen;
    const std::array<dvec3, 2> frame = section_frame(n);
    const dvec3 u = frame[0], v = frame[1];
    const double d = section.offset_m;
    auto azimuth_dir = [&](double phi) { return std::cos(phi) * u + std::sin(phi) * v; };
    auto meridian_dir = [&](const dvec3& w, double theta) { return std::cos(theta) * w + std::sin(theta) * n; };

    // Elevation of the section on the meridian of azimuth φ: the root of
    // g(θ) = r(m(θ)) sin θ − d on [−90°, 90°], bracketed on a 0.25° grid and refined by
    // bisection. One sign change means the plane crosses this meridian once.
    constexpr int kElevationSamples = 720;
    auto height = [&](const dvec3& w, double theta) { return radius(s, meridian_dir(w, theta)) * std::sin(theta); };
    struct Crossing {
        int count = 0;
        double lo = 0.0, hi = 0.0; ///< the bracket of the last one
    };
    auto crossings = [&](double phi) {
        const dvec3 w = azimuth_dir(phi);
        Crossing c;
        double th_prev = -0.5 * kPi;
        bool below_prev = height(w, th_prev) - d < 0.0;
        for (int k = 1; k <= kElevationSamples; ++k) {
            const double th = -0.5 * kPi + kPi * static_cast<double>(k) / kElevationSamples;
            const bool below = height(w, th) - d < 0.0;
            if (below != below_prev) {
                ++c.count;
                c.lo = th_prev;
                c.hi = th;
            }
            th_prev = th;
            below_prev = below;
        }
        return c;
    };
    auto plane_text = [&] { return "the plane at " + num(d) + " m"; };
    auto elevation = [&](double phi) {
        if (d == 0.0) return 0.0; // a plane through the centre of a star-shaped surface
        const Crossing c = crossings(phi);
        if (c.count != 1)
            fail(field + ".offset_m", plane_text() + " crosses the meridian at azimuth " +
                                          num(std::remainder(phi / kDeg, 360.0)) + "° " + std::to_string(c.count) +
                                          " times: the section is not a single loop");
        double lo = c.lo, hi = c.hi;
        const dvec3 w = azimuth_dir(phi);
        const bool rising = height(w, lo) - d < 0.0;
        for (int it = 0; it < 200 && hi - lo > 1e-15; ++it) {
            const double mid = 0.5 * (lo + hi);
            if ((height(w, mid) - d < 0.0) == rising) lo = mid;
            else hi = mid;
        }
        return 0.5 * (lo + hi);
    };

    if (d != 0.0) {
        // The whole loop every 2°: the plane must meet the surface, cross every meridian once
        // and not merely graze it.
        int missed = 0;
        for (int k = 0; k < 180; ++k) missed += crossings(2.0 * k * kDeg).count == 0;
        if (missed == 180)
            fail(field + ".offset_m", plane_text() + " misses the surface (it spans " + num(-radius(s, -n)) + " to " +
                                          num(radius(s, n)) + " m along the normal)");
        for (int k = 0; k < 180; ++k) {
            const double phi = 2.0 * k * kDeg;
            const double th = elevation(phi);
            const double in_plane = radius(s, meridian_dir(azimuth_dir(phi), th)) * std::cos(th);
            if (in_plane < 0.005)
                fail(field + ".offset_m", plane_text() + " only grazes the surface (the loop is " +
                                              num(2000.0 * in_plane) + " mm across at azimuth " + num(2.0 * k) + "°)");
        }
    }

    const bool full = section.sweep_deg >= 360.0;
    const auto segments =
        std::max<std::size_t>(full ? 3 : 1, static_cast<std::size_t>(std::ceil(section.sweep_deg / section.step_deg - 1e-9)));
    const double step = section.sweep_deg / static_cast<double>(segments);
    std::vector<glm::dvec3> out;
    out.reserve(segments + 1);
    for (std::size_t k = 0; k < (full ? segments : segments + 1); ++k) {
        const double deg = section.start_angle_deg + section.direction * step * static_cast<double>(k);
        const double phi = deg * kDeg;
        const dvec3 w = azimuth_dir(phi);
        double th = elevation(phi);
        if (across) {
            const double r = radius(s, meridian_dir(w, th));
            th += across(phi) / r;
        }
        out.push_back(point(s, meridian_dir(w, th)));
    }
    return out;
}

} // namespace lobe
