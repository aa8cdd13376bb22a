// lobe_from_model() includes no CGAL header itself; it lives in the lobe_meshing_cgal target
// (hence the file name) because it calls repair_mesh() and remesh_isotropic().
#include "meshing/model_import.h"

#include "core/errors.h"
#include "meshing/mesh_io.h"
#include "meshing/mesh_quality.h"
#include "meshing/remesh.h"

namespace lobe {

TriangleMesh lobe_from_mesh(const TriangleMesh& mesh, const LobeFromModelOptions& options, RepairReport* report)
{
    const TriangleMesh repaired = repair_mesh(mesh, report);
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
