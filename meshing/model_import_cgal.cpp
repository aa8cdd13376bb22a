// lobe_from_model() includes no CGAL header itself; it lives in the lobe_meshing_cgal target
// (hence the file name) because it calls repair_mesh() and remesh_isotropic().
#include "meshing/model_import.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <optional>
#include <vector>

#include "core/errors.h"
#include "meshing/mesh_io.h"
#include "meshing/mesh_quality.h"
#include "meshing/remesh.h"

namespace lobe {

namespace {

/// The largest side of the box that holds the middle 99 % of the vertices triangles use
/// (0.5 % cut off at each end of each axis): the extent the lobe will be scaled from, unmoved
/// by a few stray points or specks far away, which repair drops (unused vertices, smaller
/// components). 0 when it has no extent; not finite when a coordinate is not.
double robust_extent(const TriangleMesh& mesh)
{
    std::vector<char> used(mesh.positions.size(), 0);
    for (const auto& t : mesh.triangles)
        for (int v : t)
            if (v >= 0 && static_cast<std::size_t>(v) < used.size()) used[static_cast<std::size_t>(v)] = 1;
    std::vector<float> c;
    double largest = 0;
    for (int axis = 0; axis < 3; ++axis) {
        c.clear();
        for (std::size_t v = 0; v < used.size(); ++v)
            if (used[v]) c.push_back(mesh.positions[v][axis]);
        if (c.empty()) return 0;
        for (float x : c)
            if (!std::isfinite(x)) return x;
        const std::size_t cut = c.size() / 200;
        std::nth_element(c.begin(), c.begin() + static_cast<std::ptrdiff_t>(cut), c.end());
        const double lo = c[cut];
        std::nth_element(c.begin(), c.end() - 1 - static_cast<std::ptrdiff_t>(cut), c.end());
        largest = std::max(largest, static_cast<double>(c[c.size() - 1 - cut]) - lo);
    }
    return largest;
}

} // namespace

TriangleMesh lobe_from_mesh(const TriangleMesh& mesh, const LobeFromModelOptions& options, RepairReport* report)
{
    // A mesh far finer than the lobe's spacing is simplified first (LobeFromModelOptions);
    // where repair refuses the simplified mesh, or none was made, the mesh as read is repaired.
    std::optional<TriangleMesh> repaired;
    if (options.simplify_above_triangles > 0 && mesh.triangles.size() > options.simplify_above_triangles &&
        options.simplify_cell_fraction > 0) {
        const double cell_m = options.simplify_cell_fraction * options.target_edge_length_m;
        const double cell = cell_m * robust_extent(mesh) / options.size_m; // in the mesh's own units
        if (std::isfinite(cell) && cell > 0) { // else no extent or not finite: refused below
            const TriangleMesh simplified = cluster_vertices(mesh, cell);
            try {
                repaired = repair_mesh(simplified, report);
            } catch (const InvalidInput&) {
                // beyond repair once simplified: the mesh as read, below
            }
            if (repaired && report) {
                report->simplified_from_triangles = mesh.triangles.size();
                report->simplify_cell_m = cell_m;
                char note[200];
                std::snprintf(note, sizeof note,
                              "simplified %zu triangles to %zu by merging the vertices within each %.3g mm cube",
                              mesh.triangles.size(), simplified.triangles.size(), cell_m * 1000.0);
                report->notes.insert(report->notes.begin(), note);
            }
        }
    }
    if (!repaired) repaired = repair_mesh(mesh, report);
    const TriangleMesh scaled = normalize_to_box(*repaired, options.size_m);
    RemeshOptions ro;
    ro.target_edge_length_m = options.target_edge_length_m;
    ro.iterations = options.iterations;
    TriangleMesh lobe = remesh_isotropic(scaled, ro);
    // Remeshing a sliver of a repaired mesh can collapse it flat; no such lobe leaves here.
    check_encloses_volume(lobe, measure_quality(lobe), "the remeshed lobe");
    return lobe;
}

TriangleMesh lobe_from_model(const std::string& path, const LobeFromModelOptions& options, RepairReport* report)
{
    const TriangleMesh raw = read_mesh(path);
    try {
        return lobe_from_mesh(raw, options, report);
    } catch (const InvalidInput& e) {
        throw InvalidInput(path + ": " + e.what()); // one line that names the file
    }
}

} // namespace lobe
