#pragma once
/// \file lobe_regions.h
/// The stroke-bounded regions of a lobe surface and what stays of them when a stroke is
/// added. See docs/lobes.md ("What changes when a stroke is added").
///
/// The strokes cut a lobe's surface into regions: strips between two strokes, caps over a
/// region one stroke encloses, cells between crossing strokes. Every region is bounded by
/// stroke edges (TriangleMesh::feature_edges) and nothing inside it depends on anything
/// outside it but the lobe's centre and the smooth radius model its fill follows. So a
/// region whose stroke edges are exactly those it had before a stroke was added can keep
/// its triangles and vertices, bit for bit (keep_unchanged_regions); only the regions the
/// new stroke runs through (or whose boundary it moved, at a crossing) change.

#include <array>
#include <cstddef>
#include <vector>

#include "core/mesh.h"
#include "meshing/lobe_surface.h"

namespace lobe {

/// The regions of `mesh`: faces connected across edges that are not feature edges. Regions
/// are numbered in the order of their first triangle.
struct MeshRegions {
    std::vector<int> face_region; ///< #F: region of each triangle
    int count = 0;
};
MeshRegions mesh_regions(const TriangleMesh& mesh);

/// A stroke edge of a region, directed as the region's triangles run round it, by the
/// positions of its ends (x, y, z of the first, then of the second).
using RegionStrokeEdge = std::array<float, 6>;
/// Every region's stroke edges, sorted: what identifies a region from one surface to the next.
std::vector<std::vector<RegionStrokeEdge>> region_stroke_edges(const TriangleMesh& mesh, const MeshRegions& regions);

/// A surface's regions and their stroke edges.
struct SurfaceRegions {
    MeshRegions regions;
    std::vector<std::vector<RegionStrokeEdge>> edges; ///< per region, as region_stroke_edges
};
SurfaceRegions surface_regions(const TriangleMesh& mesh);

/// What keep_unchanged_regions did.
struct KeptRegions {
    int regions = 0;          ///< regions of the new surface
    int kept = 0;             ///< of them, taken from the previous surface
    std::size_t kept_triangles = 0;
};

/// Replaces every region of `next` whose stroke edges (directed, by position) are exactly
/// those of a region of `previous` by that region of `previous`: its triangles and its
/// inner (interpolated) vertices. Both surfaces must share their centre and reference
/// radius (the fill of a region depends on them); otherwise nothing is kept. The result is
/// canonical as build_lobe_surface's: stroke vertices in their order, interpolated vertices
/// sorted by direction, triangles sorted, each starting at its lowest index.
/// `previous_regions` are surface_regions(previous.mesh); `next_regions` is set to the
/// regions of the result (kept, so that the next stroke need not find them again).
KeptRegions keep_unchanged_regions(const LobeSurface& previous, const SurfaceRegions& previous_regions,
                                   LobeSurface& next, SurfaceRegions& next_regions);

} // namespace lobe
