// A sketched L-system tree (issue 40, Performance): changing the sketch or the iteration
// regrows the full-size tree within one 90 Hz frame (11.1 ms) for trees up to 20k segments.
// One regrowth is what the live sketch mode does after an edit: the rules derived from the
// sketch (growth/lsystem/sketch.h), parsed, derived and drawn by the lsystem grower, and the
// pipe model's radii. The sketch is tests/data/sketches/maple.json's (two branch types); the
// argument is the iteration, and a node of the sketch moves a little before every regrowth.
#include <benchmark/benchmark.h>

#include <fstream>
#include <sstream>
#include <string>

#include "growth/lsystem/sketch.h"
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

} // namespace

BENCHMARK(BM_SketchRegrow)->Arg(10)->Arg(16)->Arg(20)->Arg(22)->Arg(23)->Unit(benchmark::kMillisecond);
