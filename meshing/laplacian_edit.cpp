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

/// The rotation R maximising tr(Rᵀa), i.e. minimising Σⱼ ‖e′ⱼ − R eⱼ‖² for a = Σⱼ e′ⱼ eⱼᵀ:
/// the polar factor a (aᵀa)^(−1/2), from the closed-form eigen decomposition of aᵀa. Falls
/// back to the SVD (a = UΣVᵀ, R = UVᵀ with the reflection removed) when a is near singular
/// or a reflection.
Eigen::Matrix3d fit_rotation(const Eigen::Matrix3d& a)
{
    if (a.determinant() > 0.0) {
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
        eig.computeDirect(a.transpose() * a);
        const Eigen::Vector3d lambda = eig.eigenvalues(); // ascending
        if (lambda(0) > 1e-6 * lambda(2)) {
            const Eigen::Matrix3d& v = eig.eigenvectors();
            return a * (v * lambda.cwiseSqrt().cwiseInverse().asDiagonal() * v.transpose());
        }
    }
    Eigen::JacobiSVD<Eigen::Matrix3d> svd(a, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Matrix3d u = svd.matrixU();
    const Eigen::Matrix3d& v = svd.matrixV();
    if ((u * v.transpose()).determinant() < 0.0)
        u.col(2) = -u.col(2); // singular values are sorted: flip the least certain axis
    return u * v.transpose();
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
    Eigen::MatrixX3d delta;                   ///< rows by 3: δ = L(x) when the pinch starts
    SparseMatrix a_free_t;                    ///< nf by rows: A_Fᵀ, A = ∂L/∂x_F
    Eigen::MatrixX3d fixed_part;              ///< rows by 3: L applied to the fixed vertices but the handle
    Eigen::VectorXd handle_column;            ///< rows: ∂L/∂x_handle
    Eigen::SimplicialLDLT<SparseMatrix> ldlt; ///< of A_FᵀA_F = Pᵀ L D Lᵀ P
    // The factor copied out of ldlt, so that the three right-hand sides (x, y, z) are
    // substituted together in one pass over L (Eigen's solve makes one pass per column).
    std::vector<int> l_outer, l_inner; ///< L strictly below the diagonal, compressed columns
    std::vector<double> l_values;
    std::vector<double> inverse_d;
    std::vector<int> permutation;      ///< P: row i of the system is row permutation[i] of the factor

    /// (A_FᵀA_F)⁻¹ rhs for nf by 3 rhs: P, forward substitution with L, D⁻¹, backward with Lᵀ, P⁻¹.
    Eigen::MatrixX3d substitute(const Eigen::MatrixX3d& rhs) const
    {
        const std::size_t n = nf;
        std::vector<double> y(3 * n);
        for (std::size_t i = 0; i < n; ++i)
            for (std::size_t c = 0; c < 3; ++c)
                y[3 * std::size_t(permutation[i]) + c] = rhs(Eigen::Index(i), Eigen::Index(c));
        for (std::size_t j = 0; j < n; ++j) {
            const double y0 = y[3 * j], y1 = y[3 * j + 1], y2 = y[3 * j + 2];
            for (int p = l_outer[j]; p < l_outer[j + 1]; ++p) {
                double* yi = &y[3 * std::size_t(l_inner[std::size_t(p)])];
                const double v = l_values[std::size_t(p)];
                yi[0] -= v * y0;
                yi[1] -= v * y1;
                yi[2] -= v * y2;
            }
        }
        for (std::size_t j = 0; j < n; ++j)
            for (std::size_t c = 0; c < 3; ++c)
                y[3 * j + c] *= inverse_d[j];
        for (std::size_t j = n; j-- > 0;) {
            double y0 = y[3 * j], y1 = y[3 * j + 1], y2 = y[3 * j + 2];
            for (int p = l_outer[j]; p < l_outer[j + 1]; ++p) {
                const double* yi = &y[3 * std::size_t(l_inner[std::size_t(p)])];
                const double v = l_values[std::size_t(p)];
                y0 -= v * yi[0];
                y1 -= v * yi[1];
                y2 -= v * yi[2];
            }
            y[3 * j] = y0;
            y[3 * j + 1] = y1;
            y[3 * j + 2] = y2;
        }
        Eigen::MatrixX3d x(Eigen::Index(n), 3);
        for (std::size_t i = 0; i < n; ++i)
            for (std::size_t c = 0; c < 3; ++c)
                x(Eigen::Index(i), Eigen::Index(c)) = y[3 * std::size_t(permutation[i]) + c];
        return x;
    }

    // Rotation fit (rows only): 1-ring edges and incident triangles in local numbering, the
    // rest edges, the rest normal scaled to the ring's mean edge length.
    std::vector<int> ring_offsets;                   ///< rows + 1
    std::vector<int> ring_vertices;                  ///< local neighbour per ring entry
    std::vector<Eigen::Vector3d> rest_edges;         ///< xⱼ − xᵢ per ring entry
    std::vector<int> fan_offsets;                    ///< rows + 1
    std::vector<std::array<int, 3>> fan_triangles;   ///< incident triangles, local
    std::vector<Eigen::Vector3d> rest_normals;       ///< per row: unit normal × mean edge length

    /// Free positions (nf by 3) for a handle target.
    Eigen::MatrixX3d solve(const Eigen::Vector3d& target) const
    {
        const Eigen::MatrixX3d base = fixed_part + handle_column * target.transpose();
        Eigen::MatrixX3d x = substitute(a_free_t * (delta - base));
        if (!options.rotation_invariant || options.rotation_iterations == 0)
            return x;
        std::vector<Eigen::Vector3d> current(rest_points);
        current[nf] = target;
        Eigen::MatrixX3d rotated(Eigen::Index(rows), 3);
        for (int it = 0; it < options.rotation_iterations; ++it) {
            for (std::size_t l = 0; l < nf; ++l)
                current[l] = x.row(Eigen::Index(l)).transpose();
            for (std::size_t r = 0; r < rows; ++r) {
                // a = Σⱼ e′ⱼ eⱼᵀ + n′ nᵀ: the 1-ring edges and the normal, before and after.
                Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
                for (int k = ring_offsets[r]; k < ring_offsets[r + 1]; ++k)
                    a.noalias() += (current[std::size_t(ring_vertices[std::size_t(k)])] - current[r]) *
                                   rest_edges[std::size_t(k)].transpose();
                Eigen::Vector3d n = Eigen::Vector3d::Zero();
                for (int k = fan_offsets[r]; k < fan_offsets[r + 1]; ++k) {
                    const auto& t = fan_triangles[std::size_t(k)];
                    const Eigen::Vector3d& p0 = current[std::size_t(t[0])];
                    n += (current[std::size_t(t[1])] - p0).cross(current[std::size_t(t[2])] - p0);
                }
                const double length = n.norm();
                if (length > 0.0)
                    a.noalias() += (rest_normals[r].norm() / length) * n * rest_normals[r].transpose();
                rotated.row(Eigen::Index(r)) = (fit_rotation(a) * delta.row(Eigen::Index(r)).transpose()).transpose();
            }
            x = substitute(a_free_t * (rotated - base));
        }
        return x;
    }
};

PinchEditor::PinchEditor(const TriangleMesh& mesh, int handle_vertex, const PinchEditOptions& options)
    : impl_(std::make_unique<Impl>())
{
    Impl& m = *impl_;
    m.options = options;
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

    m.vertex_count = nv;
    m.handle = handle_vertex;
    m.handle_start = mesh.positions[std::size_t(handle_vertex)];
    const Incidence inc(mesh);
    auto for_each_neighbour = [&](int v, auto&& f) {
        inc.for_each_triangle(v, [&](int t) {
            for (int u : mesh.triangles[std::size_t(t)])
                if (u != v)
                    f(u);
        });
    };

    // ROI: Dijkstra along edges from the handle, up to roi_radius_m.
    std::vector<double> dist(nv, std::numeric_limits<double>::infinity());
    using Item = std::pair<double, int>;
    std::priority_queue<Item, std::vector<Item>, std::greater<>> queue;
    dist[std::size_t(handle_vertex)] = 0.0;
    queue.emplace(0.0, handle_vertex);
    while (!queue.empty()) {
        const double d = queue.top().first; // named copies: lambdas may not capture bindings (clang 14)
        const int v = queue.top().second;
        queue.pop();
        if (d > dist[std::size_t(v)])
            continue;
        m.roi.push_back(v);
        for_each_neighbour(v, [&](int u) {
            const double nd = d + glm::length(glm::dvec3(mesh.positions[std::size_t(u)]) -
                                               glm::dvec3(mesh.positions[std::size_t(v)]));
            if (nd <= options.roi_radius_m && nd < dist[std::size_t(u)]) {
                dist[std::size_t(u)] = nd;
                queue.emplace(nd, u);
            }
        });
    }
    std::sort(m.roi.begin(), m.roi.end());
    if (m.roi.size() < 2)
        fail("the ROI around vertex " + std::to_string(handle_vertex) + " has no free vertex (roi_radius_m = " +
             fmt(options.roi_radius_m) + " is shorter than every edge at the handle, or the vertex is isolated)");

    // Local numbering: free, handle, ring, outside.
    std::vector<int> local(nv, -1);
    for (int v : m.roi)
        if (v != handle_vertex) {
            local[std::size_t(v)] = int(m.local_to_global.size());
            m.local_to_global.push_back(v);
        }
    m.nf = m.local_to_global.size();
    local[std::size_t(handle_vertex)] = int(m.local_to_global.size());
    m.local_to_global.push_back(handle_vertex);
    for (int v : m.roi)
        for_each_neighbour(v, [&](int u) {
            if (local[std::size_t(u)] < 0) {
                local[std::size_t(u)] = int(m.local_to_global.size());
                m.local_to_global.push_back(u);
                m.ring.push_back(u);
            }
        });
    std::sort(m.ring.begin(), m.ring.end());
    m.rows = m.local_to_global.size();
    for (std::size_t r = m.nf + 1; r < m.rows; ++r)
        for_each_neighbour(m.local_to_global[r], [&](int u) {
            if (local[std::size_t(u)] < 0) {
                local[std::size_t(u)] = int(m.local_to_global.size());
                m.local_to_global.push_back(u);
            }
        });
    const std::size_t nl = m.local_to_global.size();
    for (std::size_t l = 0; l < nl; ++l)
        m.rest_points.push_back(to_eigen(mesh.positions[std::size_t(m.local_to_global[l])]));

    // Rows of L (Sorkine et al. 2004, Eq. 1 with weights): L(x)ᵢ = xᵢ − Σⱼ wᵢⱼ xⱼ / Σⱼ wᵢⱼ.
    // A vertex whose 1-ring weights add up to nothing (all triangles degenerate) has no row.
    std::vector<Eigen::Triplet<double>> free_entries;
    m.ring_offsets.push_back(0);
    m.fan_offsets.push_back(0);
    m.fixed_part = Eigen::MatrixX3d::Zero(Eigen::Index(m.rows), 3);
    m.handle_column = Eigen::VectorXd::Zero(Eigen::Index(m.rows));
    Eigen::MatrixX3d full_lx = Eigen::MatrixX3d::Zero(Eigen::Index(m.rows), 3);
    for (std::size_t r = 0; r < m.rows; ++r) {
        const auto ri = Eigen::Index(r);
        const auto ring = one_ring(mesh, inc, m.local_to_global[r], options.weights);
        const Eigen::Vector3d& xi = m.rest_points[r];
        double total = 0.0, squared_lengths = 0.0;
        for (const auto& [j, w] : ring) {
            total += w;
            const int lj = local[std::size_t(j)];
            m.ring_vertices.push_back(lj);
            m.rest_edges.push_back(m.rest_points[std::size_t(lj)] - xi);
            squared_lengths += m.rest_edges.back().squaredNorm();
        }
        m.ring_offsets.push_back(int(m.ring_vertices.size()));
        Eigen::Vector3d normal = Eigen::Vector3d::Zero();
        inc.for_each_triangle(m.local_to_global[r], [&](int f) {
            const auto& t = mesh.triangles[std::size_t(f)];
            const std::array<int, 3> lt = {local[std::size_t(t[0])], local[std::size_t(t[1])], local[std::size_t(t[2])]};
            m.fan_triangles.push_back(lt);
            const Eigen::Vector3d& p0 = m.rest_points[std::size_t(lt[0])];
            normal += (m.rest_points[std::size_t(lt[1])] - p0).cross(m.rest_points[std::size_t(lt[2])] - p0);
        });
        m.fan_offsets.push_back(int(m.fan_triangles.size()));
        const double mean_length = ring.empty() ? 0.0 : std::sqrt(squared_lengths / double(ring.size()));
        m.rest_normals.push_back(normal.norm() > 0.0 ? Eigen::Vector3d(normal.normalized() * mean_length)
                                                     : Eigen::Vector3d::Zero());
        if (!(total > 0.0) || !std::isfinite(total))
            continue;
        auto add = [&](std::size_t col, double coef) {
            full_lx.row(ri) += coef * m.rest_points[col].transpose();
            if (col < m.nf)
                free_entries.emplace_back(ri, Eigen::Index(col), coef);
            else if (col == m.nf)
                m.handle_column(ri) += coef;
            else
                m.fixed_part.row(ri) += coef * m.rest_points[col].transpose();
        };
        add(r, 1.0);
        for (const auto& [j, w] : ring)
            add(std::size_t(local[std::size_t(j)]), -w / total);
    }
    m.delta = full_lx;
    Impl::SparseMatrix a_free(Eigen::Index(m.rows), Eigen::Index(m.nf));
    a_free.setFromTriplets(free_entries.begin(), free_entries.end());
    m.a_free_t = a_free.transpose();
    const Impl::SparseMatrix normal = (m.a_free_t * a_free).pruned();
    m.ldlt.compute(normal);
    if (m.ldlt.info() != Eigen::Success)
        throw SolverError("pinch edit: the Laplacian system of the ROI around vertex " + std::to_string(handle_vertex) +
                          " is singular (degenerate triangles?)");
    const Eigen::VectorXd d = m.ldlt.vectorD();
    const double largest = d.cwiseAbs().maxCoeff();
    if (!(d.minCoeff() > 1e-13 * largest))
        throw SolverError("pinch edit: the Laplacian system of the ROI around vertex " + std::to_string(handle_vertex) +
                          " is singular or not positive definite (degenerate triangles?)");
    m.inverse_d.resize(m.nf);
    for (std::size_t i = 0; i < m.nf; ++i)
        m.inverse_d[i] = 1.0 / d(Eigen::Index(i));
    const Impl::SparseMatrix& l = m.ldlt.matrixL().nestedExpression();
    for (Eigen::Index j = 0; j < l.outerSize(); ++j) {
        m.l_outer.push_back(int(m.l_inner.size()));
        for (Impl::SparseMatrix::InnerIterator it(l, j); it; ++it)
            if (it.row() > j) {
                m.l_inner.push_back(int(it.row()));
                m.l_values.push_back(it.value());
            }
    }
    m.l_outer.push_back(int(m.l_inner.size()));
    const auto& p = m.ldlt.permutationP().indices();
    m.permutation.assign(p.data(), p.data() + p.size());
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
    const Eigen::MatrixX3d x = m.solve(to_eigen(handle_position));
    if (!x.allFinite())
        throw SolverError("pinch edit: the solve gave non-finite positions");
    for (std::size_t l = 0; l < m.nf; ++l) {
        const auto r = x.row(Eigen::Index(l));
        mesh.positions[std::size_t(m.local_to_global[l])] = glm::vec3(float(r(0)), float(r(1)), float(r(2)));
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
