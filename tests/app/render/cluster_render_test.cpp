// `render --show clusters` (§5.2, Fig. 7b–c): the first growth iteration's attractor clusters
// and their pieces, each piece in its own colour.
#include <algorithm>
#include <array>
#include <filesystem>
#include <set>

#include <gtest/gtest.h>

#include "app/render/render_scene.h"
#include "core/errors.h"
#include "app/session/tree_pipeline.h"
#include "tests/support/cli_run.h"
#include "tests/support/replay_fixture.h"
#include "tests/support/test_data.h"
#include "tests/support/test_paths.h"

namespace lobe {
namespace {

TEST(ClusterRender, ShowListTakesClustersAndNamesItInItsMessage)
{
    EXPECT_TRUE(parse_show_list("tree,clusters").clusters);
    EXPECT_FALSE(parse_show_list("tree").clusters);
    try {
        parse_show_list("trees");
        FAIL();
    } catch (const InvalidInput& e) {
        EXPECT_NE(std::string(e.what()).find("clusters"), std::string::npos);
    }
}

TEST(ClusterRender, EveryFirstIterationAttractorIsDrawnInItsPiecesColour)
{
    if (test::source_data("recordings/table1-1lobe-5strokes.lrec").empty()) return;
    const test::ReplayedScene& s = test::replayed_scene("table1-1lobe-5strokes");
    const BuiltTree t = grow_document_tree(s.doc, s.lobes);
    const auto& clusters = t.growth.first_clusters;
    // Every attractor (but the few a skeleton node reached at once) is in one piece.
    ASSERT_LE(clusters.size(), s.lobes[0].mesh.positions.size());
    ASSERT_GE(clusters.size(), s.lobes[0].mesh.positions.size() * 98 / 100);
    std::set<int> nodes, pieces;
    for (const ClusteredAttractor& a : clusters) {
        nodes.insert(a.node);
        pieces.insert(a.piece);
    }
    EXPECT_GT(nodes.size(), 3u);            // several clusters (Fig. 7b)
    EXPECT_GT(pieces.size(), nodes.size()); // large ones split (Fig. 7c)
    RenderScene scene;
    add_cluster_items(scene, clusters, t.growth.tree);
    EXPECT_EQ(scene.items.size(), std::min<std::size_t>(12, pieces.size()));
    std::set<std::array<float, 3>> colours;
    std::size_t vertices = 0;
    for (const RenderItem& item : scene.items) {
        colours.insert({item.color[0], item.color[1], item.color[2]});
        vertices += item.geometry.positions.size();
    }
    EXPECT_EQ(colours.size(), scene.items.size());
    EXPECT_GE(vertices, 6 * clusters.size()); // an octahedron per attractor, and the tubes
}

TEST(ClusterRender, RenderShowClustersWritesAPicture)
{
    const std::string recording = test::source_data("recordings/table1-1lobe-5strokes.lrec");
    if (recording.empty()) return;
    const std::string out = test::temp_dir("render-clusters");
    const test::CliRun r =
        test::run_cli("render " + recording + " --out " + out + "/c.png --show tree,clusters --size 160x120");
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_TRUE(std::filesystem::exists(out + "/c.png"));
}

} // namespace
} // namespace lobe
