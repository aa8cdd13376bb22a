// Pictures of the largest Table 1 tree (4 lobes, 22 strokes) at 1280×720 with tree and
// leaves: the CPU time to record one frame's command buffer, and the whole frame (record,
// draw with 4× MSAA and resolve, copy out, read back) on the device the renderer picks
// (lavapipe on a machine without a GPU), at LOD0 and LOD2. BM_RenderLeaves320x240: the same
// frame, small, with the leaves instanced (the default) and as plain triangles
// (RendererOptions::instanced_leaves off), and the bytes the leaves upload either way.
// Run with --benchmark_filter=Render --benchmark_repetitions=5 and read the medians.
#include <benchmark/benchmark.h>

#include <ctime>
#include <memory>
#include <string>

#include "app/session/edit_hooks.h"
#include "app/render/render_scene.h"
#include "app/render/renderer.h"
#include "app/export/tree_output.h"
#include "app/session/tree_pipeline.h"
#include "input/pipeline.h"
#include "input/recording.h"
#include "app/session/session_builder.h"
#include "tests/support/test_paths.h"

using namespace lobe;

namespace {

struct Fixture {
    TreeGeometry geometry;
    float ground_y = 0.0f;
    std::unique_ptr<Renderer> renderer;
    std::unique_ptr<Renderer> triangle_leaves; // instanced_leaves off (made on first use)
};

Fixture& fixture()
{
    static Fixture f = [] {
        Fixture out;
        const Recording rec = read_recording(test::source_path("recordings/table1-4lobes-22strokes.lrec"));
        const InputResult r = run_input_pipeline(rec);
        SessionBuilder b(Document{}, EditPickOptions{}, meshing_edit_hooks());
        b.apply(r.actions);
        const Document doc = b.take_document();
        const BuiltTree tree = build_document_tree(doc);
        out.geometry = document_tree_geometry(doc, tree);
        out.ground_y = tree.growth.tree.nodes[0].position.y;
        out.renderer = std::make_unique<Renderer>();
        return out;
    }();
    return f;
}

/// Sets up the scene of LOD `lod` and its front camera.
Camera prepare(benchmark::State& state, int lod)
{
    Fixture& f = fixture();
    RenderContent content;
    content.lod = lod;
    const RenderScene scene = tree_render_scene(f.geometry, {}, {}, f.ground_y, content);
    f.renderer->set_scene(scene);
    std::size_t triangles = 0;
    for (const RenderItem& item : scene.items) triangles += item.geometry.triangle_count();
    state.counters["triangles"] = static_cast<double>(triangles);
    state.SetLabel(f.renderer->device_name());
    return frame_view(scene_bounds(scene), front_view(), 1280.0f / 720.0f);
}

} // namespace

// The whole frame, as `lobesketch render` draws it (wall time).
static void BM_RenderFrame1280x720(benchmark::State& state)
{
    const Camera camera = prepare(state, static_cast<int>(state.range(0)));
    Renderer& r = *fixture().renderer;
    r.render(camera, 1280, 720); // the target is made once
    double record = 0.0, gpu = 0.0;
    for (auto _ : state) {
        RgbaImage image = r.render(camera, 1280, 720);
        benchmark::DoNotOptimize(image.pixels.data());
        record += r.stats().record_ms;
        gpu += r.stats().gpu_ms;
    }
    state.counters["record_ms"] = record / static_cast<double>(state.iterations());
    state.counters["gpu_ms"] = gpu / static_cast<double>(state.iterations());
}
// A frame on lavapipe takes hundreds of milliseconds: a fixed, small number of iterations.
BENCHMARK(BM_RenderFrame1280x720)->ArgName("lod")->Arg(0)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);

// Only the recording of the frame's command buffer (CPU), timed by the renderer.
static void BM_RenderRecordCommandBuffer(benchmark::State& state)
{
    const Camera camera = prepare(state, static_cast<int>(state.range(0)));
    Renderer& r = *fixture().renderer;
    r.render(camera, 1280, 720);
    for (auto _ : state) {
        r.render(camera, 1280, 720);
        state.SetIterationTime(r.stats().record_ms / 1000.0);
    }
}
// Manual time is only the recording (microseconds): without a fixed count the library would
// run thousands of whole frames to fill its minimum time.
BENCHMARK(BM_RenderRecordCommandBuffer)->ArgName("lod")->Arg(0)->Arg(2)->Unit(benchmark::kMicrosecond)->UseManualTime()->Iterations(3);

/// CPU time of the whole process (every thread: lavapipe rasterises in its own), in ms.
static double process_cpu_ms()
{
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return double(t.tv_sec) * 1e3 + double(t.tv_nsec) * 1e-6;
}

// Leaves instanced (arg 1) or as plain triangles (arg 0), LOD0, at 320×240: the frame (wall),
// its recording and submit-to-fence times, the CPU time of all the process's threads per
// frame (lavapipe's work, steadier than wall time on a loaded machine), and what uploading
// the leaves costs in bytes.
static void BM_RenderLeaves320x240(benchmark::State& state)
{
    Fixture& f = fixture();
    const bool instanced = state.range(0) != 0;
    if (!instanced && !f.triangle_leaves) {
        RendererOptions options;
        options.instanced_leaves = false;
        f.triangle_leaves = std::make_unique<Renderer>(options);
    }
    Renderer& r = instanced ? *f.renderer : *f.triangle_leaves;
    const RenderScene scene = tree_render_scene(f.geometry, {}, {}, f.ground_y, RenderContent{});
    RenderScene texture_only = scene, leaves_only = scene;
    texture_only.items.clear();
    leaves_only.items.clear();
    for (const RenderItem& item : scene.items)
        if (item.material == RenderMaterial::Leaf) leaves_only.items.push_back(item);
    r.set_scene(texture_only); // then only the leaf mesh is uploaded
    r.set_scene(leaves_only);
    state.counters["leaf_bytes"] = static_cast<double>(r.stats().bytes_uploaded);
    state.counters["leaf_instances"] = static_cast<double>(r.stats().leaf_instances);
    r.set_scene(scene);
    state.SetLabel(r.device_name());
    const Camera camera = frame_view(scene_bounds(scene), front_view(), 320.0f / 240.0f);
    r.render(camera, 320, 240); // the target is made once, the shaders compiled
    double record = 0.0, gpu = 0.0;
    const double cpu0 = process_cpu_ms();
    for (auto _ : state) {
        RgbaImage image = r.render(camera, 320, 240);
        benchmark::DoNotOptimize(image.pixels.data());
        record += r.stats().record_ms;
        gpu += r.stats().gpu_ms;
    }
    const auto n = static_cast<double>(state.iterations());
    state.counters["process_cpu_ms"] = (process_cpu_ms() - cpu0) / n;
    state.counters["record_ms"] = record / n;
    state.counters["gpu_ms"] = gpu / n;
}
BENCHMARK(BM_RenderLeaves320x240)->ArgName("instanced")->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(5);
