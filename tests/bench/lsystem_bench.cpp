// L-systems (issue 39, Performance): bracketed context-free rewriting (≥ 50 M modules/s),
// parametric rewriting with conditions (≥ 5 M modules/s), stochastic rewriting, and turtle
// interpretation plus branch geometry for 100k segments (≤ 100 ms).
//
// A rewriting benchmark's modules/s counts the modules written: the sum of the word's
// length after every step, from the axiom to the last step. scripts/lsystem-compare.sh runs
// the same grammars for the same number of steps (so the same words) in the npm package
// `lindenmayer` (tests/bench/lsystem_lindenmayer.cjs) and prints the medians side by side.
#include <benchmark/benchmark.h>

#include <cstddef>
#include <string>

#include "growth/lsystem/lsystem.h"

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

} // namespace
