// The checks every shipped recording's tree and every reference mesh's tree must pass (issue
// #37, docs/growth.md "Checks"): branch tips reach the lobe surface (a tip within 4 cm of
// ≥ 90 % of lobe vertices), ≤ 2 % of grown branch length outside the lobes, radii that never
// increase from the root and keep a leader at ≥ 98 % of branchings (thickest child ≥ half the
// node's radius), and growth that ends by the stop rule (§5.2) rather than attractor removal.
#include <cstdio>

#include <gtest/gtest.h>

#include "app/session/tree_pipeline.h"
#include "tests/support/replay_fixture.h"
#include "tests/support/test_data.h"
#include "tests/support/tree_checks.h"

namespace lobe {
namespace {

void check_tree(const std::string& what, const BuiltTree& t)
{
    std::vector<TriangleMesh> meshes;
    for (const BuiltLobe& l : t.lobes) meshes.push_back(l.mesh);
    const TreeGraph& g = t.growth.tree;
    const double reach = test::tip_reach_share(g, meshes);
    const double outside = test::outside_share(g, meshes);
    const double leader = test::leader_share(g);
    std::size_t attractors = 0, reached = 0, stopped = 0;
    for (const LobeGrowthStats& l : t.growth.lobes) {
        attractors += l.attractors;
        reached += l.reached;
        stopped += l.stopped;
    }
    const double stop_share = attractors ? static_cast<double>(stopped) / static_cast<double>(attractors) : 0.0;
    const double reach_share = attractors ? static_cast<double>(reached) / static_cast<double>(attractors) : 0.0;
    std::printf("[checks] %-28s nodes %7zu  tips-within-4cm %.3f  outside %.4f  leader %.4f  stopped %.3f  "
                "removed %.3f\n",
                what.c_str(), g.size(), reach, outside, leader, stop_share, reach_share);
    ::testing::Test::RecordProperty(what + ".tip_reach", std::to_string(reach));
    EXPECT_GE(reach, 0.9) << what;
    EXPECT_LE(outside, 0.02) << what;
    EXPECT_GE(leader, 0.98) << what;
    EXPECT_TRUE(test::radii_non_increasing(g)) << what;
    EXPECT_GT(stop_share, reach_share) << what << ": growth must end by the stop rule, not by removal";
}

class ChecksOnRecording : public ::testing::TestWithParam<const char*> {};

TEST_P(ChecksOnRecording, TipsReachTheSurfaceBranchesStayInsideRadiiTaperWithALeader)
{
    const std::string name = GetParam();
    if (test::source_data("recordings/" + name + ".lrec").empty()) return;
    const test::ReplayedScene& s = test::replayed_scene(name);
    ASSERT_FALSE(s.lobes.empty());
    check_tree(name, grow_document_tree(s.doc, s.lobes));
}

INSTANTIATE_TEST_SUITE_P(Shipped, ChecksOnRecording,
                         ::testing::Values("demo", "edit-stroke-transform", "pinch-edit", "table1-1lobe-5strokes",
                                           "table1-4lobes-22strokes", "table1-3lobes-16strokes"));

class ChecksOnModel : public ::testing::TestWithParam<const char*> {};

TEST_P(ChecksOnModel, TipsReachTheSurfaceBranchesStayInsideRadiiTaperWithALeader)
{
    const std::string model = test::shared_data(std::string("data/models/") + GetParam() + ".obj");
    if (model.empty()) return;
    Document doc;
    const BuiltLobe lobe = model_lobe(model, doc.settings);
    doc.lobes.push_back(LobeRecord::of_strokes(1));
    check_tree(GetParam(), grow_document_tree(doc, {lobe}));
}

INSTANTIATE_TEST_SUITE_P(Fig14, ChecksOnModel, ::testing::Values("stanford-bunny", "cow", "nefertiti", "spot"));

} // namespace
} // namespace lobe
