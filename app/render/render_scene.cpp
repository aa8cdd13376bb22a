#include "app/render/render_scene.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>
#include <tiny_gltf.h>

#include "core/errors.h"

namespace lobe {

namespace {

// Item keys: the part kind in the top byte, an index below.
constexpr std::uint64_t kBranchesKey = 1ull << 56, kLeavesKey = 2ull << 56, kLobeKey = 3ull << 56, kStrokeKey = 4ull << 56,
                        kClusterKey = 5ull << 56;

/// FNV-1a over the mesh's arrays: the version of a mesh is its content.
std::uint64_t content_hash(const SurfaceGeometry& g)
{
    std::uint64_t h = 1469598103934665603ull;
    auto mix = [&](const void* data, std::size_t bytes) {
        const auto* p = static_cast<const unsigned char*>(data);
        for (std::size_t i = 0; i < bytes; ++i) h = (h ^ p[i]) * 1099511628211ull;
        h = (h ^ bytes) * 1099511628211ull;
    };
    mix(g.positions.data(), g.positions.size() * sizeof(glm::vec3));
    mix(g.normals.data(), g.normals.size() * sizeof(glm::vec3));
    mix(g.uvs.data(), g.uvs.size() * sizeof(glm::vec2));
    mix(g.triangles.data(), g.triangles.size() * sizeof(g.triangles[0]));
    return h;
}

std::uint64_t image_hash(const RgbaImage& image)
{
    std::uint64_t h = 1469598103934665603ull ^ std::uint64_t(image.width) << 20 ^ std::uint64_t(image.height);
    for (std::uint8_t b : image.pixels) h = (h ^ b) * 1099511628211ull;
    return h;
}

void add_item(RenderScene& scene, std::uint64_t key, RenderMaterial material, std::array<float, 4> color,
              SurfaceGeometry geometry)
{
    if (geometry.empty()) return;
    RenderItem item;
    item.key = key;
    item.material = material;
    item.color = color;
    item.version = content_hash(geometry) ^ (std::uint64_t(material) << 60);
    item.geometry = std::move(geometry);
    scene.items.push_back(std::move(item));
}

} // namespace

std::uint64_t bytes_hash(const void* data, std::size_t bytes)
{
    std::uint64_t h = 1469598103934665603ull;
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < bytes; ++i) h = (h ^ p[i]) * 1099511628211ull;
    return h;
}

RenderContent parse_show_list(const std::string& text)
{
    RenderContent c;
    c.tree = c.leaves = c.lobes = c.strokes = false;
    std::stringstream ss(text);
    std::string item;
    bool any = false;
    while (std::getline(ss, item, ',')) {
        if (item == "tree")
            c.tree = true;
        else if (item == "leaves")
            c.leaves = true;
        else if (item == "lobes")
            c.lobes = true;
        else if (item == "strokes")
            c.strokes = true;
        else if (item == "clusters")
            c.clusters = true;
        else
            throw InvalidInput("--show: unknown item '" + item + "' (expected tree, leaves, lobes, strokes, clusters)");
        any = true;
    }
    if (!any) throw InvalidInput("--show: expected a list of tree, leaves, lobes, strokes, clusters");
    return c;
}

SurfaceGeometry polyline_tube(const std::vector<glm::vec3>& points_in, float radius_m, int sides)
{
    SurfaceGeometry g;
    std::vector<glm::vec3> pts;
    for (const glm::vec3& p : points_in)
        if (pts.empty() || glm::length(p - pts.back()) > 1e-5f) pts.push_back(p);
    if (pts.size() < 2 || sides < 3) return g;
    const std::size_t n = pts.size(), s = static_cast<std::size_t>(sides);
    // Frames by parallel transport: the rings do not twist along the stroke.
    glm::vec3 t0 = glm::normalize(pts[1] - pts[0]);
    glm::vec3 normal = glm::cross(t0, std::abs(t0.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0));
    normal = glm::normalize(normal);
    for (std::size_t i = 0; i < n; ++i) {
        const glm::vec3 a = pts[i == 0 ? 0 : i - 1], b = pts[i + 1 < n ? i + 1 : n - 1];
        glm::vec3 t = b - a;
        t = glm::length(t) > 1e-9f ? glm::normalize(t) : t0;
        glm::vec3 nn = normal - glm::dot(normal, t) * t;
        if (glm::length(nn) < 1e-4f) nn = glm::cross(t, std::abs(t.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0));
        normal = glm::normalize(nn);
        const glm::vec3 binormal = glm::cross(t, normal);
        for (std::size_t j = 0; j < s; ++j) {
            const float angle = 6.2831853f * float(j) / float(s);
            const glm::vec3 d = std::cos(angle) * normal + std::sin(angle) * binormal;
            g.positions.push_back(pts[i] + radius_m * d);
            g.normals.push_back(d);
            g.uvs.emplace_back(float(j) / float(s), float(i));
        }
    }
    for (std::size_t i = 0; i + 1 < n; ++i)
        for (std::size_t j = 0; j < s; ++j) {
            const auto v = [&](std::size_t ring, std::size_t k) { return static_cast<std::uint32_t>(ring * s + k % s); };
            g.triangles.push_back({v(i, j), v(i, j + 1), v(i + 1, j + 1)});
            g.triangles.push_back({v(i, j), v(i + 1, j + 1), v(i + 1, j)});
        }
    return g;
}

SurfaceGeometry lobe_surface(const TriangleMesh& mesh)
{
    SurfaceGeometry g;
    g.positions = mesh.positions;
    g.normals.assign(mesh.positions.size(), glm::vec3(0.0f));
    for (const auto& t : mesh.triangles) {
        for (int i : t)
            if (i < 0 || std::size_t(i) >= mesh.positions.size())
                throw InvalidInput("render: a lobe triangle index " + std::to_string(i) + " is out of range");
        const glm::vec3 &a = mesh.positions[std::size_t(t[0])], &b = mesh.positions[std::size_t(t[1])],
                        &c = mesh.positions[std::size_t(t[2])];
        const glm::vec3 area = glm::cross(b - a, c - a);
        for (int i : t) g.normals[std::size_t(i)] += area;
        g.triangles.push_back({std::uint32_t(t[0]), std::uint32_t(t[1]), std::uint32_t(t[2])});
    }
    for (glm::vec3& n : g.normals) n = glm::length(n) > 1e-20f ? glm::normalize(n) : glm::vec3(0, 1, 0);
    return g;
}

bool replace_lobe_item(RenderScene& scene, std::size_t index, const TriangleMesh& mesh)
{
    for (RenderItem& item : scene.items)
        if (item.key == (kLobeKey | index)) {
            item.geometry = lobe_surface(mesh);
            item.version = content_hash(item.geometry) ^ (std::uint64_t(item.material) << 60);
            return true;
        }
    return false;
}

namespace {

std::uint64_t stroke_key(const Stroke& s) { return kStrokeKey | (static_cast<std::uint64_t>(s.id) & 0x00FFFFFFFFFFFFFFull); }

/// The tube a stroke is drawn as: through its points, round again when it is closed.
SurfaceGeometry stroke_tube(const Stroke& s)
{
    std::vector<glm::vec3> pts;
    pts.reserve(s.points.size() + 1);
    for (const StrokePoint& p : s.points) pts.push_back(p.position);
    if (s.closed && pts.size() > 2) pts.push_back(pts.front());
    return polyline_tube(pts);
}

} // namespace

bool replace_stroke_item(RenderScene& scene, const Stroke& stroke)
{
    for (RenderItem& item : scene.items)
        if (item.key == stroke_key(stroke)) {
            item.geometry = stroke_tube(stroke);
            item.version = content_hash(item.geometry) ^ (std::uint64_t(item.material) << 60);
            return true;
        }
    return false;
}

RenderScene tree_render_scene(const TreeGeometry& geometry, const std::vector<TriangleMesh>& lobes,
                              const std::vector<Stroke>& strokes, float ground_y, const RenderContent& content)
{
    RenderScene scene;
    scene.ground_y = ground_y;
    if ((content.tree || content.leaves) && (content.lod < 0 || std::size_t(content.lod) >= geometry.lods.size()))
        throw InvalidInput("--lod: LOD " + std::to_string(content.lod) + " does not exist (the tree has LOD0 to LOD" +
                           std::to_string(int(geometry.lods.size()) - 1) + ")");
    const auto& bark = geometry.bark_color;
    const auto& leaf = geometry.leaf_color;
    if (content.tree || content.leaves) {
        const TreeLod& lod = geometry.lods[std::size_t(content.lod)];
        if (content.tree)
            add_item(scene, kBranchesKey | std::uint64_t(content.lod), RenderMaterial::Bark, {bark[0], bark[1], bark[2], 1.0f},
                     lod.branches);
        if (content.leaves) {
            add_item(scene, kLeavesKey | std::uint64_t(content.lod), RenderMaterial::Leaf, {leaf[0], leaf[1], leaf[2], 1.0f},
                     lod.leaves);
            scene.leaf_texture = geometry.leaf_texture;
            scene.leaf_texture_version = image_hash(geometry.leaf_texture);
        }
    }
    if (content.lobes)
        for (std::size_t i = 0; i < lobes.size(); ++i)
            add_item(scene, kLobeKey | i, RenderMaterial::Lobe, kLobeColor, lobe_surface(lobes[i]));
    if (content.strokes)
        for (const Stroke& s : strokes) add_item(scene, stroke_key(s), RenderMaterial::Stroke, kStrokeColor, stroke_tube(s));
    return scene;
}

namespace {

// Twelve colours far apart (linear RGB): piece k of the tree gets colour k mod 12.
constexpr std::array<std::array<float, 3>, 12> kPieceColors{{{0.90f, 0.10f, 0.10f}, {0.10f, 0.45f, 0.95f},
                                                            {0.95f, 0.80f, 0.05f}, {0.55f, 0.10f, 0.85f},
                                                            {0.05f, 0.80f, 0.30f}, {0.95f, 0.45f, 0.05f},
                                                            {0.05f, 0.80f, 0.85f}, {0.95f, 0.25f, 0.65f},
                                                            {0.45f, 0.80f, 0.05f}, {0.25f, 0.15f, 0.60f},
                                                            {0.70f, 0.45f, 0.25f}, {0.60f, 0.60f, 0.60f}}};

void add_octahedron(SurfaceGeometry& g, const glm::vec3& c, float r)
{
    const auto base = static_cast<std::uint32_t>(g.positions.size());
    const glm::vec3 dirs[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    for (const glm::vec3& d : dirs) {
        g.positions.push_back(c + r * d);
        g.normals.push_back(d);
        g.uvs.emplace_back(0.0f, 0.0f);
    }
    const std::uint32_t faces[8][3] = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
    for (const auto& f : faces) g.triangles.push_back({base + f[0], base + f[1], base + f[2]});
}

void append(SurfaceGeometry& to, const SurfaceGeometry& from)
{
    const auto base = static_cast<std::uint32_t>(to.positions.size());
    to.positions.insert(to.positions.end(), from.positions.begin(), from.positions.end());
    to.normals.insert(to.normals.end(), from.normals.begin(), from.normals.end());
    to.uvs.insert(to.uvs.end(), from.uvs.begin(), from.uvs.end());
    for (const auto& t : from.triangles) to.triangles.push_back({base + t[0], base + t[1], base + t[2]});
}

} // namespace

void add_cluster_items(RenderScene& scene, const std::vector<ClusteredAttractor>& clusters, const TreeGraph& tree)
{
    std::array<SurfaceGeometry, kPieceColors.size()> by_color;
    // Each piece's attractors, centre and node, in piece order.
    std::vector<glm::vec3> centre;
    std::vector<int> count, node;
    for (const ClusteredAttractor& a : clusters) {
        if (a.piece < 0 || a.node < 0 || static_cast<std::size_t>(a.node) >= tree.nodes.size()) continue;
        const auto p = static_cast<std::size_t>(a.piece);
        if (p >= centre.size()) {
            centre.resize(p + 1, glm::vec3(0.0f));
            count.resize(p + 1, 0);
            node.resize(p + 1, -1);
        }
        centre[p] += a.position;
        ++count[p];
        node[p] = a.node;
        add_octahedron(by_color[p % by_color.size()], a.position, 0.006f);
    }
    for (std::size_t p = 0; p < centre.size(); ++p) {
        if (count[p] == 0) continue;
        const glm::vec3 from = tree.nodes[static_cast<std::size_t>(node[p])].position;
        append(by_color[p % by_color.size()], polyline_tube({from, centre[p] / static_cast<float>(count[p])}, 0.002f, 5));
    }
    for (std::size_t c = 0; c < by_color.size(); ++c)
        add_item(scene, kClusterKey | c, RenderMaterial::Stroke,
                 {kPieceColors[c][0], kPieceColors[c][1], kPieceColors[c][2], 1.0f}, std::move(by_color[c]));
}

namespace {

/// Reads a glTF accessor of `components` floats per element, bounds-checked.
std::vector<float> read_floats(const tinygltf::Model& m, int index, int type, const std::string& path)
{
    const int components = type == TINYGLTF_TYPE_VEC3 ? 3 : 2;
    if (index < 0 || std::size_t(index) >= m.accessors.size()) throw FileError(path, "an accessor index is out of range");
    const tinygltf::Accessor& a = m.accessors[std::size_t(index)];
    if (a.type != type || a.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT || a.bufferView < 0 ||
        std::size_t(a.bufferView) >= m.bufferViews.size())
        throw FileError(path, "an accessor is not of the float type Lobesketch writes");
    const tinygltf::BufferView& v = m.bufferViews[std::size_t(a.bufferView)];
    if (v.buffer < 0 || std::size_t(v.buffer) >= m.buffers.size()) throw FileError(path, "a buffer index is out of range");
    const std::vector<unsigned char>& data = m.buffers[std::size_t(v.buffer)].data;
    const std::size_t element = std::size_t(components) * sizeof(float);
    const std::size_t stride = v.byteStride ? v.byteStride : element;
    const std::size_t start = v.byteOffset + a.byteOffset;
    if (a.count > 0 && (start + (a.count - 1) * stride + element > data.size() || start + (a.count - 1) * stride + element > v.byteOffset + v.byteLength))
        throw FileError(path, "an accessor runs past its buffer");
    std::vector<float> out(a.count * std::size_t(components));
    for (std::size_t i = 0; i < a.count; ++i) std::memcpy(&out[i * std::size_t(components)], &data[start + i * stride], element);
    for (float f : out)
        if (!std::isfinite(f)) throw FileError(path, "a vertex value is not finite");
    return out;
}

std::vector<std::uint32_t> read_indices(const tinygltf::Model& m, int index, const std::string& path)
{
    if (index < 0 || std::size_t(index) >= m.accessors.size()) throw FileError(path, "an index accessor is out of range");
    const tinygltf::Accessor& a = m.accessors[std::size_t(index)];
    std::size_t size = 0;
    switch (a.componentType) {
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: size = 1; break;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: size = 2; break;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: size = 4; break;
    default: throw FileError(path, "indices are not unsigned integers");
    }
    if (a.type != TINYGLTF_TYPE_SCALAR || a.bufferView < 0 || std::size_t(a.bufferView) >= m.bufferViews.size())
        throw FileError(path, "an index accessor is malformed");
    const tinygltf::BufferView& v = m.bufferViews[std::size_t(a.bufferView)];
    if (v.buffer < 0 || std::size_t(v.buffer) >= m.buffers.size()) throw FileError(path, "a buffer index is out of range");
    const std::vector<unsigned char>& data = m.buffers[std::size_t(v.buffer)].data;
    const std::size_t stride = v.byteStride ? v.byteStride : size;
    const std::size_t start = v.byteOffset + a.byteOffset;
    if (a.count > 0 && start + (a.count - 1) * stride + size > data.size()) throw FileError(path, "indices run past their buffer");
    std::vector<std::uint32_t> out(a.count);
    for (std::size_t i = 0; i < a.count; ++i) {
        const unsigned char* p = &data[start + i * stride];
        out[i] = size == 1 ? p[0] : size == 2 ? std::uint32_t(p[0] | p[1] << 8) : std::uint32_t(p[0] | p[1] << 8 | p[2] << 16 | std::uint32_t(p[3]) << 24);
    }
    return out;
}

std::vector<glm::vec3> as_vec3(const std::vector<float>& f)
{
    std::vector<glm::vec3> out(f.size() / 3);
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = {f[3 * i], f[3 * i + 1], f[3 * i + 2]};
    return out;
}

/// The triangle mesh of one glTF primitive (normals computed when it has none).
SurfaceGeometry glb_primitive(const tinygltf::Model& m, const tinygltf::Mesh& mesh, const tinygltf::Primitive& p,
                              const std::string& path)
{
    SurfaceGeometry g;
    if (p.mode != TINYGLTF_MODE_TRIANGLES) return g;
    const auto pos = p.attributes.find("POSITION");
    if (pos == p.attributes.end()) throw FileError(path, "mesh '" + mesh.name + "' has no POSITION");
    g.positions = as_vec3(read_floats(m, pos->second, TINYGLTF_TYPE_VEC3, path));
    const std::vector<std::uint32_t> idx = read_indices(m, p.indices, path);
    if (idx.size() % 3) throw FileError(path, "mesh '" + mesh.name + "' has a partial triangle");
    for (std::size_t i = 0; i < idx.size(); i += 3) {
        for (std::size_t k = 0; k < 3; ++k)
            if (idx[i + k] >= g.positions.size()) throw FileError(path, "mesh '" + mesh.name + "' has an index out of range");
        g.triangles.push_back({idx[i], idx[i + 1], idx[i + 2]});
    }
    if (const auto n = p.attributes.find("NORMAL"); n != p.attributes.end()) {
        g.normals = as_vec3(read_floats(m, n->second, TINYGLTF_TYPE_VEC3, path));
    } else {
        TriangleMesh t;
        t.positions = g.positions;
        for (const auto& tri : g.triangles) t.triangles.push_back({int(tri[0]), int(tri[1]), int(tri[2])});
        g.normals = lobe_surface(t).normals;
    }
    if (const auto uv = p.attributes.find("TEXCOORD_0"); uv != p.attributes.end()) {
        const std::vector<float> f = read_floats(m, uv->second, TINYGLTF_TYPE_VEC2, path);
        for (std::size_t i = 0; i + 1 < f.size(); i += 2) g.uvs.emplace_back(f[i], f[i + 1]);
    }
    if (g.normals.size() != g.positions.size() || (!g.uvs.empty() && g.uvs.size() != g.positions.size()))
        throw FileError(path, "mesh '" + mesh.name + "' has attributes of different lengths");
    return g;
}

/// The triangle mesh of a glTF mesh: its triangle primitives one after the other (a large
/// LOD is split into primitives of at most 65,535 vertices, docs/export.md).
SurfaceGeometry glb_surface(const tinygltf::Model& m, const tinygltf::Mesh& mesh, const std::string& path)
{
    SurfaceGeometry g;
    for (const tinygltf::Primitive& p : mesh.primitives) {
        const SurfaceGeometry part = glb_primitive(m, mesh, p, path);
        if (part.empty()) continue;
        if (!g.empty() && g.uvs.empty() != part.uvs.empty())
            throw FileError(path, "mesh '" + mesh.name + "' has primitives with and without texture coordinates");
        const auto offset = static_cast<std::uint32_t>(g.positions.size());
        g.positions.insert(g.positions.end(), part.positions.begin(), part.positions.end());
        g.normals.insert(g.normals.end(), part.normals.begin(), part.normals.end());
        g.uvs.insert(g.uvs.end(), part.uvs.begin(), part.uvs.end());
        for (const auto& t : part.triangles) g.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
    }
    return g;
}

std::vector<glm::vec3> glb_line(const tinygltf::Model& m, const tinygltf::Mesh& mesh, const std::string& path)
{
    if (mesh.primitives.empty()) return {};
    const tinygltf::Primitive& p = mesh.primitives[0];
    const auto pos = p.attributes.find("POSITION");
    if (pos == p.attributes.end()) return {};
    return as_vec3(read_floats(m, pos->second, TINYGLTF_TYPE_VEC3, path));
}

std::array<float, 4> material_color(const tinygltf::Model& m, int material, std::array<float, 4> fallback)
{
    if (material < 0 || std::size_t(material) >= m.materials.size()) return fallback;
    const std::vector<double>& f = m.materials[std::size_t(material)].pbrMetallicRoughness.baseColorFactor;
    if (f.size() != 4) return fallback;
    return {float(f[0]), float(f[1]), float(f[2]), float(f[3])};
}

RgbaImage material_texture(const tinygltf::Model& m, int material)
{
    RgbaImage out;
    if (material < 0 || std::size_t(material) >= m.materials.size()) return out;
    const int tex = m.materials[std::size_t(material)].pbrMetallicRoughness.baseColorTexture.index;
    if (tex < 0 || std::size_t(tex) >= m.textures.size()) return out;
    const int source = m.textures[std::size_t(tex)].source;
    if (source < 0 || std::size_t(source) >= m.images.size()) return out;
    const tinygltf::Image& im = m.images[std::size_t(source)];
    if (im.width <= 0 || im.height <= 0 || im.bits != 8 || (im.component != 3 && im.component != 4) ||
        im.image.size() != std::size_t(im.width) * std::size_t(im.height) * std::size_t(im.component))
        return out;
    out.width = im.width;
    out.height = im.height;
    out.pixels.resize(std::size_t(im.width) * std::size_t(im.height) * 4u);
    const std::size_t c = std::size_t(im.component);
    for (std::size_t i = 0; i < std::size_t(im.width) * std::size_t(im.height); ++i)
        for (std::size_t k = 0; k < 4; ++k) out.pixels[4 * i + k] = k < c ? im.image[c * i + k] : 255;
    return out;
}

} // namespace

/// Refuses, with one line, a .glb whose required extensions the reader below does not
/// decode: the quantized and compressed exports (docs/export.md).
void refuse_packed_glb(const std::string& path)
{
    std::ifstream in(path, std::ios::binary);
    char header[20] = {};
    if (!in.read(header, sizeof header) || std::memcmp(header, "glTF", 4) != 0 || std::memcmp(header + 16, "JSON", 4) != 0) return;
    std::uint32_t length = 0;
    std::memcpy(&length, header + 12, 4);
    if (length > (64u << 20)) return; // tinygltf says what is wrong with it
    std::string json(length, '\0');
    if (!in.read(json.data(), static_cast<std::streamsize>(length))) return;
    const nlohmann::json j = nlohmann::json::parse(json, nullptr, false);
    if (!j.is_object() || !j.contains("extensionsRequired") || !j["extensionsRequired"].is_array()) return;
    for (const auto& e : j["extensionsRequired"])
        if (e == "KHR_mesh_quantization" || e == "EXT_meshopt_compression")
            throw FileError(path, "written with --quantize or --compress (" + e.get<std::string>() +
                                      "), which render does not read: export the tree again without them");
}

RenderScene glb_render_scene(const std::string& path, const RenderContent& content)
{
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) throw FileError(path, "no such file");
    // The exporter refuses to write more than 4 GiB; a bigger file is not one of ours.
    if (std::filesystem::file_size(path, ec) > (std::uintmax_t(4) << 30))
        throw FileError(path, "larger than 4 GiB: not a tree exported by Lobesketch");
    refuse_packed_glb(path);
    tinygltf::TinyGLTF loader;
    tinygltf::Model m;
    std::string err, warning;
    if (!loader.LoadBinaryFromFile(&m, &err, &warning, path)) {
        std::string why = err.empty() ? "not a glTF binary" : err;
        std::replace(why.begin(), why.end(), '\n', ' ');
        while (!why.empty() && why.back() == ' ') why.pop_back();
        throw FileError(path, "cannot read the glTF binary: " + why);
    }
    RenderScene scene;
    scene.ground_y = 0.0f; // the export's origin is the trunk base
    const std::string lod = "_LOD" + std::to_string(content.lod);
    bool found_lod = false;
    std::set<int> lods_found; // the LODs the file has, to name them when the asked one is missing
    for (const tinygltf::Node& node : m.nodes) {
        if (node.mesh < 0 || std::size_t(node.mesh) >= m.meshes.size()) continue;
        const tinygltf::Mesh& mesh = m.meshes[std::size_t(node.mesh)];
        const int material = mesh.primitives.empty() ? -1 : mesh.primitives[0].material;
        const std::string& name = node.name;
        // `<stem>_branches_LOD<k>` and `<stem>_leaves_LOD<k>`, whatever the file's stem.
        const std::size_t at = name.rfind("_LOD");
        const std::string digits = at == std::string::npos ? std::string() : name.substr(at + 4);
        const bool lod_name = !digits.empty() && digits.size() < 3 && std::all_of(digits.begin(), digits.end(), ::isdigit);
        auto part_is = [&](const std::string& part) {
            return lod_name && at >= part.size() && name.compare(at - part.size(), part.size(), part) == 0;
        };
        const bool branches = part_is("_branches"), leaves = part_is("_leaves"), billboard = part_is("_billboard");
        if (branches || leaves || billboard) lods_found.insert(std::stoi(digits));
        if (branches && name.compare(at, std::string::npos, lod) == 0) {
            found_lod = true;
            if (content.tree)
                add_item(scene, kBranchesKey | std::uint64_t(content.lod), RenderMaterial::Bark,
                         material_color(m, material, {0.36f, 0.25f, 0.17f, 1.0f}), glb_surface(m, mesh, path));
        } else if (leaves && name.compare(at, std::string::npos, lod) == 0) {
            found_lod = true;
            if (content.leaves) {
                std::array<float, 4> c = material_color(m, material, {0.20f, 0.42f, 0.12f, 1.0f});
                c[3] = 1.0f;
                add_item(scene, kLeavesKey | std::uint64_t(content.lod), RenderMaterial::Leaf, c, glb_surface(m, mesh, path));
                scene.leaf_texture = material_texture(m, material);
                scene.leaf_texture_version = image_hash(scene.leaf_texture);
            }
        } else if (billboard && name.compare(at, std::string::npos, lod) == 0) {
            // The billboard level: cards drawn as leaves are, with its baked picture.
            found_lod = true;
            if (content.tree || content.leaves) {
                add_item(scene, kLeavesKey | std::uint64_t(content.lod), RenderMaterial::Leaf, {1.0f, 1.0f, 1.0f, 1.0f},
                         glb_surface(m, mesh, path));
                scene.leaf_texture = material_texture(m, material);
                scene.leaf_texture_version = image_hash(scene.leaf_texture);
            }
        } else if (name.rfind("lobe_", 0) == 0 && content.lobes) {
            add_item(scene, kLobeKey | std::uint64_t(&node - m.nodes.data()), RenderMaterial::Lobe, kLobeColor,
                     glb_surface(m, mesh, path));
        } else if (name.rfind("stroke_", 0) == 0 && content.strokes) {
            add_item(scene, kStrokeKey | std::uint64_t(&node - m.nodes.data()), RenderMaterial::Stroke, kStrokeColor,
                     polyline_tube(glb_line(m, mesh, path)));
        }
    }
    if ((content.tree || content.leaves) && !found_lod) {
        if (lods_found.empty())
            throw FileError(path, "has no <name>_branches_LOD<k> meshes (not a tree exported by Lobesketch?)");
        std::string has;
        for (const int k : lods_found) has += (has.empty() ? "LOD" : ", LOD") + std::to_string(k);
        throw FileError(path, "has no LOD" + std::to_string(content.lod) + " (it has " + has + "; pick one with --lod)");
    }
    return scene;
}

double coverage(const RgbaImage& picture, const RgbaImage& background, int threshold, std::vector<std::uint8_t>* mask)
{
    if (picture.width != background.width || picture.height != background.height ||
        picture.pixels.size() != background.pixels.size())
        throw InvalidInput("coverage: pictures of different sizes");
    const std::size_t n = picture.pixels.size() / 4;
    if (mask) mask->assign(n, 0);
    std::size_t covered = 0;
    for (std::size_t i = 0; i < n; ++i) {
        int diff = 0;
        for (std::size_t k = 0; k < 3; ++k)
            diff = std::max(diff, std::abs(int(picture.pixels[4 * i + k]) - int(background.pixels[4 * i + k])));
        if (diff > threshold) {
            ++covered;
            if (mask) (*mask)[i] = 1;
        }
    }
    return n ? double(covered) / double(n) : 0.0;
}

} // namespace lobe
