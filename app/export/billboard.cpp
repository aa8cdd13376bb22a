#include "app/export/billboard.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include <glm/geometric.hpp>

#include "app/export/export_scene.h"
#include "core/errors.h"

namespace lobe {

namespace {

/// One card's view: the card spans u along `h` and v along `w` (image rows run against w);
/// the viewer looks along −n from the side n points to.
struct View {
    glm::vec3 h, w, n;
    float offset = 0.0f; ///< the card's plane is dot(p, n) = offset
    float u0 = 0, u1 = 0, v0 = 0, v1 = 0;
};

/// Linear colour of an sRGB texel (nearest), with its alpha byte; REPEAT or CLAMP.
struct Texel {
    glm::vec3 rgb;
    int alpha;
};

class TextureReader {
public:
    TextureReader(const RgbaImage* image, bool repeat) : image_(image), repeat_(repeat)
    {
        for (int i = 0; i < 256; ++i) lut_[static_cast<std::size_t>(i)] = static_cast<float>(srgb_to_linear(static_cast<std::uint8_t>(i)));
    }
    Texel at(glm::vec2 uv) const
    {
        if (image_ == nullptr || image_->width <= 0 || image_->height <= 0) return {glm::vec3(1.0f), 255};
        auto index = [&](float t, int size) {
            int i = static_cast<int>(std::floor(t * static_cast<float>(size)));
            if (repeat_) {
                i %= size;
                return i < 0 ? i + size : i;
            }
            return std::clamp(i, 0, size - 1);
        };
        const int x = index(uv.x, image_->width), y = index(uv.y, image_->height);
        const std::uint8_t* p = &image_->pixels[(static_cast<std::size_t>(y) * static_cast<std::size_t>(image_->width) +
                                                 static_cast<std::size_t>(x)) * 4];
        return {glm::vec3(lut_[p[0]], lut_[p[1]], lut_[p[2]]), p[3]};
    }

private:
    const RgbaImage* image_;
    bool repeat_;
    std::array<float, 256> lut_{};
};

/// The supersampled picture of one card.
struct Samples {
    int size = 0;
    std::vector<float> depth;    ///< larger is nearer the viewer; −∞: empty
    std::vector<glm::vec3> rgb;  ///< linear
    explicit Samples(int s)
        : size(s), depth(static_cast<std::size_t>(s) * static_cast<std::size_t>(s), -std::numeric_limits<float>::infinity()),
          rgb(depth.size(), glm::vec3(0.0f))
    {
    }
};

const glm::vec3 kSun = glm::normalize(glm::vec3(0.4f, 1.0f, 0.6f));

/// Draws the triangles of `g` into `out`: leaves cut out by the texture's alpha.
void raster(const SurfaceGeometry& g, const View& v, const TextureReader& tex, const glm::vec3& colour, bool leaves,
            Samples& out)
{
    const float s = static_cast<float>(out.size);
    const float su = s / (v.u1 - v.u0), sv = s / (v.v1 - v.v0);
    for (const auto& t : g.triangles) {
        glm::vec2 q[3];
        float z[3];
        for (int k = 0; k < 3; ++k) {
            const glm::vec3& p = g.positions[t[static_cast<std::size_t>(k)]];
            q[k] = glm::vec2((glm::dot(p, v.h) - v.u0) * su, (v.v1 - glm::dot(p, v.w)) * sv);
            z[k] = glm::dot(p, v.n);
        }
        const float area = (q[1].x - q[0].x) * (q[2].y - q[0].y) - (q[2].x - q[0].x) * (q[1].y - q[0].y);
        if (std::abs(area) < 1e-12f) continue;
        const int x0 = std::max(0, static_cast<int>(std::floor(std::min({q[0].x, q[1].x, q[2].x}))));
        const int x1 = std::min(out.size - 1, static_cast<int>(std::ceil(std::max({q[0].x, q[1].x, q[2].x}))));
        const int y0 = std::max(0, static_cast<int>(std::floor(std::min({q[0].y, q[1].y, q[2].y}))));
        const int y1 = std::min(out.size - 1, static_cast<int>(std::ceil(std::max({q[0].y, q[1].y, q[2].y}))));
        for (int y = y0; y <= y1; ++y)
            for (int x = x0; x <= x1; ++x) {
                const glm::vec2 c(static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f);
                float b[3];
                for (int k = 0; k < 3; ++k) {
                    const glm::vec2& a = q[(k + 1) % 3];
                    const glm::vec2& d = q[(k + 2) % 3];
                    b[k] = ((d.x - a.x) * (c.y - a.y) - (c.x - a.x) * (d.y - a.y)) / area;
                }
                if (b[0] < 0.0f || b[1] < 0.0f || b[2] < 0.0f) continue;
                const float depth = b[0] * z[0] + b[1] * z[1] + b[2] * z[2];
                const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(out.size) + static_cast<std::size_t>(x);
                if (!(depth > out.depth[i])) continue;
                glm::vec2 uv(0.0f);
                glm::vec3 normal(0.0f);
                for (int k = 0; k < 3; ++k) {
                    uv += b[k] * g.uvs[t[static_cast<std::size_t>(k)]];
                    normal += b[k] * g.normals[t[static_cast<std::size_t>(k)]];
                }
                const Texel texel = tex.at(uv);
                if (leaves && texel.alpha < 128) continue;
                const float len = glm::length(normal);
                const float lit = len > 1e-6f ? glm::dot(normal / len, kSun) : 1.0f;
                const float shade = leaves ? 0.7f + 0.3f * std::abs(lit) : 0.6f + 0.4f * std::max(0.0f, lit);
                out.depth[i] = depth;
                out.rgb[i] = texel.rgb * colour * shade;
            }
    }
}

/// Averages 2 × 2 samples into the cell at (cx, cy) of `atlas` (cell size c): colour of the
/// covered samples, alpha the coverage.
void resolve(const Samples& s, RgbaImage& atlas, int cx, int cy, int c)
{
    for (int y = 0; y < c; ++y)
        for (int x = 0; x < c; ++x) {
            glm::vec3 sum(0.0f);
            int covered = 0;
            for (int dy = 0; dy < 2; ++dy)
                for (int dx = 0; dx < 2; ++dx) {
                    const std::size_t i = static_cast<std::size_t>(2 * y + dy) * static_cast<std::size_t>(s.size) +
                                          static_cast<std::size_t>(2 * x + dx);
                    if (s.depth[i] == -std::numeric_limits<float>::infinity()) continue;
                    sum += s.rgb[i];
                    ++covered;
                }
            std::uint8_t* p = &atlas.pixels[(static_cast<std::size_t>(cy + y) * static_cast<std::size_t>(atlas.width) +
                                             static_cast<std::size_t>(cx + x)) * 4];
            if (covered > 0) {
                const glm::vec3 mean = sum / static_cast<float>(covered);
                for (int k = 0; k < 3; ++k) p[k] = linear_to_srgb(static_cast<double>(mean[k]));
            }
            p[3] = static_cast<std::uint8_t>((covered * 255 + 2) / 4);
        }
}

/// Gives every transparent texel of a cell the mean colour of its covered neighbours,
/// growing outwards a few texels, then the cell's mean colour to the rest.
void bleed(RgbaImage& atlas, int cx, int cy, int c)
{
    auto px = [&](int x, int y) {
        return &atlas.pixels[(static_cast<std::size_t>(cy + y) * static_cast<std::size_t>(atlas.width) +
                              static_cast<std::size_t>(cx + x)) * 4];
    };
    std::vector<char> known(static_cast<std::size_t>(c) * static_cast<std::size_t>(c));
    long long sum[3] = {0, 0, 0}, count = 0;
    for (int y = 0; y < c; ++y)
        for (int x = 0; x < c; ++x) {
            known[static_cast<std::size_t>(y * c + x)] = px(x, y)[3] > 0;
            if (px(x, y)[3] > 0) {
                for (int k = 0; k < 3; ++k) sum[k] += px(x, y)[k];
                ++count;
            }
        }
    for (int pass = 0; pass < 4; ++pass) {
        std::vector<char> next = known;
        for (int y = 0; y < c; ++y)
            for (int x = 0; x < c; ++x) {
                if (known[static_cast<std::size_t>(y * c + x)]) continue;
                int acc[3] = {0, 0, 0}, n = 0;
                for (int dy = -1; dy <= 1; ++dy)
                    for (int dx = -1; dx <= 1; ++dx) {
                        const int nx = x + dx, ny = y + dy;
                        if (nx < 0 || ny < 0 || nx >= c || ny >= c || !known[static_cast<std::size_t>(ny * c + nx)]) continue;
                        for (int k = 0; k < 3; ++k) acc[k] += px(nx, ny)[k];
                        ++n;
                    }
                if (n == 0) continue;
                for (int k = 0; k < 3; ++k) px(x, y)[k] = static_cast<std::uint8_t>((acc[k] + n / 2) / n);
                next[static_cast<std::size_t>(y * c + x)] = 1;
            }
        known.swap(next);
    }
    for (int y = 0; y < c; ++y)
        for (int x = 0; x < c; ++x)
            if (!known[static_cast<std::size_t>(y * c + x)] && count > 0)
                for (int k = 0; k < 3; ++k) px(x, y)[k] = static_cast<std::uint8_t>((sum[k] + count / 2) / count);
}

} // namespace

Billboard bake_billboard(const BillboardInput& in, int size)
{
    if (size < 16 || size > 4096 || (size & (size - 1)) != 0)
        throw InvalidInput("billboard: texture size " + std::to_string(size) + " is not a power of two from 16 to 4096");
    std::vector<const SurfaceGeometry*> parts;
    for (const SurfaceGeometry* g : {in.branches, in.leaves})
        if (g != nullptr && !g->empty()) parts.push_back(g);
    glm::vec3 lo(std::numeric_limits<float>::max()), hi(std::numeric_limits<float>::lowest());
    for (const SurfaceGeometry* g : parts)
        for (const glm::vec3& p : g->positions) {
            lo = glm::min(lo, p);
            hi = glm::max(hi, p);
        }
    if (parts.empty()) throw InvalidInput("billboard: the tree has nothing to draw");
    const float crown_mid = 0.5f * (lo.y + hi.y);

    std::vector<View> views;
    constexpr float kPi = 3.14159265358979f;
    for (int k = 0; k < 3; ++k) {
        const float a = static_cast<float>(k) * kPi / 3.0f;
        const glm::vec3 h(std::cos(a), 0.0f, -std::sin(a));
        views.push_back({h, glm::vec3(0, 1, 0), glm::cross(h, glm::vec3(0, 1, 0)), 0.0f});
    }
    views.push_back({glm::vec3(1, 0, 0), glm::vec3(0, 0, -1), glm::vec3(0, 1, 0), crown_mid});
    for (View& v : views) {
        v.u0 = v.v0 = std::numeric_limits<float>::max();
        v.u1 = v.v1 = std::numeric_limits<float>::lowest();
        for (const SurfaceGeometry* g : parts)
            for (const glm::vec3& p : g->positions) {
                v.u0 = std::min(v.u0, glm::dot(p, v.h));
                v.u1 = std::max(v.u1, glm::dot(p, v.h));
                v.v0 = std::min(v.v0, glm::dot(p, v.w));
                v.v1 = std::max(v.v1, glm::dot(p, v.w));
            }
        // A sliver of a tree (a lone trunk seen edge-on) still gets a card a centimetre wide.
        if (v.u1 - v.u0 < 0.01f) v.u0 -= 0.005f, v.u1 += 0.005f;
        if (v.v1 - v.v0 < 0.01f) v.v0 -= 0.005f, v.v1 += 0.005f;
    }

    Billboard out;
    out.texture.width = out.texture.height = size;
    out.texture.pixels.assign(static_cast<std::size_t>(size) * static_cast<std::size_t>(size) * 4, 0);
    const int cell = size / 2;
    const TextureReader bark(in.bark_texture, true), leaf(in.leaf_texture, false);
    const glm::vec3 bark_colour(in.bark_color[0], in.bark_color[1], in.bark_color[2]);
    const glm::vec3 leaf_colour(in.leaf_color[0], in.leaf_color[1], in.leaf_color[2]);
    for (std::size_t k = 0; k < views.size(); ++k) {
        const View& v = views[k];
        Samples samples(2 * cell);
        if (in.branches != nullptr) raster(*in.branches, v, bark, bark_colour, false, samples);
        if (in.leaves != nullptr) raster(*in.leaves, v, leaf, leaf_colour, in.leaf_texture != nullptr, samples);
        const int cx = static_cast<int>(k % 2) * cell, cy = static_cast<int>(k / 2) * cell;
        resolve(samples, out.texture, cx, cy, cell);
        bleed(out.texture, cx, cy, cell);

        // The card: corners (u0, v0), (u1, v0), (u1, v1), (u0, v1), counter-clockwise seen from n.
        const auto first = static_cast<std::uint32_t>(out.cards.positions.size());
        const float tu0 = static_cast<float>(cx) / static_cast<float>(size), tu1 = static_cast<float>(cx + cell) / static_cast<float>(size);
        const float tv0 = static_cast<float>(cy) / static_cast<float>(size), tv1 = static_cast<float>(cy + cell) / static_cast<float>(size);
        const float us[4] = {v.u0, v.u1, v.u1, v.u0}, vs[4] = {v.v0, v.v0, v.v1, v.v1};
        const float tus[4] = {tu0, tu1, tu1, tu0}, tvs[4] = {tv1, tv1, tv0, tv0};
        for (int c = 0; c < 4; ++c) {
            out.cards.positions.push_back(us[c] * v.h + vs[c] * v.w + v.offset * v.n);
            out.cards.normals.push_back(v.n);
            out.cards.uvs.emplace_back(tus[c], tvs[c]);
        }
        out.cards.triangles.push_back({first, first + 1, first + 2});
        out.cards.triangles.push_back({first, first + 2, first + 3});
    }
    return out;
}

} // namespace lobe
