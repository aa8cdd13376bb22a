// Progressive lobes against lobes built from scratch: a lobe whose strokes were added one at
// a time (and removed again) has the surface that build_lobe_surface makes from the same
// strokes around the same centre, and building twice gives the same bytes (replay).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "core/errors.h"
#include "meshing/lobe.h"
#include "meshing/lobe_cache.h"
#include "meshing/mesh_quality.h"
#include "meshing/repair.h"
#include "tests/replay_fixture.h"

namespace lobe {
namespace {

constexpr double kPi = 3.14159265358979323846;

/// Raw stroke points 5 mm apart with 1 mm of wobble (as the lobe benchmark draws them).
std::vector<glm::vec3> raw_loop(const glm::dvec3& centre, const glm::dvec3& u, const glm::dvec3& v, double r, int seed)
{
    const int n = static_cast<int>(2 * kPi * r / 0.005);
    std::vector<glm::vec3> out;
    for (int i = 0; i < n; ++i) {
        const double t = 2 * kPi * i / n;
        const double w = 0.001 * std::sin(7 * t + seed);
        out.emplace_back(centre + (r + w) * (std::cos(t) * u + std::sin(t) * v));
    }
    return out;
}

/// The benchmark's lobe: six loops through the centre 30° apart, four stacked rings, and a
/// loop tilted by 45° as the eleventh stroke.
std::vector<std::vector<glm::vec3>> eleven_strokes()
{
    const glm::dvec3 c(0.0, 1.4, -0.45);
    const double r = 0.2;
    std::vector<std::vector<glm::vec3>> s;
    for (int k = 0; k < 6; ++k) {
        const double a = k * kPi / 6;
        s.push_back(raw_loop(c, {0, 1, 0}, {std::cos(a), 0, std::sin(a)}, r, k));
    }
    for (double h : {-0.15, -0.08, 0.08, 0.15})
        s.push_back(raw_loop(c + glm::dvec3(0, h, 0), {1, 0, 0}, {0, 0, 1}, std::sqrt(r * r - h * h), static_cast<int>(h * 100)));
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

bool same_bytes(const LobeSurface& a, const LobeSurface& b)
{
    return a.mesh.positions.size() == b.mesh.positions.size() && a.mesh.triangles == b.mesh.triangles &&
           a.mesh.feature_edges == b.mesh.feature_edges &&
           std::memcmp(a.mesh.positions.data(), b.mesh.positions.data(), a.mesh.positions.size() * sizeof(glm::vec3)) == 0;
}

TEST(LobeIncremental, StrokesAddedOneAtATimeGiveTheSurfaceBuiltFromScratch)
{
    for (const auto& [name, strokes] : {std::pair{"eleven strokes", eleven_strokes()}, std::pair{"rings and arcs", rings_and_arcs()}}) {
        Lobe lobe;
        std::size_t added = 0;
        for (std::size_t i = 0; i < strokes.size(); ++i) {
            const std::string what = std::string(name) + ", stroke " + std::to_string(i + 1);
            try {
                lobe.add_stroke(static_cast<std::int64_t>(i + 1), strokes[i]);
            } catch (const InvalidInput& e) {
                ADD_FAILURE() << what << " refused: " << e.what();
                continue;
            }
            ++added;
            expect_from_scratch(lobe, what);
        }
        EXPECT_EQ(added, strokes.size()) << name;
        // Removing strokes again (the last, then the first) gives the from-scratch surface too.
        ASSERT_TRUE(lobe.remove_stroke(static_cast<std::int64_t>(strokes.size())));
        expect_from_scratch(lobe, std::string(name) + ", last stroke removed");
        ASSERT_TRUE(lobe.remove_stroke(1));
        expect_from_scratch(lobe, std::string(name) + ", first stroke removed");
    }
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
    expect_from_scratch(lobe, "after a refusal");
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
    }
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
