// Pinch editing (meshing/laplacian_edit.h) on a 4,842-vertex sphere lobe (radius 25 cm):
// the factorisation when a pinch starts, and one drag frame after it. Goal: ≤ 2 ms per frame.
// Run with --benchmark_repetitions=5 --benchmark_report_aggregates_only=true for medians.
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "core/mesh.h"
#include "meshing/laplacian_edit.h"
#include "tests/support/shapes.h"

using namespace lobe;

namespace {

const TriangleMesh& lobe_mesh()
{
    static const TriangleMesh mesh = test::geodesic_sphere(22, glm::dvec3(0.0, 1.2, -0.4), 0.25); // 4,842 vertices
    return mesh;
}

/// Arg 0: ROI radius in millimetres (80 = the default; 300 gives an ROI of over 1,000 vertices).
/// Arg 1: rotation iterations (0 = linear Laplacian editing only).
PinchEditOptions options_for(const benchmark::State& state)
{
    PinchEditOptions options;
    options.roi_radius_m = double(state.range(0)) / 1000.0;
    options.rotation_invariant = state.range(1) > 0;
    options.rotation_iterations = int(state.range(1));
    return options;
}

void report(benchmark::State& state, const PinchEditor& editor)
{
    state.counters["roi_vertices"] = double(editor.roi().size());
    state.counters["mesh_vertices"] = double(lobe_mesh().vertex_count());
}

} // namespace

static void BM_PinchEditFactor(benchmark::State& state)
{
    const TriangleMesh& mesh = lobe_mesh();
    const PinchEditOptions options = options_for(state);
    for (auto _ : state) {
        PinchEditor editor(mesh, 0, options);
        benchmark::DoNotOptimize(editor);
    }
    const PinchEditor editor(mesh, 0, options);
    if (state.range(0) >= 300 && editor.roi().size() < 1000)
        state.SkipWithError("ROI smaller than 1,000 vertices");
    report(state, editor);
}
BENCHMARK(BM_PinchEditFactor)->Args({80, 3})->Args({300, 3})->Unit(benchmark::kMillisecond);

static void BM_PinchEditDragFrame(benchmark::State& state)
{
    TriangleMesh mesh = lobe_mesh();
    const PinchEditOptions options = options_for(state);
    const PinchEditor editor(mesh, 0, options);
    if (state.range(0) >= 300 && editor.roi().size() < 1000)
        state.SkipWithError("ROI smaller than 1,000 vertices");
    const glm::vec3 start = editor.handle_start();
    const glm::vec3 out = glm::normalize(start - glm::vec3(0.0f, 1.2f, -0.4f));
    int frame = 0;
    for (auto _ : state) {
        // A pinch pulling out 5 cm over 90 frames and back.
        const float s = 0.05f * float(std::sin(double(frame++ % 180) * 3.14159265358979 / 180.0));
        editor.drag_to(start + s * out + glm::vec3(0.3f * s, 0.0f, 0.0f), mesh);
        benchmark::ClobberMemory();
    }
    report(state, editor);
}
BENCHMARK(BM_PinchEditDragFrame)
    ->Args({80, 3})
    ->Args({300, 0})
    ->Args({300, 2})
    ->Args({300, 3})
    ->Unit(benchmark::kMillisecond);
