#include "growth/grow.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>
#include <utility>

#include <glm/geometric.hpp>
#include <nanoflann.hpp>

#include "core/errors.h"
#include "core/random.h"
#include "growth/mesh_raycast.h"
#include "growth/species_form.h"

namespace lobe {

namespace {

constexpr double kPi = std::numbers::pi;
// A subtree segment that would leave the lobe ends at this fraction of the way to the surface.
constexpr float kClipFraction = 0.8f;

// Each node's random choices come from a stream keyed by (seed, lobe, node key, growth, piece)
// with the SplitMix64 hash (core/random.h), so they depend only on that key, never on how
// many numbers other nodes drew.
class Stream {
public:
    Stream(std::uint64_t seed, std::int64_t lobe, std::uint64_t node_key, int growth, std::size_t piece)
        : state_(splitmix64(splitmix64(splitmix64(splitmix64(seed) ^ static_cast<std::uint64_t>(lobe)) ^ node_key) ^
                     (static_cast<std::uint64_t>(growth) << 32 | piece)))
    {
    }
    double uniform() { return unit_interval(splitmix64(state_++)); } // [0, 1)

private:
    std::uint64_t state_;
};

// nanoflann adaptor over some of the node positions.
struct NodeSubset {
    const std::vector<glm::vec3>* points = nullptr;
    const std::vector<std::uint32_t>* ids = nullptr;
    std::size_t kdtree_get_point_count() const { return ids->size(); }
    float kdtree_get_pt(std::size_t i, std::size_t dim) const { return (*points)[(*ids)[i]][static_cast<int>(dim)]; }
    template <class Box>
    bool kdtree_get_bbox(Box&) const { return false; }
};
using NodeIndex = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, NodeSubset>, NodeSubset, 3,
                                                      std::uint32_t>;

// Rotation taking +Y to `dir`, turned by `roll` about it.
struct Frame {
    glm::vec3 x, y, z;
    glm::vec3 apply(const glm::vec3& v) const { return v.x * x + v.y * y + v.z * z; }
};
Frame frame_along(const glm::vec3& dir, double roll)
{
    const glm::vec3 ref = std::fabs(dir.z) < 0.9f ? glm::vec3(0, 0, 1) : glm::vec3(1, 0, 0);
    const glm::vec3 x0 = glm::normalize(glm::cross(dir, ref));
    const glm::vec3 z0 = glm::cross(x0, dir);
    const float c = static_cast<float>(std::cos(roll)), s = static_cast<float>(std::sin(roll));
    const glm::vec3 x = c * x0 + s * z0;
    return {x, dir, glm::cross(x, dir)};
}

std::size_t pick_weighted(const std::vector<double>& weights, double u)
{
    double total = 0.0;
    for (double w : weights) total += w;
    double at = u * total;
    for (std::size_t i = 0; i < weights.size(); ++i) {
        if (at < weights[i]) return i;
        at -= weights[i];
    }
    for (std::size_t i = weights.size(); i-- > 0;)
        if (weights[i] > 0.0) return i;
    return 0;
}

} // namespace

glm::dvec3 growth_vector(const glm::dvec3& v_cluster, const glm::dvec3& v_default, double alpha, double beta)
{
    return v_cluster + alpha * v_default + beta * glm::dvec3(0.0, -1.0, 0.0);
}

namespace {

// The frame the spans are measured in (§5.2, Fig. 7c): longitude about `pole`, zero at `mean`,
// and latitude from the plane of `mean` and `side`. The pole is perpendicular to the cluster's
// mean direction, so a cluster never sits on it, whichever way it points; `pole` leans to +Y
// so that θv is the cluster's vertical span. A cluster whose directions nearly cancel out (a
// node inside a ball of attractors) has no mean direction and is measured about +Y.
struct SplitFrame {
    glm::dvec3 mean{1.0, 0.0, 0.0}, side{0.0, 0.0, 1.0}, pole{0.0, 1.0, 0.0};
};

SplitFrame split_frame(const std::vector<glm::vec3>& unit_dirs)
{
    glm::dvec3 sum(0.0);
    for (const glm::vec3& d : unit_dirs) sum += glm::dvec3(d);
    const double l = glm::length(sum);
    SplitFrame f;
    if (!(l > 0.1 * static_cast<double>(unit_dirs.size()))) return f;
    f.mean = sum / l;
    const glm::dvec3 ref = std::fabs(f.mean.y) < 0.99 ? glm::dvec3(0.0, 1.0, 0.0) : glm::dvec3(1.0, 0.0, 0.0);
    f.side = glm::normalize(glm::cross(f.mean, ref));
    f.pole = glm::cross(f.side, f.mean);
    return f;
}

// Longitudes and latitudes of unit directions in `f`, radians.
void longitude_latitude(const std::vector<glm::vec3>& unit_dirs, const SplitFrame& f, std::vector<double>& lon,
                        std::vector<double>& lat)
{
    lon.resize(unit_dirs.size());
    lat.resize(unit_dirs.size());
    for (std::size_t i = 0; i < unit_dirs.size(); ++i) {
        const glm::dvec3 d(unit_dirs[i]);
        lon[i] = std::atan2(glm::dot(d, f.side), glm::dot(d, f.mean));
        lat[i] = std::asin(std::clamp(glm::dot(d, f.pole), -1.0, 1.0));
    }
}

// The smallest arc of longitudes holding them all: its start and its length (radians).
std::pair<double, double> longitude_arc(const std::vector<double>& lon)
{
    std::vector<double> sorted = lon;
    std::sort(sorted.begin(), sorted.end());
    double start = sorted.front(), gap = sorted.front() + 2 * kPi - sorted.back();
    for (std::size_t i = 1; i < sorted.size(); ++i)
        if (sorted[i] - sorted[i - 1] > gap) {
            gap = sorted[i] - sorted[i - 1];
            start = sorted[i];
        }
    return {start, 2 * kPi - gap};
}

} // namespace

ClusterSpan cluster_span(const std::vector<glm::vec3>& unit_dirs)
{
    ClusterSpan span;
    if (unit_dirs.empty()) return span;
    std::vector<double> lon, lat;
    longitude_latitude(unit_dirs, split_frame(unit_dirs), lon, lat);
    const auto [lo, hi] = std::minmax_element(lat.begin(), lat.end());
    span.horizontal_deg = longitude_arc(lon).second * 180.0 / kPi;
    span.vertical_deg = (*hi - *lo) * 180.0 / kPi;
    return span;
}

std::vector<std::vector<int>> split_cluster(const std::vector<glm::vec3>& unit_dirs, double split_angle_deg,
                                            int* grid_h, int* grid_v)
{
    const int n = static_cast<int>(unit_dirs.size());
    if (n == 0) return {};
    const double t = std::max(split_angle_deg, 1e-3) * kPi / 180.0;
    std::vector<double> lon, lat;
    longitude_latitude(unit_dirs, split_frame(unit_dirs), lon, lat);
    const auto [start, hspan] = longitude_arc(lon);
    const auto [lo, hi] = std::minmax_element(lat.begin(), lat.end());
    const double vmin = *lo, vspan = *hi - *lo;
    int nh = hspan > t ? static_cast<int>(std::ceil(hspan / t)) : 1;
    int nv = vspan > t ? static_cast<int>(std::ceil(vspan / t)) : 1;
    while (nh * nv > kMaxPiecesPerNode) {
        if (nh >= nv) nh = (nh + 1) / 2; else nv = (nv + 1) / 2;
    }
    if (grid_h) *grid_h = nh;
    if (grid_v) *grid_v = nv;
    if (nh * nv == 1) {
        std::vector<int> all(static_cast<std::size_t>(n));
        for (int i = 0; i < n; ++i) all[static_cast<std::size_t>(i)] = i;
        return {all};
    }
    // Longitudes measured from the start of the smallest arc holding them all.
    std::vector<std::vector<int>> bins(static_cast<std::size_t>(nh * nv));
    for (int i = 0; i < n; ++i) {
        double rel = lon[static_cast<std::size_t>(i)] - start;
        if (rel < 0) rel += 2 * kPi;
        const int ih = std::clamp(static_cast<int>(rel / std::max(hspan, 1e-12) * nh), 0, nh - 1);
        const int iv = std::clamp(static_cast<int>((lat[static_cast<std::size_t>(i)] - vmin) / std::max(vspan, 1e-12) * nv), 0, nv - 1);
        bins[static_cast<std::size_t>(iv * nh + ih)].push_back(i);
    }
    std::vector<std::vector<int>> pieces;
    for (auto& b : bins)
        if (!b.empty()) pieces.push_back(std::move(b));
    return pieces;
}

glm::dvec3 cluster_direction(const glm::vec3& node, const std::vector<glm::vec3>& attractors)
{
    // Σ d_i·V_i / Σ d_i with V_i = (a_i − node)/d_i: the sum of the vectors themselves, so
    // distant attractors pull harder (§5.2: "towards bulgy and distant regions").
    glm::dvec3 sum(0.0);
    double weight = 0.0;
    for (const glm::vec3& a : attractors) {
        const glm::dvec3 v = glm::dvec3(a) - glm::dvec3(node);
        sum += v;
        weight += glm::length(v);
    }
    const double l = glm::length(sum);
    return weight > 0.0 && l > 1e-9 * weight ? sum / l : glm::dvec3(0.0, 1.0, 0.0);
}

namespace {

// A lobe's attractors are taken only by nodes inside the lobe once the skeleton enters it.
// Node eligibility is decided when a node is made: inside the lobe's box and by parity.
struct LobeBounds {
    glm::vec3 lo{0.0f}, hi{0.0f};
    bool contains(const glm::vec3& p) const
    {
        return p.x >= lo.x && p.y >= lo.y && p.z >= lo.z && p.x <= hi.x && p.y <= hi.y && p.z <= hi.z;
    }
};

LobeBounds bounds_of(const TriangleMesh& m)
{
    LobeBounds b;
    if (m.positions.empty()) return b;
    b.lo = b.hi = m.positions.front();
    for (const glm::vec3& p : m.positions) {
        b.lo = glm::min(b.lo, p);
        b.hi = glm::max(b.hi, p);
    }
    return b;
}

// The stream key of a node grown as node `j` of the subtree that `parent` grew in its growth
// `growth`, piece `piece`, for lobe `lobe_id`: a hash of its parent's key, never of an index
// in the tree, so a lobe's branches do not depend on how many nodes grew in the others.
std::uint64_t child_key(std::uint64_t parent, std::int64_t lobe_id, int growth, std::size_t piece, std::size_t j)
{
    return splitmix64(parent ^ splitmix64(static_cast<std::uint64_t>(lobe_id) ^
                                          (static_cast<std::uint64_t>(growth) << 56 | piece << 8 | j)));
}

// nanoflann adaptor over a lobe's vertices.
struct VertexCloud {
    const std::vector<glm::vec3>* points = nullptr;
    std::size_t kdtree_get_point_count() const { return points->size(); }
    float kdtree_get_pt(std::size_t i, std::size_t dim) const { return (*points)[i][static_cast<int>(dim)]; }
    template <class Box>
    bool kdtree_get_bbox(Box&) const { return false; }
};
using VertexIndex = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, VertexCloud>, VertexCloud,
                                                        3, std::uint32_t>;

// A lobe's vertices and its longest edge: every point of the surface lies within that edge
// length of a vertex, so a ball around p of radius (distance to the nearest vertex − longest
// edge) is clear of the surface.
struct LobeClearance {
    VertexCloud cloud;
    std::unique_ptr<VertexIndex> index;
    float longest_edge = 0.0f;
    explicit LobeClearance(const TriangleMesh& m) : cloud{&m.positions}
    {
        for (const auto& t : m.triangles)
            for (int k = 0; k < 3; ++k)
                longest_edge = std::max(longest_edge, glm::distance(m.positions[static_cast<std::size_t>(t[k])],
                                                                    m.positions[static_cast<std::size_t>(t[(k + 1) % 3])]));
        if (!m.positions.empty()) index = std::make_unique<VertexIndex>(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(10));
    }
    // A distance from p within which there is no surface (0 when unknown).
    float clear(const glm::vec3& p) const
    {
        if (!index) return 0.0f;
        std::uint32_t i = 0;
        float d2 = 0.0f;
        if (index->knnSearch(&p.x, 1, &i, &d2) == 0) return 0.0f;
        return std::max(0.0f, std::sqrt(d2) - longest_edge);
    }
};

// The whole tree's growth loop (§5.2): every live attractor of every lobe belongs to its
// nearest node of the tree (among the nodes that may take that lobe's attractors); a node's
// attractors form one cluster per lobe, split into pieces; each piece grows a subtree or stops.
class TreeGrowth {
public:
    TreeGrowth(const Skeleton& skeleton, const std::vector<GrowthLobe>& lobes, const std::vector<MeshRaycaster>& rays,
               const GrowthSettings& settings, const SubtreeLibrary& library, std::uint64_t seed, std::size_t node_cap,
               GrowthResult& result)
        : lobes_(lobes), rays_(rays), settings_(settings), library_(library), seed_(seed), node_cap_(node_cap),
          result_(result), tree_(result.tree.nodes)
    {
        result.lobes.assign(lobes.size(), LobeGrowthStats{});
        for (const GrowthLobe& l : lobes) {
            std::vector<double> w = l.subtree_weights;
            if (w.size() != library.subtrees.size()) w.assign(library.subtrees.size(), 1.0);
            weights_.push_back(std::move(w));
            bounds_.push_back(bounds_of(l.mesh));
            clearance_.push_back(std::make_unique<LobeClearance>(l.mesh));
        }
        // Attractors: every lobe's vertices, lobe after lobe.
        for (std::size_t l = 0; l < lobes.size(); ++l) {
            first_attractor_.push_back(attractors_.size());
            for (const glm::vec3& p : lobes[l].mesh.positions) {
                attractors_.push_back(p);
                attractor_lobe_.push_back(static_cast<std::uint32_t>(l));
            }
            result.lobes[l].attractors = lobes[l].mesh.positions.size();
        }
        first_attractor_.push_back(attractors_.size());
        live_.assign(attractors_.size(), 1);
        nearest_.assign(attractors_.size(), 0);
        nearest_d2_.assign(attractors_.size(), std::numeric_limits<float>::max());
        // A lobe the skeleton enters takes attractors only from nodes inside it.
        inside_only_.assign(lobes.size(), 0);
        batch_.resize(lobes.size());
        for (std::size_t l = 0; l < lobes.size(); ++l)
            for (const TreeNode& n : skeleton.graph.nodes)
                if (bounds_[l].contains(n.position) && rays_[l].inside(n.position)) {
                    inside_only_[l] = 1;
                    break;
                }
        const float spacing = static_cast<float>(settings.skeleton_spacing_m);
        for (std::size_t i = 0; i < skeleton.graph.nodes.size(); ++i) {
            const TreeNode& n = skeleton.graph.nodes[i];
            glm::vec3 h(0, 1, 0);
            if (n.parent >= 0) {
                const glm::vec3 d = n.position - skeleton.graph.nodes[static_cast<std::size_t>(n.parent)].position;
                if (glm::length(d) > 1e-7f) h = glm::normalize(d);
            }
            add_node(n.position, h, splitmix64(i), spacing, -1, false);
        }
    }

    // Assignment and reach: each live attractor keeps its nearest node, compared only against
    // the nodes made since that may take its lobe's attractors; one within its node's reach
    // (kKillFraction of the node's subtree scale, at most the kill distance) is removed.
    void assign_attractors()
    {
        const float kill_cap = static_cast<float>(settings_.kill_distance_m);
        for (std::size_t l = 0; l < lobes_.size(); ++l) {
            std::vector<std::uint32_t>& batch = batch_[l];
            if (batch.empty()) continue;
            NodeSubset subset{&pos_, &batch};
            NodeIndex index(3, subset, nanoflann::KDTreeSingleIndexAdaptorParams(12));
            for (std::size_t a = first_attractor_[l]; a < first_attractor_[l + 1]; ++a) {
                if (!live_[a]) continue;
                std::uint32_t idx = 0;
                float d2 = 0.0f;
                if (index.knnSearch(&attractors_[a].x, 1, &idx, &d2) == 0) continue;
                if (d2 < nearest_d2_[a]) {
                    nearest_d2_[a] = d2;
                    nearest_[a] = batch[idx];
                }
                const float reach = std::min(kill_cap, kKillFraction * scale_[nearest_[a]]);
                if (nearest_d2_[a] < reach * reach) {
                    live_[a] = 0;
                    ++result_.lobes[l].reached;
                }
            }
            batch.clear();
        }
    }

    // Clusters: the live attractors grouped by their nearest node (a counting sort keeps node
    // order, and within a node attractor order, so lobe order): node n's are
    // order_[count_[n]] … order_[count_[n + 1] − 1]. False when none is live.
    bool cluster_attractors()
    {
        count_.assign(pos_.size() + 1, 0);
        std::size_t live_count = 0;
        for (std::size_t a = 0; a < attractors_.size(); ++a)
            if (live_[a]) {
                ++count_[nearest_[a] + 1];
                ++live_count;
            }
        if (live_count == 0) return false;
        for (std::size_t i = 1; i < count_.size(); ++i) count_[i] += count_[i - 1];
        order_.assign(live_count, 0);
        std::vector<std::uint32_t> fill(count_.begin(), count_.end() - 1);
        for (std::size_t a = 0; a < attractors_.size(); ++a)
            if (live_[a]) order_[fill[nearest_[a]]++] = static_cast<std::uint32_t>(a);
        return true;
    }

    // An active node (one with attractors): one cluster per lobe among them, each split by
    // its angular spans into pieces, each growing a subtree unless the stop rule stops it. A
    // node that has grown kMaxGrowthsPerNode times, or grew nothing, leaves its attractors.
    void grow_node(std::size_t n, bool record)
    {
        const std::uint32_t first = count_[n], last = count_[n + 1];
        if (first == last) return;
        if (stopped_[n] || growths_[n] >= kMaxGrowthsPerNode) {
            for (std::uint32_t k = first; k < last; ++k) drop(order_[k], false);
            return;
        }
        bool grew = false;
        for (std::uint32_t f = first; f < last && !capped_;) {
            const std::uint32_t lobe = attractor_lobe_[order_[f]];
            std::uint32_t l = f;
            while (l < last && attractor_lobe_[order_[l]] == lobe) ++l;
            if (grow_cluster(n, lobe, f, l, record)) grew = true;
            f = l;
        }
        ++growths_[n];
        if (!grew) stopped_[n] = 1;
    }

    std::size_t node_count() const { return pos_.size(); }
    bool capped() const { return capped_; }
    bool any_live(std::size_t lobe) const
    {
        for (std::size_t a = first_attractor_[lobe]; a < first_attractor_[lobe + 1]; ++a)
            if (live_[a]) return true;
        return false;
    }

private:
    // Node n's cluster of lobe `lobe`'s attractors order_[f … l − 1]: split (§5.2, Fig. 7c),
    // then a subtree per piece. True when a subtree grew.
    bool grow_cluster(std::size_t n, std::uint32_t lobe, std::uint32_t f, std::uint32_t l, bool record)
    {
        cluster_.clear();
        dirs_.clear();
        for (std::uint32_t k = f; k < l; ++k) {
            const glm::vec3& a = attractors_[order_[k]];
            cluster_.push_back(a);
            const glm::vec3 v = a - pos_[n];
            const float len = glm::length(v);
            dirs_.push_back(len > 1e-9f ? v / len : heading_[n]);
        }
        const std::vector<std::vector<int>> pieces = split_cluster(dirs_, lobes_[lobe].split_angle_deg);
        bool grew = false;
        for (std::size_t p = 0; p < pieces.size() && !capped_; ++p) {
            if (record) {
                for (int k : pieces[p])
                    result_.first_clusters.push_back({cluster_[static_cast<std::size_t>(k)], static_cast<int>(n),
                                                      static_cast<int>(lobe), next_piece_});
                ++next_piece_;
            }
            if (grow_piece(n, lobe, p, pieces[p], f)) grew = true;
        }
        return grew;
    }

    // Piece `p` of node n's cluster (its attractors `piece`, indices from `first`): the
    // direction V_A and the signed distance to the lobe's surface along it, the stop rule,
    // then a subtree of length growth_ratio × that distance. True when a subtree grew.
    bool grow_piece(std::size_t n, std::uint32_t lobe, std::size_t p, const std::vector<int>& piece, std::uint32_t first)
    {
        piece_pts_.clear();
        for (int k : piece) piece_pts_.push_back(cluster_[static_cast<std::size_t>(k)]);
        const MeshRaycaster& ray = rays_[lobe];
        const glm::dvec3 vc = cluster_direction(pos_[n], piece_pts_);
        glm::dvec3 va = growth_vector(vc, glm::dvec3(heading_[n]), settings_.alpha, settings_.beta);
        if (glm::length(va) < 1e-9) va = vc;
        const glm::vec3 dir = glm::vec3(glm::normalize(va));
        // A node grown from inside this lobe is inside it (its segments were clipped): the
        // signed distance is the nearest crossing.
        const bool known_inside = inside_of_[n] == static_cast<int>(lobe);
        bool node_inside = false;
        const auto distance_along = [&](const glm::vec3& d) {
            if (known_inside) {
                const float hit = ray.first_hit(pos_[n], d);
                node_inside = true;
                if (hit >= 0.0f) return hit;
            }
            return ray.signed_distance_along(pos_[n], d, &node_inside);
        };
        glm::vec3 dir_used = dir;
        float s = distance_along(dir);
        const float stop = static_cast<float>(settings_.stop_distance_m);
        // The stop rule ends a piece whose node has reached the surface towards its
        // attractors. Where V_A meets the surface but the attractors lie elsewhere through the
        // lobe (V_A bent up by gravity in a hanging thin part, a trunk running close under a
        // flat lobe's top), the piece grows along V_cluster, towards them, instead.
        if (s >= 0.0f && s < stop) {
            dir_used = glm::vec3(vc);
            s = distance_along(dir_used);
        }
        // Outside the lobe with V_A missing it: nothing to grow towards from here. The
        // attractors stay live, so nodes grown nearer can take them; the node's attempts are
        // bounded by kMaxGrowthsPerNode.
        if (!(s >= 0.0f)) return false;
        // §5.2's stop rule: too close to the surface along V_A; the piece's attractors leave.
        // A node walled in far from its attractors (a thin part of the lobe between them)
        // has not reached them: they stay live for nodes grown nearer, and the node's
        // attempts are bounded by kMaxGrowthsPerNode.
        if (s < stop && walled_in(n, stop)) return false;
        if (s < stop) {
            for (int k : piece) drop(order_[first + static_cast<std::uint32_t>(k)], true);
            return false;
        }
        grow_subtree(n, lobe, p, dir_used, dir, static_cast<float>(settings_.growth_ratio) * s, node_inside || known_inside);
        ++result_.lobes[lobe].subtrees;
        return true;
    }

    // True when the piece's attractors (piece_pts_) lie on average farther than
    // kWalledInFactor × the stop distance from node n.
    bool walled_in(std::size_t n, float stop) const
    {
        double sum = 0.0;
        for (const glm::vec3& a : piece_pts_) sum += static_cast<double>(glm::distance(a, pos_[n]));
        return sum > kWalledInFactor * static_cast<double>(stop) * static_cast<double>(piece_pts_.size());
    }

    // A library subtree (picked by the lobe's weights, rolled at random) attached at node n,
    // its +Y along `along`, scaled to `length`. `fallback` is the heading of a node whose
    // segment has no length. A subtree grown from inside the lobe stays inside it.
    void grow_subtree(std::size_t n, std::uint32_t lobe, std::size_t p, const glm::vec3& along,
                      const glm::vec3& fallback, float length, bool root_inside)
    {
        const GrowthLobe& gl = lobes_[lobe];
        Stream rng(gl.seed.value_or(seed_), gl.id, key_[n], growths_[n], p);
        const std::size_t sub = pick_weighted(weights_[lobe], rng.uniform());
        const Subtree& st = library_.subtrees[sub];
        const Frame f = frame_along(along, rng.uniform() * 2 * kPi);
        const std::size_t base = pos_.size();
        const MeshRaycaster& ray = rays_[lobe];
        // The subtree lies within `length` of node n: where the surface is farther, no
        // segment can leave the lobe and none is cast.
        const bool clip = root_inside && clearance_[lobe]->clear(pos_[n]) <= length;
        for (std::size_t j = 1; j < st.nodes.size(); ++j) {
            const int sp = st.parents[j];
            const std::size_t parent = sp == 0 ? n : base + static_cast<std::size_t>(sp) - 1;
            // Each segment of the subtree, turned and scaled, from where its parent ended up.
            glm::vec3 q = pos_[parent] + length * f.apply(st.nodes[j] - st.nodes[static_cast<std::size_t>(sp)]);
            glm::vec3 d = q - pos_[parent];
            // A segment grown from inside the lobe stays inside: where it would leave
            // through a thin part of the lobe it ends short of the surface instead.
            const float seg = glm::length(d);
            if (clip && seg > 1e-9f) {
                const float hit = ray.first_hit(pos_[parent], d / seg, seg);
                if (hit >= 0.0f && hit < seg) {
                    q = pos_[parent] + (kClipFraction * hit / seg) * d;
                    d = q - pos_[parent];
                }
            }
            const glm::vec3 h = glm::length(d) > 1e-9f ? glm::normalize(d) : fallback;
            add_node(q, h, child_key(key_[n], gl.id, growths_[n], p, j), length, static_cast<int>(parent), true,
                     static_cast<int>(lobe), root_inside, static_cast<int>(sub));
        }
        result_.lobes[lobe].nodes += st.nodes.size() - 1;
        if (tree_.size() >= node_cap_) capped_ = true;
    }

    // A node of the tree: a skeleton node (parent −1 here: its TreeNode is already in the
    // tree) or a grown one. It joins the candidates of every lobe whose attractors it may take.
    void add_node(const glm::vec3& q, const glm::vec3& heading, std::uint64_t key, float scale, int parent, bool grown,
                  int lobe = -1, bool inside_lobe = false, int subtree = -1)
    {
        const auto id = static_cast<std::uint32_t>(pos_.size());
        pos_.push_back(q);
        heading_.push_back(heading);
        key_.push_back(key);
        scale_.push_back(scale);
        inside_of_.push_back(inside_lobe ? lobe : -1);
        growths_.push_back(0);
        stopped_.push_back(0);
        if (grown) {
            TreeNode node;
            node.position = q;
            node.parent = parent;
            node.subtree_id = subtree;
            node.kind = TreeNodeKind::Grown;
            node.lobe = lobe;
            tree_.push_back(node);
        }
        for (std::size_t l = 0; l < lobes_.size(); ++l) {
            bool take = !inside_only_[l];
            if (!take && static_cast<int>(l) == lobe && inside_lobe) take = true;
            else if (!take && bounds_[l].contains(q)) take = rays_[l].inside(q);
            if (take) batch_[l].push_back(id);
        }
    }

    // Attractor a leaves: with a node that stopped (the stop rule) or one that can grow no more.
    void drop(std::uint32_t a, bool by_stop_rule)
    {
        live_[a] = 0;
        LobeGrowthStats& s = result_.lobes[attractor_lobe_[a]];
        ++(by_stop_rule ? s.stopped : s.left);
    }

    // An attractor nearer a node than this fraction of the node's subtree scale is reached.
    static constexpr float kKillFraction = 0.25f;
    // A node whose piece's attractors are this many stop distances away is walled in, not done.
    static constexpr double kWalledInFactor = 4.0;

    const std::vector<GrowthLobe>& lobes_;
    const std::vector<MeshRaycaster>& rays_;
    const GrowthSettings& settings_;
    const SubtreeLibrary& library_;
    const std::uint64_t seed_;
    const std::size_t node_cap_;
    GrowthResult& result_;
    std::vector<TreeNode>& tree_;
    std::vector<std::vector<double>> weights_;
    std::vector<LobeBounds> bounds_;
    std::vector<std::unique_ptr<LobeClearance>> clearance_;
    std::vector<std::uint8_t> inside_only_;

    // Per node (the tree's order): position, heading (V_default), stream key, subtree scale.
    std::vector<glm::vec3> pos_, heading_;
    std::vector<std::uint64_t> key_;
    std::vector<float> scale_;
    std::vector<int> inside_of_; // the lobe a node is known to be inside (grown from inside it), or −1
    std::vector<std::uint8_t> growths_, stopped_;
    bool capped_ = false;

    std::vector<glm::vec3> attractors_;
    std::vector<std::uint32_t> attractor_lobe_;
    std::vector<std::size_t> first_attractor_; // lobe l's are [first_attractor_[l], first_attractor_[l + 1])
    std::vector<std::uint8_t> live_;
    std::vector<std::uint32_t> nearest_; // each attractor's node
    std::vector<float> nearest_d2_;
    int next_piece_ = 0;

    // Per lobe: the nodes made since the last assignment that may take its attractors.
    std::vector<std::vector<std::uint32_t>> batch_;
    // Kept across iterations for their storage.
    std::vector<std::uint32_t> order_, count_;
    std::vector<glm::vec3> cluster_, dirs_, piece_pts_;
};

} // namespace

GrowthResult grow_tree(const std::vector<std::vector<glm::vec3>>& trunk_strokes, const std::vector<GrowthLobe>& lobes,
                       const GrowthSettings& settings, const SubtreeLibrary& library, std::uint64_t seed,
                       std::size_t max_tree_nodes)
{
    GrowthResult result;
    result.leader_radii = true;
    std::vector<TriangleMesh> meshes;
    for (const GrowthLobe& l : lobes) meshes.push_back(l.mesh);
    std::vector<MeshRaycaster> rays;
    rays.reserve(lobes.size());
    for (const GrowthLobe& l : lobes) rays.emplace_back(l.mesh);
    SkeletonOptions so;
    so.spacing_m = settings.skeleton_spacing_m;
    so.leader = settings.leader != 0;
    so.whorl_spacing = settings.whorl_spacing;
    Skeleton skeleton = build_skeleton(trunk_strokes, meshes, so, &rays);
    result.messages = skeleton.messages;
    result.tree = skeleton.graph;
    result.skeleton_nodes = skeleton.graph.nodes.size();
    if (skeleton.graph.empty()) {
        result.messages.push_back("nothing to grow: no lobes and no trunk strokes");
        return result;
    }
    bool any_attractor = false;
    for (const GrowthLobe& l : lobes) any_attractor = any_attractor || !l.mesh.positions.empty();
    if (any_attractor && library.subtrees.empty()) throw InvalidInput("growth: the subtree library is empty");
    // The node cap: max_nodes per lobe, and the whole tree's.
    const std::size_t per_lobes = static_cast<std::size_t>(std::max(settings.max_nodes, 1)) * std::max<std::size_t>(lobes.size(), 1);
    const std::size_t cap = std::min(max_tree_nodes, result.skeleton_nodes + per_lobes);
    TreeGrowth growth(skeleton, lobes, rays, settings, library, seed, cap, result);
    growth.assign_attractors();
    int iterations = 0;
    // Each iteration: the live attractors' clusters; every active node splits its clusters
    // and grows a subtree per piece (or stops); the new nodes take the attractors nearest them.
    for (int it = 0; it < settings.max_iterations && result.tree.size() < cap; ++it) {
        if (!growth.cluster_attractors()) break; // every attractor reached or stopped
        const std::size_t active_end = growth.node_count(); // nodes grown now wait for the next iteration
        for (std::size_t n = 0; n < active_end && !growth.capped(); ++n) growth.grow_node(n, it == 0);
        iterations = it + 1;
        if (growth.node_count() == active_end) break; // nothing grew
        growth.assign_attractors();
        if (growth.capped()) break;
    }
    for (std::size_t l = 0; l < lobes.size(); ++l) {
        LobeGrowthStats& st = result.lobes[l];
        st.iterations = iterations;
        const std::string name = "lobe " + std::to_string(l + 1);
        if (growth.capped() && growth.any_live(l)) {
            st.node_cap = true;
            result.messages.push_back(st.nodes == 0 ? name + ": not grown, the tree already has " +
                                                          std::to_string(result.tree.size()) + " nodes (limit " +
                                                          std::to_string(cap) + ")"
                                                    : name + ": node cap of " + std::to_string(cap) +
                                                          " reached; growth stopped early");
        } else if (iterations == settings.max_iterations && growth.any_live(l)) {
            st.iteration_cap = true;
            result.messages.push_back(name + ": iteration cap of " + std::to_string(settings.max_iterations) +
                                      " reached with attractors left");
        } else if (st.attractors > 0 && st.nodes == 0) {
            result.messages.push_back(name + ": no branch could grow into it (a lobe that is flat, on a line or "
                                             "out of reach); the rest of the tree grew");
        }
    }
    apply_species_form(result.tree, result.skeleton_nodes, settings); // droop and hang
    return result;
}

} // namespace lobe
