#include "growth/leaf_lod.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>

#include "core/errors.h"

namespace lobe {

namespace {

/// Bilinear sample of `img` at (x, y) in pixels (pixel centres at .5); outside: transparent.
std::array<double, 4> sample(const RgbaImage& img, double x, double y)
{
    std::array<double, 4> out{0.0, 0.0, 0.0, 0.0};
    const double fx = x - 0.5, fy = y - 0.5;
    const double x0 = std::floor(fx), y0 = std::floor(fy);
    const double tx = fx - x0, ty = fy - y0;
    for (int dy = 0; dy < 2; ++dy)
        for (int dx = 0; dx < 2; ++dx) {
            const int px = static_cast<int>(x0) + dx, py = static_cast<int>(y0) + dy;
            if (px < 0 || py < 0 || px >= img.width || py >= img.height) continue;
            const double w = (dx ? tx : 1.0 - tx) * (dy ? ty : 1.0 - ty);
            const std::uint8_t* p = &img.pixels[(static_cast<std::size_t>(py) * static_cast<std::size_t>(img.width) +
                                                 static_cast<std::size_t>(px)) * 4];
            for (std::size_t k = 0; k < 4; ++k) out[k] += w * p[k];
        }
    return out;
}

/// One leaf of the spray: turn (radians, + is counter-clockwise in the picture), size as a
/// share of the cell, and where its stalk sits (share of the cell from the left, bottom).
struct SprayLeaf {
    double turn, size, x, y;
};
// A fan from the bottom centre, back to front: the upright leaf last, on top.
constexpr SprayLeaf kSpray[] = {
    {1.45, 0.5, 0.50, 1.0},  {-1.45, 0.5, 0.50, 1.0}, {1.15, 0.62, 0.50, 1.0}, {-1.15, 0.62, 0.50, 1.0},
    {0.85, 0.78, 0.49, 1.0}, {-0.85, 0.78, 0.51, 1.0}, {0.55, 0.9, 0.49, 1.0},  {-0.55, 0.9, 0.51, 1.0},
    {0.27, 0.98, 0.49, 1.0}, {-0.27, 0.98, 0.51, 1.0}, {0.0, 1.0, 0.50, 1.0},
};

} // namespace

RgbaImage make_leaf_atlas(const RgbaImage& leaf)
{
    if (leaf.width <= 0 || leaf.width != leaf.height ||
        leaf.pixels.size() != static_cast<std::size_t>(leaf.width) * static_cast<std::size_t>(leaf.height) * 4u)
        throw InvalidInput("leaf atlas: the leaf picture must be square and non-empty");
    const int n = leaf.width;
    RgbaImage atlas;
    atlas.width = 2 * n;
    atlas.height = n;
    atlas.pixels.assign(static_cast<std::size_t>(atlas.width) * static_cast<std::size_t>(n) * 4u, 0);
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            const std::uint8_t* src = &leaf.pixels[(static_cast<std::size_t>(y) * static_cast<std::size_t>(n) +
                                                    static_cast<std::size_t>(x)) * 4];
            std::uint8_t* left = &atlas.pixels[(static_cast<std::size_t>(y) * static_cast<std::size_t>(atlas.width) +
                                                static_cast<std::size_t>(x)) * 4];
            std::copy(src, src + 4, left);
            std::uint8_t* right = left + static_cast<std::size_t>(n) * 4;
            std::copy(src, src + 3, right); // the leaf's colour under alpha 0, as in the picture
        }
    // The spray: each leaf maps the cell's pixel back into the leaf picture (its stalk, the
    // picture's bottom centre, at the spray leaf's stalk position) and is laid over by alpha.
    for (const SprayLeaf& s : kSpray) {
        const double c = std::cos(s.turn), sn = std::sin(s.turn);
        const double scale = 1.0 / s.size; // cell pixels to picture pixels
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                const double dx = (x + 0.5) - s.x * n, dy = (y + 0.5) - s.y * n;
                // Turn the offset back by the leaf's turn (picture y runs down).
                const double lx = (c * dx - sn * dy) * scale, ly = (sn * dx + c * dy) * scale;
                const std::array<double, 4> t = sample(leaf, 0.5 * n + lx, static_cast<double>(n) + ly);
                const double a = t[3] / 255.0;
                if (a <= 0.0) continue;
                std::uint8_t* p = &atlas.pixels[(static_cast<std::size_t>(y) * static_cast<std::size_t>(atlas.width) +
                                                 static_cast<std::size_t>(n + x)) * 4];
                const double under = p[3] / 255.0;
                for (std::size_t k = 0; k < 3; ++k) {
                    const double colour = t[k] / a; // un-premultiply the filtered colour
                    p[k] = static_cast<std::uint8_t>(std::clamp(colour * a + p[k] * (1.0 - a), 0.0, 255.0) + 0.5);
                }
                p[3] = static_cast<std::uint8_t>(std::clamp((a + under * (1.0 - a)) * 255.0, 0.0, 255.0) + 0.5);
            }
    }
    return atlas;
}

void use_single_leaf_half(SurfaceGeometry& leaves)
{
    for (glm::vec2& uv : leaves.uvs) uv.x *= 0.5f;
}

namespace {

/// Spreads the low 21 bits of v to every third bit.
std::uint64_t spread3(std::uint64_t v)
{
    v &= 0x1FFFFFull;
    v = (v | v << 32) & 0x1F00000000FFFFull;
    v = (v | v << 16) & 0x1F0000FF0000FFull;
    v = (v | v << 8) & 0x100F00F00F00F00Full;
    v = (v | v << 4) & 0x10C30C30C30C30C3ull;
    v = (v | v << 2) & 0x1249249249249249ull;
    return v;
}

glm::dvec3 leaf_centre(const LeafCloud::Leaf& l) { return glm::dvec3(l.base) + 0.5 * l.length_m * glm::dvec3(l.axis); }

void push_quad(SurfaceGeometry& out, const std::array<glm::vec3, 4>& corners, const glm::vec3& normal, float u0, float u1)
{
    const auto first = static_cast<std::uint32_t>(out.positions.size());
    for (const glm::vec3& p : corners) out.positions.push_back(p);
    out.uvs.emplace_back(u0, 1.0f);
    out.uvs.emplace_back(u1, 1.0f);
    out.uvs.emplace_back(u1, 0.0f);
    out.uvs.emplace_back(u0, 0.0f);
    for (int k = 0; k < 4; ++k) out.normals.push_back(normal);
    out.triangles.push_back({first, first + 1, first + 2});
    out.triangles.push_back({first, first + 2, first + 3});
}

/// The card of the leaves `order[begin, end)` (indices into cloud.leaves).
/// The card of the leaves `order[begin, end)` (indices into cloud.leaves); with `single`, a
/// lone leaf keeps its own quad on the single-leaf half, else every card shows the spray
/// (one texture rectangle for all cards, so a renderer can draw them instanced).
void emit_card(const LeafCloud& cloud, const std::vector<std::pair<std::uint64_t, std::uint32_t>>& order,
               std::size_t begin, std::size_t end, bool single, SurfaceGeometry& out)
{
    const LeafCloud::Leaf& first = cloud.leaves[order[begin].second];
    if (end - begin == 1) { // a lone leaf keeps its own rectangle
        const glm::vec3 side = static_cast<float>(0.5 * first.width_m) * first.across;
        const glm::vec3 up = static_cast<float>(first.length_m) * first.axis;
        push_quad(out, {first.base - side, first.base + side, first.base + up + side, first.base + up - side},
                  glm::normalize(glm::cross(first.across, first.axis)), single ? 0.0f : 0.5f, single ? 0.5f : 1.0f);
        return;
    }
    glm::dvec3 axis(0.0), centre(0.0);
    for (std::size_t i = begin; i < end; ++i) {
        const LeafCloud::Leaf& l = cloud.leaves[order[i].second];
        axis += glm::dvec3(l.axis);
        centre += glm::dvec3(l.base);
    }
    centre /= static_cast<double>(end - begin);
    axis = glm::length(axis) > 1e-6 ? glm::normalize(axis) : glm::dvec3(first.axis);
    glm::dvec3 across = glm::dvec3(first.across) - glm::dot(glm::dvec3(first.across), axis) * axis;
    if (glm::length(across) < 1e-6) across = glm::dvec3(first.axis) - glm::dot(glm::dvec3(first.axis), axis) * axis;
    if (glm::length(across) < 1e-6) across = std::abs(axis.y) < 0.9 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0);
    across = glm::normalize(across - glm::dot(across, axis) * axis);
    // The box of every leaf corner, in the card's plane.
    double a0 = 1e300, a1 = -1e300, b0 = 1e300, b1 = -1e300;
    for (std::size_t i = begin; i < end; ++i) {
        const LeafCloud::Leaf& l = cloud.leaves[order[i].second];
        const glm::dvec3 side = 0.5 * l.width_m * glm::dvec3(l.across), up = l.length_m * glm::dvec3(l.axis);
        const glm::dvec3 base = glm::dvec3(l.base) - centre;
        for (const glm::dvec3& p : {base - side, base + side, base + up + side, base + up - side}) {
            const double a = glm::dot(p, axis), b = glm::dot(p, across);
            a0 = std::min(a0, a);
            a1 = std::max(a1, a);
            b0 = std::min(b0, b);
            b1 = std::max(b1, b);
        }
    }
    // A tilted card's corners may stand past its leaves: shrink it about its middle (moved
    // into the leaves' box) until every corner lies in the box of the leaves' corners.
    glm::dvec3 lo(1e300), hi(-1e300);
    for (std::size_t i = begin; i < end; ++i) {
        const LeafCloud::Leaf& l = cloud.leaves[order[i].second];
        const glm::dvec3 side = 0.5 * l.width_m * glm::dvec3(l.across), up = l.length_m * glm::dvec3(l.axis);
        for (const glm::dvec3& p : {glm::dvec3(l.base) - side, glm::dvec3(l.base) + side, glm::dvec3(l.base) + up + side,
                                    glm::dvec3(l.base) + up - side}) {
            lo = glm::min(lo, p);
            hi = glm::max(hi, p);
        }
    }
    const glm::dvec3 middle = glm::clamp(centre + 0.5 * (a0 + a1) * axis + 0.5 * (b0 + b1) * across, lo, hi);
    std::array<glm::dvec3, 4> corners{centre + a0 * axis + b0 * across, centre + a0 * axis + b1 * across,
                                      centre + a1 * axis + b1 * across, centre + a1 * axis + b0 * across};
    double shrink = 1.0;
    for (const glm::dvec3& c : corners)
        for (int k = 0; k < 3; ++k) {
            const double d = c[k] - middle[k];
            if (d > 1e-12 && middle[k] + d > hi[k]) shrink = std::min(shrink, (hi[k] - middle[k]) / d);
            if (d < -1e-12 && middle[k] + d < lo[k]) shrink = std::min(shrink, (lo[k] - middle[k]) / d);
        }
    std::array<glm::vec3, 4> quad;
    for (std::size_t k = 0; k < 4; ++k) quad[k] = glm::vec3(glm::clamp(middle + shrink * (corners[k] - middle), lo, hi));
    const glm::vec3 normal = glm::normalize(glm::cross(glm::vec3(across), glm::vec3(axis)));
    push_quad(out, quad, normal, 0.5f, 1.0f);
}

} // namespace

void emit_leaf_cluster_cards(const LeafCloud& cloud, std::size_t max_cards, SurfaceGeometry& out)
{
    out.positions.clear();
    out.normals.clear();
    out.uvs.clear();
    out.triangles.clear();
    const std::size_t n = cloud.leaves.size();
    if (n == 0 || max_cards == 0) return;
    // Morton codes of the leaf centres in the bounding cube of them all.
    glm::dvec3 lo(1e300), hi(-1e300);
    for (const LeafCloud::Leaf& l : cloud.leaves) {
        lo = glm::min(lo, leaf_centre(l));
        hi = glm::max(hi, leaf_centre(l));
    }
    const glm::dvec3 extent = hi - lo;
    const double side = std::max({extent.x, extent.y, extent.z, 1e-9});
    constexpr double kCells = 2097152.0; // 2^21 per axis
    std::vector<std::pair<std::uint64_t, std::uint32_t>> order(n);
    for (std::size_t i = 0; i < n; ++i) {
        const glm::dvec3 q = (leaf_centre(cloud.leaves[i]) - lo) / side * kCells;
        auto cell = [&](double v) { return static_cast<std::uint64_t>(std::clamp(v, 0.0, kCells - 1.0)); };
        order[i] = {spread3(cell(q.x)) << 2 | spread3(cell(q.y)) << 1 | spread3(cell(q.z)), static_cast<std::uint32_t>(i)};
    }
    std::sort(order.begin(), order.end()); // ties: by leaf index
    // The finest level (bits of prefix kept, a multiple of 3: one octree level) whose groups
    // number no more than max_cards; the number of groups only grows with the level.
    auto groups = [&](int level) {
        const int shift = 63 - 3 * level;
        std::size_t count = 0;
        for (std::size_t i = 0; i < n; ++i)
            count += i == 0 || (order[i].first >> shift) != (order[i - 1].first >> shift);
        return count;
    };
    if (n <= max_cards) { // every leaf alone
        for (std::size_t i = 0; i < n; ++i) emit_card(cloud, order, i, i + 1, true, out);
        return;
    }
    int level = 0;
    while (level < 21 && groups(level + 1) <= max_cards) ++level;
    // Groups at that level, then, in Morton order, each split into its cells one level finer
    // while the total stays within max_cards: the count comes close to the limit.
    auto prefix = [&](std::size_t i, int lv) { return lv == 0 ? 0 : order[i].first >> (63 - 3 * lv); };
    std::vector<std::size_t> starts;
    for (std::size_t i = 0; i < n; ++i)
        if (i == 0 || prefix(i, level) != prefix(i - 1, level)) starts.push_back(i);
    std::size_t total = starts.size();
    out.positions.reserve(max_cards * 4);
    for (std::size_t g = 0; g < starts.size(); ++g) {
        const std::size_t begin = starts[g], end = g + 1 < starts.size() ? starts[g + 1] : n;
        std::vector<std::size_t> cuts{begin};
        if (level < 21)
            for (std::size_t i = begin + 1; i < end; ++i)
                if (prefix(i, level + 1) != prefix(i - 1, level + 1)) cuts.push_back(i);
        if (total + cuts.size() - 1 > max_cards) cuts.resize(1);
        total += cuts.size() - 1;
        cuts.push_back(end);
        for (std::size_t c = 0; c + 1 < cuts.size(); ++c) emit_card(cloud, order, cuts[c], cuts[c + 1], false, out);
    }
}

} // namespace lobe
