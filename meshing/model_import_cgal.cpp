// lobe_from_model() includes no CGAL header itself; it lives in the lobe_meshing_cgal target
// (hence the file name) because it calls repair_mesh() and remesh_isotropic().
#include "meshing/model_import.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <glm/vec3.hpp>

#include "core/errors.h"
#include "meshing/mesh_io.h"
#include "meshing/mesh_quality.h"
#include "meshing/remesh.h"

namespace lobe {

TriangleMesh lobe_from_mesh(const TriangleMesh& mesh, const LobeFromModelOptions& options, RepairReport* report)
{
    // A mesh far finer than the lobe's spacing is simplified first (LobeFromModelOptions).
    TriangleMesh simplified;
    double cell_m = 0;
    if (options.simplify_above_triangles > 0 && mesh.triangles.size() > options.simplify_above_triangles &&
        options.simplify_cell_fraction > 0) {
        glm::dvec3 lo, hi;
        bounding_box(mesh, lo, hi);
        const double largest = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
        cell_m = options.simplify_cell_fraction * options.target_edge_length_m;
        const double cell = cell_m * largest / options.size_m; // in the mesh's own units
        if (std::isfinite(cell) && cell > 0) simplified = cluster_vertices(mesh, cell);
        else cell_m = 0; // no extent or not finite: repair and scaling refuse it as it is
    }
    TriangleMesh repaired;
    if (cell_m > 0) {
        try {
            repaired = repair_mesh(simplified, report);
        } catch (const InvalidInput&) {
            cell_m = 0; // the simplified mesh is beyond repair: the mesh as it was, as below
        }
    }
    if (cell_m > 0) {
        if (report) {
            report->simplified_from_triangles = mesh.triangles.size();
            report->simplify_cell_m = cell_m;
            char note[200];
            std::snprintf(note, sizeof note,
                          "simplified %zu triangles to %zu by merging the vertices within each %.3g mm cube",
                          mesh.triangles.size(), simplified.triangles.size(), cell_m * 1000.0);
            report->notes.insert(report->notes.begin(), note);
        }
    } else {
        repaired = repair_mesh(mesh, report);
    }
    const TriangleMesh scaled = normalize_to_box(repaired, options.size_m);
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
