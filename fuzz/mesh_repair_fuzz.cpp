// libFuzzer target: OBJ meshes read by parse_mesh, then
// - simplified by vertex clustering and repaired, as meshes of over a million triangles are
//   (cluster_vertices, lobe_from_mesh);
// - repaired as read (repair_mesh, the first step of `lobesketch lobes MESH`) and remeshed
//   twice: by CGAL's rounds (remesh_isotropic's default, as lobes from models are remeshed)
//   and by our rounds (own_rounds, as every lobe drawn with strokes is remeshed).
// Repair either returns a closed, 2-manifold, outward-oriented surface, free of
// self-intersections unless its report says some were left, or refuses with a one-line
// InvalidInput; so does each remeshing.
//
// The remeshing runs at 15 cm instead of 3 cm so that one input takes milliseconds; its code
// paths are the same. This target once found CGAL 5.5's tangential relaxation reading an edge
// property at a null halfedge (index −1) where every face around a vertex is exactly
// degenerate, on integer-coordinate slivers; remesh_cgal.cpp now runs its own relaxation in
// CGAL's rounds (docs/fuzzing.md, "Findings").
#include <algorithm>
#include <cstdint>

#include <glm/vec3.hpp>

#include "fuzz/fuzz_common.h"
#include "fuzz/repair_checks.h"
#include "meshing/mesh_io.h"
#include "meshing/mesh_quality.h"
#include "meshing/model_import.h"
#include "meshing/remesh.h"
#include "meshing/repair.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const std::string bytes = lobe::fuzz::as_string(data, size);
    return lobe::fuzz::run_reader([&] {
        const lobe::TriangleMesh in = lobe::parse_mesh(bytes, "fuzz.obj");
        {
            // The simplification meshes of over a million triangles get before repair
            // (cluster_vertices, lobe_from_mesh), in cubes of 1/2 to 1/257 of the largest side
            // as the last byte says, then repaired: the same checks, or a one-line refusal.
            glm::dvec3 lo, hi;
            lobe::bounding_box(in, lo, hi);
            const double largest = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
            if (largest > 0) {
                const lobe::TriangleMesh clustered = lobe::cluster_vertices(in, largest / (2.0 + data[size - 1]));
                try {
                    lobe::RepairReport clustered_report;
                    lobe::fuzz::check_repaired(lobe::repair_mesh(clustered, &clustered_report), clustered_report);
                } catch (const lobe::InvalidInput& e) {
                    lobe::fuzz::check_one_line(e.what());
                }
            }
        }
        lobe::RepairReport report;
        const lobe::TriangleMesh repaired = lobe::repair_mesh(in, &report);
        lobe::fuzz::check_repaired(repaired, report);

        const lobe::TriangleMesh boxed = lobe::normalize_to_box(repaired, 1.5);
        for (const bool own_rounds : {false, true}) {
            lobe::RemeshOptions options;
            options.target_edge_length_m = 0.15;
            options.iterations = 3;
            options.own_rounds = own_rounds;
            const lobe::TriangleMesh lobe = lobe::remesh_isotropic(boxed, options);
            const lobe::MeshQuality l = lobe::measure_quality(lobe);
            lobe::check_encloses_volume(lobe, l, "the remeshed lobe"); // a flattened sliver is refused
            lobe::fuzz::require(l.closed && l.manifold && l.outward,
                                "a remeshed lobe that is not closed, 2-manifold and outward");
        }
    });
}
