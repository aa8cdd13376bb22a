// Per-frame cost of the input pipeline (filters, gestures, stroke capture) on a realistic
// synthesized session, and of whole-recording replay.
#include <benchmark/benchmark.h>

#include "input/pipeline.h"
#include "input/synth.h"
#include "tests/support/test_paths.h"

using namespace lobe;

namespace {
const Recording& session()
{
    static const Recording rec =
        synthesize(load_scenario(test::source_path("recordings/table1-4lobes-22strokes.scenario.json"))).recording;
    return rec;
}
} // namespace

static void BM_InputPipelinePerFrame(benchmark::State& state)
{
    const Recording& rec = session();
    InputPipeline pipe;
    std::size_t i = 0;
    double t0 = 0;
    for (auto _ : state) {
        HandFrame f = rec.frames[i];
        f.time += t0;
        pipe.push_frame(f);
        benchmark::DoNotOptimize(pipe.gestures().hand(Hand::Right).pinch_gap);
        if (++i == rec.frames.size()) {
            i = 0;
            t0 += rec.frames.back().time + 1.0;
            pipe.take_actions();
        }
    }
    state.SetItemsProcessed(static_cast<int64_t>(state.iterations()));
}
BENCHMARK(BM_InputPipelinePerFrame);

static void BM_ReplayWholeSession(benchmark::State& state)
{
    const Recording& rec = session();
    for (auto _ : state) {
        InputResult r = run_input_pipeline(rec);
        benchmark::DoNotOptimize(r.strokes.data());
    }
    state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * rec.frames.size()));
    state.counters["frames"] = static_cast<double>(rec.frames.size());
}
BENCHMARK(BM_ReplayWholeSession)->Unit(benchmark::kMillisecond);
