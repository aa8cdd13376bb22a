// Remeshing a sketched-size lobe (a bumpy sphere of ~40 cm diameter, 5,120 triangles at
// ~1.3 cm) to the 3 cm attractor spacing: remesh_isotropic (3 iterations, OpenMesh) beside a
// plain default CGAL isotropic_remeshing call with 10 iterations on a CGAL::Surface_mesh.
// Quality of each result is reported as counters. Goal: remesh_isotropic ≤ 20 ms.
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "meshing/cgal_prelude.h"
LOBE_CGAL_HEADERS_BEGIN
#include <CGAL/Polygon_mesh_processing/remesh.h>
#include <CGAL/Surface_mesh.h>
LOBE_CGAL_HEADERS_END

#include <glm/geometric.hpp>

#include "meshing/mesh_quality.h"
#include "meshing/remesh.h"
#include "tests/bench/cgal_surface_mesh.h"
#include "tests/support/shapes.h"

using namespace lobe;
using lobe::bench::from_surface_mesh;
using lobe::bench::to_surface_mesh;

namespace {

/// A lobe-like closed surface: an icosphere of radius 0.2 m (4 subdivisions) with smooth
/// bumps of ±2 cm.
TriangleMesh bumpy_lobe()
{
    return test::icosphere(4, [](const glm::dvec3& n) {
        return 0.2 + 0.02 * std::sin(3.0 * n.x) * std::cos(2.0 * n.y + 1.0) * std::sin(2.5 * n.z + 0.5);
    });
}

const TriangleMesh& bench_lobe()
{
    static const TriangleMesh m = bumpy_lobe();
    return m;
}

void report_quality(benchmark::State& state, const TriangleMesh& out)
{
    const MeshQuality q = measure_quality(out);
    state.counters["triangles"] = static_cast<double>(q.triangles);
    state.counters["min_angle_deg"] = q.min_angle_deg;
    state.counters["pct_ge_30deg"] = 100.0 * q.share_all_angles_ge_30;
    state.counters["n_lt_15deg"] = static_cast<double>(q.count_angle_lt_15);
    state.counters["edge_mean_mm"] = 1000.0 * q.edge_mean_m;
    state.counters["edge_sd_mm"] = 1000.0 * q.edge_stddev_m;
    // Vertices lie on the input (projection); triangle centroids and edge midpoints show the
    // chordal deviation.
    TriangleMesh samples;
    for (const auto& t : out.triangles) {
        const glm::vec3 a = out.positions[static_cast<std::size_t>(t[0])], b = out.positions[static_cast<std::size_t>(t[1])],
                        c = out.positions[static_cast<std::size_t>(t[2])];
        samples.positions.push_back((a + b + c) / 3.0f);
        samples.positions.push_back(0.5f * (a + b));
    }
    state.counters["hausdorff_mm"] = 1000.0 * max_vertex_distance(samples, bench_lobe());
}

} // namespace

static void BM_RemeshLobe40cmAt3cm(benchmark::State& state)
{
    TriangleMesh out;
    for (auto _ : state) {
        out = remesh_isotropic(bench_lobe());
        benchmark::DoNotOptimize(out.positions.data());
    }
    report_quality(state, out);
}
BENCHMARK(BM_RemeshLobe40cmAt3cm)->Unit(benchmark::kMillisecond);

static void BM_CgalDefaultRemesh10Iterations(benchmark::State& state)
{
    const cgal::Mesh input = to_surface_mesh(bench_lobe());
    cgal::Mesh sm;
    for (auto _ : state) {
        sm = input;
        CGAL::Polygon_mesh_processing::isotropic_remeshing(faces(sm), 0.03, sm,
                                                           CGAL::parameters::number_of_iterations(10));
        benchmark::DoNotOptimize(sm.number_of_faces());
    }
    report_quality(state, from_surface_mesh(sm));
}
BENCHMARK(BM_CgalDefaultRemesh10Iterations)->Unit(benchmark::kMillisecond);
