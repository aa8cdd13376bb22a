#include "app/export/export_scene.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>

#include <glm/geometric.hpp>
#include <meshoptimizer.h>

#include "app/export/billboard.h"
#include "core/errors.h"

namespace lobe {

namespace {

[[noreturn]] void fail(const std::string& what) { throw InvalidInput("export: " + what); }

bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
bool finite(const glm::vec2& v) { return std::isfinite(v.x) && std::isfinite(v.y); }

void check_name(const std::string& name)
{
    if (name.empty()) fail("the scene name is empty");
    for (unsigned char c : name)
        if (c < 0x20 || c == 0x7f) fail("the scene name contains a control character");
}

/// Checks one mesh of one LOD; `what` names it in messages ("LOD 1 leaves").
void check_surface(const SurfaceGeometry& g, const std::string& what)
{
    const std::size_t n = g.positions.size();
    if (g.normals.size() != n)
        fail(what + ": " + std::to_string(g.normals.size()) + " normals for " + std::to_string(n) + " positions");
    if (g.uvs.size() != n)
        fail(what + ": " + std::to_string(g.uvs.size()) + " uvs for " + std::to_string(n) + " positions");
    if (n > std::numeric_limits<std::uint32_t>::max()) fail(what + ": too many vertices");
    for (std::size_t i = 0; i < n; ++i) {
        if (!finite(g.positions[i])) fail(what + ": position " + std::to_string(i) + " is not finite");
        if (!finite(g.normals[i])) fail(what + ": normal " + std::to_string(i) + " is not finite");
        if (!finite(g.uvs[i])) fail(what + ": uv " + std::to_string(i) + " is not finite");
        if (glm::length(g.normals[i]) < 1e-6f) fail(what + ": normal " + std::to_string(i) + " is zero");
    }
    for (std::size_t t = 0; t < g.triangles.size(); ++t)
        for (std::uint32_t v : g.triangles[t])
            if (v >= n)
                fail(what + ": triangle " + std::to_string(t) + " uses vertex " + std::to_string(v) + " of " +
                     std::to_string(n));
}

std::vector<int> chosen_lods(const TreeGeometry& tree, const std::vector<int>& requested, bool billboard)
{
    const int count = static_cast<int>(tree.lods.size()) + (billboard ? 1 : 0);
    std::vector<int> lods;
    if (requested.empty()) {
        for (int i = 0; i < count; ++i) lods.push_back(i);
        return lods;
    }
    lods = requested;
    std::sort(lods.begin(), lods.end());
    for (std::size_t i = 0; i < lods.size(); ++i) {
        if (lods[i] < 0 || lods[i] >= count)
            fail("LOD " + std::to_string(lods[i]) + " requested, the tree has " + std::to_string(count));
        if (i > 0 && lods[i] == lods[i - 1]) fail("LOD " + std::to_string(lods[i]) + " requested twice");
    }
    return lods;
}

} // namespace

double tree_height(const TreeGeometry& tree, const glm::vec3& base)
{
    double top = -std::numeric_limits<double>::infinity();
    if (tree.lods.empty()) return top;
    for (const SurfaceGeometry* g : {&tree.lods[0].branches, &tree.lods[0].leaves})
        for (const glm::vec3& p : g->positions) top = std::max(top, double(p.y) - double(base.y));
    return top;
}

namespace {

glm::vec3 to_export(const glm::vec3& p, const glm::vec3& base, float scale) { return (p - base) * scale; }

ExportPart make_part(const SurfaceGeometry& g, ExportPart::Kind kind, int lod, const std::string& name,
                     const glm::vec3& base, float scale)
{
    ExportPart part;
    part.kind = kind;
    part.lod = lod;
    part.name = name + (kind == ExportPart::Kind::Branches ? "_branches_LOD" : "_leaves_LOD") + std::to_string(lod);
    part.geometry.positions.reserve(g.positions.size());
    for (const glm::vec3& p : g.positions) part.geometry.positions.push_back(to_export(p, base, scale));
    part.geometry.normals.reserve(g.normals.size());
    for (const glm::vec3& n : g.normals) part.geometry.normals.push_back(glm::normalize(n));
    part.geometry.uvs = g.uvs;
    part.geometry.triangles = g.triangles;
    return part;
}

} // namespace

bool PreparedExport::has_leaves() const
{
    return std::any_of(parts.begin(), parts.end(), [](const ExportPart& p) { return p.kind == ExportPart::Kind::Leaves; });
}

namespace {

/// Tangents of a bark mesh: the bitangent follows +v (along the branch, never mirrored); the
/// tangent is perpendicular to it and the normal, pointing along +u (which the mirrored bark
/// u reverses on the back half of each ring).
std::vector<glm::vec4> bark_tangents(const SurfaceGeometry& g)
{
    std::vector<glm::vec3> du(g.positions.size(), glm::vec3(0.0f)), dv(g.positions.size(), glm::vec3(0.0f));
    for (const auto& t : g.triangles) {
        const glm::vec3 e1 = g.positions[t[1]] - g.positions[t[0]], e2 = g.positions[t[2]] - g.positions[t[0]];
        const glm::vec2 w1 = g.uvs[t[1]] - g.uvs[t[0]], w2 = g.uvs[t[2]] - g.uvs[t[0]];
        const float det = w1.x * w2.y - w2.x * w1.y;
        if (std::abs(det) < 1e-12f) continue;
        const glm::vec3 pu = (e1 * w2.y - e2 * w1.y) / det, pv = (e2 * w1.x - e1 * w2.x) / det;
        for (std::uint32_t v : t) {
            du[v] += pu;
            dv[v] += pv;
        }
    }
    std::vector<glm::vec4> out(g.positions.size());
    for (std::size_t i = 0; i < out.size(); ++i) {
        const glm::vec3 n = g.normals[i];
        glm::vec3 b = dv[i] - glm::dot(dv[i], n) * n;
        if (glm::length(b) < 1e-9f) b = std::abs(n.y) < 0.9f ? glm::vec3(0, 1, 0) - n.y * n : glm::vec3(1, 0, 0) - n.x * n;
        glm::vec3 t = glm::normalize(glm::cross(glm::normalize(b), n));
        if (glm::dot(du[i], t) < 0.0f) t = -t;
        const float w = glm::dot(glm::cross(n, t), b) < 0.0f ? -1.0f : 1.0f;
        out[i] = glm::vec4(t, w);
    }
    return out;
}

} // namespace

namespace {

/// Reorders a part's triangles for the post-transform vertex cache (when that beats the order
/// they have), then (bark only) for overdraw, then its vertices for fetch (meshoptimizer):
/// the same triangles, in another order.
void optimize_part(ExportPart& part)
{
    SurfaceGeometry& g = part.geometry;
    const std::size_t vcount = g.vertex_count(), icount = g.triangles.size() * 3;
    if (icount == 0) return;
    std::vector<unsigned int> idx;
    idx.reserve(icount);
    for (const auto& t : g.triangles) idx.insert(idx.end(), t.begin(), t.end());
    // The sweep's ring-by-ring order is often better already: keep whichever order needs
    // fewer vertex shader runs (meshoptimizer's analysis, a 16-entry cache).
    std::vector<unsigned int> cached(icount);
    meshopt_optimizeVertexCache(cached.data(), idx.data(), icount, vcount);
    if (meshopt_analyzeVertexCache(cached.data(), icount, vcount, 16, 0, 0).acmr <
        meshopt_analyzeVertexCache(idx.data(), icount, vcount, 16, 0, 0).acmr)
        idx.swap(cached);
    // Overdraw order assumes opaque, back-face culled triangles: the bark. Leaf and billboard
    // cards are alpha-tested and double-sided, and their quads are already in cache order.
    if (part.kind == ExportPart::Kind::Branches)
        meshopt_optimizeOverdraw(idx.data(), idx.data(), icount, &g.positions[0].x, vcount, sizeof(glm::vec3), 1.05f);
    std::vector<unsigned int> remap(vcount);
    const std::size_t unique = meshopt_optimizeVertexFetchRemap(remap.data(), idx.data(), icount, vcount);
    meshopt_remapIndexBuffer(idx.data(), idx.data(), icount, remap.data());
    auto apply = [&](auto& v) {
        using T = typename std::decay_t<decltype(v)>::value_type;
        std::vector<T> out(vcount);
        meshopt_remapVertexBuffer(out.data(), v.data(), vcount, sizeof(T), remap.data());
        out.resize(unique);
        v = std::move(out);
    };
    apply(g.positions);
    apply(g.normals);
    apply(g.uvs);
    if (!part.tangents.empty()) apply(part.tangents);
    for (std::size_t t = 0; t < g.triangles.size(); ++t) g.triangles[t] = {idx[3 * t], idx[3 * t + 1], idx[3 * t + 2]};
}

} // namespace

bool PreparedExport::has_billboard() const
{
    return std::any_of(parts.begin(), parts.end(), [](const ExportPart& p) { return p.kind == ExportPart::Kind::Billboard; });
}

namespace {

/// Bakes the billboard from LOD0 (in export space) and adds it as the part of level `lod`.
void add_billboard(PreparedExport& out, const TreeGeometry& tree, const ExportScene& scene, float scale, int size, int lod)
{
    const TreeLod& l0 = tree.lods[0];
    const ExportPart branches = make_part(l0.branches, ExportPart::Kind::Branches, 0, scene.name, scene.base, scale);
    const ExportPart leaves = make_part(l0.leaves, ExportPart::Kind::Leaves, 0, scene.name, scene.base, scale);
    BillboardInput in;
    in.branches = &branches.geometry;
    in.leaves = &leaves.geometry;
    in.bark_texture = out.bark_texture;
    in.leaf_texture = out.leaf_texture;
    in.bark_color = tree.bark_color;
    in.leaf_color = tree.leaf_color;
    Billboard baked = bake_billboard(in, size);
    ExportPart part;
    part.kind = ExportPart::Kind::Billboard;
    part.lod = lod;
    part.name = scene.name + "_billboard_LOD" + std::to_string(lod);
    part.geometry = std::move(baked.cards);
    out.billboard_texture = std::move(baked.texture);
    out.parts.push_back(std::move(part));
}

} // namespace

bool PreparedExport::has_branches() const
{
    return std::any_of(parts.begin(), parts.end(), [](const ExportPart& p) { return p.kind == ExportPart::Kind::Branches; });
}

PreparedExport prepare_export(const ExportScene& scene, const ExportOptions& options)
{
    if (scene.tree == nullptr) fail("no tree given");
    const TreeGeometry& tree = *scene.tree;
    check_name(scene.name);
    if (!finite(scene.base)) fail("the base is not finite");
    if (!std::isfinite(options.target_height_m) || options.target_height_m < 0.0)
        fail("target height " + std::to_string(options.target_height_m) + " m is not a positive number");

    if (options.billboard_size < 0) fail("billboard size " + std::to_string(options.billboard_size) + " is negative");
    const bool billboard = options.billboard_size > 0 && !tree.lods.empty();
    const std::vector<int> lods = chosen_lods(tree, options.lods, billboard);
    // Every LOD is checked, exported or not: the height used for scaling reads them all.
    for (std::size_t i = 0; i < tree.lods.size(); ++i) {
        check_surface(tree.lods[i].branches, "LOD " + std::to_string(i) + " branches");
        check_surface(tree.lods[i].leaves, "LOD " + std::to_string(i) + " leaves");
    }
    const RgbaImage& tex = tree.leaf_texture;
    const RgbaImage& bark = tree.bark_texture;
    for (const auto& [image, what] : {std::pair{&tex, "leaf"}, std::pair{&bark, "bark"}})
        if (image->width < 0 || image->height < 0 ||
            image->pixels.size() != std::size_t(image->width) * std::size_t(image->height) * 4u)
            fail(std::string(what) + " texture of " + std::to_string(image->width) + "x" +
                 std::to_string(image->height) + " has " + std::to_string(image->pixels.size()) + " bytes");

    float scale = 1.0f;
    if (options.target_height_m > 0.0) {
        const double height = tree_height(tree, scene.base);
        if (!(height > 1e-9)) fail("the tree has no height above its base to scale");
        scale = static_cast<float>(options.target_height_m / height);
    }

    PreparedExport out;
    out.name = scene.name;
    out.scale = scale;
    out.bark_color = tree.bark_color;
    out.leaf_color = tree.leaf_color;
    out.species = tree.species;
    out.leaf_texture = (tex.width > 0 && tex.height > 0) ? &tex : nullptr;
    if (options.bark_normal_map && bark.width > 0 && bark.height > 0) out.bark_normal_map = normal_map_from_height(bark);
    out.bark_texture = (bark.width > 0 && bark.height > 0) ? &bark : nullptr;
    for (int lod : lods) {
        if (std::size_t(lod) == tree.lods.size()) {
            add_billboard(out, tree, scene, scale, options.billboard_size, lod);
            continue;
        }
        const TreeLod& l = tree.lods[std::size_t(lod)];
        if (!l.branches.empty()) {
            out.parts.push_back(make_part(l.branches, ExportPart::Kind::Branches, lod, scene.name, scene.base, scale));
            if (!out.bark_normal_map.pixels.empty()) out.parts.back().tangents = bark_tangents(out.parts.back().geometry);
        }
        if (!l.leaves.empty())
            out.parts.push_back(make_part(l.leaves, ExportPart::Kind::Leaves, lod, scene.name, scene.base, scale));
    }

    if (options.optimize)
        for (ExportPart& part : out.parts) optimize_part(part);

    if (options.include_lobes) {
        for (std::size_t i = 0; i < scene.lobes.size(); ++i) {
            const TriangleMesh& m = scene.lobes[i];
            if (!scene.lobe_ids.empty() && scene.lobe_ids.size() != scene.lobes.size())
                fail(std::to_string(scene.lobe_ids.size()) + " lobe ids for " + std::to_string(scene.lobes.size()) + " lobes");
            const std::int64_t id = scene.lobe_ids.empty() ? std::int64_t(i) + 1 : scene.lobe_ids[i];
            const std::string what = "lobe " + std::to_string(id);
            if (m.triangles.empty()) continue;
            ExportLobe lobe;
            lobe.name = "lobe_" + std::to_string(id);
            for (std::size_t v = 0; v < m.positions.size(); ++v) {
                if (!finite(m.positions[v])) fail(what + ": position " + std::to_string(v) + " is not finite");
                lobe.positions.push_back(to_export(m.positions[v], scene.base, scale));
            }
            for (std::size_t t = 0; t < m.triangles.size(); ++t) {
                std::array<std::uint32_t, 3> tri{};
                for (int k = 0; k < 3; ++k) {
                    const int v = m.triangles[t][std::size_t(k)];
                    if (v < 0 || std::size_t(v) >= m.positions.size())
                        fail(what + ": triangle " + std::to_string(t) + " uses vertex " + std::to_string(v) + " of " +
                             std::to_string(m.positions.size()));
                    tri[std::size_t(k)] = static_cast<std::uint32_t>(v);
                }
                lobe.triangles.push_back(tri);
            }
            out.lobes.push_back(std::move(lobe));
        }
    }

    if (options.include_strokes) {
        for (const Stroke& s : scene.strokes) {
            if (s.points.size() < 2) continue;
            ExportPolyline line;
            line.name = "stroke_" + std::to_string(s.id);
            for (std::size_t i = 0; i < s.points.size(); ++i) {
                if (!finite(s.points[i].position))
                    fail("stroke " + std::to_string(s.id) + ": point " + std::to_string(i) + " is not finite");
                line.points.push_back(to_export(s.points[i].position, scene.base, scale));
            }
            out.strokes.push_back(std::move(line));
        }
    }
    return out;
}

double srgb_to_linear(std::uint8_t v)
{
    const double c = v / 255.0;
    return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

std::uint8_t linear_to_srgb(double v)
{
    const double c = std::clamp(v, 0.0, 1.0);
    const double s = c <= 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1.0 / 2.4) - 0.055;
    return static_cast<std::uint8_t>(std::clamp(s * 255.0 + 0.5, 0.0, 255.0));
}

RgbaImage tinted_texture(const RgbaImage& image, const std::array<float, 3>& rgb)
{
    std::array<double, 256> linear{};
    for (int i = 0; i < 256; ++i) linear[static_cast<std::size_t>(i)] = srgb_to_linear(static_cast<std::uint8_t>(i));
    RgbaImage out = image;
    for (std::size_t i = 0; i + 3 < out.pixels.size(); i += 4)
        for (std::size_t k = 0; k < 3; ++k)
            out.pixels[i + k] = linear_to_srgb(linear[out.pixels[i + k]] * static_cast<double>(rgb[k]));
    return out;
}

RgbaImage normal_map_from_height(const RgbaImage& image, double strength)
{
    const int w = image.width, h = image.height;
    RgbaImage out;
    out.width = w;
    out.height = h;
    out.pixels.assign(static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 4, 255);
    if (w <= 0 || h <= 0) return out;
    auto height = [&](int x, int y) {
        x = (x % w + w) % w;
        y = (y % h + h) % h;
        const std::uint8_t* p = &image.pixels[(static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)) * 4];
        return (0.299 * p[0] + 0.587 * p[1] + 0.114 * p[2]) / 255.0;
    };
    const double scale = strength * static_cast<double>(w) / 32.0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            // Sobel slopes; image rows run down while the texture's v (and +Y of tangent space) runs up.
            const double dx = (height(x + 1, y - 1) + 2.0 * height(x + 1, y) + height(x + 1, y + 1)) -
                              (height(x - 1, y - 1) + 2.0 * height(x - 1, y) + height(x - 1, y + 1));
            const double dy = (height(x - 1, y + 1) + 2.0 * height(x, y + 1) + height(x + 1, y + 1)) -
                              (height(x - 1, y - 1) + 2.0 * height(x, y - 1) + height(x + 1, y - 1));
            const glm::dvec3 n = glm::normalize(glm::dvec3(-dx * scale / 8.0, dy * scale / 8.0, 1.0));
            std::uint8_t* p = &out.pixels[(static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)) * 4];
            for (int k = 0; k < 3; ++k)
                p[k] = static_cast<std::uint8_t>(std::clamp((n[k] * 0.5 + 0.5) * 255.0 + 0.5, 0.0, 255.0));
        }
    return out;
}

} // namespace lobe
