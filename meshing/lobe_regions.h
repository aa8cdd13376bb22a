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
#include <cstdint>
#include <tuple>
#include <vector>

#include <glm/vec3.hpp>

#include "core/mesh.h"
#include "meshing/lobe_surface.h"

namespace lobe {

/// (direction x, y, z, position x, y, z, vertex): see fill_order_key.
using FillOrderKey = std::tuple<double, double, double, float, float, float, int>;

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

/// What keep_unchanged_regions (or continue_lobe_surface) did.
struct KeptRegions {
    int regions = 0;          ///< regions of the new surface
    int kept = 0;             ///< of them, taken from the previous surface
    std::size_t kept_triangles = 0;
    /// Only the regions that changed were built (continue_lobe_surface); false when the
    /// whole surface was built and the unchanged regions then swapped back.
    bool built_changed_only = false;
    /// The search for the pole, the crossings and the radius model took the previous build's
    /// over (the strokes before the new one unchanged, the same centre) and looked only at the
    /// new stroke where the answer could change (continue_lobe_surface).
    bool followed_previous_build = false;
};

/// Replaces every region of `next` whose stroke edges (directed, by position) are exactly
/// those of a region of `previous` by that region of `previous`: its triangles and its
/// inner (interpolated) vertices. Both surfaces must share their centre and reference
/// radius (the fill of a region depends on them); otherwise nothing is kept. The result is
/// canonical as build_lobe_surface's: stroke vertices in their order, interpolated vertices
/// sorted by direction, triangles sorted, each starting at its lowest index.
/// `previous_regions` are surface_regions(previous.mesh); `next_regions` is set to the
/// regions of the result (kept, so that the next stroke need not find them again). With
/// `next_regions_known`, `next_regions` holds surface_regions(next.mesh) on entry (the
/// builder knows them), and they are not found again.
KeptRegions keep_unchanged_regions(const LobeSurface& previous, const SurfaceRegions& previous_regions,
                                   LobeSurface& next, SurfaceRegions& next_regions, bool next_regions_known = false);

/// A stroke of the next surface as its vertices will lie: the stroke's samples, crossings and
/// subdivisions in order (the nodes the surface joins), at the positions the surface gives them.
struct RegionChain {
    std::vector<glm::vec3> points;
    bool closed = false;
    bool crossed = false; ///< crosses another stroke somewhere
};

/// Which regions of `previous` the next surface, through `chains`, leaves as they were, and
/// what a build of the rest needs. A region changes when one of its stroke edges is no
/// longer an edge of the chains (a new crossing split it, a sample next to the crossing was
/// dropped), or a chain runs through it (found by where an uncrossed new chain lies; a crossed
/// one enters every region it reaches across an edge it splits).
struct ChangedRegions {
    bool everything = false;  ///< no region of `previous` can be kept: build the whole surface
    std::vector<char> keep;   ///< per region of `previous`: left as it was
    /// Per chain, per edge (point i → i + 1): what the build of the changed regions does with it.
    enum Edge : std::uint8_t {
        Outside = 0,     ///< between two kept regions: not needed
        Inside = 1,      ///< in or between changed regions
        BorderAhead = 2, ///< between a changed and a kept region; the changed region's
                         ///< triangles run round it point i → i + 1 (as the surface faces outward)
        BorderBack = 3,  ///< … and the changed region's triangles run round it i + 1 → i
    };
    std::vector<std::vector<Edge>> edges;
};
ChangedRegions find_changed_regions(const LobeSurface& previous, const SurfaceRegions& previous_regions,
                                    const std::vector<RegionChain>& chains);

/// The key interpolated vertices are ordered by (build_lobe_surface's output and
/// complete_with_kept_regions'): the direction from `centre` of the stored (float) position,
/// then the position, then `vertex` (ties keep vertex order).
/// Defined out of line on purpose, so that both callers key the float as stored (why:
/// docs/lobes.md, "a compiler's rounding slip").
FillOrderKey fill_order_key(const glm::vec3& position, const glm::dvec3& centre, int vertex);

/// The second half of a build of only the changed regions: `next` has the triangles of the
/// changed regions (and every stroke vertex), `keep` (ChangedRegions::keep) says which regions
/// of `previous` complete it. Adds them, bit for bit, and any region of `next` whose stroke
/// edges are a region's of `previous` is swapped for it as keep_unchanged_regions does; the
/// result is canonical as build_lobe_surface's. False (and `next` unchanged) when a kept
/// region's stroke vertex is not one of `next`'s: then the whole surface must be built.
bool complete_with_kept_regions(const LobeSurface& previous, const SurfaceRegions& previous_regions,
                                const std::vector<char>& keep, LobeSurface& next, SurfaceRegions& next_regions,
                                KeptRegions& kept, bool next_regions_known = false);

/// The surface of `strokes` around `centre` after a stroke was added to (or changed in) the
/// lobe whose surface was `previous`: the same, bit for bit, as build_lobe_surface followed by
/// keep_unchanged_regions, but only the regions that changed are built (a constrained
/// triangulation of their strokes alone, filled and solved region by region), so its time
/// follows what the stroke changed rather than the lobe's size. Falls back to the whole build
/// where the changed part cannot be told apart (`kept.built_changed_only` says which).
/// \throw InvalidInput as build_lobe_surface.
LobeSurface continue_lobe_surface(const LobeSurface& previous, const SurfaceRegions& previous_regions,
                                  const std::vector<LobeStrokeSamples>& strokes, const glm::dvec3& centre,
                                  const LobeSurfaceOptions& options, SurfaceRegions& regions, KeptRegions& kept);

} // namespace lobe
