// A sketched L-system tree (issue 40, Performance): changing the sketch or the iteration
// regrows the full-size tree within one 90 Hz frame (11.1 ms) for trees up to 20k segments.
// One regrowth is what the live sketch mode does after an edit: the rules derived from the
// sketch (growth/lsystem/sketch.h), parsed, derived and drawn by the lsystem grower, and the
// pipe model's radii. The sketch is tests/data/sketches/maple.json's (two branch types); the
// argument is the iteration, and a node of the sketch moves a little before every regrowth.
// BM_SketchLiveStep: the same in the live mode (app/live/lsystem_sketch_mode.h) with the
// scene items it shows (the tree's mesh made again), as a growth key is pressed.
#include <benchmark/benchmark.h>

#include <fstream>
#include <sstream>
#include <string>

#include "app/live/lsystem_sketch_mode.h"
#include "app/live/lsystem_sketch_view.h"
#include "growth/lsystem/sketch.h"
#include "input/recording.h"
#include "growth/radii.h"
#include "tests/support/test_paths.h"

using namespace lobe;
using namespace lobe::lsystem;

namespace {

Sketch maple_sketch()
{
    std::ifstream in(test::source_path("tests/data/sketches/maple.json"), std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return parse_sketch(ss.str(), "maple.json");
}

void BM_SketchRegrow(benchmark::State& state)
{
    Sketch sketch = maple_sketch();
    SketchRulesOptions o;
    o.growth = static_cast<double>(state.range(0));
    std::size_t segments = 0;
    int k = 0;
    for (auto _ : state) {
        // An edit: the branch's tip moves by a millimetre back and forth.
        sketch.branches[0].points.back().x += (++k % 2 ? 0.001 : -0.001);
        SketchGrown g = grow_sketch(sketch, o);
        assign_pipe_radii(g.growth.tree);
        segments = g.growth.tree.size() - 1;
        benchmark::DoNotOptimize(g.growth.tree.nodes.data());
    }
    state.counters["segments"] = static_cast<double>(segments);
}

/// The live mode as a person steps the growth of the shipped maple recording's sketch (a
/// key press regrows the tree beside the platform) and the frame's scene items are made (the
/// tree's mesh made again): between iteration N − 1 and N, N the argument.
void BM_SketchLiveStep(benchmark::State& state)
{
    LSystemSketchMode mode = replay_lsystem_sketch(read_recording(test::source_path("recordings/lsystem-sketch/maple.lrec")));
    InputEvent key;
    key.kind = InputEventKind::Key;
    key.value = 1;
    key.code = lsystem_sketch_keys::kIterationForward;
    while (mode.growth() < static_cast<double>(state.range(0))) mode.push_event(key);
    LSystemSketchView view;
    RenderScene scene;
    int k = 0;
    for (auto _ : state) {
        key.code = ++k % 2 ? lsystem_sketch_keys::kIterationBack : lsystem_sketch_keys::kIterationForward;
        mode.push_event(key);
        view.reclaim(scene.items);
        scene.items.clear();
        view.append(mode, scene);
        benchmark::DoNotOptimize(scene.items.data());
    }
    state.counters["segments"] = static_cast<double>(mode.tree().size() - 1);
}

/// A frame of the live mode in which nothing changed: its scene items appended again (the
/// tree's mesh not made again).
void BM_SketchLiveFrame(benchmark::State& state)
{
    LSystemSketchMode mode = replay_lsystem_sketch(read_recording(test::source_path("recordings/lsystem-sketch/maple.lrec")));
    InputEvent key;
    key.kind = InputEventKind::Key;
    key.value = 1;
    key.code = lsystem_sketch_keys::kIterationForward;
    while (mode.growth() < static_cast<double>(state.range(0))) mode.push_event(key);
    LSystemSketchView view;
    RenderScene scene;
    for (auto _ : state) {
        view.reclaim(scene.items); // as the live session does before cutting its items back
        scene.items.clear();
        view.append(mode, scene);
        benchmark::DoNotOptimize(scene.items.data());
    }
    state.counters["segments"] = static_cast<double>(mode.tree().size() - 1);
}

} // namespace

BENCHMARK(BM_SketchLiveFrame)->Arg(23)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SketchLiveStep)->Arg(20)->Arg(23)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SketchRegrow)->Arg(10)->Arg(16)->Arg(20)->Arg(22)->Arg(23)->Unit(benchmark::kMillisecond);
