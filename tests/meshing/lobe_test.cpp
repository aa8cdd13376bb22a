// Progressive lobes (§4.2, Fig. 5 and 9) on the shipped recordings and on constructed
// strokes: closed, 2-manifold, outward, free of self-intersections, through every stroke;
// local insertion; refusal of bad strokes with the lobe unchanged; edits that survive.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <tuple>

#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include "core/document.h"
#include "core/errors.h"
#include "input/pipeline.h"
#include "input/recording.h"
#include "app/session/session_builder.h"
#include "input/synth.h"
#include "input/truth_surface.h"
#include "core/atomic_file.h"
#include "app/session/edit_hooks.h"
#include "app/session/edit_ops.h"
#include "meshing/lobe.h"
#include "app/session/lobe_document.h"
#include "app/session/stage_options.h"
#include "meshing/lobe_remesh.h"
#include "meshing/mesh_quality.h"
#include "meshing/repair.h"
#include "meshing/stitch.h"
#include "tests/support/test_data.h"
#include "tests/support/test_paths.h"

namespace lobe {
namespace {

constexpr double kPi = 3.14159265358979323846;

Document replay_document(const std::string& rec_path)
{
    const Recording rec = read_recording(rec_path);
    const InputResult r = run_input_pipeline(rec);
    SessionBuilder b;
    b.apply(r.actions);
    return b.take_document();
}

/// Distance from p to the closest triangle of `mesh` (brute force; meshes here are small).
double distance_to_mesh(const glm::dvec3& p, const TriangleMesh& mesh)
{
    double best = std::numeric_limits<double>::infinity();
    for (const auto& t : mesh.triangles) {
        const glm::dvec3 a(mesh.positions[static_cast<std::size_t>(t[0])]);
        const glm::dvec3 b(mesh.positions[static_cast<std::size_t>(t[1])]);
        const glm::dvec3 c(mesh.positions[static_cast<std::size_t>(t[2])]);
        // Ericson, Real-Time Collision Detection, 5.1.5.
        const glm::dvec3 ab = b - a, ac = c - a, ap = p - a;
        const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
        glm::dvec3 q;
        if (d1 <= 0 && d2 <= 0) q = a;
        else {
            const glm::dvec3 bp = p - b;
            const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
            const glm::dvec3 cp = p - c;
            const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
            const double vc = d1 * d4 - d3 * d2, vb = d5 * d2 - d1 * d6, va = d3 * d6 - d5 * d4;
            if (d3 >= 0 && d4 <= d3) q = b;
            else if (vc <= 0 && d1 >= 0 && d3 <= 0) q = a + ab * (d1 / (d1 - d3));
            else if (d6 >= 0 && d5 <= d6) q = c;
            else if (vb <= 0 && d2 >= 0 && d6 <= 0) q = a + ac * (d2 / (d2 - d6));
            else if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) q = b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
            else {
                const double denom = 1.0 / (va + vb + vc);
                q = a + ab * (vb * denom) + ac * (vc * denom);
            }
        }
        best = std::min(best, glm::distance(p, q));
    }
    return best;
}

void expect_valid_lobe(const TriangleMesh& mesh, const std::string& what)
{
    const MeshQuality q = measure_quality(mesh);
    EXPECT_TRUE(q.closed) << what << ": " << q.boundary_edges << " boundary edges";
    EXPECT_TRUE(q.manifold) << what << ": " << q.non_manifold_edges << " non-manifold edges, " << q.non_manifold_vertices
                            << " non-manifold vertices, " << q.inconsistent_edges << " inconsistent edges";
    EXPECT_TRUE(q.outward) << what << ": signed volume " << q.signed_volume_m3;
    EXPECT_EQ(q.components, 1u) << what;
    EXPECT_FALSE(self_intersects(mesh)) << what;
}

/// Corners under `limit_deg` that strokes do not force. Two kinds are forced: a corner between two
/// stroke edges (strokes crossing or meeting at a smaller angle), and a corner facing a stroke
/// edge that runs between two stroke crossings (both ends on three or more stroke edges) and is
/// shorter than half the 3 cm target: neither end may move, so whatever vertex faces that
/// edge from a target length away sees it under a small angle.
std::size_t sharp_corners_off_strokes(const TriangleMesh& mesh, double limit_deg = 15.0)
{
    std::set<std::pair<int, int>> strokes;
    std::map<int, int> stroke_degree;
    for (const auto& e : mesh.feature_edges)
        if (strokes.emplace(std::min(e[0], e[1]), std::max(e[0], e[1])).second) {
            ++stroke_degree[e[0]];
            ++stroke_degree[e[1]];
        }
    auto on_stroke = [&](int a, int b) { return strokes.count({std::min(a, b), std::max(a, b)}) > 0; };
    auto crossing = [&](int v) { return stroke_degree.count(v) && stroke_degree[v] >= 3; };
    auto at = [&](int v) { return glm::dvec3(mesh.positions[static_cast<std::size_t>(v)]); };
    std::size_t n = 0;
    for (const auto& t : mesh.triangles)
        for (std::size_t c = 0; c < 3; ++c) {
            const int v = t[c], a = t[(c + 1) % 3], b = t[(c + 2) % 3];
            const glm::dvec3 u = glm::normalize(at(a) - at(v)), w = glm::normalize(at(b) - at(v));
            const double angle = std::acos(std::clamp(glm::dot(u, w), -1.0, 1.0)) * 180.0 / kPi;
            if (angle >= limit_deg || (on_stroke(v, a) && on_stroke(v, b))) continue;
            if (on_stroke(a, b) && crossing(a) && crossing(b) && glm::distance(at(a), at(b)) < 0.015) continue;
            ++n;
        }
    return n;
}

/// How far the farthest vertex of `mesh`'s feature edges lies from every feature edge of
/// `input` (metres).
double worst_stroke_vertex_offset(const TriangleMesh& mesh, const TriangleMesh& input)
{
    std::set<int> vertices;
    for (const auto& e : mesh.feature_edges) vertices.insert({e[0], e[1]});
    double worst = 0.0;
    for (int v : vertices) {
        const glm::dvec3 p(mesh.positions[static_cast<std::size_t>(v)]);
        double best = std::numeric_limits<double>::infinity();
        for (const auto& e : input.feature_edges) {
            const glm::dvec3 a(input.positions[static_cast<std::size_t>(e[0])]), b(input.positions[static_cast<std::size_t>(e[1])]);
            const double l2 = glm::dot(b - a, b - a);
            const double t = l2 > 0.0 ? std::clamp(glm::dot(p - a, b - a) / l2, 0.0, 1.0) : 0.0;
            best = std::min(best, glm::distance(a + t * (b - a), p));
        }
        worst = std::max(worst, best);
    }
    return worst;
}

/// A closed loop: centre + radius·(cos t·u + sin t·v), with a wobble of `wobble` metres.
std::vector<glm::vec3> loop(const glm::dvec3& centre, const glm::dvec3& u, const glm::dvec3& v, double ru, double rv,
                            int n = 160, double wobble = 0.0, double phase = 0.0)
{
    std::vector<glm::vec3> out;
    for (int i = 0; i < n; ++i) {
        const double t = 2.0 * kPi * i / n + phase;
        const double w = 1.0 + wobble * std::sin(5.0 * t + 0.3);
        out.emplace_back(centre + w * (ru * std::cos(t) * u + rv * std::sin(t) * v));
    }
    return out;
}

/// A loop of the sphere of radius r around c, at height h along `axis` (a small circle).
std::vector<glm::vec3> sphere_ring(const glm::dvec3& c, double r, double h, int n = 160)
{
    const double rr = std::sqrt(r * r - h * h);
    return loop(c + glm::dvec3(0, h, 0), {1, 0, 0}, {0, 0, 1}, rr, rr, n);
}

/// A triangle by the positions of its corners, starting at the least: the same triangle in
/// two meshes, whatever its vertices' indices.
std::array<std::array<float, 3>, 3> corners(const TriangleMesh& m, const std::array<int, 3>& t)
{
    std::array<std::array<float, 3>, 3> k{};
    for (std::size_t i = 0; i < 3; ++i) {
        const glm::vec3& p = m.positions[static_cast<std::size_t>(t[i])];
        k[i] = {p.x, p.y, p.z};
    }
    std::rotate(k.begin(), std::min_element(k.begin(), k.end()), k.end());
    return k;
}

// ---------------------------------------------------------------------------------------
// The shipped recordings, through the whole pipeline.

TEST(Lobes, EveryShippedRecordingGivesClosedManifoldOutwardLobesThroughEveryStroke)
{
    double share_sum = 0;
    int share_count = 0;
    for (const char* name : {"table1-1lobe-5strokes", "table1-3lobes-16strokes", "table1-4lobes-22strokes", "pinch-edit"}) {
        const std::string base = test::source_path(std::string("recordings/") + name);
        if (!test::require_data(base + ".lrec") || !test::require_data(base + ".truth.json")) return;
        SCOPED_TRACE(name);
        const Document doc = replay_document(base + ".lrec");
        std::vector<std::string> warnings;
        const std::vector<BuiltLobe> lobes = build_document_lobes(doc, &warnings);
        for (const std::string& w : warnings) ADD_FAILURE() << w;
        ASSERT_EQ(lobes.size(), doc.lobes.size());
        const auto truth = load_ground_truth(base + ".truth.json");
        const std::vector<TruthSurface> surfaces =
            truth_surfaces_from_json(nlohmann::json::parse(read_file_limited(base + ".truth.json", 64u << 20)));
        std::vector<const GroundTruthStroke*> truth_lobe_strokes;
        for (const auto& t : truth)
            if (t.kind == StrokeKind::Lobe && !t.drag) truth_lobe_strokes.push_back(&t);
        // Document lobe strokes are numbered in drawing order, like the truth.
        std::map<std::int64_t, const GroundTruthStroke*> truth_of;
        std::size_t k = 0;
        for (const Stroke& s : doc.strokes)
            if (s.kind == StrokeKind::Lobe && k < truth_lobe_strokes.size()) truth_of[s.id] = truth_lobe_strokes[k++];
        for (const BuiltLobe& b : lobes) {
            const std::string what = std::string(name) + " lobe " + std::to_string(b.lobe_id);
            expect_valid_lobe(b.surface.mesh, what + " (before remeshing)");
            expect_valid_lobe(b.mesh, what);
            {
                // Remeshed region by region (lobe_remesh.h), not as a whole.
                RemeshOptions o;
                o.target_edge_length_m = doc.settings.lobes.edge_length_m;
                o.iterations = static_cast<unsigned>(doc.settings.lobes.remesh_iterations);
                LobeRemeshStats stats;
                const TriangleMesh again = remesh_lobe_surface(b.surface, o, nullptr, &stats);
                EXPECT_FALSE(stats.whole) << what;
                EXPECT_EQ(stats.remeshed, stats.regions) << what;
                if (b.edits_applied == 0) {
                    EXPECT_TRUE(again.positions == b.mesh.positions) << what;
                }
            }
            const MeshQuality q = measure_quality(b.mesh);
            // Issue goal: ≥ 95 % of triangles with every angle ≥ 30°, in every lobe. The worst
            // is the kidney lobe, whose stacked loops run 3 cm apart (one target edge) and are
            // crossed by three loops: about 98.3 %, 94.4 % without the small-angle repairs.
            EXPECT_GE(q.share_all_angles_ge_30, 0.95) << what;
            share_sum += q.share_all_angles_ge_30;
            ++share_count;
            RecordProperty(what + " angles>=30", std::to_string(q.share_all_angles_ge_30));
            RecordProperty(what + " min_angle", std::to_string(q.min_angle_deg));
            // No angle under 15° but between two stroke edges (strokes crossing or meeting at
            // a smaller angle).
            EXPECT_EQ(sharp_corners_off_strokes(b.mesh), 0u) << what << ": min angle " << q.min_angle_deg << "°";
            // Stricter than the issue: after the small-angle repairs nothing unforced is under
            // 20° (the kidney lobe comes closest).
            EXPECT_EQ(sharp_corners_off_strokes(b.mesh, 20.0), 0u) << what;
            // Every ground-truth point of the lobe's strokes lies on the lobe (before edits).
            if (std::string(name) == "pinch-edit") continue;
            // Remeshing slides stroke vertices along the strokes; they end on the drawn strokes.
            EXPECT_LT(worst_stroke_vertex_offset(b.mesh, b.surface.mesh), 1e-5) << what;
            double worst = 0, worst_surface = 0;
            for (std::int64_t id : b.stroke_ids) {
                for (std::size_t i = 0; i < truth_of[id]->points.size(); i += 3)
                    worst_surface = std::max(worst_surface, distance_to_mesh(glm::dvec3(truth_of[id]->points[i]), b.surface.mesh));
                ASSERT_TRUE(truth_of.count(id)) << what << " stroke " << id;
                const auto& pts = truth_of[id]->points;
                for (std::size_t i = 0; i < pts.size(); i += 3)
                    worst = std::max(worst, distance_to_mesh(glm::dvec3(pts[i]), b.mesh));
            }
            EXPECT_LE(worst_surface, 0.005) << what << ": before remeshing";
            // Two-sided Hausdorff distance to the scenario's ground-truth surface (before edits).
            const int surface = truth_of[b.stroke_ids.front()]->surface;
            ASSERT_GE(surface, 0) << what;
            const TriangleMesh truth_mesh = truth_surface_mesh(surfaces[static_cast<std::size_t>(surface)], 5);
            const double to_truth = max_vertex_distance(b.mesh, truth_mesh);
            const double from_truth = max_vertex_distance(truth_mesh, b.mesh);
            EXPECT_LE(std::max(to_truth, from_truth), 0.01)
                << what << ": Hausdorff " << to_truth * 1000 << " / " << from_truth * 1000 << " mm";
            RecordProperty(what + " hausdorff_mm", std::to_string(1000 * std::max(to_truth, from_truth)));
            RecordProperty(what + " stroke_mm", std::to_string(1000 * worst));
            EXPECT_LE(worst, 0.005) << what << ": a ground-truth stroke point is " << worst * 1000 << " mm off the lobe";
        }
    }
    ASSERT_GT(share_count, 0);
    EXPECT_GE(share_sum / share_count, 0.98) << "mean share of triangles with all angles ≥ 30°";
}

TEST(Lobes, RegionByRegionRemeshingGivesValidLobesForEveryKindOfDrawingAndFallsBackWhereARegionWrapsTheCentre)
{
    const glm::dvec3 c(0.0, 1.3, -0.4);
    const double r = 0.18;
    std::vector<glm::vec3> arc; // an open arc over the top, alone: one region all round it
    for (int i = 0; i <= 80; ++i) {
        const double t = 0.3 + (kPi - 0.6) * i / 80.0;
        arc.emplace_back(c + r * glm::dvec3(std::cos(t), std::sin(t), 0.1 * std::sin(3 * t)));
    }
    const auto tilted = [&](double deg) {
        const double a = deg * kPi / 180.0;
        return loop(c, {1, 0, 0}, {0, std::cos(a), std::sin(a)}, r, r, 160, 0.01);
    };
    struct Case {
        const char* name;
        std::vector<std::vector<glm::vec3>> strokes;
        bool whole;
    };
    const std::vector<Case> cases = {
        {"one ring", {sphere_ring(c, r, 0.0)}, false},
        {"stacked rings", {sphere_ring(c, r, -0.1), sphere_ring(c, r, 0.0), sphere_ring(c, r, 0.1)}, false},
        {"two loops at 60°", {tilted(0), tilted(60)}, false},
        {"two loops at 90°", {tilted(0), tilted(90)}, false},
        {"rings and an arc over the top", {sphere_ring(c, r, -0.08), sphere_ring(c, r, 0.08), arc}, false},
        {"an open arc alone", {arc}, true},
    };
    RemeshOptions options;
    options.iterations = 4;
    for (const Case& k : cases) {
        Lobe lobe;
        for (std::size_t i = 0; i < k.strokes.size(); ++i) lobe.add_stroke(static_cast<std::int64_t>(i + 1), k.strokes[i]);
        LobeRemeshStats stats;
        const TriangleMesh mesh = remesh_lobe_surface(lobe.surface(), options, nullptr, &stats);
        EXPECT_EQ(stats.whole, k.whole) << k.name;
        expect_valid_lobe(mesh, k.name);
        EXPECT_LT(worst_stroke_vertex_offset(mesh, lobe.surface().mesh), 1e-5) << k.name;
        const MeshQuality q = measure_quality(mesh);
        EXPECT_GE(q.share_all_angles_ge_30, 0.95) << k.name;
        EXPECT_EQ(sharp_corners_off_strokes(mesh), 0u) << k.name << ": min angle " << q.min_angle_deg << "°";
        if (k.whole) continue;
        EXPECT_EQ(stats.remeshed, stats.regions) << k.name;
        // Stroke edges: equal steps along each piece, none longer than 1.2 × the target.
        for (const auto& e : mesh.feature_edges)
            EXPECT_LE(glm::distance(mesh.positions[static_cast<std::size_t>(e[0])], mesh.positions[static_cast<std::size_t>(e[1])]),
                      1.2 * options.target_edge_length_m + 1e-6)
                << k.name;
    }
}

/// A stroke as fuzz/lobe_strokes_fuzz.cpp draws it round (0, 1.3, −0.4): a loop or, with
/// sweep < 1, an arc of the circle at height h on the sphere of radius r about the axis of
/// the given tilt and turn, with a wobble of the radius.
std::vector<glm::vec3> fuzz_stroke(double tilt, double turn, double r, double h, int n, double sweep, double wobble,
                                   int frequency, bool reverse)
{
    const glm::dvec3 c(0.0, 1.3, -0.4);
    const glm::dvec3 axis(std::sin(tilt) * std::cos(turn), std::cos(tilt), std::sin(tilt) * std::sin(turn));
    glm::dvec3 u = glm::cross(axis, glm::dvec3(0.3, 0.1, 0.9));
    u = glm::length(u) > 1e-9 ? glm::normalize(u) : glm::dvec3(1, 0, 0);
    const glm::dvec3 v = glm::cross(axis, u);
    const double rr = std::sqrt(std::max(0.0, r * r - h * h));
    std::vector<glm::vec3> raw;
    for (int i = 0; i < n; ++i) {
        const double t = sweep * 2.0 * kPi * (reverse ? n - 1 - i : i) / n;
        const double w = wobble * std::sin(frequency * t);
        raw.emplace_back(c + h * axis + (rr + w) * (std::cos(t) * u + std::sin(t) * v));
    }
    return raw;
}

TEST(Lobes, AnArcRetracingALoopIsRemeshedThoughARegionLiesOnOneLineOfItsChart)
{
    // Found by fuzz/lobe_strokes_fuzz.cpp once it remeshed its lobes: a wobbly loop and an arc
    // drawn backwards over it, without the wobble (the lobe's first strokes). A region
    // of that lobe lay on one line of its chart, and its triangulation (one-dimensional, faces
    // without neighbours) was walked as if it had faces: a null dereference (UBSan stops the
    // ASan build there). Now such a region is not charted and the lobe is remeshed whole,
    // like every region that cannot be.
    Lobe lobe;
    const double b = 251.0 / 255.0; // the fuzzer's input byte 251
    const double r = 0.2 * (0.2 + 1.3 * b);
    // Its strokes 3 and 4 (1 and 2 were refused: a NaN, a path and back along it); a
    // stroke's sampling starts where its id says.
    lobe.add_stroke(3, fuzz_stroke(kPi * b, 2.0 * kPi * b, r, (b - 0.5) * 1.6 * r, 95, 1.0, 0.005 * b, 11, false));
    lobe.add_stroke(4, fuzz_stroke(kPi * b, 2.0 * kPi * b, r, (b - 0.5) * 1.6 * r, 95, 0.1 + 0.9 * b, 0.005 * b, 0, true));
    ASSERT_EQ(lobe.strokes().size(), 2u);
    LobeRemeshStats stats;
    RemeshOptions o;
    o.relax_feature_edges = true;
    o.iterations = 4;
    const TriangleMesh remeshed = remesh_lobe_surface(lobe.surface(), o, nullptr, &stats);
    EXPECT_TRUE(stats.whole);
    // One closed, 2-manifold, outward piece. The arc runs within 5 mm of the loop (its
    // wobble), a sliver of a region that 3 cm triangles cannot follow without crossing
    // themselves (the nearest-point projection of before gives the same).
    const MeshQuality q = measure_quality(remeshed);
    EXPECT_TRUE(q.closed && q.manifold && q.outward);
    EXPECT_EQ(q.components, 1u);
    EXPECT_GT(q.signed_volume_m3, 0.0);
}

TEST(Lobes, ALobeThatRemeshingWouldCollapseIsRefusedInOneLine)
{
    // A lobe of one open arc 6 cm across (found by fuzz/lobe_strokes_fuzz.cpp): its one region
    // cannot be charted, and the whole-lobe remeshing at 5 cm collapsed it to two triangles
    // back to back (CGAL collapses every edge under 4/5 of the target). Now remeshing refuses
    // it in one line; a lobe list leaves it out with a warning. At 1 cm it is remeshed.
    const double r = 0.2 * (0.2 + 1.3 * 9.0 / 255.0);
    Lobe lobe;
    lobe.add_stroke(1, fuzz_stroke(0.0, 2.0 * kPi * 64.0 / 255.0, r, (1.0 / 255.0 - 0.5) * 1.6 * r, 100,
                                   0.1 + 0.9 * 96.0 / 255.0, 0.0, 0, true));
    RemeshOptions o;
    o.relax_feature_edges = true;
    o.target_edge_length_m = 0.05;
    try {
        remesh_lobe_surface(lobe.surface(), o);
        ADD_FAILURE() << "a collapsed lobe was not refused";
    } catch (const InvalidInput& e) {
        const std::string what = e.what();
        EXPECT_EQ(what.find('\n'), std::string::npos);
        EXPECT_NE(what.find("too small"), std::string::npos) << what;
    }
    o.target_edge_length_m = 0.01;
    const MeshQuality q = measure_quality(remesh_lobe_surface(lobe.surface(), o));
    EXPECT_TRUE(q.closed && q.manifold && q.outward);
}

TEST(Lobes, ALobeThatIsNotRemeshedKeepsItsFillAtTheAttractorSpacing)
{
    // Remeshed lobes get a fill twice as coarse (remeshing lays the attractors); without
    // remeshing the fill vertices are the attractors, so they stay at the spacing.
    const std::string rec_path = test::source_data("recordings/table1-1lobe-5strokes.lrec");
    if (rec_path.empty()) return;
    Document doc = replay_document(rec_path);
    auto fill_of = [](const BuiltLobe& b) {
        std::size_t n = 0;
        for (const LobeVertexOrigin& o : b.surface.origins) n += o.kind == LobeVertexKind::Fill ? 1 : 0;
        return n;
    };
    ASSERT_GT(doc.settings.lobes.remesh_iterations, 0);
    EXPECT_EQ(lobe_options(doc.settings).surface.fill_coarseness, 2.0);
    const auto remeshed = build_document_lobes(doc);
    doc.settings.lobes.remesh_iterations = 0;
    EXPECT_EQ(lobe_options(doc.settings).surface.fill_coarseness, 1.0);
    const auto kept = build_document_lobes(doc);
    ASSERT_EQ(remeshed.size(), 1u);
    ASSERT_EQ(kept.size(), 1u);
    EXPECT_TRUE(kept[0].mesh.positions == kept[0].surface.mesh.positions) << "not remeshed";
    expect_valid_lobe(kept[0].mesh, "not remeshed");
    EXPECT_GT(fill_of(remeshed[0]), 20u);
    // Measured: 594 fill vertices against 222 (strips beside the strokes keep some).
    EXPECT_GT(fill_of(kept[0]), 2 * fill_of(remeshed[0]));
}

TEST(Lobes, SurfaceBeforeRemeshingIsMadeOfStrokePointsStripsAndCaps)
{
    const std::string rec_path = test::source_data("recordings/table1-1lobe-5strokes.lrec");
    if (rec_path.empty()) return;
    const Document doc = replay_document(rec_path);
    const auto lobes = build_document_lobes(doc);
    ASSERT_EQ(lobes.size(), 1u);
    const LobeSurface& s = lobes[0].surface;
    ASSERT_EQ(s.origins.size(), s.mesh.positions.size());
    std::size_t samples = 0, crossings = 0;
    for (const LobeVertexOrigin& o : s.origins) {
        if (o.kind == LobeVertexKind::Sample) ++samples;
        if (o.kind == LobeVertexKind::Crossing) ++crossings;
    }
    EXPECT_EQ(crossings, s.crossings);
    EXPECT_GT(s.crossings, 0u); // the loops are drawn at different angles and cross
    // Every sample of every stroke is a vertex, except those that gave way to a crossing
    // vertex within the merge distance (a quarter of the stroke's median spacing).
    std::set<std::tuple<float, float, float>> vertices;
    std::vector<glm::vec3> crossing_vertices;
    for (std::size_t i = 0; i < s.mesh.positions.size(); ++i) {
        const glm::vec3& p = s.mesh.positions[i];
        vertices.insert({p.x, p.y, p.z});
        if (s.origins[i].kind == LobeVertexKind::Crossing) crossing_vertices.push_back(p);
    }
    std::size_t checked = 0, gave_way = 0;
    for (std::int64_t id : lobes[0].stroke_ids)
        for (const Stroke& st : doc.strokes)
            if (st.id == id) {
                std::vector<glm::vec3> raw;
                for (const auto& p : st.points) raw.push_back(p.position);
                const LobeStrokeSamples prepared = prepare_lobe_stroke(id, raw);
                std::vector<double> gaps;
                for (std::size_t i = 0; i + 1 < prepared.points.size(); ++i)
                    gaps.push_back(glm::distance(prepared.points[i], prepared.points[i + 1]));
                std::nth_element(gaps.begin(), gaps.begin() + static_cast<long>(gaps.size() / 2), gaps.end());
                const double merge = 0.25 * gaps[gaps.size() / 2];
                for (const glm::vec3& p : prepared.points) {
                    ++checked;
                    if (vertices.count({p.x, p.y, p.z})) continue;
                    ++gave_way;
                    double nearest = 1e9;
                    for (const glm::vec3& q : crossing_vertices) nearest = std::min(nearest, static_cast<double>(glm::distance(p, q)));
                    EXPECT_LT(nearest, merge * 1.5) << "stroke " << id << ": a sample is neither a vertex nor next to a crossing";
                }
            }
    EXPECT_GT(checked, 40u);
    EXPECT_LT(gave_way, checked / 5);
    // Stroke segments are the remeshing constraints: every feature edge is a mesh edge.
    std::set<std::pair<int, int>> edges;
    for (const auto& t : s.mesh.triangles)
        for (int k = 0; k < 3; ++k) edges.insert({std::min(t[k], t[(k + 1) % 3]), std::max(t[k], t[(k + 1) % 3])});
    for (const auto& e : s.mesh.feature_edges) EXPECT_TRUE(edges.count({e[0], e[1]}));
}

// ---------------------------------------------------------------------------------------
// Constructed strokes.

TEST(Lobes, Fig9TwoFreeFormLoopsAt0_60_90DegreesGiveManifoldStripsThatDoNotCross)
{
    const glm::dvec3 c(0, 1.4, -0.4);
    for (double deg : {0.0, 60.0, 90.0}) {
        SCOPED_TRACE(deg);
        const double a = deg * kPi / 180.0;
        // Two free-form loops around the same foliage; at 0° the second is a stacked copy.
        const auto first = loop(c, {1, 0, 0}, {0, 0, 1}, 0.16, 0.13, 150, 0.06);
        const glm::dvec3 v(0, std::sin(a), std::cos(a));
        const auto second = loop(c + (deg == 0.0 ? glm::dvec3(0, 0.06, 0) : glm::dvec3(0.0)), {1, 0, 0}, v, 0.15, 0.12,
                                 140, 0.05, 0.7);
        const StrokeStrip strip = stitch_closed_closed(sample_by_curvature(first, true), sample_by_curvature(second, true));
        TriangleMesh m;
        m.positions = strip.positions;
        m.triangles = strip.triangles;
        const MeshQuality q = measure_quality(m);
        EXPECT_TRUE(q.manifold);
        EXPECT_EQ(q.components, 1u);
        EXPECT_FALSE(self_intersects(m));
        // The lobe through both is a valid closed surface.
        Lobe lobe;
        lobe.add_stroke(1, first);
        lobe.add_stroke(2, second);
        expect_valid_lobe(lobe.surface().mesh, "lobe at " + std::to_string(deg));
        if (deg > 0) {
            EXPECT_EQ(lobe.surface().crossings, 2u);
        }
    }
}

TEST(Lobes, StackedLoopsAreJoinedByThePapersStripsAndOpenArcsCapThem)
{
    const glm::dvec3 c(0, 1.4, -0.4);
    Lobe lobe;
    lobe.add_stroke(1, sphere_ring(c, 0.15, 0.0));
    lobe.add_stroke(2, sphere_ring(c, 0.15, 0.07));
    expect_valid_lobe(lobe.surface().mesh, "two stacked loops");
    EXPECT_GT(lobe.surface().paper_strip_triangles, 0u);
    // An open arc over the top, ends near the upper loop.
    std::vector<glm::vec3> arc;
    const double top = std::asin(0.07 / 0.15);
    for (int i = 0; i <= 120; ++i) {
        const double t = top + (kPi - 2 * top) * i / 120.0;
        arc.emplace_back(c + 0.15 * glm::dvec3(std::cos(t), std::sin(t), 0.0));
    }
    lobe.add_stroke(3, arc);
    expect_valid_lobe(lobe.surface().mesh, "with a cap arc");
    // The surface hugs the sphere the strokes were drawn on where they cover it; below the
    // equator nothing was drawn: the automatic cap rounds off (biharmonic fill), within a
    // quarter of the radius of the sphere the person had in mind.
    for (const glm::vec3& p : lobe.surface().mesh.positions)
        EXPECT_NEAR(glm::distance(glm::dvec3(p), c), 0.15, p.y >= c.y ? 0.006 : 0.035) << p.y - c.y;
}

TEST(Lobes, TheCoarseFillIsRemeshedOntoTheLobesCurvatureNotOntoItsFlatFacets)
{
    // Three loops of a 30 cm sphere about different axes, crossing: the cells between them
    // are filled. The fill is laid twice as coarse as the attractor spacing (fill_coarseness
    // 2): its flat triangles lie millimetres inside the sphere. Remeshing lifts every vertex
    // it makes along its ray from the centre to the distance interpolated across them, so the
    // lobe is as round as with the fill at the spacing itself.
    const glm::dvec3 c(0.1, 1.3, -0.4);
    const double r = 0.3;
    auto ring_about = [&](const glm::dvec3& axis, double h) {
        const glm::dvec3 a = glm::normalize(axis);
        const glm::dvec3 u = glm::normalize(glm::cross(a, std::abs(a.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0)));
        const double rr = std::sqrt(r * r - h * h);
        return loop(c + h * a, u, glm::cross(a, u), rr, rr, 240);
    };
    const std::vector<std::vector<glm::vec3>> loops = {ring_about({0, 1, 0}, 0.06), ring_about({1, 0, 0}, -0.05),
                                                       ring_about({1, 0.3, 1}, 0.04)};
    auto off_sphere = [&](const TriangleMesh& m, bool centroids) {
        double worst = 0.0;
        for (const auto& t : m.triangles)
            for (int k = 0; k < (centroids ? 1 : 3); ++k) {
                const glm::dvec3 p = centroids ? (glm::dvec3(m.positions[static_cast<std::size_t>(t[0])]) +
                                                  glm::dvec3(m.positions[static_cast<std::size_t>(t[1])]) +
                                                  glm::dvec3(m.positions[static_cast<std::size_t>(t[2])])) / 3.0
                                               : glm::dvec3(m.positions[static_cast<std::size_t>(t[static_cast<std::size_t>(k)])]);
                worst = std::max(worst, std::abs(glm::distance(p, c) - r));
            }
        return worst;
    };
    struct Built {
        std::size_t fill = 0;
        double facets = 0.0, remeshed = 0.0;
        std::size_t triangles = 0;
    };
    auto build = [&](double coarseness) {
        LobeOptions o;
        o.surface.fill_coarseness = coarseness;
        Lobe lobe(o);
        for (std::size_t i = 0; i < loops.size(); ++i) lobe.add_stroke(static_cast<std::int64_t>(i + 1), loops[i]);
        const LobeSurface& surface = lobe.surface();
        expect_valid_lobe(surface.mesh, "before remeshing");
        Built b;
        for (const LobeVertexOrigin& v : surface.origins) b.fill += v.kind == LobeVertexKind::Fill ? 1 : 0;
        b.facets = off_sphere(surface.mesh, true);
        LobeRemeshStats stats;
        const TriangleMesh remeshed = remesh_lobe_surface(surface, RemeshOptions{}, nullptr, &stats);
        EXPECT_FALSE(stats.whole);
        expect_valid_lobe(remeshed, "remeshed");
        b.remeshed = off_sphere(remeshed, false);
        b.triangles = remeshed.triangles.size();
        return b;
    };
    const Built fine = build(1.0), coarse = build(2.0);
    // Measured: 1472 and 360 fill vertices; the fill's flat triangles up to 2.0 and 6.8 mm
    // inside the sphere at their centroids; remeshed, every vertex within 0.97 and 1.45 mm of
    // it (the loops' centroid is not the sphere's centre, so the radius model only nearly
    // follows the sphere, fine fill or coarse).
    EXPECT_GT(fine.fill, 100u);
    EXPECT_LT(coarse.fill * 3, fine.fill) << "half the spacing, a quarter of the fill vertices, about";
    EXPECT_GT(coarse.facets, 0.005) << "the coarse fill's flat triangles lie inside the sphere";
    EXPECT_LT(fine.remeshed, 0.002) << "fill at the spacing";
    EXPECT_LT(coarse.remeshed, 0.002) << "coarse fill";
    // The same attractor density.
    EXPECT_NEAR(static_cast<double>(coarse.triangles), static_cast<double>(fine.triangles), 0.05 * static_cast<double>(fine.triangles));
}

TEST(Lobes, AStrokeInsertedBetweenTwoOthersOnlyChangesThatRegion)
{
    const glm::dvec3 c(0, 1.4, -0.4);
    Lobe lobe;
    lobe.add_stroke(1, sphere_ring(c, 0.15, -0.10));
    lobe.add_stroke(2, sphere_ring(c, 0.15, 0.0));
    lobe.add_stroke(3, sphere_ring(c, 0.15, 0.10));
    const glm::dvec3 centre = lobe.centre();
    // Triangles are compared by the directions of their vertices from the (unchanged)
    // centre: the triangulation, independent of where interpolated vertices are lifted to.
    using Dir = std::tuple<long, long, long>;
    auto dir = [&](const glm::vec3& p) {
        const glm::dvec3 d = glm::normalize(glm::dvec3(p) - centre);
        return Dir{std::lround(d.x * 2e3), std::lround(d.y * 2e3), std::lround(d.z * 2e3)};
    };
    auto key = [&](const TriangleMesh& m, const std::array<int, 3>& t) {
        std::array<Dir, 3> k;
        for (int i = 0; i < 3; ++i) k[static_cast<std::size_t>(i)] = dir(m.positions[static_cast<std::size_t>(t[i])]);
        std::rotate(k.begin(), std::min_element(k.begin(), k.end()), k.end());
        return k;
    };
    const LobeSurface s0 = lobe.surface();
    std::map<Dir, glm::vec3> position0;
    for (const glm::vec3& p : s0.mesh.positions) position0[dir(p)] = p;
    // Between the middle and the top loop.
    lobe.add_stroke(4, sphere_ring(c, 0.15, 0.05));
    ASSERT_EQ(lobe.centre(), centre) << "the centre stays, so the rest of the lobe keeps its triangles";
    const LobeSurface& s1 = lobe.surface();
    expect_valid_lobe(s1.mesh, "after insertion");
    std::set<std::array<Dir, 3>> after;
    for (const auto& t : s1.mesh.triangles) after.insert(key(s1.mesh, t));
    // Every triangle that changed lies between the middle and the top loop …
    std::size_t changed = 0, kept = 0;
    for (const auto& t : s0.mesh.triangles) {
        if (after.count(key(s0.mesh, t))) {
            ++kept;
            continue;
        }
        ++changed;
        for (int i = 0; i < 3; ++i) {
            const double h = s0.mesh.positions[static_cast<std::size_t>(t[i])].y - c.y;
            EXPECT_GE(h, -0.001) << "a triangle below the middle loop changed";
            EXPECT_LE(h, 0.101) << "a triangle above the top loop changed";
        }
    }
    EXPECT_GT(changed, 0u);
    EXPECT_GT(kept, 2 * changed);
    // … and every vertex outside that strip, stroke or interpolated, stays exactly where it was
    // (the regions the stroke did not reach are kept bit for bit).
    std::size_t outside = 0;
    for (std::size_t i = 0; i < s1.mesh.positions.size(); ++i) {
        const glm::vec3& p = s1.mesh.positions[i];
        if (p.y - c.y > -0.001 && p.y - c.y < 0.101) continue;
        const auto it = position0.find(dir(p));
        ASSERT_NE(it, position0.end()) << "a vertex outside the strip is new";
        EXPECT_EQ(p, it->second);
        ++outside;
    }
    EXPECT_GT(outside, 100u);
    // The remeshed lobe too: every remeshed triangle wholly below the middle loop or above the
    // top one is found, bit for bit, in the remeshing after the stroke.
    RemeshOptions remesh;
    remesh.iterations = 4;
    LobeRemeshCache cache;
    const TriangleMesh r0 = remesh_lobe_surface(s0, remesh, &cache);
    LobeRemeshStats stats;
    const TriangleMesh r1 = remesh_lobe_surface(s1, remesh, &cache, &stats);
    EXPECT_EQ(stats.remeshed, 2) << "the strip, now two strips";
    EXPECT_EQ(stats.reused, stats.regions - 2);
    std::set<std::array<std::array<float, 3>, 3>> after_remesh;
    for (const auto& t : r1.triangles) after_remesh.insert(corners(r1, t));
    std::size_t away = 0;
    for (const auto& t : r0.triangles) {
        bool in_strip = false;
        for (int v : t) {
            const double h = r0.positions[static_cast<std::size_t>(v)].y - c.y;
            in_strip = in_strip || (h > -0.001 && h < 0.101);
        }
        if (in_strip) continue;
        ++away;
        EXPECT_TRUE(after_remesh.count(corners(r0, t))) << "a remeshed triangle away from the new stroke changed";
    }
    EXPECT_GT(away, 100u);
}

TEST(Lobes, ARingDrawnBetweenTwoRingsAcrossSixLoopsChangesOnlyTheCellsBetweenThem)
{
    // Fig. 5 on a lobe whose strokes cross: six loops through both poles at 30° steps and four
    // rings. Where the six loops meet, which of them are found to cross where must not depend
    // on the projection the new ring moves, or the cells round the poles change too.
    const glm::dvec3 c(0, 1.4, -0.45);
    const double r = 0.2;
    Lobe lobe;
    std::int64_t id = 0;
    for (int k = 0; k < 6; ++k) {
        const double a = k * kPi / 6;
        lobe.add_stroke(++id, loop(c, {0, 1, 0}, {std::cos(a), 0, std::sin(a)}, r, r, 160, 0.005, 0.1 * k));
    }
    for (double h : {-0.15, -0.08, 0.08, 0.15}) lobe.add_stroke(++id, sphere_ring(c, r, h));
    const LobeSurface before = lobe.surface();
    const int regions_before = lobe.last_kept().regions;
    // Round the equator, between the two middle rings: it splits each of the 12 cells between
    // them in two.
    lobe.add_stroke(++id, sphere_ring(c, r, 0.0));
    const LobeSurface& after = lobe.surface();
    expect_valid_lobe(after.mesh, "after the ring");
    ASSERT_EQ(after.centre, before.centre);
    EXPECT_TRUE(lobe.last_kept().built_changed_only);
    EXPECT_EQ(lobe.last_kept().regions, regions_before + 12);
    EXPECT_EQ(lobe.last_kept().kept, regions_before - 12) << "every region but the 12 cells between the middle rings";
    std::set<std::array<std::array<float, 3>, 3>> now;
    for (const auto& t : after.mesh.triangles) now.insert(corners(after.mesh, t));
    std::size_t kept = 0;
    for (const auto& t : before.mesh.triangles) {
        if (now.count(corners(before.mesh, t))) {
            ++kept;
            continue;
        }
        for (int v : t) {
            const double h = before.mesh.positions[static_cast<std::size_t>(v)].y - c.y;
            EXPECT_LE(std::abs(h), 0.081) << "a triangle outside the band between the middle rings changed";
        }
    }
    EXPECT_GT(kept, before.mesh.triangles.size() / 2);
}

TEST(Lobes, BadStrokesAreRefusedWithOneLineAndTheLobeUnchanged)
{
    const glm::dvec3 c(0, 1.4, -0.4);
    Lobe lobe;
    const auto ring = loop(c, {1, 0, 0}, {0, 0, 1}, 0.15, 0.15);
    lobe.add_stroke(1, ring);
    lobe.add_stroke(2, loop(c, {1, 0, 0}, {0, 1, 0}, 0.15, 0.15));
    const TriangleMesh before = lobe.surface().mesh;
    auto expect_refused = [&](const std::vector<glm::vec3>& pts, const std::string& what) {
        SCOPED_TRACE(what);
        try {
            lobe.add_stroke(99, pts);
            ADD_FAILURE() << "accepted";
        } catch (const InvalidInput& e) {
            const std::string msg = e.what();
            EXPECT_EQ(msg.find('\n'), std::string::npos);
            EXPECT_FALSE(msg.empty());
        }
        EXPECT_EQ(lobe.strokes().size(), 2u);
        EXPECT_EQ(lobe.surface().mesh.positions, before.positions);
        EXPECT_EQ(lobe.surface().mesh.triangles, before.triangles);
    };
    expect_refused({glm::vec3(c), glm::vec3(c) + glm::vec3(0.01f, 0, 0), glm::vec3(c) + glm::vec3(0.02f, 0, 0)}, "3 points");
    expect_refused(std::vector<glm::vec3>(50, glm::vec3(c) + glm::vec3(0.1f, 0, 0)), "zero length");
    std::vector<glm::vec3> line;
    for (int i = 0; i < 50; ++i) line.emplace_back(glm::vec3(c) + glm::vec3(0.005f * static_cast<float>(i), 0.1f, 0.0f));
    expect_refused(line, "collinear");
    auto nan = ring;
    nan[10].y = std::numeric_limits<float>::quiet_NaN();
    expect_refused(nan, "NaN");
    auto huge = ring;
    huge[10].x = 1e30f;
    expect_refused(huge, "enormous");
    expect_refused(ring, "identical to stroke 1");
    // A stroke that folds back over itself seen from the centre: a zigzag along one meridian.
    std::vector<glm::vec3> fold;
    for (int i = 0; i < 60; ++i) {
        const double t = (i < 30 ? i : 60 - i) * 0.02;
        fold.emplace_back(c + glm::dvec3(0.15 * std::cos(t), 0.15 * std::sin(t), (i < 30 ? 0.0 : 0.004)));
    }
    expect_refused(fold, "folding back");
    // Through the lobe's inside, near its centre.
    std::vector<glm::vec3> through;
    for (int i = 0; i < 60; ++i) through.emplace_back(c + glm::dvec3(-0.15 + 0.005 * i, 0.002 * std::sin(i * 0.3), 0.001 * (i - 30)));
    expect_refused(through, "through the centre");
}

TEST(Lobes, AnArcDrawnBackToItsStartIsRefusedRatherThanLeavingTheSurfaceOpen)
{
    // Two rings, then a 2 cm arc and back along it until its ends met: judged closed, a loop
    // that encloses nothing, whose region of the triangulation has no area. The surface had an
    // open border there (fuzz/lobe_strokes_fuzz.cpp found it). Now such a stroke is refused
    // when it is sampled and the lobe stays as it was; and a build given such a loop anyway
    // refuses the open surface.
    const std::string path = test::source_data("tests/data/lobe-strokes/arc-and-back-to-its-start.txt");
    if (path.empty()) return;
    std::ifstream in(path);
    ASSERT_TRUE(in.good());
    std::vector<std::vector<glm::vec3>> strokes;
    for (std::string line; std::getline(in, line);) {
        if (line.empty() || line[0] == '#') continue;
        std::istringstream words(line);
        int id = 0;
        words >> id;
        std::vector<glm::vec3> raw;
        for (float x, y, z; words >> x >> y >> z;) raw.emplace_back(x, y, z);
        strokes.push_back(raw);
    }
    ASSERT_EQ(strokes.size(), 3u);
    Lobe lobe;
    lobe.add_stroke(1, strokes[0]);
    lobe.add_stroke(2, strokes[1]);
    const TriangleMesh before = lobe.surface().mesh;
    try {
        lobe.add_stroke(3, strokes[2]);
        ADD_FAILURE() << "accepted";
    } catch (const InvalidInput& e) {
        // A closed stroke enclosing nothing: refused before any build.
        EXPECT_NE(std::string(e.what()).find("lobe stroke 3 retraces itself"), std::string::npos) << e.what();
    }
    EXPECT_EQ(lobe.strokes().size(), 2u);
    EXPECT_EQ(lobe.surface().mesh.positions, before.positions);
    EXPECT_EQ(lobe.surface().mesh.triangles, before.triangles);
    // Its points as samples (the last, which repeats the first, left out): the whole build
    // leaves the surface open there, and refuses it.
    std::vector<LobeStrokeSamples> all = lobe.strokes();
    LobeStrokeSamples arc;
    arc.id = 3;
    arc.points.assign(strokes[2].begin(), strokes[2].end() - 1);
    arc.closed = true;
    all.push_back(arc);
    try {
        build_lobe_surface(all, lobe.centre());
        ADD_FAILURE() << "the whole build accepted it";
    } catch (const InvalidInput& e) {
        EXPECT_NE(std::string(e.what()).find("leave its surface open"), std::string::npos) << e.what();
    }
}

TEST(Lobes, StrokesFarFromEveryLobeAndTheNewLobeKeyStartNewLobes)
{
    const glm::dvec3 a(0, 1.4, -0.4), b(0.6, 1.4, -0.4);
    auto stroke = [](std::int64_t id, const std::vector<glm::vec3>& pts) {
        InputAction act;
        act.type = InputAction::Type::StrokeCompleted;
        act.stroke.id = id;
        act.stroke.kind = StrokeKind::Lobe;
        double t = 0;
        for (const glm::vec3& p : pts) act.stroke.points.push_back({p, t += 0.01});
        return act;
    };
    SessionBuilder sb;
    sb.apply(stroke(1, loop(a, {1, 0, 0}, {0, 0, 1}, 0.15, 0.15)));
    sb.apply(stroke(2, loop(a, {1, 0, 0}, {0, 1, 0}, 0.15, 0.15)));
    sb.apply(stroke(3, loop(b, {1, 0, 0}, {0, 0, 1}, 0.12, 0.12))); // far away: a new lobe
    sb.apply(stroke(4, loop(a, {0, 1, 0}, {0, 0, 1}, 0.14, 0.14))); // back into the first
    const Document& doc = sb.document();
    ASSERT_EQ(doc.lobes.size(), 2u);
    EXPECT_EQ(doc.lobes[0].stroke_ids, (std::vector<std::int64_t>{1, 2, 4}));
    EXPECT_EQ(doc.lobes[1].stroke_ids, (std::vector<std::int64_t>{3}));
    const auto lobes = build_document_lobes(doc);
    ASSERT_EQ(lobes.size(), 2u);
    for (const auto& l : lobes) expect_valid_lobe(l.mesh, "lobe " + std::to_string(l.lobe_id));
}

// ---------------------------------------------------------------------------------------
// Edits survive rebuilding.

TEST(Lobes, APinchEditSurvivesALaterStrokeAndAReload)
{
    const glm::dvec3 c(0, 1.4, -0.4);
    Document doc;
    auto add = [&](std::int64_t id, const std::vector<glm::vec3>& pts) {
        Stroke s;
        s.id = id;
        s.kind = StrokeKind::Lobe;
        double t = 0;
        for (const glm::vec3& p : pts) s.points.push_back({p, t += 0.01});
        doc.strokes.push_back(s);
        if (doc.lobes.empty()) doc.lobes.push_back(LobeRecord::of_strokes(1));
        doc.lobes[0].stroke_ids.push_back(id);
    };
    add(1, loop(c, {1, 0, 0}, {0, 0, 1}, 0.15, 0.15));
    add(2, loop(c, {1, 0, 0}, {0, 1, 0}, 0.15, 0.15));
    add(3, loop(c, {0, 1, 0}, {0, 0, 1}, 0.15, 0.15));
    const glm::vec3 from(c + glm::dvec3(0.106, 0.0, 0.106)); // on the equator, between strokes
    const glm::vec3 to = from + glm::vec3(0.035f, 0.0f, 0.035f);
    EditOperation op;
    op.id = 1;
    op.params = DeformLobeParams{};
    op.path = {{glm::dvec3(from), 0.0}, {glm::dvec3(to), 1.0}};
    doc.edits.push_back(op);
    auto handle_moved = [&](const Document& d) {
        const auto lobes = build_document_lobes(d);
        EXPECT_EQ(lobes.size(), 1u);
        EXPECT_EQ(lobes[0].edits_applied, 1u);
        expect_valid_lobe(lobes[0].mesh, "edited");
        // Something reaches the pulled-out position.
        double best = 1e9;
        for (const glm::vec3& p : lobes[0].mesh.positions) best = std::min(best, static_cast<double>(glm::distance(p, to)));
        return best;
    };
    EXPECT_LT(handle_moved(doc), 0.02);
    // A later stroke on the far side.
    add(4, loop(c + glm::dvec3(0, -0.08, 0), {1, 0, 0}, {0, 0, 1}, 0.125, 0.125));
    EXPECT_LT(handle_moved(doc), 0.02);
    // Save and reload.
    const std::string path = test::temp_dir("pinch-survives") + "/session.json";
    save_document(path, doc);
    EXPECT_LT(handle_moved(load_document(path)), 0.02);
}

TEST(Lobes, TheLobeFollowsStrokeEditsMovesRotationsAndScales)
{
    // The scripted recording: five loops, then a Bézier stroke edit, a move, a rotation and a
    // scale. Replayed with the meshing stage's hooks, as `lobesketch replay` does.
    const std::string rec_path = test::source_data("recordings/edit-stroke-transform.lrec");
    if (rec_path.empty()) return;
    const Recording rec = read_recording(rec_path);
    const InputResult r = run_input_pipeline(rec);
    SessionBuilder b(Document{}, EditPickOptions{}, meshing_edit_hooks());
    b.apply(r.actions);
    const Document doc = b.take_document();
    ASSERT_EQ(doc.edits.size(), 4u);
    std::vector<std::string> warnings;
    const auto lobes = build_document_lobes(doc, &warnings);
    for (const std::string& w : warnings) ADD_FAILURE() << w;
    ASSERT_EQ(lobes.size(), 1u);
    expect_valid_lobe(lobes[0].mesh, "edited lobe");
    // Every point of the strokes where the person now sees them (bent, moved, rotated,
    // scaled) lies on the lobe.
    // Where the bent stroke crosses the loops it was pulled away from, the lobe passes
    // between them (crossings take the mean), so the bound there is looser; without the
    // edits applied the bent part would be 5 cm off and everything 6 cm off after the move.
    std::vector<double> d;
    for (const Stroke& s : effective_strokes(doc))
        for (std::size_t i = 0; i < s.points.size(); i += 4)
            d.push_back(distance_to_mesh(glm::dvec3(s.points[i].position), lobes[0].mesh));
    std::sort(d.begin(), d.end());
    EXPECT_LE(d[d.size() * 9 / 10], 0.004) << "90th percentile";
    EXPECT_LE(d.back(), 0.015) << "worst";
}

} // namespace
} // namespace lobe
