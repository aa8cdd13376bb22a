// Ground-truth lobe surfaces (input/truth_surface.h): the radial function, the mesh, plane
// sections, and strict reading of the JSON form.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include "core/errors.h"
#include "input/truth_surface.h"
#include "meshing/polyline.h"
#include "tests/support/expect_throw.h"
#include "tests/support/shapes.h"
#include "tests/support/test_data.h"
#include "tests/support/test_paths.h"

using namespace lobe;
using json = nlohmann::json;
using glm::dvec3;
using lobe::test::ellipsoid_surface;
using lobe::test::invalid_input_message;
using lobe::test::sphere_directions;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180.0;

/// The kidney of the four-lobe scene: long front to back, dented 45 mm towards −X.
TruthSurface kidney()
{
    TruthSurface s = ellipsoid_surface(dvec3(0.21, 1.30, -0.46), dvec3(0.10, 0.09, 0.16));
    s.dents.push_back({dvec3(-1.0, 0.0, 0.0), 45.0, 65.0});
    return s;
}

/// An ellipsoid turned 30° about the vertical.
TruthSurface turned()
{
    TruthSurface s = ellipsoid_surface(dvec3(0.05, 1.40, -0.42), dvec3(0.17, 0.12, 0.08));
    const double c = std::cos(30.0 * kDeg), sn = std::sin(30.0 * kDeg);
    s.axes = {dvec3(c, 0.0, -sn), dvec3(0.0, 1.0, 0.0), dvec3(sn, 0.0, c)};
    return s;
}

/// Largest radial gap of the centripetal Catmull–Rom spline through `ctrl` (the synthesizer's
/// densification), 16 samples per segment.
double spline_gap(const TruthSurface& s, const std::vector<dvec3>& ctrl, bool closed)
{
    const std::size_t n = ctrl.size();
    auto at = [&](long i) {
        const long m = static_cast<long>(n);
        if (closed) return ctrl[static_cast<std::size_t>(((i % m) + m) % m)];
        if (i < 0) return 2.0 * ctrl[0] - ctrl[1];
        if (i >= m) return 2.0 * ctrl[n - 1] - ctrl[n - 2];
        return ctrl[static_cast<std::size_t>(i)];
    };
    double worst = 0.0;
    const std::size_t segments = closed ? n : n - 1;
    for (std::size_t k = 0; k < segments; ++k) {
        const long i = static_cast<long>(k);
        for (int q = 0; q <= 16; ++q) {
            const dvec3 p = catmull_rom(at(i - 1), at(i), at(i + 1), at(i + 2), q / 16.0);
            worst = std::max(worst, std::abs(radial_gap(s, p)));
        }
    }
    return worst;
}

json surfaces_doc(const json& surface) { return json{{"surfaces", json::array({surface})}}; }

json good_surface()
{
    return json{{"center", {0.1, 1.3, -0.4}},
                {"radii", {0.12, 0.10, 0.15}},
                {"axes", {{1.0, 0.0, 0.2}, {0.0, 1.0, 0.0}}},
                {"dents", {{{"direction", {-1.0, 0.0, 0.0}}, {"depth_mm", 40.0}, {"width_deg", 60.0}}}}};
}

} // namespace

// ---------------------------------------------------------------------------------------
// The radial function
// ---------------------------------------------------------------------------------------

TEST(TruthSurfaceRadius, SphereHasItsRadiusEverywhere)
{
    const TruthSurface s = ellipsoid_surface(dvec3(0.0, 1.4, -0.4), dvec3(0.12));
    for (const dvec3& u : sphere_directions(200)) {
        EXPECT_NEAR(radius(s, u), 0.12, 1e-12);
        EXPECT_NEAR(glm::distance(point(s, u), s.center), 0.12, 1e-12);
        EXPECT_NEAR(glm::dot(normal(s, u), u), 1.0, 1e-8);
    }
}

TEST(TruthSurfaceRadius, EllipsoidRadiiAlongItsAxesAndPointsOnItsEquation)
{
    const TruthSurface s = turned();
    for (int i = 0; i < 3; ++i) {
        EXPECT_NEAR(radius(s, s.axes[static_cast<std::size_t>(i)]), s.radii[i], 1e-12);
        EXPECT_NEAR(radius(s, -s.axes[static_cast<std::size_t>(i)]), s.radii[i], 1e-12);
    }
    for (const dvec3& u : sphere_directions(300)) {
        const dvec3 p = point(s, u) - s.center;
        double q = 0.0;
        dvec3 gradient(0.0);
        for (int i = 0; i < 3; ++i) {
            const dvec3& axis = s.axes[static_cast<std::size_t>(i)];
            const double c = glm::dot(p, axis) / s.radii[i];
            q += c * c;
            gradient += axis * (glm::dot(p, axis) / (s.radii[i] * s.radii[i]));
        }
        EXPECT_NEAR(q, 1.0, 1e-12);
        // The normal is the gradient of the implicit equation.
        EXPECT_GT(glm::dot(normal(s, u), glm::normalize(gradient)), 1.0 - 1e-8);
        EXPECT_NEAR(ellipsoid_radius(s, u), radius(s, u), 1e-15);
    }
}

TEST(TruthSurfaceRadius, DentIsAGaussianInTheAngle)
{
    const TruthSurface s = kidney();
    const dvec3 dir(-1.0, 0.0, 0.0);
    EXPECT_NEAR(radius(s, dir), 0.10 - 0.045, 1e-12);
    // At the dent's width the push has fallen to 1/e; far away it has gone.
    const dvec3 at_width(-std::cos(65.0 * kDeg), 0.0, -std::sin(65.0 * kDeg));
    EXPECT_NEAR(radius(s, at_width), ellipsoid_radius(s, at_width) - 0.045 / std::exp(1.0), 1e-12);
    EXPECT_NEAR(radius(s, dvec3(1.0, 0.0, 0.0)), 0.10 - 0.045 * std::exp(-std::pow(180.0 / 65.0, 2.0)), 1e-12);
    // Radial gap and projection.
    const dvec3 p = s.center + dvec3(0.0, 0.0, -0.2);
    EXPECT_NEAR(radial_gap(s, p), 0.2 - radius(s, dvec3(0.0, 0.0, -1.0)), 1e-12);
    EXPECT_NEAR(radial_gap(s, project_radially(s, p)), 0.0, 1e-12);
}

// ---------------------------------------------------------------------------------------
// Mesh
// ---------------------------------------------------------------------------------------

TEST(TruthSurfaceMesh, IcosphereCountsClosedManifoldOutwardAndOnTheSurface)
{
    for (const TruthSurface& s : {turned(), kidney()}) {
        for (int k = 0; k <= 4; ++k) {
            SCOPED_TRACE("subdivisions " + std::to_string(k));
            const TriangleMesh m = truth_surface_mesh(s, k);
            const std::size_t faces = 20u << (2 * k);
            ASSERT_EQ(m.triangle_count(), faces);
            ASSERT_EQ(m.vertex_count(), faces / 2 + 2); // Euler: V − E + F = 2, E = 3F/2
            // Closed 2-manifold: every directed edge once, and its reverse once.
            std::map<std::pair<int, int>, int> edges;
            for (const auto& t : m.triangles)
                for (int e = 0; e < 3; ++e) ++edges[{t[static_cast<std::size_t>(e)], t[static_cast<std::size_t>((e + 1) % 3)]}];
            for (const auto& [edge, count] : edges) {
                ASSERT_EQ(count, 1);
                ASSERT_EQ(edges.count({edge.second, edge.first}), 1u);
            }
            // Outward: positive volume, and every triangle faces away from the centre.
            double volume = 0.0;
            for (const auto& t : m.triangles) {
                const dvec3 a = dvec3(m.positions[static_cast<std::size_t>(t[0])]) - s.center;
                const dvec3 b = dvec3(m.positions[static_cast<std::size_t>(t[1])]) - s.center;
                const dvec3 c = dvec3(m.positions[static_cast<std::size_t>(t[2])]) - s.center;
                volume += glm::dot(a, glm::cross(b, c)) / 6.0;
                ASSERT_GT(glm::dot(glm::cross(b - a, c - a), a + b + c), 0.0);
            }
            EXPECT_GT(volume, 0.0);
            for (const glm::vec3& p : m.positions) ASSERT_LT(std::abs(radial_gap(s, dvec3(p))), 1e-6);
        }
    }
    // The volume converges to the ellipsoid's.
    const TruthSurface e = turned();
    const TriangleMesh m = truth_surface_mesh(e, 5);
    double volume = 0.0;
    for (const auto& t : m.triangles)
        volume += glm::dot(dvec3(m.positions[static_cast<std::size_t>(t[0])]) - e.center,
                           glm::cross(dvec3(m.positions[static_cast<std::size_t>(t[1])]) - e.center,
                                      dvec3(m.positions[static_cast<std::size_t>(t[2])]) - e.center)) / 6.0;
    EXPECT_NEAR(volume, 4.0 / 3.0 * kPi * 0.17 * 0.12 * 0.08, 0.002 * volume);
}

TEST(TruthSurfaceMesh, RefusesSubdivisionsOutOfRange)
{
    EXPECT_NE(invalid_input_message([] { truth_surface_mesh(kidney(), -1); }).find("subdivisions"), std::string::npos);
    EXPECT_NE(invalid_input_message([] { truth_surface_mesh(kidney(), 8); }).find("subdivisions"), std::string::npos);
}

// ---------------------------------------------------------------------------------------
// Sections
// ---------------------------------------------------------------------------------------

TEST(TruthSurfaceSection, CentralAndOffsetPlanesLieOnTheSurfaceAndInThePlane)
{
    struct Case {
        TruthSurface s;
        dvec3 normal;
        double offset;
    };
    const std::vector<Case> cases = {
        {turned(), dvec3(0, 1, 0), 0.0},     {turned(), dvec3(0, 0, 1), 0.0},
        {turned(), dvec3(0.866, 0, 0.5), 0.0}, {turned(), dvec3(0, 1, 0), 0.07},
        {turned(), dvec3(0, 1, 0), -0.09},   {turned(), dvec3(1, 1, 0), 0.05},
        {kidney(), dvec3(0, 1, 0), 0.0},     {kidney(), dvec3(0, 1, 0), 0.045},
        {kidney(), dvec3(0, 0, 1), 0.0},     {kidney(), dvec3(0, 1, 0), -0.06},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE("offset " + std::to_string(c.offset));
        SurfaceSection sec;
        sec.plane_normal = glm::normalize(c.normal);
        sec.offset_m = c.offset;
        sec.start_angle_deg = 37.0;
        const std::vector<dvec3> pts = section_points(c.s, sec, "section");
        ASSERT_EQ(pts.size(), 180u); // every 2°, the first point not repeated
        for (const dvec3& p : pts) {
            ASSERT_LT(std::abs(radial_gap(c.s, p)), 1e-9);
            ASSERT_NEAR(glm::dot(p - c.s.center, sec.plane_normal), c.offset, 1e-9);
        }
        // The densified stroke stays on the surface: 2° control points are dense enough.
        EXPECT_LT(spline_gap(c.s, pts, true), 0.0005);

        // With a wobble the points leave the plane but not the surface.
        const SectionAcross across = [](double phi) { return 0.006 * std::sin(3.0 * phi + 0.4); };
        const std::vector<dvec3> wobbly = section_points(c.s, sec, "section", across);
        double off_plane = 0.0;
        for (const dvec3& p : wobbly) {
            ASSERT_LT(std::abs(radial_gap(c.s, p)), 1e-9);
            off_plane = std::max(off_plane, std::abs(glm::dot(p - c.s.center, sec.plane_normal) - c.offset));
        }
        EXPECT_GT(off_plane, 0.002);
        EXPECT_LT(off_plane, 0.012);
        EXPECT_LT(spline_gap(c.s, wobbly, true), 0.0005);
    }
}

TEST(TruthSurfaceSection, ArcsStartAndEndWhereAskedInEitherDirection)
{
    const TruthSurface s = turned();
    SurfaceSection sec;
    sec.plane_normal = dvec3(0.0, 0.0, 1.0); // u = +X, v = +Y: 90° is the top
    sec.start_angle_deg = 20.0;
    sec.sweep_deg = 140.0;
    const std::vector<dvec3> arc = section_points(s, sec, "section");
    ASSERT_EQ(arc.size(), 71u);
    auto dir = [](double deg) { return dvec3(std::cos(deg * kDeg), std::sin(deg * kDeg), 0.0); };
    EXPECT_LT(glm::distance(arc.front(), point(s, dir(20.0))), 1e-12);
    EXPECT_LT(glm::distance(arc.back(), point(s, dir(160.0))), 1e-12);
    EXPECT_LT(glm::distance(arc[35], point(s, dir(90.0))), 1e-12); // over the top
    EXPECT_LT(spline_gap(s, arc, false), 0.0005);

    sec.direction = -1;
    const std::vector<dvec3> back = section_points(s, sec, "section");
    EXPECT_LT(glm::distance(back.back(), point(s, dir(-120.0))), 1e-12); // under the bottom
    EXPECT_LT(glm::distance(back[55], point(s, dir(-90.0))), 1e-12);

    const auto frame = section_frame(dvec3(1.0, 0.0, 0.0));
    EXPECT_LT(glm::distance(frame[0], dvec3(0.0, 0.0, -1.0)), 1e-12);
    EXPECT_LT(glm::distance(frame[1], dvec3(0.0, 1.0, 0.0)), 1e-12);
}

TEST(TruthSurfaceSection, RefusesMissedGrazedAndSplitSections)
{
    const TruthSurface e = turned();
    SurfaceSection sec;
    sec.offset_m = 0.13; // the ellipsoid reaches 0.12 m up
    std::string msg = invalid_input_message([&] { section_points(e, sec, "steps[3].section"); });
    EXPECT_EQ(msg.rfind("steps[3].section.offset_m: ", 0), 0u) << msg;
    EXPECT_NE(msg.find("misses"), std::string::npos) << msg;

    sec.offset_m = 0.11999;
    msg = invalid_input_message([&] { section_points(e, sec, "s"); });
    EXPECT_NE(msg.find("grazes"), std::string::npos) << msg;

    // A crater on top of a ball: a plane between its floor and its rim cuts two loops.
    TruthSurface crater = ellipsoid_surface(dvec3(0.0, 1.4, -0.4), dvec3(0.1));
    crater.dents.push_back({dvec3(0.0, 1.0, 0.0), 50.0, 25.0});
    sec.offset_m = 0.075;
    msg = invalid_input_message([&] { section_points(crater, sec, "s"); });
    EXPECT_NE(msg.find("not a single loop"), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos);

    sec = SurfaceSection{};
    sec.sweep_deg = 0.0;
    EXPECT_EQ(invalid_input_message([&] { section_points(e, sec, "s"); }).rfind("s.sweep_deg:", 0), 0u);
    sec = SurfaceSection{};
    sec.direction = 2;
    EXPECT_EQ(invalid_input_message([&] { section_points(e, sec, "s"); }).rfind("s.direction:", 0), 0u);
    sec = SurfaceSection{};
    sec.plane_normal = dvec3(0.0);
    EXPECT_EQ(invalid_input_message([&] { section_points(e, sec, "s"); }).rfind("s.normal:", 0), 0u);
}

// ---------------------------------------------------------------------------------------
// JSON
// ---------------------------------------------------------------------------------------

TEST(TruthSurfaceJson, ReadsOrthonormalisesAndRoundTrips)
{
    const std::vector<TruthSurface> s = truth_surfaces_from_json(surfaces_doc(good_surface()));
    ASSERT_EQ(s.size(), 1u);
    const TruthSurface& t = s[0];
    EXPECT_NEAR(glm::length(t.axes[0]), 1.0, 1e-15);
    EXPECT_NEAR(glm::dot(t.axes[0], t.axes[1]), 0.0, 1e-15);
    EXPECT_LT(glm::distance(t.axes[2], glm::cross(t.axes[0], t.axes[1])), 1e-15);
    EXPECT_NEAR(t.axes[0].z / t.axes[0].x, 0.2, 1e-12);
    ASSERT_EQ(t.dents.size(), 1u);
    EXPECT_EQ(t.dents[0].depth_mm, 40.0);
    EXPECT_EQ(t.dents[0].width_deg, 60.0);

    const json again = surfaces_doc(truth_surface_to_json(t));
    const TruthSurface back = truth_surfaces_from_json(again)[0];
    for (const dvec3& u : sphere_directions(50)) EXPECT_EQ(radius(back, u), radius(t, u));
    EXPECT_EQ(again.dump(), surfaces_doc(truth_surface_to_json(back)).dump());

    EXPECT_TRUE(truth_surfaces_from_json(json::object()).empty());
}

TEST(TruthSurfaceJson, BadSurfacesGiveOneLineInvalidInputNamingTheField)
{
    struct Case {
        const char* what;
        json surface;
        const char* field;
    };
    std::vector<Case> cases;
    auto with = [](const char* key, json value) {
        json j = good_surface();
        j[key] = std::move(value);
        return j;
    };
    cases.push_back({"radius too small", with("radii", {0.01, 0.1, 0.1}), "surfaces[0].radii"});
    cases.push_back({"radius too large", with("radii", {0.1, 2.5, 0.1}), "surfaces[0].radii"});
    cases.push_back({"two radii", with("radii", {0.1, 0.1}), "surfaces[0].radii"});
    cases.push_back({"centre far away", with("center", {0.0, 11.0, 0.0}), "surfaces[0].center"});
    cases.push_back({"NaN centre", with("center", {0.0, std::nan(""), 0.0}), "surfaces[0].center"});
    cases.push_back({"parallel axes", with("axes", {{1, 0, 0}, {2, 0, 0}}), "surfaces[0].axes"});
    cases.push_back({"zero axis", with("axes", {{0, 0, 0}, {0, 1, 0}}), "surfaces[0].axes[0]"});
    cases.push_back({"three axes", with("axes", {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}), "surfaces[0].axes"});
    cases.push_back({"misspelt field", with("radius", 0.1), "surfaces[0]"});
    cases.push_back({"dent too deep",
                     with("dents", {{{"direction", {-1, 0, 0}}, {"depth_mm", 90.0}, {"width_deg", 60.0}}}),
                     "surfaces[0].dents"});
    cases.push_back({"two dents together too deep",
                     with("dents", {{{"direction", {-1, 0, 0}}, {"depth_mm", 50.0}, {"width_deg", 40.0}},
                                    {{"direction", {-1, 0.1, 0}}, {"depth_mm", 50.0}, {"width_deg", 40.0}}}),
                     "surfaces[0].dents"});
    cases.push_back({"dent too wide",
                     with("dents", {{{"direction", {-1, 0, 0}}, {"depth_mm", 10.0}, {"width_deg", 120.0}}}),
                     "surfaces[0].dents[0].width_deg"});
    cases.push_back({"negative depth",
                     with("dents", {{{"direction", {-1, 0, 0}}, {"depth_mm", -5.0}}}), "surfaces[0].dents[0].depth_mm"});
    cases.push_back({"zero dent direction",
                     with("dents", {{{"direction", {0, 0, 0}}, {"depth_mm", 5.0}}}), "surfaces[0].dents[0].direction"});
    cases.push_back({"dent without direction", with("dents", {{{"depth_mm", 5.0}}}), "surfaces[0].dents[0]"});
    cases.push_back({"unknown dent field",
                     with("dents", {{{"direction", {1, 0, 0}}, {"depth_mm", 5.0}, {"angle_deg", 3}}}),
                     "surfaces[0].dents[0]"});
    {
        json many = json::array();
        for (int i = 0; i < 9; ++i) many.push_back({{"direction", {1, 0, 0}}, {"depth_mm", 1.0}});
        cases.push_back({"nine dents", with("dents", many), "surfaces[0].dents"});
    }
    cases.push_back({"not an object", json::array({1, 2}), "surfaces[0]"});
    for (const Case& c : cases) {
        SCOPED_TRACE(c.what);
        const std::string msg = invalid_input_message([&] { truth_surfaces_from_json(surfaces_doc(c.surface)); });
        ASSERT_FALSE(msg.empty()) << "should be refused";
        EXPECT_EQ(msg.rfind(std::string(c.field) + ":", 0), 0u) << msg;
        EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    }
    EXPECT_EQ(invalid_input_message([] { truth_surfaces_from_json(json{{"surfaces", 3}}); }).rfind("surfaces:", 0), 0u);

    // Surfaces built in code are checked as strictly.
    TruthSurface s = kidney();
    s.axes[1] = dvec3(1.0, 0.0, 0.0);
    EXPECT_EQ(invalid_input_message([&] { validate_truth_surface(s, "lobe"); }).rfind("lobe.axes:", 0), 0u);
    s = kidney();
    s.dents[0].depth_mm = 80.0;
    EXPECT_EQ(invalid_input_message([&] { validate_truth_surface(s, "lobe"); }).rfind("lobe.dents:", 0), 0u);
}

// ---------------------------------------------------------------------------------------
// Shipped truth files: everything a test needs is in the truth file alone
// ---------------------------------------------------------------------------------------

TEST(TruthSurfaceShipped, TruthFilesCarryTheScenarioSurfacesAndStrokesLieOnThem)
{
    const std::string recordings = test::source_data("recordings");
    if (recordings.empty()) return;
    int checked = 0;
    for (const auto& e : std::filesystem::directory_iterator(recordings)) {
        const std::string name = e.path().filename().string();
        if (!name.ends_with(".scenario.json")) continue;
        const std::string stem = e.path().string().substr(0, e.path().string().size() - 14);
        if (!test::require_data(stem + ".truth.json")) return;
        SCOPED_TRACE(name);
        json truth, scenario;
        std::ifstream(stem + ".truth.json") >> truth;
        std::ifstream(stem + ".scenario.json") >> scenario;
        const std::vector<TruthSurface> surfaces = truth_surfaces_from_json(truth);
        const std::vector<TruthSurface> expected = truth_surfaces_from_json(scenario);
        ASSERT_EQ(surfaces.size(), expected.size());
        for (std::size_t k = 0; k < surfaces.size(); ++k)
            EXPECT_EQ(truth_surface_to_json(surfaces[k]), truth_surface_to_json(expected[k]));
        for (const json& st : truth["strokes"]) {
            if (!st.contains("surface")) continue;
            EXPECT_EQ(st["kind"], "lobe");
            const TruthSurface& s = surfaces.at(st["surface"].get<std::size_t>());
            for (const json& p : st["points"]) {
                const dvec3 q(p[0].get<double>(), p[1].get<double>(), p[2].get<double>());
                ASSERT_LT(std::abs(radial_gap(s, q)), 0.0005);
            }
            ++checked;
        }
    }
    EXPECT_GE(checked, 48) << "the Table 1 scenes and pinch-edit draw every lobe stroke on a surface";
}
