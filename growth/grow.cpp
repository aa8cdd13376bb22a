#include "growth/grow.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>

#include <glm/geometric.hpp>
#include <nanoflann.hpp>

#include "core/errors.h"
#include "core/random.h"
#include "growth/mesh_raycast.h"

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

std::vector<TreeNode> grow_in_lobe(const Skeleton& skeleton, int lobe_index, const GrowthLobe& lobe,
                                   const GrowthSettings& settings, const SubtreeLibrary& library,
                                   std::uint64_t seed, LobeGrowthStats& stats, const MeshRaycaster* shared_ray)
{
    stats = {};
    if (library.subtrees.empty()) throw InvalidInput("growth: the subtree library is empty");
    std::vector<double> weights = lobe.subtree_weights;
    if (weights.size() != library.subtrees.size()) weights.assign(library.subtrees.size(), 1.0);

    // Local nodes: the skeleton nodes this lobe grows from, then the nodes it grows.
    const std::size_t skeleton_size = skeleton.graph.nodes.size();
    std::vector<glm::vec3> pos;
    std::vector<glm::vec3> heading; // V_default of each node: its own direction
    std::vector<int> global;        // local → skeleton index (skeleton nodes only)
    std::vector<int> local_of(skeleton_size, -1);
    for (std::size_t i = 0; i < skeleton_size; ++i) {
        if (skeleton.owner[i] != -1 && skeleton.owner[i] != lobe_index) continue;
        const TreeNode& n = skeleton.graph.nodes[i];
        glm::vec3 h(0, 1, 0);
        if (n.parent >= 0) {
            const glm::vec3 d = n.position - skeleton.graph.nodes[static_cast<std::size_t>(n.parent)].position;
            if (glm::length(d) > 1e-7f) h = glm::normalize(d);
        }
        local_of[i] = static_cast<int>(pos.size());
        pos.push_back(n.position);
        heading.push_back(h);
        global.push_back(static_cast<int>(i));
    }
    const std::size_t start_nodes = pos.size();
    std::vector<TreeNode> grown;
    if (start_nodes == 0 || lobe.mesh.positions.empty()) return grown;

    const std::vector<glm::vec3>& attractors = lobe.mesh.positions;
    const std::size_t na = attractors.size();
    stats.attractors = na;
    std::optional<MeshRaycaster> own_ray;
    if (!shared_ray) own_ray.emplace(lobe.mesh);
    const MeshRaycaster& ray = shared_ray ? *shared_ray : *own_ray;
    const float kill2 = static_cast<float>(settings.kill_distance_m * settings.kill_distance_m);

    std::vector<std::uint8_t> live(na, 1);
    std::vector<std::uint32_t> nearest(na, 0);
    std::vector<float> nearest_d2(na, std::numeric_limits<float>::max());
    std::vector<std::uint8_t> growths;
    growths.assign(start_nodes, 0);
    std::vector<std::uint8_t> stopped(start_nodes, 0);

    // Once a lobe has branch nodes inside it, only nodes inside it take its attractors, so
    // branches grow through the lobe rather than around its thin parts from outside. A lobe
    // that the skeleton does not enter is grown into from outside (signed distance, §5.2).
    std::vector<std::uint8_t> eligible(start_nodes, 0);
    bool inside_only = false;
    for (std::size_t i = 0; i < start_nodes; ++i) {
        eligible[i] = ray.inside(pos[i]) ? 1 : 0;
        inside_only = inside_only || eligible[i];
    }
    if (!inside_only) eligible.assign(start_nodes, 1);

    // Each attractor keeps its nearest node; only nodes added since are compared (§5.2).
    std::vector<std::uint32_t> batch;
    auto update_nearest = [&](std::size_t begin, std::size_t end) {
        batch.clear();
        for (std::size_t i = begin; i < end; ++i)
            if (eligible[i]) batch.push_back(static_cast<std::uint32_t>(i));
        if (batch.empty()) return;
        NodeSubset subset{&pos, &batch};
        NodeIndex index(3, subset, nanoflann::KDTreeSingleIndexAdaptorParams(12));
        for (std::size_t a = 0; a < na; ++a) {
            if (!live[a]) continue;
            std::uint32_t idx = 0;
            float d2 = 0.0f;
            if (index.knnSearch(&attractors[a].x, 1, &idx, &d2) == 0) continue;
            if (d2 < nearest_d2[a]) {
                nearest_d2[a] = d2;
                nearest[a] = batch[idx];
            }
            if (nearest_d2[a] < kill2) {
                live[a] = 0;
                ++stats.reached;
            }
        }
    };
    update_nearest(0, start_nodes);

    const double t = lobe.split_angle_deg;
    const std::size_t node_cap = static_cast<std::size_t>(settings.max_nodes);
    std::vector<std::uint32_t> order, count;
    std::vector<glm::vec3> cluster, dirs, piece_pts;
    for (int it = 0; it < settings.max_iterations; ++it) {
        // Group the live attractors by their nearest node (a counting sort keeps node order).
        count.assign(pos.size() + 1, 0);
        std::size_t live_count = 0;
        for (std::size_t a = 0; a < na; ++a)
            if (live[a]) {
                ++count[nearest[a] + 1];
                ++live_count;
            }
        if (live_count == 0) break;
        for (std::size_t i = 1; i < count.size(); ++i) count[i] += count[i - 1];
        order.assign(live_count, 0);
        {
            std::vector<std::uint32_t> fill(count.begin(), count.end() - 1);
            for (std::size_t a = 0; a < na; ++a)
                if (live[a]) order[fill[nearest[a]]++] = static_cast<std::uint32_t>(a);
        }
        const std::size_t batch_begin = pos.size();
        const std::size_t active_end = pos.size();
        for (std::size_t n = 0; n < active_end && !stats.node_cap; ++n) {
            const std::uint32_t first = count[n], last = count[n + 1];
            if (first == last) continue;
            auto drop = [&](std::uint32_t from, std::uint32_t to, const std::vector<int>* subset) {
                if (subset) {
                    for (int k : *subset) {
                        live[order[from + static_cast<std::uint32_t>(k)]] = 0;
                        ++stats.stopped;
                    }
                } else {
                    for (std::uint32_t k = from; k < to; ++k) {
                        live[order[k]] = 0;
                        ++stats.stopped;
                    }
                }
            };
            if (stopped[n] || growths[n] >= kMaxGrowthsPerNode) {
                stopped[n] = 1;
                drop(first, last, nullptr);
                continue;
            }
            cluster.clear();
            dirs.clear();
            for (std::uint32_t k = first; k < last; ++k) {
                const glm::vec3& a = attractors[order[k]];
                cluster.push_back(a);
                const glm::vec3 v = a - pos[n];
                const float l = glm::length(v);
                dirs.push_back(l > 1e-9f ? v / l : glm::vec3(0, 1, 0));
            }
            const std::vector<std::vector<int>> pieces = split_cluster(dirs, t);
            bool grew = false;
            for (std::size_t p = 0; p < pieces.size() && !stats.node_cap; ++p) {
                piece_pts.clear();
                for (int k : pieces[p]) piece_pts.push_back(cluster[static_cast<std::size_t>(k)]);
                const glm::dvec3 vc = cluster_direction(pos[n], piece_pts);
                glm::dvec3 va = growth_vector(vc, glm::dvec3(heading[n]), settings.alpha, settings.beta);
                if (glm::length(va) < 1e-9) va = vc;
                const glm::vec3 dir = glm::vec3(glm::normalize(va));
                bool node_inside = false;
                glm::vec3 dir_used = dir;
                float s = ray.signed_distance_along(pos[n], dir, &node_inside);
                // The stop rule is for grown tips. A sketched skeleton node is not a tip: where
                // V_A would stop it at the surface (a trunk running close under a flat lobe's
                // top, pointing up), it sprouts along V_cluster, towards its attractors, instead.
                if (n < start_nodes && s >= 0.0f && s < static_cast<float>(settings.stop_distance_m)) {
                    dir_used = glm::vec3(vc);
                    s = ray.signed_distance_along(pos[n], dir_used, &node_inside);
                }
                // Outside the lobe with V_A missing it: nothing to grow towards from here.
                // The attractors stay live, so nodes grown nearer can take them; the
                // node's attempts are bounded by kMaxGrowthsPerNode.
                if (!(s >= 0.0f)) continue;
                // §5.2's stop rule: too close to the surface along V_A.
                if (s < static_cast<float>(settings.stop_distance_m)) {
                    drop(first, last, &pieces[p]);
                    continue;
                }
                const float length = static_cast<float>(settings.growth_ratio) * s;
                Stream rng(lobe.seed.value_or(seed), lobe.id, n, growths[n], p);
                const std::size_t sub = pick_weighted(weights, rng.uniform());
                const Subtree& st = library.subtrees[sub];
                const Frame f = frame_along(dir_used, rng.uniform() * 2 * kPi);
                const std::size_t base = pos.size();
                const bool root_inside = node_inside;
                for (std::size_t j = 1; j < st.nodes.size(); ++j) {
                    const int sp = st.parents[j];
                    const std::size_t parent = sp == 0 ? n : base + static_cast<std::size_t>(sp) - 1;
                    // Each segment of the subtree, turned and scaled, from where its parent ended up.
                    glm::vec3 q = pos[parent] + length * f.apply(st.nodes[j] - st.nodes[static_cast<std::size_t>(sp)]);
                    glm::vec3 d = q - pos[parent];
                    // A segment grown from inside the lobe stays inside: where it would leave
                    // through a thin part of the lobe it ends short of the surface instead.
                    const float seg = glm::length(d);
                    if (root_inside && seg > 1e-9f) {
                        const float hit = ray.first_hit(pos[parent], d / seg, seg);
                        if (hit >= 0.0f && hit < seg) {
                            q = pos[parent] + (kClipFraction * hit / seg) * d;
                            d = q - pos[parent];
                        }
                    }
                    pos.push_back(q);
                    eligible.push_back(!inside_only || root_inside || ray.inside(q) ? 1 : 0);
                    heading.push_back(glm::length(d) > 1e-9f ? glm::normalize(d) : dir);
                    growths.push_back(0);
                    stopped.push_back(0);
                    TreeNode node;
                    node.position = q;
                    node.parent = static_cast<int>(parent); // local for now
                    node.subtree_id = static_cast<int>(sub);
                    node.kind = TreeNodeKind::Grown;
                    grown.push_back(node);
                }
                ++stats.subtrees;
                grew = true;
                if (grown.size() >= node_cap) stats.node_cap = true;
            }
            ++growths[n];
            if (!grew) stopped[n] = 1;
        }
        ++stats.iterations;
        if (pos.size() == batch_begin) break;
        update_nearest(batch_begin, pos.size());
        if (stats.node_cap) break;
        if (it + 1 == settings.max_iterations)
            for (std::size_t a = 0; a < na; ++a)
                if (live[a]) {
                    stats.iteration_cap = true;
                    break;
                }
    }
    stats.nodes = grown.size();

    // Parents to the output convention: skeleton indices below skeleton_size, then ours.
    for (TreeNode& node : grown) {
        const auto p = static_cast<std::size_t>(node.parent);
        node.parent = p < start_nodes ? global[p] : static_cast<int>(skeleton_size + (p - start_nodes));
        node.lobe = lobe_index;
    }
    return grown;
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
    return result;
}

} // namespace lobe
