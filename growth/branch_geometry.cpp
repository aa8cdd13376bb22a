#include "growth/branch_geometry.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>

#include <glm/geometric.hpp>

#include "core/errors.h"
#include "growth/leaves.h"

namespace lobe {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr float kMinRingRadius = 1e-5f; // no ring collapses to a point

/// Children of every node in one flat array (CSR): children of i are
/// child[first[i]] … child[first[i + 1] − 1], in node order.
struct ChildIndex {
    std::vector<int> first;
    std::vector<int> child;
};

ChildIndex child_index(const TreeGraph& graph)
{
    const std::size_t n = graph.nodes.size();
    ChildIndex ci;
    ci.first.assign(n + 1, 0);
    for (std::size_t i = 1; i < n; ++i) {
        const int p = graph.nodes[i].parent;
        if (p >= 0 && static_cast<std::size_t>(p) < i) ++ci.first[static_cast<std::size_t>(p) + 1];
    }
    for (std::size_t i = 0; i < n; ++i) ci.first[i + 1] += ci.first[i];
    ci.child.resize(static_cast<std::size_t>(ci.first[n]));
    std::vector<int> fill(ci.first.begin(), ci.first.end() - 1);
    for (std::size_t i = 1; i < n; ++i) {
        const int p = graph.nodes[i].parent;
        if (p >= 0 && static_cast<std::size_t>(p) < i)
            ci.child[static_cast<std::size_t>(fill[static_cast<std::size_t>(p)]++)] = static_cast<int>(i);
    }
    return ci;
}

/// A ring's centre and radius before the sweep.
struct RingSample {
    glm::vec3 centre;
    float radius;
    float arc;
};

/// Where one curve's rings are in the flat ring array.
struct RingRange {
    std::uint32_t first = 0;
    std::uint32_t count = 0;
};

/// Appends the rings of `curve` (see count_branch_rings) to `out`.
void place_rings(const BranchCurve& curve, double spacing, double cos_max_turn, std::vector<RingSample>& out)
{
    const std::size_t m = curve.points.size();
    if (m < 2) return;
    const auto& P = curve.points;
    const auto& R = curve.radii;
    auto radius_at = [&](std::size_t k) { return std::max(R[k], kMinRingRadius); };
    double s_last = 0.0; // arc of the last ring, always at curve point `a`
    std::size_t a = 0;
    out.push_back({P[0], radius_at(0), 0.0f});
    // Greedy: from the last ring, the farthest curve point within the spacing that is not
    // past a sharp turn gets the next ring; a segment longer than the spacing is split evenly.
    auto seg_len = [&](std::size_t k) { return static_cast<double>(glm::length(P[k + 1] - P[k])); };
    auto turn_cos = [&](std::size_t k) {
        const glm::vec3 d0 = P[k] - P[k - 1], d1 = P[k + 1] - P[k];
        const float l = glm::length(d0) * glm::length(d1);
        return l > 1e-20f ? static_cast<double>(glm::dot(d0, d1) / l) : 1.0;
    };
    const double limit = spacing * (1.0 + 1e-6);
    while (a + 1 < m) {
        std::size_t best = 0;
        double s_best = 0.0;
        double s = s_last;
        for (std::size_t j = a + 1; j < m; ++j) {
            s += seg_len(j - 1);
            if (s - s_last > limit) break;
            best = j;
            s_best = s;
            if (j + 1 == m || turn_cos(j) < cos_max_turn) break;
        }
        if (best > 0) {
            out.push_back({P[best], radius_at(best), static_cast<float>(s_best)});
            a = best;
            s_last = s_best;
            continue;
        }
        // The next point is farther than the spacing: split the segment evenly.
        const double gap = seg_len(a);
        const int pieces = static_cast<int>(std::ceil(gap / spacing - 1e-9));
        for (int i = 1; i < pieces; ++i) {
            const float t = static_cast<float>(i) / static_cast<float>(pieces);
            out.push_back({P[a] + (P[a + 1] - P[a]) * t, std::max(R[a] + (R[a + 1] - R[a]) * t, kMinRingRadius),
                           static_cast<float>(s_last + gap * static_cast<double>(t))});
        }
        ++a;
        s_last += gap;
        out.push_back({P[a], radius_at(a), static_cast<float>(s_last)});
    }
}

void check_mesh_options(const BranchMeshOptions& o)
{
    if (o.radial_segments < 3 || o.radial_segments > 1024)
        throw InvalidInput("branch mesh: radial_segments must be in [3, 1024]");
    if (!(o.ring_spacing_m > 0.0) || !std::isfinite(o.ring_spacing_m))
        throw InvalidInput("branch mesh: ring_spacing_m must be > 0");
}

double cos_turn_limit(const BranchMeshOptions& o) { return std::cos(std::clamp(o.max_turn_deg, 0.0, 180.0) * kPi / 180.0); }

/// Rings of every curve, one flat array.
void sample_all_rings(const std::vector<BranchCurve>& curves, const BranchMeshOptions& o,
                      std::vector<RingSample>& samples, std::vector<RingRange>& ranges)
{
    const double cos_max = cos_turn_limit(o);
    samples.clear();
    ranges.assign(curves.size(), {});
    std::size_t points = 0;
    for (const BranchCurve& c : curves) points += c.points.size();
    samples.reserve(points + points / 2 + 16);
    for (std::size_t c = 0; c < curves.size(); ++c) {
        ranges[c].first = static_cast<std::uint32_t>(samples.size());
        place_rings(curves[c], o.ring_spacing_m, cos_max, samples);
        ranges[c].count = static_cast<std::uint32_t>(samples.size() - ranges[c].first);
    }
}

std::size_t curve_triangles(const BranchCurve& curve, std::uint32_t rings, int n)
{
    if (rings < 2) return 0;
    const auto nn = static_cast<std::size_t>(n);
    return 2 * nn * (rings - 1) + nn + (curve.parent < 0 ? nn : 0);
}

/// Unit vector perpendicular to unit `t`.
glm::vec3 any_perpendicular(const glm::vec3& t)
{
    const glm::vec3 axis = std::abs(t.x) < 0.6f ? glm::vec3(1, 0, 0) : (std::abs(t.y) < 0.6f ? glm::vec3(0, 1, 0) : glm::vec3(0, 0, 1));
    return glm::normalize(axis - glm::dot(axis, t) * t);
}

/// The generalised-cylinder sweep over the kept curves.
SurfaceGeometry sweep_curves(const std::vector<BranchCurve>& curves, const std::vector<RingSample>& samples,
                             const std::vector<RingRange>& ranges, const std::vector<char>& keep, int n,
                             std::vector<BranchRing>* rings_out)
{
    SurfaceGeometry g;
    const auto nn = static_cast<std::uint32_t>(n);
    std::size_t vertex_total = 0, triangle_total = 0;
    for (std::size_t c = 0; c < curves.size(); ++c) {
        if (!keep[c] || ranges[c].count < 2) continue;
        vertex_total += ranges[c].count * nn + 1 + (curves[c].parent < 0 ? 1 : 0);
        triangle_total += curve_triangles(curves[c], ranges[c].count, n);
    }
    g.positions.resize(vertex_total);
    g.normals.resize(vertex_total);
    g.uvs.resize(vertex_total);
    g.triangles.resize(triangle_total);
    if (rings_out) {
        rings_out->clear();
        rings_out->reserve(samples.size());
    }

    // Unit circle, and the mirrored u of each column (welded seam).
    std::vector<float> cos_j(nn), sin_j(nn), u_j(nn);
    for (std::uint32_t j = 0; j < nn; ++j) {
        const double a = 2.0 * kPi * j / n;
        cos_j[j] = static_cast<float>(std::cos(a));
        sin_j[j] = static_cast<float>(std::sin(a));
        u_j[j] = static_cast<float>(1.0 - std::abs(1.0 - 2.0 * j / n));
    }

    std::vector<glm::vec3> normal_of_ring(samples.size()); // transported frame normal, for child curves
    std::vector<glm::vec3> tangent_of_ring(samples.size());
    std::vector<glm::vec3> tangents;
    // Raw pointers: the compiler keeps them in registers, unlike a vector's end.
    glm::vec3* pos = g.positions.data();
    glm::vec3* nor = g.normals.data();
    glm::vec2* uv = g.uvs.data();
    std::array<std::uint32_t, 3>* tri = g.triangles.data();
    std::uint32_t v = 0; // next vertex index

    for (std::size_t c = 0; c < curves.size(); ++c) {
        if (!keep[c] || ranges[c].count < 2) continue;
        const BranchCurve& curve = curves[c];
        const RingSample* rs = samples.data() + ranges[c].first;
        const std::uint32_t R = ranges[c].count;

        // Tangents from the neighbouring ring centres.
        tangents.resize(R);
        for (std::uint32_t k = 0; k < R; ++k) {
            const glm::vec3 d = rs[std::min(k + 1, R - 1)].centre - rs[k == 0 ? 0 : k - 1].centre;
            const float len = glm::length(d);
            if (len > 1e-12f) {
                tangents[k] = d / len;
            } else {
                const glm::vec3 d1 = rs[std::min(k + 1, R - 1)].centre - rs[k].centre;
                const float l1 = glm::length(d1);
                tangents[k] = l1 > 1e-12f ? d1 / l1 : (k > 0 ? tangents[k - 1] : glm::vec3(0, 1, 0));
            }
        }

        // First frame: the parent's at the fork, projected; else any. Then the curve's phase.
        glm::vec3 N;
        const glm::vec3 t0 = tangents[0];
        if (curve.parent >= 0 && keep[static_cast<std::size_t>(curve.parent)]) {
            const RingRange& pr = ranges[static_cast<std::size_t>(curve.parent)];
            const RingSample* ps = samples.data() + pr.first;
            const RingSample* hit = std::lower_bound(ps, ps + pr.count, curve.fork_arc_m,
                                                     [](const RingSample& r, float s) { return r.arc < s; });
            std::uint32_t k = static_cast<std::uint32_t>(hit - ps);
            if (k >= pr.count) k = pr.count - 1;
            if (k > 0 && curve.fork_arc_m - ps[k - 1].arc < ps[k].arc - curve.fork_arc_m) --k;
            const glm::vec3 pn = normal_of_ring[pr.first + k];
            const glm::vec3 pb = glm::cross(tangent_of_ring[pr.first + k], pn);
            glm::vec3 cand = pn - glm::dot(pn, t0) * t0;
            if (glm::length(cand) < 1e-3f) cand = pb - glm::dot(pb, t0) * t0;
            N = glm::length(cand) > 1e-6f ? glm::normalize(cand) : any_perpendicular(t0);
        } else {
            N = any_perpendicular(t0);
        }
        if (curve.phase != 0.0f) {
            const double delta = 2.0 * kPi * static_cast<double>(curve.phase) / n;
            N = static_cast<float>(std::cos(delta)) * N + static_cast<float>(std::sin(delta)) * glm::cross(t0, N);
        }

        std::uint32_t base_centre = 0;
        if (curve.parent < 0) { // flat base cap centre
            base_centre = v++;
            pos[base_centre] = rs[0].centre;
            nor[base_centre] = -t0;
            uv[base_centre] = glm::vec2(0.5f, 0.0f);
        }
        float vcoord = 0.0f;
        glm::vec3 t_prev = t0;
        for (std::uint32_t k = 0; k < R; ++k) {
            const glm::vec3 t = tangents[k];
            if (k > 0) {
                // Double reflection (Wang, Jüttler, Zheng and Liu 2008): rotation-minimising.
                const glm::vec3 v1 = rs[k].centre - rs[k - 1].centre;
                const float c1 = glm::dot(v1, v1);
                if (c1 > 1e-24f) {
                    const glm::vec3 nl = N - (2.0f / c1) * glm::dot(v1, N) * v1;
                    const glm::vec3 tl = t_prev - (2.0f / c1) * glm::dot(v1, t_prev) * v1;
                    const glm::vec3 v2 = t - tl;
                    const float c2 = glm::dot(v2, v2);
                    N = c2 > 1e-24f ? nl - (2.0f / c2) * glm::dot(v2, nl) * v2 : nl;
                }
                const glm::vec3 o = N - glm::dot(N, t) * t;
                const float ol = glm::length(o);
                N = ol > 1e-6f ? o / ol : any_perpendicular(t);
                const float r_avg = 0.5f * (rs[k].radius + rs[k - 1].radius);
                vcoord += std::sqrt(c1) / (static_cast<float>(kPi) * r_avg);
            }
            t_prev = t;
            const glm::vec3 B = glm::cross(t, N);
            normal_of_ring[ranges[c].first + k] = N;
            tangent_of_ring[ranges[c].first + k] = t;
            const glm::vec3 centre = rs[k].centre;
            const float r = rs[k].radius;
            if (rings_out) rings_out->push_back({centre, t, r, rs[k].arc, v, static_cast<int>(c)});
            for (std::uint32_t j = 0; j < nn; ++j) {
                const glm::vec3 d = cos_j[j] * N + sin_j[j] * B;
                pos[v + j] = centre + r * d;
                nor[v + j] = d;
                uv[v + j] = glm::vec2(u_j[j], vcoord);
            }
            if (k == 0 && curve.parent < 0) {
                for (std::uint32_t j = 0; j < nn; ++j) {
                    const std::uint32_t j1 = j + 1 == nn ? 0 : j + 1;
                    *tri++ = {base_centre, v + j1, v + j};
                }
            }
            if (k > 0) {
                const std::uint32_t a = v - nn; // previous ring
                for (std::uint32_t j = 0; j < nn; ++j) {
                    const std::uint32_t j1 = j + 1 == nn ? 0 : j + 1;
                    *tri++ = {a + j, a + j1, v + j1};
                    *tri++ = {a + j, v + j1, v + j};
                }
            }
            v += nn;
        }
        // Tip cone: apex one tip radius beyond the last ring.
        const std::uint32_t last = v - nn;
        const glm::vec3 t_end = tangents[R - 1];
        const float r_end = rs[R - 1].radius;
        const std::uint32_t apex = v++;
        pos[apex] = rs[R - 1].centre + r_end * t_end;
        nor[apex] = t_end;
        uv[apex] = glm::vec2(0.5f, vcoord + 1.0f / static_cast<float>(kPi));
        for (std::uint32_t j = 0; j < nn; ++j) {
            const std::uint32_t j1 = j + 1 == nn ? 0 : j + 1;
            *tri++ = {last + j, last + j1, apex};
        }
    }
    return g;
}

std::vector<char> keep_by_min_radius(const std::vector<BranchCurve>& curves, double min_radius)
{
    std::vector<char> keep(curves.size(), 1);
    for (std::size_t c = 0; c < curves.size(); ++c) {
        const int p = curves[c].parent;
        if (p < 0) continue;
        const bool parent_kept = static_cast<std::size_t>(p) < c && keep[static_cast<std::size_t>(p)];
        keep[c] = parent_kept && !curves[c].radii.empty() && static_cast<double>(curves[c].radii[0]) >= min_radius;
    }
    return keep;
}

bool finite(const glm::vec3& p) { return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z); }

} // namespace

std::vector<BranchChain> decompose_branch_chains(const TreeGraph& graph)
{
    std::vector<BranchChain> chains;
    const std::size_t n = graph.nodes.size();
    if (n < 2) return chains;
    const ChildIndex ci = child_index(graph);
    if (ci.first[1] == ci.first[0]) return chains; // the root has no child: no valid chain at all
    std::vector<int> chain_of(n, -1), index_in_chain(n, -1), next_rank(n, 0);
    std::vector<int> continuing(n, -1);
    for (std::size_t i = 0; i < n; ++i) {
        int best = -1;
        for (int k = ci.first[i]; k < ci.first[i + 1]; ++k) {
            const int c = ci.child[static_cast<std::size_t>(k)];
            if (best < 0 || graph.nodes[static_cast<std::size_t>(c)].radius > graph.nodes[static_cast<std::size_t>(best)].radius)
                best = c;
        }
        continuing[i] = best;
    }
    std::size_t chain_count = 1;
    for (std::size_t i = 0; i < n; ++i)
        if (ci.first[i + 1] > ci.first[i]) chain_count += static_cast<std::size_t>(ci.first[i + 1] - ci.first[i] - 1);
    chains.reserve(chain_count);
    chains.push_back({});
    chains[0].nodes.push_back(0);
    chain_of[0] = 0;
    index_in_chain[0] = 0;
    for (std::size_t i = 1; i < n; ++i) {
        const int p = graph.nodes[i].parent;
        if (p < 0 || static_cast<std::size_t>(p) >= i || chain_of[static_cast<std::size_t>(p)] < 0) continue; // unreachable
        const auto pu = static_cast<std::size_t>(p);
        if (continuing[pu] == static_cast<int>(i)) {
            BranchChain& ch = chains[static_cast<std::size_t>(chain_of[pu])];
            index_in_chain[i] = static_cast<int>(ch.nodes.size());
            chain_of[i] = chain_of[pu];
            ch.nodes.push_back(static_cast<int>(i));
        } else {
            BranchChain ch;
            ch.nodes = {p, static_cast<int>(i)};
            ch.parent_chain = chain_of[pu];
            ch.fork_index = index_in_chain[pu];
            ch.sibling_ordinal = ++next_rank[pu];
            ch.sibling_count = ci.first[pu + 1] - ci.first[pu];
            chain_of[i] = static_cast<int>(chains.size());
            index_in_chain[i] = 1;
            chains.push_back(std::move(ch));
        }
    }
    return chains;
}

std::vector<BranchCurve> smooth_branch_curves(const TreeGraph& graph, const std::vector<BranchChain>& chains,
                                              int iterations)
{
    std::vector<BranchCurve> curves(chains.size());
    std::vector<glm::vec3> smoothed(graph.nodes.size());
    std::vector<std::vector<float>> arcs(chains.size());
    std::vector<glm::vec3> tmp;
    for (std::size_t c = 0; c < chains.size(); ++c) {
        const BranchChain& ch = chains[c];
        BranchCurve& cu = curves[c];
        const std::size_t m = ch.nodes.size();
        cu.points.resize(m);
        cu.radii.resize(m);
        for (std::size_t k = 0; k < m; ++k) {
            const TreeNode& node = graph.nodes[static_cast<std::size_t>(ch.nodes[k])];
            cu.points[k] = node.position;
            cu.radii[k] = node.radius;
        }
        if (ch.parent_chain >= 0) {
            cu.points[0] = smoothed[static_cast<std::size_t>(ch.nodes[0])];
            cu.radii[0] = cu.radii.size() > 1 ? cu.radii[1] : cu.radii[0];
            cu.parent = ch.parent_chain;
            const auto& parc = arcs[static_cast<std::size_t>(ch.parent_chain)];
            cu.fork_arc_m = parc[static_cast<std::size_t>(ch.fork_index)];
            cu.phase = ch.sibling_count > 0 ? static_cast<float>(ch.sibling_ordinal) / static_cast<float>(ch.sibling_count) : 0.0f;
            if (cu.phase >= 1.0f) cu.phase = 0.0f;
        }
        for (int it = 0; it < iterations && m > 2; ++it) {
            tmp = cu.points;
            for (std::size_t k = 1; k + 1 < m; ++k)
                cu.points[k] = 0.5f * tmp[k] + 0.25f * (tmp[k - 1] + tmp[k + 1]);
        }
        for (std::size_t k = ch.parent_chain >= 0 ? 1 : 0; k < m; ++k)
            smoothed[static_cast<std::size_t>(ch.nodes[k])] = cu.points[k];
        auto& arc = arcs[c];
        arc.resize(m);
        arc[0] = 0.0f;
        double s = 0.0;
        for (std::size_t k = 1; k < m; ++k) {
            s += static_cast<double>(glm::length(cu.points[k] - cu.points[k - 1]));
            arc[k] = static_cast<float>(s);
        }
    }
    return curves;
}

std::size_t count_branch_rings(const BranchCurve& curve, const BranchMeshOptions& options)
{
    check_mesh_options(options);
    std::vector<RingSample> rings;
    place_rings(curve, options.ring_spacing_m, cos_turn_limit(options), rings);
    return rings.size();
}

SurfaceGeometry build_branch_mesh(const std::vector<BranchCurve>& curves, const BranchMeshOptions& options,
                                  std::vector<BranchRing>* rings)
{
    check_mesh_options(options);
    std::vector<RingSample> samples;
    std::vector<RingRange> ranges;
    sample_all_rings(curves, options, samples, ranges);
    return sweep_curves(curves, samples, ranges, keep_by_min_radius(curves, options.min_radius_m), options.radial_segments,
                        rings);
}

TreeGraph merge_coincident_nodes(const TreeGraph& graph, float tolerance_m, std::vector<int>* old_to_new)
{
    const std::size_t n = graph.nodes.size();
    for (std::size_t i = 0; i < n; ++i) {
        const TreeNode& node = graph.nodes[i];
        if (i == 0 ? node.parent != -1 : (node.parent < 0 || static_cast<std::size_t>(node.parent) >= i))
            throw InvalidInput("tree graph: node " + std::to_string(i) + " has parent " + std::to_string(node.parent) +
                               " (the root must have -1, every other node an earlier node)");
        if (!finite(node.position) || !std::isfinite(node.radius) || node.radius < 0.0f)
            throw InvalidInput("tree graph: node " + std::to_string(i) + " has a non-finite position or a bad radius");
    }
    TreeGraph out;
    std::vector<int> map(n, -1);
    if (n == 0) {
        if (old_to_new) old_to_new->clear();
        return out;
    }
    out.nodes.reserve(n);
    std::vector<int> first_child, next_sibling;
    first_child.reserve(n);
    next_sibling.reserve(n);
    out.nodes.push_back(graph.nodes[0]);
    first_child.push_back(-1);
    next_sibling.push_back(-1);
    map[0] = 0;
    const float tol2 = tolerance_m * tolerance_m;
    auto near = [&](const glm::vec3& a, const glm::vec3& b) {
        const glm::vec3 d = a - b;
        return glm::dot(d, d) < tol2;
    };
    for (std::size_t i = 1; i < n; ++i) {
        const TreeNode& node = graph.nodes[i];
        const int p = map[static_cast<std::size_t>(node.parent)];
        int target = -1;
        if (near(node.position, out.nodes[static_cast<std::size_t>(p)].position)) target = p;
        for (int s = first_child[static_cast<std::size_t>(p)]; target < 0 && s >= 0; s = next_sibling[static_cast<std::size_t>(s)])
            if (near(node.position, out.nodes[static_cast<std::size_t>(s)].position)) target = s;
        if (target >= 0) {
            TreeNode& t = out.nodes[static_cast<std::size_t>(target)];
            t.radius = std::max(t.radius, node.radius);
            map[i] = target;
            continue;
        }
        const int id = static_cast<int>(out.nodes.size());
        TreeNode copy = node;
        copy.parent = p;
        out.nodes.push_back(copy);
        // Prepend: order among siblings does not matter for the lookup.
        next_sibling.push_back(first_child[static_cast<std::size_t>(p)]);
        first_child.push_back(-1);
        first_child[static_cast<std::size_t>(p)] = id;
        map[i] = id;
    }
    if (old_to_new) *old_to_new = std::move(map);
    return out;
}

TreeGraph prune_twigs(const TreeGraph& graph, float min_radius_m, std::vector<int>* old_to_new)
{
    const std::size_t n = graph.nodes.size();
    const std::vector<BranchChain> chains = decompose_branch_chains(graph);
    std::vector<char> removed_chain(chains.size(), 0), removed(n, 0);
    for (std::size_t c = 1; c < chains.size(); ++c) {
        const BranchChain& ch = chains[c];
        const bool parent_removed = ch.parent_chain >= 0 && removed_chain[static_cast<std::size_t>(ch.parent_chain)];
        if (parent_removed || graph.nodes[static_cast<std::size_t>(ch.nodes[1])].radius < min_radius_m) {
            removed_chain[c] = 1;
            for (std::size_t k = 1; k < ch.nodes.size(); ++k) removed[static_cast<std::size_t>(ch.nodes[k])] = 1;
        }
    }
    TreeGraph out;
    out.nodes.reserve(n);
    std::vector<int> map(n, -1);
    for (std::size_t i = 0; i < n; ++i) {
        if (removed[i]) continue;
        const int p = graph.nodes[i].parent;
        if (i > 0 && (p < 0 || map[static_cast<std::size_t>(p)] < 0)) continue; // detached: drop
        TreeNode node = graph.nodes[i];
        node.parent = i == 0 ? -1 : map[static_cast<std::size_t>(p)];
        map[i] = static_cast<int>(out.nodes.size());
        out.nodes.push_back(node);
    }
    if (old_to_new) *old_to_new = std::move(map);
    return out;
}

BranchMeshOptions branch_lod_options(const BranchSettings& branches, int lod)
{
    BranchMeshOptions o;
    const int level = std::max(0, lod);
    o.radial_segments = level == 0 ? branches.radial_segments
                                   : std::max(3, static_cast<int>(std::lround(branches.radial_segments * std::pow(0.7, level))));
    o.ring_spacing_m = branches.ring_spacing_m * std::pow(2.0, level);
    o.max_turn_deg = std::min(60.0, 10.0 * std::pow(1.75, level));
    o.min_radius_m = 0.0;
    return o;
}

double lod_triangle_budget(int lod)
{
    return std::pow(1.0 / 3.0, std::max(0, lod));
}

TreeGeometry build_tree_geometry(const TreeGraph& graph, const BranchSettings& branches, const LeafSettings& leaves,
                                 std::uint64_t seed, const std::string& species)
{
    if (branches.lod_count < 1 || branches.lod_count > 6) throw InvalidInput("tree geometry: lod_count must be in [1, 6]");
    TreeGeometry geo;
    geo.species = species;
    for (int i = 0; i < 3; ++i) {
        geo.bark_color[static_cast<std::size_t>(i)] = static_cast<float>(branches.bark_color[i]);
        geo.leaf_color[static_cast<std::size_t>(i)] = static_cast<float>(leaves.color[i]);
    }
    geo.leaf_texture = make_leaf_texture(leaves.shape);
    check_mesh_options(branch_lod_options(branches, 0));

    const TreeGraph clean = merge_coincident_nodes(graph);
    const std::vector<BranchChain> chains = decompose_branch_chains(clean);
    const std::vector<BranchCurve> curves = smooth_branch_curves(clean, chains, std::max(0, branches.smoothing_iterations));

    std::vector<RingSample> samples;
    std::vector<RingRange> ranges;
    geo.lods.resize(static_cast<std::size_t>(branches.lod_count));

    // LOD0: everything at full resolution.
    {
        const BranchMeshOptions o = branch_lod_options(branches, 0);
        sample_all_rings(curves, o, samples, ranges);
        geo.lods[0].branches = sweep_curves(curves, samples, ranges, std::vector<char>(curves.size(), 1), o.radial_segments, nullptr);
        geo.lods[0].leaves = build_leaf_quads(graph, leaves, seed);
    }
    const double total0 = static_cast<double>(geo.lods[0].branches.triangle_count() + geo.lods[0].leaves.triangle_count());
    const double leaves0 = static_cast<double>(geo.lods[0].leaves.triangle_count());

    std::vector<double> eff(curves.size());
    std::vector<float> length(curves.size());
    std::vector<std::uint32_t> order(curves.size());
    for (int lod = 1; lod < branches.lod_count; ++lod) {
        TreeLod& out = geo.lods[static_cast<std::size_t>(lod)];
        const double budget = lod_triangle_budget(lod) * total0;
        // Leaves: fewer and larger; never more than 80 % of the budget.
        double keep = leaf_lod_keep_fraction(lod);
        if (leaves0 > 0.0 && leaves0 * keep > 0.8 * budget) keep = std::max(1e-4, 0.8 * budget / leaves0);
        out.leaves = build_leaf_quads(graph, leaves, seed, LeafLodOptions{keep});

        // Branches: coarser rings, then the thickest chains that fit the rest of the budget.
        const BranchMeshOptions o = branch_lod_options(branches, lod);
        sample_all_rings(curves, o, samples, ranges);
        const double branch_budget = budget - static_cast<double>(out.leaves.triangle_count());
        for (std::size_t c = 0; c < curves.size(); ++c) {
            const int p = curves[c].parent;
            eff[c] = p < 0 ? std::numeric_limits<double>::infinity()
                           : std::min(static_cast<double>(curves[c].radii[0]), eff[static_cast<std::size_t>(p)]);
        }
        // Thickest first; among equally thick chains (all single-tip twigs have the tip
        // radius) the longer first, so pruning thins the crown evenly instead of clearing one
        // side of it.
        for (std::size_t c = 0; c < curves.size(); ++c) length[c] = ranges[c].count ? samples[ranges[c].first + ranges[c].count - 1].arc : 0.0f;
        std::iota(order.begin(), order.end(), 0u);
        std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
            if (eff[a] != eff[b]) return eff[a] > eff[b];
            if (length[a] != length[b]) return length[a] > length[b];
            return a < b;
        });
        std::vector<char> keep_curve(curves.size(), 0);
        double used = 0.0;
        for (std::size_t i = 0; i < order.size(); ++i) {
            const std::uint32_t c = order[i];
            const int p = curves[c].parent;
            if (p >= 0 && !keep_curve[static_cast<std::size_t>(p)]) continue; // only below a kept parent
            const double t = static_cast<double>(curve_triangles(curves[c], ranges[c].count, o.radial_segments));
            if (p >= 0 && used + t > branch_budget) break; // the root curve is always kept
            used += t;
            keep_curve[c] = 1;
        }
        out.branches = sweep_curves(curves, samples, ranges, keep_curve, o.radial_segments, nullptr);
    }
    return geo;
}

} // namespace lobe
