#include "growth/grow.h"

#include <algorithm>
#include <cmath>
#include <limits>
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

// Each node's random choices come from a stream keyed by (seed, lobe, node, growth, piece)
// with the SplitMix64 hash (core/random.h), so they depend only on that key, never on how
// many numbers other nodes drew.
class Stream {
public:
    Stream(std::uint64_t seed, std::int64_t lobe, std::size_t node, int growth, std::size_t piece)
        : state_(splitmix64(splitmix64(splitmix64(splitmix64(seed) ^ static_cast<std::uint64_t>(lobe)) ^ node) ^
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

// Azimuths (about +Y) and elevations of unit directions, radians.
void azimuth_elevation(const std::vector<glm::vec3>& unit_dirs, std::vector<double>& az, std::vector<double>& el)
{
    az.resize(unit_dirs.size());
    el.resize(unit_dirs.size());
    for (std::size_t i = 0; i < unit_dirs.size(); ++i) {
        const glm::vec3& d = unit_dirs[i];
        az[i] = std::atan2(static_cast<double>(d.z), static_cast<double>(d.x));
        el[i] = std::asin(std::clamp(static_cast<double>(d.y), -1.0, 1.0));
    }
}

// The smallest arc of azimuths holding them all: its start and its length (radians).
std::pair<double, double> azimuth_arc(const std::vector<double>& az)
{
    std::vector<double> sorted = az;
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
    std::vector<double> az, el;
    azimuth_elevation(unit_dirs, az, el);
    const auto [lo, hi] = std::minmax_element(el.begin(), el.end());
    span.horizontal_deg = azimuth_arc(az).second * 180.0 / kPi;
    span.vertical_deg = (*hi - *lo) * 180.0 / kPi;
    return span;
}

std::vector<std::vector<int>> split_cluster(const std::vector<glm::vec3>& unit_dirs, double split_angle_deg,
                                            int* grid_h, int* grid_v)
{
    const int n = static_cast<int>(unit_dirs.size());
    if (n == 0) return {};
    const double t = std::max(split_angle_deg, 1e-3) * kPi / 180.0;
    std::vector<double> az, el;
    azimuth_elevation(unit_dirs, az, el);
    const auto [start, hspan] = azimuth_arc(az);
    const auto [lo, hi] = std::minmax_element(el.begin(), el.end());
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
    // Azimuths measured from the start of the smallest arc holding them all.
    std::vector<std::vector<int>> bins(static_cast<std::size_t>(nh * nv));
    for (int i = 0; i < n; ++i) {
        double rel = az[static_cast<std::size_t>(i)] - start;
        if (rel < 0) rel += 2 * kPi;
        const int ih = std::clamp(static_cast<int>(rel / std::max(hspan, 1e-12) * nh), 0, nh - 1);
        const int iv = std::clamp(static_cast<int>((el[static_cast<std::size_t>(i)] - vmin) / std::max(vspan, 1e-12) * nv), 0, nv - 1);
        bins[static_cast<std::size_t>(iv * nh + ih)].push_back(i);
    }
    std::vector<std::vector<int>> pieces;
    for (auto& b : bins)
        if (!b.empty()) pieces.push_back(std::move(b));
    return pieces;
}

glm::dvec3 cluster_direction(const glm::vec3& node, const std::vector<glm::vec3>& attractors)
{
    glm::dvec3 sum(0.0);
    for (const glm::vec3& a : attractors) {
        const glm::dvec3 v = glm::dvec3(a) - glm::dvec3(node);
        const double d = glm::length(v);
        if (d < 1e-9) continue;
        sum += v / (d * d); // unit vector weighted by 1/d
    }
    const double l = glm::length(sum);
    return l > 0.0 ? sum / l : glm::dvec3(0.0, 1.0, 0.0);
}

namespace {

// The nodes one lobe grows from and grows, by local index: the skeleton nodes it starts from
// (those shared by every lobe and the limbs made for it), then the nodes it grows.
struct LocalNodes {
    std::vector<glm::vec3> pos;
    std::vector<glm::vec3> heading; // V_default of each node: its own direction
    std::vector<int> global;        // local → skeleton index (skeleton nodes only)
    std::size_t start = 0;          // how many come from the skeleton
};

LocalNodes start_nodes(const Skeleton& skeleton, int lobe_index)
{
    LocalNodes nodes;
    for (std::size_t i = 0; i < skeleton.graph.nodes.size(); ++i) {
        if (skeleton.owner[i] != -1 && skeleton.owner[i] != lobe_index) continue;
        const TreeNode& n = skeleton.graph.nodes[i];
        glm::vec3 h(0, 1, 0);
        if (n.parent >= 0) {
            const glm::vec3 d = n.position - skeleton.graph.nodes[static_cast<std::size_t>(n.parent)].position;
            if (glm::length(d) > 1e-7f) h = glm::normalize(d);
        }
        nodes.pos.push_back(n.position);
        nodes.heading.push_back(h);
        nodes.global.push_back(static_cast<int>(i));
    }
    nodes.start = nodes.pos.size();
    return nodes;
}

// One lobe's growth loop (§5.2) and what it keeps between its steps: the nodes, the
// attractors (the lobe's vertices) with the node each is assigned to, and the grown nodes.
class LobeGrowth {
public:
    LobeGrowth(LocalNodes nodes, const GrowthLobe& lobe, const GrowthSettings& settings, const SubtreeLibrary& library,
               std::vector<double> weights, std::uint64_t seed, const MeshRaycaster& ray, LobeGrowthStats& stats)
        : lobe_(lobe), settings_(settings), library_(library), weights_(std::move(weights)), seed_(seed), ray_(ray),
          stats_(stats), pos_(std::move(nodes.pos)), heading_(std::move(nodes.heading)), global_(std::move(nodes.global)),
          start_nodes_(nodes.start), growths_(start_nodes_, 0), stopped_(start_nodes_, 0), attractors_(lobe.mesh.positions),
          live_(attractors_.size(), 1), nearest_(attractors_.size(), 0),
          nearest_d2_(attractors_.size(), std::numeric_limits<float>::max())
    {
    }

    std::size_t node_count() const { return pos_.size(); }

    // Once a lobe has branch nodes inside it, only nodes inside it take its attractors, so
    // branches grow through the lobe rather than around its thin parts from outside. A lobe
    // that the skeleton does not enter is grown into from outside (signed distance, §5.2).
    void mark_eligible_nodes()
    {
        eligible_.assign(start_nodes_, 0);
        for (std::size_t i = 0; i < start_nodes_; ++i) {
            eligible_[i] = ray_.inside(pos_[i]) ? 1 : 0;
            inside_only_ = inside_only_ || eligible_[i];
        }
        if (!inside_only_) eligible_.assign(start_nodes_, 1);
    }

    // Assignment and reach: each live attractor keeps its nearest node, compared only against
    // the eligible nodes [begin, end) added since (§5.2); one within the kill distance is
    // reached and leaves.
    void assign_attractors(std::size_t begin, std::size_t end)
    {
        batch_.clear();
        for (std::size_t i = begin; i < end; ++i)
            if (eligible_[i]) batch_.push_back(static_cast<std::uint32_t>(i));
        if (batch_.empty()) return;
        const float kill2 = static_cast<float>(settings_.kill_distance_m * settings_.kill_distance_m);
        NodeSubset subset{&pos_, &batch_};
        NodeIndex index(3, subset, nanoflann::KDTreeSingleIndexAdaptorParams(12));
        for (std::size_t a = 0; a < attractors_.size(); ++a) {
            if (!live_[a]) continue;
            std::uint32_t idx = 0;
            float d2 = 0.0f;
            if (index.knnSearch(&attractors_[a].x, 1, &idx, &d2) == 0) continue;
            if (d2 < nearest_d2_[a]) {
                nearest_d2_[a] = d2;
                nearest_[a] = batch_[idx];
            }
            if (nearest_d2_[a] < kill2) {
                live_[a] = 0;
                ++stats_.reached;
            }
        }
    }

    // Clusters: the live attractors grouped by their nearest node (a counting sort keeps node
    // order): node n's are order_[count_[n]] … order_[count_[n + 1] − 1]. False when none is live.
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

    // An active node (one with attractors): its cluster split by its angular spans into
    // pieces, each growing a subtree unless the stop rule stops it. A node that has grown
    // kMaxGrowthsPerNode times, or grew nothing, stops and its attractors leave.
    void grow_node(std::size_t n)
    {
        const std::uint32_t first = count_[n], last = count_[n + 1];
        if (first == last) return;
        if (stopped_[n] || growths_[n] >= kMaxGrowthsPerNode) {
            stopped_[n] = 1;
            drop_attractors(first, last);
            return;
        }
        cluster_.clear();
        dirs_.clear();
        for (std::uint32_t k = first; k < last; ++k) {
            const glm::vec3& a = attractors_[order_[k]];
            cluster_.push_back(a);
            const glm::vec3 v = a - pos_[n];
            const float l = glm::length(v);
            dirs_.push_back(l > 1e-9f ? v / l : glm::vec3(0, 1, 0));
        }
        const std::vector<std::vector<int>> pieces = split_cluster(dirs_, lobe_.split_angle_deg);
        bool grew = false;
        for (std::size_t p = 0; p < pieces.size() && !stats_.node_cap; ++p)
            if (grow_piece(n, p, pieces[p], first)) grew = true;
        ++growths_[n];
        if (!grew) stopped_[n] = 1;
    }

    // True while an attractor is live.
    bool any_live() const { return std::find(live_.begin(), live_.end(), 1) != live_.end(); }

    // The grown nodes, their parents in grow_in_lobe's output convention: skeleton indices
    // below skeleton_size, then the grown nodes.
    std::vector<TreeNode> take_grown(std::size_t skeleton_size, int lobe_index)
    {
        for (TreeNode& node : grown_) {
            const auto p = static_cast<std::size_t>(node.parent);
            node.parent = p < start_nodes_ ? global_[p] : static_cast<int>(skeleton_size + (p - start_nodes_));
            node.lobe = lobe_index;
        }
        return std::move(grown_);
    }

    std::size_t grown_count() const { return grown_.size(); }

private:
    // Piece `p` of node n's cluster (its attractors `piece`, indices from `first`): the
    // direction V_A and the signed distance to the surface along it, the stop rule, then a
    // subtree. True when a subtree grew.
    bool grow_piece(std::size_t n, std::size_t p, const std::vector<int>& piece, std::uint32_t first)
    {
        piece_pts_.clear();
        for (int k : piece) piece_pts_.push_back(cluster_[static_cast<std::size_t>(k)]);
        const glm::dvec3 vc = cluster_direction(pos_[n], piece_pts_);
        glm::dvec3 va = growth_vector(vc, glm::dvec3(heading_[n]), settings_.alpha, settings_.beta);
        if (glm::length(va) < 1e-9) va = vc;
        const glm::vec3 dir = glm::vec3(glm::normalize(va));
        bool node_inside = false;
        glm::vec3 dir_used = dir;
        float s = ray_.signed_distance_along(pos_[n], dir, &node_inside);
        // The stop rule is for grown tips. A sketched skeleton node is not a tip: where
        // V_A would stop it at the surface (a trunk running close under a flat lobe's
        // top, pointing up), it sprouts along V_cluster, towards its attractors, instead.
        if (n < start_nodes_ && s >= 0.0f && s < static_cast<float>(settings_.stop_distance_m)) {
            dir_used = glm::vec3(vc);
            s = ray_.signed_distance_along(pos_[n], dir_used, &node_inside);
        }
        // Outside the lobe with V_A missing it: nothing to grow towards from here.
        // The attractors stay live, so nodes grown nearer can take them; the
        // node's attempts are bounded by kMaxGrowthsPerNode.
        if (!(s >= 0.0f)) return false;
        // §5.2's stop rule: too close to the surface along V_A.
        if (s < static_cast<float>(settings_.stop_distance_m)) {
            drop_attractors(first, piece);
            return false;
        }
        grow_subtree(n, p, dir_used, dir, static_cast<float>(settings_.growth_ratio) * s, node_inside);
        ++stats_.subtrees;
        if (grown_.size() >= static_cast<std::size_t>(settings_.max_nodes)) stats_.node_cap = true;
        return true;
    }

    // A library subtree (picked by the lobe's weights, rolled at random) attached at node n,
    // its +Y along `along`, scaled to `length`. `fallback` is the heading of a node whose
    // segment has no length. A subtree grown from inside the lobe stays inside it.
    void grow_subtree(std::size_t n, std::size_t p, const glm::vec3& along, const glm::vec3& fallback, float length,
                      bool root_inside)
    {
        Stream rng(lobe_.seed.value_or(seed_), lobe_.id, n, growths_[n], p);
        const std::size_t sub = pick_weighted(weights_, rng.uniform());
        const Subtree& st = library_.subtrees[sub];
        const Frame f = frame_along(along, rng.uniform() * 2 * kPi);
        const std::size_t base = pos_.size();
        for (std::size_t j = 1; j < st.nodes.size(); ++j) {
            const int sp = st.parents[j];
            const std::size_t parent = sp == 0 ? n : base + static_cast<std::size_t>(sp) - 1;
            // Each segment of the subtree, turned and scaled, from where its parent ended up.
            glm::vec3 q = pos_[parent] + length * f.apply(st.nodes[j] - st.nodes[static_cast<std::size_t>(sp)]);
            glm::vec3 d = q - pos_[parent];
            // A segment grown from inside the lobe stays inside: where it would leave
            // through a thin part of the lobe it ends short of the surface instead.
            const float seg = glm::length(d);
            if (root_inside && seg > 1e-9f) {
                const float hit = ray_.first_hit(pos_[parent], d / seg, seg);
                if (hit >= 0.0f && hit < seg) {
                    q = pos_[parent] + (kClipFraction * hit / seg) * d;
                    d = q - pos_[parent];
                }
            }
            pos_.push_back(q);
            eligible_.push_back(!inside_only_ || root_inside || ray_.inside(q) ? 1 : 0);
            heading_.push_back(glm::length(d) > 1e-9f ? glm::normalize(d) : fallback);
            growths_.push_back(0);
            stopped_.push_back(0);
            TreeNode node;
            node.position = q;
            node.parent = static_cast<int>(parent); // local for now
            node.subtree_id = static_cast<int>(sub);
            node.kind = TreeNodeKind::Grown;
            grown_.push_back(node);
        }
    }

    // Attractors order_[from … to − 1] stop: they leave with their node.
    void drop_attractors(std::uint32_t from, std::uint32_t to)
    {
        for (std::uint32_t k = from; k < to; ++k) {
            live_[order_[k]] = 0;
            ++stats_.stopped;
        }
    }

    // The attractors of a stopped piece (indices from `from`) leave.
    void drop_attractors(std::uint32_t from, const std::vector<int>& piece)
    {
        for (int k : piece) {
            live_[order_[from + static_cast<std::uint32_t>(k)]] = 0;
            ++stats_.stopped;
        }
    }

    const GrowthLobe& lobe_;
    const GrowthSettings& settings_;
    const SubtreeLibrary& library_;
    const std::vector<double> weights_;
    const std::uint64_t seed_;
    const MeshRaycaster& ray_;
    LobeGrowthStats& stats_;

    std::vector<glm::vec3> pos_, heading_; // per local node (LocalNodes)
    std::vector<int> global_;
    std::size_t start_nodes_ = 0;
    std::vector<std::uint8_t> eligible_; // may take attractors
    bool inside_only_ = false;
    std::vector<std::uint8_t> growths_;  // times each node grew
    std::vector<std::uint8_t> stopped_;

    const std::vector<glm::vec3>& attractors_;
    std::vector<std::uint8_t> live_;
    std::vector<std::uint32_t> nearest_; // each attractor's node
    std::vector<float> nearest_d2_;

    std::vector<TreeNode> grown_;

    // Kept across iterations for their storage.
    std::vector<std::uint32_t> batch_, order_, count_;
    std::vector<glm::vec3> cluster_, dirs_, piece_pts_;
};

} // namespace

std::vector<TreeNode> grow_in_lobe(const Skeleton& skeleton, int lobe_index, const GrowthLobe& lobe,
                                   const GrowthSettings& settings, const SubtreeLibrary& library,
                                   std::uint64_t seed, LobeGrowthStats& stats, const MeshRaycaster* shared_ray)
{
    stats = {};
    if (library.subtrees.empty()) throw InvalidInput("growth: the subtree library is empty");
    std::vector<double> weights = lobe.subtree_weights;
    if (weights.size() != library.subtrees.size()) weights.assign(library.subtrees.size(), 1.0);
    LocalNodes nodes = start_nodes(skeleton, lobe_index);
    if (nodes.start == 0 || lobe.mesh.positions.empty()) return {};
    stats.attractors = lobe.mesh.positions.size();
    std::optional<MeshRaycaster> own_ray;
    if (!shared_ray) own_ray.emplace(lobe.mesh);

    const std::size_t start = nodes.start;
    LobeGrowth growth(std::move(nodes), lobe, settings, library, std::move(weights), seed,
                      shared_ray ? *shared_ray : *own_ray, stats);
    growth.mark_eligible_nodes();
    growth.assign_attractors(0, start);
    // Each iteration: the live attractors' clusters; every active node splits its cluster and
    // grows a subtree per piece (or stops); the new nodes take the attractors nearest them.
    for (int it = 0; it < settings.max_iterations; ++it) {
        if (!growth.cluster_attractors()) break; // every attractor reached or stopped
        const std::size_t active_end = growth.node_count(); // nodes grown now wait for the next iteration
        for (std::size_t n = 0; n < active_end && !stats.node_cap; ++n) growth.grow_node(n);
        ++stats.iterations;
        if (growth.node_count() == active_end) break; // nothing grew
        growth.assign_attractors(active_end, growth.node_count());
        if (stats.node_cap) break;
        if (it + 1 == settings.max_iterations && growth.any_live()) stats.iteration_cap = true;
    }
    stats.nodes = growth.grown_count();
    return growth.take_grown(skeleton.graph.nodes.size(), lobe_index);
}

GrowthResult grow_tree(const std::vector<std::vector<glm::vec3>>& trunk_strokes, const std::vector<GrowthLobe>& lobes,
                       const GrowthSettings& settings, const SubtreeLibrary& library, std::uint64_t seed,
                       std::size_t max_tree_nodes)
{
    GrowthResult result;
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
    const std::size_t s = skeleton.graph.nodes.size();
    for (std::size_t l = 0; l < lobes.size(); ++l) {
        LobeGrowthStats stats;
        // The whole tree's cap (kMaxTreeNodes): a lobe grows at most the nodes left under it.
        const std::size_t left = max_tree_nodes - std::min(max_tree_nodes, result.tree.nodes.size());
        if (left == 0) {
            result.messages.push_back("lobe " + std::to_string(l + 1) + ": not grown, the tree already has " +
                                      std::to_string(result.tree.nodes.size()) + " nodes (limit " +
                                      std::to_string(max_tree_nodes) + ")");
            result.lobes.push_back(stats);
            continue;
        }
        GrowthSettings capped = settings;
        if (static_cast<std::size_t>(capped.max_nodes) > left) capped.max_nodes = static_cast<int>(left);
        std::vector<TreeNode> nodes =
            grow_in_lobe(skeleton, static_cast<int>(l), lobes[l], capped, library, seed, stats, &rays[l]);
        const int offset = static_cast<int>(result.tree.nodes.size());
        for (TreeNode& n : nodes) {
            if (n.parent >= static_cast<int>(s)) n.parent = offset + (n.parent - static_cast<int>(s));
            result.tree.nodes.push_back(n);
        }
        if (stats.node_cap)
            result.messages.push_back("lobe " + std::to_string(l + 1) + ": node cap of " +
                                      std::to_string(capped.max_nodes) + " reached; growth stopped early");
        if (stats.iteration_cap)
            result.messages.push_back("lobe " + std::to_string(l + 1) + ": iteration cap of " +
                                      std::to_string(settings.max_iterations) + " reached with attractors left");
        result.lobes.push_back(stats);
    }
    apply_species_form(result.tree, result.skeleton_nodes, settings); // droop and hang
    return result;
}

} // namespace lobe
