// glTF (.glb) and OBJ export of a hand-built tree: structure, materials, bounds, origin and
// height, LOD selection, extras, determinism, the Khronos validator, and failures.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <set>
#include <sstream>

#include <sys/wait.h>

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>
#include <tiny_gltf.h>

#include "app/export/export_gltf.h"
#include "app/export/export_obj.h"
#include "core/errors.h"
#include "growth/bark_texture.h"
#include "tests/support/gltf_check.h"
#include "tests/support/shapes.h"
#include "tests/support/test_paths.h"

namespace lobe {
namespace {

namespace fs = std::filesystem;
using test::octahedron;

// --- a hand-built tree -------------------------------------------------------------------

/// Open cylinder from a to b: (sides+1) × (rings+1) vertices (the seam doubled for the
/// uvs), outward normals, u around, v along in units of the circumference.
SurfaceGeometry cylinder(glm::vec3 a, glm::vec3 b, float r, int sides, int rings)
{
    SurfaceGeometry g;
    const glm::vec3 axis = b - a;
    const float len = glm::length(axis);
    const glm::vec3 d = axis / len;
    const glm::vec3 helper = std::abs(d.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
    const glm::vec3 e1 = glm::normalize(glm::cross(helper, d));
    const glm::vec3 e2 = glm::cross(d, e1);
    const float circumference = 2.0f * 3.14159265f * r;
    for (int k = 0; k <= rings; ++k) {
        const float t = float(k) / float(rings);
        for (int j = 0; j <= sides; ++j) {
            const float th = 2.0f * 3.14159265f * float(j) / float(sides);
            const glm::vec3 radial = std::cos(th) * e1 + std::sin(th) * e2;
            g.positions.push_back(a + t * axis + r * radial);
            g.normals.push_back(radial);
            g.uvs.emplace_back(float(j) / float(sides), t * len / circumference);
        }
    }
    const auto at = [&](int j, int k) { return std::uint32_t(k * (sides + 1) + j); };
    for (int k = 0; k < rings; ++k)
        for (int j = 0; j < sides; ++j) {
            g.triangles.push_back({at(j, k), at(j + 1, k), at(j, k + 1)});
            g.triangles.push_back({at(j + 1, k), at(j + 1, k + 1), at(j, k + 1)});
        }
    return g;
}

void append(SurfaceGeometry& to, const SurfaceGeometry& g)
{
    const auto offset = std::uint32_t(to.positions.size());
    to.positions.insert(to.positions.end(), g.positions.begin(), g.positions.end());
    to.normals.insert(to.normals.end(), g.normals.begin(), g.normals.end());
    to.uvs.insert(to.uvs.end(), g.uvs.begin(), g.uvs.end());
    for (auto t : g.triangles) to.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
}

/// `count` leaf quads spread around a point, each two triangles over the whole texture.
SurfaceGeometry leaf_quads(glm::vec3 centre, int count, float size)
{
    SurfaceGeometry g;
    for (int i = 0; i < count; ++i) {
        const float a = 2.399963f * float(i); // golden angle
        const glm::vec3 c = centre + glm::vec3(0.35f * std::cos(a), 0.02f * float(i % 7), 0.35f * std::sin(a));
        const glm::vec3 n = glm::normalize(glm::vec3(std::cos(a), 0.6f, std::sin(a)));
        const glm::vec3 e1 = glm::normalize(glm::cross(glm::vec3(0, 1, 0), n));
        const glm::vec3 e2 = glm::cross(n, e1);
        const auto o = std::uint32_t(g.positions.size());
        const float h = 0.5f * size;
        g.positions.insert(g.positions.end(), {c - h * e1 - h * e2, c + h * e1 - h * e2, c + h * e1 + h * e2,
                                               c - h * e1 + h * e2});
        g.normals.insert(g.normals.end(), 4, n);
        g.uvs.insert(g.uvs.end(), {{0.0f, 1.0f}, {1.0f, 1.0f}, {1.0f, 0.0f}, {0.0f, 0.0f}});
        g.triangles.push_back({o, o + 1, o + 2});
        g.triangles.push_back({o, o + 2, o + 3});
    }
    return g;
}

/// 64×64 leaf: opaque inside an ellipse, alpha 0 outside.
RgbaImage leaf_texture()
{
    RgbaImage img;
    img.width = 64;
    img.height = 64;
    for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 64; ++x) {
            const float dx = (float(x) + 0.5f - 32.0f) / 14.0f, dy = (float(y) + 0.5f - 32.0f) / 30.0f;
            const bool inside = dx * dx + dy * dy <= 1.0f;
            img.pixels.insert(img.pixels.end(), {std::uint8_t(60 + x), std::uint8_t(120 + y), 40,
                                                 std::uint8_t(inside ? 255 : 0)});
        }
    return img;
}

const glm::vec3 kBase{1.5f, 0.25f, -2.0f};

/// A trunk and two limbs over three LODs (12/6/4 sides); leaves on LOD0 (24 quads) and
/// LOD1 (8 quads), none on LOD2.
TreeGeometry test_tree()
{
    TreeGeometry tree;
    const int sides[3] = {12, 6, 4}, rings[3] = {4, 2, 1}, leaves[3] = {24, 8, 0};
    for (int l = 0; l < 3; ++l) {
        TreeLod lod;
        append(lod.branches, cylinder(kBase, kBase + glm::vec3(0, 2.5f, 0), 0.12f, sides[l], rings[l]));
        append(lod.branches, cylinder(kBase + glm::vec3(0, 1.5f, 0), kBase + glm::vec3(0.8f, 2.6f, 0.1f), 0.05f,
                                      sides[l], rings[l]));
        append(lod.branches, cylinder(kBase + glm::vec3(0, 1.8f, 0), kBase + glm::vec3(-0.6f, 2.9f, -0.3f), 0.04f,
                                      sides[l], rings[l]));
        if (leaves[l] > 0) lod.leaves = leaf_quads(kBase + glm::vec3(0, 2.8f, 0), leaves[l], 0.12f);
        tree.lods.push_back(std::move(lod));
    }
    tree.leaf_texture = leaf_texture();
    tree.bark_color = {0.3f, 0.2f, 0.1f};
    tree.leaf_color = {0.25f, 0.5f, 0.15f};
    tree.species = "broadleaf";
    return tree;
}

/// Highest y of LOD0 of the test tree above kBase.
float tree_height(const TreeGeometry& tree)
{
    float top = -1e30f;
    for (const SurfaceGeometry* g : {&tree.lods[0].branches, &tree.lods[0].leaves})
        for (const glm::vec3& p : g->positions) top = std::max(top, p.y - kBase.y);
    return top;
}

Stroke stroke(std::int64_t id, int points, glm::vec3 from)
{
    Stroke s;
    s.id = id;
    for (int i = 0; i < points; ++i)
        s.points.push_back({from + glm::vec3(0.1f * float(i), 0.05f * float(i * i % 5), 0.0f), 0.01 * i});
    return s;
}

ExportScene scene_of(const TreeGeometry& tree, bool with_sketch = false)
{
    ExportScene s;
    s.tree = &tree;
    s.base = kBase;
    if (with_sketch) {
        s.lobes = {octahedron(kBase + glm::vec3(0.5f, 2.7f, 0), 0.6f), octahedron(kBase + glm::vec3(-0.4f, 2.9f, 0), 0.5f)};
        s.strokes = {stroke(7, 12, kBase + glm::vec3(0, 2.2f, 0)), stroke(9, 5, kBase + glm::vec3(0, 0.1f, 0)),
                     stroke(11, 1, kBase)};
    }
    return s;
}

// --- reading exports back ------------------------------------------------------------------

tinygltf::Model load_glb(const std::vector<std::uint8_t>& bytes)
{
    tinygltf::TinyGLTF loader;
    tinygltf::Model model;
    std::string err, warn;
    const bool ok = loader.LoadBinaryFromMemory(&model, &err, &warn, bytes.data(), unsigned(bytes.size()));
    EXPECT_TRUE(ok) << err;
    EXPECT_EQ(err, "");
    EXPECT_EQ(warn, "");
    return model;
}

const unsigned char* accessor_data(const tinygltf::Model& m, int accessor)
{
    const tinygltf::Accessor& a = m.accessors.at(std::size_t(accessor));
    const tinygltf::BufferView& v = m.bufferViews.at(std::size_t(a.bufferView));
    return m.buffers.at(std::size_t(v.buffer)).data.data() + v.byteOffset + a.byteOffset;
}

std::vector<glm::vec3> read_vec3(const tinygltf::Model& m, int accessor)
{
    const tinygltf::Accessor& a = m.accessors.at(std::size_t(accessor));
    EXPECT_EQ(a.componentType, TINYGLTF_COMPONENT_TYPE_FLOAT);
    EXPECT_EQ(a.type, TINYGLTF_TYPE_VEC3);
    std::vector<glm::vec3> out(a.count);
    std::memcpy(out.data(), accessor_data(m, accessor), a.count * sizeof(glm::vec3));
    return out;
}

std::vector<glm::vec2> read_vec2(const tinygltf::Model& m, int accessor)
{
    const tinygltf::Accessor& a = m.accessors.at(std::size_t(accessor));
    EXPECT_EQ(a.type, TINYGLTF_TYPE_VEC2);
    std::vector<glm::vec2> out(a.count);
    std::memcpy(out.data(), accessor_data(m, accessor), a.count * sizeof(glm::vec2));
    return out;
}

std::vector<std::uint32_t> read_indices(const tinygltf::Model& m, int accessor)
{
    const tinygltf::Accessor& a = m.accessors.at(std::size_t(accessor));
    std::vector<std::uint32_t> out(a.count);
    const unsigned char* p = accessor_data(m, accessor);
    for (std::size_t i = 0; i < a.count; ++i) {
        if (a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT) {
            std::uint16_t v;
            std::memcpy(&v, p + 2 * i, 2);
            out[i] = v;
        } else {
            EXPECT_EQ(a.componentType, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT);
            std::memcpy(&out[i], p + 4 * i, 4);
        }
    }
    return out;
}

const tinygltf::Node* find_node(const tinygltf::Model& m, const std::string& name)
{
    for (const tinygltf::Node& n : m.nodes)
        if (n.name == name) return &n;
    return nullptr;
}

std::vector<std::string> child_names(const tinygltf::Model& m, const tinygltf::Node& n)
{
    std::vector<std::string> names;
    for (int c : n.children) names.push_back(m.nodes.at(std::size_t(c)).name);
    return names;
}

std::vector<std::string> node_names(const tinygltf::Model& m)
{
    std::vector<std::string> names;
    for (const tinygltf::Node& n : m.nodes) names.push_back(n.name);
    return names;
}

const tinygltf::Primitive& primitive_of(const tinygltf::Model& m, const std::string& node)
{
    const tinygltf::Node* n = find_node(m, node);
    if (n == nullptr || n->mesh < 0) throw std::runtime_error("no mesh node " + node);
    return m.meshes.at(std::size_t(n->mesh)).primitives.at(0);
}

std::vector<std::uint8_t> read_bytes(const std::string& path)
{
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::string read_text(const std::string& path)
{
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// --- glTF ---------------------------------------------------------------------------------

TEST(ExportGltf, GlbParsesBackWithTinygltfAsGltf2FromLobesketch)
{
    const TreeGeometry tree = test_tree();
    const std::vector<std::uint8_t> glb = encode_glb(scene_of(tree));
    ASSERT_GE(glb.size(), 12u);
    EXPECT_EQ(std::string(glb.begin(), glb.begin() + 4), "glTF");
    const tinygltf::Model m = load_glb(glb);
    EXPECT_EQ(m.asset.version, "2.0");
    EXPECT_EQ(m.asset.generator, "Lobesketch");
    EXPECT_EQ(m.buffers.size(), 1u);
    EXPECT_EQ(m.scenes.size(), 1u);
    EXPECT_EQ(m.defaultScene, 0);
}

TEST(ExportGltf, RootNodeGroupsBranchAndLeafNodesNamedPerLodAndEmptyMeshesAreOmitted)
{
    const TreeGeometry tree = test_tree();
    const tinygltf::Model m = load_glb(encode_glb(scene_of(tree)));
    ASSERT_EQ(m.scenes[0].nodes.size(), 1u);
    const tinygltf::Node& root = m.nodes.at(std::size_t(m.scenes[0].nodes[0]));
    EXPECT_EQ(root.name, "tree");
    EXPECT_EQ(root.mesh, -1);
    EXPECT_TRUE(root.extras.Has("species"));
    EXPECT_EQ(root.extras.Get("species").Get<std::string>(), "broadleaf");
    const std::vector<std::string> expected = {"tree_branches_LOD0", "tree_leaves_LOD0", "tree_branches_LOD1",
                                               "tree_leaves_LOD1", "tree_branches_LOD2"};
    EXPECT_EQ(child_names(m, root), expected); // LOD2 has no leaves: no tree_leaves_LOD2
    EXPECT_EQ(m.meshes.size(), expected.size());
    for (const std::string& name : expected) {
        const tinygltf::Node* n = find_node(m, name);
        ASSERT_NE(n, nullptr) << name;
        ASSERT_GE(n->mesh, 0);
        EXPECT_EQ(m.meshes[std::size_t(n->mesh)].name, name);
        EXPECT_TRUE(n->matrix.empty() && n->translation.empty() && n->rotation.empty() && n->scale.empty())
            << "transforms are baked into the vertices";
        const tinygltf::Primitive& p = primitive_of(m, name);
        EXPECT_EQ(p.mode, TINYGLTF_MODE_TRIANGLES);
        const bool leaves = name.find("_leaves_") != std::string::npos;
        EXPECT_EQ(m.materials.at(std::size_t(p.material)).name, leaves ? "leaf" : "bark");
        const int lod = name.back() - '0';
        const SurfaceGeometry& g = leaves ? tree.lods[std::size_t(lod)].leaves : tree.lods[std::size_t(lod)].branches;
        EXPECT_EQ(m.accessors.at(std::size_t(p.indices)).count, 3 * g.triangle_count()) << name;
        EXPECT_EQ(m.accessors.at(std::size_t(p.attributes.at("POSITION"))).count, g.vertex_count()) << name;
    }
    // Fewer triangles per LOD, as made.
    EXPECT_GT(m.accessors.at(std::size_t(primitive_of(m, "tree_branches_LOD0").indices)).count,
              m.accessors.at(std::size_t(primitive_of(m, "tree_branches_LOD1").indices)).count);
    for (const tinygltf::Accessor& a : m.accessors) EXPECT_GT(a.count, 0u) << "no empty accessor";
}

TEST(ExportGltf, LeafMaterialIsMaskedDoubleSidedWithEmbeddedPngOfTheOriginalTexture)
{
    const TreeGeometry tree = test_tree();
    const tinygltf::Model m = load_glb(encode_glb(scene_of(tree)));
    const tinygltf::Material& leaf = m.materials.at(std::size_t(primitive_of(m, "tree_leaves_LOD0").material));
    EXPECT_EQ(leaf.alphaMode, "MASK");
    EXPECT_DOUBLE_EQ(leaf.alphaCutoff, 0.5);
    EXPECT_TRUE(leaf.doubleSided);
    EXPECT_EQ(leaf.pbrMetallicRoughness.baseColorFactor,
              (std::vector<double>{tree.leaf_color[0], tree.leaf_color[1], tree.leaf_color[2], 1.0}));
    const int tex = leaf.pbrMetallicRoughness.baseColorTexture.index;
    ASSERT_GE(tex, 0);
    EXPECT_EQ(leaf.pbrMetallicRoughness.baseColorTexture.texCoord, 0);
    ASSERT_EQ(m.images.size(), 1u);
    const tinygltf::Image& img = m.images.at(std::size_t(m.textures.at(std::size_t(tex)).source));
    EXPECT_EQ(img.uri, "") << "embedded, not a separate file";
    EXPECT_EQ(img.mimeType, "image/png");
    ASSERT_GE(img.bufferView, 0);
    const tinygltf::BufferView& view = m.bufferViews.at(std::size_t(img.bufferView));
    const unsigned char* png = m.buffers[0].data.data() + view.byteOffset;
    EXPECT_EQ(std::memcmp(png, "\x89PNG\r\n\x1a\n", 8), 0);
    // tinygltf's loader decodes the embedded PNG: lossless, so the very same pixels.
    EXPECT_EQ(img.width, 64);
    EXPECT_EQ(img.height, 64);
    EXPECT_EQ(img.component, 4);
    EXPECT_EQ(img.image, tree.leaf_texture.pixels);
    // Leaves carry the leaf uvs unchanged.
    EXPECT_EQ(read_vec2(m, primitive_of(m, "tree_leaves_LOD0").attributes.at("TEXCOORD_0")), tree.lods[0].leaves.uvs);
}

TEST(ExportGltf, BarkMaterialIsOpaqueRoughDielectricWithBarkColorAndBarkUvs)
{
    const TreeGeometry tree = test_tree();
    const tinygltf::Model m = load_glb(encode_glb(scene_of(tree)));
    const tinygltf::Primitive& p = primitive_of(m, "tree_branches_LOD1");
    const tinygltf::Material& bark = m.materials.at(std::size_t(p.material));
    EXPECT_EQ(bark.alphaMode, "OPAQUE");
    EXPECT_FALSE(bark.doubleSided);
    EXPECT_DOUBLE_EQ(bark.pbrMetallicRoughness.metallicFactor, 0.0);
    EXPECT_DOUBLE_EQ(bark.pbrMetallicRoughness.roughnessFactor, 0.9);
    EXPECT_EQ(bark.pbrMetallicRoughness.baseColorFactor,
              (std::vector<double>{tree.bark_color[0], tree.bark_color[1], tree.bark_color[2], 1.0}));
    EXPECT_EQ(read_vec2(m, p.attributes.at("TEXCOORD_0")), tree.lods[1].branches.uvs);
    EXPECT_EQ(m.materials.size(), 2u) << "bark and leaf only, shared by all LODs";
}

TEST(ExportGltf, BarkTextureIsEmbeddedRepeatingAndTheLeafTextureClamped)
{
    TreeGeometry tree = test_tree();
    tree.bark_texture = make_bark_texture(16);
    const tinygltf::Model m = load_glb(encode_glb(scene_of(tree)));
    const tinygltf::Material& bark = m.materials.at(std::size_t(primitive_of(m, "tree_branches_LOD0").material));
    const tinygltf::Material& leaf = m.materials.at(std::size_t(primitive_of(m, "tree_leaves_LOD0").material));
    ASSERT_GE(bark.pbrMetallicRoughness.baseColorTexture.index, 0);
    ASSERT_GE(leaf.pbrMetallicRoughness.baseColorTexture.index, 0);
    const tinygltf::Texture& bt = m.textures.at(std::size_t(bark.pbrMetallicRoughness.baseColorTexture.index));
    const tinygltf::Texture& lt = m.textures.at(std::size_t(leaf.pbrMetallicRoughness.baseColorTexture.index));
    EXPECT_EQ(m.samplers.at(std::size_t(bt.sampler)).wrapS, TINYGLTF_TEXTURE_WRAP_REPEAT);
    EXPECT_EQ(m.samplers.at(std::size_t(bt.sampler)).wrapT, TINYGLTF_TEXTURE_WRAP_REPEAT);
    EXPECT_EQ(m.samplers.at(std::size_t(lt.sampler)).wrapS, TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE);
    const tinygltf::Image& image = m.images.at(std::size_t(bt.source));
    EXPECT_EQ(image.width, 16);
    EXPECT_EQ(image.height, 16);
    EXPECT_EQ(image.image, tree.bark_texture.pixels);
    // With a bark texture the bark UVs are used: the validator has nothing to say about them.
    const std::string file = test::temp_dir("export-bark") + "/tree.glb";
    write_glb(file, scene_of(tree));
    nlohmann::json report;
    ASSERT_TRUE(test::validate_gltf(file, report));
    EXPECT_EQ(report["issues"]["numErrors"], 0) << test::describe_gltf_issues(report);
    EXPECT_EQ(report["issues"]["numWarnings"], 0) << test::describe_gltf_issues(report);
    EXPECT_EQ(report["issues"]["numInfos"], 0) << test::describe_gltf_issues(report);
}

TEST(ExportGltf, PositionBoundsMatchTheDataWhichIsTheInputMinusTheBase)
{
    const TreeGeometry tree = test_tree();
    const tinygltf::Model m = load_glb(encode_glb(scene_of(tree)));
    float min_y = 1e30f;
    for (const tinygltf::Node& n : m.nodes) {
        if (n.mesh < 0) continue;
        const tinygltf::Primitive& p = m.meshes[std::size_t(n.mesh)].primitives[0];
        const int pos = p.attributes.at("POSITION");
        const std::vector<glm::vec3> v = read_vec3(m, pos);
        glm::vec3 lo(1e30f), hi(-1e30f);
        for (const glm::vec3& x : v) {
            lo = glm::min(lo, x);
            hi = glm::max(hi, x);
        }
        const tinygltf::Accessor& a = m.accessors[std::size_t(pos)];
        EXPECT_EQ(a.minValues, (std::vector<double>{lo.x, lo.y, lo.z})) << n.name;
        EXPECT_EQ(a.maxValues, (std::vector<double>{hi.x, hi.y, hi.z})) << n.name;
        min_y = std::min(min_y, lo.y);

        const int lod = n.name.back() - '0';
        const bool leaves = n.name.find("_leaves_") != std::string::npos;
        const SurfaceGeometry& g = leaves ? tree.lods[std::size_t(lod)].leaves : tree.lods[std::size_t(lod)].branches;
        ASSERT_EQ(v.size(), g.positions.size());
        for (std::size_t i = 0; i < v.size(); ++i) {
            EXPECT_EQ(v[i], g.positions[i] - kBase) << n.name << " vertex " << i;
        }
        EXPECT_EQ(read_indices(m, p.indices).size(), 3 * g.triangle_count());
    }
    EXPECT_NEAR(min_y, 0.0f, 1e-6f) << "the trunk base is the origin";
}

TEST(ExportGltf, NormalsAreWrittenUnitLength)
{
    TreeGeometry tree = test_tree();
    for (glm::vec3& n : tree.lods[0].branches.normals) n *= 3.0f; // not unit on input
    const tinygltf::Model m = load_glb(encode_glb(scene_of(tree)));
    for (const tinygltf::Node& n : m.nodes) {
        if (n.mesh < 0) continue;
        for (const glm::vec3& v : read_vec3(m, m.meshes[std::size_t(n.mesh)].primitives[0].attributes.at("NORMAL")))
            EXPECT_NEAR(glm::length(v), 1.0f, 1e-6f) << n.name;
    }
}

TEST(ExportGltf, TargetHeightScalesTheTreeUniformlyToThatHeightAboveItsBase)
{
    const TreeGeometry tree = test_tree();
    ExportOptions options;
    options.target_height_m = 12.0;
    const tinygltf::Model m = load_glb(encode_glb(scene_of(tree), options));
    const float s = 12.0f / tree_height(tree);
    double top = -1e30, bottom = 1e30;
    for (const tinygltf::Node& n : m.nodes) {
        if (n.mesh < 0 || n.name.find("_LOD0") == std::string::npos) continue;
        const tinygltf::Accessor& a = m.accessors[std::size_t(m.meshes[std::size_t(n.mesh)].primitives[0].attributes.at("POSITION"))];
        top = std::max(top, a.maxValues[1]);
        bottom = std::min(bottom, a.minValues[1]);
    }
    EXPECT_NEAR(top, 12.0, 1e-4);
    EXPECT_NEAR(bottom, 0.0, 1e-5);
    // Uniform: x and z scale like y.
    const std::vector<glm::vec3> v = read_vec3(m, primitive_of(m, "tree_branches_LOD0").attributes.at("POSITION"));
    const glm::vec3 expected = (tree.lods[0].branches.positions[5] - kBase) * s;
    EXPECT_NEAR(v[5].x, expected.x, 1e-5f);
    EXPECT_NEAR(v[5].y, expected.y, 1e-5f);
    EXPECT_NEAR(v[5].z, expected.z, 1e-5f);

    // Writing LOD2 alone scales it exactly as in the full export.
    options.lods = {2};
    const tinygltf::Model m2 = load_glb(encode_glb(scene_of(tree), options));
    const std::vector<glm::vec3> lod2 = read_vec3(m2, primitive_of(m2, "tree_branches_LOD2").attributes.at("POSITION"));
    const std::vector<glm::vec3> lod2_full = read_vec3(m, primitive_of(m, "tree_branches_LOD2").attributes.at("POSITION"));
    EXPECT_EQ(lod2, lod2_full);
}

TEST(ExportGltf, LodSelectionWritesOnlyTheChosenLods)
{
    const TreeGeometry tree = test_tree();
    ExportOptions options;
    options.lods = {0};
    const tinygltf::Model m0 = load_glb(encode_glb(scene_of(tree), options));
    EXPECT_EQ(child_names(m0, m0.nodes.at(std::size_t(m0.scenes[0].nodes[0]))),
              (std::vector<std::string>{"tree_branches_LOD0", "tree_leaves_LOD0"}));
    EXPECT_EQ(m0.meshes.size(), 2u);
    for (const std::string& name : node_names(m0)) EXPECT_EQ(name.find("LOD1"), std::string::npos) << name;

    options.lods = {2}; // no leaves there: no leaf material and no texture
    const tinygltf::Model m2 = load_glb(encode_glb(scene_of(tree), options));
    EXPECT_EQ(child_names(m2, m2.nodes.at(std::size_t(m2.scenes[0].nodes[0]))),
              (std::vector<std::string>{"tree_branches_LOD2"}));
    EXPECT_EQ(m2.materials.size(), 1u);
    EXPECT_TRUE(m2.images.empty());

    options.lods = {2, 0}; // any order; written LOD ascending
    const tinygltf::Model m20 = load_glb(encode_glb(scene_of(tree), options));
    EXPECT_EQ(child_names(m20, m20.nodes.at(std::size_t(m20.scenes[0].nodes[0]))),
              (std::vector<std::string>{"tree_branches_LOD0", "tree_leaves_LOD0", "tree_branches_LOD2"}));

    options.lods = {3};
    EXPECT_THROW(encode_glb(scene_of(tree), options), InvalidInput);
    options.lods = {1, 1};
    EXPECT_THROW(encode_glb(scene_of(tree), options), InvalidInput);
}

TEST(ExportGltf, LobesAndStrokesAppearOnlyWhenAsked)
{
    const TreeGeometry tree = test_tree();
    const ExportScene scene = scene_of(tree, true);
    const tinygltf::Model plain = load_glb(encode_glb(scene));
    EXPECT_EQ(plain.scenes[0].nodes.size(), 1u);
    for (const std::string& name : node_names(plain)) {
        EXPECT_NE(name.rfind("lobe_", 0), 0u) << name;
        EXPECT_NE(name.rfind("stroke_", 0), 0u) << name;
    }

    ExportOptions options;
    options.include_lobes = true;
    const tinygltf::Model lobes_only = load_glb(encode_glb(scene, options));
    EXPECT_NE(find_node(lobes_only, "lobe_1"), nullptr); // named by id: 1, 2, … when the scene gives no ids
    EXPECT_EQ(find_node(lobes_only, "lobe_0"), nullptr);
    EXPECT_EQ(find_node(lobes_only, "stroke_7"), nullptr);

    options.include_strokes = true;
    const tinygltf::Model m = load_glb(encode_glb(scene, options));
    ASSERT_EQ(m.scenes[0].nodes.size(), 2u);
    const tinygltf::Node& sketch = m.nodes.at(std::size_t(m.scenes[0].nodes[1]));
    EXPECT_EQ(sketch.name, "tree_sketch");
    // The one-point stroke 11 is left out: a line needs two points.
    EXPECT_EQ(child_names(m, sketch), (std::vector<std::string>{"lobe_1", "lobe_2", "stroke_7", "stroke_9"}));

    const tinygltf::Primitive& lobe = primitive_of(m, "lobe_2");
    EXPECT_EQ(lobe.mode, TINYGLTF_MODE_TRIANGLES);
    const tinygltf::Material& lobe_mat = m.materials.at(std::size_t(lobe.material));
    EXPECT_EQ(lobe_mat.alphaMode, "BLEND");
    EXPECT_LT(lobe_mat.pbrMetallicRoughness.baseColorFactor[3], 1.0);
    const std::vector<glm::vec3> lobe_pos = read_vec3(m, lobe.attributes.at("POSITION"));
    ASSERT_EQ(lobe_pos.size(), scene.lobes[1].positions.size());
    EXPECT_EQ(lobe_pos[2], scene.lobes[1].positions[2] - kBase) << "same origin as the tree";

    const tinygltf::Primitive& line = primitive_of(m, "stroke_7");
    EXPECT_EQ(line.mode, TINYGLTF_MODE_LINE_STRIP);
    EXPECT_EQ(line.indices, -1);
    EXPECT_EQ(m.accessors.at(std::size_t(line.attributes.at("POSITION"))).count, 12u);
    const tinygltf::Material& stroke_mat = m.materials.at(std::size_t(line.material));
    EXPECT_EQ(stroke_mat.extensions.count("KHR_materials_unlit"), 1u);
    EXPECT_NE(std::find(m.extensionsUsed.begin(), m.extensionsUsed.end(), "KHR_materials_unlit"), m.extensionsUsed.end());
}

TEST(ExportGltf, TwoExportsOfTheSameInputAreByteIdentical)
{
    const TreeGeometry tree = test_tree();
    ExportOptions options;
    options.include_lobes = options.include_strokes = true;
    options.target_height_m = 7.5;
    const std::vector<std::uint8_t> a = encode_glb(scene_of(tree, true), options);
    const TreeGeometry tree_again = test_tree();
    const std::vector<std::uint8_t> b = encode_glb(scene_of(tree_again, true), options);
    EXPECT_EQ(a, b);
    const std::string dir = test::temp_dir("export-identical");
    write_glb(dir + "/t.glb", scene_of(tree, true), options);
    EXPECT_EQ(read_bytes(dir + "/t.glb"), a) << "write_glb writes encode_glb's bytes";
}

TEST(ExportGltf, BufferViewsAreFourByteAlignedAndIndicesUseTheSmallestType)
{
    const TreeGeometry tree = test_tree();
    ExportOptions options;
    options.include_lobes = options.include_strokes = true;
    const tinygltf::Model m = load_glb(encode_glb(scene_of(tree, true), options));
    for (const tinygltf::BufferView& v : m.bufferViews) EXPECT_EQ(v.byteOffset % 4, 0u);
    EXPECT_EQ(m.buffers[0].data.size() % 4, 0u);
    EXPECT_EQ(m.accessors.at(std::size_t(primitive_of(m, "tree_branches_LOD0").indices)).componentType,
              TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT);

    // 301 × 301 grid vertices: beyond 16-bit indices, so the mesh is split into primitives
    // of at most 65,535 vertices, each with 16-bit indices.
    TreeGeometry big;
    big.lods.emplace_back();
    big.lods[0].branches = cylinder(kBase, kBase + glm::vec3(0, 3, 0), 0.2f, 300, 300);
    ASSERT_GT(big.lods[0].branches.vertex_count(), 65535u);
    const tinygltf::Model mb = load_glb(encode_glb(scene_of(big)));
    const auto mesh = std::find_if(mb.meshes.begin(), mb.meshes.end(), [](const tinygltf::Mesh& x) { return x.name == "tree_branches_LOD0"; });
    ASSERT_NE(mesh, mb.meshes.end());
    EXPECT_EQ(mesh->primitives.size(), 2u);
    std::size_t triangles = 0;
    for (const tinygltf::Primitive& p : mesh->primitives) {
        EXPECT_EQ(mb.accessors.at(std::size_t(p.indices)).componentType, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT);
        const std::vector<std::uint32_t> idx = read_indices(mb, p.indices);
        EXPECT_LT(*std::max_element(idx.begin(), idx.end()), 65535u);
        triangles += idx.size() / 3;
    }
    EXPECT_EQ(triangles, big.lods[0].branches.triangle_count());
}

TEST(ExportGltf, KhronosValidatorReportsNoErrorsForTheTree)
{
    const TreeGeometry tree = test_tree();
    const std::string file = test::temp_dir("export-validate-tree") + "/tree.glb";
    write_glb(file, scene_of(tree));
    nlohmann::json report;
    ASSERT_TRUE(test::validate_gltf(file, report));
    const auto& issues = report["issues"];
    std::cout << "gltf-validator " << report.value("validatorVersion", "?") << ": " << issues["numErrors"]
              << " errors, " << issues["numWarnings"] << " warnings, " << issues["numInfos"] << " infos, "
              << issues["numHints"] << " hints\n"
              << test::describe_gltf_issues(report);
    EXPECT_EQ(issues["numErrors"].get<int>(), 0) << test::describe_gltf_issues(report);
    EXPECT_EQ(issues["numWarnings"].get<int>(), 0) << test::describe_gltf_issues(report);
    EXPECT_EQ(report["info"]["generator"], "Lobesketch");
}

TEST(ExportGltf, KhronosValidatorReportsNoErrorsForTheTreeWithLobesStrokesAndHeight)
{
    const TreeGeometry tree = test_tree();
    ExportOptions options;
    options.include_lobes = options.include_strokes = true;
    options.target_height_m = 4.0;
    const std::string file = test::temp_dir("export-validate-extras") + "/tree.glb";
    write_glb(file, scene_of(tree, true), options);
    nlohmann::json report;
    ASSERT_TRUE(test::validate_gltf(file, report));
    const auto& issues = report["issues"];
    std::cout << "gltf-validator " << report.value("validatorVersion", "?") << ": " << issues["numErrors"]
              << " errors, " << issues["numWarnings"] << " warnings, " << issues["numInfos"] << " infos, "
              << issues["numHints"] << " hints\n"
              << test::describe_gltf_issues(report);
    EXPECT_EQ(issues["numErrors"].get<int>(), 0) << test::describe_gltf_issues(report);
    EXPECT_EQ(issues["numWarnings"].get<int>(), 0) << test::describe_gltf_issues(report);
}

/// `fn` must throw E with a one-line message and leave `file` as it was, with no temporary
/// file left beside it.
template <class E, class Fn>
void expect_refused_and_untouched(Fn fn, const std::string& file, const std::string& label)
{
    const std::vector<std::uint8_t> before = read_bytes(file);
    try {
        fn();
        ADD_FAILURE() << label << ": no exception";
    } catch (const E& e) {
        const std::string what = e.what();
        EXPECT_EQ(what.find('\n'), std::string::npos) << label << ": " << what;
        EXPECT_FALSE(what.empty()) << label;
    } catch (const std::exception& e) {
        ADD_FAILURE() << label << ": wrong exception: " << e.what();
    }
    EXPECT_EQ(read_bytes(file), before) << label;
    for (const auto& entry : fs::directory_iterator(fs::path(file).parent_path()))
        EXPECT_EQ(entry.path().string().find(".tmp"), std::string::npos) << label << ": " << entry.path();
}

TEST(ExportGltf, BadInputsGiveOneLineErrorsAndLeaveAnExistingFileUntouched)
{
    const std::string dir = test::temp_dir("export-bad");
    const std::string file = dir + "/tree.glb";
    const TreeGeometry good = test_tree();
    write_glb(file, scene_of(good));
    ASSERT_GT(fs::file_size(file), 1000u);

    ExportScene no_tree = scene_of(good);
    no_tree.tree = nullptr;
    expect_refused_and_untouched<InvalidInput>([&] { write_glb(file, no_tree); }, file, "null tree");

    TreeGeometry nan = test_tree();
    nan.lods[1].leaves.positions[3].y = std::numeric_limits<float>::quiet_NaN();
    expect_refused_and_untouched<InvalidInput>([&] { write_glb(file, scene_of(nan)); }, file, "NaN position");

    TreeGeometry bad_index = test_tree();
    bad_index.lods[0].branches.triangles[4][1] = std::uint32_t(bad_index.lods[0].branches.vertex_count());
    expect_refused_and_untouched<InvalidInput>([&] { write_glb(file, scene_of(bad_index)); }, file, "index out of range");

    // An unexported LOD is checked too: the height scale reads every LOD.
    ExportOptions lod0;
    lod0.lods = {0};
    expect_refused_and_untouched<InvalidInput>([&] { write_glb(file, scene_of(nan), lod0); }, file, "NaN in LOD1");

    ExportScene bad_lobe = scene_of(good, true);
    bad_lobe.lobes[1].triangles[0][2] = -1;
    ExportOptions with_lobes;
    with_lobes.include_lobes = true;
    expect_refused_and_untouched<InvalidInput>([&] { write_glb(file, bad_lobe, with_lobes); }, file, "lobe index");

    ExportOptions negative_height;
    negative_height.target_height_m = -2.0;
    expect_refused_and_untouched<InvalidInput>([&] { write_glb(file, scene_of(good), negative_height); }, file,
                                               "negative height");

    TreeGeometry short_normals = test_tree();
    short_normals.lods[2].branches.normals.pop_back();
    expect_refused_and_untouched<InvalidInput>([&] { write_glb(file, scene_of(short_normals)); }, file,
                                               "normals count");

    // An unwritable path: a folder that is a regular file.
    const std::string unwritable = file + "/inside.glb";
    try {
        write_glb(unwritable, scene_of(good));
        ADD_FAILURE() << "no exception for " << unwritable;
    } catch (const FileError& e) {
        const std::string what = e.what();
        EXPECT_EQ(what.rfind(unwritable + ": ", 0), 0u) << what;
        EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
    // The good file is still the good file.
    EXPECT_EQ(read_bytes(file), encode_glb(scene_of(good)));
}

// --- OBJ ----------------------------------------------------------------------------------

struct ObjSummary {
    std::vector<std::string> objects;
    std::map<std::string, std::string> material_of; ///< object → usemtl
    std::size_t v = 0, vt = 0, vn = 0, faces = 0, lines = 0;
    std::string mtllib;
    std::vector<glm::vec3> positions;
    bool indices_in_range = true;
    std::string first_bad;
};

ObjSummary parse_obj(const std::string& text)
{
    ObjSummary s;
    std::istringstream in(text);
    std::string line;
    struct Ref {
        long v, vt, vn;
    };
    std::vector<std::pair<std::string, std::vector<Ref>>> faces;
    while (std::getline(in, line)) {
        std::istringstream l(line);
        std::string key;
        l >> key;
        if (key == "o") {
            std::string name;
            l >> name;
            s.objects.push_back(name);
        } else if (key == "usemtl") {
            l >> s.material_of[s.objects.empty() ? "" : s.objects.back()];
        } else if (key == "mtllib") {
            l >> s.mtllib;
        } else if (key == "v") {
            glm::vec3 p;
            l >> p.x >> p.y >> p.z;
            s.positions.push_back(p);
            ++s.v;
        } else if (key == "vt") {
            ++s.vt;
        } else if (key == "vn") {
            ++s.vn;
        } else if (key == "f" || key == "l") {
            (key == "f" ? s.faces : s.lines)++;
            std::vector<Ref> refs;
            std::string tok;
            while (l >> tok) {
                Ref r{0, 0, 0};
                std::sscanf(tok.c_str(), "%ld/%ld/%ld", &r.v, &r.vt, &r.vn);
                refs.push_back(r);
            }
            faces.emplace_back(line, refs);
        }
    }
    for (const auto& [text_line, refs] : faces)
        for (const Ref& r : refs) {
            const bool ok = r.v >= 1 && std::size_t(r.v) <= s.v && r.vt >= 0 && std::size_t(r.vt) <= s.vt &&
                            r.vn >= 0 && std::size_t(r.vn) <= s.vn;
            if (!ok && s.indices_in_range) {
                s.indices_in_range = false;
                s.first_bad = text_line;
            }
        }
    return s;
}

TEST(ExportObj, WritesOneLodPerObjWithNamedObjectsAndFaceIndicesInRange)
{
    const TreeGeometry tree = test_tree();
    const std::string dir = test::temp_dir("export-obj");
    const std::vector<std::string> written = write_obj(dir + "/tree.obj", scene_of(tree));
    EXPECT_EQ(written, (std::vector<std::string>{dir + "/tree.obj", dir + "/tree.mtl", dir + "/tree_leaf.png",
                                                 dir + "/tree_LOD1.obj", dir + "/tree_LOD2.obj"}));
    const std::vector<std::vector<std::string>> expected = {
        {"tree_branches_LOD0", "tree_leaves_LOD0"}, {"tree_branches_LOD1", "tree_leaves_LOD1"}, {"tree_branches_LOD2"}};
    for (std::size_t lod = 0; lod < 3; ++lod) {
        const std::string file = dir + (lod == 0 ? "/tree.obj" : "/tree_LOD" + std::to_string(lod) + ".obj");
        const ObjSummary s = parse_obj(read_text(file));
        EXPECT_EQ(s.objects, expected[lod]) << file;
        for (const std::string& o : expected[lod])
            EXPECT_EQ(s.material_of.at(o), o.find("_leaves_") != std::string::npos ? "leaf" : "bark") << o;
        EXPECT_EQ(s.mtllib, "tree.mtl");
        const TreeLod& l = tree.lods[lod];
        EXPECT_EQ(s.v, l.branches.vertex_count() + l.leaves.vertex_count()) << file;
        EXPECT_EQ(s.vt, s.v);
        EXPECT_EQ(s.vn, s.v);
        EXPECT_EQ(s.faces, l.branches.triangle_count() + l.leaves.triangle_count()) << file;
        EXPECT_TRUE(s.indices_in_range) << s.first_bad;
        float min_y = 1e30f;
        for (const glm::vec3& p : s.positions) min_y = std::min(min_y, p.y);
        EXPECT_NEAR(min_y, 0.0f, 1e-6f) << "the trunk base is the origin";
    }
}

TEST(ExportObj, MtlDefinesBarkAndLeafAndReferencesTheLeafPngWhichExistsAndDecodes)
{
    const TreeGeometry tree = test_tree();
    const std::string dir = test::temp_dir("export-mtl");
    write_obj(dir + "/oak.obj", scene_of(tree));
    const std::string mtl = read_text(dir + "/oak.mtl");
    EXPECT_NE(mtl.find("newmtl bark\n"), std::string::npos) << mtl;
    EXPECT_NE(mtl.find("newmtl leaf\n"), std::string::npos) << mtl;
    // The leaf colour is baked into its texture (Kd white); the untextured bark keeps its Kd.
    EXPECT_NE(mtl.find("Kd 0.3 0.2 0.1\n"), std::string::npos) << mtl;
    EXPECT_EQ(mtl.find("Kd 0.25 0.5 0.15\n"), std::string::npos) << mtl;
    EXPECT_NE(mtl.find("Kd 1 1 1\n"), std::string::npos) << mtl;
    EXPECT_NE(mtl.find("map_Kd oak_leaf.png\n"), std::string::npos) << mtl;
    EXPECT_NE(mtl.find("map_d oak_leaf.png\n"), std::string::npos) << mtl;
    const std::string png_path = dir + "/oak_leaf.png";
    ASSERT_TRUE(fs::exists(png_path));
    const std::vector<std::uint8_t> png = read_bytes(png_path);
    tinygltf::Image img;
    std::string err, warn;
    ASSERT_TRUE(tinygltf::LoadImageData(&img, 0, &err, &warn, 0, 0, png.data(), int(png.size()), nullptr)) << err;
    EXPECT_EQ(img.width, 64);
    EXPECT_EQ(img.height, 64);
    EXPECT_EQ(img.image, tinted_texture(tree.leaf_texture, tree.leaf_color).pixels);
    // Tinting is what a glTF viewer does with the factor: white (sRGB 255) becomes the colour
    // itself in sRGB, alpha is kept.
    RgbaImage white{1, 1, {255, 255, 255, 77}};
    const RgbaImage t = tinted_texture(white, {0.25f, 0.5f, 0.15f});
    EXPECT_EQ(t.pixels, (std::vector<std::uint8_t>{linear_to_srgb(0.25), linear_to_srgb(0.5), linear_to_srgb(0.15), 77}));
    EXPECT_EQ(linear_to_srgb(0.5), 188);
}

TEST(ExportObj, FlipsVForObjAndFollowsTheSameOriginHeightAndExtrasRules)
{
    const TreeGeometry tree = test_tree();
    ExportOptions options;
    options.target_height_m = 12.0;
    options.lods = {1};
    options.include_lobes = options.include_strokes = true;
    const ObjFiles files = encode_obj(scene_of(tree, true), options, "t.mtl", "t_leaf.png");
    const ObjSummary s = parse_obj(files.obj);
    EXPECT_EQ(s.objects, (std::vector<std::string>{"tree_branches_LOD1", "tree_leaves_LOD1", "lobe_1", "lobe_2",
                                                   "stroke_7", "stroke_9"}));
    EXPECT_EQ(s.material_of.at("lobe_1"), "lobe");
    EXPECT_EQ(s.material_of.at("stroke_9"), "stroke");
    EXPECT_EQ(s.lines, 2u);
    EXPECT_TRUE(s.indices_in_range) << s.first_bad;
    // Same vertices as the glb with the same options.
    const tinygltf::Model m = load_glb(encode_glb(scene_of(tree, true), options));
    const std::vector<glm::vec3> leaves = read_vec3(m, primitive_of(m, "tree_leaves_LOD1").attributes.at("POSITION"));
    const std::size_t first_leaf = tree.lods[1].branches.vertex_count();
    for (std::size_t i = 0; i < leaves.size(); ++i) ASSERT_EQ(s.positions[first_leaf + i], leaves[i]) << i;
    // The leaf quad's first corner has uv (0, 1) (bottom-left in image rows): vt 0 0 in OBJ.
    std::istringstream in(files.obj);
    std::string line;
    std::vector<std::string> vts;
    while (std::getline(in, line))
        if (line.rfind("vt ", 0) == 0) vts.push_back(line);
    ASSERT_GT(vts.size(), first_leaf + 3);
    EXPECT_EQ(vts[first_leaf], "vt 0 0");
    EXPECT_EQ(vts[first_leaf + 2], "vt 1 1");

    // Without leaves (LOD2) there is no leaf material and no PNG.
    options.lods = {2};
    const ObjFiles bare = encode_obj(scene_of(tree), options, "t.mtl", "t_leaf.png");
    EXPECT_EQ(bare.mtl.find("newmtl leaf"), std::string::npos);
    EXPECT_TRUE(bare.leaf_png.empty());
}

TEST(ExportObj, BadInputsGiveOneLineErrorsAndLeaveExistingFilesUntouched)
{
    const std::string dir = test::temp_dir("export-obj-bad");
    const TreeGeometry good = test_tree();
    write_obj(dir + "/tree.obj", scene_of(good));
    const std::vector<std::uint8_t> mtl_before = read_bytes(dir + "/tree.mtl");
    const std::vector<std::uint8_t> png_before = read_bytes(dir + "/tree_leaf.png");

    ExportScene no_tree = scene_of(good);
    no_tree.tree = nullptr;
    expect_refused_and_untouched<InvalidInput>([&] { write_obj(dir + "/tree.obj", no_tree); }, dir + "/tree.obj",
                                               "null tree");
    TreeGeometry nan = test_tree();
    nan.lods[0].branches.positions[0].x = std::numeric_limits<float>::infinity();
    expect_refused_and_untouched<InvalidInput>([&] { write_obj(dir + "/tree.obj", scene_of(nan)); },
                                               dir + "/tree.obj", "infinite position");
    TreeGeometry bad_index = test_tree();
    bad_index.lods[1].leaves.triangles[0][0] = 1000000;
    expect_refused_and_untouched<InvalidInput>([&] { write_obj(dir + "/tree.obj", scene_of(bad_index)); },
                                               dir + "/tree.obj", "index out of range");
    EXPECT_EQ(read_bytes(dir + "/tree.mtl"), mtl_before);
    EXPECT_EQ(read_bytes(dir + "/tree_leaf.png"), png_before);

    const std::string unwritable = dir + "/tree.obj/x.obj";
    try {
        write_obj(unwritable, scene_of(good));
        ADD_FAILURE() << "no exception for " << unwritable;
    } catch (const FileError& e) {
        const std::string what = e.what();
        EXPECT_EQ(what.find('\n'), std::string::npos) << what;
        EXPECT_NE(what.find(dir + "/tree.obj/"), std::string::npos) << "names the file: " << what;
    }
}

} // namespace
} // namespace lobe
