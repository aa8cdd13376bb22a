// The tree as a user gets it: `replay`, `grow` and `export` from recordings, sessions and the
// reference meshes, the .glb checked by the Khronos validator, levels of detail within their
// triangle budgets, and bad options refused with one line.
#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>
#include <sys/wait.h>

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wconversion"
#pragma GCC diagnostic ignored "-Wshadow"
#include <tiny_gltf.h>
#pragma GCC diagnostic pop

#include "app/export/tree_output.h"
#include "app/session/tree_pipeline.h"
#include "app/live/regrow_worker.h"
#include "growth/mesh_raycast.h"
#include "tests/support/gltf_check.h"
#include "tests/support/replay_fixture.h"
#include "tests/support/cli_run.h"
#include "tests/support/test_data.h"
#include "tests/support/tree_checks.h"
#include "tests/support/test_paths.h"

namespace lobe {
namespace {

namespace fs = std::filesystem;

using test::CliRun;
using test::run_cli;

/// recordings/<name>.lrec; empty when it is missing (the test has then failed with one line).
std::string rec(const std::string& name, const char* file = __builtin_FILE(), int line = __builtin_LINE())
{
    return test::source_data("recordings/" + name + ".lrec", file, line);
}

tinygltf::Model load_glb(const std::string& path)
{
    tinygltf::TinyGLTF loader;
    tinygltf::Model model;
    std::string err, warn;
    EXPECT_TRUE(loader.LoadBinaryFromFile(&model, &err, &warn, path)) << err;
    return model;
}

// Min and max of the POSITION accessors of the meshes whose names end with `suffix`.
std::pair<glm::dvec3, glm::dvec3> bounds(const tinygltf::Model& m, const std::string& suffix)
{
    glm::dvec3 lo(1e30), hi(-1e30);
    for (const tinygltf::Mesh& mesh : m.meshes) {
        if (mesh.name.size() < suffix.size() || mesh.name.compare(mesh.name.size() - suffix.size(), suffix.size(), suffix))
            continue;
        for (const tinygltf::Primitive& p : mesh.primitives) {
            const tinygltf::Accessor& a = m.accessors[static_cast<std::size_t>(p.attributes.at("POSITION"))];
            for (int k = 0; k < 3; ++k) {
                lo[k] = std::min(lo[k], a.minValues[static_cast<std::size_t>(k)]);
                hi[k] = std::max(hi[k], a.maxValues[static_cast<std::size_t>(k)]);
            }
        }
    }
    return {lo, hi};
}

std::vector<std::string> node_names(const tinygltf::Model& m)
{
    std::vector<std::string> out;
    for (const tinygltf::Node& n : m.nodes) out.push_back(n.name);
    return out;
}

bool has(const std::vector<std::string>& v, const std::string& s) { return std::find(v.begin(), v.end(), s) != v.end(); }

TEST(TreeCli, ReplayWritesAValidatedGlbOfTheTreeWithThreeLodsAndItsOriginAtTheTrunkBase)
{
    const std::string recording = rec("table1-1lobe-5strokes");
    if (recording.empty()) return;
    const std::string out = test::temp_dir("tree-replay");
    const CliRun r = run_cli("replay " + recording + " --out " + out);
    ASSERT_EQ(r.code, 0) << r.out;
    const std::string glb = out + "/tree.glb";
    ASSERT_TRUE(fs::exists(glb));
    nlohmann::json report;
    ASSERT_TRUE(test::validate_gltf(glb, report));
    EXPECT_EQ(report["issues"]["numErrors"], 0) << test::describe_gltf_issues(report);
    EXPECT_EQ(report["issues"]["numWarnings"], 0) << test::describe_gltf_issues(report);
    EXPECT_EQ(report["issues"]["numInfos"], 0) << test::describe_gltf_issues(report); // bark UVs used by the bark texture
    const tinygltf::Model m = load_glb(glb);
    const auto names = node_names(m);
    for (int lod = 0; lod < 3; ++lod) {
        EXPECT_TRUE(has(names, "tree_branches_LOD" + std::to_string(lod)));
        EXPECT_TRUE(has(names, "tree_leaves_LOD" + std::to_string(lod)));
    }
    // The trunk base is the origin: the branches start at y = 0 and stand above it.
    const auto [lo, hi] = bounds(m, "branches_LOD0");
    EXPECT_NEAR(lo.y, 0.0, 0.01);
    EXPECT_GT(hi.y, 0.4); // the trunk rises from 0.98 m to the crown at about 1.54 m
    EXPECT_LT(hi.y, 0.7);
    EXPECT_LT(std::abs(lo.x + hi.x) / 2, 0.1); // centred on the trunk
}

TEST(TreeCli, GrowTakesSeedSplitAngleSpeciesLodAndHeightAndExportRewritesASession)
{
    const std::string recording = rec("table1-1lobe-5strokes");
    if (recording.empty()) return;
    const std::string out = test::temp_dir("tree-grow");
    const CliRun a = run_cli("grow " + recording + " --out " + out +
                             "/a.glb --species conifer --split-angle 20 --seed 3 --lod 0 --height 8");
    ASSERT_EQ(a.code, 0) << a.out;
    const tinygltf::Model m = load_glb(out + "/a.glb");
    const auto names = node_names(m);
    EXPECT_TRUE(has(names, "a_branches_LOD0")); // named by the output's stem
    EXPECT_FALSE(has(names, "a_branches_LOD1"));
    EXPECT_FALSE(has(names, "tree_branches_LOD0"));
    double top = -1e30;
    for (const char* part : {"branches_LOD0", "leaves_LOD0"}) top = std::max(top, bounds(m, part).second.y);
    EXPECT_NEAR(top, 8.0, 1e-3);
    nlohmann::json report;
    ASSERT_TRUE(test::validate_gltf(out + "/a.glb", report));
    EXPECT_EQ(report["issues"]["numErrors"], 0) << test::describe_gltf_issues(report);

    // The same tree from the session that replay wrote: grow and export agree byte for byte.
    ASSERT_EQ(run_cli("replay " + recording + " --out " + out + "/r").code, 0);
    // (Same file name, so the same node names: tree_branches_LOD0, …)
    fs::create_directories(out + "/b");
    fs::create_directories(out + "/c");
    ASSERT_EQ(run_cli("grow " + out + "/r/session.json --out " + out + "/b/tree.glb --skeleton-out " + out + "/b/tree.json").code, 0);
    ASSERT_EQ(run_cli("export " + out + "/r/session.json --out " + out + "/c/tree.glb").code, 0);
    auto bytes = [](const std::string& p) {
        std::ifstream in(p, std::ios::binary);
        return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    };
    EXPECT_EQ(bytes(out + "/b/tree.glb"), bytes(out + "/r/tree.glb"));
    EXPECT_EQ(bytes(out + "/c/tree.glb"), bytes(out + "/r/tree.glb"));
    // replay also writes the tree graph, as grow --skeleton-out does.
    EXPECT_FALSE(bytes(out + "/r/tree.json").empty());
    EXPECT_EQ(bytes(out + "/b/tree.json"), bytes(out + "/r/tree.json"));
    // Another seed, another tree.
    fs::create_directories(out + "/d");
    ASSERT_EQ(run_cli("export " + out + "/r/session.json --seed 2 --out " + out + "/d/tree.glb").code, 0);
    EXPECT_NE(bytes(out + "/d/tree.glb"), bytes(out + "/c/tree.glb"));
    // OBJ with its material file and leaf texture.
    const CliRun o = run_cli("export " + out + "/r/session.json --out " + out + "/t.obj --lobes --strokes");
    ASSERT_EQ(o.code, 0) << o.out;
    EXPECT_TRUE(fs::exists(out + "/t.obj"));
    EXPECT_TRUE(fs::exists(out + "/t.mtl"));
    EXPECT_TRUE(fs::exists(out + "/t_leaf.png"));
    EXPECT_TRUE(fs::exists(out + "/t_bark.png"));
    // One LOD per OBJ: LOD0 by default, the output line names every file written.
    EXPECT_FALSE(fs::exists(out + "/t_LOD1.obj"));
    EXPECT_NE(o.out.find("wrote " + out + "/t.obj (" + out + "/t.mtl, " + out + "/t_leaf.png, " + out + "/t_bark.png)"),
              std::string::npos) << o.out;
    const CliRun o2 = run_cli("export " + out + "/r/session.json --out " + out + "/u.obj --lod 0,2");
    ASSERT_EQ(o2.code, 0) << o2.out;
    EXPECT_TRUE(fs::exists(out + "/u_LOD2.obj"));
    EXPECT_FALSE(fs::exists(out + "/u_LOD1.obj"));
    EXPECT_NE(o2.out.find(out + "/u_LOD2.obj)"), std::string::npos) << o2.out;
}

TEST(TreeCli, BadGrowOptionsGiveOneLineAndExitCodes)
{
    const std::string r = rec("table1-1lobe-5strokes");
    if (r.empty()) return;
    const std::string out = test::temp_dir("tree-bad");
    struct Case {
        std::string args, expect;
        int code;
    };
    const Case cases[] = {
        {"grow " + r + " --out " + out + "/x.glb --species baobab", "unknown species 'baobab'", 2},
        {"grow " + r + " --out " + out + "/x.glb --lod 5", "--lod: LOD 5 does not exist", 1},
        {"grow " + r + " --out " + out + "/x.glb --lod 0,0", "given twice", 2},
        {"grow " + r + " --out " + out + "/x.fbx", "is written as .glb", 2},
        {"grow " + r + " --out " + out + "/x.glb --split-angle 2", "split-angle", 2},
        {"grow " + out + "/missing.json --out " + out + "/x.glb", "missing.json", 1},
    };
    for (const Case& c : cases) {
        const CliRun run = run_cli(c.args);
        EXPECT_EQ(run.code, c.code) << c.args << "\n" << run.out;
        EXPECT_NE(run.out.find(c.expect), std::string::npos) << c.args << "\n" << run.out;
    }
    EXPECT_FALSE(fs::exists(out + "/x.glb"));
    EXPECT_FALSE(fs::exists(out + "/x.fbx"));
}

TEST(TreeGeometryOfRecordings, LodsStayWithinTheirTriangleBudgetsOnEveryTable1Tree)
{
    for (const char* name : {"table1-1lobe-5strokes", "table1-4lobes-22strokes", "table1-3lobes-16strokes"}) {
        if (rec(name).empty()) return;
        const Document doc = test::replay_document(name);
        const BuiltTree tree = build_document_tree(doc);
        const TreeGeometry g = document_tree_geometry(doc, tree);
        ASSERT_EQ(g.lods.size(), 3u);
        const double t0 = static_cast<double>(lod_triangles(g.lods[0]));
        EXPECT_LE(static_cast<double>(lod_triangles(g.lods[1])), 0.5 * t0) << name;
        EXPECT_LE(static_cast<double>(lod_triangles(g.lods[2])), 0.15 * t0) << name;
        EXPECT_FALSE(g.lods[2].leaves.empty()) << name; // the leaf cloud stays
    }
}

class TreeInModel : public ::testing::TestWithParam<const char*> {};

TEST_P(TreeInModel, ReferenceMeshGrowsOneConnectedTreeFillingIt)
{
    const std::string model = test::shared_data(std::string("data/models/") + GetParam() + ".obj");
    if (model.empty()) return;
    Document doc;
    const BuiltLobe lobe = model_lobe(model, doc.settings);
    doc.lobes.push_back(LobeRecord::of_strokes(1));
    const BuiltTree t = grow_document_tree(doc, {lobe});
    const TreeGraph& g = t.growth.tree;
    ASSERT_GT(g.size(), 1000u);
    for (std::size_t i = 1; i < g.size(); ++i) {
        ASSERT_GE(g.nodes[i].parent, 0);
        ASSERT_LT(g.nodes[i].parent, static_cast<int>(i));
        ASSERT_LE(g.nodes[i].radius, g.nodes[static_cast<std::size_t>(g.nodes[i].parent)].radius);
        ASSERT_TRUE(std::isfinite(g.nodes[i].position.x + g.nodes[i].position.y + g.nodes[i].position.z));
    }
    EXPECT_NEAR(g.nodes[0].position.y, 0.0f, 1e-6f); // rooted at the ground below the model
    ASSERT_EQ(t.growth.lobes.size(), 1u);
    // The tree fills the model whatever the seed: branch tips within 4 cm of 90 % of its
    // vertices, judged over four seeds.
    std::vector<double> reach{test::tip_reach_share(g, {lobe.mesh})};
    for (std::uint64_t seed = 2; seed <= 4; ++seed) {
        Document other = doc;
        other.seed = seed;
        const BuiltTree u = grow_document_tree(other, {lobe});
        ASSERT_EQ(u.growth.lobes.size(), 1u);
        reach.push_back(test::tip_reach_share(u.growth.tree, {lobe.mesh}));
    }
    std::string shares;
    for (double c : reach) shares += std::to_string(c).substr(0, 5) + " ";
    RecordProperty("tip_reach", shares);
    for (double c : reach) EXPECT_GE(c, 0.9) << "shares of vertices with a tip within 4 cm, seeds 1–4: " << shares;
    const MeshRaycaster ray(lobe.mesh);
    double out = 0.0, total = 0.0;
    for (const TreeNode& n : g.nodes) {
        if (n.kind != TreeNodeKind::Grown) continue;
        const glm::vec3 a = g.nodes[static_cast<std::size_t>(n.parent)].position;
        const double len = glm::distance(a, n.position);
        total += len;
        if (!ray.inside(0.5f * (a + n.position))) out += len;
    }
    EXPECT_LE(out / total, 0.02);
}

INSTANTIATE_TEST_SUITE_P(Fig14, TreeInModel, ::testing::Values("stanford-bunny", "cow", "nefertiti", "spot"));

TEST(RegrowWorker, LatestSubmissionWinsAndMatchesAGrowthOnTheCallingThread)
{
    if (rec("table1-1lobe-5strokes").empty()) return;
    const Document doc = test::replay_document("table1-1lobe-5strokes");
    RegrowWorker worker;
    EXPECT_FALSE(worker.take().has_value());
    Document a = doc, b = doc, c = doc;
    b.seed = 2;
    c.seed = 3;
    worker.submit(a);
    worker.submit(b);
    const std::uint64_t last = worker.submit(c);
    EXPECT_EQ(last, 3u);
    const RegrowResult r = worker.wait_for(last);
    EXPECT_EQ(r.generation, last);
    EXPECT_TRUE(r.error.empty()) << r.error;
    const BuiltTree direct = build_document_tree(c);
    ASSERT_EQ(r.tree.growth.tree.size(), direct.growth.tree.size());
    for (std::size_t i = 0; i < direct.growth.tree.size(); ++i)
        ASSERT_EQ(r.tree.growth.tree.nodes[i].position, direct.growth.tree.nodes[i].position);
    EXPECT_FALSE(r.geometry.lods.empty());
    EXPECT_FALSE(worker.take().has_value()); // taken once
}

TEST(RegrowWorker, ADocumentThatCannotGrowGivesAnErrorLineNotACrash)
{
    Document doc;
    doc.settings.growth.subtree_weights = {{"no-such-subtree", 1.0}};
    Stroke s;
    s.id = 1;
    s.kind = StrokeKind::Trunk;
    s.points = {{{0, 1, 0}, 0.0}, {{0, 1.2f, 0}, 0.1}};
    doc.strokes.push_back(s);
    RegrowWorker worker;
    const RegrowResult r = worker.wait_for(worker.submit(doc));
    EXPECT_NE(r.error.find("no subtree named 'no-such-subtree'"), std::string::npos) << r.error;
}

} // namespace
} // namespace lobe
