// Trees grown in the lobes of the shipped recordings (§5), the whole pipeline from hand
// frames: one connected tree rooted at the trunk base, tips at the lobe surface, branches inside
// the lobes, radii from the pipe model, determinism, and lobes independent of each other.
#include <cmath>
#include <map>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include "app/export/tree_output.h"
#include "app/session/tree_pipeline.h"
#include "growth/leaves.h"
#include "growth/mesh_raycast.h"
#include "tests/support/replay_fixture.h"
#include "tests/support/test_data.h"
#include "tests/support/tree_checks.h"

namespace lobe {
namespace {

const char* const kTable1[] = {"table1-1lobe-5strokes", "table1-4lobes-22strokes", "table1-3lobes-16strokes"};

using Scene = test::ReplayedScene;
/// recordings/<name>.lrec replayed and its lobes built, once per process; null when the
/// recording is missing (the test has then failed with one line).
const Scene* scene(const std::string& name, const char* file = __builtin_FILE(), int line = __builtin_LINE())
{
    if (test::source_data("recordings/" + name + ".lrec", file, line).empty()) return nullptr;
    return &test::replayed_scene(name);
}

double outside_fraction(const BuiltTree& t)
{
    std::vector<MeshRaycaster> rays;
    for (const BuiltLobe& l : t.lobes) rays.emplace_back(l.mesh);
    double out = 0.0, total = 0.0;
    const TreeGraph& g = t.growth.tree;
    for (const TreeNode& n : g.nodes) {
        if (n.kind != TreeNodeKind::Grown) continue; // trunk and sketched skeleton excepted
        const glm::vec3 a = g.nodes[static_cast<std::size_t>(n.parent)].position;
        const glm::vec3 mid = 0.5f * (a + n.position);
        bool in = false;
        for (const MeshRaycaster& r : rays) in = in || r.inside(mid);
        const double len = glm::distance(a, n.position);
        total += len;
        if (!in) out += len;
    }
    return total > 0.0 ? out / total : 0.0;
}

class TreeOnRecording : public ::testing::TestWithParam<const char*> {};

TEST_P(TreeOnRecording, OneConnectedTreeRootedAtTheTrunkBaseFillingItsLobes)
{
    const Scene* found = scene(GetParam());
    if (!found) return;
    const Scene& s = *found;
    ASSERT_FALSE(s.lobes.empty());
    const BuiltTree t = grow_document_tree(s.doc, s.lobes);
    const TreeGraph& g = t.growth.tree;
    ASSERT_GT(g.size(), 500u);
    // Connected and rooted: every node but the root has an earlier parent.
    EXPECT_EQ(g.nodes[0].kind, TreeNodeKind::Root);
    EXPECT_EQ(g.nodes[0].parent, -1);
    float lowest_trunk = g.nodes[0].position.y;
    for (std::size_t i = 1; i < g.size(); ++i) {
        const TreeNode& n = g.nodes[i];
        ASSERT_GE(n.parent, 0) << i;
        ASSERT_LT(n.parent, static_cast<int>(i)) << i;
        ASSERT_TRUE(std::isfinite(n.position.x) && std::isfinite(n.position.y) && std::isfinite(n.position.z) &&
                    std::isfinite(n.radius));
        // Radii never increase from root to tip.
        ASSERT_LE(n.radius, g.nodes[static_cast<std::size_t>(n.parent)].radius);
        if (n.kind == TreeNodeKind::Skeleton) lowest_trunk = std::min(lowest_trunk, n.position.y);
    }
    // The root is the trunk base: the lowest point of the sketched trunk, on the ground.
    EXPECT_FLOAT_EQ(lowest_trunk, g.nodes[0].position.y);
    ASSERT_EQ(t.growth.lobes.size(), s.lobes.size());
    for (const LobeGrowthStats& l : t.growth.lobes) {
        EXPECT_FALSE(l.node_cap);
        EXPECT_FALSE(l.iteration_cap);
    }
    // Branch tips reach each lobe's surface (tree_checks_test.cpp checks every recording).
    for (const BuiltLobe& l : t.lobes) EXPECT_GE(test::tip_reach_share(g, {l.mesh}), 0.9) << GetParam();
    EXPECT_LE(outside_fraction(t), 0.02);
    for (const std::string& w : t.warnings) ADD_FAILURE() << w; // the shipped scenes grow cleanly
}

TEST_P(TreeOnRecording, SameSeedSameTreeAnotherSeedAnotherTree)
{
    const Scene* found = scene(GetParam());
    if (!found) return;
    const Scene& s = *found;
    Document doc = s.doc;
    const BuiltTree a = grow_document_tree(doc, s.lobes);
    const BuiltTree b = grow_document_tree(doc, s.lobes);
    doc.seed += 1;
    const BuiltTree c = grow_document_tree(doc, s.lobes);
    ASSERT_EQ(a.growth.tree.size(), b.growth.tree.size());
    for (std::size_t i = 0; i < a.growth.tree.size(); ++i)
        ASSERT_EQ(a.growth.tree.nodes[i].position, b.growth.tree.nodes[i].position);
    bool differs = a.growth.tree.size() != c.growth.tree.size();
    for (std::size_t i = 0; !differs && i < a.growth.tree.size(); ++i)
        differs = a.growth.tree.nodes[i].position != c.growth.tree.nodes[i].position;
    EXPECT_TRUE(differs);
}

INSTANTIATE_TEST_SUITE_P(Table1, TreeOnRecording, ::testing::ValuesIn(kTable1));

TEST(TreeOnRecording, MovingOneLobeOfTheFourLobeSceneLeavesTheOtherLobesBranchesBitIdentical)
{
    const Scene* found = scene("table1-4lobes-22strokes");
    if (!found) return;
    const Scene& s = *found;
    ASSERT_EQ(s.lobes.size(), 4u);
    const BuiltTree before = grow_document_tree(s.doc, s.lobes);
    // A recorded move of the third lobe by 4 cm, as the M tool stores it.
    Document doc = s.doc;
    const BuiltLobe& moved = s.lobes[2];
    glm::dvec3 centre(0.0);
    for (const glm::vec3& p : moved.mesh.positions) centre += glm::dvec3(p);
    centre /= static_cast<double>(moved.mesh.positions.size());
    EditOperation op;
    op.id = 1000;
    op.target = moved.lobe_id;
    op.path = {{centre, 100.0}, {centre + glm::dvec3(0.04, 0.0, 0.0), 101.0}};
    MoveLobeParams move;
    move.centre = centre;
    op.params = move;
    doc.edits.push_back(op);
    const BuiltTree after = build_document_tree(doc);
    ASSERT_EQ(after.lobes.size(), 4u);
    auto of_lobe = [](const BuiltTree& t, int lobe) {
        std::vector<TreeNode> out;
        for (const TreeNode& n : t.growth.tree.nodes)
            if (n.lobe == lobe) out.push_back(n);
        return out;
    };
    for (int l = 0; l < 4; ++l) {
        const auto a = of_lobe(before, l), b = of_lobe(after, l);
        if (l == 2) {
            ASSERT_FALSE(a.empty());
            ASSERT_FALSE(b.empty());
            EXPECT_TRUE(a.size() != b.size() || a.back().position != b.back().position); // the moved lobe regrew
            continue;
        }
        ASSERT_EQ(a.size(), b.size()) << "lobe " << l;
        for (std::size_t i = 0; i < a.size(); ++i) {
            ASSERT_EQ(a[i].position, b[i].position) << "lobe " << l << " node " << i;
            ASSERT_EQ(a[i].subtree_id, b[i].subtree_id);
        }
    }
}

TEST(TreeOnRecording, PerLobeSplitAngleOverridesTheTrees)
{
    const Scene* found = scene("table1-3lobes-16strokes");
    if (!found) return;
    const Scene& s = *found;
    Document doc = s.doc;
    const BuiltTree base = grow_document_tree(doc, s.lobes);
    doc.lobes.at(0).split_angle_deg = 12.0;
    const BuiltTree fine = grow_document_tree(doc, s.lobes);
    EXPECT_GT(fine.growth.lobes[0].subtrees, base.growth.lobes[0].subtrees);
    EXPECT_EQ(fine.growth.lobes[1].subtrees, base.growth.lobes[1].subtrees);
    EXPECT_EQ(fine.growth.lobes[2].subtrees, base.growth.lobes[2].subtrees);
}

TEST(TreeOnRecording, PerLobeSeedLeafSizeAndLeafCountChangeThatLobeOnly)
{
    const Scene* found = scene("table1-3lobes-16strokes");
    if (!found) return;
    const Scene& s = *found;
    Document doc = s.doc;
    const BuiltTree base = grow_document_tree(doc, s.lobes);
    doc.lobes.at(0).seed = 777;
    doc.lobes.at(0).leaf_length_m = 0.1;
    doc.lobes.at(0).leaves_per_node = 7;
    const BuiltTree own = grow_document_tree(doc, s.lobes);
    auto of_lobe = [](const BuiltTree& t, int lobe) {
        std::vector<TreeNode> out;
        for (const TreeNode& n : t.growth.tree.nodes)
            if (n.lobe == lobe) out.push_back(n);
        return out;
    };
    const auto a0 = of_lobe(base, 0), b0 = of_lobe(own, 0);
    ASSERT_FALSE(a0.empty());
    ASSERT_FALSE(b0.empty());
    EXPECT_TRUE(a0.size() != b0.size() || a0.back().position != b0.back().position) << "lobe 0 grows from its own seed";
    for (int l = 1; l < 3; ++l) {
        const auto a = of_lobe(base, l), b = of_lobe(own, l);
        ASSERT_EQ(a.size(), b.size()) << "lobe " << l;
        for (std::size_t i = 0; i < a.size(); ++i) ASSERT_EQ(a[i].position, b[i].position) << "lobe " << l;
    }
    // The leaves: lobe 0's are 10 cm long, seven per tip; the others' are the tree's.
    const LobeLeafOverrides leaves = document_lobe_leaves(doc, own);
    ASSERT_EQ(leaves.size(), 3u);
    const LeafCloud cloud = make_leaf_cloud(own.growth.tree, doc.settings.leaves, doc.seed, leaves);
    std::map<int, int> per_tip;
    for (const LeafCloud::Leaf& leaf : cloud.leaves) {
        const int lobe = own.growth.tree.nodes[static_cast<std::size_t>(leaf.node)].lobe;
        EXPECT_EQ(leaf.per_node, lobe == 0 ? 7 : doc.settings.leaves.per_node);
        EXPECT_DOUBLE_EQ(leaf.length_m, lobe == 0 ? 0.1 : doc.settings.leaves.length_m);
        ++per_tip[leaf.node];
    }
    for (const auto& [node, n] : per_tip)
        EXPECT_EQ(n, own.growth.tree.nodes[static_cast<std::size_t>(node)].lobe == 0 ? 7 : doc.settings.leaves.per_node);
    // What the exported geometry holds.
    const TreeGeometry geo = document_tree_geometry(doc, own);
    SurfaceGeometry lod0;
    emit_leaf_quads(cloud, {1.0}, lod0);
    EXPECT_EQ(geo.lods[0].leaves.positions, lod0.positions);
    // Without overrides the geometry is the tree-wide one, bit for bit.
    EXPECT_TRUE(document_lobe_leaves(s.doc, base).empty());
}

} // namespace
} // namespace lobe
