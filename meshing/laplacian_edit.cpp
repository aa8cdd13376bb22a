#include "meshing/laplacian_edit.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <sstream>
#include <string>
#include <utility>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wconversion"
#pragma GCC diagnostic ignored "-Wshadow"
#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#pragma GCC diagnostic pop

#include "core/errors.h"
#include "meshing/best_rotation.h"

namespace lobe {

namespace {

std::string fmt(double v)
{
    std::ostringstream s;
    s << v;
    return s.str();
}

[[noreturn]] void fail(const std::string& what) { throw InvalidInput("pinch edit: " + what); }

bool finite(const glm::vec3& p) { return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z); }

Eigen::Vector3d to_eigen(const glm::vec3& p) { return {double(p.x), double(p.y), double(p.z)}; }

/// Vertex → incident triangles, compressed (offsets has #V + 1 entries).
struct Incidence {
    std::vector<int> offsets;
    std::vector<int> triangles;

    explicit Incidence(const TriangleMesh& mesh)
        : offsets(mesh.vertex_count() + 1, 0), triangles(3 * mesh.triangle_count())
    {
        for (const auto& t : mesh.triangles)
            for (int v : t)
                ++offsets[std::size_t(v) + 1];
        for (std::size_t i = 1; i < offsets.size(); ++i)
            offsets[i] += offsets[i - 1];
        std::vector<int> next(offsets.begin(), offsets.end() - 1);
        for (std::size_t f = 0; f < mesh.triangle_count(); ++f)
            for (int v : mesh.triangles[f])
                triangles[std::size_t(next[std::size_t(v)]++)] = int(f);
    }
    template <class F> void for_each_triangle(int v, F&& f) const
    {
        for (int k = offsets[std::size_t(v)]; k < offsets[std::size_t(v) + 1]; ++k)
            f(triangles[std::size_t(k)]);
    }
};

/// Weighted 1-ring of vertex v: (neighbour, wᵥⱼ) with each neighbour once, ascending.
/// Cotangent weights skip degenerate triangles (|u × w| ≤ 1e-10 |u| |w| at a corner).
std::vector<std::pair<int, double>> one_ring(const TriangleMesh& mesh, const Incidence& inc, int v,
                                             PinchEditOptions::Weights weights)
{
    std::vector<std::pair<int, double>> ring;
    inc.for_each_triangle(v, [&](int f) {
        const auto& t = mesh.triangles[std::size_t(f)];
        const int c = t[0] == v ? 0 : t[1] == v ? 1 : 2;
        const int a = t[std::size_t((c + 1) % 3)], b = t[std::size_t((c + 2) % 3)];
        if (weights == PinchEditOptions::Weights::Uniform) {
            ring.emplace_back(a, 0.0);
            ring.emplace_back(b, 0.0);
            return;
        }
        // Edge v–a is opposite corner b, edge v–b is opposite corner a.
        const Eigen::Vector3d pv = to_eigen(mesh.positions[std::size_t(v)]);
        const Eigen::Vector3d pa = to_eigen(mesh.positions[std::size_t(a)]);
        const Eigen::Vector3d pb = to_eigen(mesh.positions[std::size_t(b)]);
        auto cot = [](const Eigen::Vector3d& u, const Eigen::Vector3d& w, bool& degenerate) {
            const double s = u.cross(w).norm();
            if (!(s > 1e-10 * u.norm() * w.norm()))
                degenerate = true;
            return degenerate ? 0.0 : u.dot(w) / s;
        };
        bool degenerate = false;
        const double cot_b = cot(pv - pb, pa - pb, degenerate);
        const double cot_a = cot(pv - pa, pb - pa, degenerate);
        ring.emplace_back(a, degenerate ? 0.0 : 0.5 * cot_b);
        ring.emplace_back(b, degenerate ? 0.0 : 0.5 * cot_a);
    });
    std::sort(ring.begin(), ring.end(), [](const auto& l, const auto& r) { return l.first < r.first; });
    std::vector<std::pair<int, double>> merged;
    for (const auto& [j, w] : ring) {
        if (j == v)
            continue;
        if (!merged.empty() && merged.back().first == j)
            merged.back().second += w;
        else
            merged.emplace_back(j, w);
    }
    if (weights == PinchEditOptions::Weights::Uniform)
        for (auto& e : merged)
            e.second = 1.0;
    return merged;
}

} // namespace

int pick_handle(const TriangleMesh& mesh, const glm::vec3& point, double max_distance_m)
{
    if (mesh.positions.empty())
        fail("cannot pick a handle on an empty mesh");
    if (!finite(point))
        fail("the pinch point is not finite");
    if (!(max_distance_m >= 0.0))
        fail("max pick distance must be non-negative, got " + fmt(max_distance_m));
    int best = -1;
    double best_d2 = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
        const glm::dvec3 d = glm::dvec3(mesh.positions[i]) - glm::dvec3(point);
        const double d2 = glm::dot(d, d);
        if (d2 < best_d2) {
            best_d2 = d2;
            best = int(i);
        }
    }
    if (best < 0 || std::sqrt(best_d2) > max_distance_m)
        fail("the pinch point is " + fmt(std::sqrt(best_d2) * 100.0) + " cm from the nearest vertex (at most " +
             fmt(max_distance_m * 100.0) + " cm)");
    return best;
}

struct PinchEditor::Impl {
    using SparseMatrix = Eigen::SparseMatrix<double>;

    PinchEditOptions options;
    std::size_t vertex_count = 0;
    int handle = -1;
    glm::vec3 handle_start{};
    std::vector<int> roi, ring;

    // Local numbering: the free vertices F (0 … nf−1), then the handle, the fixed ring and
    // the vertices just outside it (the fixed vertices that rows of the ring involve).
    std::size_t nf = 0;
    std::vector<int> local_to_global;
    std::vector<Eigen::Vector3d> rest_points; ///< #local positions when the pinch starts
    // Rows of the energy: the local vertices 0 … rows−1 (F, handle, fixed ring).
    std::size_t rows = 0;
    std::vector<Eigen::Vector3d> delta;       ///< per row: δ = L(x) when the pinch starts

    // Everything the per-frame solve touches is in the factor's order (the free vertex l is
    // unknown factor_index[l]) and stored as 4 doubles per point (x, y, z, 0): two SSE2
    // packets, so the substitutions below vectorise without gathers or permutations.
    using Point4 = Eigen::Array4d;
    std::vector<int> factor_index; ///< P: free vertex l is row factor_index[l] of the factor
    // A = ∂L/∂x_F by rows: row r's entries a_offsets[r] … a_offsets[r + 1] − 1 are
    // (factor index of a free vertex, coefficient).
    std::vector<int> a_offsets, a_columns;
    std::vector<double> a_values;
    // Right-hand side for target t and rotated δ: Aᵀ(Rδ) − known_rhs − handle_rhs t, where
    // known_rhs = Aᵀ L_C x_C (the fixed vertices but the handle) and handle_rhs = Aᵀ ∂L/∂x_handle.
    std::vector<Point4> known_rhs;
    std::vector<double> handle_rhs;
    // The first solve (R = I) is affine in the target, so it is solved when the pinch starts:
    // x_F = first_base − first_slope t.
    std::vector<Point4> first_base;
    std::vector<double> first_slope;
    // LDLᵀ of A_FᵀA_F (Eigen's SimplicialLDLT, AMD ordering). L strictly below the diagonal is
    // kept twice, by rows for the forward substitution and by columns for the backward one, so
    // that both are gathers into a running sum: no store-to-load chains through y.
    std::vector<int> l_row_offsets, l_row_columns;
    std::vector<double> l_row_values;
    std::vector<int> l_column_offsets, l_column_rows;
    std::vector<double> l_column_values;
    std::vector<double> inverse_d;

    /// y[i] − Σ values[p] · y[indices[p]] over row or column i of a compressed L (p from
    /// offsets[i] to offsets[i + 1] − 1). Two running sums halve the dependency chain.
    static Point4 reduce(const std::vector<Point4>& y, std::size_t i, const std::vector<int>& offsets,
                         const std::vector<int>& indices, const std::vector<double>& values)
    {
        Point4 s0 = y[i], s1 = Point4::Zero();
        auto p = static_cast<std::size_t>(offsets[i]);
        const auto end = static_cast<std::size_t>(offsets[i + 1]);
        for (; p + 1 < end; p += 2) {
            s0 -= values[p] * y[static_cast<std::size_t>(indices[p])];
            s1 -= values[p + 1] * y[static_cast<std::size_t>(indices[p + 1])];
        }
        if (p < end)
            s0 -= values[p] * y[static_cast<std::size_t>(indices[p])];
        return s0 + s1;
    }

    /// y ← (LDLᵀ)⁻¹ y in the factor's order, for x, y and z together: forward substitution
    /// with L by rows, D⁻¹, backward substitution with Lᵀ (L by columns).
    void substitute(std::vector<Point4>& y) const
    {
        for (std::size_t i = 0; i < nf; ++i)
            y[i] = reduce(y, i, l_row_offsets, l_row_columns, l_row_values);
        for (std::size_t i = 0; i < nf; ++i)
            y[i] *= inverse_d[i];
        for (std::size_t j = nf; j-- > 0;)
            y[j] = reduce(y, j, l_column_offsets, l_column_rows, l_column_values);
    }

    // Rotation fit (rows only): 1-ring edges and incident triangles in local numbering, the
    // rest edges, the rest normal scaled to the ring's mean edge length.
    std::vector<int> ring_offsets;                   ///< rows + 1
    std::vector<int> ring_vertices;                  ///< local neighbour per ring entry
    std::vector<Eigen::Vector3d> rest_edges;         ///< xⱼ − xᵢ per ring entry
    std::vector<int> fan_offsets;                    ///< rows + 1
    std::vector<std::array<int, 3>> fan_triangles;   ///< incident triangles, local
    std::vector<Eigen::Vector3d> rest_normals;       ///< per row: unit normal × mean edge length

    /// Free positions for a handle target, in the factor's order.
    std::vector<Point4> solve(const Eigen::Vector3d& target) const
    {
        const Point4 t(target.x(), target.y(), target.z(), 0.0);
        std::vector<Point4> x(nf);
        for (std::size_t i = 0; i < nf; ++i)
            x[i] = first_base[i] - first_slope[i] * t;
        if (!options.rotation_invariant || options.rotation_iterations == 0)
            return x;
        std::vector<Point4> known(nf);
        for (std::size_t i = 0; i < nf; ++i)
            known[i] = -known_rhs[i] - handle_rhs[i] * t;
        std::vector<Eigen::Vector3d> current(rest_points);
        current[nf] = target;
        for (int it = 0; it < options.rotation_iterations; ++it) {
            for (std::size_t l = 0; l < nf; ++l)
                current[l] = x[std::size_t(factor_index[l])].head<3>().matrix();
            x = known;
            for (std::size_t r = 0; r < rows; ++r) {
                // a = Σⱼ e′ⱼ eⱼᵀ + n′ nᵀ: the 1-ring edges and the normal, before and after.
                Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
                for (int k = ring_offsets[r]; k < ring_offsets[r + 1]; ++k)
                    a.noalias() += (current[std::size_t(ring_vertices[std::size_t(k)])] - current[r]) *
                                   rest_edges[std::size_t(k)].transpose();
                Eigen::Vector3d n = Eigen::Vector3d::Zero();
                for (int k = fan_offsets[r]; k < fan_offsets[r + 1]; ++k) {
                    const auto& t3 = fan_triangles[std::size_t(k)];
                    const Eigen::Vector3d& p0 = current[std::size_t(t3[0])];
                    n += (current[std::size_t(t3[1])] - p0).cross(current[std::size_t(t3[2])] - p0);
                }
                const double length = n.norm();
                if (length > 0.0)
                    a.noalias() += (rest_normals[r].norm() / length) * n * rest_normals[r].transpose();
                const Eigen::Vector3d rotated = best_rotation(a) * delta[r];
                const Point4 d(rotated.x(), rotated.y(), rotated.z(), 0.0);
                for (int p = a_offsets[r]; p < a_offsets[r + 1]; ++p)
                    x[std::size_t(a_columns[std::size_t(p)])] += a_values[std::size_t(p)] * d;
            }
            substitute(x);
        }
        return x;
    }

    // The constructor's steps.
    void find_roi(const TriangleMesh& mesh, const Incidence& inc);
    std::vector<int> number_locally(const TriangleMesh& mesh, const Incidence& inc);
    /// The Laplacian's rows split by the kind of their columns.
    struct RowParts {
        std::vector<Eigen::Triplet<double>> free_entries; ///< A_F
        std::vector<Eigen::Vector3d> fixed_part;          ///< L_C x_C per row
        std::vector<double> handle_column;                ///< ∂L/∂x_handle per row
    };
    RowParts build_rows(const TriangleMesh& mesh, const Incidence& inc, const std::vector<int>& local);
    void factor(const RowParts& parts);
    void prepare_first_solve(const RowParts& parts);
};

namespace {

/// \throw InvalidInput (one line) unless `mesh`, `handle_vertex` and `options` can start a pinch.
void check_pinch(const TriangleMesh& mesh, int handle_vertex, const PinchEditOptions& options)
{
    const std::size_t nv = mesh.vertex_count();
    if (nv == 0 || mesh.triangles.empty())
        fail("the mesh is empty (" + std::to_string(nv) + " vertices, " + std::to_string(mesh.triangle_count()) +
             " triangles)");
    if (handle_vertex < 0 || std::size_t(handle_vertex) >= nv)
        fail("handle vertex " + std::to_string(handle_vertex) + " is out of range (mesh has " + std::to_string(nv) +
             " vertices)");
    if (!(options.roi_radius_m > 0.0) || !std::isfinite(options.roi_radius_m))
        fail("roi_radius_m must be positive and finite, got " + fmt(options.roi_radius_m));
    if (!(options.max_drag_m > 0.0))
        fail("max_drag_m must be positive, got " + fmt(options.max_drag_m));
    if (options.rotation_iterations < 0)
        fail("rotation_iterations must be non-negative, got " + std::to_string(options.rotation_iterations));
    for (std::size_t f = 0; f < mesh.triangle_count(); ++f)
        for (int v : mesh.triangles[f])
            if (v < 0 || std::size_t(v) >= nv)
                fail("triangle " + std::to_string(f) + " has vertex index " + std::to_string(v) + " out of range (mesh has " +
                     std::to_string(nv) + " vertices)");
    for (std::size_t i = 0; i < nv; ++i)
        if (!finite(mesh.positions[i]))
            fail("vertex " + std::to_string(i) + " has a non-finite position");
}

/// Calls f(u) for every vertex u of a triangle at v but v (as often as they share triangles).
template <class F>
void for_each_neighbour(const TriangleMesh& mesh, const Incidence& inc, int v, F&& f)
{
    inc.for_each_triangle(v, [&](int t) {
        for (int u : mesh.triangles[std::size_t(t)])
            if (u != v)
                f(u);
    });
}

} // namespace

/// The vertices within options.roi_radius_m of the handle (Dijkstra along edges), sorted.
void PinchEditor::Impl::find_roi(const TriangleMesh& mesh, const Incidence& inc)
{
    std::vector<double> dist(mesh.vertex_count(), std::numeric_limits<double>::infinity());
    using Item = std::pair<double, int>;
    std::priority_queue<Item, std::vector<Item>, std::greater<>> queue;
    dist[std::size_t(handle)] = 0.0;
    queue.emplace(0.0, handle);
    while (!queue.empty()) {
        const double d = queue.top().first; // named copies: lambdas may not capture bindings (clang 14)
        const int v = queue.top().second;
        queue.pop();
        if (d > dist[std::size_t(v)])
            continue;
        roi.push_back(v);
        for_each_neighbour(mesh, inc, v, [&](int u) {
            const double nd = d + glm::length(glm::dvec3(mesh.positions[std::size_t(u)]) -
                                               glm::dvec3(mesh.positions[std::size_t(v)]));
            if (nd <= options.roi_radius_m && nd < dist[std::size_t(u)]) {
                dist[std::size_t(u)] = nd;
                queue.emplace(nd, u);
            }
        });
    }
    std::sort(roi.begin(), roi.end());
    if (roi.size() < 2)
        fail("the ROI around vertex " + std::to_string(handle) + " has no free vertex (roi_radius_m = " +
             fmt(options.roi_radius_m) + " is shorter than every edge at the handle, or the vertex is isolated)");
}

/// Local numbering (local_to_global): the free vertices, the handle, the fixed ring, the
/// vertices just outside it. Returns the local number of each vertex (-1: none).
std::vector<int> PinchEditor::Impl::number_locally(const TriangleMesh& mesh, const Incidence& inc)
{
    std::vector<int> local(mesh.vertex_count(), -1);
    for (int v : roi)
        if (v != handle) {
            local[std::size_t(v)] = int(local_to_global.size());
            local_to_global.push_back(v);
        }
    nf = local_to_global.size();
    local[std::size_t(handle)] = int(local_to_global.size());
    local_to_global.push_back(handle);
    for (int v : roi)
        for_each_neighbour(mesh, inc, v, [&](int u) {
            if (local[std::size_t(u)] < 0) {
                local[std::size_t(u)] = int(local_to_global.size());
                local_to_global.push_back(u);
                ring.push_back(u);
            }
        });
    std::sort(ring.begin(), ring.end());
    rows = local_to_global.size();
    for (std::size_t r = nf + 1; r < rows; ++r)
        for_each_neighbour(mesh, inc, local_to_global[r], [&](int u) {
            if (local[std::size_t(u)] < 0) {
                local[std::size_t(u)] = int(local_to_global.size());
                local_to_global.push_back(u);
            }
        });
    const std::size_t nl = local_to_global.size();
    for (std::size_t l = 0; l < nl; ++l)
        rest_points.push_back(to_eigen(mesh.positions[std::size_t(local_to_global[l])]));
    return local;
}

/// The rows of L (Sorkine et al. 2004, Eq. 1 with weights), and per row what the rotation fit
/// needs: L(x)ᵢ = xᵢ − Σⱼ wᵢⱼ xⱼ / Σⱼ wᵢⱼ. A vertex whose 1-ring weights add up to nothing (all
/// triangles degenerate) has no row.
PinchEditor::Impl::RowParts PinchEditor::Impl::build_rows(const TriangleMesh& mesh, const Incidence& inc,
                                                          const std::vector<int>& local)
{
    RowParts parts;
    std::vector<Eigen::Triplet<double>>& free_entries = parts.free_entries;
    std::vector<Eigen::Vector3d>& fixed_part = parts.fixed_part;
    std::vector<double>& handle_column = parts.handle_column;
    fixed_part.assign(rows, Eigen::Vector3d::Zero());
    handle_column.assign(rows, 0.0);
    ring_offsets.push_back(0);
    fan_offsets.push_back(0);
    a_offsets.push_back(0);
    delta.assign(rows, Eigen::Vector3d::Zero());
    for (std::size_t r = 0; r < rows; ++r) {
        const auto ri = Eigen::Index(r);
        const auto neighbours = one_ring(mesh, inc, local_to_global[r], options.weights);
        const Eigen::Vector3d& xi = rest_points[r];
        double total = 0.0, squared_lengths = 0.0;
        for (const auto& [j, w] : neighbours) {
            total += w;
            const int lj = local[std::size_t(j)];
            ring_vertices.push_back(lj);
            rest_edges.push_back(rest_points[std::size_t(lj)] - xi);
            squared_lengths += rest_edges.back().squaredNorm();
        }
        ring_offsets.push_back(int(ring_vertices.size()));
        Eigen::Vector3d normal = Eigen::Vector3d::Zero();
        inc.for_each_triangle(local_to_global[r], [&](int f) {
            const auto& t = mesh.triangles[std::size_t(f)];
            const std::array<int, 3> lt = {local[std::size_t(t[0])], local[std::size_t(t[1])], local[std::size_t(t[2])]};
            fan_triangles.push_back(lt);
            const Eigen::Vector3d& p0 = rest_points[std::size_t(lt[0])];
            normal += (rest_points[std::size_t(lt[1])] - p0).cross(rest_points[std::size_t(lt[2])] - p0);
        });
        fan_offsets.push_back(int(fan_triangles.size()));
        const double mean_length = neighbours.empty() ? 0.0 : std::sqrt(squared_lengths / double(neighbours.size()));
        rest_normals.push_back(normal.norm() > 0.0 ? Eigen::Vector3d(normal.normalized() * mean_length)
                                                   : Eigen::Vector3d::Zero());
        if (total > 0.0 && std::isfinite(total)) {
            auto add = [&](std::size_t col, double coef) {
                delta[r] += coef * rest_points[col];
                if (col < nf) {
                    free_entries.emplace_back(ri, Eigen::Index(col), coef);
                    a_columns.push_back(int(col)); // local for now; factor order below
                    a_values.push_back(coef);
                } else if (col == nf) {
                    handle_column[r] += coef;
                } else {
                    fixed_part[r] += coef * rest_points[col];
                }
            };
            add(r, 1.0);
            for (const auto& [j, w] : neighbours)
                add(std::size_t(local[std::size_t(j)]), -w / total);
        }
        a_offsets.push_back(int(a_columns.size()));
    }
    return parts;
}

/// LDLᵀ of A_FᵀA_F, L kept by rows and by columns.
/// \throw SolverError where it is singular or not positive definite.
void PinchEditor::Impl::factor(const RowParts& parts)
{
    SparseMatrix a_free(static_cast<Eigen::Index>(rows), static_cast<Eigen::Index>(nf));
    a_free.setFromTriplets(parts.free_entries.begin(), parts.free_entries.end());
    const SparseMatrix normal = (SparseMatrix(a_free.transpose()) * a_free).pruned();
    const Eigen::SimplicialLDLT<SparseMatrix> ldlt(normal);
    if (ldlt.info() != Eigen::Success)
        throw SolverError("pinch edit: the Laplacian system of the ROI around vertex " + std::to_string(handle) +
                          " is singular (degenerate triangles?)");
    const Eigen::VectorXd d = ldlt.vectorD();
    const double largest = d.cwiseAbs().maxCoeff();
    if (!(d.minCoeff() > 1e-13 * largest))
        throw SolverError("pinch edit: the Laplacian system of the ROI around vertex " + std::to_string(handle) +
                          " is singular or not positive definite (degenerate triangles?)");
    inverse_d.resize(nf);
    for (std::size_t i = 0; i < nf; ++i)
        inverse_d[i] = 1.0 / d(Eigen::Index(i));
    const auto& p = ldlt.permutationP().indices();
    factor_index.assign(p.data(), p.data() + p.size());

    // L below the diagonal by columns (as Eigen stores it), then by rows (a counting sort).
    const SparseMatrix& l = ldlt.matrixL().nestedExpression();
    std::vector<int> per_row(nf + 1, 0);
    for (Eigen::Index j = 0; j < l.outerSize(); ++j) {
        l_column_offsets.push_back(int(l_column_rows.size()));
        for (SparseMatrix::InnerIterator it(l, j); it; ++it)
            if (it.row() > j) {
                l_column_rows.push_back(int(it.row()));
                l_column_values.push_back(it.value());
                ++per_row[std::size_t(it.row()) + 1];
            }
    }
    l_column_offsets.push_back(int(l_column_rows.size()));
    for (std::size_t i = 1; i <= nf; ++i)
        per_row[i] += per_row[i - 1];
    l_row_offsets = per_row;
    l_row_columns.resize(l_column_rows.size());
    l_row_values.resize(l_column_rows.size());
    for (std::size_t j = 0; j < nf; ++j)
        for (int q = l_column_offsets[j]; q < l_column_offsets[j + 1]; ++q) {
            const auto slot = std::size_t(per_row[std::size_t(l_column_rows[std::size_t(q)])]++);
            l_row_columns[slot] = int(j);
            l_row_values[slot] = l_column_values[std::size_t(q)];
        }
}

/// A's columns in factor order, the known parts of the right-hand side, and the first
/// (unrotated) solve as base and slope.
void PinchEditor::Impl::prepare_first_solve(const RowParts& parts)
{
    for (int& c : a_columns)
        c = factor_index[std::size_t(c)];
    known_rhs.assign(nf, Point4::Zero());
    handle_rhs.assign(nf, 0.0);
    std::vector<Point4> slope(nf, Point4::Zero());
    first_base.assign(nf, Point4::Zero());
    for (std::size_t r = 0; r < rows; ++r) {
        const Point4 known(parts.fixed_part[r].x(), parts.fixed_part[r].y(), parts.fixed_part[r].z(), 0.0);
        const Point4 dr(delta[r].x(), delta[r].y(), delta[r].z(), 0.0);
        for (int q = a_offsets[r]; q < a_offsets[r + 1]; ++q) {
            const auto c = std::size_t(a_columns[std::size_t(q)]);
            const double v = a_values[std::size_t(q)];
            known_rhs[c] += v * known;
            handle_rhs[c] += v * parts.handle_column[r];
            first_base[c] += v * dr;
        }
    }
    for (std::size_t i = 0; i < nf; ++i) {
        first_base[i] -= known_rhs[i];
        slope[i] = Point4::Constant(handle_rhs[i]);
    }
    substitute(first_base);
    substitute(slope);
    first_slope.resize(nf);
    for (std::size_t i = 0; i < nf; ++i)
        first_slope[i] = slope[i](0);
}

PinchEditor::PinchEditor(const TriangleMesh& mesh, int handle_vertex, const PinchEditOptions& options)
    : impl_(std::make_unique<Impl>())
{
    check_pinch(mesh, handle_vertex, options);
    Impl& m = *impl_;
    m.options = options;
    m.vertex_count = mesh.vertex_count();
    m.handle = handle_vertex;
    m.handle_start = mesh.positions[std::size_t(handle_vertex)];
    const Incidence inc(mesh);
    m.find_roi(mesh, inc);
    const std::vector<int> local = m.number_locally(mesh, inc);
    const Impl::RowParts parts = m.build_rows(mesh, inc, local);
    m.factor(parts);
    m.prepare_first_solve(parts);
}

PinchEditor::~PinchEditor() = default;
PinchEditor::PinchEditor(PinchEditor&&) noexcept = default;
PinchEditor& PinchEditor::operator=(PinchEditor&&) noexcept = default;

void PinchEditor::drag_to(const glm::vec3& handle_position, TriangleMesh& mesh) const
{
    const Impl& m = *impl_;
    if (!finite(handle_position))
        fail("the handle target is not finite");
    const double drag = glm::length(glm::dvec3(handle_position) - glm::dvec3(m.handle_start));
    if (drag > m.options.max_drag_m)
        fail("the handle target is " + fmt(drag) + " m from where the pinch started (at most " +
             fmt(m.options.max_drag_m) + " m)");
    if (mesh.vertex_count() != m.vertex_count)
        fail("the mesh has " + std::to_string(mesh.vertex_count()) + " vertices, the pinch started on " +
             std::to_string(m.vertex_count));
    const std::vector<Impl::Point4> x = m.solve(to_eigen(handle_position));
    for (const Impl::Point4& p : x)
        if (!p.isFinite().all())
            throw SolverError("pinch edit: the solve gave non-finite positions");
    for (std::size_t l = 0; l < m.nf; ++l) {
        const Impl::Point4& p = x[std::size_t(m.factor_index[l])];
        mesh.positions[std::size_t(m.local_to_global[l])] = glm::vec3(float(p(0)), float(p(1)), float(p(2)));
    }
    mesh.positions[std::size_t(m.handle)] = handle_position;
}

int PinchEditor::handle() const { return impl_->handle; }
const glm::vec3& PinchEditor::handle_start() const { return impl_->handle_start; }
const std::vector<int>& PinchEditor::roi() const { return impl_->roi; }
const std::vector<int>& PinchEditor::fixed_ring() const { return impl_->ring; }
std::size_t PinchEditor::free_vertex_count() const { return impl_->nf; }

void laplacian_deform(TriangleMesh& mesh, int handle_vertex, const glm::vec3& target, const PinchEditOptions& options)
{
    const PinchEditor editor(mesh, handle_vertex, options);
    editor.drag_to(target, mesh);
}

} // namespace lobe
