// L-systems (issue 39, Performance): bracketed context-free rewriting (≥ 50 M modules/s),
// parametric rewriting with conditions (≥ 5 M modules/s), stochastic rewriting, and turtle
// interpretation plus branch geometry for 100k segments (≤ 100 ms).
//
// A rewriting benchmark's modules/s counts the modules written: the sum of the word's
// length after every step, from the axiom to the last step. scripts/lsystem-compare.sh runs
// the same grammars for the same number of steps (so the same words) in the npm package
// `lindenmayer` (tests/bench/lsystem_lindenmayer.cjs) and prints the medians side by side.
#include <benchmark/benchmark.h>

#include <chrono>
#include <cstddef>
#include <string>

#include <glm/geometric.hpp>

#include "app/export/tree_output.h"
#include "core/settings.h"
#include "growth/branch_geometry.h"
#include "growth/radii.h"
#include "growth/lsystem/lsystem.h"
#include "growth/lsystem/turtle.h"

using namespace lobe;
using namespace lobe::lsystem;

namespace {

// The Algorithmic Beauty of Plants, Fig. 1.24d: bracketed, context-free; 12 steps give a
// word of 3,446,171 modules, 5,165,118 written in all.
constexpr const char* kBracketed = R"(
Lsystem: 1
derivation length: 12
Axiom: X
X --> F[+X]F[-X]+X
F --> FF
endlsystem
)";

// Parametric with conditions: every apex A(l,w) chooses between two productions by its
// length (forking while at least 0.2 long, else growing on four times longer), every
// internode F(l) lengthens while shorter than 10; 18 steps give a word of 1,297,754
// modules, 2,653,061 written in all.
constexpr const char* kParametric = R"(
Lsystem: 1
derivation length: 18
Axiom: A(1,1)
A(l,w) : l >= 0.2 --> !(w)F(l)[+(30)A(l*0.8,w*0.7)]/(137.5)[-(30)A(l*0.9,w*0.7)]
A(l,w) : l < 0.2 --> !(w)F(l)/(90)A(l*4,w)
F(l) : l < 10 --> F(l*1.02)
endlsystem
)";

// Stochastic: The Algorithmic Beauty of Plants, Fig. 1.27 (seed 002); 10 steps give about a
// million modules (the count depends on the seed).
constexpr const char* kStochastic = R"(
Lsystem: 1
derivation length: 10
Axiom: F
F --> F[+F]F[-F]F : 0.33
F --> F[+F]F : 0.33
F --> F[-F]F : 0.34
endlsystem
)";

/// The modules written by deriving `system` with `options`: the sum of the word's length
/// after every step.
std::size_t modules_written(const LSystem& system, const DeriveOptions& options)
{
    Word a = system.axiom(), b;
    std::size_t total = 0;
    for (int step = 1; step <= system.derivation_length(); ++step) {
        derive_step(system, a, b, step, options);
        total += b.size();
        std::swap(a, b);
    }
    return total;
}

void run_rewriting(benchmark::State& state, const char* text, const char* name)
{
    const LSystem system = parse_lsystem(text, name);
    DeriveOptions options;
    options.seed = 7;
    const std::size_t written = modules_written(system, options);
    std::size_t final_size = 0;
    for (auto _ : state) {
        Word w = derive(system, options);
        final_size = w.size();
        benchmark::DoNotOptimize(w.modules.data());
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(written) * state.iterations());
    state.counters["steps"] = system.derivation_length();
    state.counters["modules_final"] = static_cast<double>(final_size);
    state.counters["modules_written"] = static_cast<double>(written);
}

void BM_LSystemBracketed(benchmark::State& state) { run_rewriting(state, kBracketed, "bracketed.l"); }
BENCHMARK(BM_LSystemBracketed)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_LSystemParametric(benchmark::State& state) { run_rewriting(state, kParametric, "parametric.l"); }
BENCHMARK(BM_LSystemParametric)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_LSystemStochastic(benchmark::State& state) { run_rewriting(state, kStochastic, "stochastic.l"); }
BENCHMARK(BM_LSystemStochastic)->Unit(benchmark::kMillisecond)->UseRealTime();

// A ternary tree after The Algorithmic Beauty of Plants, Fig. 2.8, in 3D with widths and
// internodes shortening by 0.8 per order: 10 steps draw 1 + 2·(3¹⁰ − 1) = 118,097 segments,
// no two of them merged (a width change or a branch separates every pair).
constexpr const char* kTernary = R"(
Lsystem: 1
derivation length: 10
Axiom: !(1)F(4)/(45)A(1,0.7)
A(l,w) --> !(w)F(l)[&(30)F(l)A(l*0.8,w*0.7)]/(94.74)[&(30)F(l)A(l*0.8,w*0.7)]/(132.63)[&(30)F(l)A(l*0.8,w*0.7)]
endlsystem
)";

struct TurtleInput {
    LSystem system;
    Word word;
    TurtleOptions options;
};

/// The ternary tree's word, scaled so that its segments are 2 cm long on average: about one
/// ring (every 1.5 cm at LOD0) per segment, as twigs of a tree this size have.
const TurtleInput& ternary_tree()
{
    static const TurtleInput input = [] {
        TurtleInput in;
        in.system = parse_lsystem(kTernary, "ternary.l");
        in.word = derive(in.system);
        const TurtleResult unit = interpret(in.system, in.word, in.options);
        double length = 0.0;
        for (std::size_t i = 1; i < unit.tree.size(); ++i) {
            const TreeNode& n = unit.tree.nodes[i];
            length += glm::length(glm::dvec3(n.position) - glm::dvec3(unit.tree.nodes[static_cast<std::size_t>(n.parent)].position));
        }
        in.options.metres_per_unit = 0.02 / (length / static_cast<double>(unit.segments));
        return in;
    }();
    return input;
}

// The turtle alone: the word drawn as a tree graph.
void BM_LSystemTurtle(benchmark::State& state)
{
    const TurtleInput& in = ternary_tree();
    const TurtleSymbols symbols(in.system);
    std::size_t segments = 0, nodes = 0;
    for (auto _ : state) {
        TurtleResult r = interpret(symbols, in.word, in.options);
        segments = r.segments;
        nodes = r.tree.size();
        benchmark::DoNotOptimize(r.tree.nodes.data());
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(segments) * state.iterations());
    state.counters["segments"] = static_cast<double>(segments);
    state.counters["nodes"] = static_cast<double>(nodes);
    state.counters["modules"] = static_cast<double>(in.word.size());
}
BENCHMARK(BM_LSystemTurtle)->Unit(benchmark::kMillisecond)->UseRealTime();

// The turtle and the branch geometry (issue: ≤ 100 ms for 100k segments): the tree graph and
// its LOD0 branch mesh at the default branch settings, built into kept storage as the apps
// regrow (build_tree_geometry_into, one level of detail, no leaves: the ternary tree places
// none and the tips' leaves are a separate cost, measured with them in BM_LSystemTreeGeometry).
void BM_LSystemTurtleBranchGeometry(benchmark::State& state)
{
    const TurtleInput& in = ternary_tree();
    const TurtleSymbols symbols(in.system);
    BranchSettings branches;
    branches.lod_count = 1;
    LeafSettings leaves;
    leaves.per_node = 0;
    TreeGeometry g;
    std::size_t segments = 0;
    for (auto _ : state) {
        TurtleResult r = interpret(symbols, in.word, in.options);
        segments = r.segments;
        build_tree_geometry_into(g, r.tree, branches, leaves, 1);
        benchmark::DoNotOptimize(g);
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(segments) * state.iterations());
    state.counters["segments"] = static_cast<double>(segments);
    state.counters["tris_LOD0"] = static_cast<double>(lod_triangles(g.lods[0]));
}
BENCHMARK(BM_LSystemTurtleBranchGeometry)->Unit(benchmark::kMillisecond)->UseRealTime();

// Everything a tree gets in the apps: the turtle, then branches and leaves at every level
// of detail of the default settings (3 LODs, 4 leaves per tip).
void BM_LSystemTreeGeometry(benchmark::State& state)
{
    const TurtleInput& in = ternary_tree();
    const TurtleSymbols symbols(in.system);
    const BranchSettings branches;
    const LeafSettings leaves;
    TreeGeometry g;
    std::size_t segments = 0;
    for (auto _ : state) {
        TurtleResult r = interpret(symbols, in.word, in.options);
        segments = r.segments;
        build_tree_geometry_into(g, r.tree, branches, leaves, 1);
        benchmark::DoNotOptimize(g);
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(segments) * state.iterations());
    state.counters["segments"] = static_cast<double>(segments);
    for (std::size_t i = 0; i < g.lods.size(); ++i)
        state.counters["tris_LOD" + std::to_string(i)] = static_cast<double>(lod_triangles(g.lods[i]));
}
BENCHMARK(BM_LSystemTreeGeometry)->Unit(benchmark::kMillisecond)->UseRealTime();

// The bracketed tree of docs/lsystem-turtle.md's timings: `F → F[+F]F[-F]/(90)F` from `F`,
// 7 steps (5⁷ = 78,125 segments) and 8 steps (390,625), tropism on, no widths; drawn as the
// grower draws a free tree (scaled to 3 m, pipe-model radii), then branches and leaves at
// the default settings' 3 LODs.
constexpr const char* kBracketedTree = R"(
Lsystem: 1
derivation length: 7
Axiom: F
F --> F[+F]F[-F]/(90)F
endlsystem
)";

void BM_LSystemBracketedTreeGeometry(benchmark::State& state)
{
    const LSystem system = parse_lsystem(kBracketedTree, "bracketed-tree.l");
    DeriveOptions d;
    d.steps = static_cast<int>(state.range(0));
    const Word word = derive(system, d);
    const TurtleSymbols symbols(system);
    TurtleOptions t;
    t.view = parse_view("angle increment: 25.7\ntropism direction: 0,-1,0\ninitial elasticity: 0.1\n", "bracketed-tree.v");
    t.fit_height_m = 3.0;
    const BranchSettings branches;
    const LeafSettings leaves;
    TreeGeometry g;
    std::size_t segments = 0;
    double turtle_ms = 0.0;
    for (auto _ : state) {
        const auto t0 = std::chrono::steady_clock::now();
        TurtleResult r = interpret(symbols, word, t);
        turtle_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        segments = r.segments;
        assign_pipe_radii(r.tree, branches.pipe_exponent, branches.tip_radius_m);
        build_tree_geometry_into(g, r.tree, branches, leaves, 1);
        benchmark::DoNotOptimize(g);
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(segments) * state.iterations());
    state.counters["segments"] = static_cast<double>(segments);
    state.counters["turtle_ms"] = turtle_ms / static_cast<double>(state.iterations());
    for (std::size_t i = 0; i < g.lods.size(); ++i)
        state.counters["tris_LOD" + std::to_string(i)] = static_cast<double>(lod_triangles(g.lods[i]));
}
BENCHMARK(BM_LSystemBracketedTreeGeometry)->Arg(7)->Arg(8)->Unit(benchmark::kMillisecond)->UseRealTime();

} // namespace
