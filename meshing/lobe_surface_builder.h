#pragma once
/// \file lobe_surface_builder.h
/// Internal to meshing/: the stages of a lobe surface build (build_lobe_surface in
/// lobe_surface.h, continue_lobe_surface in lobe_regions.h) and what they hand each other,
/// for the lobe_surface_*.cpp files that implement them. No CGAL here: the one stage that
/// needs it, the constrained Delaunay triangulation on the sphere of directions, is the
/// class derived from LobeSurfaceBuilder in lobe_surface_cgal.cpp.
///
/// A build, in order:
///  1. check_strokes, make_directions, the memo of the previous build   lobe_surface_builder.cpp
///  2. choose_pole: the pole of the stereographic projection, the       lobe_surface_pole.cpp
///     direction farthest from every sample
///  3. find_crossings: where strokes cross, seen from the centre        lobe_surface_crossings.cpp
///  4. build_chains: each stroke's vertices, its crossings among them   lobe_surface_chains.cpp
///  5. plan_partial (after one more stroke): which regions change       lobe_surface_builder.cpp
///  6. the constrained Delaunay triangulation of the chains, its        lobe_surface_cgal.cpp
///     regions and paper strips, and the fill vertices (fill_lattice)   lobe_surface_fill.cpp
///  7. emit: the surface in canonical order, the fill's radii           lobe_surface_emit.cpp,
///     (solve_fill_radii)                                               lobe_surface_fill.cpp

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "core/mesh.h"
#include "meshing/lobe_regions.h"
#include "meshing/lobe_surface.h"
#include "meshing/stereographic.h"

namespace lobe {

/// See lobe_surface.h. Filled by every build; read by the next (LobeSurfaceBuilder::usable_memo)
/// only when the strokes it was made from are the first strokes of that build, unchanged,
/// around the same centre.
struct LobeBuildMemo {
    /// A crossing of segment `seg` of stroke `a` (at parameter `s`) with segment `other_seg`
    /// of stroke `b` (at `t`).
    struct Crossing {
        int a, seg, b, other_seg;
        double s, t;
        int node = -1;
    };
    glm::dvec3 centre{0.0};
    std::vector<std::vector<glm::vec3>> points; ///< per stroke, its samples (the directions follow from them)
    std::vector<char> closed;                  ///< per stroke
    /// The pole search (LobeSurfaceBuilder::choose_pole): per lattice candidate, the largest dot
    /// product of its direction with any sample, exact or (when it was pruned) a lower bound of it.
    std::vector<double> candidate_bound;
    std::vector<char> candidate_exact;
    glm::dvec3 start{0.0};  ///< the best candidate
    double start_dot = 0.0; ///< … its largest dot product
    /// Each round of pushing the pole away from its nearest sample.
    struct Step {
        int nearest = -1;       ///< index of the nearest sample (over all strokes, in order)
        bool accepted = false;  ///< the trial direction became the pole
        double value = 0.0;     ///< accepted: its largest dot product; else a lower bound ≥ the pole's
    };
    std::vector<Step> steps;
    /// The crossings of the strokes, as find_crossings found them.
    std::vector<Crossing> crossings;
    /// The radius model's normal equations, per stroke (fit_radius_model).
    struct FitPart {
        std::vector<double> key; ///< per row: its direction and radius
        Eigen::Matrix<double, 20, 20> ata = Eigen::Matrix<double, 20, 20>::Zero(); ///< lower triangle
        Eigen::Matrix<double, 20, 1> atb = Eigen::Matrix<double, 20, 1>::Zero();
    };
    std::vector<FitPart> fit;
};

namespace lobe_surface_detail {

using Index = std::size_t;
using Crossing = LobeBuildMemo::Crossing;

/// A vertex of the surface before lifting.
struct Node {
    glm::dvec3 dir{0.0};  ///< unit direction from the centre
    double radius = 0.0;  ///< distance from the centre (interpolated for Fill)
    LobeVertexOrigin origin;
};

/// a · (b × c): positive when a, b, c run counter-clockwise seen from outside the sphere.
inline double orient3(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c)
{
    return glm::dot(a, glm::cross(b, c));
}

/// The angle between two unit directions (from their chord: accurate for small angles).
inline double angle_between(const glm::dvec3& a, const glm::dvec3& b)
{
    return 2.0 * std::asin(std::min(1.0, 0.5 * glm::length(a - b)));
}

/// Angular radius of the circle through three unit directions.
inline double circumradius_angle(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c)
{
    glm::dvec3 n = glm::cross(b - a, c - a);
    const double len = glm::length(n);
    if (!(len > 1e-300)) return M_PI;
    n /= len;
    return std::acos(std::clamp(std::abs(glm::dot(n, a)), -1.0, 1.0));
}

/// A build of the changed regions only met something it cannot tell apart (a kept region
/// the new strokes run into, a stroke edge the triangulation split): the whole surface is
/// built instead.
struct PartialFailed {};

/// What the triangulation on the sphere hands to emit: the surface's triangles over the nodes,
/// before they are put in canonical order.
struct SphereTriangles {
    std::vector<std::array<int, 3>> triangles; ///< node ids, outward; the paper strips' come first
    std::vector<int> region;                   ///< per triangle: its region of the triangulation
    /// Per triangle: bit k is set when its side k (corner k to corner k + 1) is a stroke edge.
    std::vector<std::uint8_t> stroke_sides;
    std::size_t strip_triangles = 0;           ///< how many of the first triangles are paper strips
    int region_count = 0;                      ///< regions of the triangulation
    /// The ends of every stroke edge of the triangulation (split at crossings), node ids.
    std::vector<std::array<int, 2>> stroke_edges;
};

/// Everything one build needs, and its stages that need no CGAL. The triangulation stage and
/// run() are CdtLobeSurfaceBuilder's (lobe_surface_cgal.cpp).
class LobeSurfaceBuilder {
public:
    LobeSurfaceBuilder(const std::vector<LobeStrokeSamples>& strokes, const glm::dvec3& centre,
                       const LobeSurfaceOptions& options)
        : strokes_(strokes), centre_(centre), options_(options)
    {
    }

    /// Builds only the regions that changed since `previous` (see continue_lobe_surface)
    /// where they can be told apart: run() then returns those regions' triangles and every
    /// stroke vertex, and partial() is true.
    /// With `changed_only` false, only the previous build's memo is used (the whole surface
    /// is built).
    void set_previous(const LobeSurface& previous, const SurfaceRegions& regions, bool changed_only = true)
    {
        previous_ = &previous;
        previous_regions_ = &regions;
        changed_only_ = changed_only;
    }
    bool partial() const { return partial_; }
    /// The pole search and the crossings followed the previous build's (its memo was usable).
    bool followed_previous() const { return old_memo_ != nullptr; }
    const std::vector<char>& kept_previous_regions() const { return changed_.keep; }

protected:
    /// Stages 1 to 5, everything before the triangulation (lobe_surface_builder.cpp).
    /// \throw InvalidInput as build_lobe_surface.
    void plan();
    /// The result as far as it is known before the triangulation: memo, centre, reference radius.
    LobeSurface start_surface() const;
    /// Stage 7: `built` in canonical order, the fill's radii solved, into `out`
    /// (lobe_surface_emit.cpp). `regions` (may be null): set to surface_regions of the result.
    void emit(SphereTriangles built, LobeSurface& out, SurfaceRegions* regions);
    // emit's steps (lobe_surface_emit.cpp).
    /// Puts the nodes in canonical order, renumbering `triangles`; returns the new id of each
    /// old one.
    std::vector<int> sort_nodes(std::vector<std::array<int, 3>>& triangles);
    /// Adds to `out` the vertices of the nodes `triangles` use (and, for a build of the changed
    /// regions, every stroke node) in the output's order; returns each node's vertex, or -1.
    std::vector<int> emit_vertices(const std::vector<std::array<int, 3>>& triangles, const std::vector<char>& on_chain,
                                   LobeSurface& out) const;

    std::string stroke_name(int s) const
    {
        return "lobe stroke " + std::to_string(strokes_[static_cast<Index>(s)].id);
    }
    void check_strokes() const;
    void make_directions();
    void choose_pole();
    /// The previous build's memo when its strokes are this build's first ones, unchanged,
    /// around the same centre (else null); `old_strokes_` is how many.
    const LobeBuildMemo* usable_memo();
    void remember_strokes();
    void find_crossings();
    bool find_crossings(bool only_new);
    void sort_crossings();
    void build_chains();
    // build_chains' steps (lobe_surface_chains.cpp).
    /// A crossing on a stroke: on its segment `seg` at parameter `t`, node `node`.
    struct CrossingOnStroke {
        int seg;
        double t;
        int node;
    };
    void add_sample_nodes();
    void add_crossing_nodes();
    void merge_close_crossings();
    /// Stroke `s`'s samples and its crossings (`list`) in order, without the samples next to
    /// a crossing. \throw InvalidInput when too few are left.
    std::vector<int> stroke_chain(Index s, std::vector<CrossingOnStroke> list) const;
    /// `chain` with its long segments split into pieces of at most max_piece_angle_ seen from
    /// the centre.
    std::vector<int> subdivided_chain(Index s, const std::vector<int>& chain);
    void plan_partial();
    glm::vec3 emitted_position(int id) const
    {
        const Node& n = nodes_[static_cast<Index>(id)];
        return n.origin.kind == LobeVertexKind::Sample
                   ? strokes_[static_cast<Index>(n.origin.stroke)].points[static_cast<Index>(n.origin.sample)]
                   : glm::vec3(centre_ + n.radius * n.dir);
    }
    /// The fill's candidate directions (lobe_surface_fill.cpp): a Fibonacci lattice about as
    /// dense as triangles with sides of `max_edge` (radians), without the points near a stroke,
    /// within `ring_angle` + their spacing of the pole, or (a build of the changed regions only)
    /// outside the caps round the changed regions.
    std::vector<glm::dvec3> fill_lattice(double max_edge, double ring_angle) const;
    /// The paper's strip (stitch_closed_closed) between the chains of the closed strokes `a`
    /// and `b`, as outward node triangles; empty when it cannot be made or would fold seen from
    /// the centre (lobe_surface_emit.cpp).
    std::vector<std::array<int, 3>> paper_strip(int a, int b) const;
    void solve_fill_radii(const std::vector<std::array<int, 3>>& triangles, const std::vector<char>& on_chain);
    bool fit_radius_model(const std::vector<char>& fit, const std::vector<char>& at, std::vector<double>& model) const;

    int add_node(const Node& n)
    {
        nodes_.push_back(n);
        return static_cast<int>(nodes_.size()) - 1;
    }

    const std::vector<LobeStrokeSamples>& strokes_;
    glm::dvec3 centre_;
    LobeSurfaceOptions options_;

    std::vector<std::vector<glm::dvec3>> dirs_;    ///< per stroke, per sample
    std::vector<std::vector<double>> radii_;       ///< per stroke, per sample
    std::vector<double> spacing_;                  ///< per stroke: median 3D spacing
    double mean_radius_ = 0;
    double empty_angle_ = 0;                       ///< angular radius of the empty cap at the pole
    Stereo stereo_{glm::dvec3(0, 0, 1)};

    std::vector<Crossing> crossings_;
    std::shared_ptr<LobeBuildMemo> memo_ = std::make_shared<LobeBuildMemo>(); ///< this build's
    const LobeBuildMemo* old_memo_ = nullptr;
    Index old_strokes_ = 0;
    std::vector<int> crossing_count_;              ///< per stroke
    std::vector<Node> nodes_;
    std::vector<std::vector<int>> chains_;         ///< per stroke: node ids in order
    std::vector<int> sample_node_;                 ///< flattened (stroke, sample) → node, or -1
    std::vector<Index> sample_offset_;
    double max_piece_angle_ = 6.0 * M_PI / 180.0;

    // A build of the changed regions only (partial_): the stroke edges in or around them
    // are triangulated, and the regions outside them (the kept ones, seen as one or more
    // regions bounded by the border edges) are left out.
    const LobeSurface* previous_ = nullptr;
    const SurfaceRegions* previous_regions_ = nullptr;
    ChangedRegions changed_;
    bool changed_only_ = true;
    bool partial_ = false;
    /// Per changed region of the previous surface: a cap of directions holding it (centre,
    /// cosine of its angular radius).
    std::vector<std::pair<glm::dvec3, double>> caps_;
};

/// Whether a surface has no hole (lobe_surface_builder.cpp).
bool closed_surface(const TriangleMesh& mesh);
/// \throw InvalidInput unless closed_surface(mesh).
void require_closed(const TriangleMesh& mesh);

} // namespace lobe_surface_detail

} // namespace lobe
