// Isotropic remeshing: CGAL's isotropic_remeshing running directly on an OpenMesh TriMesh
// through CGAL's OpenMesh adapters (DESIGN.md), behind the plain interface of remesh.h.
#include "meshing/remesh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <string>
#include <tuple>
#include <unordered_map>
#include <vector>

#include "meshing/cgal_prelude.h"
LOBE_CGAL_HEADERS_BEGIN
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <CGAL/boost/graph/graph_traits_TriMesh_ArrayKernelT.h>
#include <CGAL/boost/graph/properties_TriMesh_ArrayKernelT.h>
#include <CGAL/Polygon_mesh_processing/remesh.h>
LOBE_CGAL_HEADERS_END

#include <glm/geometric.hpp>

#include "core/errors.h"
#include "meshing/mesh_quality.h"
#include "meshing/triangle_distance.h"

namespace lobe {

namespace {

namespace PMP = cgal::PMP;

constexpr double kDegree = 3.14159265358979323846 / 180.0;

/// Double-precision points: CGAL's adapter converts them to Epick points without loss.
struct OmTraits : public OpenMesh::DefaultTraits {
    typedef OpenMesh::Vec3d Point;
    typedef OpenMesh::Vec3d Normal;
};
using OMesh = OpenMesh::TriMesh_ArrayKernelT<OmTraits>;
using EdgeDescriptor = boost::graph_traits<OMesh>::edge_descriptor;

/// CGAL 5.5's tangential relaxation as PMP::isotropic_remeshing runs it on this file's mesh
/// type, the same operations in the same order (so the meshes are the same bit for bit), but
/// for one case. Each move is undone step by step while two faces round the moved vertex,
/// compared in turn from the first face that is not exactly degenerate, face apart. Where
/// every face round the vertex is exactly degenerate there is no first face, and CGAL reads
/// the edge-constraint map at the null halfedge: index −1 of an OpenMesh property array
/// (found by fuzz/mesh_repair_fuzz.cpp on a thin wedge with integer coordinates; UBSan stops
/// there, a release build reads four bytes before the array). Here such a vertex does not
/// move, which is what CGAL's check decides unless those four bytes happen to read as
/// "constrained".
///
/// The remesher calls `tangential_relaxation(vertices(mesh), mesh, named parameters)`
/// unqualified; OmTraits, a template argument of OMesh, makes this namespace one that
/// argument-dependent lookup searches, and this overload, taking OMesh itself, is more
/// specialised than CGAL's template, so the remesher calls it. Test
/// `Remesh.CGALsRoundsRemeshASmallRepairedModelWhoseRelaxationMeetsOnlyDegenerateFaces` fails
/// under UBSan (the asan build) should it ever call CGAL's again (another CGAL version).
template <class VertexRange, class NamedParameters>
void tangential_relaxation(const VertexRange& range, OMesh& tm, const NamedParameters& np)
{
    using CGAL::parameters::choose_parameter;
    using CGAL::parameters::get_parameter;
    using GT = typename CGAL::GetGeomTraits<OMesh, NamedParameters>::type;
    using Vector = typename GT::Vector_3;
    using Point = typename GT::Point_3;
    using V = boost::graph_traits<OMesh>::vertex_descriptor;
    using H = boost::graph_traits<OMesh>::halfedge_descriptor;
    using E = boost::graph_traits<OMesh>::edge_descriptor;
    const GT gt = choose_parameter<GT>(get_parameter(np, CGAL::internal_np::geom_traits));
    const auto vpm = choose_parameter(get_parameter(np, CGAL::internal_np::vertex_point),
                                      CGAL::get_property_map(CGAL::vertex_point, tm));
    const auto ecm = choose_parameter(get_parameter(np, CGAL::internal_np::edge_is_constrained),
                                      CGAL::Static_boolean_property_map<E, false>());
    const auto vcm = choose_parameter(get_parameter(np, CGAL::internal_np::vertex_is_constrained),
                                      CGAL::Static_boolean_property_map<V, false>());
    const auto allowed = choose_parameter(get_parameter(np, CGAL::internal_np::allow_move_functor),
                                          PMP::internal::Allow_all_moves());
    const bool relax_constraints = choose_parameter(get_parameter(np, CGAL::internal_np::relax_constraints), false);
    const unsigned iterations = choose_parameter(get_parameter(np, CGAL::internal_np::number_of_iterations), 1);
    auto constrained = [&](H h) { return get(ecm, edge(h, tm)); };

    // No two faces round v, taken in turn across free edges (and the last with the first),
    // face apart; exactly degenerate faces are passed over.
    auto faces_agree = [&](V v) {
        bool any = false;
        Vector first = CGAL::NULL_VECTOR, previous = CGAL::NULL_VECTOR;
        H first_h = boost::graph_traits<OMesh>::null_halfedge();
        for (H h : CGAL::halfedges_around_target(v, tm)) {
            if (CGAL::is_border(h, tm)) continue;
            const Vector n = PMP::compute_face_normal(face(h, tm), tm, np);
            if (n == CGAL::NULL_VECTOR) continue;
            if (!any) {
                any = true;
                first = n;
                first_h = h;
            } else if (!constrained(h) && CGAL::to_double(n * previous) <= 0) {
                return false;
            }
            previous = n;
        }
        if (!any) return false; // every face degenerate: nothing tells the move is safe
        return constrained(first_h) || !(CGAL::to_double(first * previous) <= 0);
    };

    std::vector<H> inner, along;
    std::vector<std::tuple<V, Vector, Point>> targets; // vertex, its normal, where its neighbours pull it
    for (unsigned round = 0; round < iterations; ++round) {
        std::unordered_map<V, Vector> normals;
        PMP::compute_vertex_normals(tm, boost::make_assoc_property_map(normals), np);
        targets.clear();
        for (V v : range) {
            if (get(vcm, v) || CGAL::internal::is_isolated(v, tm)) continue;
            inner.clear();
            along.clear();
            for (H h : CGAL::halfedges_around_target(v, tm))
                (CGAL::is_border_edge(h, tm) || constrained(h) ? along : inner).push_back(h);
            const Point p = get(vpm, v);
            if (along.empty()) {
                // The mean of the neighbours, as the mean of the edge vectors from v.
                Vector sum = CGAL::NULL_VECTOR;
                unsigned count = 0;
                for (H h : inner) {
                    sum = sum + Vector(p, get(vpm, source(h, tm)));
                    ++count;
                }
                sum = (1. / static_cast<double>(count)) * sum;
                targets.emplace_back(v, normals.at(v), p + sum);
            } else if (relax_constraints && along.size() == 2) {
                // Along a constrained line, unless it turns by more than 60° there.
                const Point a = get(vpm, source(along[0], tm)), b = get(vpm, source(along[1], tm));
                const double dot = CGAL::to_double(Vector(p, a) * Vector(p, b));
                if (0.25 < dot * dot / (CGAL::squared_distance(a, p) * CGAL::squared_distance(b, p)))
                    targets.emplace_back(v, Vector(CGAL::NULL_VECTOR), gt.construct_barycenter_3_object()(a, 0.25, b, 0.25, p, 0.5));
            }
        }
        // Every target from the old places first (projected onto the vertex's tangent plane),
        // then the moves one after another, each halved up to five times while faces round the
        // vertex face apart, and undone after that.
        std::vector<std::pair<V, Point>> moves;
        moves.reserve(targets.size());
        for (const auto& [v, n, q] : targets) moves.emplace_back(v, q + (n * Vector(q, get(vpm, v))) * n);
        for (const auto& [v, to] : moves) {
            const Point from = get(vpm, v);
            const Vector step(from, to);
            put(vpm, v, to);
            double frac = 1.;
            while (frac > 0.03 && (!faces_agree(v) || !allowed(v, from, get(vpm, v)))) {
                frac = 0.5 * frac;
                put(vpm, v, from + frac * step);
            }
            if (frac <= 0.02) put(vpm, v, from);
        }
    }
}

/// CGAL's edge_is_constrained_map over an OpenMesh edge property. Edges that remeshing
/// creates get OpenMesh's default, false; CGAL marks sub-edges of constrained edges itself.
struct ConstrainedEdgeMap {
    using key_type = EdgeDescriptor;
    using value_type = bool;
    using reference = bool;
    using category = boost::read_write_property_map_tag;

    OMesh* mesh = nullptr;
    OpenMesh::EPropHandleT<bool> prop;

    friend bool get(const ConstrainedEdgeMap& m, const key_type& e)
    {
        return m.mesh->property(m.prop, OMesh::EdgeHandle(static_cast<int>(e.idx())));
    }
    friend void put(const ConstrainedEdgeMap& m, const key_type& e, bool value)
    {
        m.mesh->property(m.prop, OMesh::EdgeHandle(static_cast<int>(e.idx()))) = value;
    }
};

OMesh::Point om_point(const glm::vec3& p) { return OMesh::Point(p.x, p.y, p.z); }

/// Splits edge `e` (from a to b) at the point at fraction t, keeping per-edge "constrained"
/// on the two halves only and per-face "in region" on the faces each old face became.
void split_edge(OMesh& om, OMesh::EdgeHandle e, double t, OpenMesh::EPropHandleT<bool> constrained,
                OpenMesh::FPropHandleT<bool> in_region)
{
    const OMesh::HalfedgeHandle h0 = om.halfedge_handle(e, 0), h1 = om.halfedge_handle(e, 1);
    const OMesh::VertexHandle a = om.from_vertex_handle(h0), b = om.to_vertex_handle(h0);
    const bool was_constrained = om.property(constrained, e);
    // Opposite vertex and region flag of each incident face.
    std::array<OMesh::VertexHandle, 2> opp;
    std::array<bool, 2> flag{false, false};
    const std::array<OMesh::HalfedgeHandle, 2> hs{h0, h1};
    for (int k = 0; k < 2; ++k) {
        const auto ku = static_cast<std::size_t>(k);
        if (om.is_boundary(hs[ku])) continue;
        opp[ku] = om.to_vertex_handle(om.next_halfedge_handle(hs[ku]));
        flag[ku] = om.property(in_region, om.face_handle(hs[ku]));
    }
    const OMesh::Point p = om.point(a) * (1.0 - t) + om.point(b) * t;
    const OMesh::VertexHandle m = om.add_vertex(p);
    om.split(e, m);
    for (OMesh::VertexOHalfedgeIter it = om.voh_iter(m); it.is_valid(); ++it) {
        const OMesh::VertexHandle w = om.to_vertex_handle(*it);
        om.property(constrained, om.edge_handle(*it)) = (w == a || w == b) && was_constrained;
        const OMesh::FaceHandle f = om.face_handle(*it);
        if (!f.is_valid()) continue;
        bool has_opp0 = false;
        for (OMesh::FaceVertexIter fv = om.fv_iter(f); fv.is_valid(); ++fv)
            if (*fv == opp[0]) has_opp0 = true;
        om.property(in_region, f) = has_opp0 ? flag[0] : flag[1];
    }
}

/// The constrained edges of `om` (the input's strokes, split to at most 1.25 × target) in a
/// uniform grid of cells of about the target length, so that a stroke vertex that CGAL's 1-D
/// relaxation slid along (and so a little off) its stroke can be put back onto it.
class FeatureSegments {
public:
    FeatureSegments(const OMesh& om, OpenMesh::EPropHandleT<bool> constrained, double cell) : cell_(cell)
    {
        for (auto e : om.edges()) {
            if (!om.property(constrained, e)) continue;
            const OMesh::HalfedgeHandle h = om.halfedge_handle(e, 0);
            const glm::dvec3 a = to_glm(om.point(om.from_vertex_handle(h))), b = to_glm(om.point(om.to_vertex_handle(h)));
            const int id = static_cast<int>(segments_.size());
            segments_.push_back({a, b});
            const auto lo = cell_of(glm::min(a, b)), hi = cell_of(glm::max(a, b));
            for (long long x = lo[0]; x <= hi[0]; ++x)
                for (long long y = lo[1]; y <= hi[1]; ++y)
                    for (long long z = lo[2]; z <= hi[2]; ++z) grid_[key({x, y, z})].push_back(id);
        }
    }

    /// The nearest point of a segment that passes within `radius` of x (in the cells that the
    /// box of that radius around x overlaps); x itself when there is none.
    glm::dvec3 nearest(const glm::dvec3& x, double radius) const
    {
        const auto lo = cell_of(x - radius), hi = cell_of(x + radius);
        glm::dvec3 best = x;
        double best_d2 = std::numeric_limits<double>::infinity();
        for (long long cx = lo[0]; cx <= hi[0]; ++cx)
            for (long long cy = lo[1]; cy <= hi[1]; ++cy)
                for (long long cz = lo[2]; cz <= hi[2]; ++cz) {
                    const auto it = grid_.find(key({cx, cy, cz}));
                    if (it == grid_.end()) continue;
                    for (int id : it->second) {
                        const auto& [a, b] = segments_[static_cast<std::size_t>(id)];
                        const glm::dvec3 ab = b - a;
                        const double l2 = glm::dot(ab, ab);
                        const double t = l2 > 0.0 ? std::clamp(glm::dot(x - a, ab) / l2, 0.0, 1.0) : 0.0;
                        const glm::dvec3 q = a + t * ab;
                        const double d2 = glm::dot(q - x, q - x);
                        if (d2 < best_d2) {
                            best_d2 = d2;
                            best = q;
                        }
                    }
                }
        return best;
    }

    static glm::dvec3 to_glm(const OMesh::Point& p) { return {p[0], p[1], p[2]}; }

private:
    std::array<long long, 3> cell_of(const glm::dvec3& p) const
    {
        return {static_cast<long long>(std::floor(p.x / cell_)), static_cast<long long>(std::floor(p.y / cell_)),
                static_cast<long long>(std::floor(p.z / cell_))};
    }
    // Distinct cells may share a key: that only adds candidates, the distances decide.
    static long long key(const std::array<long long, 3>& c) { return (c[0] * 73856093LL) ^ (c[1] * 19349663LL) ^ (c[2] * 83492791LL); }

    double cell_;
    std::vector<std::pair<glm::dvec3, glm::dvec3>> segments_;
    std::unordered_map<long long, std::vector<int>> grid_;
};

/// Projection onto the input surface by a walk from a known triangle: the triangles that
/// come within the distance of the best point found so far, reached from the start through
/// shared corners. Near the surface that region is a disc, so the walk finds the nearest
/// point of it; a sheet elsewhere that comes as close is not searched, which is what a
/// projection for remeshing wants anyway. Every vertex keeps the triangle it was projected
/// to, and its next move is a fraction of the target length, so a walk visits a few
/// triangles. This replaces an AABB tree (CGAL's, with its k-d tree for hints), whose build
/// alone cost as much as every query of a remeshing.
class SurfaceProjector {
public:
    explicit SurfaceProjector(const TriangleMesh& surface, std::optional<glm::dvec3> centre = std::nullopt)
        : surface_(surface), centre_(centre), stamp_(surface.triangles.size(), 0)
    {
        offsets_.assign(surface.positions.size() + 1, 0);
        for (const auto& t : surface.triangles)
            for (int v : t) ++offsets_[static_cast<std::size_t>(v) + 1];
        for (std::size_t i = 1; i < offsets_.size(); ++i) offsets_[i] += offsets_[i - 1];
        triangles_of_.resize(static_cast<std::size_t>(offsets_.back()));
        std::vector<int> fill(offsets_.begin(), offsets_.end() - 1);
        for (std::size_t f = 0; f < surface.triangles.size(); ++f)
            for (int v : surface.triangles[f]) triangles_of_[static_cast<std::size_t>(fill[static_cast<std::size_t>(v)]++)] = static_cast<int>(f);
    }

    /// A triangle of the surface at input vertex v (v in range, and on a triangle).
    int triangle_at(int v) const { return triangles_of_[static_cast<std::size_t>(offsets_[static_cast<std::size_t>(v)])]; }

    /// The nearest point to x of the surface around triangle `start`; `start` becomes the
    /// triangle it lies on. Without a start (−1) every triangle is searched.
    glm::dvec3 project(const glm::dvec3& x, int& start)
    {
        glm::dvec3 best_point(0.0);
        double best = std::numeric_limits<double>::infinity();
        auto visit = [&](int f) {
            const glm::dvec3 q = closest(x, f);
            const double d = glm::dot(q - x, q - x);
            if (d < best) {
                best = d;
                best_point = q;
                start = f;
            }
            return d <= best;
        };
        if (start < 0) {
            for (std::size_t f = 0; f < surface_.triangles.size(); ++f) visit(static_cast<int>(f));
            return best_point;
        }
        if (++generation_ == 0) { // wrapped: forget every old mark
            std::fill(stamp_.begin(), stamp_.end(), 0u);
            generation_ = 1;
        }
        stack_.clear();
        stack_.push_back(start);
        stamp_[static_cast<std::size_t>(start)] = generation_;
        visit(start);
        while (!stack_.empty()) {
            const int f = stack_.back();
            stack_.pop_back();
            for (int v : surface_.triangles[static_cast<std::size_t>(f)])
                for (int k = offsets_[static_cast<std::size_t>(v)]; k < offsets_[static_cast<std::size_t>(v) + 1]; ++k) {
                    const int g = triangles_of_[static_cast<std::size_t>(k)];
                    if (stamp_[static_cast<std::size_t>(g)] == generation_) continue;
                    stamp_[static_cast<std::size_t>(g)] = generation_;
                    if (visit(g)) stack_.push_back(g);
                }
        }
        return best_point;
    }

    /// Where a free vertex at x goes: with a centre (RemeshOptions::radial_centre), the
    /// point on the ray from the centre through x at the distance interpolated across the
    /// triangle the ray passes through, looked for among the triangles round the nearest one
    /// (a vertex moves a fraction of the target length, its nearest triangle is the ray's or
    /// one beside it); without a centre, or where no triangle nearby holds the ray (at the
    /// input's border), the nearest point. `start` becomes the triangle used.
    glm::dvec3 place(const glm::dvec3& x, int& start)
    {
        const glm::dvec3 nearest = project(x, start);
        if (!centre_ || start < 0) return nearest;
        const glm::dvec3 d = x - *centre_;
        if (!(glm::dot(d, d) > 0.0)) return nearest;
        // The nearest triangle, then those sharing a corner with it, then with those.
        if (++generation_ == 0) {
            std::fill(stamp_.begin(), stamp_.end(), 0u);
            generation_ = 1;
        }
        ring_.clear();
        ring_.push_back(start);
        stamp_[static_cast<std::size_t>(start)] = generation_;
        for (std::size_t i = 0; i < ring_.size() && i < kRadialSearch; ++i) {
            const int f = ring_[i];
            glm::dvec3 at;
            if (radial_point(d, f, at)) {
                start = f;
                return at;
            }
            for (int v : surface_.triangles[static_cast<std::size_t>(f)])
                for (int k = offsets_[static_cast<std::size_t>(v)]; k < offsets_[static_cast<std::size_t>(v) + 1]; ++k) {
                    const int g = triangles_of_[static_cast<std::size_t>(k)];
                    if (stamp_[static_cast<std::size_t>(g)] == generation_) continue;
                    stamp_[static_cast<std::size_t>(g)] = generation_;
                    ring_.push_back(g);
                }
        }
        return nearest;
    }

private:
    /// Triangles looked at for the ray before the nearest point is taken instead.
    static constexpr std::size_t kRadialSearch = 64;

    /// Whether the ray from the centre along d passes through triangle f (corners A, B, C
    /// from the centre: d = αA + βB + γC with α, β, γ ≥ 0, by Cramer's rule); then `at` is the
    /// point on it at the distance interpolated with the weights where it meets the triangle.
    bool radial_point(const glm::dvec3& d, int f, glm::dvec3& at) const
    {
        const auto& t = surface_.triangles[static_cast<std::size_t>(f)];
        const glm::dvec3 a = glm::dvec3(surface_.positions[static_cast<std::size_t>(t[0])]) - *centre_;
        const glm::dvec3 b = glm::dvec3(surface_.positions[static_cast<std::size_t>(t[1])]) - *centre_;
        const glm::dvec3 c = glm::dvec3(surface_.positions[static_cast<std::size_t>(t[2])]) - *centre_;
        const glm::dvec3 bc = glm::cross(b, c);
        if (!(glm::dot(a, bc) > 0.0)) return false; // degenerate, or facing the centre
        const double alpha = glm::dot(bc, d), beta = glm::dot(glm::cross(c, a), d), gamma = glm::dot(glm::cross(a, b), d);
        if (alpha < 0.0 || beta < 0.0 || gamma < 0.0) return false;
        const double sum = alpha + beta + gamma;
        if (!(sum > 0.0)) return false;
        const double r = (alpha * glm::length(a) + beta * glm::length(b) + gamma * glm::length(c)) / sum;
        at = *centre_ + d * (r / glm::length(d));
        return true;
    }

    glm::dvec3 closest(const glm::dvec3& x, int f) const
    {
        const auto& t = surface_.triangles[static_cast<std::size_t>(f)];
        auto at = [&](int v) { return glm::dvec3(surface_.positions[static_cast<std::size_t>(v)]); };
        return closest_point_on_triangle(x, at(t[0]), at(t[1]), at(t[2]));
    }

    const TriangleMesh& surface_;
    std::optional<glm::dvec3> centre_;
    std::vector<int> offsets_, triangles_of_; ///< triangles around each vertex
    std::vector<unsigned> stamp_;
    unsigned generation_ = 0;
    std::vector<int> stack_, ring_;
};

/// The smallest angle of the triangle (a, b, c), radians.
double smallest_angle(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c)
{
    auto angle = [](const glm::dvec3& p, const glm::dvec3& q, const glm::dvec3& r) {
        const glm::dvec3 u = q - p, w = r - p;
        return std::atan2(glm::length(glm::cross(u, w)), glm::dot(u, w));
    };
    return std::min({angle(a, b, c), angle(b, c, a), angle(c, a, b)});
}

/// Local repairs of the angles CGAL's rounds leave under 30°, in a closed mesh whose
/// constrained edges are strokes. CGAL only collapses an edge shorter than 4/5 of the target
/// when no edge longer than 4/3 of it results, and it flips for valence, not for angles. So a
/// cell of the stroke network about one target across (stacked loops one target apart,
/// crossed by other loops) keeps a free vertex a centimetre from one of its corners, with
/// two thin triangles beside it, and long diagonals stay where the other one is better.
/// Two passes, each taken only where it raises the smallest angle of the triangles it
/// changes by at least a degree:
/// - a free vertex with a triangle under 30° collapses into the neighbour that gives its fan
///   the best smallest angle (edges up to 1.6 × target; every new triangle within 30° of the
///   one it replaces, so nothing folds);
/// - a free edge is flipped where its two triangles are within 20° of coplanar.
/// Stroke vertices never move and stroke edges stay; a removed vertex lay on the input
/// surface, and the triangles that replace it span at most 1.6 × target.
void improve_small_angles(OMesh& om, OpenMesh::EPropHandleT<bool> constrained, double target)
{
    const double poor = 30.0 * kDegree, gain = 1.0 * kDegree, longest2 = 1.6 * 1.6 * target * target;
    const double fold_cos = std::cos(30.0 * kDegree), flat_cos = std::cos(20.0 * kDegree);
    auto at = [&](OMesh::VertexHandle v) { return FeatureSegments::to_glm(om.point(v)); };
    auto unit_normal = [](const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
        const glm::dvec3 n = glm::cross(b - a, c - a);
        const double l = glm::length(n);
        return l > 0.0 ? n / l : glm::dvec3(0.0);
    };
    auto on_stroke = [&](OMesh::VertexHandle v) {
        for (OMesh::VertexOHalfedgeIter h = om.voh_iter(v); h.is_valid(); ++h)
            if (om.property(constrained, om.edge_handle(*h))) return true;
        return false;
    };
    auto face_points = [&](OMesh::FaceHandle f) {
        std::array<OMesh::VertexHandle, 3> t;
        int k = 0;
        for (OMesh::FaceVertexIter fv = om.fv_iter(f); fv.is_valid() && k < 3; ++fv) t[static_cast<std::size_t>(k++)] = *fv;
        return t;
    };
    // Which faces have an angle under 30° (by cosines: no trigonometry for the many good ones).
    const double poor_cos = std::cos(poor);
    std::vector<char> poor_face;
    auto mark_poor_faces = [&] {
        poor_face.assign(om.n_faces(), 0);
        for (auto f : om.faces()) {
            const auto t = face_points(f);
            const glm::dvec3 p[3] = {at(t[0]), at(t[1]), at(t[2])};
            for (int k = 0; k < 3; ++k) {
                const glm::dvec3 u = p[(k + 1) % 3] - p[k], w = p[(k + 2) % 3] - p[k];
                if (glm::dot(u, w) > poor_cos * glm::length(u) * glm::length(w))
                    poor_face[static_cast<std::size_t>(f.idx())] = 1;
            }
        }
    };
    auto is_poor = [&](OMesh::FaceHandle f) { return f.is_valid() && poor_face[static_cast<std::size_t>(f.idx())] != 0; };
    for (int pass = 0; pass < 3; ++pass) {
        bool changed = false;
        mark_poor_faces();
        for (auto v : om.vertices()) {
            if (om.status(v).deleted() || om.is_boundary(v) || on_stroke(v)) continue;
            bool any_poor = false;
            for (OMesh::VertexFaceIter f = om.vf_iter(v); f.is_valid(); ++f) any_poor = any_poor || is_poor(*f);
            if (!any_poor) continue;
            double old_min = std::numeric_limits<double>::infinity();
            for (OMesh::VertexFaceIter f = om.vf_iter(v); f.is_valid(); ++f) {
                const auto t = face_points(*f);
                old_min = std::min(old_min, smallest_angle(at(t[0]), at(t[1]), at(t[2])));
            }
            if (old_min >= poor) continue;
            OMesh::HalfedgeHandle best;
            double best_min = old_min + gain;
            for (OMesh::VertexOHalfedgeIter h = om.voh_iter(v); h.is_valid(); ++h) {
                const OMesh::VertexHandle u = om.to_vertex_handle(*h);
                if (!om.is_collapse_ok(*h)) continue;
                double new_min = std::numeric_limits<double>::infinity();
                bool ok = true;
                for (OMesh::VertexFaceIter f = om.vf_iter(v); ok && f.is_valid(); ++f) {
                    auto t = face_points(*f);
                    if (t[0] == u || t[1] == u || t[2] == u) continue;
                    const glm::dvec3 before = unit_normal(at(t[0]), at(t[1]), at(t[2]));
                    for (auto& x : t)
                        if (x == v) x = u;
                    const glm::dvec3 a = at(t[0]), b = at(t[1]), c = at(t[2]);
                    const glm::dvec3 u_at = at(u);
                    ok = glm::dot(unit_normal(a, b, c), before) > fold_cos;
                    for (const glm::dvec3& w : {a, b, c}) ok = ok && glm::dot(w - u_at, w - u_at) <= longest2;
                    new_min = std::min(new_min, smallest_angle(a, b, c));
                }
                if (ok && new_min > best_min) {
                    best_min = new_min;
                    best = *h;
                }
            }
            if (!best.is_valid()) continue;
            // The two triangles beside the collapsed edge go; of each, the edge (u, w) stays,
            // and it keeps its stroke flag whichever of the two OpenMesh keeps.
            const OMesh::VertexHandle u = om.to_vertex_handle(best);
            std::vector<OMesh::VertexHandle> stroke_ends;
            for (const OMesh::HalfedgeHandle side : {best, om.opposite_halfedge_handle(best)}) {
                if (om.is_boundary(side)) continue;
                const OMesh::HalfedgeHandle next = om.next_halfedge_handle(side);
                const OMesh::VertexHandle w = om.to_vertex_handle(next);
                const OMesh::HalfedgeHandle uw = om.find_halfedge(u, w);
                if (uw.is_valid() && om.property(constrained, om.edge_handle(uw))) stroke_ends.push_back(w);
            }
            om.collapse(best);
            for (const OMesh::VertexHandle w : stroke_ends) {
                const OMesh::HalfedgeHandle uw = om.find_halfedge(u, w);
                if (uw.is_valid()) om.property(constrained, om.edge_handle(uw)) = true;
            }
            changed = true;
        }
        mark_poor_faces();
        for (auto e : om.edges()) {
            if (om.status(e).deleted() || om.is_boundary(e) || om.property(constrained, e)) continue;
            const OMesh::HalfedgeHandle h0 = om.halfedge_handle(e, 0), h1 = om.halfedge_handle(e, 1);
            if (!is_poor(om.face_handle(h0)) && !is_poor(om.face_handle(h1))) continue;
            const OMesh::VertexHandle a = om.from_vertex_handle(h0), b = om.to_vertex_handle(h0);
            const OMesh::VertexHandle c = om.to_vertex_handle(om.next_halfedge_handle(h0));
            const OMesh::VertexHandle d = om.to_vertex_handle(om.next_halfedge_handle(h1));
            const glm::dvec3 pa = at(a), pb = at(b), pc = at(c), pd = at(d);
            const double old_min = std::min(smallest_angle(pa, pb, pc), smallest_angle(pb, pa, pd));
            if (old_min >= poor) continue;
            // After the flip: (a, d, c) and (d, b, c).
            const double new_min = std::min(smallest_angle(pa, pd, pc), smallest_angle(pd, pb, pc));
            if (!(new_min > old_min + gain) || !om.is_flip_ok(e)) continue;
            const glm::dvec3 n0 = unit_normal(pa, pb, pc), n1 = unit_normal(pb, pa, pd);
            const glm::dvec3 mean = glm::normalize(n0 + n1);
            if (glm::dot(n0, n1) < flat_cos || glm::dot(unit_normal(pa, pd, pc), mean) < flat_cos ||
                glm::dot(unit_normal(pd, pb, pc), mean) < flat_cos)
                continue;
            om.flip(e);
            changed = true;
        }
        if (!changed) break;
    }
}

/// One step of tangential relaxation, as CGAL's (PMP::tangential_relaxation as
/// isotropic_remeshing calls it, with relax_constraints): a free vertex moves to the mean of
/// its neighbours, projected onto its tangent plane; a stroke vertex with two stroke edges
/// whose stroke turns there by less than 60° or more than 120° moves halfway to the midpoint
/// of its stroke neighbours; other stroke vertices stay. Every new place is computed from the
/// old ones; the moves are then made one after another, each halved up to five times while
/// two neighbouring triangles across a free edge would face apart (and dropped after that).
/// Written here rather than called because CGAL's computes every vertex normal into a hash
/// map by its "most visible normal" search and allocates per vertex: on a lobe that took
/// a fifth of the whole remeshing. The normal here is the sum of the face normals weighted by
/// the angle sines at the vertex (CGAL's own fallback); the tangent plane only steers the
/// move, the projection onto the input surface follows.
void relax_tangentially(OMesh& om, OpenMesh::EPropHandleT<bool> constrained, const std::vector<int>& stroke_edges,
                        std::vector<glm::dvec3>& face_normal,
                        std::vector<std::pair<OMesh::VertexHandle, glm::dvec3>>& moves)
{
    auto at = [&](OMesh::VertexHandle v) { return FeatureSegments::to_glm(om.point(v)); };
    auto unit_face_normal = [&](OMesh::FaceHandle f) {
        OMesh::ConstFaceVertexIter fv = om.cfv_iter(f);
        const glm::dvec3 a = at(*fv), b = at(*++fv), c = at(*++fv);
        const glm::dvec3 n = glm::cross(b - a, c - a);
        const double l = glm::length(n);
        return l > 0.0 ? n / l : glm::dvec3(0.0);
    };
    face_normal.resize(om.n_faces());
    for (auto f : om.faces()) face_normal[static_cast<std::size_t>(f.idx())] = unit_face_normal(f);

    moves.clear();
    for (auto v : om.vertices()) {
        const int c = stroke_edges[static_cast<std::size_t>(v.idx())];
        if (om.is_isolated(v) || om.is_boundary(v)) continue;
        const glm::dvec3 p = at(v);
        if (c == 0) {
            glm::dvec3 sum(0.0), normal(0.0);
            int n = 0;
            for (OMesh::ConstVertexOHalfedgeIter h = om.cvoh_iter(v); h.is_valid(); ++h) {
                const glm::dvec3 q = at(om.to_vertex_handle(*h));
                sum += q;
                ++n;
                // The face left of v → q, and its angle at v (between q and the next neighbour).
                const OMesh::FaceHandle f = om.face_handle(*h);
                if (!f.is_valid()) continue;
                const glm::dvec3 r = at(om.to_vertex_handle(om.next_halfedge_handle(*h)));
                const glm::dvec3 u = q - p, w = r - p;
                const double lu = glm::length(u), lw = glm::length(w);
                if (lu > 0.0 && lw > 0.0)
                    normal += face_normal[static_cast<std::size_t>(f.idx())] * (glm::length(glm::cross(u, w)) / (lu * lw));
            }
            const double ln = glm::length(normal);
            const glm::dvec3 nv = ln > 0.0 ? normal / ln : glm::dvec3(0.0);
            const glm::dvec3 bary = sum / static_cast<double>(n);
            moves.emplace_back(v, bary + glm::dot(nv, p - bary) * nv);
        } else if (c == 2) {
            std::array<glm::dvec3, 2> ends{};
            int k = 0;
            for (OMesh::ConstVertexOHalfedgeIter h = om.cvoh_iter(v); h.is_valid() && k < 2; ++h)
                if (om.property(constrained, om.edge_handle(*h))) ends[static_cast<std::size_t>(k++)] = at(om.to_vertex_handle(*h));
            const glm::dvec3 u = ends[0] - p, w = ends[1] - p;
            const double d = glm::dot(u, w);
            if (0.25 < d * d / (glm::dot(u, u) * glm::dot(w, w))) moves.emplace_back(v, 0.25 * ends[0] + 0.25 * ends[1] + 0.5 * p);
        }
    }

    // Neighbouring triangles across a free edge must not face apart.
    auto normals_agree = [&](OMesh::VertexHandle v) {
        for (OMesh::ConstVertexOHalfedgeIter h = om.cvoh_iter(v); h.is_valid(); ++h) {
            if (om.property(constrained, om.edge_handle(*h))) continue;
            const OMesh::FaceHandle f0 = om.face_handle(*h), f1 = om.opposite_face_handle(*h);
            if (!f0.is_valid() || !f1.is_valid()) continue;
            const glm::dvec3 n0 = face_normal[static_cast<std::size_t>(f0.idx())];
            const glm::dvec3 n1 = face_normal[static_cast<std::size_t>(f1.idx())];
            if (n0 == glm::dvec3(0.0) || n1 == glm::dvec3(0.0)) continue; // degenerate
            if (glm::dot(n0, n1) <= 0.0) return false;
        }
        return true;
    };
    auto place = [&](OMesh::VertexHandle v, const glm::dvec3& x) {
        om.point(v) = OMesh::Point(x.x, x.y, x.z);
        for (OMesh::ConstVertexFaceIter f = om.cvf_iter(v); f.is_valid(); ++f)
            face_normal[static_cast<std::size_t>(f->idx())] = unit_face_normal(*f);
    };
    for (const auto& [v, target] : moves) {
        const glm::dvec3 start = at(v), move = target - start;
        place(v, target);
        double frac = 1.0;
        while (frac > 0.03 && !normals_agree(v)) {
            frac *= 0.5;
            place(v, start + frac * move);
        }
        if (frac <= 0.02) place(v, start);
    }
}

/// Remeshing with relaxed feature edges (RemeshOptions::relax_feature_edges) on the whole
/// mesh: CGAL's rounds one at a time, with the stroke vertices relaxed along their strokes
/// (relax_constraints) and put back onto the input strokes after every round, and every other
/// vertex projected onto the input surface. CGAL's own 1-D relaxation moves a stroke vertex
/// towards the midpoint of its two stroke neighbours, which on a bend is off the stroke, and
/// it never projects stroke vertices back; without the relaxation stroke vertices stay where
/// splits left them, and the triangles along strokes (above all where strokes run one target
/// length apart) stay poorly shaped.
void remesh_relaxing_features(OMesh& om, const TriangleMesh& input, double target, unsigned iterations,
                              OpenMesh::EPropHandleT<bool> constrained, bool slide_features,
                              const std::optional<glm::dvec3>& radial_centre)
{
    SurfaceProjector surface(input, radial_centre);
    std::optional<FeatureSegments> strokes; // where slid stroke vertices are put back
    if (slide_features) strokes.emplace(om, constrained, target);
    // The triangle of the input surface each vertex was last projected to (at first one at
    // its own place: the first vertices are the input's), where its next walk starts.
    // Vertices that splits made have none and start from a neighbour's.
    struct SurfaceHint {
        int triangle = -1;
    };
    OpenMesh::VPropHandleT<SurfaceHint> hint;
    om.add_property(hint);
    for (auto v : om.vertices())
        if (static_cast<std::size_t>(v.idx()) < input.positions.size() && !om.is_isolated(v))
            om.property(hint, v).triangle = surface.triangle_at(v.idx());
    auto project = [&](OMesh::VertexHandle v) {
        int& start = om.property(hint, v).triangle;
        for (OMesh::ConstVertexVertexIter w = om.cvv_iter(v); start < 0 && w.is_valid(); ++w)
            start = om.property(hint, *w).triangle;
        const glm::dvec3 q = surface.place(FeatureSegments::to_glm(om.point(v)), start);
        return OMesh::Point(q.x, q.y, q.z);
    };
    auto stay = [&](OMesh::VertexHandle v) {
        const OMesh::Point& p = om.point(v);
        return CGAL::Epick::Point_3(p[0], p[1], p[2]);
    };
    ConstrainedEdgeMap ecm{&om, constrained};
    std::vector<int> stroke_edges;
    std::vector<glm::dvec3> face_normal;
    std::vector<std::pair<OMesh::VertexHandle, glm::dvec3>> moves;
    for (unsigned round = 0; round < iterations; ++round) {
        // CGAL's split, collapse and flip; the relaxation and the projection follow here.
        PMP::isotropic_remeshing(faces(om), target, om,
                                 CGAL::parameters::number_of_iterations(1)
                                     .edge_is_constrained_map(ecm)
                                     .protect_constraints(!slide_features)
                                     .number_of_relaxation_steps(0)
                                     .do_project(false)
                                     // Never called (do_project is off); without a functor
                                     // CGAL builds an AABB tree of the mesh for nothing.
                                     .projection_functor(stay));
        stroke_edges.assign(om.n_vertices(), 0);
        for (auto e : om.edges())
            if (om.property(constrained, e)) {
                const OMesh::HalfedgeHandle h = om.halfedge_handle(e, 0);
                ++stroke_edges[static_cast<std::size_t>(om.from_vertex_handle(h).idx())];
                ++stroke_edges[static_cast<std::size_t>(om.to_vertex_handle(h).idx())];
            }
        if (!slide_features)
            for (int& c : stroke_edges)
                if (c == 2) c = -1; // stroke vertices stay (relax_tangentially moves only 0 and 2)
        relax_tangentially(om, constrained, stroke_edges, face_normal, moves);
        for (auto v : om.vertices()) {
            const int c = stroke_edges[static_cast<std::size_t>(v.idx())];
            if (c == 0) {
                // CGAL's projection step: free vertices onto the input surface.
                om.point(v) = project(v);
            } else if (c == 2) {
                // A stroke vertex that the 1-D relaxation moved towards the midpoint of its
                // stroke neighbours: off its stroke by the bend there, millimetres, well
                // within the half target length searched.
                const glm::dvec3 q = strokes->nearest(FeatureSegments::to_glm(om.point(v)), 0.5 * target);
                om.point(v) = OMesh::Point(q.x, q.y, q.z);
            }
        }
    }
    om.remove_property(hint);
    if (iterations > 0) improve_small_angles(om, constrained, target);
}

} // namespace

double remesh_area(const TriangleMesh& mesh, const std::vector<int>& faces)
{
    auto area_of = [&](std::size_t f) {
        const auto& t = mesh.triangles[f];
        const glm::dvec3 a(mesh.positions[static_cast<std::size_t>(t[0])]);
        const glm::dvec3 b(mesh.positions[static_cast<std::size_t>(t[1])]);
        const glm::dvec3 c(mesh.positions[static_cast<std::size_t>(t[2])]);
        return 0.5 * glm::length(glm::cross(b - a, c - a));
    };
    double area = 0.0;
    if (faces.empty()) {
        for (std::size_t f = 0; f < mesh.triangles.size(); ++f) area += area_of(f);
    } else {
        for (int f : faces)
            if (f >= 0 && f < static_cast<int>(mesh.triangles.size())) area += area_of(static_cast<std::size_t>(f));
    }
    return area;
}

double remesh_triangle_estimate(double area, double target) { return area / (std::sqrt(3.0) / 4.0 * target * target); }

TriangleMesh remesh_isotropic(const TriangleMesh& mesh, const RemeshOptions& options)
{
    const double target = options.target_edge_length_m;
    if (!(target > 0) || !std::isfinite(target))
        throw InvalidInput("remesh_isotropic: target edge length must be a positive number");
    if (options.iterations > 100) throw InvalidInput("remesh_isotropic: more than 100 iterations");
    for (const glm::vec3& p : mesh.positions)
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
            throw InvalidInput("remesh_isotropic: vertex with a non-finite coordinate");
    const MeshQuality q = measure_quality(mesh); // also checks the indices
    if (!q.manifold)
        throw InvalidInput("remesh_isotropic: the mesh is not 2-manifold or not consistently oriented "
                           "(run repair_mesh first)");
    {
        // What the remeshing would make, before it allocates anything (kMaxRemeshTriangles).
        const double area = remesh_area(mesh, options.faces);
        const double estimate = remesh_triangle_estimate(area, target);
        if (!(estimate <= static_cast<double>(kMaxRemeshTriangles))) {
            char buf[200];
            std::snprintf(buf, sizeof buf,
                          "remesh_isotropic: %.3g m² at edge length %g m would make about %.3g triangles, more than the "
                          "%zu allowed",
                          area, target, estimate, kMaxRemeshTriangles);
            throw InvalidInput(buf);
        }
    }

    OMesh om;
    om.request_vertex_status();
    om.request_edge_status();
    om.request_halfedge_status();
    om.request_face_status();
    std::vector<OMesh::VertexHandle> vh;
    vh.reserve(mesh.positions.size());
    for (const glm::vec3& p : mesh.positions) vh.push_back(om.add_vertex(om_point(p)));
    for (const auto& t : mesh.triangles) {
        const OMesh::FaceHandle f = om.add_face(vh[static_cast<std::size_t>(t[0])], vh[static_cast<std::size_t>(t[1])],
                                                vh[static_cast<std::size_t>(t[2])]);
        if (!f.is_valid()) throw InvalidInput("remesh_isotropic: a triangle cannot be added (not 2-manifold)");
    }

    OpenMesh::EPropHandleT<bool> constrained;
    OpenMesh::FPropHandleT<bool> in_region;
    om.add_property(constrained);
    om.add_property(in_region);
    for (auto e : om.edges()) om.property(constrained, e) = false;
    const bool whole = options.faces.empty();
    for (auto f : om.faces()) om.property(in_region, f) = whole;
    for (int f : options.faces) {
        if (f < 0 || f >= static_cast<int>(mesh.triangles.size()))
            throw InvalidInput("remesh_isotropic: face index " + std::to_string(f) + " out of range");
        om.property(in_region, OMesh::FaceHandle(f)) = true;
    }
    if (options.protect_feature_edges) {
        for (const auto& fe : mesh.feature_edges) {
            const int n = static_cast<int>(mesh.positions.size());
            if (fe[0] < 0 || fe[0] >= n || fe[1] < 0 || fe[1] >= n)
                throw InvalidInput("remesh_isotropic: feature edge index out of range");
            const OMesh::HalfedgeHandle h =
                om.find_halfedge(vh[static_cast<std::size_t>(fe[0])], vh[static_cast<std::size_t>(fe[1])]);
            if (!h.is_valid()) throw InvalidInput("remesh_isotropic: a feature edge is not an edge of the mesh");
            om.property(constrained, om.edge_handle(h)) = true;
        }
    }

    // protect_constraints(true) needs every constrained edge shorter than 4/3 of the target,
    // or remeshing may not terminate. Constrained here: feature edges, and the borders of the
    // region (and of the mesh), which CGAL always treats as constrained. Halve those longer
    // than 1.25 × target until none is left (each round halves them all, so a 1 km edge
    // needs 15 rounds at 3 cm).
    std::vector<OMesh::EdgeHandle> long_edges;
    for (int round = 0; round < 64; ++round) {
        long_edges.clear();
        for (auto e : om.edges()) {
            const OMesh::HalfedgeHandle h0 = om.halfedge_handle(e, 0), h1 = om.halfedge_handle(e, 1);
            const bool r0 = !om.is_boundary(h0) && om.property(in_region, om.face_handle(h0));
            const bool r1 = !om.is_boundary(h1) && om.property(in_region, om.face_handle(h1));
            const bool fixed = om.property(constrained, e) || (r0 != r1);
            if ((r0 || r1) && fixed && om.calc_edge_length(e) > target * 1.25) long_edges.push_back(e);
        }
        if (long_edges.empty()) break;
        for (OMesh::EdgeHandle e : long_edges) split_edge(om, e, 0.5, constrained, in_region);
    }

    if (options.protect_feature_edges && (options.relax_feature_edges || options.own_rounds) && whole) {
        remesh_relaxing_features(om, mesh, target, options.iterations, constrained, options.relax_feature_edges,
                                 options.radial_centre);
    } else {
        std::vector<OMesh::FaceHandle> region;
        for (auto f : om.faces())
            if (om.property(in_region, f)) region.push_back(f);
        ConstrainedEdgeMap ecm{&om, constrained};
        PMP::isotropic_remeshing(region, target, om,
                                 CGAL::parameters::number_of_iterations(options.iterations)
                                     .edge_is_constrained_map(ecm)
                                     .protect_constraints(!(options.relax_feature_edges && whole)));
    }

    // The mesh still holds what remeshing deleted (a garbage collection would cost as much as
    // a tenth of the remeshing): the vertices left are numbered afresh, in order.
    TriangleMesh out;
    std::vector<int> index(om.n_vertices(), -1);
    out.positions.reserve(om.n_vertices());
    for (auto v : om.vertices()) {
        const OMesh::Point& p = om.point(v);
        index[static_cast<std::size_t>(v.idx())] = static_cast<int>(out.positions.size());
        out.positions.emplace_back(static_cast<float>(p[0]), static_cast<float>(p[1]), static_cast<float>(p[2]));
    }
    auto new_index = [&](OMesh::VertexHandle v) { return index[static_cast<std::size_t>(v.idx())]; };
    out.triangles.reserve(om.n_faces());
    for (auto f : om.faces()) {
        std::array<int, 3> t{};
        int k = 0;
        for (OMesh::FaceVertexIter fv = om.fv_iter(f); fv.is_valid() && k < 3; ++fv) t[static_cast<std::size_t>(k++)] = new_index(*fv);
        out.triangles.push_back(t);
    }
    if (options.protect_feature_edges)
        for (auto e : om.edges())
            if (om.property(constrained, e)) {
                const OMesh::HalfedgeHandle h = om.halfedge_handle(e, 0);
                out.feature_edges.push_back({new_index(om.from_vertex_handle(h)), new_index(om.to_vertex_handle(h))});
            }
    return out;
}

} // namespace lobe
