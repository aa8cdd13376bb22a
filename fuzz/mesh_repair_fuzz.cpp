// libFuzzer target: OBJ meshes read by parse_mesh and handed to repair_mesh, the first step
// of a lobe from a model (`lobesketch lobes MESH`): whatever the mesh, repair either returns a
// closed, 2-manifold, outward-oriented surface or refuses with a one-line InvalidInput.
#include <cstdint>

#include "fuzz/fuzz_common.h"
#include "meshing/mesh_io.h"
#include "meshing/mesh_quality.h"
#include "meshing/repair.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const std::string bytes = lobe::fuzz::as_string(data, size);
    return lobe::fuzz::run_reader([&] {
        const lobe::TriangleMesh in = lobe::parse_mesh(bytes, "fuzz.obj");
        lobe::RepairReport report;
        const lobe::TriangleMesh out = lobe::repair_mesh(in, &report);
        lobe::fuzz::check_mesh(out);
        const lobe::MeshQuality q = lobe::measure_quality(out);
        lobe::fuzz::require(q.closed && q.manifold && q.outward, "a repaired mesh that is not closed, 2-manifold and outward");
        lobe::fuzz::require(report.output_triangles == out.triangles.size(), "a report that miscounts the triangles");
        for (const std::string& note : report.notes) lobe::fuzz::check_one_line(note.c_str());
    });
}
