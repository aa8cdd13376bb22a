// libFuzzer target: repair_mesh on meshes with one long hole (over the 200 edges above which
// holes are triangulated in their plane or fanned from their centre instead of CGAL's search
// for the best patch; docs/lobes-from-models.md, step 4). A text mesh small enough for the
// other mesh targets cannot hold such a hole, so the bytes choose a shape and bend it
// (tests/support/hole_meshes.h, hole_fill_mesh, which the repair tests use for the findings too):
//   byte 0      shape: even a dome whose open base runs up and down in waves, odd a sphere
//               with a slit along its equator;
//   bytes 1–2   border edges (dome: 201–700) or the slit's length (sphere: 60°–330°);
//   byte 3      waves (dome) or latitude bands (sphere: 20–83);
//   byte 4      the waves' amplitude, 0–50° of latitude (dome);
//   the rest    each byte moves one vertex (in order from the ring at the hole's edge) by up
//               to ±5 % of the radius along an axis the byte also picks.
// The input may intersect itself (a steep base folds the dome's first band). The promise:
// a closed, 2-manifold, outward-oriented surface, or a one-line refusal; a report whose counts
// add up; one-line notes; no self-intersection unless the report says some were left; and
// within the fuzzer's time and memory limits. A repair that cut nothing (no crossing: a
// second repair is cheap then) is made again and must give the same bytes: repair may not
// depend on what ran before in the process (docs/lobes-from-models.md, Limits).
#include <cstdint>

#include "fuzz/fuzz_common.h"
#include "fuzz/repair_checks.h"
#include "meshing/repair.h"
#include "tests/support/hole_meshes.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const lobe::TriangleMesh m = lobe::test::hole_fill_mesh(data, size);
    if (m.triangles.empty()) return 0;
    return lobe::fuzz::run_reader([&] {
        lobe::RepairReport report;
        const lobe::TriangleMesh repaired = lobe::repair_mesh(m, &report);
        lobe::fuzz::check_repaired(repaired, report);
        if (report.crossing_pairs == 0) {
            const lobe::TriangleMesh again = lobe::repair_mesh(m);
            lobe::fuzz::require(again.positions == repaired.positions && again.triangles == repaired.triangles,
                                "a mesh that repairs to another surface the second time");
        }
    });
}
