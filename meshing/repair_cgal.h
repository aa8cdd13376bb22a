#pragma once
/// \file repair_cgal.h
/// Internal to the translation units of repair_mesh (repair.h) that include CGAL:
/// repair_cgal.cpp (the steps of the repair) and hole_filling_cgal.cpp (step 4, the holes).
/// Like cgal_prelude.h, included by *_cgal.cpp files only.

#include <array>
#include <cstddef>
#include <optional>
#include <vector>

#include "core/mesh.h"
#include "meshing/cgal_prelude.h"
#include "meshing/repair.h"

namespace lobe::repair_detail {

/// A compact (garbage-free) Surface_mesh as a TriangleMesh (repair_cgal.cpp).
TriangleMesh to_triangle_mesh(cgal::Mesh& mesh);

/// The pairs of intersecting triangles of `tm`; nothing when it is not 2-manifold as a soup
/// (the self-intersection step says so, as it always did) (repair_cgal.cpp).
std::optional<std::vector<std::array<std::size_t, 2>>> crossing_pairs(const TriangleMesh& tm);

/// Fills every hole with a refined, faired patch (hole_filling_cgal.cpp).
/// Fairing keeps the patch's interior smooth but not out of the surface's way: over a long,
/// wavy border (the open base of a scan, say) the faired patch can fold through itself or
/// the surface. Those holes are filled again with the refined patch alone, which lies on the
/// border's triangulation. Left to CGAL's self-intersection removal, such a fold cost a minute on a
/// 1,000-edge border and took most of the mesh with it. `pairs` (when given) receives the
/// intersecting pairs of the result when they were found on the way (one pass saved).
/// Counts what it did in `r` (holes_filled, holes_faired, holes_not_faired, holes_fanned, notes).
/// \throw InvalidInput when a hole stays open.
void fill_holes(cgal::Mesh& mesh, RepairReport& r,
                std::optional<std::vector<std::array<std::size_t, 2>>>* pairs = nullptr);

} // namespace lobe::repair_detail
