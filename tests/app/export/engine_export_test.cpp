// What an engine gets from the exporters (app/export/export_gltf.h, app/export/billboard.h):
// the billboard level, meshoptimizer's orderings, quantized and meshopt-compressed .glb files
// that decode to the same tree, the bark normal map, checked by the Khronos validator.
#include <algorithm>
#include <array>
#include <cstring>
#include <set>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>
#include <meshoptimizer.h>
#include <nlohmann/json.hpp>

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wconversion"
#pragma GCC diagnostic ignored "-Wshadow"
#include <tiny_gltf.h>
#pragma GCC diagnostic pop

#include "app/export/billboard.h"
#include "app/export/export_gltf.h"
#include "app/export/export_scene.h"
#include "core/errors.h"
#include "growth/branch_geometry.h"
#include "tests/support/cli_run.h"
#include "tests/support/gltf_check.h"
#include "tests/support/test_paths.h"
#include "tests/support/tree_fixtures.h"

namespace lobe {
namespace {

const TreeGeometry& tree()
{
    static const TreeGeometry geometry = [] {
        BranchSettings b;
        return build_tree_geometry(test::binary_test_tree(), b, LeafSettings{}, 4, "broadleaf");
    }();
    return geometry;
}

ExportScene scene_named(const std::string& name)
{
    ExportScene s;
    s.name = name;
    s.tree = &tree();
    s.base = tree().lods[0].branches.positions.empty() ? glm::vec3(0.0f) : glm::vec3(0.0f);
    return s;
}

nlohmann::json json_of(const std::vector<std::uint8_t>& glb)
{
    std::uint32_t length = 0;
    std::memcpy(&length, glb.data() + 12, 4);
    return nlohmann::json::parse(std::string(glb.begin() + 20, glb.begin() + 20 + length));
}

const std::uint8_t* bin_of(const std::vector<std::uint8_t>& glb)
{
    std::uint32_t length = 0;
    std::memcpy(&length, glb.data() + 12, 4);
    return glb.data() + 20 + length + 8;
}

/// Writes `glb` to a temporary file and runs the validator on it.
nlohmann::json validate(const std::vector<std::uint8_t>& glb, const std::string& name)
{
    const std::string path = test::temp_dir("engine-export") + "/" + name + ".glb";
    FILE* f = std::fopen(path.c_str(), "wb");
    std::fwrite(glb.data(), 1, glb.size(), f);
    std::fclose(f);
    nlohmann::json report;
    EXPECT_TRUE(test::validate_gltf(path, report));
    return report;
}

/// Each triangle as its three corner positions, rotated to start at the smallest: the same
/// set whatever the vertex and triangle order.
std::multiset<std::array<float, 9>> triangle_set(const std::vector<glm::vec3>& p, const std::vector<std::uint32_t>& idx)
{
    std::multiset<std::array<float, 9>> out;
    for (std::size_t t = 0; t + 2 < idx.size(); t += 3) {
        std::array<std::array<float, 3>, 3> c;
        for (int k = 0; k < 3; ++k) c[std::size_t(k)] = {p[idx[t + std::size_t(k)]].x, p[idx[t + std::size_t(k)]].y, p[idx[t + std::size_t(k)]].z};
        const std::size_t first = std::size_t(std::min_element(c.begin(), c.end()) - c.begin());
        std::array<float, 9> key{};
        for (std::size_t k = 0; k < 3; ++k)
            for (std::size_t j = 0; j < 3; ++j) key[3 * k + j] = c[(first + k) % 3][j];
        out.insert(key);
    }
    return out;
}

std::vector<std::uint32_t> flat(const SurfaceGeometry& g)
{
    std::vector<std::uint32_t> out;
    for (const auto& t : g.triangles) out.insert(out.end(), t.begin(), t.end());
    return out;
}

TEST(EngineExport, BillboardIsTheLastLevelOfFourCrossedCardsWithTheTreeBakedInColourAndAlpha)
{
    ExportOptions options;
    options.billboard_size = 64;
    const std::vector<std::uint8_t> glb = encode_glb(scene_named("oak"), options);
    const nlohmann::json j = json_of(glb);
    std::vector<std::string> names;
    for (const auto& n : j["nodes"]) names.push_back(n.value("name", ""));
    EXPECT_NE(std::find(names.begin(), names.end(), "oak_billboard_LOD3"), names.end());
    EXPECT_NE(std::find(names.begin(), names.end(), "oak_branches_LOD0"), names.end());
    const nlohmann::json report = validate(glb, "billboard");
    EXPECT_EQ(report["issues"]["numErrors"], 0) << test::describe_gltf_issues(report);
    EXPECT_EQ(report["issues"]["numWarnings"], 0) << test::describe_gltf_issues(report);

    BillboardInput in;
    in.branches = &tree().lods[0].branches;
    in.leaves = &tree().lods[0].leaves;
    in.leaf_texture = &tree().leaf_texture;
    in.bark_texture = &tree().bark_texture;
    in.bark_color = tree().bark_color;
    in.leaf_color = tree().leaf_color;
    const Billboard b = bake_billboard(in, 128);
    EXPECT_EQ(b.cards.triangle_count(), 8u);
    EXPECT_EQ(b.texture.width, 128);
    // Every cell shows the tree: some texels covered, some clear, and the covered ones
    // mostly leaf green (green above red and blue).
    for (int cell = 0; cell < 4; ++cell) {
        std::size_t covered = 0, green = 0;
        for (int y = 0; y < 64; ++y)
            for (int x = 0; x < 64; ++x) {
                const std::uint8_t* p = &b.texture.pixels[(std::size_t((cell / 2) * 64 + y) * 128 + std::size_t((cell % 2) * 64 + x)) * 4];
                if (p[3] < 128) continue;
                ++covered;
                green += p[1] > p[0] && p[1] > p[2];
            }
        EXPECT_GT(covered, 64u * 64u / 50) << "cell " << cell;
        EXPECT_LT(covered, 64u * 64u / 2) << "cell " << cell; // a sparse test tree
        EXPECT_GT(green, covered / 3) << "cell " << cell;
    }
    // The cards span the tree: from its lowest to its highest point, within its width.
    float lo = 1e30f, hi = -1e30f, card_lo = 1e30f, card_hi = -1e30f;
    for (const glm::vec3& p : tree().lods[0].branches.positions) lo = std::min(lo, p.y), hi = std::max(hi, p.y);
    for (const glm::vec3& p : tree().lods[0].leaves.positions) lo = std::min(lo, p.y), hi = std::max(hi, p.y);
    for (const glm::vec3& p : b.cards.positions) card_lo = std::min(card_lo, p.y), card_hi = std::max(card_hi, p.y);
    EXPECT_FLOAT_EQ(card_lo, lo);
    EXPECT_FLOAT_EQ(card_hi, hi);
    EXPECT_EQ(bake_billboard(in, 128).texture.pixels, b.texture.pixels) << "deterministic";
    EXPECT_THROW(bake_billboard(in, 100), InvalidInput);
}

TEST(EngineExport, OptimizedMeshesHoldTheSameTrianglesInAnotherOrder)
{
    const ExportScene scene = scene_named("tree");
    ExportOptions plain, optimized;
    optimized.optimize = true;
    const PreparedExport a = prepare_export(scene, plain), b = prepare_export(scene, optimized);
    ASSERT_EQ(a.parts.size(), b.parts.size());
    bool reordered = false;
    for (std::size_t i = 0; i < a.parts.size(); ++i) {
        const SurfaceGeometry &ga = a.parts[i].geometry, &gb = b.parts[i].geometry;
        EXPECT_EQ(ga.vertex_count(), gb.vertex_count()) << a.parts[i].name;
        EXPECT_EQ(triangle_set(ga.positions, flat(ga)), triangle_set(gb.positions, flat(gb))) << a.parts[i].name;
        reordered = reordered || flat(ga) != flat(gb);
        // No more vertex shader runs per triangle (a 16-entry FIFO cache, meshoptimizer's measure)
        // than before, but for the 5 % the overdraw order of the opaque bark may cost.
        const auto before = meshopt_analyzeVertexCache(flat(ga).data(), ga.triangles.size() * 3, ga.vertex_count(), 16, 0, 0);
        const auto after = meshopt_analyzeVertexCache(flat(gb).data(), gb.triangles.size() * 3, gb.vertex_count(), 16, 0, 0);
        EXPECT_LE(after.acmr, before.acmr * 1.05f + 1e-6f) << a.parts[i].name;
    }
    EXPECT_TRUE(reordered);
}

/// Decodes one EXT_meshopt_compression view into `bytes` (its uncompressed length).
std::vector<unsigned char> decode_view(const nlohmann::json& j, const std::uint8_t* bin, int view)
{
    const nlohmann::json& v = j["bufferViews"][std::size_t(view)];
    const nlohmann::json& e = v["extensions"]["EXT_meshopt_compression"];
    const std::size_t count = e["count"], stride = e["byteStride"];
    std::vector<unsigned char> out(count * stride);
    const std::uint8_t* src = bin + std::size_t(e["byteOffset"]);
    const std::size_t length = e["byteLength"];
    if (e["mode"] == "ATTRIBUTES")
        EXPECT_EQ(meshopt_decodeVertexBuffer(out.data(), count, stride, src, length), 0);
    else
        EXPECT_EQ(meshopt_decodeIndexBuffer(out.data(), count, stride, src, length), 0);
    return out;
}

TEST(EngineExport, CompressedGlbDecodesToTheSameTreeWithinTheQuantizationStepWith16BitIndicesAndIsLessThanHalfTheSize)
{
    const ExportScene scene = scene_named("tree");
    ExportOptions plain, compressed, quantized;
    plain.optimize = true;
    compressed.optimize = compressed.compress = true;
    quantized.optimize = quantized.quantize = true;
    const std::vector<std::uint8_t> glb = encode_glb(scene, compressed), raw = encode_glb(scene, plain);
    EXPECT_LT(glb.size() * 2, raw.size());
    const nlohmann::json j = json_of(glb);
    EXPECT_EQ(j["extensionsRequired"], (nlohmann::json{"KHR_mesh_quantization", "EXT_meshopt_compression", "KHR_texture_transform"}));
    EXPECT_EQ(j["buffers"][1]["extensions"]["EXT_meshopt_compression"]["fallback"], true);
    const PreparedExport e = prepare_export(scene, plain);
    for (const ExportPart& part : e.parts) {
        const auto node = std::find_if(j["nodes"].begin(), j["nodes"].end(), [&](const nlohmann::json& n) { return n.value("name", "") == part.name; });
        ASSERT_NE(node, j["nodes"].end()) << part.name;
        const double step = (*node)["scale"][0];
        const glm::dvec3 offset((*node)["translation"][0], (*node)["translation"][1], (*node)["translation"][2]);
        // Every primitive decoded: its quantized positions within one step of the tree's, its
        // triangles (as quantized corner triples) those of the part, indices 16-bit.
        auto on_grid = [&](const glm::vec3& p) {
            return glm::dvec3(std::round((double(p.x) - offset.x) / step), std::round((double(p.y) - offset.y) / step),
                              std::round((double(p.z) - offset.z) / step));
        };
        std::vector<glm::vec3> expected_q;
        for (const glm::vec3& p : part.geometry.positions) expected_q.push_back(glm::vec3(on_grid(p)));
        const std::multiset<std::array<float, 9>> expected = triangle_set(expected_q, flat(part.geometry));
        std::multiset<std::array<float, 9>> got;
        for (const nlohmann::json& prim : j["meshes"][std::size_t((*node)["mesh"])]["primitives"]) {
            const nlohmann::json& pos = j["accessors"][std::size_t(prim["attributes"]["POSITION"])];
            EXPECT_EQ(pos["componentType"], 5123); // UNSIGNED_SHORT
            const std::vector<unsigned char> p = decode_view(j, bin_of(glb), pos["bufferView"]);
            std::vector<glm::vec3> positions(pos["count"].get<std::size_t>());
            for (std::size_t v = 0; v < positions.size(); ++v) {
                std::uint16_t q[4];
                std::memcpy(q, p.data() + 8 * v, 8);
                positions[v] = glm::vec3(q[0], q[1], q[2]);
            }
            const nlohmann::json& ind = j["accessors"][std::size_t(prim["indices"])];
            EXPECT_EQ(ind["componentType"], 5123) << part.name << ": 16-bit indices";
            const std::vector<unsigned char> raw_idx = decode_view(j, bin_of(glb), ind["bufferView"]);
            std::vector<std::uint32_t> idx(ind["count"].get<std::size_t>());
            for (std::size_t i = 0; i < idx.size(); ++i) {
                std::uint16_t v16 = 0;
                std::memcpy(&v16, raw_idx.data() + 2 * i, 2);
                idx[i] = v16;
            }
            // (The index codec keeps each triangle's winding but may start it at another corner:
            // triangle_set rotates each to its smallest corner.)
            const auto set = triangle_set(positions, idx);
            got.insert(set.begin(), set.end());
        }
        EXPECT_TRUE(got == expected) << part.name;
        for (std::size_t v = 0; v < part.geometry.vertex_count(); ++v)
            ASSERT_LE(glm::length(offset + step * glm::dvec3(expected_q[v]) - glm::dvec3(part.geometry.positions[v])), step);
    }
    nlohmann::json report = validate(glb, "compressed");
    EXPECT_EQ(report["issues"]["numErrors"], 0) << test::describe_gltf_issues(report);
    EXPECT_EQ(report["issues"]["numWarnings"], 0) << test::describe_gltf_issues(report);
    // The validator reads quantized files whole (it does not decode meshopt).
    report = validate(encode_glb(scene, quantized), "quantized");
    EXPECT_EQ(report["issues"]["numErrors"], 0) << test::describe_gltf_issues(report);
    EXPECT_EQ(report["issues"]["numWarnings"], 0) << test::describe_gltf_issues(report);
    EXPECT_EQ(report["issues"]["numInfos"], 0) << test::describe_gltf_issues(report);
    EXPECT_EQ(encode_glb(scene, compressed), glb) << "same input, same bytes";
}

TEST(EngineExport, AMeshOfMoreThan65535VerticesIsSplitIntoPrimitivesWith16BitIndices)
{
    static const TreeGeometry large = [] {
        return build_tree_geometry(test::large_test_tree(), BranchSettings{}, LeafSettings{}, 4, "broadleaf");
    }();
    ASSERT_GT(large.lods[0].branches.vertex_count(), 65535u);
    ExportScene scene;
    scene.name = "large";
    scene.tree = &large;
    ExportOptions options;
    options.lods = {0};
    const std::vector<std::uint8_t> glb = encode_glb(scene, options);
    const nlohmann::json j = json_of(glb);
    std::size_t triangles = 0, vertices = 0, primitives = 0;
    for (const nlohmann::json& mesh : j["meshes"]) {
        if (mesh["name"] != "large_branches_LOD0") continue;
        for (const nlohmann::json& prim : mesh["primitives"]) {
            ++primitives;
            const nlohmann::json& ind = j["accessors"][std::size_t(prim["indices"])];
            EXPECT_EQ(ind["componentType"], 5123);
            triangles += ind["count"].get<std::size_t>() / 3;
            const std::size_t count = j["accessors"][std::size_t(prim["attributes"]["POSITION"])]["count"];
            EXPECT_LE(count, 65535u);
            vertices += count;
        }
    }
    EXPECT_GE(primitives, 2u);
    EXPECT_EQ(triangles, large.lods[0].branches.triangle_count());
    EXPECT_GE(vertices, large.lods[0].branches.vertex_count()); // seams repeat a few vertices
    EXPECT_LT(vertices, large.lods[0].branches.vertex_count() * 11 / 10);
    const nlohmann::json report = validate(glb, "split");
    EXPECT_EQ(report["issues"]["numErrors"], 0) << test::describe_gltf_issues(report);
    EXPECT_EQ(report["issues"]["numWarnings"], 0) << test::describe_gltf_issues(report);
}

TEST(EngineExport, BarkNormalMapComesWithUnitTangentsAcrossTheBranches)
{
    ExportOptions options;
    options.bark_normal_map = true;
    const ExportScene scene = scene_named("tree");
    const PreparedExport e = prepare_export(scene, options);
    ASSERT_EQ(e.bark_normal_map.width, tree().bark_texture.width);
    for (const ExportPart& part : e.parts) {
        if (part.kind != ExportPart::Kind::Branches) {
            EXPECT_TRUE(part.tangents.empty());
            continue;
        }
        ASSERT_EQ(part.tangents.size(), part.geometry.vertex_count());
        for (std::size_t v = 0; v < part.tangents.size(); ++v) {
            const glm::vec3 t(part.tangents[v]);
            ASSERT_NEAR(glm::length(t), 1.0f, 1e-4f);
            ASSERT_NEAR(glm::dot(t, part.geometry.normals[v]), 0.0f, 1e-3f);
            ASSERT_EQ(std::abs(part.tangents[v].w), 1.0f);
        }
    }
    // A flat picture gives a flat normal map: (0, 0, 1) everywhere.
    RgbaImage grey{4, 4, std::vector<std::uint8_t>(64, 128)};
    const RgbaImage flat_map = normal_map_from_height(grey);
    for (std::size_t i = 0; i < 16; ++i) EXPECT_EQ((std::array<int, 3>{flat_map.pixels[4 * i], flat_map.pixels[4 * i + 1], flat_map.pixels[4 * i + 2]}), (std::array<int, 3>{128, 128, 255}));
    const std::vector<std::uint8_t> glb = encode_glb(scene, options);
    const nlohmann::json report = validate(glb, "normal-map");
    EXPECT_EQ(report["issues"]["numErrors"], 0) << test::describe_gltf_issues(report);
    EXPECT_EQ(report["issues"]["numWarnings"], 0) << test::describe_gltf_issues(report);
    EXPECT_EQ(report["issues"]["numInfos"], 0) << test::describe_gltf_issues(report);
}

TEST(EngineExport, BadBillboardAndTextureSizesAreABadCommandLine)
{
    const std::string dir = test::temp_dir("engine-export-cli");
    const std::string rec = test::source_path("recordings/table1-1lobe-5strokes.lrec");
    for (const char* bad : {"--billboard 100", "--billboard 8", "--billboard x", "--texture-size 0", "--texture-size 4096",
                            "--texture-size 3"}) {
        const test::CliRun r = test::run_cli("grow " + rec + " --out " + dir + "/x.glb " + bad);
        EXPECT_EQ(r.code, 2) << bad << ": " << r.out;
        EXPECT_EQ(r.out.rfind("lobesketch: error: ", 0), 0u) << r.out;
        EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << r.out;
    }
    EXPECT_FALSE(std::filesystem::exists(dir + "/x.glb"));
    const test::CliRun ok = test::run_cli("grow " + rec + " --out " + dir + "/oak.glb --texture-size 64 --billboard 32 --compress");
    ASSERT_EQ(ok.code, 0) << ok.out;
    const nlohmann::json report = [&] {
        nlohmann::json r;
        EXPECT_TRUE(test::validate_gltf(dir + "/oak.glb", r));
        return r;
    }();
    EXPECT_EQ(report["issues"]["numErrors"], 0) << test::describe_gltf_issues(report);
    // render reads plain exports only, and says so in one line.
    const test::CliRun render = test::run_cli("render " + dir + "/oak.glb --out " + dir + "/oak.png");
    EXPECT_EQ(render.code, 1) << render.out;
    EXPECT_EQ(render.out, "lobesketch: error: " + dir + "/oak.glb: written with --quantize or --compress "
                          "(KHR_mesh_quantization), which render does not read: export the tree again without them\n");
}

} // namespace
} // namespace lobe
