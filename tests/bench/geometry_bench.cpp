// Branch and leaf geometry of the largest scene's tree (about 30,000 nodes, 5,000 tips), all
// LODs at once. Goal: ≤ 20 ms. Run with --benchmark_repetitions=5 and read the median.
#include <benchmark/benchmark.h>

#include <string>

#include "growth/branch_geometry.h"
#include "growth/leaves.h"
#include "tests/support/tree_fixtures.h"

using namespace lobe;

namespace {
const TreeGraph& large_tree()
{
    static const TreeGraph tree = test::large_test_tree();
    return tree;
}
} // namespace

static void BM_GeometryLargeTreeAllLods(benchmark::State& state)
{
    const TreeGraph& tree = large_tree();
    const BranchSettings branches;
    const LeafSettings leaves;
    TreeGeometry geo;
    for (auto _ : state) {
        geo = build_tree_geometry(tree, branches, leaves, 1, "broadleaf");
        benchmark::DoNotOptimize(geo.lods.data());
    }
    state.counters["nodes"] = static_cast<double>(tree.size());
    state.counters["tips"] = static_cast<double>(leaf_tip_nodes(tree).size());
    for (std::size_t k = 0; k < geo.lods.size(); ++k) {
        const std::string lod = "lod" + std::to_string(k);
        state.counters[lod + "_branch_tris"] = static_cast<double>(geo.lods[k].branches.triangle_count());
        state.counters[lod + "_leaf_tris"] = static_cast<double>(geo.lods[k].leaves.triangle_count());
    }
}
BENCHMARK(BM_GeometryLargeTreeAllLods)->Unit(benchmark::kMillisecond);

// The editor's pattern: rebuild into a TreeGeometry whose storage is kept between regrowths,
// so no fresh pages are mapped for the meshes.
static void BM_GeometryLargeTreeAllLodsReusedStorage(benchmark::State& state)
{
    const TreeGraph& tree = large_tree();
    const BranchSettings branches;
    const LeafSettings leaves;
    TreeGeometry geo;
    build_tree_geometry_into(geo, tree, branches, leaves, 1, "broadleaf");
    for (auto _ : state) {
        build_tree_geometry_into(geo, tree, branches, leaves, 1, "broadleaf");
        benchmark::DoNotOptimize(geo.lods.data());
    }
    std::size_t triangles = 0;
    for (const TreeLod& lod : geo.lods) triangles += lod.branches.triangle_count() + lod.leaves.triangle_count();
    state.counters["all_lod_tris"] = static_cast<double>(triangles);
}
BENCHMARK(BM_GeometryLargeTreeAllLodsReusedStorage)->Unit(benchmark::kMillisecond);

static void BM_GeometryLargeTreeLod0Branches(benchmark::State& state)
{
    const TreeGraph& tree = large_tree();
    const auto curves = smooth_branch_curves(tree, decompose_branch_chains(tree), 2);
    for (auto _ : state) {
        SurfaceGeometry s = build_branch_mesh(curves, BranchMeshOptions{});
        benchmark::DoNotOptimize(s.positions.data());
    }
}
BENCHMARK(BM_GeometryLargeTreeLod0Branches)->Unit(benchmark::kMillisecond);

static void BM_GeometryLargeTreeLeaves(benchmark::State& state)
{
    const TreeGraph& tree = large_tree();
    for (auto _ : state) {
        SurfaceGeometry s = build_leaf_quads(tree, LeafSettings{}, 1);
        benchmark::DoNotOptimize(s.positions.data());
    }
}
BENCHMARK(BM_GeometryLargeTreeLeaves)->Unit(benchmark::kMillisecond);

static void BM_GeometryLeafTexture(benchmark::State& state)
{
    for (auto _ : state) {
        RgbaImage img = make_leaf_texture("ovate", 128);
        benchmark::DoNotOptimize(img.pixels.data());
    }
}
BENCHMARK(BM_GeometryLeafTexture)->Unit(benchmark::kMillisecond);
