#pragma once
/// \file cgal_prelude.h
/// The start of every translation unit that includes CGAL: the meshing/*_cgal.cpp files and
/// the CGAL benchmarks, never a header that others include (DESIGN.md: compile time).
///
/// CGAL's and OpenMesh's headers do not build cleanly under our warnings (-Wconversion,
/// -Wshadow, …): include them between LOBE_CGAL_HEADERS_BEGIN and LOBE_CGAL_HEADERS_END,
///
///     #include "meshing/cgal_prelude.h"
///     LOBE_CGAL_HEADERS_BEGIN
///     #include <CGAL/Surface_mesh.h>
///     LOBE_CGAL_HEADERS_END
///
/// and name the kernel and the halfedge mesh by the aliases in lobe::cgal.

#ifdef __clang__ // Clang has no -Wmaybe-uninitialized and would warn about the pragma
#define LOBE_CGAL_IGNORE_GCC_ONLY_WARNINGS
#else
#define LOBE_CGAL_IGNORE_GCC_ONLY_WARNINGS _Pragma("GCC diagnostic ignored \"-Wmaybe-uninitialized\"")
#endif

#define LOBE_CGAL_HEADERS_BEGIN                                    \
    _Pragma("GCC diagnostic push")                                 \
    _Pragma("GCC diagnostic ignored \"-Wconversion\"")             \
    _Pragma("GCC diagnostic ignored \"-Wshadow\"")                 \
    _Pragma("GCC diagnostic ignored \"-Wsign-conversion\"")        \
    _Pragma("GCC diagnostic ignored \"-Wunused-parameter\"")       \
    _Pragma("GCC diagnostic ignored \"-Wpedantic\"")               \
    _Pragma("GCC diagnostic ignored \"-Wdeprecated-copy\"")        \
    _Pragma("GCC diagnostic ignored \"-Woverloaded-virtual\"")     \
    LOBE_CGAL_IGNORE_GCC_ONLY_WARNINGS

#define LOBE_CGAL_HEADERS_END _Pragma("GCC diagnostic pop")

#include <cstddef>
#include <vector>

#include "core/mesh.h"

LOBE_CGAL_HEADERS_BEGIN
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh/Surface_mesh_fwd.h>
LOBE_CGAL_HEADERS_END

namespace CGAL::Polygon_mesh_processing {
} // namespace CGAL::Polygon_mesh_processing

namespace lobe::cgal {

/// The kernel of every CGAL call: exact predicates, constructions in double.
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
/// CGAL's halfedge mesh (repair, self-intersections); include <CGAL/Surface_mesh.h> to use it.
using Mesh = CGAL::Surface_mesh<Point>;

namespace PMP = CGAL::Polygon_mesh_processing;

/// A triangle of a polygon soup: indices into its points.
using Polygon = std::vector<std::size_t>;

/// `in` as a polygon soup, its preconditions checked (repair_cgal.cpp).
/// \throw InvalidInput ("WHO: vertex with a non-finite coordinate", "WHO: triangle index out
/// of range").
void to_polygon_soup(const TriangleMesh& in, const char* who, std::vector<Point>& points,
                     std::vector<Polygon>& polygons);

} // namespace lobe::cgal
