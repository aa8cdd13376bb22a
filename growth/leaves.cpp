#include "growth/leaves.h"

#include <algorithm>
#include <cmath>
#include <map>

#include <glm/geometric.hpp>

#include "core/errors.h"
#include "core/random.h"

namespace lobe {
namespace {

constexpr double kPi = 3.14159265358979323846;

/// The leaf stream of one node: keyed by the lobe and the node's ordinal inside it, never by
/// its global index.
SplitMix64 leaf_stream(std::uint64_t seed, int lobe, std::uint64_t ordinal)
{
    std::uint64_t s = splitmix64_finalize(seed ^ 0x6C6F6265u /* "lobe" */);
    s = splitmix64_finalize(s ^ (static_cast<std::uint64_t>(static_cast<std::int64_t>(lobe)) * 0xD1B54A32D192ED03ull));
    s = splitmix64_finalize(s ^ (ordinal * 0x8CB92BA72F3D8DD7ull + 0x632BE59BD9B4E019ull));
    return SplitMix64{s};
}

/// An orthonormal pair perpendicular to unit `n` (Duff et al. 2017, branchless ONB).
void perpendicular_basis(const glm::dvec3& n, glm::dvec3& b1, glm::dvec3& b2)
{
    const double sign = std::copysign(1.0, n.z);
    const double a = -1.0 / (sign + n.z);
    const double b = n.x * n.y * a;
    b1 = glm::dvec3(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
    b2 = glm::dvec3(b, sign + n.y * n.y * a, -n.y);
}

/// Ordinal of every node among the nodes of its lobe, in node order.
std::vector<std::uint32_t> ordinals_within_lobes(const TreeGraph& graph)
{
    std::vector<std::uint32_t> ordinal(graph.nodes.size());
    int lo = 0, hi = 0;
    for (const TreeNode& n : graph.nodes) {
        lo = std::min(lo, n.lobe);
        hi = std::max(hi, n.lobe);
    }
    const long long span = static_cast<long long>(hi) - lo + 1;
    if (span <= (1 << 20)) {
        std::vector<std::uint32_t> count(static_cast<std::size_t>(span), 0);
        for (std::size_t i = 0; i < graph.nodes.size(); ++i)
            ordinal[i] = count[static_cast<std::size_t>(graph.nodes[i].lobe - lo)]++;
    } else {
        std::map<int, std::uint32_t> count;
        for (std::size_t i = 0; i < graph.nodes.size(); ++i) ordinal[i] = count[graph.nodes[i].lobe]++;
    }
    return ordinal;
}

// --- leaf outlines --------------------------------------------------------------------------

enum class LeafShape { Ovate, Round, Needle };

LeafShape parse_shape(const std::string& shape)
{
    if (shape == "ovate") return LeafShape::Ovate;
    if (shape == "round") return LeafShape::Round;
    if (shape == "needle") return LeafShape::Needle;
    throw InvalidInput("leaf texture: unknown shape \"" + shape + "\" (expected \"ovate\", \"round\" or \"needle\")");
}

/// Half width of the blade (in texture units, 1 = half the image) at t ∈ [0, 1] from the
/// blade's base to its tip.
double blade_half_width(LeafShape shape, double t)
{
    if (t <= 0.0 || t >= 1.0) return 0.0;
    switch (shape) {
    case LeafShape::Ovate: return 0.9 * std::pow(std::sin(kPi * std::pow(t, 0.7)), 0.8);
    case LeafShape::Round: return 0.94 * std::sqrt(std::max(0.0, 1.0 - (2.0 * t - 1.0) * (2.0 * t - 1.0)));
    case LeafShape::Needle: return 0.2 * std::min(1.0, 8.0 * t) * std::pow(1.0 - t, 0.35);
    }
    return 0.0;
}

/// Smooth value noise in [0, 1] on a lattice of `cells` cells, deterministic.
double value_noise(double x, double y, int cells, std::uint64_t salt)
{
    const double fx = x * cells, fy = y * cells;
    const double ix = std::floor(fx), iy = std::floor(fy);
    const double tx = fx - ix, ty = fy - iy;
    auto lattice = [&](double cx, double cy) {
        const auto h = splitmix64_finalize(salt ^ (static_cast<std::uint64_t>(static_cast<std::int64_t>(cx)) * 0x9E3779B97F4A7C15ull) ^
                             (static_cast<std::uint64_t>(static_cast<std::int64_t>(cy)) * 0xC2B2AE3D27D4EB4Full));
        return static_cast<double>(h >> 11) * 0x1.0p-53;
    };
    const double sx = tx * tx * (3.0 - 2.0 * tx), sy = ty * ty * (3.0 - 2.0 * ty);
    const double a = lattice(ix, iy), b = lattice(ix + 1, iy), c = lattice(ix, iy + 1), d = lattice(ix + 1, iy + 1);
    return (a + (b - a) * sx) + ((c + (d - c) * sx) - (a + (b - a) * sx)) * sy;
}

std::uint8_t to_byte(double v) { return static_cast<std::uint8_t>(std::clamp(v, 0.0, 1.0) * 255.0 + 0.5); }

} // namespace

RgbaImage make_leaf_texture(const std::string& shape_name, int size)
{
    const LeafShape shape = parse_shape(shape_name);
    if (size < 8 || size > 4096) throw InvalidInput("leaf texture: size must be in [8, 4096]");
    RgbaImage img;
    img.width = img.height = size;
    img.pixels.resize(static_cast<std::size_t>(size) * static_cast<std::size_t>(size) * 4);

    constexpr double stalk_top = 0.1;  // the blade runs from here …
    constexpr double blade_top = 0.97; // … to here (y: 0 at the image's bottom)
    const double px_per_unit = size * 0.5; // texture units (x ∈ [−1, 1]) to pixels
    const double blade_len = blade_top - stalk_top;
    const int vein_pairs = shape == LeafShape::Round ? 5 : 7;
    const std::uint64_t salt = 0x1EAFull + static_cast<std::uint64_t>(shape);
    // Light, slightly green base colours: the material colour multiplies them.
    const double base[3] = {0.84, 0.9, 0.76};

    for (int py = 0; py < size; ++py) {
        const double y = 1.0 - (py + 0.5) / size;
        const double t = (y - stalk_top) / blade_len;
        const double hw = blade_half_width(shape, t);
        for (int px = 0; px < size; ++px) {
            const double x = (px + 0.5) / size * 2.0 - 1.0;
            const double ax = std::abs(x);
            // Coverage of the blade, antialiased over one pixel across the outline.
            double alpha = std::clamp((hw - ax) * px_per_unit + 0.5, 0.0, 1.0);
            double shade = 1.0;
            if (alpha > 0.0) {
                // Midrib, narrowing to the tip.
                const double rib = 0.028 * (1.0 - 0.7 * t);
                const double rib_px = (rib - ax) * px_per_unit;
                shade += 0.14 * std::clamp(rib_px + 0.5, 0.0, 1.0);
                // Side veins leaving the midrib towards the tip and the edge (not on needles).
                if (shape != LeafShape::Needle && hw > 1e-6) {
                    const double q = (t - 0.22 * ax / hw) * vein_pairs;
                    const double dist_px = std::abs(q - std::round(q)) / vein_pairs * blade_len * size;
                    const double fade = std::clamp(1.0 - ax / (0.85 * hw), 0.0, 1.0) * std::clamp((0.9 - t) * 8.0, 0.0, 1.0);
                    shade += 0.08 * fade * std::clamp(1.2 - dist_px, 0.0, 1.0);
                }
                // Darker towards the edge, soft mottling.
                shade -= 0.07 * std::clamp(1.0 - (hw - ax) / 0.12, 0.0, 1.0);
                shade -= 0.08 * value_noise(x * 0.5 + 0.5, y, 6, salt);
            }
            // Outside the blade: the stalk, then nothing.
            if (alpha < 1.0 && y > 0.015 && t <= 0.02) {
                const double stalk = std::clamp((0.03 - ax) * px_per_unit + 0.5, 0.0, 1.0);
                if (stalk > alpha) {
                    alpha = stalk;
                    shade = 0.9;
                }
            }
            std::uint8_t* p = &img.pixels[(static_cast<std::size_t>(py) * static_cast<std::size_t>(size) +
                                           static_cast<std::size_t>(px)) * 4];
            // Colour is kept outside the leaf too (alpha 0), so filtering does not darken edges.
            p[0] = to_byte(base[0] * shade);
            p[1] = to_byte(base[1] * shade);
            p[2] = to_byte(base[2] * shade);
            p[3] = to_byte(alpha);
        }
    }
    return img;
}

std::vector<int> leaf_tip_nodes(const TreeGraph& graph)
{
    const std::size_t n = graph.nodes.size();
    std::vector<char> has_child(n, 0);
    for (std::size_t i = 1; i < n; ++i) {
        const int p = graph.nodes[i].parent;
        if (p >= 0 && static_cast<std::size_t>(p) < i) has_child[static_cast<std::size_t>(p)] = 1;
    }
    std::vector<int> tips;
    for (std::size_t i = 1; i < n; ++i) {
        const TreeNode& node = graph.nodes[i];
        if (!has_child[i] && node.parent >= 0 && static_cast<std::size_t>(node.parent) < i &&
            node.kind == TreeNodeKind::Grown)
            tips.push_back(static_cast<int>(i));
    }
    return tips;
}

double leaf_lod_keep_fraction(int lod) { return std::pow(0.5, std::max(0, lod)); }

LeafCloud make_leaf_cloud(const TreeGraph& graph, const LeafSettings& leaves, std::uint64_t seed,
                          const LobeLeafOverrides& per_lobe)
{
    for (std::size_t i = 0; i < per_lobe.size(); ++i) {
        const LobeLeafOverride& o = per_lobe[i];
        if (o.length_m && !(*o.length_m > 0.0 && *o.length_m <= 1.0))
            throw InvalidInput("leaves: lobe " + std::to_string(i) + " leaf length must be in (0, 1] m");
        if (o.per_node && (*o.per_node < 0 || *o.per_node > 64))
            throw InvalidInput("leaves: lobe " + std::to_string(i) + " leaves per node must be in [0, 64]");
    }
    LeafCloud cloud;
    const int per_node = std::max(0, leaves.per_node);
    cloud.per_node = per_node;
    int most = per_node;
    for (const LobeLeafOverride& o : per_lobe) most = std::max(most, o.per_node.value_or(0));
    if (most == 0 || graph.nodes.size() < 2) return cloud;
    const std::vector<int> tips = leaf_tip_nodes(graph);
    const std::vector<std::uint32_t> ordinal = ordinals_within_lobes(graph);
    const double cos_dev = std::cos(std::clamp(leaves.deviation_deg, 0.0, 180.0) * kPi / 180.0);
    cloud.leaves.reserve(tips.size() * static_cast<std::size_t>(per_node));
    // A uniform direction in the plane of (a, b), by rejection: no trigonometry, so the draws
    // give the same bits wherever the math library differs.
    auto unit_in_plane = [](SplitMix64& rng, const glm::dvec3& a, const glm::dvec3& b) {
        for (;;) {
            const double x = 2.0 * rng.uniform() - 1.0, y = 2.0 * rng.uniform() - 1.0;
            const double s2 = x * x + y * y;
            if (s2 <= 1.0 && s2 > 1e-8) return (x * a + y * b) / std::sqrt(s2);
        }
    };
    for (const int tip : tips) {
        const TreeNode& node = graph.nodes[static_cast<std::size_t>(tip)];
        const glm::dvec3 base(node.position);
        // Branch direction: from the nearest ancestor not at the tip's position.
        glm::dvec3 dir(0.0, 1.0, 0.0);
        for (int a = node.parent; a >= 0; a = graph.nodes[static_cast<std::size_t>(a)].parent) {
            const glm::dvec3 d = base - glm::dvec3(graph.nodes[static_cast<std::size_t>(a)].position);
            const double len = glm::length(d);
            if (len > 1e-7) {
                dir = d / len;
                break;
            }
        }
        // The tree's leaves, or the lobe's own.
        int tip_count = per_node;
        std::uint64_t tip_seed = seed;
        double length = leaves.length_m, width = leaves.width_m;
        if (node.lobe >= 0 && static_cast<std::size_t>(node.lobe) < per_lobe.size()) {
            const LobeLeafOverride& o = per_lobe[static_cast<std::size_t>(node.lobe)];
            tip_count = o.per_node.value_or(per_node);
            tip_seed = o.seed.value_or(seed);
            if (o.length_m) {
                width = leaves.length_m > 0.0 ? *o.length_m * (leaves.width_m / leaves.length_m) : leaves.width_m;
                length = *o.length_m;
            }
        }
        if (tip_count == 0) continue;
        SplitMix64 rng = leaf_stream(tip_seed, node.lobe, ordinal[static_cast<std::size_t>(tip)]);
        // Always drawn first, so every LOD sees the same leaf draws after it.
        const auto keep_offset = static_cast<float>(rng.uniform());
        glm::dvec3 e1, e2;
        perpendicular_basis(dir, e1, e2);
        for (int j = 0; j < tip_count; ++j) {
            // Axis: uniform over the spherical cap of half-angle deviation_deg around dir.
            const double cos_t = 1.0 - rng.uniform() * (1.0 - cos_dev);
            const double sin_t = std::sqrt(std::max(0.0, 1.0 - cos_t * cos_t));
            const glm::dvec3 axis = glm::normalize(cos_t * dir + sin_t * unit_in_plane(rng, e1, e2));
            // Roll about the axis.
            glm::dvec3 a1, a2;
            perpendicular_basis(axis, a1, a2);
            const glm::dvec3 across = unit_in_plane(rng, a1, a2);
            cloud.leaves.push_back(
                {glm::vec3(base), glm::vec3(axis), glm::vec3(across), tip, j, tip_count, keep_offset, length, width});
        }
    }
    return cloud;
}

LeafCloud make_placed_leaf_cloud(const std::vector<PlacedLeaf>& placed, std::uint64_t seed)
{
    auto finite3 = [](const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); };
    LeafCloud cloud;
    cloud.per_node = 1;
    cloud.leaves.reserve(placed.size());
    // Keyed apart from the tip leaves' streams (leaf_stream's lobe −2 is used by no lobe).
    constexpr int kPlacedStream = -2;
    for (std::size_t i = 0; i < placed.size(); ++i) {
        const PlacedLeaf& p = placed[i];
        if (!finite3(p.base) || !finite3(p.axis) || !finite3(p.across) || !(p.length_m > 0.0f) || !(p.width_m > 0.0f) ||
            !std::isfinite(p.length_m) || !std::isfinite(p.width_m))
            throw InvalidInput("leaves: placed leaf " + std::to_string(i) + " has a non-finite position or direction, or a size not > 0");
        SplitMix64 rng = leaf_stream(seed, kPlacedStream, i);
        const auto keep_offset = static_cast<float>(rng.uniform());
        cloud.leaves.push_back({p.base, p.axis, p.across, p.node, 0, 1, keep_offset, static_cast<double>(p.length_m),
                                static_cast<double>(p.width_m)});
    }
    return cloud;
}

namespace {
void check_keep(double keep)
{
    if (!(keep > 0.0 && keep <= 1.0)) throw InvalidInput("leaves: keep_fraction must be in (0, 1]");
}
int kept_per_tip(int per_node, double keep, float offset)
{
    return keep >= 1.0 ? per_node : std::min(per_node, static_cast<int>(std::floor(per_node * keep + static_cast<double>(offset))));
}
} // namespace

std::size_t count_leaf_quads(const LeafCloud& cloud, double keep_fraction)
{
    check_keep(keep_fraction);
    std::size_t n = 0;
    for (const LeafCloud::Leaf& leaf : cloud.leaves)
        n += leaf.rank < kept_per_tip(leaf.per_node, keep_fraction, leaf.keep_offset);
    return n;
}

void emit_leaf_quads(const LeafCloud& cloud, const LeafLodOptions& lod, SurfaceGeometry& out, std::vector<int>* quad_nodes)
{
    check_keep(lod.keep_fraction);
    const double keep = lod.keep_fraction;
    const std::size_t quads = count_leaf_quads(cloud, keep);
    out.positions.clear();
    out.normals.clear();
    out.uvs.clear();
    out.triangles.clear();
    out.positions.reserve(quads * 4);
    out.normals.reserve(quads * 4);
    out.uvs.reserve(quads * 4);
    out.triangles.reserve(quads * 2);
    if (quad_nodes) {
        quad_nodes->clear();
        quad_nodes->reserve(quads);
    }
    // Area × 1/keep, mostly in width: a coarse leaf grows a little longer and much wider,
    // centred where the LOD0 leaf was, so the crown's outline stays where LOD0's is (longer
    // leaves would reach out of it).
    const double grow = 1.0 / keep;
    const double length_scale = std::pow(grow, 0.125), width_scale = grow / length_scale;
    for (const LeafCloud::Leaf& leaf : cloud.leaves) {
        if (leaf.rank >= kept_per_tip(leaf.per_node, keep, leaf.keep_offset)) continue;
        const auto length = static_cast<float>(leaf.length_m * length_scale);
        const auto half_width = static_cast<float>(0.5 * leaf.width_m * width_scale);
        const auto back = static_cast<float>(0.5 * leaf.length_m * (length_scale - 1.0));
        const glm::vec3 normal = glm::normalize(glm::cross(leaf.across, leaf.axis));
        const auto first = static_cast<std::uint32_t>(out.positions.size());
        const glm::vec3 side = half_width * leaf.across, up = length * leaf.axis;
        const glm::vec3 base = leaf.base - back * leaf.axis;
        out.positions.push_back(base - side);
        out.positions.push_back(base + side);
        out.positions.push_back(base + up + side);
        out.positions.push_back(base + up - side);
        out.uvs.emplace_back(0.0f, 1.0f);
        out.uvs.emplace_back(1.0f, 1.0f);
        out.uvs.emplace_back(1.0f, 0.0f);
        out.uvs.emplace_back(0.0f, 0.0f);
        for (int k = 0; k < 4; ++k) out.normals.push_back(normal);
        out.triangles.push_back({first, first + 1, first + 2});
        out.triangles.push_back({first, first + 2, first + 3});
        if (quad_nodes) quad_nodes->push_back(leaf.node);
    }
}

SurfaceGeometry build_leaf_quads(const TreeGraph& graph, const LeafSettings& leaves, std::uint64_t seed,
                                 const LeafLodOptions& lod, std::vector<int>* quad_nodes)
{
    check_keep(lod.keep_fraction);
    SurfaceGeometry out;
    emit_leaf_quads(make_leaf_cloud(graph, leaves, seed), lod, out, quad_nodes);
    return out;
}

} // namespace lobe
