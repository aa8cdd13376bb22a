#pragma once
/// \file model_import.h
/// Lobes from external meshes (the paper grows trees in the Stanford bunny, a cow and
/// Nefertiti, Fig. 14): read, repair, scale into a box, remesh to the attractor spacing.
/// See docs/lobes-from-models.md.

#include <string>

#include "core/mesh.h"
#include "meshing/repair.h"

namespace lobe {

/// Uniformly scales and moves `mesh` so that its bounding box's largest side is `size_m`,
/// centred on the origin in x and z, its lowest point at y = 0.
/// \throw InvalidInput when the mesh has no vertex, a non-finite coordinate, or zero extent.
TriangleMesh normalize_to_box(const TriangleMesh& mesh, double size_m = 1.5);

/// Options of lobe_from_model().
struct LobeFromModelOptions {
    double size_m = 1.5;                 ///< largest side of the lobe's bounding box
    double target_edge_length_m = 0.03;  ///< attractor spacing (RemeshOptions)
    unsigned iterations = 3;             ///< remeshing rounds (RemeshOptions)
};

/// repair_mesh → normalize_to_box → remesh_isotropic, and the result checked: closed,
/// 2-manifold, enclosing a volume (check_encloses_volume). `report` (optional) receives what
/// repair did.
/// \throw InvalidInput for a mesh beyond repair, or one that remeshing flattened (one line).
TriangleMesh lobe_from_mesh(const TriangleMesh& mesh, const LobeFromModelOptions& options = {},
                            RepairReport* report = nullptr);

/// read_mesh → lobe_from_mesh, errors naming the file.
/// \throw FileError for an unreadable or malformed file; InvalidInput for a mesh beyond
/// repair.
TriangleMesh lobe_from_model(const std::string& path, const LobeFromModelOptions& options = {},
                             RepairReport* report = nullptr);

} // namespace lobe
