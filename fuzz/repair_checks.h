/// \file repair_checks.h
/// What every fuzz target that repairs a mesh (mesh_repair, hole_fill) asks of repair_mesh's
/// result and report (meshing/repair.h).
#pragma once

#include <string>

#include "fuzz/fuzz_common.h"
#include "meshing/mesh_quality.h"
#include "meshing/repair.h"

namespace lobe::fuzz {

/// A closed, 2-manifold, outward surface; a report whose counts add up and whose notes are one
/// line each; no self-intersection unless the report says some were left.
inline void check_repaired(const lobe::TriangleMesh& repaired, const lobe::RepairReport& report)
{
    check_mesh(repaired);
    const lobe::MeshQuality q = lobe::measure_quality(repaired);
    require(q.closed && q.manifold && q.outward, "a repaired mesh that is not closed, 2-manifold and outward");
    require(report.output_triangles == repaired.triangles.size(), "a repair report that miscounts the triangles");
    require(report.holes_faired + report.holes_not_faired <= report.holes_filled &&
                report.holes_fanned <= report.holes_filled,
            "a repair report whose hole counts do not add up");
    for (const std::string& note : report.notes) check_one_line(note.c_str());
    require(report.self_intersections_left == (report.crossing_pairs_left > 0),
            "a repair report whose crossings left do not add up");
    require(report.self_intersections_left || !lobe::self_intersects(repaired),
            "a repaired mesh reported free of self-intersections that has some");
}

} // namespace lobe::fuzz
