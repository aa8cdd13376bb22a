#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "core/errors.h"
#include "meshing/sampling.h"
#include "meshing/stitch.h"

using namespace lobe;

namespace {

constexpr double kPi = 3.14159265358979323846;
using Tri = std::array<int, 3>;
using Edge = std::pair<int, int>;

/// A raw ring at 5 mm spacing around `normal`, starting at `phase_deg` from `u`
/// (any vector not parallel to the normal); `reverse` runs it the other way round.
std::vector<glm::vec3> raw_ring(glm::dvec3 centre, double radius, glm::dvec3 normal, glm::dvec3 u,
                                double phase_deg = 0.0, bool reverse = false)
{
    normal = glm::normalize(normal);
    u = glm::normalize(u - normal * glm::dot(u, normal));
    const glm::dvec3 v = glm::cross(normal, u);
    const int n = static_cast<int>(std::lround(2.0 * kPi * radius / 0.005));
    std::vector<glm::vec3> out;
    for (int i = 0; i < n; ++i) {
        const double t = phase_deg * kPi / 180.0 + (reverse ? -1.0 : 1.0) * 2.0 * kPi * i / n;
        out.emplace_back(centre + radius * (std::cos(t) * u + std::sin(t) * v));
    }
    return out;
}

std::vector<glm::vec3> sampled_ring(glm::dvec3 centre, double radius, glm::dvec3 normal, glm::dvec3 u,
                                    double phase_deg, std::uint64_t seed, bool reverse = false)
{
    SamplingOptions o;
    o.seed = seed;
    return sample_by_curvature(raw_ring(centre, radius, normal, u, phase_deg, reverse), true, o);
}

Edge undirected(int a, int b) { return {std::min(a, b), std::max(a, b)}; }

double area(const std::vector<glm::vec3>& pos, const Tri& t)
{
    const glm::dvec3 a(pos[static_cast<std::size_t>(t[0])]), b(pos[static_cast<std::size_t>(t[1])]),
        c(pos[static_cast<std::size_t>(t[2])]);
    return 0.5 * glm::length(glm::cross(b - a, c - a));
}

// --- triangle-triangle intersection, for the "no two triangles cross" checks ---

bool segment_crosses_triangle(glm::dvec3 p, glm::dvec3 q, glm::dvec3 a, glm::dvec3 b, glm::dvec3 c, double eps)
{
    glm::dvec3 n = glm::cross(b - a, c - a);
    const double nl = glm::length(n);
    if (nl < 1e-20) return false;
    n /= nl;
    const double dp = glm::dot(p - a, n);
    const double dq = glm::dot(q - a, n);
    if ((dp > eps && dq > eps) || (dp < -eps && dq < -eps)) return false;
    if (std::abs(dp) <= eps && std::abs(dq) <= eps) return false; // in the plane: see the coplanar test
    const glm::dvec3 x = p + (dp / (dp - dq)) * (q - p);
    auto side = [&](glm::dvec3 e0, glm::dvec3 e1) {
        return glm::dot(glm::cross(e1 - e0, x - e0), n) >= -eps * glm::length(e1 - e0);
    };
    return side(a, b) && side(b, c) && side(c, a);
}

bool coplanar_triangles_overlap(const std::array<glm::dvec3, 3>& s, const std::array<glm::dvec3, 3>& t,
                                glm::dvec3 n, double eps)
{
    // Project onto the plane's dominant axes.
    const glm::dvec3 an = glm::abs(n);
    const int drop = an.x > an.y ? (an.x > an.z ? 0 : 2) : (an.y > an.z ? 1 : 2);
    auto proj = [&](glm::dvec3 p) {
        return drop == 0 ? std::array<double, 2>{p.y, p.z}
                         : (drop == 1 ? std::array<double, 2>{p.x, p.z} : std::array<double, 2>{p.x, p.y});
    };
    auto orient = [](std::array<double, 2> a, std::array<double, 2> b, std::array<double, 2> c) {
        return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    };
    const double e2 = eps * eps;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            auto a = proj(s[static_cast<std::size_t>(i)]), b = proj(s[static_cast<std::size_t>((i + 1) % 3)]);
            auto c = proj(t[static_cast<std::size_t>(j)]), d = proj(t[static_cast<std::size_t>((j + 1) % 3)]);
            const double o1 = orient(a, b, c), o2 = orient(a, b, d), o3 = orient(c, d, a), o4 = orient(c, d, b);
            if (((o1 > e2 && o2 < -e2) || (o1 < -e2 && o2 > e2)) && ((o3 > e2 && o4 < -e2) || (o3 < -e2 && o4 > e2)))
                return true;
        }
    auto inside = [&](const std::array<glm::dvec3, 3>& tri, glm::dvec3 p) {
        auto a = proj(tri[0]), b = proj(tri[1]), c = proj(tri[2]), x = proj(p);
        const double s0 = orient(a, b, x), s1 = orient(b, c, x), s2 = orient(c, a, x);
        return (s0 > e2 && s1 > e2 && s2 > e2) || (s0 < -e2 && s1 < -e2 && s2 < -e2);
    };
    for (int i = 0; i < 3; ++i)
        if (inside(t, s[static_cast<std::size_t>(i)]) || inside(s, t[static_cast<std::size_t>(i)])) return true;
    return false;
}

bool triangles_intersect(const std::array<glm::dvec3, 3>& s, const std::array<glm::dvec3, 3>& t)
{
    constexpr double eps = 1e-9;
    const glm::dvec3 ns = glm::cross(s[1] - s[0], s[2] - s[0]);
    const double nl = glm::length(ns);
    if (nl > 1e-20) {
        bool coplanar = true;
        for (const glm::dvec3& p : t) coplanar = coplanar && std::abs(glm::dot(p - s[0], ns / nl)) <= eps;
        if (coplanar) return coplanar_triangles_overlap(s, t, ns / nl, eps);
    }
    for (int i = 0; i < 3; ++i) {
        if (segment_crosses_triangle(s[static_cast<std::size_t>(i)], s[static_cast<std::size_t>((i + 1) % 3)], t[0], t[1],
                                     t[2], eps))
            return true;
        if (segment_crosses_triangle(t[static_cast<std::size_t>(i)], t[static_cast<std::size_t>((i + 1) % 3)], s[0], s[1],
                                     s[2], eps))
            return true;
    }
    return false;
}

/// Pairs of triangles that share no vertex and intersect (O(n²)).
int crossing_pairs(const std::vector<glm::vec3>& pos, const std::vector<Tri>& tris)
{
    int crossings = 0;
    for (std::size_t i = 0; i < tris.size(); ++i)
        for (std::size_t j = i + 1; j < tris.size(); ++j) {
            bool adjacent = false;
            for (int a : tris[i])
                for (int b : tris[j]) adjacent = adjacent || a == b;
            if (adjacent) continue;
            std::array<glm::dvec3, 3> s, t;
            for (std::size_t k = 0; k < 3; ++k) {
                s[k] = glm::dvec3(pos[static_cast<std::size_t>(tris[i][k])]);
                t[k] = glm::dvec3(pos[static_cast<std::size_t>(tris[j][k])]);
            }
            if (triangles_intersect(s, t)) ++crossings;
        }
    return crossings;
}

/// Checks an indexed triangle mesh: no degenerate triangle; each edge in one or two
/// triangles; the edges in one triangle are exactly `boundary`; consistent orientation
/// (no directed edge twice); every vertex's triangles form one fan; no crossings.
void expect_manifold_patch(const std::vector<glm::vec3>& pos, const std::vector<Tri>& tris,
                           const std::set<Edge>& boundary, const std::string& what)
{
    ASSERT_FALSE(tris.empty()) << what;
    std::map<Edge, int> count;
    std::set<Edge> directed;
    for (const Tri& t : tris) {
        EXPECT_TRUE(t[0] != t[1] && t[1] != t[2] && t[0] != t[2]) << what << ": repeated vertex";
        EXPECT_GT(area(pos, t), 1e-8) << what << ": degenerate triangle";
        for (int k = 0; k < 3; ++k) {
            const int a = t[static_cast<std::size_t>(k)], b = t[static_cast<std::size_t>((k + 1) % 3)];
            ++count[undirected(a, b)];
            EXPECT_TRUE(directed.insert({a, b}).second) << what << ": edge " << a << "-" << b << " twice in one direction";
        }
    }
    std::set<Edge> once;
    for (const auto& [e, c] : count) {
        EXPECT_LE(c, 2) << what << ": edge " << e.first << "-" << e.second << " in " << c << " triangles";
        if (c == 1) once.insert(e);
    }
    EXPECT_EQ(once, boundary) << what << ": boundary edges differ from the expected loops";
    // Vertex manifold: the link of each vertex (opposite edges) is one path or one cycle.
    std::map<int, std::vector<Edge>> link;
    for (const Tri& t : tris)
        for (int k = 0; k < 3; ++k)
            link[t[static_cast<std::size_t>(k)]].push_back(
                {t[static_cast<std::size_t>((k + 1) % 3)], t[static_cast<std::size_t>((k + 2) % 3)]});
    for (const auto& [v, edges] : link) {
        std::map<int, std::vector<int>> adj;
        for (const Edge& e : edges) {
            adj[e.first].push_back(e.second);
            adj[e.second].push_back(e.first);
        }
        std::set<int> seen{adj.begin()->first};
        std::vector<int> stack{adj.begin()->first};
        while (!stack.empty()) {
            const int x = stack.back();
            stack.pop_back();
            for (int y : adj[x])
                if (seen.insert(y).second) stack.push_back(y);
        }
        EXPECT_EQ(seen.size(), adj.size()) << what << ": vertex " << v << " is not manifold";
    }
    EXPECT_EQ(crossing_pairs(pos, tris), 0) << what << ": triangles cross each other";
}

/// Edges of a closed loop of vertex ids.
std::set<Edge> loop_edges(const std::vector<int>& ids)
{
    std::set<Edge> out;
    for (std::size_t i = 0; i < ids.size(); ++i) out.insert(undirected(ids[i], ids[(i + 1) % ids.size()]));
    return out;
}

/// Vertex id of each (stroke, sample); fails when a sample appears twice.
std::map<std::pair<int, int>, int> vertex_of(const StrokeStrip& s)
{
    std::map<std::pair<int, int>, int> out;
    for (std::size_t v = 0; v < s.sources.size(); ++v)
        EXPECT_TRUE(out.insert({{s.sources[v].stroke, s.sources[v].sample}, static_cast<int>(v)}).second)
            << "sample " << s.sources[v].stroke << "/" << s.sources[v].sample << " is two vertices";
    return out;
}

/// The checks for a closed–closed band.
void expect_band(const StrokeStrip& s, const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b,
                 const std::string& what)
{
    ASSERT_EQ(s.positions.size(), s.sources.size());
    ASSERT_EQ(s.positions.size(), a.size() + b.size()) << what << ": every sample is one vertex";
    const auto ids = vertex_of(s);
    for (std::size_t v = 0; v < s.positions.size(); ++v) {
        const StripVertexSource& src = s.sources[v];
        const std::vector<glm::vec3>& stroke = src.stroke == 0 ? a : b;
        ASSERT_LT(static_cast<std::size_t>(src.sample), stroke.size());
        EXPECT_EQ(s.positions[v], stroke[static_cast<std::size_t>(src.sample)]) << what << ": vertex is not a sample";
    }
    std::vector<int> la, lb;
    for (std::size_t i = 0; i < a.size(); ++i) la.push_back(ids.at({0, static_cast<int>(i)}));
    for (std::size_t i = 0; i < b.size(); ++i) lb.push_back(ids.at({1, static_cast<int>(i)}));
    std::set<Edge> boundary = loop_edges(la);
    const std::set<Edge> eb = loop_edges(lb);
    boundary.insert(eb.begin(), eb.end());
    expect_manifold_patch(s.positions, s.triangles, boundary, what);
    // A band: V − E + F = 0, and with V boundary edges that means one triangle per vertex.
    EXPECT_EQ(s.triangles.size(), a.size() + b.size()) << what;
    std::set<Edge> edges;
    for (const Tri& t : s.triangles)
        for (int k = 0; k < 3; ++k) edges.insert(undirected(t[static_cast<std::size_t>(k)], t[static_cast<std::size_t>((k + 1) % 3)]));
    EXPECT_EQ(static_cast<long>(s.positions.size()) - static_cast<long>(edges.size()) + static_cast<long>(s.triangles.size()), 0)
        << what;
}

double total_area(const StrokeStrip& s)
{
    double sum = 0.0;
    for (const Tri& t : s.triangles) sum += area(s.positions, t);
    return sum;
}

bool one_line(const std::string& s) { return !s.empty() && s.find('\n') == std::string::npos; }

const glm::dvec3 kCentre(0.1, 1.3, -0.4);
const glm::dvec3 kUp(0.0, 1.0, 0.0);
const glm::dvec3 kX(1.0, 0.0, 0.0);

} // namespace

TEST(Stitch, RingsAt60And90DegreesGiveManifoldBandsWithoutCrossings)
{
    for (double degrees : {60.0, 90.0}) {
        const double r = degrees * kPi / 180.0;
        const glm::dvec3 tilted(0.0, std::cos(r), std::sin(r)); // rotated about x: both rings contain ±x
        for (std::uint64_t seed = 0; seed < 4; ++seed) {
            const std::string what = std::to_string(static_cast<int>(degrees)) + "° seed " + std::to_string(seed);
            // Different radii around one centre: the smaller ring passes inside the larger.
            {
                const auto a = sampled_ring(kCentre, 0.15, kUp, kX, 0.0, seed);
                const auto b = sampled_ring(kCentre, 0.12, tilted, kX, 0.0, seed + 10);
                ASSERT_NE(a.size(), b.size());
                expect_band(stitch_closed_closed(a, b), a, b, what + " radii 15/12 cm");
            }
            // Equal radii: the rings cross each other twice (paper Fig. 9b).
            {
                const auto a = sampled_ring(kCentre, 0.15, kUp, kX, 3.0, seed);
                const auto b = sampled_ring(kCentre, 0.15, tilted, kX, 7.0, seed + 20);
                expect_band(stitch_closed_closed(a, b), a, b, what + " crossing");
            }
        }
    }
}

TEST(Stitch, ParallelRingsOfDifferentRadiusGiveManifoldBand)
{
    for (std::uint64_t seed = 0; seed < 4; ++seed) {
        const auto a = sampled_ring(kCentre, 0.15, kUp, kX, 0.0, seed);
        // 10 cm above, 5 cm smaller.
        const auto b = sampled_ring(kCentre + glm::dvec3(0.0, 0.1, 0.0), 0.10, kUp, kX, 0.0, seed + 5);
        const StrokeStrip s = stitch_closed_closed(a, b);
        expect_band(s, a, b, "stacked, seed " + std::to_string(seed));
        // In one plane: an annulus, every triangle coplanar with every other.
        const auto c = sampled_ring(kCentre, 0.10, kUp, kX, 0.0, seed + 5);
        expect_band(stitch_closed_closed(a, c), a, c, "annulus, seed " + std::to_string(seed));
    }
    // Exact counts: 21 and 16 samples give one triangle per sample, 37 in all.
    const auto a = sampled_ring(kCentre, 0.15, kUp, kX, 0.0, 0);
    const auto b = sampled_ring(kCentre + glm::dvec3(0.0, 0.1, 0.0), 0.10, kUp, kX, 0.0, 5);
    ASSERT_EQ(a.size(), 21u);
    ASSERT_EQ(b.size(), 16u);
    EXPECT_EQ(stitch_closed_closed(a, b).triangles.size(), 37u);
}

TEST(Stitch, RingsDrawnInOppositeDirectionsGiveTheSameBand)
{
    for (std::uint64_t seed = 0; seed < 4; ++seed) {
        const auto a = sampled_ring(kCentre, 0.15, kUp, kX, 0.0, seed);
        const auto b = sampled_ring(kCentre + glm::dvec3(0.02, 0.12, 0.0), 0.11, kUp, kX, 0.0, seed + 3);
        std::vector<glm::vec3> b_reversed(b.rbegin(), b.rend());
        const StrokeStrip same = stitch_closed_closed(a, b);
        const StrokeStrip opposite = stitch_closed_closed(a, b_reversed);
        expect_band(same, a, b, "same direction");
        expect_band(opposite, a, b_reversed, "opposite direction");
        EXPECT_EQ(same.triangles.size(), opposite.triangles.size());
        EXPECT_NEAR(total_area(same), total_area(opposite), 1e-9);
        // The same triangles, up to vertex numbering.
        auto geometry = [](const StrokeStrip& s) {
            std::set<std::array<std::array<float, 3>, 3>> out;
            for (const Tri& t : s.triangles) {
                std::array<std::array<float, 3>, 3> g;
                for (std::size_t k = 0; k < 3; ++k) {
                    const glm::vec3 p = s.positions[static_cast<std::size_t>(t[k])];
                    g[k] = {p.x, p.y, p.z};
                }
                std::sort(g.begin(), g.end());
                out.insert(g);
            }
            return out;
        };
        EXPECT_EQ(geometry(same), geometry(opposite)) << "seed " << seed;
    }
    // Both reversed to the first stroke's direction of the crossing case too.
    const glm::dvec3 tilted(0.0, 0.0, 1.0);
    const auto a = sampled_ring(kCentre, 0.15, kUp, kX, 3.0, 1);
    const auto b = sampled_ring(kCentre, 0.13, tilted, kX, 7.0, 2, true);
    expect_band(stitch_closed_closed(a, b), a, b, "90°, opposite direction");
}

TEST(Stitch, ThreeRingsStitched12And23ShareTheVerticesOfRing2)
{
    const auto r1 = sampled_ring(kCentre, 0.15, kUp, kX, 0.0, 1);
    const auto r2 = sampled_ring(kCentre + glm::dvec3(0.0, 0.1, 0.01), 0.18, glm::dvec3(0.1, 1.0, 0.0), kX, 10.0, 2);
    const auto r3 = sampled_ring(kCentre + glm::dvec3(0.0, 0.2, 0.0), 0.12, kUp, kX, 20.0, 3);
    const StrokeStrip s12 = stitch_closed_closed(r1, r2);
    const StrokeStrip s23 = stitch_closed_closed(r2, r3);
    // Merge by source: stroke 0/1 of s12 are rings 1/2, of s23 rings 2/3.
    std::map<std::pair<int, int>, int> id;
    std::vector<glm::vec3> pos;
    std::vector<Tri> tris;
    auto merge = [&](const StrokeStrip& s, int first_ring) {
        std::vector<int> local;
        for (std::size_t v = 0; v < s.positions.size(); ++v) {
            const std::pair<int, int> key{first_ring + s.sources[v].stroke, s.sources[v].sample};
            auto [it, added] = id.insert({key, static_cast<int>(pos.size())});
            if (added) pos.push_back(s.positions[v]);
            EXPECT_EQ(pos[static_cast<std::size_t>(it->second)], s.positions[v]);
            local.push_back(it->second);
        }
        for (const Tri& t : s.triangles)
            tris.push_back({local[static_cast<std::size_t>(t[0])], local[static_cast<std::size_t>(t[1])],
                            local[static_cast<std::size_t>(t[2])]});
    };
    merge(s12, 1);
    merge(s23, 2);
    EXPECT_EQ(pos.size(), r1.size() + r2.size() + r3.size()) << "ring 2's vertices are shared, not duplicated";
    std::vector<int> l1, l2, l3;
    for (std::size_t i = 0; i < r1.size(); ++i) l1.push_back(id.at({1, static_cast<int>(i)}));
    for (std::size_t i = 0; i < r2.size(); ++i) l2.push_back(id.at({2, static_cast<int>(i)}));
    for (std::size_t i = 0; i < r3.size(); ++i) l3.push_back(id.at({3, static_cast<int>(i)}));
    std::set<Edge> boundary = loop_edges(l1);
    const std::set<Edge> b3 = loop_edges(l3);
    boundary.insert(b3.begin(), b3.end());
    expect_manifold_patch(pos, tris, boundary, "rings 1-2-3");
    // Every edge of ring 2 is now inside the surface: one triangle from each strip.
    std::map<Edge, int> count;
    for (const Tri& t : tris)
        for (int k = 0; k < 3; ++k) ++count[undirected(t[static_cast<std::size_t>(k)], t[static_cast<std::size_t>((k + 1) % 3)])];
    for (const Edge& e : loop_edges(l2)) EXPECT_EQ(count[e], 2);
}

TEST(Stitch, StartPairFollowsBarycentricDirectionNotNearestPoints)
{
    // A small ring above the rim of a large one: nearest points would tie the whole small
    // ring to one side of the large one; Eq. 2 pairs equal directions.
    const glm::dvec3 small_centre = kCentre + glm::dvec3(0.25, 0.1, 0.0);
    const auto big = sampled_ring(kCentre, 0.3, kUp, kX, 0.0, 4);
    const auto small = sampled_ring(small_centre, 0.05, kUp, kX, 0.0, 5);
    const StrokeStrip s = stitch_closed_closed(small, big);
    expect_band(s, small, big, "offset rings");
    int rungs = 0;
    double mean_dot = 0.0;
    std::set<Edge> seen;
    for (const Tri& t : s.triangles)
        for (int k = 0; k < 3; ++k) {
            const int u = t[static_cast<std::size_t>(k)], v = t[static_cast<std::size_t>((k + 1) % 3)];
            if (s.sources[static_cast<std::size_t>(u)].stroke == s.sources[static_cast<std::size_t>(v)].stroke) continue;
            if (!seen.insert(undirected(u, v)).second) continue;
            const int us = s.sources[static_cast<std::size_t>(u)].stroke == 0 ? u : v;
            const int ub = us == u ? v : u;
            const glm::dvec3 ds = glm::normalize(glm::dvec3(s.positions[static_cast<std::size_t>(us)]) - small_centre);
            const glm::dvec3 db = glm::normalize(glm::dvec3(s.positions[static_cast<std::size_t>(ub)]) - kCentre);
            // Within the small ring's sample spacing (40°) plus the big ring's (11°).
            EXPECT_GT(glm::dot(ds, db), std::cos(45.0 * kPi / 180.0)) << "rung " << us << "-" << ub;
            mean_dot += glm::dot(ds, db);
            ++rungs;
        }
    EXPECT_GE(rungs, static_cast<int>(big.size()));
    EXPECT_GT(mean_dot / rungs, std::cos(20.0 * kPi / 180.0));
}

TEST(Stitch, OpenStrokeCapsRingAsDiscWithTheRingAsBoundary)
{
    const auto ring = sampled_ring(kCentre, 0.15, kUp, kX, 0.0, 7);
    // An arch over the ring in the xy plane, its ends 2 cm above the ring.
    auto arch = [](glm::dvec3 from, glm::dvec3 to, double height) {
        std::vector<glm::vec3> raw;
        const glm::dvec3 mid = 0.5 * (from + to);
        const glm::dvec3 half = 0.5 * (to - from);
        for (int i = 0; i <= 200; ++i) {
            const double t = kPi * i / 200.0;
            raw.emplace_back(mid - std::cos(t) * half + glm::dvec3(0.0, height * std::sin(t), 0.0));
        }
        return sample_by_curvature(raw, false);
    };
    auto check_disc = [&](const StrokeStrip& s, const std::vector<glm::vec3>& open, std::size_t merged,
                          const std::string& what) {
        EXPECT_EQ(s.positions.size(), ring.size() + open.size() - merged) << what;
        const auto ids = vertex_of(s);
        for (std::size_t v = 0; v < s.positions.size(); ++v) {
            const StripVertexSource& src = s.sources[v];
            EXPECT_EQ(s.positions[v], (src.stroke == 0 ? open : ring)[static_cast<std::size_t>(src.sample)]);
        }
        std::vector<int> loop;
        for (std::size_t i = 0; i < ring.size(); ++i) loop.push_back(ids.at({1, static_cast<int>(i)}));
        expect_manifold_patch(s.positions, s.triangles, loop_edges(loop), what);
        std::set<Edge> edges;
        for (const Tri& t : s.triangles)
            for (int k = 0; k < 3; ++k)
                edges.insert(undirected(t[static_cast<std::size_t>(k)], t[static_cast<std::size_t>((k + 1) % 3)]));
        // A disc: V − E + F = 1.
        EXPECT_EQ(static_cast<long>(s.positions.size()) - static_cast<long>(edges.size()) +
                      static_cast<long>(s.triangles.size()),
                  1)
            << what;
    };
    const glm::dvec3 lift(0.0, 0.02, 0.0);
    const auto hovering = arch(kCentre - glm::dvec3(0.15, 0, 0) + lift, kCentre + glm::dvec3(0.15, 0, 0) + lift, 0.12);
    check_disc(stitch_open_closed(hovering, ring), hovering, 0, "arch 2 cm above the ring");
    // Drawn the other way, and with its ends on two ring samples (they merge into them).
    std::vector<glm::vec3> backwards(hovering.rbegin(), hovering.rend());
    check_disc(stitch_open_closed(backwards, ring), backwards, 0, "arch drawn backwards");
    const std::size_t half = ring.size() / 2;
    const auto touching = arch(glm::dvec3(ring[0]), glm::dvec3(ring[half]), 0.1);
    ASSERT_EQ(touching.front(), ring[0]);
    check_disc(stitch_open_closed(touching, ring), touching, 2, "arch ending on ring samples");
}

TEST(Stitch, RawJitteredStrokesThroughClosingSamplingAndStitching)
{
    // Hand-drawn-like rings: 1 mm jitter, an overlapping tail, then the whole chain.
    auto drawn = [](glm::dvec3 centre, double radius, double degrees, std::uint64_t seed) {
        std::mt19937_64 rng(seed);
        auto noise = [&] { return (static_cast<double>(rng() >> 11) * 0x1.0p-53 - 0.5) * 0.002; };
        std::vector<glm::vec3> raw;
        const int n = static_cast<int>(2.0 * kPi * radius * degrees / 360.0 / 0.005);
        for (int i = 0; i < n; ++i) {
            const double t = i * 0.005 / radius;
            raw.emplace_back(centre + glm::dvec3(radius * std::cos(t) + noise(), noise(), radius * std::sin(t) + noise()));
        }
        return raw;
    };
    const auto raw_a = drawn(kCentre, 0.16, 385.0, 1);
    const auto raw_b = drawn(kCentre + glm::dvec3(0.01, 0.09, 0.0), 0.12, 370.0, 2);
    ASSERT_TRUE(is_closed_stroke(raw_a));
    ASSERT_TRUE(is_closed_stroke(raw_b));
    const auto a = sample_by_curvature(close_stroke(raw_a), true);
    const auto b = sample_by_curvature(close_stroke(raw_b), true);
    expect_band(stitch_closed_closed(a, b), a, b, "hand-drawn rings");
}

TEST(StitchErrors, DegenerateInputsThrowInvalidInputWithOneLineMessages)
{
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    const auto ring = sampled_ring(kCentre, 0.15, kUp, kX, 0.0, 1);
    const auto other = sampled_ring(kCentre + glm::dvec3(0, 0.1, 0), 0.1, kUp, kX, 0.0, 1);
    std::vector<glm::vec3> rotated(ring.begin() + 5, ring.end());
    rotated.insert(rotated.end(), ring.begin(), ring.begin() + 5);
    std::vector<glm::vec3> far = ring;
    for (glm::vec3& p : far) p.z -= 1200.0f;
    const std::vector<std::pair<const char*, std::vector<glm::vec3>>> bad = {
        {"three points", {{0, 0, 0}, {0.05f, 0, 0}, {0, 0.05f, 0}}},
        {"coincident", std::vector<glm::vec3>(8, glm::vec3(0.1f, 1.0f, 0.2f))},
        {"collinear", {{0, 1, 0}, {0.05f, 1, 0}, {0.1f, 1, 0}, {0.15f, 1, 0}, {0.2f, 1, 0}}},
        {"nan", {{0, 1, 0}, {0.05f, 1, 0}, {0.05f, nan, 0}, {0, 1.05f, 0}}},
        {"inf", {{0, 1, 0}, {0.05f, 1, 0}, {0.05f, 1.05f, -inf}, {0, 1.05f, 0}}},
        {"1.2 km away", far},
    };
    auto expect_invalid = [](const std::string& what, const std::function<void()>& f) {
        try {
            f();
            ADD_FAILURE() << what << " was accepted";
        } catch (const InvalidInput& e) {
            EXPECT_TRUE(one_line(e.what())) << what << ": " << e.what();
        }
    };
    for (const auto& entry : bad) {
        const auto& name = entry.first; // named copies: lambdas may not capture bindings (clang 14)
        const auto& pts = entry.second;
        expect_invalid(std::string("closed-closed first ") + name, [&] { stitch_closed_closed(pts, ring); });
        expect_invalid(std::string("closed-closed second ") + name, [&] { stitch_closed_closed(ring, pts); });
        expect_invalid(std::string("open-closed open ") + name, [&] { stitch_open_closed(pts, ring); });
        expect_invalid(std::string("open-closed closed ") + name, [&] { stitch_open_closed(other, pts); });
    }
    expect_invalid("identical strokes", [&] { stitch_closed_closed(ring, ring); });
    expect_invalid("identical strokes, other start", [&] { stitch_closed_closed(ring, rotated); });
    expect_invalid("identical open and closed", [&] { stitch_open_closed(ring, ring); });
    // Both ends of the open stroke towards the same point of the ring.
    const std::vector<glm::vec3> hook = {glm::vec3(kCentre + glm::dvec3(0.16, 0.0, 0.0)),
                                         glm::vec3(kCentre + glm::dvec3(0.1, 0.1, 0.0)),
                                         glm::vec3(kCentre + glm::dvec3(0.05, 0.1, 0.01)),
                                         glm::vec3(kCentre + glm::dvec3(0.17, 0.02, 0.0))};
    expect_invalid("open stroke ends towards one point", [&] { stitch_open_closed(hook, ring); });
    StitchOptions o;
    o.merge_fraction = -1.0;
    expect_invalid("negative merge fraction", [&] { stitch_closed_closed(ring, other, o); });
}

TEST(StitchErrors, LongStrokesStayBoundedAndFinite)
{
    // 4 points against 20,000: insertion and scoring stay fast and every output is finite.
    const std::vector<glm::vec3> square = {{0.0f, 1.0f, 0.0f}, {0.1f, 1.0f, 0.0f}, {0.1f, 1.0f, 0.1f}, {0.0f, 1.0f, 0.1f}};
    std::vector<glm::vec3> dense;
    for (int i = 0; i < 20000; ++i) {
        const double t = 2.0 * kPi * i / 20000.0;
        dense.emplace_back(0.05 + 0.2 * std::cos(t), 1.1, 0.05 + 0.2 * std::sin(t));
    }
    const StrokeStrip s = stitch_closed_closed(square, dense);
    EXPECT_EQ(s.positions.size(), 20004u);
    EXPECT_EQ(s.triangles.size(), 20004u);
    for (const glm::vec3& p : s.positions) EXPECT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
}
