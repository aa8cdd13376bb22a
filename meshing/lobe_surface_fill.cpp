// The fill of a lobe surface (lobe_surface_builder.h): where its vertices go (fill_lattice, for
// the triangulation's refinement in lobe_surface_cgal.cpp) and at what distance from the centre
// (solve_fill_radii, fit_radius_model). No CGAL.
#include "meshing/lobe_surface_builder.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>

#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <glm/geometric.hpp>

#include "core/errors.h"

namespace lobe {

namespace lobe_surface_detail {

namespace {

bool solver_ok(const Eigen::VectorXd& x)
{
    return x.allFinite();
}

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


/// The fill vertices' radii, one group of connected unknowns at a time (solve_fill_radii).
/// The harmonic interpolation of the residuals: (Σ_j w_ij) x_i − Σ_j w_ij x_j = 0 at every
/// free vertex, with w_ij the inverse angular length of edge ij (so long strip edges and
/// short cap edges measure slope alike). Symmetric positive definite; only its lower
/// triangle is stored, which is all SimplicialLDLT reads. Small groups are solved dense.
class FillGroupSolver {
public:
    /// `unknown`: per node, its row (-1: known); `row_node`: per row, its node; `local`: per
    /// row, its place in its group; `model` (when `have_model`): the radius model per node;
    /// [lo, hi]: the strokes' radii.
    FillGroupSolver(const Adjacency& adj, const std::vector<int>& unknown, const std::vector<int>& row_node,
                    const std::vector<int>& local, const std::vector<double>& model, bool have_model, double lo, double hi)
        : adj_(adj), unknown_(unknown), row_node_(row_node), local_(local), model_(model), have_model_(have_model), lo_(lo),
          hi_(hi)
    {
    }
    /// Solves the group of rows `members` (in row order) and sets their nodes' radii.
    /// \throw InvalidInput where the system cannot be solved or gives a radius below a quarter
    /// of the strokes' least.
    void solve(const std::vector<int>& members, std::vector<Node>& nodes);

private:
    static constexpr Index kDense = 48; ///< groups up to this size are solved dense
    const Adjacency& adj_;
    const std::vector<int>& unknown_;
    const std::vector<int>& row_node_;
    const std::vector<int>& local_;
    const std::vector<double>& model_;
    bool have_model_;
    double lo_, hi_;
    std::vector<Eigen::Triplet<double>> entries_; ///< kept between groups, as its memory
    Eigen::MatrixXd dense_;
};

void FillGroupSolver::solve(const std::vector<int>& members, std::vector<Node>& nodes)
{
    const Index m = members.size();
    bool use_model = have_model_;
    for (int r : members) {
        const double v = model_[static_cast<Index>(row_node_[static_cast<Index>(r)])];
        if (!(v >= 0.5 * lo_ && v <= 1.5 * hi_)) use_model = false;
    }
    auto model_at = [&](Index i) { return use_model ? model_[i] : 0.0; };
    entries_.clear();
    if (m <= kDense) dense_.setZero(static_cast<Eigen::Index>(m), static_cast<Eigen::Index>(m));
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(m));
    for (int r : members) {
        const Index i = static_cast<Index>(row_node_[static_cast<Index>(r)]);
        const int row = local_[static_cast<Index>(r)];
        double sum = 0;
        for (int j : adj_[i]) {
            const double w = 1.0 / std::max(1e-6, angle_between(nodes[i].dir, nodes[static_cast<Index>(j)].dir));
            sum += w;
            const int c = unknown_[static_cast<Index>(j)];
            if (c < 0) {
                rhs[row] += w * (nodes[static_cast<Index>(j)].radius - model_at(static_cast<Index>(j)));
            } else if (local_[static_cast<Index>(c)] < row) {
                if (m <= kDense) dense_(row, local_[static_cast<Index>(c)]) = -w;
                else entries_.emplace_back(row, local_[static_cast<Index>(c)], -w);
            }
        }
        if (m <= kDense) dense_(row, row) = sum;
        else entries_.emplace_back(row, row, sum);
    }
    Eigen::VectorXd x;
    bool ok = false;
    if (m <= kDense) {
        const Eigen::LLT<Eigen::MatrixXd, Eigen::Lower> llt(dense_);
        ok = llt.info() == Eigen::Success;
        if (ok) x = llt.solve(rhs);
    } else {
        Eigen::SparseMatrix<double> system(static_cast<Eigen::Index>(m), static_cast<Eigen::Index>(m));
        system.setFromTriplets(entries_.begin(), entries_.end());
        const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(system);
        ok = solver.info() == Eigen::Success;
        if (ok) x = solver.solve(rhs);
    }
    if (!ok || !solver_ok(x)) throw InvalidInput("the lobe's strokes leave a gap that cannot be closed around its centre");
    for (int r : members) {
        const Index i = static_cast<Index>(row_node_[static_cast<Index>(r)]);
        const double radius = x[local_[static_cast<Index>(r)]] + model_at(i);
        if (!(radius > 0.25 * lo_)) throw InvalidInput("the lobe's strokes leave a gap too wide to close around its centre");
        nodes[i].radius = radius;
    }
}

/// The unknowns (rows) in groups of connected ones (union–find over the rows of `adj`), each
/// group's rows in increasing order; `local` receives each row's place in its group.
std::vector<std::vector<int>> connected_groups(const Adjacency& adj, const std::vector<int>& unknown, int count,
                                               std::vector<int>& local)
{
    std::vector<int> parent(static_cast<Index>(count));
    for (Index r = 0; r < parent.size(); ++r) parent[r] = static_cast<int>(r);
    auto find = [&](int x) {
        while (parent[static_cast<Index>(x)] != x)
            x = parent[static_cast<Index>(x)] = parent[static_cast<Index>(parent[static_cast<Index>(x)])];
        return x;
    };
    for (Index i = 0; i < unknown.size(); ++i) {
        if (unknown[i] < 0) continue;
        for (int j : adj[i]) {
            const int col = unknown[static_cast<Index>(j)];
            if (col < 0) continue;
            const int a = find(unknown[i]), b = find(col);
            if (a != b) parent[static_cast<Index>(std::max(a, b))] = std::min(a, b);
        }
    }
    // Members of each group in row order, and their place in it.
    std::vector<int> group_of_root(static_cast<Index>(count), -1);
    local.assign(static_cast<Index>(count), 0);
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
    return groups;
}

} // namespace

std::vector<glm::dvec3> LobeSurfaceBuilder::fill_lattice(double max_edge, double ring_angle) const
{
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
    const double ring_keep = std::cos(ring_angle + clearance);
    const int count = static_cast<int>(std::ceil(4.0 * M_PI / (spacing * spacing * 0.866)));
    const double golden = M_PI * (3.0 - std::sqrt(5.0));
    std::vector<glm::dvec3> lattice;
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
        lattice.push_back(d);
    }
    return lattice;
}

void LobeSurfaceBuilder::solve_fill_radii(const std::vector<std::array<int, 3>>& triangles, const std::vector<char>& on_chain)
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
    std::vector<int> row_node(static_cast<Index>(count));
    for (Index i = 0; i < n; ++i)
        if (unknown[i] >= 0) row_node[static_cast<Index>(unknown[i])] = static_cast<int>(i);
    std::vector<int> local;
    const std::vector<std::vector<int>> groups = connected_groups(adj, unknown, count, local);
    FillGroupSolver solver(adj, unknown, row_node, local, model, have_model, lo, hi);
    for (const auto& members : groups) solver.solve(members, nodes_);
}

bool LobeSurfaceBuilder::fit_radius_model(const std::vector<char>& fit, const std::vector<char>& at, std::vector<double>& model) const
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

} // namespace lobe_surface_detail

} // namespace lobe
