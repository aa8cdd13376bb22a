// The lobe surface: a constrained Delaunay triangulation of the strokes on the sphere of
// directions around the lobe's centre (CGAL's Constrained_Delaunay_triangulation_2 in a
// stereographic projection), lifted back to the strokes' distances. See lobe_surface.h.
#include "meshing/lobe_surface.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <map>
#include <numeric>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>

#include "meshing/cgal_prelude.h"
LOBE_CGAL_HEADERS_BEGIN
#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Constrained_triangulation_face_base_2.h>
#include <CGAL/Spatial_sort_traits_adapter_2.h>
#include <CGAL/property_map.h>
#include <CGAL/spatial_sort.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>
#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
LOBE_CGAL_HEADERS_END

#include "core/errors.h"
#include "meshing/lobe_regions.h"
#include "meshing/polyline.h"
#include "meshing/stereographic.h"
#include "meshing/stitch.h"

namespace lobe {

namespace {

using cgal::Kernel;
struct VertexInfo {
    int id = -1; ///< index into the node table; -1: created by CGAL at a residual crossing
};
struct FaceInfo {
    int region = -1;  ///< region id (see mark_regions)
    bool fine = false; ///< refinement found nothing to add here; reset when the face changes
};
using Vb = CGAL::Triangulation_vertex_base_with_info_2<VertexInfo, Kernel>;
using Fb0 = CGAL::Constrained_triangulation_face_base_2<Kernel>;
using Fb = CGAL::Triangulation_face_base_with_info_2<FaceInfo, Kernel, Fb0>;
using Tds = CGAL::Triangulation_data_structure_2<Vb, Fb>;
using CDT = CGAL::Constrained_Delaunay_triangulation_2<Kernel, Tds, CGAL::Exact_predicates_tag>;
using VH = CDT::Vertex_handle;
using FH = CDT::Face_handle;
using Index = std::size_t;

/// A vertex of the surface before lifting.
struct Node {
    glm::dvec3 dir{0.0};  ///< unit direction from the centre
    double radius = 0.0;  ///< distance from the centre (interpolated for Fill)
    LobeVertexOrigin origin;
};

} // namespace

/// See lobe_surface.h. Filled by every build; read by the next (Builder::usable_memo) only
/// when the strokes it was made from are the first strokes of that build, unchanged, around
/// the same centre.
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
    /// The pole search (Builder::choose_pole): per lattice candidate, the largest dot product
    /// of its direction with any sample, exact or (when it was pruned) a lower bound of it.
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

namespace {

using Crossing = LobeBuildMemo::Crossing;

double orient3(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c)
{
    return glm::dot(a, glm::cross(b, c));
}

/// Proper crossing of the arcs a0a1 and b0b1 between unit directions, each shorter than 90°
/// (make_directions): each arc's ends lie strictly on opposite sides of the other's great
/// circle, and the two arcs lie on the same side of the sphere. `s` and `t` are where each
/// chord meets the other's plane. Ends touching or on the other arc count as none (adjacent
/// segments meet there by construction).
bool arc_crossing(const glm::dvec3& a0, const glm::dvec3& a1, const glm::dvec3& b0, const glm::dvec3& b1, double& s,
                  double& t)
{
    const double sa0 = orient3(a0, a1, b0), sa1 = orient3(a0, a1, b1);
    if (!((sa0 > 0.0 && sa1 < 0.0) || (sa0 < 0.0 && sa1 > 0.0))) return false;
    const double sb0 = orient3(b0, b1, a0), sb1 = orient3(b0, b1, a1);
    if (!((sb0 > 0.0 && sb1 < 0.0) || (sb0 < 0.0 && sb1 > 0.0))) return false;
    if (!(glm::dot(a0 + a1, b0 + b1) > 0.0)) return false;
    s = sb0 / (sb0 - sb1);
    t = sa0 / (sa0 - sa1);
    return true;
}

/// Angular radius of the circle through three unit directions.
double circumradius_angle(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c)
{
    glm::dvec3 n = glm::cross(b - a, c - a);
    const double len = glm::length(n);
    if (!(len > 1e-300)) return M_PI;
    n /= len;
    return std::acos(std::clamp(std::abs(glm::dot(n, a)), -1.0, 1.0));
}

double angle_between(const glm::dvec3& a, const glm::dvec3& b)
{
    return 2.0 * std::asin(std::min(1.0, 0.5 * glm::length(a - b)));
}

bool solver_ok(const Eigen::VectorXd& x)
{
    return x.allFinite();
}

/// Sorts `order` (indices into `where`) along a space-filling curve: points inserted into
/// the triangulation in that order stay near the last one, where points taken along a
/// stroke, or along the Fibonacci lattice, make insertions flip long fans or walk far.
void spatially_sort(std::vector<std::size_t>& order, std::vector<Kernel::Point_2>& where)
{
    using Map = CGAL::Pointer_property_map<Kernel::Point_2>::type;
    CGAL::spatial_sort(order.begin(), order.end(), CGAL::Spatial_sort_traits_adapter_2<Kernel, Map>(CGAL::make_property_map(where)));
}

/// The segments of all strokes, as arcs between unit directions, binned in a uniform grid
/// over [-1, 1]³ by the box of each arc (its chord's box grown by the arc's sagitta), so
/// that every pair of arcs that cross shares a cell and crossings are found in time about
/// linear in the number of segments. On the sphere, not in the projection: which strokes
/// cross does not depend on the pole.
class SegmentGrid {
public:
    struct Seg {
        int stroke, index;
        glm::dvec3 p0, p1;
    };

    SegmentGrid(std::vector<Seg> segs) : segs_(std::move(segs))
    {
        lo_ = glm::dvec3(std::numeric_limits<double>::max());
        glm::dvec3 hi(-std::numeric_limits<double>::max());
        std::vector<double> lengths;
        lengths.reserve(segs_.size());
        pad_.reserve(segs_.size());
        for (const Seg& s : segs_) {
            // The arc leaves its chord by at most 1 − cos(θ/2) = 1 − √((1 + cos θ) / 2).
            const double c = std::clamp(glm::dot(s.p0, s.p1), -1.0, 1.0);
            pad_.push_back(1.0 - std::sqrt(0.5 * (1.0 + c)) + 1e-12);
            lo_ = glm::min(lo_, glm::min(s.p0, s.p1) - pad_.back());
            hi = glm::max(hi, glm::max(s.p0, s.p1) + pad_.back());
            lengths.push_back(glm::distance(s.p0, s.p1));
        }
        std::nth_element(lengths.begin(), lengths.begin() + static_cast<long>(lengths.size() / 2), lengths.end());
        const glm::dvec3 extent = hi - lo_;
        const double cap = std::max({extent.x, extent.y, extent.z}) / 64.0;
        cell_ = std::max({lengths[lengths.size() / 2] * 2.0, cap, 1e-12});
        n_[0] = static_cast<int>(extent.x / cell_) + 1;
        n_[1] = static_cast<int>(extent.y / cell_) + 1;
        n_[2] = static_cast<int>(extent.z / cell_) + 1;
        // Cells in one array: cell c holds cells_[start_[c] .. start_[c + 1]), segments in order.
        start_.assign(static_cast<Index>(n_[0]) * static_cast<Index>(n_[1]) * static_cast<Index>(n_[2]) + 1, 0);
        for (Index i = 0; i < segs_.size(); ++i) for_cells(i, [&](Index c) { ++start_[c + 1]; });
        for (Index c = 1; c < start_.size(); ++c) start_[c] += start_[c - 1];
        cells_.resize(static_cast<Index>(start_.back()));
        std::vector<int> next(start_.begin(), start_.end() - 1);
        for (Index i = 0; i < segs_.size(); ++i)
            for_cells(i, [&](Index c) { cells_[static_cast<Index>(next[c]++)] = static_cast<int>(i); });
    }

    /// Calls f(seg_i, seg_j), i < j, once for each pair of segments whose boxes share a cell
    /// and of which one is at or after `first` (0: every pair, in increasing (i, j) order).
    template <typename F>
    void for_each_candidate_from(int first, F&& f) const
    {
        check_density();
        std::vector<int> others;
        for (int i = first; i < static_cast<int>(segs_.size()); ++i) {
            others.clear();
            for_cells(static_cast<Index>(i), [&](Index c) {
                // Cells list their segments in increasing order: those after i from the end,
                // those before `first` from the start.
                for (int k = start_[c + 1] - 1; k >= start_[c] && cells_[static_cast<Index>(k)] > i; --k)
                    others.push_back(cells_[static_cast<Index>(k)]);
                for (int k = start_[c]; k < start_[c + 1] && cells_[static_cast<Index>(k)] < first; ++k)
                    others.push_back(cells_[static_cast<Index>(k)]);
            });
            std::sort(others.begin(), others.end());
            others.erase(std::unique(others.begin(), others.end()), others.end());
            for (int j : others) {
                if (j < i) f(segs_[static_cast<Index>(j)], segs_[static_cast<Index>(i)]);
                else f(segs_[static_cast<Index>(i)], segs_[static_cast<Index>(j)]);
            }
        }
    }

private:
    /// Bounded work and memory on any input (a dense scribble in one spot).
    void check_density() const
    {
        std::size_t total = 0;
        for (Index c = 0; c + 1 < start_.size(); ++c) {
            const std::size_t k = static_cast<std::size_t>(start_[c + 1] - start_[c]);
            total += k * (k - (k > 0 ? 1 : 0)) / 2;
        }
        if (total > 20000000) throw InvalidInput("the lobe's strokes are too densely tangled to mesh");
    }

    template <typename F>
    void for_cells(Index i, F&& f) const
    {
        const Seg& s = segs_[i];
        const auto c0 = cell_of(glm::min(s.p0, s.p1) - pad_[i]);
        const auto c1 = cell_of(glm::max(s.p0, s.p1) + pad_[i]);
        for (int z = c0[2]; z <= c1[2]; ++z)
            for (int y = c0[1]; y <= c1[1]; ++y)
                for (int x = c0[0]; x <= c1[0]; ++x)
                    f((static_cast<Index>(z) * static_cast<Index>(n_[1]) + static_cast<Index>(y)) * static_cast<Index>(n_[0]) +
                      static_cast<Index>(x));
    }
    std::array<int, 3> cell_of(const glm::dvec3& p) const
    {
        std::array<int, 3> c{};
        for (int k = 0; k < 3; ++k)
            c[static_cast<Index>(k)] = std::clamp(static_cast<int>((p[k] - lo_[k]) / cell_), 0, n_[static_cast<Index>(k)] - 1);
        return c;
    }
    std::vector<Seg> segs_;
    std::vector<double> pad_;
    glm::dvec3 lo_{0.0};
    double cell_ = 1;
    std::array<int, 3> n_{1, 1, 1};
    std::vector<int> start_, cells_;
};

/// Neighbours of every node, sorted and without repeats, in one array.
struct Adjacency {
    struct Range {
        const int* b;
        const int* e;
        const int* begin() const { return b; }
        const int* end() const { return e; }
        bool empty() const { return b == e; }
        Index size() const { return static_cast<Index>(e - b); }
        int operator[](Index k) const { return b[k]; }
    };
    std::vector<int> start, list;

    /// Rows only for the nodes `rows` marks; the others are left empty.
    Adjacency(Index n, const std::vector<std::array<int, 3>>& triangles, const std::vector<char>& rows) : start(n + 1, 0)
    {
        for (const auto& t : triangles)
            for (int id : t)
                if (rows[static_cast<Index>(id)]) start[static_cast<Index>(id) + 1] += 2;
        for (Index i = 0; i < n; ++i) start[i + 1] += start[i];
        std::vector<int> raw(static_cast<Index>(start[n]));
        std::vector<int> next(start.begin(), start.end() - 1);
        for (const auto& t : triangles)
            for (Index k = 0; k < 3; ++k) {
                const Index a = static_cast<Index>(t[k]), b = static_cast<Index>(t[(k + 1) % 3]);
                if (rows[a]) raw[static_cast<Index>(next[a]++)] = t[(k + 1) % 3];
                if (rows[b]) raw[static_cast<Index>(next[b]++)] = t[k];
            }
        list.reserve(raw.size());
        for (Index i = 0; i < n; ++i) {
            const auto b = raw.begin() + start[i], e = raw.begin() + start[i + 1];
            start[i] = static_cast<int>(list.size());
            if (b == e) continue;
            std::sort(b, e);
            list.insert(list.end(), b, std::unique(b, e));
        }
        start[n] = static_cast<int>(list.size());
    }
    Range operator[](Index i) const { return {list.data() + start[i], list.data() + start[i + 1]}; }
};

/// A build of the changed regions only met something it cannot tell apart (a kept region
/// the new strokes run into, a stroke edge the triangulation split): the whole surface is
/// built instead.
struct PartialFailed {};

/// Everything one build needs.
class Builder {
public:
    Builder(const std::vector<LobeStrokeSamples>& strokes, const glm::dvec3& centre, const LobeSurfaceOptions& options)
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

    /// `regions` (may be null): set to surface_regions of the result, which the build knows.
    LobeSurface run(SurfaceRegions* regions = nullptr);

private:
    std::string stroke_name(int s) const
    {
        return "lobe stroke " + std::to_string(strokes_[static_cast<Index>(s)].id);
    }
    void make_directions();
    void choose_pole();
    /// The previous build's memo when its strokes are this build's first ones, unchanged,
    /// around the same centre (else null); `old_strokes_` is how many.
    const LobeBuildMemo* usable_memo();
    void find_crossings();
    bool find_crossings(bool only_new);
    void sort_crossings();
    void build_chains();
    void plan_partial();
    glm::vec3 emitted_position(int id) const
    {
        const Node& n = nodes_[static_cast<Index>(id)];
        return n.origin.kind == LobeVertexKind::Sample
                   ? strokes_[static_cast<Index>(n.origin.stroke)].points[static_cast<Index>(n.origin.sample)]
                   : glm::vec3(centre_ + n.radius * n.dir);
    }
    void triangulate();
    void mark_regions();
    void mark_inside();
    void find_paper_regions();
    void refine();
    void seed_fill(double max_edge, int& added);
    void insert_fill(const glm::dvec2& x, int region, VH& hint, int& added);
    void insert_fill(const Node& n, const glm::dvec2& x, int region, VH& hint, int& added);
    void emit(LobeSurface& out, SurfaceRegions* regions);
    void solve_fill_radii(const std::vector<std::array<int, 3>>& triangles, const std::vector<char>& on_chain);
    bool fit_radius_model(const std::vector<char>& fit, const std::vector<char>& at, std::vector<double>& model) const;

    int add_node(const Node& n)
    {
        nodes_.push_back(n);
        return static_cast<int>(nodes_.size()) - 1;
    }
    VH insert_node(int id, VH hint);

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

    CDT cdt_;
    std::vector<VH> node_vertex_;                  ///< node → CDT vertex (several nodes may share one)
    std::vector<char> paper_region_;               ///< per region: stitched with stitch_closed_closed
    std::vector<std::pair<int, int>> region_strokes_;
    int region_count_ = 0;
    bool regions_stale_ = false;                   ///< faces' regions must be marked again
    int pole_node_ = -1;
    double max_piece_angle_ = 6.0 * M_PI / 180.0;

    // A build of the changed regions only (partial_): the stroke edges in or around them
    // are triangulated, and the regions outside them (the kept ones, seen as one or more
    // regions bounded by the border edges) are left out.
    const LobeSurface* previous_ = nullptr;
    const SurfaceRegions* previous_regions_ = nullptr;
    ChangedRegions changed_;
    bool changed_only_ = true;
    bool partial_ = false;
    std::vector<char> region_inside_;              ///< per region: to be emitted
    std::vector<std::array<int, 2>> border_;       ///< node pairs (u, v): changed side runs u → v outward
    std::vector<std::array<int, 2>> inserted_;     ///< constrained node pairs
    /// Per changed region of the previous surface: a cap of directions holding it (centre,
    /// cosine of its angular radius).
    std::vector<std::pair<glm::dvec3, double>> caps_;
    double ring_angle_ = 0;
};

void Builder::make_directions()
{
    const Index n = strokes_.size();
    dirs_.resize(n);
    radii_.resize(n);
    spacing_.resize(n);
    double sum_r = 0;
    std::size_t count = 0;
    double largest = 0;
    for (Index s = 0; s < n; ++s) {
        const auto pts = to_double(strokes_[s].points);
        spacing_[s] = median_spacing(pts, strokes_[s].closed);
        for (const glm::dvec3& p : pts) largest = std::max(largest, glm::length(p - centre_));
    }
    const double too_close = std::max(1e-4, 1e-3 * largest);
    for (Index s = 0; s < n; ++s) {
        for (const glm::vec3& pf : strokes_[s].points) {
            const glm::dvec3 v = glm::dvec3(pf) - centre_;
            const double r = glm::length(v);
            if (!(r > too_close))
                throw InvalidInput(stroke_name(static_cast<int>(s)) + " passes through the lobe's centre");
            dirs_[s].push_back(v / r);
            radii_[s].push_back(r);
            sum_r += r;
            ++count;
        }
    }
    mean_radius_ = sum_r / static_cast<double>(count);
    // Seen from the centre, consecutive samples of a stroke drawn around the lobe are close;
    // a segment spanning more than 90° cuts through the lobe's inside.
    for (Index s = 0; s < n; ++s) {
        const auto& d = dirs_[s];
        const Index m = d.size();
        for (Index i = 0; i + (strokes_[s].closed ? 0 : 1) < m; ++i)
            if (angle_between(d[i], d[(i + 1) % m]) > M_PI / 2.0)
                throw InvalidInput(stroke_name(static_cast<int>(s)) + " cuts through the lobe's inside, near its centre");
    }
}

const LobeBuildMemo* Builder::usable_memo()
{
    if (!previous_ || !previous_->memo) return nullptr;
    const LobeBuildMemo& m = *previous_->memo;
    if (m.centre != centre_ || m.points.size() > strokes_.size() || m.points.empty()) return nullptr;
    for (Index s = 0; s < m.points.size(); ++s) {
        const auto& was = m.points[s];
        const auto& now = strokes_[s].points;
        if (was.size() != now.size() || (m.closed[s] != 0) != strokes_[s].closed ||
            std::memcmp(was.data(), now.data(), was.size() * sizeof(glm::vec3)) != 0)
            return nullptr;
    }
    old_strokes_ = m.points.size();
    return &m;
}

void Builder::choose_pole()
{
    // The direction farthest from every sample: a Fibonacci lattice of candidates, then a
    // few rounds of pushing the best one away from its nearest sample.
    //
    // After one more stroke (old_memo_), the previous build's search is followed wherever the
    // new samples cannot change a step: a candidate whose bound was already no better than the
    // best is passed over again; an exact one needs only the new samples; a round whose nearest
    // sample and outcome stay keeps them. The result is the whole search's, bit for bit: the
    // first candidate with the smallest largest dot product, then the same rounds.
    constexpr int kCandidates = 512;
    static const std::vector<glm::dvec3> lattice = [] {
        std::vector<glm::dvec3> out;
        const double golden = M_PI * (3.0 - std::sqrt(5.0));
        for (int i = 0; i < kCandidates; ++i) {
            const double z = 1.0 - (2.0 * i + 1.0) / kCandidates;
            const double rr = std::sqrt(std::max(0.0, 1.0 - z * z));
            out.emplace_back(rr * std::cos(golden * i), rr * std::sin(golden * i), z);
        }
        return out;
    }();
    double best_dot = 2.0;
    glm::dvec3 best(0, 0, 1);
    std::vector<glm::dvec3> all;
    for (const auto& stroke : dirs_) all.insert(all.end(), stroke.begin(), stroke.end());
    const LobeBuildMemo* memo = old_memo_;
    Index old_count = 0;
    if (memo)
        for (Index s = 0; s < old_strokes_; ++s) old_count += dirs_[s].size();
    // Scans over the samples listed in [first, last) (indices into `all`, in order).
    std::vector<Index> every(all.size());
    std::iota(every.begin(), every.end(), Index{0});
    // The largest dot product with `d`, and the first sample giving it.
    auto max_over = [&](const glm::dvec3& d, const Index* first, const Index* last, int* nearest) {
        double m = -2.0;
        for (const Index* k = first; k != last; ++k) {
            const double c = glm::dot(all[*k], d);
            if (c > m) {
                m = c;
                if (nearest) *nearest = static_cast<int>(*k);
            }
        }
        return m;
    };
    // The first sample at least as near as the best (`bound`, its dot product ≥ best_dot), or −1.
    auto beaten_over = [&](const glm::dvec3& d, const Index* first, const Index* last, double& bound) {
        for (const Index* k = first; k != last; ++k) {
            const double c = glm::dot(all[*k], d);
            if (c >= best_dot) {
                bound = c;
                return static_cast<int>(*k);
            }
        }
        return -1;
    };
    const Index* every_end = every.data() + every.size();
    // Over the samples from `from` on (the new strokes' from old_count).
    auto max_dot = [&](const glm::dvec3& d, Index from, int* nearest) {
        return max_over(d, every.data() + from, every_end, nearest);
    };
    auto beaten = [&](const glm::dvec3& d, double& bound) { return beaten_over(d, every.data(), every_end, bound); };
    // Runs of up to 8 consecutive samples (along a stroke: close together), each with a cap
    // of directions holding it, so that a scan for a largest dot product can pass over a run
    // whose cap cannot beat the value it has: the same answer (and the same first sample
    // giving it), with fewer products. The old samples' runs end at old_count.
    struct Run {
        Index first, last;
        glm::dvec3 axis;
        double cos_r, sin_r; ///< of the cap's angular radius
    };
    std::vector<Run> runs;
    auto add_runs = [&](Index from, Index to) {
        for (Index f = from; f < to; f += 8) {
            Run run{f, std::min(to, f + 8), glm::dvec3(0.0), 1.0, 0.0};
            for (Index k = run.first; k < run.last; ++k) run.axis += all[k];
            const double len = glm::length(run.axis);
            if (!(len > 1e-6)) {
                run.cos_r = -1.0; // no useful cap: always scanned
            } else {
                run.axis /= len;
                for (Index k = run.first; k < run.last; ++k) run.cos_r = std::min(run.cos_r, glm::dot(all[k], run.axis));
                run.cos_r = std::clamp(run.cos_r, -1.0, 1.0);
                run.sin_r = std::sqrt(1.0 - run.cos_r * run.cos_r);
            }
            runs.push_back(run);
        }
    };
    // Only the search after one more stroke (memo) scans by runs.
    Index first_new_run = 0;
    if (memo) {
        add_runs(0, old_count);
        first_new_run = runs.size();
        add_runs(old_count, all.size());
    }
    // An upper bound of dot(d, x) over a run's samples x: cos(θ − r) for the angle θ between d
    // and the axis beyond the radius r (the products are of unit vectors, rounded far below
    // the margin).
    auto run_bound = [](const Run& run, const glm::dvec3& d) {
        if (run.cos_r <= -1.0) return 2.0;
        const double c = glm::dot(d, run.axis);
        if (c >= run.cos_r) return 2.0;
        return c * run.cos_r + std::sqrt(std::max(0.0, 1.0 - c * c)) * run.sin_r + 1e-9;
    };
    // max(floor, the largest dot product of `d` with a new sample): the runs that cannot
    // exceed what is found so far are passed over.
    auto new_max_above = [&](const glm::dvec3& d, double floor) {
        double m = floor;
        for (Index r = first_new_run; r < runs.size(); ++r) {
            const Run& run = runs[r];
            if (run_bound(run, d) <= m) continue;
            for (Index k = run.first; k < run.last; ++k) m = std::max(m, glm::dot(all[k], d));
        }
        return m;
    };
    LobeBuildMemo& out = *memo_;
    out.candidate_bound.assign(kCandidates, 0.0);
    out.candidate_exact.assign(kCandidates, 0);
    if (memo) {
        // New samples only raise a candidate's largest dot product, so the previous bounds stay
        // lower bounds. The previous winner's new value `ceiling` is one the answer cannot
        // exceed: a candidate whose bound is above it cannot be the answer and is passed over.
        // The others are scanned in order as the whole search does, so ties go the same way.
        Index leader = 0;
        for (Index i = 1; i < static_cast<Index>(kCandidates); ++i)
            if (memo->candidate_exact[i] &&
                (!memo->candidate_exact[leader] || memo->candidate_bound[i] < memo->candidate_bound[leader]))
                leader = i;
        std::vector<int> stopped_at(kCandidates, -1); // per candidate scanned: its nearest old sample so far
        double ceiling = 2.0;
        if (memo->candidate_exact[leader])
            ceiling = new_max_above(lattice[leader], memo->candidate_bound[leader]);
        for (Index i = 0; i < static_cast<Index>(kCandidates); ++i) {
            const glm::dvec3& d = lattice[i];
            double bound = memo->candidate_bound[i];
            bool exact = memo->candidate_exact[i] != 0;
            if (bound >= best_dot || bound > ceiling) {
                exact = false; // the new samples may raise it: a lower bound now
            } else {
                // max(bound, the new samples' largest): bound is the old samples' largest
                // (exact) or a lower bound of it (< best_dot here), so `added` reaches
                // best_dot exactly when the new samples' largest does.
                const double added = new_max_above(d, bound);
                if (exact) {
                    bound = added;
                } else if (added >= best_dot) {
                    bound = added; // cannot win: a lower bound
                } else {
                    // The old samples until one is at least as near as the best (then it
                    // cannot win either), else all of them: the exact value. The samples that
                    // ended the scans of the lattice neighbours (Fibonacci index steps) are
                    // tried first, as in the whole search.
                    double old_max = -2.0;
                    for (int step : {1, 2, 3, 5, 8, 13, 21, 34, 55, 89}) {
                        if (i < static_cast<Index>(step)) break;
                        const int w = stopped_at[i - static_cast<Index>(step)];
                        if (w < 0) continue;
                        const double c = glm::dot(all[static_cast<Index>(w)], d);
                        if (c >= best_dot) {
                            old_max = c;
                            stopped_at[i] = w;
                            break;
                        }
                    }
                    // In sample order; a run that cannot beat old_max changes nothing.
                    for (Index r = 0; r < first_new_run && old_max < best_dot; ++r) {
                        const Run& run = runs[r];
                        if (run_bound(run, d) <= old_max) continue;
                        for (Index k = run.first; k < run.last && old_max < best_dot; ++k) {
                            const double c = glm::dot(all[k], d);
                            if (c > old_max) {
                                old_max = c;
                                stopped_at[i] = static_cast<int>(k);
                            }
                        }
                    }
                    // old_max is the old samples' largest when the scan ran through (so at
                    // least the lower bound folded into `added`), else a value ≥ best_dot:
                    // either way this is max(old_max, the new samples' largest).
                    bound = std::max(old_max, added);
                    exact = old_max < best_dot;
                }
                if (exact && bound < best_dot) {
                    best_dot = bound;
                    best = d;
                }
            }
            out.candidate_bound[i] = bound;
            out.candidate_exact[i] = exact ? 1 : 0;
        }
    } else {
        // A candidate is only of interest when its nearest sample is farther than the best
        // one's: the scan stops at the first sample at least as near (`witness`), and the
        // witnesses of the candidate's lattice neighbours (Fibonacci index steps) are tried first.
        std::vector<int> witness(kCandidates, 0);
        for (int i = 0; i < kCandidates; ++i) {
            const Index ii = static_cast<Index>(i);
            const glm::dvec3& d = lattice[ii];
            bool out_of_it = false;
            for (int step : {1, 2, 3, 5, 8, 13, 21, 34, 55, 89}) {
                if (i < step) break;
                const int w = witness[static_cast<Index>(i - step)];
                const double c = glm::dot(all[static_cast<Index>(w)], d);
                if (c >= best_dot) {
                    witness[ii] = w;
                    out.candidate_bound[ii] = c;
                    out_of_it = true;
                    break;
                }
            }
            if (out_of_it) continue;
            double bound = 0;
            const int w = beaten(d, bound);
            if (w >= 0) {
                witness[ii] = w;
                out.candidate_bound[ii] = bound;
                continue;
            }
            const double m = max_dot(d, 0, nullptr);
            out.candidate_bound[ii] = m;
            out.candidate_exact[ii] = 1;
            if (m < best_dot) {
                best_dot = m;
                best = d;
            }
        }
    }
    out.start = best;
    out.start_dot = best_dot;
    out.steps.clear();
    // Following the previous search while every step is the same.
    bool follow = memo && memo->start == best && memo->start_dot == best_dot && memo->steps.size() == 40;
    // Otherwise the rounds look only at the samples near a centre (first the start): the
    // nearest sample to a point within `reach` of the centre lies within θ0 + 2·reach of it
    // (θ0: the centre's distance to its nearest sample), and so does every sample at least as
    // near to a trial within reach as the nearest one is to the pole, while the pole is within
    // reach too. When the search walks out of reach, the current pole becomes the centre (a
    // step moves less than reach). Either way the answers are the full scan's, bit for bit:
    // the samples left out cannot be the first nearest or the first at least as near.
    constexpr double reach = 0.15;
    const double cos_reach = std::cos(reach);
    glm::dvec3 centre = best;
    std::vector<Index> near;
    auto recentre = [&] {
        centre = best;
        const double near_cos = std::cos(std::min(M_PI, std::acos(std::clamp(best_dot, -1.0, 1.0)) + 2.0 * reach + 1e-6));
        near.clear();
        for (Index k = 0; k < all.size(); ++k)
            if (glm::dot(all[k], centre) >= near_cos) near.push_back(k);
    };
    bool near_ready = false;
    // Whether the near samples serve `d` (and the pole), moving the centre if they did not.
    auto near_serves = [&](const glm::dvec3& d) {
        auto covers = [&](const glm::dvec3& x) { return glm::dot(x, centre) >= cos_reach; };
        if (near_ready && covers(d) && covers(best)) return true;
        recentre();
        near_ready = true;
        return covers(d);
    };
    auto max_dot_near = [&](const glm::dvec3& d, int* nearest) {
        if (!near_serves(d)) return max_dot(d, 0, nearest);
        return max_over(d, near.data(), near.data() + near.size(), nearest);
    };
    auto beaten_near = [&](const glm::dvec3& d, double& bound) {
        if (!near_serves(d)) return beaten(d, bound);
        return beaten_over(d, near.data(), near.data() + near.size(), bound);
    };
    double step = 0.1;
    for (int it = 0; it < 40; ++it) {
        LobeBuildMemo::Step rec;
        if (follow) {
            int added_nearest = -1;
            if (max_dot(best, old_count, &added_nearest) > best_dot) {
                follow = false;
                rec.nearest = added_nearest; // a new sample is nearer than every old one
            } else {
                rec.nearest = memo->steps[static_cast<Index>(it)].nearest;
            }
        } else {
            max_dot_near(best, &rec.nearest);
        }
        const glm::dvec3& nearest = all[static_cast<Index>(rec.nearest)];
        const glm::dvec3 trial = glm::normalize(best - step * (nearest - glm::dot(nearest, best) * best));
        // m: the trial's largest dot product, or a lower bound of it when that is ≥ best_dot.
        double m = 0;
        if (follow) {
            const LobeBuildMemo::Step& was = memo->steps[static_cast<Index>(it)];
            if (!was.accepted) {
                m = was.value; // ≥ best_dot: still refused, and still a lower bound
            } else {
                m = std::max(was.value, max_dot(trial, old_count, nullptr));
                if (m != was.value) follow = false; // from here on the pole differs
            }
        } else {
            double bound = 0;
            m = beaten_near(trial, bound) >= 0 ? bound : max_dot_near(trial, nullptr);
        }
        rec.accepted = m < best_dot;
        rec.value = m;
        if (rec.accepted) {
            best_dot = m;
            best = trial;
        } else {
            step *= 0.5;
        }
        out.steps.push_back(rec);
    }
    empty_angle_ = std::acos(std::clamp(best_dot, -1.0, 1.0));
    if (empty_angle_ < 3.0 * M_PI / 180.0)
        throw InvalidInput("the lobe's strokes leave no open direction around its centre (they cover it densely)");
    stereo_ = Stereo(best);
}

void Builder::find_crossings()
{
    // After one more stroke, the old strokes' crossings are the previous build's: only pairs
    // with a new segment are tested. Anything refused is refused by the whole search, so
    // that the message is the same.
    if (old_memo_) {
        if (find_crossings(true)) return;
        crossings_.clear();
    }
    find_crossings(false);
}

bool Builder::find_crossings(bool only_new)
{
    std::vector<SegmentGrid::Seg> segs;
    int first_new = 0;
    for (Index s = 0; s < strokes_.size(); ++s) {
        if (s == old_strokes_) first_new = static_cast<int>(segs.size());
        const Index n = dirs_[s].size();
        const Index count = strokes_[s].closed ? n : n - 1;
        for (Index i = 0; i < count; ++i)
            segs.push_back({static_cast<int>(s), static_cast<int>(i), dirs_[s][i], dirs_[s][(i + 1) % n]});
    }
    if (only_new && old_strokes_ >= strokes_.size()) first_new = static_cast<int>(segs.size());
    SegmentGrid grid(std::move(segs));
    crossing_count_.assign(strokes_.size(), 0);
    std::map<std::pair<int, int>, std::size_t> pair_count; // (lower, higher stroke) → crossings
    if (only_new) {
        crossings_ = old_memo_->crossings;
        for (const Crossing& c : crossings_) {
            ++crossing_count_[static_cast<Index>(c.a)];
            ++crossing_count_[static_cast<Index>(c.b)];
        }
    }
    // Looking only at the new segments, a refusal hands over to the whole search (false).
    struct Refused {};
    auto refuse = [&](const std::string& why) {
        if (only_new) throw Refused{};
        throw InvalidInput(why);
    };
    auto test = [&](const SegmentGrid::Seg& a, const SegmentGrid::Seg& b) {
        double s = 0, t = 0;
        if (!arc_crossing(a.p0, a.p1, b.p0, b.p1, s, t)) return;
        if (a.stroke == b.stroke) refuse(stroke_name(a.stroke) + " folds back over itself as seen from the lobe's centre");
        if (crossings_.size() >= 100000) refuse("the lobe's strokes cross each other too often to mesh");
        crossings_.push_back({a.stroke, a.index, b.stroke, b.index, s, t});
        ++crossing_count_[static_cast<Index>(a.stroke)];
        ++crossing_count_[static_cast<Index>(b.stroke)];
        ++pair_count[{std::min(a.stroke, b.stroke), std::max(a.stroke, b.stroke)}];
    };
    try {
        grid.for_each_candidate_from(only_new ? first_new : 0, test);
        // Two strokes that run along each other (seen from the centre) cross again and again.
        for (const auto& [pair, c] : pair_count) {
            const Index a = static_cast<Index>(pair.first), b = static_cast<Index>(pair.second);
            if (c > std::max<std::size_t>(16, std::min(dirs_[a].size(), dirs_[b].size()) / 2))
                refuse(stroke_name(pair.second) + " runs along " + stroke_name(pair.first) +
                       " as seen from the lobe's centre (they cross " + std::to_string(c) + " times; is one inside the lobe?)");
        }
    } catch (const Refused&) {
        return false;
    }
    sort_crossings();
    return true;
}

void Builder::sort_crossings()
{
    std::sort(crossings_.begin(), crossings_.end(), [](const Crossing& x, const Crossing& y) {
        return std::tie(x.a, x.seg, x.s, x.b, x.other_seg) < std::tie(y.a, y.seg, y.s, y.b, y.other_seg);
    });
    memo_->crossings = crossings_;
}

void Builder::build_chains()
{
    // Nodes: every sample, then every crossing.
    sample_offset_.assign(strokes_.size() + 1, 0);
    for (Index s = 0; s < strokes_.size(); ++s) sample_offset_[s + 1] = sample_offset_[s] + strokes_[s].points.size();
    sample_node_.assign(sample_offset_.back(), -1);
    for (Index s = 0; s < strokes_.size(); ++s)
        for (Index i = 0; i < dirs_[s].size(); ++i) {
            Node n;
            n.dir = dirs_[s][i];
            n.radius = radii_[s][i];
            n.origin = {LobeVertexKind::Sample, static_cast<int>(s), static_cast<int>(i), -1};
            sample_node_[sample_offset_[s] + i] = add_node(n);
        }
    // Per stroke: (segment, parameter, node) of every crossing on it.
    struct OnStroke {
        int seg;
        double t;
        int node;
    };
    std::vector<std::vector<OnStroke>> on(strokes_.size());
    for (Crossing& c : crossings_) {
        const Index a = static_cast<Index>(c.a), b = static_cast<Index>(c.b);
        auto lerp3 = [&](Index s, int seg, double t) {
            const auto& pts = strokes_[s].points;
            const glm::dvec3 p0(pts[static_cast<Index>(seg)]);
            const glm::dvec3 p1(pts[(static_cast<Index>(seg) + 1) % pts.size()]);
            return p0 + t * (p1 - p0);
        };
        // Where the two segments cross seen from the centre: the direction common to the
        // planes through the centre and each segment, and on each segment the point in that
        // direction. Found in 3D rather than in the projection, so that it does not depend on
        // the pole: a stroke that moves the pole leaves the crossings of other strokes (and
        // with them the regions they bound) where they were.
        const glm::dvec3 a0 = lerp3(a, c.seg, 0.0) - centre_, a1 = lerp3(a, c.seg, 1.0) - centre_;
        const glm::dvec3 b0 = lerp3(b, c.other_seg, 0.0) - centre_, b1 = lerp3(b, c.other_seg, 1.0) - centre_;
        glm::dvec3 d = glm::cross(glm::cross(a0, a1), glm::cross(b0, b1));
        auto along = [](const glm::dvec3& p0, const glm::dvec3& p1, const glm::dvec3& dir, double fallback) {
            // p0 + s (p1 − p0) parallel to dir: cross(p0, dir) + s cross(p1 − p0, dir) = 0.
            const glm::dvec3 u = glm::cross(p0, dir), w = glm::cross(p1 - p0, dir);
            const double ww = glm::dot(w, w);
            const double s = ww > 0.0 ? -glm::dot(u, w) / ww : fallback;
            return std::isfinite(s) ? std::clamp(s, 0.0, 1.0) : fallback;
        };
        double sa = c.s, sb = c.t;
        const double dl = glm::length(d);
        if (dl > 1e-12 * glm::length(a1 - a0) * glm::length(b1 - b0) * (glm::length(a0) + glm::length(b0))) {
            d /= dl;
            if (glm::dot(d, a0 + a1 + b0 + b1) < 0.0) d = -d;
            sa = along(a0, a1, d, c.s);
            sb = along(b0, b1, d, c.t);
        }
        c.s = sa; // the chains order crossings along each segment by these
        c.t = sb;
        const glm::dvec3 pa = lerp3(a, c.seg, sa), pb = lerp3(b, c.other_seg, sb);
        const glm::dvec3 mid = 0.5 * (pa + pb);
        Node n;
        n.dir = glm::normalize(mid - centre_);
        n.radius = glm::length(mid - centre_);
        n.origin = {LobeVertexKind::Crossing, c.a, -1, c.b};
        c.node = add_node(n);
    }
    // Crossings closer together than the merge distance (several strokes through about one
    // point, or two strokes crossing twice in quick succession) become one vertex, so no
    // sliver is left between them.
    if (crossings_.size() <= 4000) {
        std::vector<int> parent(nodes_.size());
        for (Index i = 0; i < parent.size(); ++i) parent[i] = static_cast<int>(i);
        auto find = [&](int x) {
            while (parent[static_cast<Index>(x)] != x) x = parent[static_cast<Index>(x)] = parent[static_cast<Index>(parent[static_cast<Index>(x)])];
            return x;
        };
        auto pos = [&](int id) { return centre_ + nodes_[static_cast<Index>(id)].radius * nodes_[static_cast<Index>(id)].dir; };
        for (Index i = 0; i < crossings_.size(); ++i)
            for (Index j = i + 1; j < crossings_.size(); ++j) {
                const Crossing& x = crossings_[i];
                const Crossing& y = crossings_[j];
                const double merge = options_.crossing_merge_fraction *
                                     std::min({spacing_[static_cast<Index>(x.a)], spacing_[static_cast<Index>(x.b)],
                                               spacing_[static_cast<Index>(y.a)], spacing_[static_cast<Index>(y.b)]});
                if (glm::distance(pos(x.node), pos(y.node)) < merge) parent[static_cast<Index>(find(x.node))] = find(y.node);
            }
        std::map<int, std::pair<glm::dvec3, int>> sums; // root → (sum of positions, count)
        for (const Crossing& c : crossings_) {
            auto& e = sums[find(c.node)];
            e.first += pos(c.node);
            e.second += 1;
        }
        for (auto& [root, e] : sums) {
            const glm::dvec3 p = e.first / static_cast<double>(e.second) - centre_;
            nodes_[static_cast<Index>(root)].radius = glm::length(p);
            nodes_[static_cast<Index>(root)].dir = p / glm::length(p);
        }
        for (Crossing& c : crossings_) c.node = find(c.node);
    }
    for (const Crossing& c : crossings_) {
        on[static_cast<Index>(c.a)].push_back({c.seg, c.s, c.node});
        on[static_cast<Index>(c.b)].push_back({c.other_seg, c.t, c.node});
    }
    chains_.assign(strokes_.size(), {});
    for (Index s = 0; s < strokes_.size(); ++s) {
        auto& list = on[s];
        std::sort(list.begin(), list.end(), [](const OnStroke& x, const OnStroke& y) {
            return std::tie(x.seg, x.t) < std::tie(y.seg, y.t);
        });
        const auto& pts = strokes_[s].points;
        const Index n = pts.size();
        const bool closed = strokes_[s].closed;
        // Drop samples too close to a crossing on the same stroke (never an open stroke's ends).
        const double merge = options_.crossing_merge_fraction * spacing_[s];
        std::vector<char> keep(n, 1);
        for (const OnStroke& c : list) {
            const glm::dvec3 x = glm::dvec3(nodes_[static_cast<Index>(c.node)].dir) *
                                     nodes_[static_cast<Index>(c.node)].radius + centre_;
            for (Index k : {static_cast<Index>(c.seg), (static_cast<Index>(c.seg) + 1) % n}) {
                if (!closed && (k == 0 || k + 1 == n)) continue;
                if (glm::distance(glm::dvec3(pts[k]), x) < merge) keep[k] = 0;
            }
        }
        std::vector<int> chain;
        Index next = 0;
        auto push = [&](int id) {
            if (chain.empty() || chain.back() != id) chain.push_back(id);
        };
        for (Index i = 0; i < n; ++i) {
            if (keep[i]) push(sample_node_[sample_offset_[s] + i]);
            while (next < list.size() && static_cast<Index>(list[next].seg) == i) push(list[next++].node);
        }
        if (closed && chain.size() > 1 && chain.front() == chain.back()) chain.pop_back();
        if (chain.size() < (closed ? 3u : 2u))
            throw InvalidInput(stroke_name(static_cast<int>(s)) + " is crossed too densely by other strokes to mesh");
        // Long segments are subdivided along the straight 3D segment, so that seen from the
        // centre every piece is short and the planar constraint follows the great arc.
        std::vector<int> fine;
        const Index m = chain.size();
        for (Index i = 0; i < m; ++i) {
            fine.push_back(chain[i]);
            if (!closed && i + 1 == m) break;
            const Node a = nodes_[static_cast<Index>(chain[i])];
            const Node b = nodes_[static_cast<Index>(chain[(i + 1) % m])];
            const int pieces = static_cast<int>(std::ceil(angle_between(a.dir, b.dir) / max_piece_angle_));
            const glm::dvec3 pa = centre_ + a.radius * a.dir, pb = centre_ + b.radius * b.dir;
            for (int k = 1; k < pieces; ++k) {
                const glm::dvec3 p = pa + (pb - pa) * (static_cast<double>(k) / pieces);
                Node piece;
                piece.radius = glm::length(p - centre_);
                piece.dir = (p - centre_) / piece.radius;
                piece.origin = {LobeVertexKind::Segment, static_cast<int>(s), a.origin.sample, -1};
                fine.push_back(add_node(piece));
            }
        }
        chains_[s] = std::move(fine);
    }
}

void Builder::plan_partial()
{
    partial_ = false;
    const double reference = options_.reference_radius_m > 0 ? options_.reference_radius_m : mean_radius_;
    if (previous_->centre != centre_ || previous_->reference_radius != reference) return;
    std::vector<RegionChain> chains(chains_.size());
    for (Index s = 0; s < chains_.size(); ++s) {
        chains[s].points.reserve(chains_[s].size());
        for (int id : chains_[s]) chains[s].points.push_back(emitted_position(id));
        chains[s].closed = strokes_[s].closed;
        chains[s].crossed = crossing_count_[s] > 0;
    }
    changed_ = find_changed_regions(*previous_, *previous_regions_, chains);
    partial_ = !changed_.everything;
    if (!partial_) return;
    // A cap of directions around each changed region of the previous surface. The changed
    // regions of this build cover what those did (the same border edges bound both), so a
    // lattice point outside every cap cannot fall into one: seed_fill neither tests it nor
    // the stroke edges that only such points could be near.
    const TriangleMesh& mesh = previous_->mesh;
    const auto& face_region = previous_regions_->regions.face_region;
    std::vector<int> cap_of(changed_.keep.size(), -1);
    std::vector<glm::dvec3> dir(mesh.positions.size(), glm::dvec3(0.0));
    std::vector<char> have(mesh.positions.size(), 0);
    std::vector<glm::dvec3> sum;
    for (Index f = 0; f < mesh.triangles.size(); ++f) {
        const Index r = static_cast<Index>(face_region[f]);
        if (changed_.keep[r]) continue;
        if (cap_of[r] < 0) {
            cap_of[r] = static_cast<int>(sum.size());
            sum.emplace_back(0.0);
        }
        for (int v : mesh.triangles[f]) {
            const Index i = static_cast<Index>(v);
            if (!have[i]) {
                have[i] = 1;
                dir[i] = glm::normalize(glm::dvec3(mesh.positions[i]) - centre_);
            }
            sum[static_cast<Index>(cap_of[r])] += dir[i];
        }
    }
    caps_.assign(sum.size(), {glm::dvec3(0.0), 1.0});
    for (Index c = 0; c < sum.size(); ++c) {
        const double len = glm::length(sum[c]);
        caps_[c].first = len > 1e-12 ? sum[c] / len : glm::dvec3(0, 0, 1);
        if (!(len > 1e-12)) caps_[c].second = -1.0; // a region round the whole sphere: everything
    }
    for (Index f = 0; f < mesh.triangles.size(); ++f) {
        const Index r = static_cast<Index>(face_region[f]);
        if (changed_.keep[r]) continue;
        auto& cap = caps_[static_cast<Index>(cap_of[r])];
        for (int v : mesh.triangles[f]) cap.second = std::min(cap.second, glm::dot(dir[static_cast<Index>(v)], cap.first));
    }
}

VH Builder::insert_node(int id, VH hint)
{
    const glm::dvec2 x = stereo_.to_plane(nodes_[static_cast<Index>(id)].dir);
    const Kernel::Point_2 p(x.x, x.y);
    VH v = hint == VH() ? cdt_.insert(p) : cdt_.insert(p, hint->face());
    // Nodes at one point (two strokes through the same sample) share the vertex: it is the
    // first node's, whatever order they went in.
    if (v->info().id < 0 || id < v->info().id) v->info().id = id;
    return v;
}

void Builder::triangulate()
{
    node_vertex_.assign(nodes_.size(), VH());
    VH hint;
    {
        std::vector<Kernel::Point_2> where(nodes_.size());
        std::vector<std::size_t> order;
        std::vector<char> seen(nodes_.size(), 0);
        if (partial_) {
            // Only the nodes of the stroke edges in or around the changed regions.
            std::fill(seen.begin(), seen.end(), 1);
            for (Index s = 0; s < chains_.size(); ++s) {
                const auto& chain = chains_[s];
                const auto& edges = changed_.edges[s];
                for (Index i = 0; i < edges.size(); ++i)
                    if (edges[i] != ChangedRegions::Outside)
                        seen[static_cast<Index>(chain[i])] = seen[static_cast<Index>(chain[(i + 1) % chain.size()])] = 0;
            }
        }
        for (const auto& chain : chains_)
            for (int id : chain)
                if (!seen[static_cast<Index>(id)]) {
                    seen[static_cast<Index>(id)] = 1;
                    const glm::dvec2 x = stereo_.to_plane(nodes_[static_cast<Index>(id)].dir);
                    where[static_cast<Index>(id)] = Kernel::Point_2(x.x, x.y);
                    order.push_back(static_cast<std::size_t>(id));
                }
        spatially_sort(order, where);
        for (std::size_t id : order) hint = node_vertex_[id] = insert_node(static_cast<int>(id), hint);
    }
    // A small ring around the pole closes the planar triangulation's outside: the ring
    // encloses every stroke point, and the pole vertex fans the ring.
    const double ring_angle = ring_angle_ = std::min(empty_angle_ * 0.5, 2.0 * M_PI / 180.0);
    for (int k = 0; k < 6; ++k) {
        const double a = k * M_PI / 3.0;
        const glm::dvec3 d = std::cos(ring_angle) * stereo_.pole +
                             std::sin(ring_angle) * (std::cos(a) * stereo_.e1 + std::sin(a) * stereo_.e2);
        Node n;
        n.dir = d;
        const int id = add_node(n);
        node_vertex_.push_back(VH());
        node_vertex_[static_cast<Index>(id)] = insert_node(id, hint);
    }
    for (Index s = 0; s < chains_.size(); ++s) {
        const auto& chain = chains_[s];
        const Index n = chain.size();
        const Index count = strokes_[s].closed ? n : n - 1;
        for (Index i = 0; i < count; ++i) {
            const int u = chain[i], v = chain[(i + 1) % n];
            if (partial_) {
                const auto kind = changed_.edges[s][i];
                if (kind == ChangedRegions::Outside) continue;
                inserted_.push_back({u, v});
                if (kind == ChangedRegions::BorderAhead) border_.push_back({u, v});
                if (kind == ChangedRegions::BorderBack) border_.push_back({v, u});
            }
            const VH a = node_vertex_[static_cast<Index>(u)];
            const VH b = node_vertex_[static_cast<Index>(v)];
            if (a != b) cdt_.insert_constraint(a, b);
        }
    }
    Node pole;
    pole.dir = stereo_.pole;
    pole_node_ = add_node(pole);
    node_vertex_.push_back(VH());
}

void Builder::mark_regions()
{
    for (FH f : cdt_.all_face_handles()) f->info() = FaceInfo{};
    region_count_ = 0;
    std::vector<FH> stack;
    for (FH f : cdt_.finite_face_handles()) {
        if (f->info().region >= 0) continue;
        f->info().region = region_count_;
        stack.push_back(f);
        while (!stack.empty()) {
            FH g = stack.back();
            stack.pop_back();
            for (int i = 0; i < 3; ++i) {
                FH h = g->neighbor(i);
                if (cdt_.is_infinite(h) || h->info().region >= 0 || cdt_.is_constrained(CDT::Edge(g, i))) continue;
                h->info().region = region_count_;
                stack.push_back(h);
            }
        }
        ++region_count_;
    }
    mark_inside();
}

void Builder::mark_inside()
{
    region_inside_.assign(static_cast<Index>(region_count_), 1);
    if (!partial_) return;
    // The changed side of every border edge is in, the kept side out; every region is one
    // or the other (the border edges enclose the changed regions).
    std::vector<char> in(static_cast<Index>(region_count_), 0), out(static_cast<Index>(region_count_), 0);
    for (const auto& [u, v] : border_) {
        const VH a = node_vertex_[static_cast<Index>(u)], b = node_vertex_[static_cast<Index>(v)];
        FH f;
        int i = 0;
        if (a == b || !cdt_.is_edge(a, b, f, i)) throw PartialFailed{};
        // Outward u → v is planar clockwise: the changed side's face runs v → u counter-clockwise.
        const FH changed = f->vertex(CDT::ccw(i)) == b ? f : f->neighbor(i);
        const FH kept = changed == f ? f->neighbor(i) : f;
        if (cdt_.is_infinite(changed) || cdt_.is_infinite(kept)) throw PartialFailed{};
        in[static_cast<Index>(changed->info().region)] = 1;
        out[static_cast<Index>(kept->info().region)] = 1;
    }
    for (Index r = 0; r < in.size(); ++r) {
        if (in[r] && out[r]) throw PartialFailed{};
        region_inside_[r] = !out[r];
    }
}

void Builder::find_paper_regions()
{
    paper_region_.assign(static_cast<Index>(region_count_), 0);
    region_strokes_.assign(static_cast<Index>(region_count_), {-1, -1});
    if (!options_.paper_strips) return;
    std::vector<char> bad(static_cast<Index>(region_count_), 0);
    auto stroke_of = [&](VH v) -> int {
        const int id = v->info().id;
        if (id < 0) return -1;
        const auto& o = nodes_[static_cast<Index>(id)].origin;
        return o.kind == LobeVertexKind::Sample || o.kind == LobeVertexKind::Segment ? o.stroke : -1;
    };
    for (Index r = 0; r < static_cast<Index>(region_count_); ++r)
        if (!region_inside_[r]) bad[r] = 1;
    std::vector<std::array<int, 2>> edge_counts(static_cast<Index>(region_count_), {0, 0});
    for (FH f : cdt_.finite_face_handles()) {
        const Index r = static_cast<Index>(f->info().region);
        auto& rs = region_strokes_[r];
        for (int i = 0; i < 3; ++i) {
            const int s = stroke_of(f->vertex(i));
            if (s < 0 || crossing_count_[static_cast<Index>(s)] > 0 || !strokes_[static_cast<Index>(s)].closed) {
                bad[r] = 1;
                continue;
            }
            if (rs.first < 0 || rs.first == s) rs.first = s;
            else if (rs.second < 0 || rs.second == s) rs.second = s;
            else bad[r] = 1;
            if (cdt_.is_infinite(f->neighbor(i))) bad[r] = 1;
        }
        for (int i = 0; i < 3; ++i) {
            if (!cdt_.is_constrained(CDT::Edge(f, i))) continue;
            const int s = stroke_of(f->vertex((i + 1) % 3));
            if (s == rs.first) ++edge_counts[r][0];
            else if (s == rs.second) ++edge_counts[r][1];
        }
    }
    for (Index r = 0; r < static_cast<Index>(region_count_); ++r) {
        const auto [a, b] = region_strokes_[r];
        if (bad[r] || a < 0 || b < 0) continue;
        // The region is the whole annulus between the two loops: all their edges bound it.
        if (edge_counts[r][0] != static_cast<int>(chains_[static_cast<Index>(a)].size()) ||
            edge_counts[r][1] != static_cast<int>(chains_[static_cast<Index>(b)].size()))
            continue;
        paper_region_[r] = 1;
    }
}

void Builder::insert_fill(const glm::dvec2& x, int region, VH& hint, int& added)
{
    Node n;
    n.dir = glm::normalize(stereo_.to_sphere(x));
    insert_fill(n, x, region, hint, added);
}

void Builder::insert_fill(const Node& n, const glm::dvec2& x, int region, VH& hint, int& added)
{
    const int id = add_node(n);
    node_vertex_.push_back(VH());
    const Kernel::Point_2 p(x.x, x.y);
    const std::size_t before = cdt_.number_of_vertices();
    VH v = hint == VH() ? cdt_.insert(p) : cdt_.insert(p, hint->face());
    if (v->info().id < 0) v->info().id = id;
    node_vertex_[static_cast<Index>(id)] = v;
    hint = v;
    ++added;
    if (cdt_.number_of_vertices() == before) return; // an existing vertex: nothing changed
    // Every face an insertion creates or changes is incident to the new vertex, and lies in
    // the region of the point, unless the point fell on a stroke segment (which it then
    // splits) or outside every region: then the regions are marked again before they are read.
    if (region < 0 || cdt_.are_there_incident_constraints(v)) {
        regions_stale_ = true;
        return;
    }
    auto f = cdt_.incident_faces(v);
    const auto done = f;
    do {
        if (!cdt_.is_infinite(f)) f->info() = FaceInfo{region, false};
    } while (++f != done);
}

void Builder::seed_fill(double max_edge, int& added)
{
    // Fill vertices on a Fibonacci lattice of directions about as dense as the largest
    // allowed triangle, except near strokes and near the pole: uniform, deterministic, and
    // a new stroke only removes the lattice points near it.
    const double spacing = 0.85 * max_edge;
    const double clearance = 0.5 * spacing;
    // Directions along every stroke, binned in a uniform grid over [-1, 1]³ whose cells are
    // at least `clearance` wide: every direction within `clearance` of a lattice point lies
    // in the point's cell or in a neighbouring one.
    //
    // A build of the changed regions only tests the lattice points in the caps around them
    // (plan_partial), and only against the stroke edges that can come within `clearance` of
    // such a point (an edge's directions lie within its length of its first end): a point's
    // verdict is the whole build's, for no direction left out could be near it.
    const double cap_margin = 0.05; // the caps bound the regions' flat triangles; this covers the planar constraints' bulge
    std::vector<double> cap_cos(caps_.size()), reach_angle(caps_.size());
    for (Index c = 0; c < caps_.size(); ++c) {
        // A cap wider than a hemisphere is not convex: the triangles between its vertices
        // may leave it, so it holds every direction.
        const double radius = caps_[c].second <= -1.0 ? M_PI : std::acos(std::clamp(caps_[c].second, -1.0, 1.0));
        cap_cos[c] = radius + cap_margin < 0.5 * M_PI ? std::cos(radius + cap_margin) : -2.0;
        reach_angle[c] = cap_cos[c] < -1.0 ? 2.0 * M_PI : radius + cap_margin + clearance + 1e-6;
    }
    auto in_caps = [&](const glm::dvec3& d) {
        if (!partial_) return true;
        for (Index c = 0; c < caps_.size(); ++c)
            if (glm::dot(d, caps_[c].first) >= cap_cos[c]) return true;
        return false;
    };
    std::vector<double> reach_cos(caps_.size()), reach_sin(caps_.size());
    for (Index c = 0; c < caps_.size(); ++c) {
        reach_cos[c] = std::cos(std::min(M_PI, reach_angle[c]));
        reach_sin[c] = std::sin(std::min(M_PI, reach_angle[c]));
    }
    auto reaches_caps = [&](const glm::dvec3& a, const glm::dvec3& b) {
        if (!partial_) return true;
        // angle(a, centre) ≤ reach + |ab|, as cosines: cos(reach + |ab|) by the sum formula.
        // reach + |ab| ≥ π (every direction is within it) ⇔ cos |ab| ≤ cos(π − reach) = −cos reach.
        const double cl = glm::dot(a, b), sl = glm::length(glm::cross(a, b));
        for (Index c = 0; c < caps_.size(); ++c)
            if (reach_angle[c] >= M_PI || cl <= -reach_cos[c] + 1e-9 ||
                glm::dot(a, caps_[c].first) >= reach_cos[c] * cl - reach_sin[c] * sl - 1e-9)
                return true;
        return false;
    };
    std::vector<glm::dvec3> along;
    for (Index s = 0; s < chains_.size(); ++s) {
        const auto& chain = chains_[s];
        const Index n = chain.size();
        const Index count = strokes_[s].closed ? n : n - 1;
        along.push_back(nodes_[static_cast<Index>(chain[0])].dir);
        for (Index i = 0; i < count; ++i) {
            const glm::dvec3 a = nodes_[static_cast<Index>(chain[i])].dir;
            const glm::dvec3 b = nodes_[static_cast<Index>(chain[(i + 1) % n])].dir;
            if (!reaches_caps(a, b)) continue;
            const int steps = std::max(1, static_cast<int>(std::ceil(angle_between(a, b) / (0.25 * clearance))));
            for (int k = 1; k <= steps; ++k) along.push_back(glm::normalize(a + (b - a) * (static_cast<double>(k) / steps)));
        }
    }
    const double cell = std::max(clearance, 2.0 / 48.0);
    const int dim = static_cast<int>(std::floor(2.0 / cell)) + 1;
    // c + 1 ≥ 0, so truncation is the floor; a multiplication by the reciprocal is monotone
    // too, and two directions within `clearance` differ by less than a cell in every coordinate
    // (by their chord, shorter than the angle) with a margin far above its rounding.
    const double per_cell = 1.0 / cell;
    auto coord = [&](double c) { return std::min(static_cast<int>(std::max(0.0, c + 1.0) * per_cell), dim - 1); };
    auto cell_index = [&](int x, int y, int z) { return (static_cast<Index>(z) * static_cast<Index>(dim) + static_cast<Index>(y)) * static_cast<Index>(dim) + static_cast<Index>(x); };
    std::vector<int> start(static_cast<Index>(dim) * static_cast<Index>(dim) * static_cast<Index>(dim) + 1, 0);
    for (const glm::dvec3& d : along) ++start[cell_index(coord(d.x), coord(d.y), coord(d.z)) + 1];
    for (Index i = 1; i < start.size(); ++i) start[i] += start[i - 1];
    std::vector<glm::dvec3> binned(along.size());
    {
        std::vector<int> next(start.begin(), start.end() - 1);
        for (const glm::dvec3& d : along) binned[static_cast<Index>(next[cell_index(coord(d.x), coord(d.y), coord(d.z))]++)] = d;
    }
    const double cos_clear = std::cos(clearance);
    const double ring_keep = std::cos(ring_angle_ + clearance);
    const int count = static_cast<int>(std::ceil(4.0 * M_PI / (spacing * spacing * 0.866)));
    const double golden = M_PI * (3.0 - std::sqrt(5.0));
    std::vector<glm::dvec3> lattice;
    std::vector<Kernel::Point_2> where;
    for (int i = 0; i < count; ++i) {
        const double z = 1.0 - (2.0 * i + 1.0) / count;
        const double rr = std::sqrt(std::max(0.0, 1.0 - z * z));
        const glm::dvec3 d(rr * std::cos(golden * i), rr * std::sin(golden * i), z);
        if (glm::dot(d, stereo_.pole) > ring_keep || !in_caps(d)) continue;
        bool near = false;
        const int cx = coord(d.x), cy = coord(d.y), cz = coord(d.z);
        for (int z2 = std::max(0, cz - 1); z2 <= std::min(dim - 1, cz + 1) && !near; ++z2)
            for (int y2 = std::max(0, cy - 1); y2 <= std::min(dim - 1, cy + 1) && !near; ++y2)
                for (int x2 = std::max(0, cx - 1); x2 <= std::min(dim - 1, cx + 1) && !near; ++x2) {
                    const Index c = cell_index(x2, y2, z2);
                    for (int k = start[c]; k < start[c + 1]; ++k)
                        if (glm::dot(binned[static_cast<Index>(k)], d) > cos_clear) {
                            near = true;
                            break;
                        }
                }
        if (near) continue;
        const glm::dvec2 x = stereo_.to_plane(d);
        lattice.push_back(d);
        where.emplace_back(x.x, x.y);
    }
    // Located and inserted along a space-filling curve.
    std::vector<std::size_t> order(lattice.size());
    for (Index i = 0; i < order.size(); ++i) order[i] = i;
    spatially_sort(order, where);
    struct Candidate {
        glm::dvec3 dir;
        int region; ///< -1: not located inside a face
    };
    std::vector<Candidate> candidates;
    FH hint_face;
    for (std::size_t i : order) {
        const glm::dvec3& d = lattice[i];
        const Kernel::Point_2& p = where[i];
        // Located before any fill vertex goes in.
        CDT::Locate_type lt;
        int li = 0;
        hint_face = cdt_.locate(p, lt, li, hint_face);
        const bool inside = hint_face != FH() && !cdt_.is_infinite(hint_face) && hint_face->info().region >= 0;
        if (inside && static_cast<Index>(hint_face->info().region) < paper_region_.size() &&
            (paper_region_[static_cast<Index>(hint_face->info().region)] ||
             !region_inside_[static_cast<Index>(hint_face->info().region)]))
            continue;
        candidates.push_back({d, inside && lt == CDT::FACE ? hint_face->info().region : -1});
    }
    VH hint;
    for (const Candidate& c : candidates) {
        if (added >= options_.max_fill_vertices) break;
        Node n;
        n.dir = c.dir;
        insert_fill(n, stereo_.to_plane(c.dir), c.region, hint, added);
    }
}

void Builder::refine()
{
    const double r = std::max(options_.reference_radius_m > 0 ? options_.reference_radius_m : mean_radius_, 1e-6);
    const double by_sagitta = std::acos(std::clamp(1.0 - options_.fill_sagitta_m / r, -1.0, 1.0));
    const double by_edge = options_.fill_edge_m / r;
    const double coarseness = std::isfinite(options_.fill_coarseness) ? std::clamp(options_.fill_coarseness, 1.0, 4.0) : 1.0;
    const double max_angle = std::max(1e-3, std::min(by_sagitta, by_edge) * coarseness);
    const double max_edge = std::sqrt(3.0) * max_angle;
    // A side whose chord is below this spans less than max_edge (with a margin far above
    // rounding), so most triangles are passed without an arcsine.
    const double short_chord = 2.0 * std::sin(0.5 * max_edge) * (1.0 - 1e-9);
    int added = 0;
    auto dir_of = [&](VH v) {
        const int id = v->info().id;
        if (id >= 0) return nodes_[static_cast<Index>(id)].dir;
        return glm::normalize(stereo_.to_sphere({v->point().x(), v->point().y()}));
    };
    // Regions are marked once; fill vertices inserted into a region keep its faces tagged
    // (insert_fill), and faces found fine in one pass are not looked at again until an
    // insertion changes them. Neither changes which points a pass adds.
    mark_regions();
    find_paper_regions();
    regions_stale_ = false;
    // Where every region built is a paper strip (a ring drawn between two others, Fig. 5),
    // there is nothing to fill: fill vertices go into the other regions only, and those are
    // the kept ones.
    bool to_fill = false;
    for (Index k = 0; k < static_cast<Index>(region_count_); ++k)
        to_fill = to_fill || (region_inside_[k] && !paper_region_[k]);
    if (!to_fill) return;
    seed_fill(max_edge, added);
    for (int pass = 0; pass < 4; ++pass) {
        if (regions_stale_) {
            mark_regions();
            find_paper_regions();
            regions_stale_ = false;
        }
        std::vector<std::pair<glm::dvec2, int>> points; // (where, region)
        for (FH f : cdt_.finite_face_handles()) {
            if (f->info().fine) continue;
            const int region = f->info().region;
            if (paper_region_[static_cast<Index>(region)] || !region_inside_[static_cast<Index>(region)]) {
                f->info().fine = true;
                continue;
            }
            const glm::dvec3 a = dir_of(f->vertex(0)), b = dir_of(f->vertex(1)), c = dir_of(f->vertex(2));
            // Too large: a free side longer than that of an equilateral triangle with the
            // largest circumradius allowed.
            // Stroke segments are never split here (remeshing splits them), so only free sides count.
            const std::array<glm::dvec3, 3> d{a, b, c};
            double chord = 0;
            for (int i = 0; i < 3; ++i)
                if (!cdt_.is_constrained(CDT::Edge(f, i)))
                    chord = std::max(chord, glm::length(d[static_cast<Index>((i + 1) % 3)] - d[static_cast<Index>((i + 2) % 3)]));
            if (chord < short_chord) {
                f->info().fine = true;
                continue;
            }
            double longest = 0;
            for (int i = 0; i < 3; ++i)
                if (!cdt_.is_constrained(CDT::Edge(f, i)))
                    longest = std::max(longest, angle_between(d[static_cast<Index>((i + 1) % 3)], d[static_cast<Index>((i + 2) % 3)]));
            if (longest <= max_edge) {
                f->info().fine = true;
                continue;
            }
            // The circumcentre (Delaunay refinement) when the triangle is not a sliver and its
            // circumcentre lies in the same region, else the centroid, which is inside the
            // triangle: no stroke is crossed either way.
            const double radius = circumradius_angle(a, b, c);
            bool use_cc = radius < longest;
            Kernel::Point_2 cc;
            if (use_cc) {
                cc = CGAL::circumcenter(f->vertex(0)->point(), f->vertex(1)->point(), f->vertex(2)->point());
                CDT::Locate_type lt;
                int li = 0;
                FH located = cdt_.locate(cc, lt, li, f);
                use_cc = lt == CDT::FACE && !cdt_.is_infinite(located) && located->info().region == region;
            }
            if (use_cc) {
                points.emplace_back(glm::dvec2(cc.x(), cc.y()), region);
            } else {
                glm::dvec2 x(0.0);
                for (int i = 0; i < 3; ++i) x += glm::dvec2(f->vertex(i)->point().x(), f->vertex(i)->point().y());
                points.emplace_back(x / 3.0, region);
            }
        }
        if (points.empty()) break;
        VH hint;
        for (const auto& [x, region] : points) {
            if (added >= options_.max_fill_vertices) break;
            insert_fill(x, region, hint, added);
        }
        if (added >= options_.max_fill_vertices) break;
    }
    // The output emits paper regions in region order (regions numbered by their first face):
    // with any paper region, or when an insertion left the regions stale, they are marked
    // again on the final triangulation. Otherwise the tags kept up by insert_fill are exact.
    if (regions_stale_ || std::find(paper_region_.begin(), paper_region_.end(), 1) != paper_region_.end()) {
        mark_regions();
        find_paper_regions();
        regions_stale_ = false;
    }
}

void Builder::solve_fill_radii(const std::vector<std::array<int, 3>>& triangles, const std::vector<char>& on_chain)
{
    // Fill vertices (and vertices CGAL made at residual crossings) get the radius of a smooth
    // model of the whole lobe plus the harmonic interpolation of the strokes' residuals:
    // - the model is a least-squares fit of the radius over the sphere of directions by
    //   polynomials of degree ≤ 3 in the direction (the span of spherical harmonics up to
    //   degree 3), penalised by degree so it stays smooth where no stroke is: an ellipsoid
    //   or an off-centre sphere is nearly exact, so an automatic cap rounds off as the
    //   strokes around it suggest;
    // - the residuals (stroke radius − model) are interpolated harmonically, so the surface
    //   passes through every stroke and stays within their range.
    // Where the model is implausible (it leaves 0.5–1.5 times the strokes' radii), the
    // radius itself is interpolated harmonically.
    // Strokes separate the interpolated vertices of one region from those of every other, so
    // the system falls apart into one small system per group of connected interpolated
    // vertices, solved (and judged plausible) each on its own: a region's radii depend on the
    // region alone (and the model), whichever other regions are built with it.
    const Index n = nodes_.size();
    std::vector<char> used(n, 0);
    for (const auto& t : triangles)
        for (int id : t) used[static_cast<Index>(id)] = 1;
    std::vector<int> unknown(n, -1);
    int count = 0;
    for (Index i = 0; i < n; ++i)
        if (nodes_[i].origin.kind == LobeVertexKind::Fill && used[i]) unknown[i] = count++;
    if (count == 0) return;
    std::vector<char> rows(n, 0);
    for (Index i = 0; i < n; ++i) rows[i] = unknown[i] >= 0 ? 1 : 0;
    const Adjacency adj(n, triangles, rows);
    double lo = std::numeric_limits<double>::infinity(), hi = 0;
    std::vector<char> fit(n, 0);
    for (Index i = 0; i < n; ++i)
        if (on_chain[i] && nodes_[i].origin.kind != LobeVertexKind::Fill) {
            fit[i] = 1;
            lo = std::min(lo, nodes_[i].radius);
            hi = std::max(hi, nodes_[i].radius);
        }
    // The model is read at the interpolated vertices and their neighbours only.
    std::vector<char> needed(n, 0);
    for (Index i = 0; i < n; ++i) {
        if (unknown[i] < 0) continue;
        needed[i] = 1;
        for (int j : adj[i]) needed[static_cast<Index>(j)] = 1;
    }
    std::vector<double> model(n, 0.0);
    const bool have_model = fit_radius_model(fit, needed, model);
    // Groups: connected interpolated vertices (union–find over their rows).
    std::vector<int> parent(static_cast<Index>(count));
    for (Index r = 0; r < parent.size(); ++r) parent[r] = static_cast<int>(r);
    auto find = [&](int x) {
        while (parent[static_cast<Index>(x)] != x)
            x = parent[static_cast<Index>(x)] = parent[static_cast<Index>(parent[static_cast<Index>(x)])];
        return x;
    };
    std::vector<int> row_node(static_cast<Index>(count));
    for (Index i = 0; i < n; ++i) {
        if (unknown[i] < 0) continue;
        row_node[static_cast<Index>(unknown[i])] = static_cast<int>(i);
        for (int j : adj[i]) {
            const int col = unknown[static_cast<Index>(j)];
            if (col < 0) continue;
            const int a = find(unknown[i]), b = find(col);
            if (a != b) parent[static_cast<Index>(std::max(a, b))] = std::min(a, b);
        }
    }
    // Members of each group in row order, and their place in it.
    std::vector<int> group_of_root(static_cast<Index>(count), -1), local(static_cast<Index>(count));
    std::vector<std::vector<int>> groups;
    for (int r = 0; r < count; ++r) {
        int& g = group_of_root[static_cast<Index>(find(r))];
        if (g < 0) {
            g = static_cast<int>(groups.size());
            groups.emplace_back();
        }
        local[static_cast<Index>(r)] = static_cast<int>(groups[static_cast<Index>(g)].size());
        groups[static_cast<Index>(g)].push_back(r);
    }
    // The harmonic interpolation of the residuals: (Σ_j w_ij) x_i − Σ_j w_ij x_j = 0 at every
    // free vertex, with w_ij the inverse angular length of edge ij (so long strip edges and
    // short cap edges measure slope alike). Symmetric positive definite; only its lower
    // triangle is stored, which is all SimplicialLDLT reads. Small groups are solved dense.
    constexpr Index kDense = 48;
    std::vector<Eigen::Triplet<double>> entries;
    Eigen::MatrixXd dense;
    for (const auto& members : groups) {
        const Index m = members.size();
        bool use_model = have_model;
        for (int r : members) {
            const double v = model[static_cast<Index>(row_node[static_cast<Index>(r)])];
            if (!(v >= 0.5 * lo && v <= 1.5 * hi)) use_model = false;
        }
        auto model_at = [&](Index i) { return use_model ? model[i] : 0.0; };
        entries.clear();
        if (m <= kDense) dense.setZero(static_cast<Eigen::Index>(m), static_cast<Eigen::Index>(m));
        Eigen::VectorXd rhs = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(m));
        for (int r : members) {
            const Index i = static_cast<Index>(row_node[static_cast<Index>(r)]);
            const int row = local[static_cast<Index>(r)];
            double sum = 0;
            for (int j : adj[i]) {
                const double w = 1.0 / std::max(1e-6, angle_between(nodes_[i].dir, nodes_[static_cast<Index>(j)].dir));
                sum += w;
                const int c = unknown[static_cast<Index>(j)];
                if (c < 0) {
                    rhs[row] += w * (nodes_[static_cast<Index>(j)].radius - model_at(static_cast<Index>(j)));
                } else if (local[static_cast<Index>(c)] < row) {
                    if (m <= kDense) dense(row, local[static_cast<Index>(c)]) = -w;
                    else entries.emplace_back(row, local[static_cast<Index>(c)], -w);
                }
            }
            if (m <= kDense) dense(row, row) = sum;
            else entries.emplace_back(row, row, sum);
        }
        Eigen::VectorXd x;
        bool ok = false;
        if (m <= kDense) {
            const Eigen::LLT<Eigen::MatrixXd, Eigen::Lower> llt(dense);
            ok = llt.info() == Eigen::Success;
            if (ok) x = llt.solve(rhs);
        } else {
            Eigen::SparseMatrix<double> system(static_cast<Eigen::Index>(m), static_cast<Eigen::Index>(m));
            system.setFromTriplets(entries.begin(), entries.end());
            const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(system);
            ok = solver.info() == Eigen::Success;
            if (ok) x = solver.solve(rhs);
        }
        if (!ok || !solver_ok(x)) throw InvalidInput("the lobe's strokes leave a gap that cannot be closed around its centre");
        for (int r : members) {
            const Index i = static_cast<Index>(row_node[static_cast<Index>(r)]);
            const double radius = x[local[static_cast<Index>(r)]] + model_at(i);
            if (!(radius > 0.25 * lo)) throw InvalidInput("the lobe's strokes leave a gap too wide to close around its centre");
            nodes_[i].radius = radius;
        }
    }
}

bool Builder::fit_radius_model(const std::vector<char>& fit, const std::vector<char>& at, std::vector<double>& model) const
{
    // Monomials x^a y^b z^c of the direction, a + b + c ≤ 3: 20 functions spanning the
    // spherical harmonics up to degree 3 on the sphere.
    constexpr int kTerms = 20;
    struct Mono {
        int a, b, c;
    };
    static const std::array<Mono, kTerms> monos = [] {
        std::array<Mono, kTerms> m{};
        Index j = 0;
        for (int d = 0; d <= 3; ++d)
            for (int a = d; a >= 0; --a)
                for (int b = d - a; b >= 0; --b) m[j++] = {a, b, d - a - b};
        return m;
    }();
    using Row = Eigen::Matrix<double, 1, kTerms>;
    using Basis = Eigen::Matrix<double, Eigen::Dynamic, kTerms, Eigen::RowMajor>;
    // The monomials in the order of `monos`, written out (a loop over the table's exponents
    // cost a third of the fit); each is x^a·y^b·z^c multiplied in that order, as the table
    // reads, factors of 1 left out (exact).
    auto basis = [&](const glm::dvec3& u, auto&& out) {
        const double x = u.x, y = u.y, z = u.z;
        const double x2 = x * x, y2 = y * y, z2 = z * z;
        const double t[kTerms] = {1.0,    x,          y,      z,          x2,         x * y,  x * z,
                                  y2,     y * z,      z2,     x2 * x,     x2 * y,     x2 * z, x * y2,
                                  x * y * z, x * z2, y2 * y, y2 * z, y * z2, z2 * z};
        for (Index j = 0; j < static_cast<Index>(kTerms); ++j) out(static_cast<Eigen::Index>(j)) = t[j];
    };
    // The basis at every sample (stroke, crossing and segment vertices in the surface), and
    // the normal equations summed stroke by stroke (a crossing counts with its first stroke),
    // each stroke's part one matrix product over its rows in node order. A stroke whose rows
    // are the previous build's, bit for bit, takes its part from the memo: the sum is the same.
    Index samples = 0;
    const Index stroke_count = strokes_.size();
    std::vector<std::vector<Index>> rows_of(stroke_count);
    for (Index i = 0; i < nodes_.size(); ++i) {
        if (!fit[i]) continue;
        ++samples;
        rows_of[static_cast<Index>(std::clamp(nodes_[i].origin.stroke, 0, static_cast<int>(stroke_count) - 1))].push_back(i);
    }
    if (samples < static_cast<Index>(kTerms)) return false;
    // Only the lower triangle of the normal matrix is formed: all the LDLT below reads.
    Eigen::Matrix<double, kTerms, kTerms> ata = Eigen::Matrix<double, kTerms, kTerms>::Zero();
    Eigen::Matrix<double, kTerms, 1> atb = Eigen::Matrix<double, kTerms, 1>::Zero();
    memo_->fit.assign(stroke_count, {});
    for (Index s = 0; s < stroke_count; ++s) {
        LobeBuildMemo::FitPart& part = memo_->fit[s];
        const auto& rows = rows_of[s];
        part.key.reserve(4 * rows.size());
        for (Index i : rows) part.key.insert(part.key.end(), {nodes_[i].dir.x, nodes_[i].dir.y, nodes_[i].dir.z, nodes_[i].radius});
        const LobeBuildMemo::FitPart* was =
            old_memo_ && s < old_memo_->fit.size() ? &old_memo_->fit[s] : nullptr;
        if (was && was->key.size() == part.key.size() &&
            std::memcmp(was->key.data(), part.key.data(), part.key.size() * sizeof(double)) == 0) {
            part.ata = was->ata;
            part.atb = was->atb;
        } else if (!rows.empty()) {
            Basis phi(static_cast<Eigen::Index>(rows.size()), kTerms);
            Eigen::VectorXd radius(static_cast<Eigen::Index>(rows.size()));
            Eigen::Index row = 0;
            for (Index i : rows) {
                basis(nodes_[i].dir, phi.row(row));
                radius[row++] = nodes_[i].radius;
            }
            part.ata.selfadjointView<Eigen::Lower>().rankUpdate(phi.transpose());
            part.atb = phi.transpose() * radius;
        }
        ata += part.ata;
        atb += part.atb;
    }
    // Penalty growing with degree (d(d+1))², scaled to the number of samples.
    for (Index j = 0; j < static_cast<Index>(kTerms); ++j) {
        const int d = monos[j].a + monos[j].b + monos[j].c;
        const double w = d == 0 ? 1e-6 : 1e-3 * static_cast<double>(d * (d + 1)) * static_cast<double>(d * (d + 1));
        ata(static_cast<Eigen::Index>(j), static_cast<Eigen::Index>(j)) += w * static_cast<double>(samples);
    }
    const Eigen::Matrix<double, kTerms, 1> coef = ata.ldlt().solve(atb);
    if (!coef.allFinite()) return false;
    Row row;
    for (Index i = 0; i < nodes_.size(); ++i) {
        if (!at[i]) continue;
        basis(nodes_[i].dir, row);
        model[i] = row.dot(coef.transpose());
    }
    return true;
}

void Builder::emit(LobeSurface& out, SurfaceRegions* regions_out)
{
    // CGAL vertices without a node (residual crossings it split itself) become fill nodes.
    for (auto v = cdt_.finite_vertices_begin(); v != cdt_.finite_vertices_end(); ++v) {
        if (v->info().id >= 0) continue;
        Node n;
        n.dir = glm::normalize(stereo_.to_sphere({v->point().x(), v->point().y()}));
        v->info().id = add_node(n);
        node_vertex_.push_back(v);
    }
    auto node_of = [&](VH v) { return v->info().id; };
    auto position = [&](int id) {
        const Node& n = nodes_[static_cast<Index>(id)];
        return centre_ + n.radius * n.dir;
    };
    auto valid = [&](const std::array<int, 3>& t) {
        const glm::dvec3 p0 = position(t[0]), p1 = position(t[1]), p2 = position(t[2]);
        return orient3(nodes_[static_cast<Index>(t[0])].dir, nodes_[static_cast<Index>(t[1])].dir,
                       nodes_[static_cast<Index>(t[2])].dir) > 0.0 &&
               glm::dot(glm::cross(p1 - p0, p2 - p0), (p0 + p1 + p2) / 3.0 - centre_) > 0.0;
    };
    // The paper's strips for the regions between two uncrossed loops; a strip that would
    // fold seen from the centre leaves its region to the Delaunay triangles.
    std::vector<std::array<int, 3>> tris; // node ids, outward
    // Per triangle: its region of the triangulation, and which of its sides (side k: corner k
    // to corner k + 1) are stroke edges, so that the output's regions need not be found again.
    std::vector<int> tri_region;
    std::vector<std::uint8_t> tri_mask;
    tris.reserve(cdt_.number_of_faces() + 8);
    tri_region.reserve(cdt_.number_of_faces() + 8);
    tri_mask.reserve(cdt_.number_of_faces() + 8);
    for (Index r = 0; r < paper_region_.size(); ++r) {
        if (!paper_region_[r]) continue;
        const auto [a, b] = region_strokes_[r];
        std::vector<std::array<int, 3>> region;
        try {
            auto chain_points = [&](int stroke) {
                std::vector<glm::vec3> pts;
                for (int id : chains_[static_cast<Index>(stroke)]) pts.emplace_back(position(id));
                return pts;
            };
            const StrokeStrip strip = stitch_closed_closed(chain_points(a), chain_points(b));
            for (const auto& t : strip.triangles) {
                std::array<int, 3> ids{};
                for (int k = 0; k < 3; ++k) {
                    const StripVertexSource src = strip.sources[static_cast<Index>(t[static_cast<Index>(k)])];
                    const int s = src.stroke == 0 ? a : b;
                    ids[static_cast<Index>(k)] = chains_[static_cast<Index>(s)][static_cast<Index>(src.sample)];
                }
                region.push_back(ids);
            }
        } catch (const InvalidInput&) {
            region.clear();
        }
        if (!region.empty() && !valid(region.front()))
            for (auto& u : region) std::swap(u[1], u[2]);
        const bool ok = !region.empty() && std::all_of(region.begin(), region.end(), valid);
        if (!ok) {
            paper_region_[r] = 0;
            continue;
        }
        out.paper_strip_triangles += region.size();
        tris.insert(tris.end(), region.begin(), region.end());
        for (const auto& t : region) {
            // A strip's stroke edges are its chains' edges: constrained edges of the triangulation.
            std::uint8_t mask = 0;
            for (int k = 0; k < 3; ++k) {
                const VH x = node_vertex_[static_cast<Index>(t[static_cast<Index>(k)])];
                const VH y = node_vertex_[static_cast<Index>(t[static_cast<Index>((k + 1) % 3)])];
                FH f;
                int i = 0;
                if (x != y && cdt_.is_edge(x, y, f, i) && cdt_.is_constrained(CDT::Edge(f, i)))
                    mask = static_cast<std::uint8_t>(mask | (1u << k));
            }
            tri_region.push_back(static_cast<int>(r));
            tri_mask.push_back(mask);
        }
    }
    const std::size_t strip_count = tris.size();
    if (partial_)
        // Every stroke edge triangulated lies in or around the changed regions: one that lies
        // in a kept region means the new strokes ran into a region taken for unchanged.
        for (const auto& [u, v] : inserted_) {
            const VH a = node_vertex_[static_cast<Index>(u)], b = node_vertex_[static_cast<Index>(v)];
            FH f;
            int i = 0;
            if (a == b) continue;
            if (!cdt_.is_edge(a, b, f, i)) throw PartialFailed{};
            const FH g = f->neighbor(i);
            if (!region_inside_[static_cast<Index>(f->info().region)] &&
                (cdt_.is_infinite(g) || !region_inside_[static_cast<Index>(g->info().region)]))
                throw PartialFailed{};
        }
    for (FH f : cdt_.finite_face_handles()) {
        if (paper_region_[static_cast<Index>(f->info().region)] || !region_inside_[static_cast<Index>(f->info().region)])
            continue;
        // Planar counter-clockwise is clockwise seen from outside the sphere.
        tris.push_back({node_of(f->vertex(0)), node_of(f->vertex(2)), node_of(f->vertex(1))});
        // Sides v0 v2, v2 v1, v1 v0: the edges opposite v1, v0 and v2.
        tri_region.push_back(f->info().region);
        tri_mask.push_back(static_cast<std::uint8_t>((cdt_.is_constrained(CDT::Edge(f, 1)) ? 1u : 0u) |
                                                     (cdt_.is_constrained(CDT::Edge(f, 0)) ? 2u : 0u) |
                                                     (cdt_.is_constrained(CDT::Edge(f, 2)) ? 4u : 0u)));
    }
    // The pole fans the ring (the triangulation's outer boundary).
    for (FH f : cdt_.all_face_handles()) {
        if (!cdt_.is_infinite(f)) continue;
        const int i = f->index(cdt_.infinite_vertex());
        if (!region_inside_[static_cast<Index>(f->neighbor(i)->info().region)]) continue;
        std::array<int, 3> t{pole_node_, node_of(f->vertex((i + 1) % 3)), node_of(f->vertex((i + 2) % 3))};
        if (orient3(nodes_[static_cast<Index>(t[0])].dir, nodes_[static_cast<Index>(t[1])].dir,
                    nodes_[static_cast<Index>(t[2])].dir) < 0)
            std::swap(t[1], t[2]);
        tris.push_back(t);
        tri_region.push_back(f->neighbor(i)->info().region);
        tri_mask.push_back(0); // the pole and the ring: no stroke edges
    }
    // Canonical order: the stroke nodes keep theirs (it follows the strokes alone), the
    // interpolated nodes are sorted by direction, and below the triangles are sorted too, so
    // the output depends on the strokes alone and not on the order the triangulation made
    // things in (its faces, and the refinement's insertions that follow them).
    std::vector<int> new_id(nodes_.size());
    {
        std::vector<int> order;
        order.reserve(nodes_.size());
        std::vector<std::tuple<double, double, double, int>> fill; // (direction, id): ties keep id order
        for (Index i = 0; i < nodes_.size(); ++i) {
            const Node& n = nodes_[i];
            if (n.origin.kind != LobeVertexKind::Fill) order.push_back(static_cast<int>(i));
            else fill.emplace_back(n.dir.x, n.dir.y, n.dir.z, static_cast<int>(i));
        }
        std::sort(fill.begin(), fill.end());
        for (const auto& f : fill) order.push_back(std::get<3>(f));
        std::vector<Node> sorted;
        sorted.reserve(nodes_.size());
        for (Index k = 0; k < order.size(); ++k) {
            new_id[static_cast<Index>(order[k])] = static_cast<int>(k);
            sorted.push_back(nodes_[static_cast<Index>(order[k])]);
        }
        nodes_ = std::move(sorted);
        for (auto& t : tris)
            for (int& id : t) id = new_id[static_cast<Index>(id)];
    }
    std::vector<char> on_chain(nodes_.size(), 0);
    for (const auto& chain : chains_)
        for (int id : chain) on_chain[static_cast<Index>(new_id[static_cast<Index>(id)])] = 1;
    solve_fill_radii(tris, on_chain);

    // Output: only nodes used by triangles; a build of the changed regions has every stroke
    // node (the kept regions use them). The stroke nodes come first in node order (samples
    // first, by stroke), then the interpolated ones by the direction of their rounded position
    // from the centre: the order complete_with_kept_regions gives its result, so that it merges
    // a build's vertices with the kept ones instead of sorting them all.
    std::vector<int> out_index(nodes_.size(), -1);
    for (const auto& t : tris)
        for (int id : t) out_index[static_cast<Index>(id)] = 0;
    if (partial_)
        for (Index i = 0; i < nodes_.size(); ++i)
            if (on_chain[i]) out_index[i] = 0;
    std::vector<FillOrderKey> fill_out;
    for (Index i = 0; i < nodes_.size(); ++i) {
        if (out_index[i] < 0) continue;
        const Node& n = nodes_[i];
        const glm::vec3 p(n.origin.kind == LobeVertexKind::Sample
                              ? glm::dvec3(strokes_[static_cast<Index>(n.origin.stroke)]
                                               .points[static_cast<Index>(n.origin.sample)])
                              : centre_ + n.radius * n.dir);
        if (n.origin.kind == LobeVertexKind::Fill) {
            fill_out.push_back(fill_order_key(p, centre_, static_cast<int>(i)));
            continue;
        }
        out_index[i] = static_cast<int>(out.mesh.positions.size());
        out.mesh.positions.push_back(p);
        out.origins.push_back(n.origin);
    }
    // The nodes are in order of their directions already, which rounding swaps only here and
    // there: an insertion sort, handing over to a full sort should it move much.
    {
        std::size_t moves = 0;
        for (Index k = 1; k < fill_out.size() && moves <= 4 * fill_out.size(); ++k)
            for (Index j = k; j > 0 && fill_out[j] < fill_out[j - 1]; --j, ++moves) std::swap(fill_out[j], fill_out[j - 1]);
        if (moves > 4 * fill_out.size()) std::sort(fill_out.begin(), fill_out.end());
    }
    for (const auto& [dx, dy, dz, px, py, pz, i] : fill_out) {
        out_index[static_cast<Index>(i)] = static_cast<int>(out.mesh.positions.size());
        out.mesh.positions.emplace_back(px, py, pz);
        out.origins.push_back(nodes_[static_cast<Index>(i)].origin);
    }
    for (const auto& t : tris) {
        const glm::dvec3 d0 = nodes_[static_cast<Index>(t[0])].dir, d1 = nodes_[static_cast<Index>(t[1])].dir,
                         d2 = nodes_[static_cast<Index>(t[2])].dir;
        const std::array<int, 3> o{out_index[static_cast<Index>(t[0])], out_index[static_cast<Index>(t[1])],
                                   out_index[static_cast<Index>(t[2])]};
        const glm::dvec3 p0(out.mesh.positions[static_cast<Index>(o[0])]);
        const glm::dvec3 p1(out.mesh.positions[static_cast<Index>(o[1])]);
        const glm::dvec3 p2(out.mesh.positions[static_cast<Index>(o[2])]);
        const glm::dvec3 normal = glm::cross(p1 - p0, p2 - p0);
        const glm::dvec3 mid = (p0 + p1 + p2) / 3.0 - centre_;
        if (!(orient3(d0, d1, d2) > 0.0) || !(glm::dot(normal, mid) > 0.0))
            throw InvalidInput("the lobe's strokes fold over each other as seen from its centre (draw around the lobe)");
        // Each triangle starts at its lowest index (same orientation), its sides' flags turned with it.
        const Index first = static_cast<Index>(std::min_element(o.begin(), o.end()) - o.begin());
        out.mesh.triangles.push_back({o[first], o[(first + 1) % 3], o[(first + 2) % 3]});
        const unsigned m = tri_mask[static_cast<Index>(&t - tris.data())];
        tri_mask[static_cast<Index>(&t - tris.data())] =
            static_cast<std::uint8_t>(((m >> first) | (m << (3 - first))) & 7u);
    }
    // Sorted: bucketed by first (lowest) index, each bucket (a vertex's few triangles) sorted;
    // the paper strips' triangles (the first strip_count) flagged.
    {
        auto& tris_out = out.mesh.triangles;
        std::vector<int> start(out.mesh.positions.size() + 1, 0);
        for (const auto& t : tris_out) ++start[static_cast<Index>(t[0]) + 1];
        for (Index i = 1; i < start.size(); ++i) start[i] += start[i - 1];
        struct Sorted {
            std::array<int, 3> t;
            std::uint8_t strip, mask;
            int region;
        };
        std::vector<Sorted> sorted(tris_out.size());
        std::vector<int> next(start.begin(), start.end() - 1);
        for (Index k = 0; k < tris_out.size(); ++k)
            sorted[static_cast<Index>(next[static_cast<Index>(tris_out[k][0])]++)] = {
                tris_out[k], static_cast<std::uint8_t>(k < strip_count ? 1 : 0), tri_mask[k], tri_region[k]};
        for (Index i = 0; i + 1 < start.size(); ++i)
            std::sort(sorted.begin() + start[i], sorted.begin() + start[i + 1],
                      [](const Sorted& x, const Sorted& y) { return x.t < y.t; });
        out.paper_strip_faces.resize(sorted.size());
        for (Index k = 0; k < sorted.size(); ++k) {
            tris_out[k] = sorted[k].t;
            out.paper_strip_faces[k] = sorted[k].strip;
        }
        if (regions_out) {
            // As surface_regions finds them: numbered by their first triangle, each with its
            // stroke edges directed as its triangles run round them, sorted.
            std::vector<int> number(static_cast<Index>(region_count_), -1);
            MeshRegions& mr = regions_out->regions;
            mr = MeshRegions{};
            mr.face_region.reserve(sorted.size());
            auto& keys = regions_out->edges;
            keys.clear();
            for (const Sorted& x : sorted) {
                int& n = number[static_cast<Index>(x.region)];
                if (n < 0) {
                    n = mr.count++;
                    keys.emplace_back();
                }
                mr.face_region.push_back(n);
                for (Index k = 0; k < 3; ++k) {
                    if (!(x.mask & (1u << k))) continue;
                    const glm::vec3& p = out.mesh.positions[static_cast<Index>(x.t[k])];
                    const glm::vec3& q = out.mesh.positions[static_cast<Index>(x.t[(k + 1) % 3])];
                    keys[static_cast<Index>(n)].push_back({p.x, p.y, p.z, q.x, q.y, q.z});
                }
            }
            for (auto& k : keys) std::sort(k.begin(), k.end());
        }
    }
    // Stroke segments (split at crossings) are the constraints of remeshing.
    auto out_of = [&](VH v) { return out_index[static_cast<Index>(new_id[static_cast<Index>(node_of(v))])]; };
    for (const auto& e : cdt_.constrained_edges()) {
        const int a = out_of(e.first->vertex(CDT::ccw(e.second)));
        const int b = out_of(e.first->vertex(CDT::cw(e.second)));
        if (a >= 0 && b >= 0 && a != b) out.mesh.feature_edges.push_back({std::min(a, b), std::max(a, b)});
    }
    std::sort(out.mesh.feature_edges.begin(), out.mesh.feature_edges.end());
    std::vector<int> crossing_nodes;
    for (const Crossing& c : crossings_) crossing_nodes.push_back(c.node);
    std::sort(crossing_nodes.begin(), crossing_nodes.end());
    out.crossings = static_cast<std::size_t>(std::unique(crossing_nodes.begin(), crossing_nodes.end()) - crossing_nodes.begin());
}

LobeSurface Builder::run(SurfaceRegions* regions)
{
    if (strokes_.empty()) throw InvalidInput("a lobe needs at least one stroke");
    std::size_t total = 0;
    for (Index s = 0; s < strokes_.size(); ++s) {
        if (strokes_[s].points.size() < 4)
            throw InvalidInput(stroke_name(static_cast<int>(s)) + " has fewer than 4 samples");
        total += strokes_[s].points.size();
        for (const glm::vec3& p : strokes_[s].points)
            if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z) ||
                std::abs(p.x) > StrokeLimits::max_coordinate_m || std::abs(p.y) > StrokeLimits::max_coordinate_m ||
                std::abs(p.z) > StrokeLimits::max_coordinate_m)
                throw InvalidInput(stroke_name(static_cast<int>(s)) + " has a coordinate that is not finite or beyond 1 km");
    }
    if (total > 200000) throw InvalidInput("a lobe's strokes have more than 200,000 samples");
    if (!std::isfinite(centre_.x) || !std::isfinite(centre_.y) || !std::isfinite(centre_.z))
        throw InvalidInput("the lobe's centre is not finite");
    make_directions();
    old_memo_ = usable_memo();
    memo_->centre = centre_;
    memo_->points.resize(strokes_.size());
    for (Index s = 0; s < strokes_.size(); ++s) memo_->points[s] = strokes_[s].points;
    memo_->closed.resize(strokes_.size());
    for (Index s = 0; s < strokes_.size(); ++s) memo_->closed[s] = strokes_[s].closed ? 1 : 0;
    choose_pole();
    find_crossings();
    build_chains();
    if (previous_ && changed_only_) plan_partial();
    LobeSurface out;
    out.memo = memo_;
    out.centre = centre_;
    out.reference_radius = options_.reference_radius_m > 0 ? options_.reference_radius_m : mean_radius_;
    try {
        triangulate();
        refine();
        emit(out, regions);
    } catch (const CGAL::Failure_exception& e) {
        throw InvalidInput(std::string("the lobe's strokes could not be triangulated: ") + e.message());
    }
    return out;
}

} // namespace

glm::dvec3 lobe_stroke_centroid(const std::vector<LobeStrokeSamples>& strokes)
{
    bool any_closed = false;
    for (const auto& s : strokes) any_closed = any_closed || s.closed;
    glm::dvec3 sum(0.0);
    double weight = 0;
    for (const auto& s : strokes) {
        if (any_closed && !s.closed) continue;
        const auto pts = to_double(s.points);
        const double len = polyline_length(pts, s.closed);
        sum += len * polyline_barycentre(pts, s.closed);
        weight += len;
    }
    if (weight > 0) return sum / weight;
    glm::dvec3 mean(0.0);
    std::size_t n = 0;
    for (const auto& s : strokes)
        for (const glm::vec3& p : s.points) {
            mean += glm::dvec3(p);
            ++n;
        }
    return n ? mean / static_cast<double>(n) : mean;
}

namespace {

/// Whether a surface has no hole. Every triangle of a build faces away from the centre, but
/// strokes that run over themselves (a loop whose ends met after it folded back, so that it
/// encloses nothing) give the triangulation regions without area, and the surface an open
/// border there. Each edge a → b adds ±hash(min, max) (+ when a < b), so a closed surface,
/// where every edge is run once each way, sums to zero; an open border edge leaves its hash
/// (a sum of such hashes is zero with a chance of 2⁻⁶⁴). One pass over the triangles, far
/// cheaper than matching the edges up.
bool closed_surface(const TriangleMesh& mesh)
{
    std::uint64_t sum = 0;
    for (const auto& t : mesh.triangles)
        for (std::size_t k = 0; k < 3; ++k) {
            const auto a = static_cast<std::uint32_t>(t[k]), b = static_cast<std::uint32_t>(t[(k + 1) % 3]);
            // A 64-bit mix of the undirected edge (two multiplications: nonlinear enough that
            // the hashes of an open border do not cancel but by chance), negated when a > b.
            std::uint64_t h = (std::uint64_t{std::min(a, b)} << 32 | std::max(a, b)) * 0x9E3779B97F4A7C15ull;
            h = (h ^ (h >> 29)) * 0xBF58476D1CE4E5B9ull;
            h ^= h >> 32;
            const std::uint64_t negate = std::uint64_t{0} - static_cast<std::uint64_t>(a > b);
            sum += (h ^ negate) - negate;
        }
    return sum == 0 && !mesh.triangles.empty();
}

void require_closed(const TriangleMesh& mesh)
{
    if (!closed_surface(mesh))
        throw InvalidInput("the lobe's strokes leave its surface open (a stroke folds back or runs over itself)");
}

} // namespace

LobeSurface build_lobe_surface(const std::vector<LobeStrokeSamples>& strokes, const glm::dvec3& centre,
                               const LobeSurfaceOptions& options)
{
    Builder b(strokes, centre, options);
    LobeSurface surface = b.run();
    require_closed(surface.mesh);
    return surface;
}

LobeSurface continue_lobe_surface(const LobeSurface& previous, const SurfaceRegions& previous_regions,
                                  const std::vector<LobeStrokeSamples>& strokes, const glm::dvec3& centre,
                                  const LobeSurfaceOptions& options, SurfaceRegions& regions, KeptRegions& kept)
{
    // The builder hands on the regions of what it built, so they are not found again.
    try {
        Builder b(strokes, centre, options);
        b.set_previous(previous, previous_regions);
        SurfaceRegions built;
        LobeSurface surface = b.run(&built);
        if (!b.partial()) {
            regions = std::move(built);
            kept = keep_unchanged_regions(previous, previous_regions, surface, regions, true);
            kept.followed_previous_build = b.followed_previous();
            require_closed(surface.mesh);
            return surface;
        }
        // An open result of the changed regions falls back to the whole build, which refuses it
        // if it is open too.
        if (complete_with_kept_regions(previous, previous_regions, b.kept_previous_regions(), surface, built, kept, true) &&
            closed_surface(surface.mesh)) {
            regions = std::move(built);
            kept.built_changed_only = true;
            kept.followed_previous_build = b.followed_previous();
            return surface;
        }
    } catch (const PartialFailed&) {
    }
    Builder b(strokes, centre, options);
    b.set_previous(previous, previous_regions, false);
    LobeSurface surface = b.run(&regions);
    kept = keep_unchanged_regions(previous, previous_regions, surface, regions, true);
    kept.followed_previous_build = b.followed_previous();
    require_closed(surface.mesh);
    return surface;
}

} // namespace lobe
