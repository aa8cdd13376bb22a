// Progressive lobes at the default 3 cm spacing (issue: adding a stroke to a 10-stroke lobe
// and updating its surface ≤ 1 ms; remeshing a lobe ≤ 20 ms). The lobe is a 20 cm sphere
// drawn as six loops through its centre at 30° steps plus four stacked rings, the kind of
// lobe a person sketches with about ten strokes.
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include <glm/geometric.hpp>

#include "app/session/edit_ops.h"
#include "meshing/lobe.h"
#include "app/session/lobe_cache.h"
#include "app/session/lobe_document.h"
#include "meshing/lobe_remesh.h"
#include "meshing/mesh_quality.h"
#include "meshing/remesh.h"
#include "tests/bench/cgal_surface_mesh.h"
#include "tests/support/replay_fixture.h"
#include "tests/support/shapes.h"

#include "meshing/cgal_prelude.h"
LOBE_CGAL_HEADERS_BEGIN
#include <CGAL/Polygon_mesh_processing/remesh.h>
LOBE_CGAL_HEADERS_END

using namespace lobe;

namespace {

constexpr double kPi = 3.14159265358979323846;
const glm::dvec3 kCentre(0.0, 1.4, -0.45);
constexpr double kRadius = 0.2;

using test::raw_loop;

/// The timed adding, apart so that scripts/count-instructions.sh can count it under callgrind.
[[gnu::noinline]] void add_timed(Lobe& lobe, const LobeStrokeSamples& prepared) { lobe.add_prepared(prepared); }

/// Times adding `prepared` to copies of `base` (copied outside the timed region) and
/// reports which regions the stroke kept; returns the lobe with the stroke added.
Lobe time_adding_stroke(benchmark::State& state, const Lobe& base, const LobeStrokeSamples& prepared)
{
    Lobe after = base;
    after.add_prepared(prepared);
    for (auto _ : state) {
        state.PauseTiming();
        Lobe lobe = base;
        state.ResumeTiming();
        add_timed(lobe, prepared);
        benchmark::DoNotOptimize(lobe.surface().mesh.positions.data());
    }
    state.counters["regions"] = static_cast<double>(after.last_kept().regions);
    state.counters["kept"] = static_cast<double>(after.last_kept().kept);
    state.counters["built_changed_only"] = after.last_kept().built_changed_only ? 1.0 : 0.0;
    return after;
}

/// Adds an 11th stroke to a lobe of ten; the lobe is copied back outside the timed region
/// each round. Arg 0: a loop tilted by 45°, which crosses every stroke (twice) and changes
/// about half of the lobe; arg 1: a ring round the equator, between the two middle rings,
/// which changes the strip between them (the paper's Fig. 5 case).
void BM_AddStrokeToTenStrokeLobe(benchmark::State& state)
{
    Lobe base;
    const auto strokes = test::ten_stroke_lobe();
    for (std::size_t i = 0; i < strokes.size(); ++i) base.add_stroke(static_cast<std::int64_t>(i + 1), strokes[i]);
    std::vector<glm::vec3> extra;
    if (state.range(0) == 0) extra = raw_loop(kCentre, glm::normalize(glm::dvec3(1, 1, 0)), {0, 0, 1}, kRadius, 11);
    if (state.range(0) == 1) extra = raw_loop(kCentre, {1, 0, 0}, {0, 0, 1}, kRadius, 5);
    if (state.range(0) == 2) {
        // A small loop on the lobe inside one cell between the upper rings (latitude 36°,
        // between the loops at 0° and 30° of longitude).
        const double lat = 36.0 * kPi / 180.0, lon = 15.0 * kPi / 180.0;
        const glm::dvec3 axis(std::cos(lat) * std::cos(lon), std::sin(lat), std::cos(lat) * std::sin(lon));
        const glm::dvec3 u = glm::normalize(glm::cross(axis, glm::dvec3(0, 1, 0))), v = glm::cross(axis, u);
        const double a = 0.04;
        extra = raw_loop(kCentre + std::sqrt(kRadius * kRadius - a * a) * axis, u, v, a, 2);
    }
    time_adding_stroke(state, base, prepare_lobe_stroke(11, extra));
    state.counters["vertices"] = static_cast<double>(base.surface().mesh.positions.size());
    state.counters["crossings"] = static_cast<double>(base.surface().crossings);
}
BENCHMARK(BM_AddStrokeToTenStrokeLobe)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);

/// The paper's progressive lobe without crossings (Fig. 5): ten rings stacked round a 20 cm
/// sphere, from 70° south to 70° north, each joined to the next by a strip and the ends capped
/// automatically; an 11th ring drawn between the two middle ones replaces the strip between
/// them with two. The lobe is copied back outside the timed region each round.
void BM_AddRingBetweenTwoOfTenStackedRings(benchmark::State& state)
{
    auto ring_at = [](double latitude_deg, int seed) {
        const double lat = latitude_deg * kPi / 180.0;
        return raw_loop(kCentre + glm::dvec3(0, kRadius * std::sin(lat), 0), {1, 0, 0}, {0, 0, 1},
                        kRadius * std::cos(lat), seed);
    };
    Lobe base;
    for (int k = 0; k < 10; ++k) base.add_stroke(k + 1, ring_at(-70.0 + k * 140.0 / 9.0, k));
    const Lobe after = time_adding_stroke(state, base, prepare_lobe_stroke(11, ring_at(0.0, 10)));
    state.counters["vertices"] = static_cast<double>(after.surface().mesh.positions.size());
    state.counters["strip_triangles"] = static_cast<double>(after.surface().paper_strip_triangles);
}
BENCHMARK(BM_AddRingBetweenTwoOfTenStackedRings)->Unit(benchmark::kMillisecond);

/// What a regrowth does with the lobes after the person drew one more lobe stroke: every lobe
/// of table1-4lobes-22strokes (4 lobes, 22 strokes) built from its strokes and remeshed.
/// Arg 0: from scratch (replay, the CLI); arg 1: with the regrowth worker's kept build
/// (app/session/lobe_cache.h), which joins the one stroke to its lobe and remeshes that lobe.
void BM_LobesAfterOneMoreStroke(benchmark::State& state)
{
    const Document full = test::replay_document("table1-4lobes-22strokes");
    Document before = full;
    LobeRecord* last = nullptr; // the lobe of the last lobe stroke drawn
    for (LobeRecord& l : before.lobes)
        if (!l.stroke_ids.empty() && (!last || l.stroke_ids.back() > last->stroke_ids.back())) last = &l;
    last->stroke_ids.pop_back();
    LobeBuildCache cache;
    for (auto _ : state) {
        if (state.range(0)) {
            state.PauseTiming();
            build_document_lobes(before, nullptr, cache);
            state.ResumeTiming();
            benchmark::DoNotOptimize(build_document_lobes(full, nullptr, cache).size());
        } else {
            benchmark::DoNotOptimize(build_document_lobes(full, nullptr).size());
        }
    }
    if (state.range(0)) {
        state.counters["lobes_kept"] = static_cast<double>(cache.last_build().kept);
        state.counters["lobes_continued"] = static_cast<double>(cache.last_build().continued);
        state.counters["regions_remeshed"] = static_cast<double>(cache.last_build().regions_remeshed);
        state.counters["regions_reused"] = static_cast<double>(cache.last_build().regions_reused);
    }
}
BENCHMARK(BM_LobesAfterOneMoreStroke)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

/// Sampling and closing one raw stroke (part of adding a stroke from the pipeline).
void BM_PrepareStroke(benchmark::State& state)
{
    const auto raw = raw_loop(kCentre, glm::normalize(glm::dvec3(1, 1, 0)), {0, 0, 1}, kRadius, 11);
    for (auto _ : state) benchmark::DoNotOptimize(prepare_lobe_stroke(11, raw).points.data());
    state.counters["raw_points"] = static_cast<double>(raw.size());
}
BENCHMARK(BM_PrepareStroke)->Unit(benchmark::kMillisecond);

/// Remeshing the ten-stroke lobe to 3 cm with the strokes as constraints. Arg 0: as lobes
/// are remeshed, region by region (lobe_remesh.h), every region from scratch; arg 1: the whole
/// lobe as one mesh with its stroke vertices relaxed along the strokes (remesh_isotropic, what
/// lobes used before, and what a lobe a region of which cannot be charted still gets).
void BM_RemeshTenStrokeLobe(benchmark::State& state)
{
    Lobe lobe;
    const auto strokes = test::ten_stroke_lobe();
    for (std::size_t i = 0; i < strokes.size(); ++i) lobe.add_stroke(static_cast<std::int64_t>(i + 1), strokes[i]);
    RemeshOptions options;
    options.relax_feature_edges = true;
    options.iterations = static_cast<unsigned>(LobeSettings{}.remesh_iterations);
    TriangleMesh out;
    LobeRemeshStats stats;
    for (auto _ : state) {
        out = state.range(0) ? remesh_isotropic(lobe.surface().mesh, options)
                             : remesh_lobe_surface(lobe.surface(), options, nullptr, &stats);
        benchmark::DoNotOptimize(out.positions.data());
    }
    const MeshQuality q = measure_quality(out);
    state.counters["in_vertices"] = static_cast<double>(lobe.surface().mesh.positions.size());
    state.counters["out_vertices"] = static_cast<double>(q.vertices);
    state.counters["share_angles_ge_30"] = q.share_all_angles_ge_30;
    state.counters["min_angle_deg"] = q.min_angle_deg;
    if (!state.range(0)) state.counters["regions"] = static_cast<double>(stats.regions);
}
BENCHMARK(BM_RemeshTenStrokeLobe)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

/// Remeshing the ten-stroke lobe after an eleventh stroke, with the regions remeshed after
/// the tenth kept (LobeRemeshCache, as the regrowth worker keeps them): only the regions the
/// stroke changed are remeshed. Arg 0: a ring round the equator, between the two middle rings
/// (it changes the strip between them); arg 1: the loop tilted by 45° of
/// BM_AddStrokeToTenStrokeLobe, which crosses every stroke.
void BM_RemeshAfterEleventhStroke(benchmark::State& state)
{
    Lobe lobe;
    const auto strokes = test::ten_stroke_lobe();
    for (std::size_t i = 0; i < strokes.size(); ++i) lobe.add_stroke(static_cast<std::int64_t>(i + 1), strokes[i]);
    RemeshOptions options;
    options.iterations = static_cast<unsigned>(LobeSettings{}.remesh_iterations);
    LobeRemeshCache before;
    remesh_lobe_surface(lobe.surface(), options, &before);
    lobe.add_stroke(11, state.range(0) ? raw_loop(kCentre, glm::normalize(glm::dvec3(1, 1, 0)), {0, 0, 1}, kRadius, 11)
                                       : raw_loop(kCentre, {1, 0, 0}, {0, 0, 1}, kRadius, 5));
    LobeRemeshStats stats;
    for (auto _ : state) {
        state.PauseTiming();
        LobeRemeshCache cache = before;
        state.ResumeTiming();
        benchmark::DoNotOptimize(remesh_lobe_surface(lobe.surface(), options, &cache, &stats).positions.data());
    }
    state.counters["regions"] = static_cast<double>(stats.regions);
    state.counters["remeshed"] = static_cast<double>(stats.remeshed);
    state.counters["kept_by_surface"] = static_cast<double>(lobe.last_kept().kept);
}
BENCHMARK(BM_RemeshAfterEleventhStroke)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

/// The same lobe through a plain default CGAL::Polygon_mesh_processing::isotropic_remeshing
/// call (10 iterations, same target, no constraints) on a CGAL::Surface_mesh, for the
/// side-by-side comparison of time and quality.
void BM_CgalDefaultRemeshTenStrokeLobe10Iterations(benchmark::State& state)
{
    Lobe lobe;
    const auto strokes = test::ten_stroke_lobe();
    for (std::size_t i = 0; i < strokes.size(); ++i) lobe.add_stroke(static_cast<std::int64_t>(i + 1), strokes[i]);
    const cgal::Mesh input = bench::to_surface_mesh(lobe.surface().mesh);
    cgal::Mesh sm;
    for (auto _ : state) {
        sm = input;
        CGAL::Polygon_mesh_processing::isotropic_remeshing(faces(sm), 0.03, sm, CGAL::parameters::number_of_iterations(10));
        benchmark::DoNotOptimize(sm.number_of_faces());
    }
    const MeshQuality q = measure_quality(bench::from_surface_mesh(sm));
    state.counters["out_vertices"] = static_cast<double>(q.vertices);
    state.counters["share_angles_ge_30"] = q.share_all_angles_ge_30;
    state.counters["min_angle_deg"] = q.min_angle_deg;
}
BENCHMARK(BM_CgalDefaultRemeshTenStrokeLobe10Iterations)->Unit(benchmark::kMillisecond);

/// A pinch deform dragged live (LivePinch, as the desktop and VR sessions run it every frame
/// while the pinch is held): one solve and the region mapped out to stage space, on lobe 1 of
/// the pinch-edit recording as built before its first deform, from that deform's start along
/// its path and back. Arg: the region radius in centimetres (8 = the default).
void BM_LivePinchFrame(benchmark::State& state)
{
    Document doc = test::replay_document("pinch-edit");
    std::vector<glm::vec3> path;
    std::size_t first = doc.edits.size();
    for (std::size_t k = 0; k < doc.edits.size() && first == doc.edits.size(); ++k)
        if (doc.edits[k].kind() == EditKind::DeformLobe) first = k;
    if (first == doc.edits.size()) {
        state.SkipWithError("the recording has no pinch deform");
        return;
    }
    const EditOperation op = doc.edits[first];
    for (const DragPoint& p : op.path) path.emplace_back(p.position);
    doc.edits.resize(first);
    doc.settings.lobes.pinch_roi_radius_m = static_cast<double>(state.range(0)) / 100.0;
    const std::vector<BuiltLobe> lobes = build_document_lobes(doc);
    const BuiltLobe* lobe = nullptr;
    for (const BuiltLobe& l : lobes)
        if (l.lobe_id == op.target) lobe = &l;
    if (!lobe || path.size() < 2) {
        state.SkipWithError("no lobe for the deform");
        return;
    }
    LivePinch live(doc, *lobe, path.front());
    std::size_t frame = 0;
    for (auto _ : state) {
        // Along the path and back, one point per frame.
        const std::size_t n = path.size(), k = frame++ % (2 * n - 2);
        benchmark::DoNotOptimize(live.drag_to(path[k < n ? k : 2 * n - 2 - k]).positions.data());
    }
    state.counters["lobe_vertices"] = static_cast<double>(lobe->mesh.positions.size());
}
BENCHMARK(BM_LivePinchFrame)->Arg(8)->Arg(30)->Unit(benchmark::kMillisecond);

} // namespace

namespace {

/// A stroke-edit operation on `stroke` that picks its 11th point and lifts it by `lift` metres.
EditOperation bend_operation(const Stroke& stroke, float lift)
{
    const glm::vec3 from = stroke.points[10].position, to = from + glm::vec3(0.0f, lift, 0.0f);
    EditOperation op;
    op.id = 1000000;
    op.target = stroke.id;
    EditStrokeParams bend;
    bend.pick_distance_m = 0.03;
    bend.half_length_m = 0.08;
    op.params = bend;
    op.path = {{glm::dvec3(from), 0.0}, {glm::dvec3(to), 1.0}};
    return op;
}

/// A stroke bend shown live (app/live/live_edit_view.h, as the live session runs it
/// every frame while the fingertip moves): the document's effective strokes with the drag's
/// operation appended, on table1-4lobes-22strokes (22 strokes, 4 lobes); the bend picks a
/// point of its first stroke and pulls it up to 4 cm out and back.
void BM_LiveStrokeEditFrame(benchmark::State& state)
{
    const Document doc = test::replay_document("table1-4lobes-22strokes");
    if (doc.strokes.empty() || doc.strokes.front().points.size() < 20) {
        state.SkipWithError("the recording has no usable stroke");
        return;
    }
    Document with = doc;
    with.edits.push_back(bend_operation(doc.strokes.front(), 0.0f));
    std::size_t frame = 0;
    std::size_t points = 0;
    for (const Stroke& s : doc.strokes) points += s.points.size();
    for (auto _ : state) {
        const float t = 0.04f * static_cast<float>(std::sin(static_cast<double>(frame++ % 180) * 3.14159265358979 / 180.0));
        with.edits.back() = bend_operation(doc.strokes.front(), t);
        benchmark::DoNotOptimize(effective_strokes(with).data());
    }
    state.counters["strokes"] = static_cast<double>(doc.strokes.size());
    state.counters["points"] = static_cast<double>(points);
}
BENCHMARK(BM_LiveStrokeEditFrame)->Unit(benchmark::kMillisecond);

/// What the regrowth thread does with the lobes for each preview of a stroke bend
/// (app/live/drag_preview.h): table1-4lobes-22strokes with a bend of one lobe stroke that changes
/// from one preview to the next, built with the kept build of the previews before it. Arg 0:
/// the first stroke of its lobe (the lobe joined again from its first stroke); arg 1: the
/// last (only that stroke joined again).
void BM_LobesWhileBendingAStroke(benchmark::State& state)
{
    const Document doc = test::replay_document("table1-4lobes-22strokes");
    const LobeRecord* lobe = nullptr;
    for (const LobeRecord& l : doc.lobes)
        if (!lobe && l.stroke_ids.size() >= 2) lobe = &l;
    const Stroke* target = nullptr;
    const std::int64_t id = lobe ? (state.range(0) ? lobe->stroke_ids.back() : lobe->stroke_ids.front()) : 0;
    for (const Stroke& s : doc.strokes)
        if (s.id == id) target = &s;
    if (!target || target->points.size() < 20) {
        state.SkipWithError("the recording has no usable lobe stroke");
        return;
    }
    LobeBuildCache cache;
    Document with = doc;
    with.edits.push_back(bend_operation(*target, 0.0f));
    build_document_lobes(with, nullptr, cache);
    std::size_t frame = 0;
    for (auto _ : state) {
        with.edits.back() = bend_operation(*target, 0.002f * static_cast<float>(1 + frame++ % 20));
        benchmark::DoNotOptimize(build_document_lobes(with, nullptr, cache).size());
    }
    state.counters["lobe_strokes"] = static_cast<double>(lobe->stroke_ids.size());
    state.counters["lobes_built"] = static_cast<double>(cache.last_build().built + cache.last_build().continued);
    state.counters["regions_remeshed"] = static_cast<double>(cache.last_build().regions_remeshed);
    state.counters["regions_reused"] = static_cast<double>(cache.last_build().regions_reused);
}
BENCHMARK(BM_LobesWhileBendingAStroke)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

} // namespace
