// The self-organizing model (growth/selforg/): free growth by shadow propagation up to 50k,
// 200k and 500k internodes (issue 41: 500k ≤ 5 s on one core, cost linear in internodes;
// Palubicki 2009: 642,000 in 60 s), and a regrowth of a ~20k-internode tree in a lobe with
// markers and shadow (issue 41: ≤ 100 ms).
#include <benchmark/benchmark.h>

#include <cmath>

#include <sys/resource.h>

#include "growth/grower.h"
#include "growth/selforg/selforg_grower.h"
#include "growth/selforg/selforg_model.h"
#include "growth/selforg/shadow_grid.h"
#include "tests/support/shapes.h"

using namespace lobe;

namespace {

// Free growth in the shadow environment from one internode, until the tree holds
// state.range(0) metamers (the grid, 240 internodes wide and high, holds the crown), with no
// shedding (every metamer stays in the tree) or with the preset's threshold 0.25 (most are
// made and shed again: state.range(1) is the threshold in hundredths). 1M: the memory bound
// (issue 41: ≤ 1 GB), read from peak_rss_MiB when run alone.
void BM_SelfOrgFreeShadow(benchmark::State& state)
{
    const std::size_t target = static_cast<std::size_t>(state.range(0));
    SelfOrgSpecies sp = selforg_species("broadleaf");
    sp.shed_threshold = static_cast<double>(state.range(1)) / 100.0;
    SelfOrgRun run;
    run.species = sp;
    run.environment = SelfOrgEnvironment::Shadow;
    run.iterations = 500;
    run.internode_m = 1.0;
    run.max_metamers = target;
    std::size_t metamers = 0, alive = 0;
    int iterations = 0;
    for (auto _ : state) {
        ShadowGrid shadow(glm::vec3(-120.0f, -1.0f, -120.0f), glm::vec3(120.0f, 240.0f, 120.0f), 1.0,
                          {sp.shadow_a, sp.shadow_b, sp.shadow_q_max, sp.light_c});
        MetamerTree tree;
        tree.metamers.reserve(target);
        Metamer m;
        m.tip = glm::vec3(0.0f, 1.0f, 0.0f);
        m.terminal_bud = true;
        tree.add(m, false);
        shadow.cast(m.tip);
        const SelfOrgStats stats = grow_metamers(tree, run, nullptr, shadow);
        metamers = tree.metamers.size();
        alive = 0;
        for (const Metamer& mm : tree.metamers) alive += mm.alive;
        iterations = stats.iterations;
        benchmark::DoNotOptimize(tree);
    }
    state.counters["metamers"] = static_cast<double>(metamers);
    state.counters["alive"] = static_cast<double>(alive);
    state.counters["iterations"] = iterations;
    // The process's peak resident memory so far (run one size alone to read it for that size).
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    state.counters["peak_rss_MiB"] = static_cast<double>(usage.ru_maxrss) / 1024.0;
}
BENCHMARK(BM_SelfOrgFreeShadow)->ArgsProduct({{50000, 200000, 500000, 1000000}, {0, 25}})->Unit(benchmark::kMillisecond);

// The whole grower in one bumpy lobe (a test shape) with the default trunk: markers fill the
// lobe, everything casts shadow; internode chosen for about 20k internodes.
void BM_SelfOrgRegrowInLobe(benchmark::State& state)
{
    GrowerInput in;
    GrowthLobe l;
    l.id = 1;
    l.mesh = test::icosphere(4, [](const glm::dvec3& u) { return 0.45 + 0.08 * std::sin(3.0 * u.x) * std::cos(2.0 * u.z); },
                             glm::dvec3(0.0, 1.4, 0.0));
    in.lobes.push_back(l);
    in.choice.name = "self-organizing";
    in.choice.params["environment"] = std::string(state.range(0) ? "shadow" : "markers");
    in.choice.params["internode_m"] = state.range(0) ? 0.009 : 0.0105;
    std::size_t nodes = 0;
    for (auto _ : state) {
        const GrowthResult r = self_organizing_grower().grow(in);
        nodes = r.tree.size();
        benchmark::DoNotOptimize(r);
    }
    state.SetLabel(state.range(0) ? "shadow" : "markers");
    state.counters["nodes"] = static_cast<double>(nodes);
}
BENCHMARK(BM_SelfOrgRegrowInLobe)->DenseRange(0, 1)->Unit(benchmark::kMillisecond);

} // namespace
