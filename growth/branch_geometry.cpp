#include "growth/branch_geometry.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>
#include <utility>

#include <glm/geometric.hpp>

#include "core/errors.h"
#include "growth/bark_texture.h"
#include "growth/leaves.h"
#include "growth/leaf_lod.h"
#include "growth/real_scale.h"

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

/// Arc length at, and turn (cosine between the two segments) at, every point of every curve,
/// in one flat array each: curve c's points start at first[c]. Computed once, used by every LOD.
struct CurveMetrics {
    std::vector<double> arc;
    std::vector<double> turn_cos;
    std::vector<std::size_t> first;
};

CurveMetrics curve_metrics(const std::vector<BranchCurve>& curves)
{
    CurveMetrics m;
    m.first.resize(curves.size() + 1, 0);
    for (std::size_t c = 0; c < curves.size(); ++c) m.first[c + 1] = m.first[c] + curves[c].points.size();
    m.arc.resize(m.first.back());
    m.turn_cos.resize(m.first.back());
    for (std::size_t c = 0; c < curves.size(); ++c) {
        const auto& P = curves[c].points;
        const std::size_t n = P.size();
        if (n == 0) continue;
        double* S = m.arc.data() + m.first[c];
        double* turn = m.turn_cos.data() + m.first[c];
        S[0] = 0.0;
        turn[0] = turn[n - 1] = 1.0;
        for (std::size_t k = 1; k < n; ++k) S[k] = S[k - 1] + static_cast<double>(glm::length(P[k] - P[k - 1]));
        for (std::size_t k = 1; k + 1 < n; ++k) {
            const double l = (S[k] - S[k - 1]) * (S[k + 1] - S[k]);
            turn[k] = l > 1e-20 ? static_cast<double>(glm::dot(P[k] - P[k - 1], P[k + 1] - P[k])) / l : 1.0;
        }
    }
    return m;
}

/// Appends the rings of curve `c` (see count_branch_rings) to `out`.
void place_rings(const std::vector<BranchCurve>& curves, const CurveMetrics& metrics, std::size_t c, double spacing,
                 double cos_max_turn, std::vector<RingSample>& out)
{
    const BranchCurve& curve = curves[c];
    const std::size_t m = curve.points.size();
    if (m < 2) return;
    const auto& P = curve.points;
    const auto& R = curve.radii;
    const double* S = metrics.arc.data() + metrics.first[c];
    const double* turn = metrics.turn_cos.data() + metrics.first[c];
    auto radius_at = [&](std::size_t k) { return std::max(R[k], kMinRingRadius); };
    std::size_t a = 0; // the last ring is at curve point a
    out.push_back({P[0], radius_at(0), 0.0f});
    // Greedy: from the last ring, the farthest curve point within the spacing that is not
    // past a sharp turn gets the next ring; a segment longer than the spacing is split evenly.
    const double limit = spacing * (1.0 + 1e-6);
    while (a + 1 < m) {
        std::size_t best = 0;
        for (std::size_t j = a + 1; j < m && S[j] - S[a] <= limit; ++j) {
            best = j;
            if (turn[j] < cos_max_turn) break;
        }
        if (best > 0) {
            out.push_back({P[best], radius_at(best), static_cast<float>(S[best])});
            a = best;
            continue;
        }
        // The next point is farther than the spacing: split the segment evenly.
        const double gap = S[a + 1] - S[a];
        const int pieces = static_cast<int>(std::ceil(gap / spacing - 1e-9));
        for (int i = 1; i < pieces; ++i) {
            const float t = static_cast<float>(i) / static_cast<float>(pieces);
            out.push_back({P[a] + (P[a + 1] - P[a]) * t, std::max(R[a] + (R[a + 1] - R[a]) * t, kMinRingRadius),
                           static_cast<float>(S[a] + gap * static_cast<double>(t))});
        }
        ++a;
        out.push_back({P[a], radius_at(a), static_cast<float>(S[a])});
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
void sample_all_rings(const std::vector<BranchCurve>& curves, const CurveMetrics& metrics, const BranchMeshOptions& o,
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
        place_rings(curves, metrics, c, o.ring_spacing_m, cos_max, samples);
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

/// Four floats in one SIMD register (GCC/Clang vector extension: SSE on x86-64, NEON on
/// ARM), for the ring vertex loop.
typedef float V4 __attribute__((vector_size(16)));
inline V4 load4(const float* p)
{
    V4 v;
    std::memcpy(&v, p, sizeof v);
    return v;
}
inline void store4(float* p, const V4& v) { std::memcpy(p, &v, sizeof v); }
typedef std::uint32_t U4 __attribute__((vector_size(16)));

/// Working arrays of the sweep, kept across curves and LODs: the current curve's ring
/// tangents, the transported frame of every ring, and the batch of curves not yet appended to
/// the mesh (when it is not written in place).
struct CurveScratch {
    std::vector<glm::vec3> tangent;
    std::vector<glm::vec3> normal_of_ring, tangent_of_ring;
    std::vector<glm::vec3> pos, nor;
    std::vector<glm::vec2> uv;
    std::vector<std::array<std::uint32_t, 3>> tri;
    std::size_t used_v = 0, used_f = 0;
    /// Room for `rings` tangents, and for `vertices` and `triangles` after what is used.
    void fit(std::size_t rings, std::size_t vertices, std::size_t triangles)
    {
        if (tangent.size() < rings) tangent.resize(rings);
        if (pos.size() < used_v + vertices) {
            const std::size_t n = std::max(used_v + vertices, 2 * pos.size());
            pos.resize(n);
            nor.resize(n);
            uv.resize(n);
        }
        if (tri.size() < used_f + triangles) tri.resize(std::max(used_f + triangles, 2 * tri.size()));
    }
};

template <class T>
void append(std::vector<T>& out, const std::vector<T>& from, std::size_t count)
{
    out.insert(out.end(), from.data(), from.data() + count);
}

/// Appends the scratch's batch to the mesh.
void flush(CurveScratch& scratch, SurfaceGeometry& g)
{
    append(g.positions, scratch.pos, scratch.used_v);
    append(g.normals, scratch.nor, scratch.used_v);
    append(g.uvs, scratch.uv, scratch.used_v);
    append(g.triangles, scratch.tri, scratch.used_f);
    scratch.used_v = scratch.used_f = 0;
}

/// Per-ring tables of the sweep for rings of n vertices. Ring vertices are written in blocks of
/// four (12 position floats, 8 uv floats), so the loops that write them have fixed lengths the
/// compiler vectorises. A ring of n vertices writes ⌈n/4⌉ blocks; the excess lands where the
/// next ring (or the apex) is written after it.
struct RingTables {
    std::uint32_t n = 0;
    std::uint32_t blocks = 0;
    /// Per block: the unit circle's cos and sin and the mirrored u of each column (welded
    /// seam), spread to the float layout of the arrays.
    std::vector<float> cos12, sin12, u8;
    /// Tube triangles between a ring and the previous one, as offsets from the previous ring's
    /// first vertex; counter-clockwise seen from outside. Padded to whole 4-index lanes; the
    /// excess lands where the next triangles go.
    std::uint32_t quad_lanes = 0;
    std::vector<std::uint32_t> quad_template;
};

RingTables ring_tables(int n)
{
    RingTables rt;
    const auto nn = static_cast<std::uint32_t>(n);
    rt.n = nn;
    rt.blocks = (nn + 3) / 4;
    rt.cos12.resize(rt.blocks * 12);
    rt.sin12.resize(rt.blocks * 12);
    rt.u8.resize(rt.blocks * 8);
    for (std::uint32_t i = 0; i < rt.blocks * 12; ++i) {
        const std::uint32_t j = i / 3;
        const double a = 2.0 * kPi * j / n;
        rt.cos12[i] = j < nn ? static_cast<float>(std::cos(a)) : 0.0f;
        rt.sin12[i] = j < nn ? static_cast<float>(std::sin(a)) : 0.0f;
    }
    for (std::uint32_t i = 0; i < rt.blocks * 8; i += 2) {
        const std::uint32_t j = i / 2;
        rt.u8[i] = j < nn ? static_cast<float>(1.0 - std::abs(1.0 - 2.0 * j / n)) : 0.0f;
        rt.u8[i + 1] = 0.0f;
    }
    rt.quad_lanes = (6 * nn + 3) / 4;
    rt.quad_template.assign(4 * rt.quad_lanes, 0);
    for (std::uint32_t j = 0; j < nn; ++j) {
        const std::uint32_t j1 = j + 1 == nn ? 0 : j + 1;
        const std::uint32_t t[6] = {j, j1, nn + j1, j, nn + j1, nn + j};
        std::copy(t, t + 6, rt.quad_template.begin() + 6 * j);
    }
    return rt;
}

/// Makes `g` ready for the sweep's `vertex_total` vertices and `triangle_total` triangles.
/// Each array is written once. When `g` already holds at least as many elements (storage
/// kept from an earlier build), the curves are written in place (returns true); otherwise
/// they go to a small cached scratch that is appended in batches (a resize would first fill
/// fresh memory with zeros). Both leave room (cut off at the end) for the last SIMD lanes'
/// overrun.
bool prepare_sweep_output(SurfaceGeometry& g, std::size_t vertex_total, std::size_t triangle_total)
{
    auto holds = [](const auto& v, std::size_t count, std::size_t pad) {
        return v.size() >= count && v.capacity() >= count + pad; // only the padding gets initialised
    };
    const bool in_place = holds(g.positions, vertex_total, 4) && holds(g.normals, vertex_total, 4) &&
                          holds(g.uvs, vertex_total, 4) && holds(g.triangles, triangle_total, 2);
    if (in_place) {
        g.positions.resize(vertex_total + 4);
        g.normals.resize(vertex_total + 4);
        g.uvs.resize(vertex_total + 4);
        g.triangles.resize(triangle_total + 2);
    } else {
        g.positions.clear();
        g.normals.clear();
        g.uvs.clear();
        g.triangles.clear();
        // Room for the padding too, so the next build into this storage can go in place.
        g.positions.reserve(vertex_total + 4);
        g.normals.reserve(vertex_total + 4);
        g.uvs.reserve(vertex_total + 4);
        g.triangles.reserve(triangle_total + 2);
    }
    return in_place;
}

/// Tangents of a curve's R rings from the neighbouring ring centres.
void ring_tangents(const RingSample* rs, std::uint32_t R, glm::vec3* tangents)
{
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
}

/// The normal of curve c's first frame (its tangent `t0`): the parent's transported normal at
/// the fork, projected (when the parent is kept), else any; then turned by the curve's phase.
glm::vec3 first_frame_normal(const std::vector<BranchCurve>& curves, const std::vector<RingSample>& samples,
                             const std::vector<RingRange>& ranges, const std::vector<char>& keep, std::size_t c,
                             const glm::vec3& t0, const glm::vec3* normal_of_ring, const glm::vec3* tangent_of_ring, int n)
{
    const BranchCurve& curve = curves[c];
    glm::vec3 N;
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
    return N;
}

/// Double reflection (Wang, Jüttler, Zheng and Liu 2008): the rotation-minimising frame's
/// normal `N` carried along the step `v1` (c1 = |v1|²) from a ring with tangent `t_prev` to
/// one with tangent `t`, then made exactly normal to `t`.
glm::vec3 transport_normal(glm::vec3 N, const glm::vec3& v1, float c1, const glm::vec3& t_prev, const glm::vec3& t)
{
    if (c1 > 1e-24f) {
        const glm::vec3 nl = N - (2.0f / c1) * glm::dot(v1, N) * v1;
        const glm::vec3 tl = t_prev - (2.0f / c1) * glm::dot(v1, t_prev) * v1;
        const glm::vec3 v2 = t - tl;
        const float c2 = glm::dot(v2, v2);
        N = c2 > 1e-24f ? nl - (2.0f / c2) * glm::dot(v2, nl) * v2 : nl;
    }
    const glm::vec3 o = N - glm::dot(N, t) * t;
    const float ol = glm::length(o);
    return ol > 1e-6f ? o / ol : any_perpendicular(t);
}

/// One ring's vertices (centre + r · (cos·N + sin·B), normals, uvs at v = `vcoord`), written
/// in blocks of four from `pos`, `nor`, `uv`.
void write_ring_vertices(const RingTables& rt, const glm::vec3& N, const glm::vec3& B, const glm::vec3& centre, float r,
                         float vcoord, glm::vec3* pos, glm::vec3* nor, glm::vec2* uv)
{
    // Four vertices = three 4-float lanes of positions (and of normals): the frame
    // and centre repeat with period 3 across the lanes.
    const V4 n0{N.x, N.y, N.z, N.x}, n1{N.y, N.z, N.x, N.y}, n2{N.z, N.x, N.y, N.z};
    const V4 b0{B.x, B.y, B.z, B.x}, b1{B.y, B.z, B.x, B.y}, b2{B.z, B.x, B.y, B.z};
    const V4 c0{centre.x, centre.y, centre.z, centre.x}, c1{centre.y, centre.z, centre.x, centre.y},
        c2{centre.z, centre.x, centre.y, centre.z};
    const V4 rv{r, r, r, r}, vv{0.0f, vcoord, 0.0f, vcoord};
    float* p = &pos->x;
    float* q = &nor->x;
    float* w = &uv->x;
    for (std::uint32_t b = 0; b < rt.blocks; ++b) {
        const float* cb = rt.cos12.data() + 12 * b;
        const float* sb = rt.sin12.data() + 12 * b;
        const V4 d0 = load4(cb) * n0 + load4(sb) * b0;
        const V4 d1 = load4(cb + 4) * n1 + load4(sb + 4) * b1;
        const V4 d2 = load4(cb + 8) * n2 + load4(sb + 8) * b2;
        store4(q + 12 * b, d0);
        store4(q + 12 * b + 4, d1);
        store4(q + 12 * b + 8, d2);
        store4(p + 12 * b, c0 + rv * d0);
        store4(p + 12 * b + 4, c1 + rv * d1);
        store4(p + 12 * b + 8, c2 + rv * d2);
        const float* ub = rt.u8.data() + 8 * b;
        store4(w + 8 * b, load4(ub) + vv);
        store4(w + 8 * b + 4, load4(ub + 4) + vv);
    }
}

/// The 2n tube triangles between the ring whose first vertex is `previous` and the next one,
/// written in whole 4-index lanes from `tri`.
void write_tube_triangles(const RingTables& rt, std::uint32_t previous, std::array<std::uint32_t, 3>* tri)
{
    std::uint32_t* t2 = tri->data();
    const std::uint32_t* tq = rt.quad_template.data();
    const U4 av{previous, previous, previous, previous};
    for (std::uint32_t i = 0; i < rt.quad_lanes; ++i) {
        U4 x;
        std::memcpy(&x, tq + 4 * i, sizeof x);
        x += av;
        std::memcpy(t2 + 4 * i, &x, sizeof x);
    }
}

/// Where one curve's vertices and triangles are written (in the mesh, or in the scratch batch).
struct CurveOutput {
    glm::vec3* pos;
    glm::vec3* nor;
    glm::vec2* uv;
    std::array<std::uint32_t, 3>* tri;
};

/// Sweeps curve c (R ≥ 2 rings) into `out`: the root's base cap, its rings with their frames
/// (stored per ring for the curves that fork from it), the tube between them and the tip cone.
/// `base` is the curve's first vertex in the mesh. Returns the vertices and triangles written.
std::pair<std::uint32_t, std::size_t> sweep_curve(const std::vector<BranchCurve>& curves,
                                                  const std::vector<RingSample>& samples,
                                                  const std::vector<RingRange>& ranges, const std::vector<char>& keep,
                                                  std::size_t c, const RingTables& rt, std::uint32_t base,
                                                  CurveOutput out, CurveScratch& scratch,
                                                  std::vector<BranchRing>* rings_out)
{
    const std::uint32_t nn = rt.n;
    const RingSample* rs = samples.data() + ranges[c].first;
    const std::uint32_t R = ranges[c].count;
    const bool root = curves[c].parent < 0;
    glm::vec3* const tangents = scratch.tangent.data();
    glm::vec3* const normal_of_ring = scratch.normal_of_ring.data();
    glm::vec3* const tangent_of_ring = scratch.tangent_of_ring.data();
    ring_tangents(rs, R, tangents);
    const glm::vec3 t0 = tangents[0];
    glm::vec3 N = first_frame_normal(curves, samples, ranges, keep, c, t0, normal_of_ring, tangent_of_ring,
                                     static_cast<int>(nn));

    std::uint32_t v = 0; // local vertex index
    std::size_t f = 0;
    if (root) { // flat base cap centre
        out.pos[0] = rs[0].centre;
        out.nor[0] = -t0;
        out.uv[0] = glm::vec2(0.5f, 0.0f);
        v = 1;
    }
    float vcoord = 0.0f;
    glm::vec3 t_prev = t0;
    for (std::uint32_t k = 0; k < R; ++k) {
        const glm::vec3 t = tangents[k];
        if (k > 0) {
            const glm::vec3 v1 = rs[k].centre - rs[k - 1].centre;
            const float c1 = glm::dot(v1, v1);
            N = transport_normal(N, v1, c1, t_prev, t);
            const float r_avg = 0.5f * (rs[k].radius + rs[k - 1].radius);
            vcoord += std::sqrt(c1) / (static_cast<float>(kPi) * r_avg);
        }
        t_prev = t;
        const glm::vec3 B = glm::cross(t, N);
        normal_of_ring[ranges[c].first + k] = N;
        tangent_of_ring[ranges[c].first + k] = t;
        const glm::vec3 centre = rs[k].centre;
        const float r = rs[k].radius;
        if (rings_out) rings_out->push_back({centre, t, r, rs[k].arc, base + v, static_cast<int>(c)});
        write_ring_vertices(rt, N, B, centre, r, vcoord, out.pos + v, out.nor + v, out.uv + v);
        const std::uint32_t gv = base + v; // this ring's first vertex in the mesh
        if (k == 0 && root) {
            for (std::uint32_t j = 0; j + 1 < nn; ++j) out.tri[f++] = {base, gv + j + 1, gv + j};
            out.tri[f++] = {base, gv, gv + nn - 1};
        }
        if (k > 0) {
            write_tube_triangles(rt, gv - nn, out.tri + f);
            f += 2 * nn;
        }
        v += nn;
    }
    // Tip cone: apex one tip radius beyond the last ring.
    const std::uint32_t last = base + v - nn;
    const glm::vec3 t_end = tangents[R - 1];
    const float r_end = rs[R - 1].radius;
    out.pos[v] = rs[R - 1].centre + r_end * t_end;
    out.nor[v] = t_end;
    out.uv[v] = glm::vec2(0.5f, vcoord + 1.0f / static_cast<float>(kPi));
    const std::uint32_t apex = base + v;
    ++v;
    for (std::uint32_t j = 0; j + 1 < nn; ++j) out.tri[f++] = {last + j, last + j + 1, apex};
    out.tri[f++] = {last + nn - 1, last, apex};
    return {v, f};
}

/// The generalised-cylinder sweep over the kept curves, into `g` (its storage reused).
void sweep_curves(const std::vector<BranchCurve>& curves, const std::vector<RingSample>& samples,
                  const std::vector<RingRange>& ranges, const std::vector<char>& keep, int n, SurfaceGeometry& g,
                  CurveScratch& scratch, std::vector<BranchRing>* rings_out)
{
    const auto nn = static_cast<std::uint32_t>(n);
    std::size_t vertex_total = 0, triangle_total = 0;
    for (std::size_t c = 0; c < curves.size(); ++c) {
        if (!keep[c] || ranges[c].count < 2) continue;
        vertex_total += ranges[c].count * nn + 1 + (curves[c].parent < 0 ? 1 : 0);
        triangle_total += curve_triangles(curves[c], ranges[c].count, n);
    }
    const bool in_place = prepare_sweep_output(g, vertex_total, triangle_total);
    if (rings_out) {
        rings_out->clear();
        rings_out->reserve(samples.size());
    }
    const RingTables rt = ring_tables(n);
    // Transported frame of every ring, looked up by child curves at their fork.
    if (scratch.normal_of_ring.size() < samples.size()) {
        scratch.normal_of_ring.resize(samples.size());
        scratch.tangent_of_ring.resize(samples.size());
    }
    std::size_t written_v = 0, written_f = 0;
    for (std::size_t c = 0; c < curves.size(); ++c) {
        if (!keep[c] || ranges[c].count < 2) continue;
        const std::uint32_t R = ranges[c].count;
        const std::size_t curve_vertices = R * nn + 1 + (curves[c].parent < 0 ? 1 : 0);
        scratch.fit(R, in_place ? 0 : curve_vertices + 4, in_place ? 0 : curve_triangles(curves[c], R, n) + 2);
        const CurveOutput out =
            in_place ? CurveOutput{g.positions.data() + written_v, g.normals.data() + written_v, g.uvs.data() + written_v,
                                   g.triangles.data() + written_f}
                     : CurveOutput{scratch.pos.data() + scratch.used_v, scratch.nor.data() + scratch.used_v,
                                   scratch.uv.data() + scratch.used_v, scratch.tri.data() + scratch.used_f};
        const auto [v, f] = sweep_curve(curves, samples, ranges, keep, c, rt, static_cast<std::uint32_t>(written_v), out,
                                        scratch, rings_out);
        written_v += v;
        written_f += f;
        if (!in_place) {
            scratch.used_v += v;
            scratch.used_f += f;
            if (scratch.used_v >= 8192) flush(scratch, g);
        }
    }
    if (in_place) {
        g.positions.resize(written_v);
        g.normals.resize(written_v);
        g.uvs.resize(written_v);
        g.triangles.resize(written_f);
    } else {
        flush(scratch, g);
    }
}

std::vector<char> keep_by_min_radius(const std::vector<BranchCurve>& curves, double min_radius)
{
    std::vector<char> keep(curves.size(), 1);
    for (std::size_t c = 0; c < curves.size(); ++c) {
        const int p = curves[c].parent;
        if (c == 0) continue; // the root curve
        if (p < 0) { // from a Detached node: by its own radius
            keep[c] = !curves[c].radii.empty() && static_cast<double>(curves[c].radii[0]) >= min_radius;
            continue;
        }
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
            if (graph.nodes[static_cast<std::size_t>(c)].kind == TreeNodeKind::Detached) continue; // starts its own chain
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
        if (p < 0 || static_cast<std::size_t>(p) >= i) continue; // unreachable
        const auto pu = static_cast<std::size_t>(p);
        if (graph.nodes[i].kind == TreeNodeKind::Detached) {
            // Nothing joins it to its parent: a chain of its own, like the root's, when a
            // drawn branch leaves it.
            if (continuing[i] < 0) continue;
            BranchChain ch;
            ch.nodes = {static_cast<int>(i)};
            chain_of[i] = static_cast<int>(chains.size());
            index_in_chain[i] = 0;
            chains.push_back(std::move(ch));
        } else if (chain_of[pu] < 0) {
            continue; // unreachable
        } else if (continuing[pu] == static_cast<int>(i)) {
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
    const std::vector<BranchCurve> one{curve};
    place_rings(one, curve_metrics(one), 0, options.ring_spacing_m, cos_turn_limit(options), rings);
    return rings.size();
}

SurfaceGeometry build_branch_mesh(const std::vector<BranchCurve>& curves, const BranchMeshOptions& options,
                                  std::vector<BranchRing>* rings)
{
    check_mesh_options(options);
    std::vector<RingSample> samples;
    std::vector<RingRange> ranges;
    sample_all_rings(curves, curve_metrics(curves), options, samples, ranges);
    SurfaceGeometry g;
    CurveScratch scratch;
    sweep_curves(curves, samples, ranges, keep_by_min_radius(curves, options.min_radius_m), options.radial_segments, g,
                 scratch, rings);
    return g;
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
        // A chain from a fork starts at the fork node, which stays; one from a Detached node
        // starts at that node.
        const std::size_t own = ch.parent_chain >= 0 ? 1 : 0;
        if (parent_removed || graph.nodes[static_cast<std::size_t>(ch.nodes[1])].radius < min_radius_m) {
            removed_chain[c] = 1;
            for (std::size_t k = own; k < ch.nodes.size(); ++k) removed[static_cast<std::size_t>(ch.nodes[k])] = 1;
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
    if (lod <= 0) return 1.0;
    if (lod == 1) return 0.27;
    return 0.072 * std::pow(0.3, lod - 2);
}

void build_tree_geometry_into(TreeGeometry& geo, const TreeGraph& graph, const BranchSettings& branches,
                              const LeafSettings& leaves, std::uint64_t seed, const std::string& species,
                              const LobeLeafOverrides& lobe_leaves, const std::vector<PlacedLeaf>* placed_leaves)
{
    if (branches.lod_count < 1 || branches.lod_count > 6) throw InvalidInput("tree geometry: lod_count must be in [1, 6]");
    check_mesh_options(branch_lod_options(branches, 0));
    RgbaImage texture = make_leaf_atlas(make_leaf_texture(leaves.shape));
    static const RgbaImage bark = make_bark_texture(); // the same for every tree
    const TreeGraph clean = merge_coincident_nodes(graph);
    const std::vector<BranchChain> chains = decompose_branch_chains(clean);
    const std::vector<BranchCurve> curves = smooth_branch_curves(clean, chains, std::max(0, branches.smoothing_iterations));
    const CurveMetrics metrics = curve_metrics(curves);

    // LOD0's rings, and what LOD0 would hold before anything is allocated for it
    // (kMaxTreeTriangles): two triangles per ring segment per radial segment, two per leaf.
    std::vector<RingSample> samples;
    std::vector<RingRange> ranges;
    const BranchMeshOptions lod0 = branch_lod_options(branches, 0);
    sample_all_rings(curves, metrics, lod0, samples, ranges);
    {
        // Leaves: at most the most leaves per tip (the tree's or a lobe's) at every tip.
        int most = std::max(0, leaves.per_node);
        for (const LobeLeafOverride& o : lobe_leaves) most = std::max(most, o.per_node.value_or(0));
        const double leaf_count = placed_leaves ? static_cast<double>(placed_leaves->size())
                                  : spread_leaf_count(graph, leaves, most);
        double triangles = 2.0 * leaf_count;
        for (const RingRange& r : ranges)
            if (r.count >= 2) triangles += 2.0 * lod0.radial_segments * (r.count - 1.0) + 2.0 * lod0.radial_segments;
        if (triangles > static_cast<double>(kMaxTreeTriangles))
            throw InvalidInput("tree geometry: LOD0 would have about " + std::to_string(static_cast<long long>(triangles)) +
                               " triangles, more than the " + std::to_string(kMaxTreeTriangles) +
                               " allowed (lower max_nodes, radial_segments or leaves per node)");
    }
    LeafCloud cloud =
        placed_leaves ? make_placed_leaf_cloud(*placed_leaves, seed) : make_leaf_cloud(graph, leaves, seed, lobe_leaves);
    if (!placed_leaves) spread_leaves_along_shoots(cloud, graph, leaves); // leaf density along long shoots

    // Nothing can throw past this point: `geo` is only changed when the whole build succeeds.
    geo.species = species;
    for (int i = 0; i < 3; ++i) {
        geo.bark_color[static_cast<std::size_t>(i)] = static_cast<float>(branches.bark_color[i]);
        geo.leaf_color[static_cast<std::size_t>(i)] = static_cast<float>(leaves.color[i]);
    }
    geo.leaf_texture = std::move(texture);
    geo.bark_texture = bark;
    geo.lods.resize(static_cast<std::size_t>(branches.lod_count));

    CurveScratch scratch;

    // LOD0: everything at full resolution (its rings are sampled above).
    {
        const BranchMeshOptions& o = lod0;
        sweep_curves(curves, samples, ranges, std::vector<char>(curves.size(), 1), o.radial_segments, geo.lods[0].branches,
                     scratch, nullptr);
        emit_leaf_quads(cloud, LeafLodOptions{}, geo.lods[0].leaves);
        use_single_leaf_half(geo.lods[0].leaves);
    }
    const double total0 = static_cast<double>(geo.lods[0].branches.triangle_count() + geo.lods[0].leaves.triangle_count());
    const double leaves0 = static_cast<double>(geo.lods[0].leaves.triangle_count());

    std::vector<double> eff(curves.size());
    std::vector<float> length(curves.size());
    std::vector<std::uint32_t> order(curves.size());
    std::vector<char> keep_curve(curves.size());
    for (int lod = 1; lod < branches.lod_count; ++lod) {
        TreeLod& out = geo.lods[static_cast<std::size_t>(lod)];
        const double budget = lod_triangle_budget(lod) * total0;
        // Leaves: merged into cluster cards, as many as leaf_lod_keep_fraction of LOD0's
        // leaves but never more than 80 % of the budget.
        const double cards = std::min(leaf_lod_keep_fraction(lod) * leaves0 / 2.0, 0.8 * budget / 2.0);
        emit_leaf_cluster_cards(cloud, static_cast<std::size_t>(std::max(1.0, std::floor(cards))), out.leaves);

        // Branches: coarser rings, then the thickest chains that fit the rest of the budget.
        const BranchMeshOptions o = branch_lod_options(branches, lod);
        sample_all_rings(curves, metrics, o, samples, ranges);
        const double branch_budget = budget - static_cast<double>(out.leaves.triangle_count());
        for (std::size_t c = 0; c < curves.size(); ++c) {
            const int p = curves[c].parent;
            // The root curve is always kept; a curve from a Detached node (p < 0, c > 0) is
            // pruned by its own radius.
            eff[c] = c == 0  ? std::numeric_limits<double>::infinity()
                     : p < 0 ? static_cast<double>(curves[c].radii[0])
                             : std::min(static_cast<double>(curves[c].radii[0]), eff[static_cast<std::size_t>(p)]);
            length[c] = ranges[c].count ? samples[ranges[c].first + ranges[c].count - 1].arc : 0.0f;
        }
        double all = 0.0;
        for (std::size_t c = 0; c < curves.size(); ++c)
            all += static_cast<double>(curve_triangles(curves[c], ranges[c].count, o.radial_segments));
        if (all <= branch_budget) { // the coarser rings alone meet the budget: no pruning
            std::fill(keep_curve.begin(), keep_curve.end(), 1);
            sweep_curves(curves, samples, ranges, keep_curve, o.radial_segments, out.branches, scratch, nullptr);
            continue;
        }
        // Thickest first; among equally thick chains (all single-tip twigs have the tip
        // radius) the longer first, so pruning thins the crown evenly instead of clearing one
        // side of it.
        std::iota(order.begin(), order.end(), 0u);
        std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
            if (eff[a] != eff[b]) return eff[a] > eff[b];
            if (length[a] != length[b]) return length[a] > length[b];
            return a < b;
        });
        std::fill(keep_curve.begin(), keep_curve.end(), 0);
        double used = 0.0;
        for (std::size_t i = 0; i < order.size(); ++i) {
            const std::uint32_t c = order[i];
            const int p = curves[c].parent;
            if (p >= 0 && !keep_curve[static_cast<std::size_t>(p)]) continue; // only below a kept parent
            const double t = static_cast<double>(curve_triangles(curves[c], ranges[c].count, o.radial_segments));
            if (c != 0 && used + t > branch_budget) break; // the root curve is always kept
            used += t;
            keep_curve[c] = 1;
        }
        sweep_curves(curves, samples, ranges, keep_curve, o.radial_segments, out.branches, scratch, nullptr);
    }
}

TreeGeometry build_tree_geometry(const TreeGraph& graph, const BranchSettings& branches, const LeafSettings& leaves,
                                 std::uint64_t seed, const std::string& species, const LobeLeafOverrides& lobe_leaves,
                                 const std::vector<PlacedLeaf>* placed_leaves)
{
    TreeGeometry geo;
    build_tree_geometry_into(geo, graph, branches, leaves, seed, species, lobe_leaves, placed_leaves);
    return geo;
}

} // namespace lobe
