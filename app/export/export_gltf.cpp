#include "app/export/export_gltf.h"

#include <algorithm>
#include <cstring>
#include <limits>
#include <cmath>
#include <cstdint>
#include <utility>
#include <sstream>
#include <string_view>

#include <glm/common.hpp>
#include <meshoptimizer.h>
#include <nlohmann/json.hpp>
#include <tiny_gltf.h>

#include "core/atomic_file.h"
#include "core/errors.h"

namespace lobe {

namespace {

constexpr int kArrayBuffer = TINYGLTF_TARGET_ARRAY_BUFFER;
constexpr int kElementArrayBuffer = TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER;

/// Builds a one-buffer glTF model: every buffer view starts on a 4-byte boundary.
class GlbBuilder {
public:
    GlbBuilder()
    {
        model_.asset.version = "2.0";
        model_.asset.generator = "Lobesketch";
        model_.buffers.emplace_back();
    }

    tinygltf::Model& model() { return model_; }

    /// A buffer view whose bytes go into the binary chunk meshopt-encoded
    /// (EXT_meshopt_compression): the view itself lies in the fallback buffer 1, which holds
    /// no data. `stride` is the vertex size (a multiple of 4) or, for indices, 2 or 4.
    int add_compressed_view(const void* data, std::size_t bytes, int target, std::size_t stride, std::size_t vertex_count)
    {
        if (!meshopt) { // quantized only: a plain view, strided when the data is padded
            const int view = add_view(data, bytes, target);
            if (target == kArrayBuffer) model_.bufferViews[std::size_t(view)].byteStride = stride;
            return view;
        }
        std::vector<unsigned char>& bin = model_.buffers[0].data;
        pad_to_4();
        const std::size_t count = bytes / stride;
        std::vector<unsigned char> encoded;
        if (target == kElementArrayBuffer) {
            std::vector<unsigned int> idx(count);
            for (std::size_t i = 0; i < count; ++i)
                idx[i] = stride == 2 ? static_cast<const std::uint16_t*>(data)[i] : static_cast<const std::uint32_t*>(data)[i];
            encoded.resize(meshopt_encodeIndexBufferBound(count, vertex_count));
            encoded.resize(meshopt_encodeIndexBuffer(encoded.data(), encoded.size(), idx.data(), count));
        } else {
            encoded.resize(meshopt_encodeVertexBufferBound(count, stride));
            encoded.resize(meshopt_encodeVertexBuffer(encoded.data(), encoded.size(), data, count, stride));
        }
        nlohmann::json ext = {{"buffer", 0},
                              {"byteOffset", bin.size()},
                              {"byteLength", encoded.size()},
                              {"byteStride", stride},
                              {"count", count},
                              {"mode", target == kElementArrayBuffer ? "TRIANGLES" : "ATTRIBUTES"}};
        bin.insert(bin.end(), encoded.begin(), encoded.end());
        tinygltf::BufferView view;
        view.buffer = 1;
        view.byteOffset = fallback_bytes_;
        view.byteLength = bytes;
        view.byteStride = target == kElementArrayBuffer ? 0 : stride;
        view.target = target;
        fallback_bytes_ += (bytes + 3) / 4 * 4;
        model_.bufferViews.push_back(view);
        const int index = static_cast<int>(model_.bufferViews.size() - 1);
        meshopt_views_.emplace_back(index, std::move(ext));
        return index;
    }

    std::size_t fallback_bytes() const { return fallback_bytes_; }
    const std::vector<std::pair<int, nlohmann::json>>& meshopt_views() const { return meshopt_views_; }

    /// Quantized vertex data (KHR_mesh_quantization), meshopt-compressed.
    /// Positions: UNSIGNED_SHORT, (p − lo) / step rounded, padded to 8 bytes; the node's
    /// translation lo and scale step restore metres.
    int add_positions_q(const std::vector<glm::vec3>& v, const glm::dvec3& lo, double step)
    {
        std::vector<std::uint16_t> q;
        q.reserve(v.size() * 4);
        glm::dvec3 qlo(65535.0), qhi(0.0);
        for (const glm::vec3& p : v) {
            for (int k = 0; k < 3; ++k) {
                const double c = std::clamp(std::round((double(p[k]) - lo[k]) / step), 0.0, 65535.0);
                q.push_back(static_cast<std::uint16_t>(c));
                qlo[k] = std::min(qlo[k], c);
                qhi[k] = std::max(qhi[k], c);
            }
            q.push_back(0);
        }
        tinygltf::Accessor a = accessor(add_compressed_view(q.data(), q.size() * 2, kArrayBuffer, 8, v.size()),
                                        TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, v.size(), TINYGLTF_TYPE_VEC3);
        a.minValues = {qlo.x, qlo.y, qlo.z};
        a.maxValues = {qhi.x, qhi.y, qhi.z};
        return push(a);
    }

    /// Unit vectors (normals: 3 components, tangents: 4) as normalized BYTE, 4 bytes each.
    int add_units_q(const float* data, std::size_t count, int components)
    {
        std::vector<std::int8_t> q(count * 4, 0);
        for (std::size_t i = 0; i < count; ++i)
            for (int k = 0; k < components; ++k)
                q[4 * i + std::size_t(k)] = static_cast<std::int8_t>(
                    std::clamp(std::round(double(data[std::size_t(components) * i + std::size_t(k)]) * 127.0), -127.0, 127.0));
        tinygltf::Accessor a = accessor(add_compressed_view(q.data(), q.size(), kArrayBuffer, 4, count),
                                        TINYGLTF_COMPONENT_TYPE_BYTE, count, components == 3 ? TINYGLTF_TYPE_VEC3 : TINYGLTF_TYPE_VEC4);
        a.normalized = true;
        return push(a);
    }

    /// Texture coordinates as normalized UNSIGNED_SHORT over the range [lo, lo + extent]
    /// (extent > 0): [0, 1] for leaves and the billboard; the bark's range, undone by the
    /// material's KHR_texture_transform (offset lo, scale extent).
    int add_uvs_q(const std::vector<glm::vec2>& v, const glm::dvec2& lo, const glm::dvec2& extent)
    {
        std::vector<std::uint16_t> q;
        q.reserve(v.size() * 2);
        for (const glm::vec2& t : v)
            for (int k = 0; k < 2; ++k)
                q.push_back(static_cast<std::uint16_t>(std::clamp(std::round((double(t[k]) - lo[k]) / extent[k] * 65535.0), 0.0, 65535.0)));
        tinygltf::Accessor a = accessor(add_compressed_view(q.data(), q.size() * 2, kArrayBuffer, 4, v.size()),
                                        TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, v.size(), TINYGLTF_TYPE_VEC2);
        a.normalized = true;
        return push(a);
    }

    bool meshopt = true; ///< quantized views meshopt-compressed (else plain)

    /// The bark's uv range (KHR_texture_transform of the bark material when compressed).
    glm::dvec2 bark_uv_lo{0.0}, bark_uv_extent{1.0};

    int add_view(const void* data, std::size_t bytes, int target)
    {
        std::vector<unsigned char>& bin = model_.buffers[0].data;
        pad_to_4();
        tinygltf::BufferView view;
        view.buffer = 0;
        view.byteOffset = bin.size();
        view.byteLength = bytes;
        view.target = target;
        const auto* p = static_cast<const unsigned char*>(data);
        bin.insert(bin.end(), p, p + bytes);
        model_.bufferViews.push_back(view);
        return static_cast<int>(model_.bufferViews.size() - 1);
    }

    /// VEC3 float accessor; with min/max when `bounds` (required for POSITION).
    int add_vec3(const std::vector<glm::vec3>& v, bool bounds)
    {
        std::vector<float> flat;
        flat.reserve(v.size() * 3);
        for (const glm::vec3& p : v) flat.insert(flat.end(), {p.x, p.y, p.z});
        tinygltf::Accessor a = accessor(add_view(flat.data(), flat.size() * sizeof(float), kArrayBuffer),
                                        TINYGLTF_COMPONENT_TYPE_FLOAT, v.size(), TINYGLTF_TYPE_VEC3);
        if (bounds) {
            glm::vec3 lo(std::numeric_limits<float>::max()), hi(std::numeric_limits<float>::lowest());
            for (const glm::vec3& p : v) {
                lo = glm::min(lo, p);
                hi = glm::max(hi, p);
            }
            a.minValues = {double(lo.x), double(lo.y), double(lo.z)};
            a.maxValues = {double(hi.x), double(hi.y), double(hi.z)};
        }
        return push(a);
    }

    int add_vec4(const std::vector<glm::vec4>& v)
    {
        std::vector<float> flat;
        flat.reserve(v.size() * 4);
        for (const glm::vec4& p : v) flat.insert(flat.end(), {p.x, p.y, p.z, p.w});
        return push(accessor(add_view(flat.data(), flat.size() * sizeof(float), kArrayBuffer),
                             TINYGLTF_COMPONENT_TYPE_FLOAT, v.size(), TINYGLTF_TYPE_VEC4));
    }

    int add_vec2(const std::vector<glm::vec2>& v)
    {
        std::vector<float> flat;
        flat.reserve(v.size() * 2);
        for (const glm::vec2& p : v) flat.insert(flat.end(), {p.x, p.y});
        return push(accessor(add_view(flat.data(), flat.size() * sizeof(float), kArrayBuffer),
                             TINYGLTF_COMPONENT_TYPE_FLOAT, v.size(), TINYGLTF_TYPE_VEC2));
    }

    /// Triangle indices as UNSIGNED_SHORT when every index fits below the 16-bit restart
    /// value (65535, which glTF forbids as an index), else UNSIGNED_INT; `compressed`: in a
    /// view of add_compressed_view (meshopt-encoded unless quantized only).
    int add_indices(const std::vector<std::array<std::uint32_t, 3>>& triangles, std::size_t vertex_count,
                    bool compressed = false)
    {
        const std::size_t count = triangles.size() * 3;
        const auto view = [&](const void* data, std::size_t element) {
            return compressed ? add_compressed_view(data, count * element, kElementArrayBuffer, element, vertex_count)
                              : add_view(data, count * element, kElementArrayBuffer);
        };
        if (vertex_count <= 65535) {
            std::vector<std::uint16_t> idx;
            idx.reserve(count);
            for (const auto& t : triangles)
                for (std::uint32_t i : t) idx.push_back(static_cast<std::uint16_t>(i));
            return push(accessor(view(idx.data(), sizeof(std::uint16_t)), TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, count,
                                 TINYGLTF_TYPE_SCALAR));
        }
        std::vector<std::uint32_t> idx;
        idx.reserve(count);
        for (const auto& t : triangles) idx.insert(idx.end(), t.begin(), t.end());
        return push(accessor(view(idx.data(), sizeof(std::uint32_t)), TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, count,
                             TINYGLTF_TYPE_SCALAR));
    }

    int add_material(tinygltf::Material m)
    {
        model_.materials.push_back(std::move(m));
        return static_cast<int>(model_.materials.size() - 1);
    }

    int add_mesh_node(const std::string& name, tinygltf::Primitive primitive)
    {
        std::vector<tinygltf::Primitive> one;
        one.push_back(std::move(primitive));
        return add_mesh_node(name, std::move(one));
    }

    int add_mesh_node(const std::string& name, std::vector<tinygltf::Primitive> primitives)
    {
        tinygltf::Mesh mesh;
        mesh.name = name;
        mesh.primitives = std::move(primitives);
        model_.meshes.push_back(std::move(mesh));
        tinygltf::Node node;
        node.name = name;
        node.mesh = static_cast<int>(model_.meshes.size() - 1);
        return add_node(std::move(node));
    }

    int add_node(tinygltf::Node node)
    {
        model_.nodes.push_back(std::move(node));
        return static_cast<int>(model_.nodes.size() - 1);
    }

    void pad_to_4()
    {
        std::vector<unsigned char>& bin = model_.buffers[0].data;
        bin.resize((bin.size() + 3) / 4 * 4, 0);
    }

private:
    static tinygltf::Accessor accessor(int view, int component, std::size_t count, int type)
    {
        tinygltf::Accessor a;
        a.bufferView = view;
        a.byteOffset = 0;
        a.componentType = component;
        a.count = count;
        a.type = type;
        return a;
    }

    int push(tinygltf::Accessor a)
    {
        model_.accessors.push_back(std::move(a));
        return static_cast<int>(model_.accessors.size() - 1);
    }

    tinygltf::Model model_;
    std::size_t fallback_bytes_ = 0;
    std::vector<std::pair<int, nlohmann::json>> meshopt_views_;
};

std::vector<double> rgba(const std::array<float, 3>& rgb, double alpha)
{
    return {double(rgb[0]), double(rgb[1]), double(rgb[2]), alpha};
}

/// Embeds `image` as a PNG in the binary chunk with its own sampler; returns the texture index.
int embed_texture(GlbBuilder& b, const RgbaImage& image, const std::string& name, int wrap)
{
    const std::vector<std::uint8_t> png = encode_png(image);
    tinygltf::Model& model = b.model();
    tinygltf::Image img;
    img.name = name;
    img.mimeType = "image/png";
    img.bufferView = b.add_view(png.data(), png.size(), 0);
    model.images.push_back(std::move(img));
    tinygltf::Sampler sampler;
    sampler.magFilter = TINYGLTF_TEXTURE_FILTER_LINEAR;
    sampler.minFilter = TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_LINEAR;
    sampler.wrapS = wrap;
    sampler.wrapT = wrap;
    model.samplers.push_back(sampler);
    tinygltf::Texture texture;
    texture.source = static_cast<int>(model.images.size() - 1);
    texture.sampler = static_cast<int>(model.samplers.size() - 1);
    model.textures.push_back(texture);
    return static_cast<int>(model.textures.size() - 1);
}

/// The bark material; embeds the tiling bark texture (PNG, REPEAT) when the tree has one.
tinygltf::Material bark_material(const PreparedExport& e, GlbBuilder& b)
{
    tinygltf::Material m;
    m.name = "bark";
    m.pbrMetallicRoughness.baseColorFactor = rgba(e.bark_color, 1.0);
    m.pbrMetallicRoughness.metallicFactor = 0.0;
    m.pbrMetallicRoughness.roughnessFactor = 0.9;
    if (e.bark_texture != nullptr) {
        m.pbrMetallicRoughness.baseColorTexture.index =
            embed_texture(b, *e.bark_texture, e.name + "_bark", TINYGLTF_TEXTURE_WRAP_REPEAT);
        m.pbrMetallicRoughness.baseColorTexture.texCoord = 0;
    }
    if (!e.bark_normal_map.pixels.empty()) {
        m.normalTexture.index = embed_texture(b, e.bark_normal_map, e.name + "_bark_normal", TINYGLTF_TEXTURE_WRAP_REPEAT);
        m.normalTexture.texCoord = 0;
    }
    return m;
}

/// The leaf material; embeds the leaf texture (PNG) when the tree has one.
tinygltf::Material leaf_material(const PreparedExport& e, GlbBuilder& b)
{
    tinygltf::Material m;
    m.name = "leaf";
    m.pbrMetallicRoughness.baseColorFactor = rgba(e.leaf_color, 1.0);
    m.pbrMetallicRoughness.metallicFactor = 0.0;
    m.pbrMetallicRoughness.roughnessFactor = 0.8;
    m.alphaMode = "MASK";
    m.alphaCutoff = 0.5;
    m.doubleSided = true;
    if (e.leaf_texture != nullptr) {
        // Clamped: the leaf is one picture, and its transparent border must not wrap round.
        m.pbrMetallicRoughness.baseColorTexture.index =
            embed_texture(b, *e.leaf_texture, e.name + "_leaf", TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE);
        m.pbrMetallicRoughness.baseColorTexture.texCoord = 0;
    }
    return m;
}

/// The billboard's material: its baked picture (colour and alpha) with a white factor.
tinygltf::Material billboard_material(const PreparedExport& e, GlbBuilder& b)
{
    tinygltf::Material m;
    m.name = "billboard";
    m.pbrMetallicRoughness.baseColorFactor = {1.0, 1.0, 1.0, 1.0};
    m.pbrMetallicRoughness.metallicFactor = 0.0;
    m.pbrMetallicRoughness.roughnessFactor = 0.9;
    m.alphaMode = "MASK";
    m.alphaCutoff = 0.5;
    m.doubleSided = true;
    m.pbrMetallicRoughness.baseColorTexture.index =
        embed_texture(b, e.billboard_texture, e.name + "_billboard", TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE);
    m.pbrMetallicRoughness.baseColorTexture.texCoord = 0;
    return m;
}

tinygltf::Material lobe_material()
{
    tinygltf::Material m;
    m.name = "lobe";
    m.pbrMetallicRoughness.baseColorFactor = {0.45, 0.75, 0.35, 0.25};
    m.pbrMetallicRoughness.metallicFactor = 0.0;
    m.pbrMetallicRoughness.roughnessFactor = 1.0;
    m.alphaMode = "BLEND";
    m.doubleSided = true;
    return m;
}

tinygltf::Material stroke_material(tinygltf::Model& model)
{
    tinygltf::Material m;
    m.name = "stroke";
    m.pbrMetallicRoughness.baseColorFactor = {1.0, 0.55, 0.1, 1.0};
    m.pbrMetallicRoughness.metallicFactor = 0.0;
    m.pbrMetallicRoughness.roughnessFactor = 1.0;
    m.extensions["KHR_materials_unlit"] = tinygltf::Value(tinygltf::Value::Object());
    model.extensionsUsed.push_back("KHR_materials_unlit");
    return m;
}

/// A piece of a part small enough for 16-bit indices.
struct PartChunk {
    SurfaceGeometry geometry;
    std::vector<glm::vec4> tangents;
};

/// `part` as pieces of at most 65,535 vertices (16-bit indices, below the restart value),
/// triangles in order: a new piece starts where the next triangle would need more vertices.
/// One piece, the part itself, when it fits.
std::vector<PartChunk> split_for_16_bit(const ExportPart& part)
{
    constexpr std::size_t kMax = 65535;
    const SurfaceGeometry& g = part.geometry;
    std::vector<PartChunk> out(1);
    if (g.vertex_count() <= kMax) {
        out[0].geometry = g;
        out[0].tangents = part.tangents;
        return out;
    }
    std::vector<std::uint32_t> local(g.vertex_count(), UINT32_MAX);
    std::vector<std::uint32_t> used; // global indices mapped in the current piece
    for (const auto& t : g.triangles) {
        std::size_t fresh = 0;
        for (std::uint32_t v : t) fresh += local[v] == UINT32_MAX;
        if (used.size() + fresh > kMax) { // start a new piece
            for (std::uint32_t v : used) local[v] = UINT32_MAX;
            used.clear();
            out.emplace_back();
        }
        PartChunk& c = out.back();
        std::array<std::uint32_t, 3> tri{};
        for (std::size_t k = 0; k < 3; ++k) {
            const std::uint32_t v = t[k];
            if (local[v] == UINT32_MAX) {
                local[v] = static_cast<std::uint32_t>(c.geometry.positions.size());
                used.push_back(v);
                c.geometry.positions.push_back(g.positions[v]);
                c.geometry.normals.push_back(g.normals[v]);
                c.geometry.uvs.push_back(g.uvs[v]);
                if (!part.tangents.empty()) c.tangents.push_back(part.tangents[v]);
            }
            tri[k] = local[v];
        }
        c.geometry.triangles.push_back(tri);
    }
    return out;
}

/// The tree's parts as children of `root`: float vertex data, or with `compress` quantized
/// and meshopt-compressed, each part's node carrying the dequantizing transform.
void add_tree_parts(const PreparedExport& e, GlbBuilder& b, bool compress, tinygltf::Node& root)
{
    // compress: quantized vertex data, meshopt-compressed unless b.meshopt is off.
    // One quantization grid for the whole tree: uniform steps, so normals stay valid.
    glm::dvec3 lo(std::numeric_limits<double>::max()), hi(std::numeric_limits<double>::lowest());
    for (const ExportPart& part : e.parts)
        for (const glm::vec3& p : part.geometry.positions) {
            lo = glm::min(lo, glm::dvec3(p));
            hi = glm::max(hi, glm::dvec3(p));
        }
    const double step = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z, 1e-6}) / 65535.0;
    glm::dvec2 uv_lo(std::numeric_limits<double>::max()), uv_hi(std::numeric_limits<double>::lowest());
    for (const ExportPart& part : e.parts)
        if (part.kind == ExportPart::Kind::Branches)
            for (const glm::vec2& t : part.geometry.uvs) {
                uv_lo = glm::min(uv_lo, glm::dvec2(t));
                uv_hi = glm::max(uv_hi, glm::dvec2(t));
            }
    if (uv_lo.x <= uv_hi.x) {
        b.bark_uv_lo = uv_lo;
        b.bark_uv_extent = glm::max(uv_hi - uv_lo, glm::dvec2(1e-6));
    }
    int bark = -1, leaf = -1, billboard = -1;
    for (const ExportPart& part : e.parts) {
        const bool is_leaves = part.kind == ExportPart::Kind::Leaves;
        const bool is_billboard = part.kind == ExportPart::Kind::Billboard;
        int& material = is_billboard ? billboard : is_leaves ? leaf : bark;
        if (material < 0)
            material = b.add_material(is_billboard ? billboard_material(e, b)
                                      : is_leaves  ? leaf_material(e, b)
                                                   : bark_material(e, b));
        std::vector<tinygltf::Primitive> prims;
        for (const PartChunk& chunk : split_for_16_bit(part)) {
            const SurfaceGeometry& g = chunk.geometry;
            tinygltf::Primitive prim;
            prim.mode = TINYGLTF_MODE_TRIANGLES;
            prim.material = material;
            if (compress) {
                prim.attributes["POSITION"] = b.add_positions_q(g.positions, lo, step);
                prim.attributes["NORMAL"] = b.add_units_q(&g.normals[0].x, g.normals.size(), 3);
                const bool bark_uvs = part.kind == ExportPart::Kind::Branches;
                prim.attributes["TEXCOORD_0"] = b.add_uvs_q(g.uvs, bark_uvs ? b.bark_uv_lo : glm::dvec2(0.0),
                                                            bark_uvs ? b.bark_uv_extent : glm::dvec2(1.0));
                if (!chunk.tangents.empty())
                    prim.attributes["TANGENT"] = b.add_units_q(&chunk.tangents[0].x, chunk.tangents.size(), 4);
                prim.indices = b.add_indices(g.triangles, g.vertex_count(), true);
            } else {
                prim.attributes["POSITION"] = b.add_vec3(g.positions, true);
                prim.attributes["NORMAL"] = b.add_vec3(g.normals, false);
                prim.attributes["TEXCOORD_0"] = b.add_vec2(g.uvs);
                if (!chunk.tangents.empty()) prim.attributes["TANGENT"] = b.add_vec4(chunk.tangents);
                prim.indices = b.add_indices(g.triangles, g.vertex_count());
            }
            prims.push_back(std::move(prim));
        }
        const int node = b.add_mesh_node(part.name, std::move(prims));
        if (compress) {
            b.model().nodes[std::size_t(node)].translation = {lo.x, lo.y, lo.z};
            b.model().nodes[std::size_t(node)].scale = {step, step, step};
        }
        root.children.push_back(node);
    }
    if (compress) {
        for (const char* ext : {"KHR_mesh_quantization", "EXT_meshopt_compression"}) {
            if (!b.meshopt && std::string_view(ext) == "EXT_meshopt_compression") continue;
            b.model().extensionsUsed.emplace_back(ext);
            b.model().extensionsRequired.emplace_back(ext);
        }
        if (b.fallback_bytes() > 0) b.model().buffers.emplace_back(); // the fallback buffer; its JSON is written by patch_meshopt_json
    }
}

tinygltf::Model build_model(const PreparedExport& e, GlbBuilder& b, bool compress)
{
    tinygltf::Node root;
    root.name = e.name;
    if (!e.species.empty()) {
        tinygltf::Value::Object extras;
        extras["species"] = tinygltf::Value(e.species);
        root.extras = tinygltf::Value(extras);
    }
    add_tree_parts(e, b, compress, root);

    tinygltf::Node sketch;
    sketch.name = e.name + "_sketch";
    if (!e.lobes.empty()) {
        const int material = b.add_material(lobe_material());
        for (const ExportLobe& lobe : e.lobes) {
            tinygltf::Primitive prim;
            prim.mode = TINYGLTF_MODE_TRIANGLES;
            prim.material = material;
            prim.attributes["POSITION"] = b.add_vec3(lobe.positions, true);
            prim.indices = b.add_indices(lobe.triangles, lobe.positions.size());
            sketch.children.push_back(b.add_mesh_node(lobe.name, std::move(prim)));
        }
    }
    if (!e.strokes.empty()) {
        const int material = b.add_material(stroke_material(b.model()));
        for (const ExportPolyline& line : e.strokes) {
            tinygltf::Primitive prim;
            prim.mode = TINYGLTF_MODE_LINE_STRIP;
            prim.material = material;
            prim.attributes["POSITION"] = b.add_vec3(line.points, true);
            sketch.children.push_back(b.add_mesh_node(line.name, std::move(prim)));
        }
    }

    tinygltf::Scene scene;
    scene.name = e.name;
    scene.nodes.push_back(b.add_node(std::move(root)));
    if (!sketch.children.empty()) scene.nodes.push_back(b.add_node(std::move(sketch)));
    b.pad_to_4();
    tinygltf::Model& model = b.model();
    model.scenes.push_back(std::move(scene));
    model.defaultScene = 0;
    if (model.buffers[0].data.empty()) model.buffers.clear(); // a tree with nothing to draw
    return std::move(model);
}

/// The .glb `bytes` with its JSON chunk rewritten for EXT_meshopt_compression: buffer 1
/// becomes the fallback buffer (byteLength only, no data) and the compressed views get their
/// extension objects. tinygltf writes neither.
std::string patch_meshopt_json(const std::string& bytes, const GlbBuilder& b)
{
    auto u32 = [&](std::size_t at) {
        std::uint32_t v = 0;
        std::memcpy(&v, bytes.data() + at, 4);
        return v;
    };
    const std::uint32_t json_length = u32(12);
    nlohmann::json j = nlohmann::json::parse(bytes.substr(20, json_length));
    if (b.meshopt && j["buffers"].size() > 1)
        j["buffers"][1] = {{"byteLength", b.fallback_bytes()}, {"extensions", {{"EXT_meshopt_compression", {{"fallback", true}}}}}};
    for (const auto& [view, ext] : b.meshopt_views()) j["bufferViews"][std::size_t(view)]["extensions"]["EXT_meshopt_compression"] = ext;
    // The bark's quantized uvs are mapped back by a texture transform on its textures.
    bool transform = false;
    for (nlohmann::json& m : j["materials"])
        if (m.value("name", "") == "bark") {
            std::vector<nlohmann::json*> infos;
            if (m.contains("normalTexture")) infos.push_back(&m["normalTexture"]);
            if (m.contains("pbrMetallicRoughness") && m["pbrMetallicRoughness"].contains("baseColorTexture"))
                infos.push_back(&m["pbrMetallicRoughness"]["baseColorTexture"]);
            for (nlohmann::json* info : infos)
                if (info->is_object() && info->contains("index")) {
                    (*info)["extensions"]["KHR_texture_transform"] = {
                        {"offset", {b.bark_uv_lo.x, b.bark_uv_lo.y}}, {"scale", {b.bark_uv_extent.x, b.bark_uv_extent.y}}};
                    transform = true;
                }
        }
    if (transform)
        for (const char* list : {"extensionsUsed", "extensionsRequired"}) j[list].push_back("KHR_texture_transform");
    std::string json = j.dump();
    json.resize((json.size() + 3) / 4 * 4, ' ');
    const std::string bin = bytes.substr(20 + json_length);
    std::string out = bytes.substr(0, 12);
    const auto put = [&](std::uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); };
    put(static_cast<std::uint32_t>(json.size()));
    put(0x4E4F534Au); // "JSON"
    out += json;
    out += bin;
    const auto total = static_cast<std::uint32_t>(out.size());
    std::memcpy(out.data() + 8, &total, 4);
    return out;
}

} // namespace

std::vector<std::uint8_t> encode_glb(const ExportScene& scene, const ExportOptions& options)
{
    const PreparedExport prepared = prepare_export(scene, options);
    GlbBuilder builder;
    builder.meshopt = options.compress;
    tinygltf::Model model = build_model(prepared, builder, options.compress || options.quantize);
    // A .glb states its total length in 32 bits; leave room for the JSON chunk.
    constexpr std::size_t kMaxBinary = std::numeric_limits<std::uint32_t>::max() - (std::size_t(64) << 20);
    if (!model.buffers.empty() && model.buffers[0].data.size() > kMaxBinary)
        throw InvalidInput("export: " + std::to_string(model.buffers[0].data.size()) +
                           " bytes of geometry do not fit a .glb (4 GiB)");
    std::ostringstream out(std::ios::binary);
    tinygltf::TinyGLTF writer;
    if (!writer.WriteGltfSceneToStream(&model, out, false, true) || !out)
        throw InvalidInput("export: tinygltf could not serialise the model");
    std::string bytes = std::move(out).str();
    if (options.compress || options.quantize) bytes = patch_meshopt_json(bytes, builder);
    return std::vector<std::uint8_t>(bytes.begin(), bytes.end());
}

void write_glb(const std::string& path, const ExportScene& scene, const ExportOptions& options)
{
    const std::vector<std::uint8_t> bytes = encode_glb(scene, options);
    write_file_atomic(path, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
}

} // namespace lobe
