// Progressive lobes against lobes built from scratch: a lobe whose strokes were added one at
// a time (and removed again) has the surface that build_lobe_surface makes from the same
// strokes around the same centre, and building twice gives the same bytes (replay).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <iostream>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "core/errors.h"
#include "meshing/lobe.h"
#include "app/session/lobe_cache.h"
#include "app/session/stage_options.h"
#include "meshing/lobe_regions.h"
#include "meshing/lobe_remesh.h"
#include "meshing/mesh_quality.h"
#include "meshing/repair.h"
#include "tests/support/replay_fixture.h"
#include "tests/support/shapes.h"
#include "tests/support/test_data.h"

namespace lobe {
namespace {

constexpr double kPi = 3.14159265358979323846;

using test::raw_loop;

/// The benchmark's lobe: its ten strokes (six loops through the centre 30° apart, four
/// stacked rings) and a loop tilted by 45° as the eleventh stroke.
std::vector<std::vector<glm::vec3>> eleven_strokes()
{
    const glm::dvec3 c(0.0, 1.4, -0.45);
    const double r = 0.2;
    std::vector<std::vector<glm::vec3>> s = test::ten_stroke_lobe();
    s.push_back(raw_loop(c, glm::normalize(glm::dvec3(1, 1, 0)), {0, 0, 1}, r, 11));
    return s;
}

/// Stacked rings drawn out of order, a tilted loop across them, open arcs over the top.
std::vector<std::vector<glm::vec3>> rings_and_arcs()
{
    const glm::dvec3 c(0.1, 1.2, -0.3);
    const double r = 0.15;
    std::vector<std::vector<glm::vec3>> s;
    for (double h : {-0.1, 0.0, 0.1, 0.05, -0.05})
        s.push_back(raw_loop(c + glm::dvec3(0, h, 0), {1, 0, 0}, {0, 0, 1}, std::sqrt(r * r - h * h), static_cast<int>(h * 100)));
    s.push_back(raw_loop(c, glm::normalize(glm::dvec3(1, 0.3, 0)), glm::normalize(glm::dvec3(0, 0.2, 1)), r, 3));
    for (int k = 0; k < 2; ++k) {
        std::vector<glm::vec3> arc;
        const double phi = 0.4 + k * kPi / 2;
        for (int i = 0; i <= 60; ++i) {
            const double th = 0.75 + (kPi - 1.5) * i / 60.0;
            arc.emplace_back(c + r * glm::dvec3(std::cos(th) * std::cos(phi), std::sin(th), std::cos(th) * std::sin(phi)));
        }
        s.push_back(arc);
    }
    return s;
}

/// Seeded random drawings: loops of random size, tilt and wobble round a centre, and (after
/// the first stroke, three times in ten) arcs over them, raw points 5 mm apart.
struct RandomDrawing {
    std::uint32_t state;
    double uniform(double lo, double hi)
    {
        state = state * 1664525u + 1013904223u;
        return lo + (hi - lo) * static_cast<double>(state >> 8) / static_cast<double>(1u << 24);
    }
    glm::dvec3 centre()
    {
        const double x = uniform(-0.3, 0.3), y = uniform(1.0, 1.6), z = uniform(-0.6, -0.2);
        return {x, y, z};
    }
    /// Stroke k (from 0) of a lobe of radius r round c.
    std::vector<glm::vec3> stroke(const glm::dvec3& c, double r, int k)
    {
        std::vector<glm::vec3> raw;
        const double tilt = uniform(0.0, kPi), turn = uniform(0.0, 2 * kPi);
        const glm::dvec3 axis(std::sin(tilt) * std::cos(turn), std::cos(tilt), std::sin(tilt) * std::sin(turn));
        const glm::dvec3 u = glm::normalize(glm::cross(axis, glm::dvec3(0.3, 0.1, 0.9)));
        const glm::dvec3 v = glm::cross(axis, u);
        const double h = uniform(-0.6, 0.6) * r, rr = std::sqrt(r * r - h * h);
        const bool arc = k > 0 && uniform(0.0, 1.0) < 0.3;
        const int n = static_cast<int>(2 * kPi * rr / 0.005);
        for (int i = 0; i < n; ++i) {
            const double t = (arc ? 0.45 : 1.0) * 2 * kPi * i / n;
            const double w = 0.002 * std::sin(5 * t + k);
            raw.emplace_back(c + h * axis + (rr + w) * (std::cos(t) * u + std::sin(t) * v));
        }
        return raw;
    }
};

void expect_valid(const TriangleMesh& mesh, const std::string& what)
{
    const MeshQuality q = measure_quality(mesh);
    EXPECT_TRUE(q.closed) << what;
    EXPECT_TRUE(q.manifold) << what;
    EXPECT_TRUE(q.outward) << what;
    EXPECT_EQ(q.components, 1u) << what;
    EXPECT_FALSE(self_intersects(mesh)) << what;
}

/// The lobe's surface against build_lobe_surface on the same strokes, around the same centre
/// and with the same fill density: same vertices (within 1 µm; they come out identical), same
/// triangles, same feature edges, same origins.
void expect_from_scratch(const Lobe& lobe, const std::string& what)
{
    const LobeSurface& kept = lobe.surface();
    LobeSurfaceOptions options;
    options.reference_radius_m = kept.reference_radius;
    const LobeSurface scratch = build_lobe_surface(lobe.strokes(), lobe.centre(), options);
    ASSERT_EQ(kept.mesh.positions.size(), scratch.mesh.positions.size()) << what;
    double worst = 0;
    for (std::size_t i = 0; i < kept.mesh.positions.size(); ++i)
        worst = std::max(worst, static_cast<double>(glm::distance(kept.mesh.positions[i], scratch.mesh.positions[i])));
    EXPECT_LE(worst, 1e-6) << what;
    EXPECT_EQ(kept.mesh.triangles, scratch.mesh.triangles) << what;
    EXPECT_EQ(kept.mesh.feature_edges, scratch.mesh.feature_edges) << what;
    ASSERT_EQ(kept.origins.size(), scratch.origins.size()) << what;
    for (std::size_t i = 0; i < kept.origins.size(); ++i) {
        EXPECT_EQ(kept.origins[i].kind, scratch.origins[i].kind) << what << " vertex " << i;
        EXPECT_EQ(kept.origins[i].stroke, scratch.origins[i].stroke) << what << " vertex " << i;
        EXPECT_EQ(kept.origins[i].sample, scratch.origins[i].sample) << what << " vertex " << i;
    }
    EXPECT_EQ(kept.crossings, scratch.crossings) << what;
    EXPECT_EQ(kept.paper_strip_triangles, scratch.paper_strip_triangles) << what;
    expect_valid(kept.mesh, what);
}

/// A region's triangles by the positions of their corners, each starting at its least
/// corner, sorted: the same for two surfaces exactly when the region is the same bit for bit.
using PositionTriangles = std::vector<std::array<float, 9>>;
std::map<std::vector<RegionStrokeEdge>, PositionTriangles> regions_by_stroke_edges(const TriangleMesh& mesh)
{
    const MeshRegions regions = mesh_regions(mesh);
    const auto keys = region_stroke_edges(mesh, regions);
    std::vector<PositionTriangles> tris(keys.size());
    for (std::size_t f = 0; f < mesh.triangles.size(); ++f) {
        std::array<std::array<float, 3>, 3> c{};
        for (int k = 0; k < 3; ++k) {
            const glm::vec3& p = mesh.positions[static_cast<std::size_t>(mesh.triangles[f][static_cast<std::size_t>(k)])];
            c[static_cast<std::size_t>(k)] = {p.x, p.y, p.z};
        }
        const std::size_t first = static_cast<std::size_t>(std::min_element(c.begin(), c.end()) - c.begin());
        std::array<float, 9> t{};
        for (std::size_t k = 0; k < 3; ++k)
            for (std::size_t j = 0; j < 3; ++j) t[3 * k + j] = c[(first + k) % 3][j];
        tris[static_cast<std::size_t>(regions.face_region[f])].push_back(t);
    }
    std::map<std::vector<RegionStrokeEdge>, PositionTriangles> out;
    for (std::size_t r = 0; r < keys.size(); ++r) {
        std::sort(tris[r].begin(), tris[r].end());
        out.emplace(keys[r], std::move(tris[r]));
    }
    return out;
}

/// The lobe's surface after a stroke was added, against build_lobe_surface on the same
/// strokes around the same centre: the same stroke vertices, stroke edges and regions, and
/// every region either the from-scratch build's or, bit for bit, the one with the same stroke
/// edges in `before` (the surface before the stroke). The regions the lobe keeps for the next
/// stroke (handed on by the builder and the kept regions) are those of its surface. Returns
/// how many were kept from `before`.
int expect_scratch_or_kept_regions(const Lobe& lobe, const LobeSurface& before, const std::string& what)
{
    const LobeSurface& kept = lobe.surface();
    const SurfaceRegions found = surface_regions(kept.mesh);
    EXPECT_EQ(lobe.regions().regions.count, found.regions.count) << what;
    EXPECT_TRUE(lobe.regions().regions.face_region == found.regions.face_region) << what << ": regions handed on differ";
    EXPECT_TRUE(lobe.regions().edges == found.edges) << what << ": regions' stroke edges handed on differ";
    LobeSurfaceOptions options;
    options.reference_radius_m = kept.reference_radius;
    const LobeSurface scratch = build_lobe_surface(lobe.strokes(), lobe.centre(), options);
    std::vector<glm::vec3> kept_strokes, scratch_strokes;
    for (std::size_t i = 0; i < kept.origins.size(); ++i)
        if (kept.origins[i].kind != LobeVertexKind::Fill) kept_strokes.push_back(kept.mesh.positions[i]);
    for (std::size_t i = 0; i < scratch.origins.size(); ++i)
        if (scratch.origins[i].kind != LobeVertexKind::Fill) scratch_strokes.push_back(scratch.mesh.positions[i]);
    EXPECT_TRUE(kept_strokes == scratch_strokes) << what;
    EXPECT_EQ(kept.crossings, scratch.crossings) << what;
    EXPECT_EQ(kept.paper_strip_triangles, scratch.paper_strip_triangles) << what;
    // The same stroke edges, by the positions of their ends.
    auto stroke_edges = [](const LobeSurface& s) {
        std::set<std::array<float, 6>> out;
        for (const auto& e : s.mesh.feature_edges) {
            glm::vec3 a = s.mesh.positions[static_cast<std::size_t>(e[0])], b = s.mesh.positions[static_cast<std::size_t>(e[1])];
            if (std::tie(b.x, b.y, b.z) < std::tie(a.x, a.y, a.z)) std::swap(a, b);
            out.insert({a.x, a.y, a.z, b.x, b.y, b.z});
        }
        return out;
    };
    EXPECT_TRUE(stroke_edges(kept) == stroke_edges(scratch)) << what << ": stroke edges differ";
    const auto now = regions_by_stroke_edges(kept.mesh);
    const auto fresh = regions_by_stroke_edges(scratch.mesh);
    const auto old = regions_by_stroke_edges(before.mesh);
    EXPECT_EQ(now.size(), fresh.size()) << what;
    int from_before = 0;
    for (const auto& [key, tris] : now) {
        const auto f = fresh.find(key);
        EXPECT_TRUE(f != fresh.end()) << what << ": a region the build from scratch does not have";
        const auto o = old.find(key);
        if (o != old.end()) {
            EXPECT_EQ(tris, o->second) << what << ": a region the stroke left is not kept bit for bit";
            ++from_before;
        } else if (f != fresh.end()) {
            EXPECT_EQ(tris, f->second) << what << ": a changed region is not the build from scratch's";
        }
    }
    EXPECT_EQ(from_before, lobe.last_kept().kept) << what;
    expect_valid(kept.mesh, what);
    return from_before;
}

bool same_bytes(const LobeSurface& a, const LobeSurface& b)
{
    return a.mesh.positions.size() == b.mesh.positions.size() && a.mesh.triangles == b.mesh.triangles &&
           a.mesh.feature_edges == b.mesh.feature_edges &&
           std::memcmp(a.mesh.positions.data(), b.mesh.positions.data(), a.mesh.positions.size() * sizeof(glm::vec3)) == 0;
}

TEST(LobeIncremental, AStrokeChangesOnlyTheRegionsItReachesAndTheRestIsKeptBitForBit)
{
    for (const auto& [name, strokes] : {std::pair{"eleven strokes", eleven_strokes()}, std::pair{"rings and arcs", rings_and_arcs()}}) {
        Lobe lobe;
        std::size_t added = 0;
        std::vector<int> kept;
        for (std::size_t i = 0; i < strokes.size(); ++i) {
            const std::string what = std::string(name) + ", stroke " + std::to_string(i + 1);
            const LobeSurface before = lobe.empty() ? LobeSurface{} : lobe.surface();
            const glm::dvec3 centre = lobe.centre();
            try {
                lobe.add_stroke(static_cast<std::int64_t>(i + 1), strokes[i]);
            } catch (const InvalidInput& e) {
                ADD_FAILURE() << what << " refused: " << e.what();
                continue;
            }
            ++added;
            if (i == 0 || centre != lobe.centre()) {
                // A new lobe, or one whose centre moved, is laid afresh.
                EXPECT_EQ(lobe.last_kept().kept, 0) << what;
                expect_from_scratch(lobe, what);
            } else {
                kept.push_back(expect_scratch_or_kept_regions(lobe, before, what));
            }
        }
        EXPECT_EQ(added, strokes.size()) << name;
        for (int k : kept) std::cout << name << ": " << k << " regions kept\n";
        // Removing strokes again (the last, then the first) lays the surface afresh.
        ASSERT_TRUE(lobe.remove_stroke(static_cast<std::int64_t>(strokes.size())));
        expect_from_scratch(lobe, std::string(name) + ", last stroke removed");
        ASSERT_TRUE(lobe.remove_stroke(1));
        expect_from_scratch(lobe, std::string(name) + ", first stroke removed");
    }
}

TEST(LobeIncremental, EveryShippedLobeStrokeRemeshesOnlyTheRegionsItChangedAndKeepsTheRestBitForBit)
{
    // Every lobe of the shipped recordings, its strokes added one at a time as drawn, remeshed
    // after each with the regions of the last remeshing kept (as the regrowth worker keeps them).
    std::size_t strokes = 0, regions = 0, remeshed = 0, triangles = 0, unchanged = 0;
    std::vector<double> shares; // per stroke: share of the remeshed lobe's triangles kept
    for (const char* name : {"table1-1lobe-5strokes", "table1-3lobes-16strokes", "table1-4lobes-22strokes", "pinch-edit"}) {
        if (test::source_data(std::string("recordings/") + name + ".lrec").empty()) return;
        const Document doc = test::replay_document(name);
        RemeshOptions remesh;
        remesh.target_edge_length_m = doc.settings.lobes.edge_length_m;
        remesh.iterations = static_cast<unsigned>(doc.settings.lobes.remesh_iterations);
        for (const LobeRecord& rec : doc.lobes) {
            Lobe lobe(lobe_options(doc.settings));
            LobeRemeshCache cache;
            TriangleMesh before;
            for (std::int64_t id : rec.stroke_ids) {
                const std::string what = std::string(name) + " lobe " + std::to_string(rec.id) + " stroke " + std::to_string(id);
                const auto it = std::find_if(doc.strokes.begin(), doc.strokes.end(), [&](const Stroke& s) { return s.id == id; });
                ASSERT_NE(it, doc.strokes.end()) << what;
                std::vector<glm::vec3> raw;
                for (const StrokePoint& p : it->points) raw.push_back(p.position);
                const glm::dvec3 centre = lobe.centre();
                const bool first = lobe.empty();
                lobe.add_stroke(id, raw);
                LobeRemeshStats stats;
                const TriangleMesh mesh = remesh_lobe_surface(lobe.surface(), remesh, &cache, &stats);
                ASSERT_FALSE(stats.whole) << what;
                // The cache changes nothing but the time.
                LobeRemeshStats fresh_stats;
                const TriangleMesh fresh = remesh_lobe_surface(lobe.surface(), remesh, nullptr, &fresh_stats);
                EXPECT_TRUE(fresh.positions == mesh.positions) << what;
                EXPECT_EQ(fresh.triangles, mesh.triangles) << what;
                EXPECT_EQ(fresh.feature_edges, mesh.feature_edges) << what;
                EXPECT_EQ(fresh_stats.remeshed, stats.regions) << what;
                expect_valid(mesh, what);
                if (!first && centre == lobe.centre()) {
                    // Remeshed: the regions the surface did not keep, no more.
                    EXPECT_EQ(stats.remeshed, stats.regions - lobe.last_kept().kept) << what;
                    EXPECT_EQ(stats.reused, lobe.last_kept().kept) << what;
                    ++strokes;
                    regions += static_cast<std::size_t>(stats.regions);
                    remeshed += static_cast<std::size_t>(stats.remeshed);
                    // Triangles of the remeshed lobe found bit for bit in the one before.
                    std::set<std::array<float, 9>> old;
                    for (const auto& [key, tris] : regions_by_stroke_edges(before)) old.insert(tris.begin(), tris.end());
                    std::size_t n = 0, kept = 0;
                    for (const auto& [key, tris] : regions_by_stroke_edges(mesh)) {
                        n += tris.size();
                        for (const auto& t : tris) kept += old.count(t);
                    }
                    triangles += n;
                    unchanged += kept;
                    shares.push_back(static_cast<double>(kept) / static_cast<double>(n));
                }
                before = mesh;
            }
        }
    }
    ASSERT_GT(strokes, 20u);
    std::cout << strokes << " strokes added to a lobe whose centre stayed: " << remeshed << " of " << regions
              << " regions remeshed, " << unchanged << " of " << triangles << " remeshed triangles kept bit for bit";
    std::sort(shares.begin(), shares.end());
    std::cout << "; per stroke, quartiles of the share kept: " << shares[shares.size() / 4] << ", "
              << shares[shares.size() / 2] << ", " << shares[3 * shares.size() / 4] << "\n";
    // A stroke drawn round a lobe crosses most of its strokes, so it changes much of it: of
    // the 39 strokes, the median keeps 9 % of the remeshed triangles and the upper quartile half
    // (GCC build); 24 % in all. Without region-by-region remeshing nothing was kept.
    EXPECT_LT(remeshed, regions);
    EXPECT_GT(100 * unchanged, 15 * triangles);
}

TEST(LobeIncremental, ShippedAndRandomLobeStrokesBuildOnlyTheRegionsTheyChangeAndGiveTheWholeBuildsSurface)
{
    // Every lobe stroke of the shipped recordings and of seeded random drawings (loops of
    // random size and tilt, arcs over them), added one at a time: the surface built from the
    // changed regions alone has every region of the whole build (or, bit for bit, the one
    // before), and the changed regions alone are what was built for nearly every stroke that
    // left a region as it was (one that changes every region builds the whole surface).
    int continued = 0, leaving = 0, changed_only = 0;
    auto check = [&](Lobe& lobe, std::int64_t id, const std::vector<glm::vec3>& raw, const std::string& what) {
        const LobeSurface before = lobe.empty() ? LobeSurface{} : lobe.surface();
        const glm::dvec3 centre = lobe.centre();
        const bool first = lobe.empty();
        try {
            lobe.add_stroke(id, raw);
        } catch (const InvalidInput&) {
            return; // refused, the lobe as it was (tested elsewhere)
        }
        if (first || centre != lobe.centre()) {
            EXPECT_FALSE(lobe.last_kept().built_changed_only) << what;
            return;
        }
        expect_scratch_or_kept_regions(lobe, before, what);
        EXPECT_TRUE(lobe.last_kept().followed_previous_build) << what << ": the pole and crossings were searched anew";
        ++continued;
        if (lobe.last_kept().kept == 0) {
            EXPECT_FALSE(lobe.last_kept().built_changed_only) << what;
            return;
        }
        ++leaving;
        changed_only += lobe.last_kept().built_changed_only ? 1 : 0;
    };
    for (const char* name : {"table1-1lobe-5strokes", "table1-3lobes-16strokes", "table1-4lobes-22strokes", "pinch-edit"}) {
        if (test::source_data(std::string("recordings/") + name + ".lrec").empty()) return;
        const Document doc = test::replay_document(name);
        for (const LobeRecord& rec : doc.lobes) {
            Lobe lobe(lobe_options(doc.settings));
            for (std::int64_t id : rec.stroke_ids) {
                const auto it = std::find_if(doc.strokes.begin(), doc.strokes.end(), [&](const Stroke& s) { return s.id == id; });
                ASSERT_NE(it, doc.strokes.end());
                std::vector<glm::vec3> raw;
                for (const StrokePoint& p : it->points) raw.push_back(p.position);
                check(lobe, id, raw, std::string(name) + " lobe " + std::to_string(rec.id) + " stroke " + std::to_string(id));
            }
        }
    }
    const int shipped = continued;
    RandomDrawing random{777u};
    for (int lobe_index = 0; lobe_index < 12; ++lobe_index) {
        const glm::dvec3 c = random.centre();
        const double r = random.uniform(0.1, 0.3);
        Lobe lobe;
        for (int k = 0; k < 3 + lobe_index % 6; ++k) {
            const std::vector<glm::vec3> raw = random.stroke(c, r, k);
            check(lobe, k + 1, raw, "random lobe " + std::to_string(lobe_index) + ", stroke " + std::to_string(k + 1));
        }
    }
    std::cout << continued << " strokes added to a lobe whose centre stayed (" << shipped << " shipped), " << leaving
              << " of them left some region as it was: " << changed_only << " built from the changed regions alone\n";
    EXPECT_GE(shipped, 30);
    EXPECT_GE(continued - shipped, 20);
    // All of them, now that crossings are found on the sphere (the rest met a stroke edge the
    // triangulation split where strokes nearly touch).
    EXPECT_GE(100 * changed_only, 95 * leaving) << "strokes fell back to building the whole surface";
}

TEST(LobeIncremental, RandomLobesStayValidStrokeByStrokeAndTheirRemeshingDoesNotDependOnWhatWasKept)
{
    // Seeded random drawings: loops of random size, tilt and wobble round one centre and arcs
    // over them, added one at a time; after each, the lobe remeshed with the regions of the last
    // remeshing kept must be a valid lobe and the same bytes as a remeshing from nothing.
    RandomDrawing random{12345u};
    RemeshOptions remesh;
    remesh.iterations = 4;
    int checked = 0, whole = 0;
    for (int lobe_index = 0; lobe_index < 12; ++lobe_index) {
        const glm::dvec3 c = random.centre();
        const double r = random.uniform(0.1, 0.3);
        Lobe lobe;
        LobeRemeshCache cache;
        const int strokes = 2 + lobe_index % 5;
        for (int k = 0; k < strokes; ++k) {
            const std::vector<glm::vec3> raw = random.stroke(c, r, k);
            try {
                lobe.add_stroke(k + 1, raw);
            } catch (const InvalidInput&) {
                continue; // refused, the lobe as it was (tested elsewhere)
            }
            const std::string what = "random lobe " + std::to_string(lobe_index) + ", stroke " + std::to_string(k + 1);
            LobeRemeshStats stats;
            const TriangleMesh mesh = remesh_lobe_surface(lobe.surface(), remesh, &cache, &stats);
            const TriangleMesh fresh = remesh_lobe_surface(lobe.surface(), remesh);
            EXPECT_TRUE(fresh.positions == mesh.positions) << what;
            EXPECT_EQ(fresh.triangles, mesh.triangles) << what;
            expect_valid(mesh, what);
            ++checked;
            whole += stats.whole ? 1 : 0;
        }
    }
    std::cout << checked << " random lobe states, " << whole << " remeshed whole\n";
    EXPECT_GE(checked, 30);
    EXPECT_LT(whole, checked / 4) << "lobes remeshed whole instead of region by region";
}

TEST(LobeIncremental, KeptRegionsAreNotTakenForASurfaceAroundAnotherCentre)
{
    // Stacked rings: their strips are the paper's, with no inner vertex, so they stay the same
    // triangles whatever the centre; but each region is charted around the centre.
    Lobe lobe;
    const auto strokes = rings_and_arcs();
    for (std::size_t i = 0; i < 3; ++i) lobe.add_stroke(static_cast<std::int64_t>(i + 1), strokes[i]);
    RemeshOptions remesh;
    remesh.iterations = 4;
    LobeRemeshCache cache;
    remesh_lobe_surface(lobe.surface(), remesh, &cache);
    LobeSurface moved = lobe.surface();
    moved.centre += glm::dvec3(0.01, 0.02, -0.01);
    LobeRemeshStats stats;
    const TriangleMesh kept = remesh_lobe_surface(moved, remesh, &cache, &stats);
    const TriangleMesh fresh = remesh_lobe_surface(moved, remesh);
    EXPECT_EQ(stats.reused, 0);
    EXPECT_TRUE(kept.positions == fresh.positions);
    EXPECT_EQ(kept.triangles, fresh.triangles);
}

TEST(LobeIncremental, AWholeBuildOrdersItsInterpolatedVerticesByTheKeyKeptBuildsMergeBy)
{
    // build_lobe_surface puts its interpolated vertices in the order complete_with_kept_regions
    // gives them: by the direction of each stored (float) position. (GCC 12 once computed the
    // build's keys from the unrounded positions, so the two orders disagreed in the last bits.)
    const auto raw = eleven_strokes();
    std::vector<LobeStrokeSamples> strokes;
    std::size_t compared = 0;
    for (std::size_t i = 0; i < raw.size(); ++i) {
        strokes.push_back(prepare_lobe_stroke(static_cast<std::int64_t>(i + 1), raw[i]));
        if (strokes.size() < 2) continue;
        const glm::dvec3 centre = lobe_stroke_centroid(strokes);
        const LobeSurface surface = build_lobe_surface(strokes, centre);
        std::vector<FillOrderKey> keys;
        for (std::size_t v = 0; v < surface.mesh.positions.size(); ++v)
            if (surface.origins[v].kind == LobeVertexKind::Fill)
                keys.push_back(fill_order_key(surface.mesh.positions[v], surface.centre, static_cast<int>(v)));
        EXPECT_TRUE(std::is_sorted(keys.begin(), keys.end())) << "with " << strokes.size() << " strokes";
        compared += keys.size();
    }
    EXPECT_GE(compared, 2000u);
}

TEST(LobeIncremental, TheSameStrokesInTheSameOrderGiveTheSameBytes)
{
    const auto strokes = eleven_strokes();
    Lobe a, b;
    for (std::size_t i = 0; i < strokes.size(); ++i) {
        a.add_stroke(static_cast<std::int64_t>(i + 1), strokes[i]);
        b.add_stroke(static_cast<std::int64_t>(i + 1), strokes[i]);
        // A copy of a lobe (the refusal guarantee works on copies) goes on the same way.
        Lobe c = a;
        if (i + 1 < strokes.size()) {
            c.add_stroke(static_cast<std::int64_t>(i + 2), strokes[i + 1]);
            Lobe d = b;
            d.add_stroke(static_cast<std::int64_t>(i + 2), strokes[i + 1]);
            EXPECT_TRUE(same_bytes(c.surface(), d.surface())) << "after stroke " << i + 2;
        }
        EXPECT_TRUE(same_bytes(a.surface(), b.surface())) << "after stroke " << i + 1;
    }
}

TEST(LobeIncremental, ARefusedStrokeLeavesTheSurfaceAsItWas)
{
    const auto strokes = eleven_strokes();
    Lobe lobe;
    for (std::size_t i = 0; i < 10; ++i) lobe.add_stroke(static_cast<std::int64_t>(i + 1), strokes[i]);
    const LobeSurface before = lobe.surface();
    // Through the centre: refused.
    std::vector<glm::vec3> through;
    for (int i = 0; i <= 40; ++i)
        through.emplace_back(glm::dvec3(0.0, 1.4, -0.45) + glm::dvec3(0.01 * (i - 20), 0.0005 * (i - 20) * (i - 20), 0.0));
    EXPECT_THROW(lobe.add_stroke(99, through), InvalidInput);
    EXPECT_TRUE(same_bytes(before, lobe.surface()));
    lobe.add_stroke(11, strokes[10]);
    Lobe straight;
    for (std::size_t i = 0; i < 11; ++i) straight.add_stroke(static_cast<std::int64_t>(i + 1), strokes[i]);
    EXPECT_TRUE(same_bytes(straight.surface(), lobe.surface())) << "after a refusal";
}

} // namespace

namespace {

/// The lobes of two builds are the same, byte for byte, and so are their warnings.
void expect_same_build(const std::vector<BuiltLobe>& a, const std::vector<std::string>& wa,
                       const std::vector<BuiltLobe>& b, const std::vector<std::string>& wb, const std::string& what)
{
    EXPECT_EQ(wa, wb) << what;
    ASSERT_EQ(a.size(), b.size()) << what;
    for (std::size_t i = 0; i < a.size(); ++i) {
        const std::string lobe = what + ", lobe " + std::to_string(a[i].lobe_id);
        EXPECT_EQ(a[i].lobe_id, b[i].lobe_id) << lobe;
        EXPECT_EQ(a[i].stroke_ids, b[i].stroke_ids) << lobe;
        EXPECT_EQ(a[i].edits_applied, b[i].edits_applied) << lobe;
        EXPECT_TRUE(a[i].surface.mesh.positions == b[i].surface.mesh.positions) << lobe;
        EXPECT_EQ(a[i].surface.mesh.triangles, b[i].surface.mesh.triangles) << lobe;
        EXPECT_EQ(a[i].surface.mesh.feature_edges, b[i].surface.mesh.feature_edges) << lobe;
        EXPECT_TRUE(a[i].mesh.positions == b[i].mesh.positions) << lobe;
        EXPECT_EQ(a[i].mesh.triangles, b[i].mesh.triangles) << lobe;
    }
}

/// `doc` with each lobe cut to its first `k` strokes.
Document first_strokes(Document doc, std::size_t k)
{
    for (LobeRecord& l : doc.lobes)
        if (l.stroke_ids.size() > k) l.stroke_ids.resize(k);
    return doc;
}

} // namespace

TEST(LobeIncremental, AKeptBuildGivesTheLobesAndWarningsOfABuildFromScratchAndRebuildsOnlyWhatChanged)
{
    if (test::source_data("recordings/table1-3lobes-16strokes.lrec").empty()) return;
    const Document full = test::replay_document("table1-3lobes-16strokes");
    ASSERT_EQ(full.lobes.size(), 3u);
    std::size_t most = 0;
    for (const LobeRecord& l : full.lobes) most = std::max(most, l.stroke_ids.size());
    LobeBuildCache cache;
    auto check = [&](const Document& doc, const std::string& what, bool compare = true) {
        std::vector<std::string> wa, wb;
        const std::vector<BuiltLobe> kept = build_document_lobes(doc, &wa, cache);
        if (compare) expect_same_build(kept, wa, build_document_lobes(doc, &wb), wb, what);
        return cache.last_build();
    };
    std::size_t reused = 0;
    // Strokes drawn one at a time: a lobe that gained one continues, the others are kept.
    // (Compared with a build from scratch after the first, second, fourth and last strokes.)
    for (std::size_t k = 1; k <= most; ++k) {
        const Document doc = first_strokes(full, k);
        const LobeBuildCache::Counts c =
            check(doc, "first " + std::to_string(k) + " strokes of each lobe", k <= 2 || k == 4 || k == most);
        std::size_t grew = 0;
        for (const LobeRecord& l : full.lobes) grew += l.stroke_ids.size() >= k ? 1 : 0;
        EXPECT_EQ(c.built, k == 1 ? 3u : 0u) << k;
        EXPECT_EQ(c.continued, k == 1 ? 0u : grew) << k;
        EXPECT_EQ(c.kept, 3u - c.built - c.continued) << k;
        if (k > 1) reused += c.regions_reused;
    }
    // The lobes that gained a stroke took the regions it did not reach as remeshed before.
    EXPECT_GT(reused, 0u);
    // The same document again: nothing is built.
    EXPECT_EQ(check(full, "the same document").kept, 3u);
    // Undo down to two strokes: those lobes are built again.
    EXPECT_EQ(check(first_strokes(full, 2), "two strokes").built, 3u);
    // A stroke of the first lobe moved by a millimetre: that lobe is built again, not the others.
    Document moved = full;
    const std::int64_t second = moved.lobes[0].stroke_ids[1];
    for (Stroke& s : moved.strokes)
        if (s.id == second)
            for (StrokePoint& p : s.points) p.position.x += 0.001f;
    check(full, "all strokes");
    const LobeBuildCache::Counts c = check(moved, "a moved stroke");
    EXPECT_EQ(c.built, 1u);
    EXPECT_EQ(c.kept, 2u);
    // Another attractor spacing rebuilds every lobe; a deleted lobe is forgotten.
    Document spaced = moved;
    spaced.settings.lobes.edge_length_m = 0.04;
    EXPECT_EQ(check(spaced, "another spacing").built, 3u);
    spaced.lobes.erase(spaced.lobes.begin() + 1);
    EXPECT_EQ(check(spaced, "a deleted lobe").kept, 2u);
}

} // namespace lobe
