// Species that differ in form and real scale (growth/species_form.h, growth/real_scale.h,
// docs/growth.md "Species form", docs/export.md "Size"), on the shipped pinch-edit sketch
// (one lobe, no trunk strokes: the default trunk) grown through the session pipeline.
#include <algorithm>
#include <cmath>
#include <map>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "app/export/tree_output.h"
#include "app/session/tree_pipeline.h"
#include "core/settings_table.h"
#include "growth/real_scale.h"
#include "growth/species.h"
#include "growth/species_form.h"
#include "tests/support/replay_fixture.h"
#include "tests/support/test_data.h"

namespace lobe {
namespace {

const char* const kSpecies[] = {"broadleaf", "conifer", "willow", "birch"};

/// The pinch-edit sketch's tree with `species`, at `height_m` (0: as sketched).
BuiltTree species_tree(const std::string& species, double height_m, Document* doc_out = nullptr)
{
    const test::ReplayedScene& scene = test::replayed_scene("pinch-edit");
    Document doc = scene.doc;
    apply_species(doc.settings, load_species(species));
    doc.settings.growth.height_m = height_m;
    BuiltTree tree = grow_document_tree(doc, scene.lobes);
    apply_real_scale(doc, tree);
    if (doc_out) *doc_out = doc;
    return tree;
}

/// Largest gap between the cumulative distributions of two sorted samples (Kolmogorov–Smirnov).
double ks_distance(const std::vector<double>& a, const std::vector<double>& b)
{
    double worst = 0.0;
    std::size_t i = 0, j = 0;
    while (i < a.size() && j < b.size()) {
        const double x = std::min(a[i], b[j]);
        while (i < a.size() && a[i] <= x) ++i;
        while (j < b.size() && b[j] <= x) ++j;
        worst = std::max(worst, std::abs(double(i) / double(a.size()) - double(j) / double(b.size())));
    }
    return worst;
}

TEST(SpeciesForm, TheDefaultSettingsAreTheBroadleafPreset)
{
    Settings s;
    apply_species(s, load_species("broadleaf"));
    for (const SettingInfo& info : settings_table())
        EXPECT_EQ(setting_text(s, info), setting_text(Settings{}, info)) << info.key;
    EXPECT_TRUE(settings_equal(s, Settings{}));
}

TEST(SpeciesForm, SpeciesSkeletonsDifferInBranchAngleAndDroop)
{
    if (test::source_data("recordings/pinch-edit.lrec").empty()) return;
    std::map<std::string, TreeFormStats> st;
    for (const char* sp : kSpecies) st[sp] = tree_form_stats(species_tree(sp, 0.0).growth.tree);
    const auto median_tip = [&](const char* sp) { return quantile(st[sp].tip_elevations_deg, 0.5); };
    // A broadleaf's shoots grow up and out; a conifer's laterals droop; a willow's twigs hang.
    EXPECT_LT(st["broadleaf"].drooping_tip_share, 0.35);
    EXPECT_GT(median_tip("broadleaf"), 15.0);
    EXPECT_GT(st["conifer"].drooping_tip_share, 0.6);
    EXPECT_LT(median_tip("conifer"), median_tip("broadleaf") - 25.0);
    EXPECT_GT(st["willow"].drooping_tip_share, 0.8);
    EXPECT_LT(median_tip("willow"), -40.0);
    EXPECT_LT(median_tip("willow"), median_tip("conifer") - 15.0);
    // Every two species differ measurably in their tip elevations, and the conifer's and
    // willow's branch angles differ from the broadleaf's.
    for (const char* a : kSpecies)
        for (const char* b : kSpecies)
            if (std::string(a) < b) {
                EXPECT_GT(ks_distance(st[a].tip_elevations_deg, st[b].tip_elevations_deg), 0.15) << a << " vs " << b;
            }
    EXPECT_GT(ks_distance(st["broadleaf"].branch_angles_deg, st["conifer"].branch_angles_deg), 0.1);
    EXPECT_GT(ks_distance(st["broadleaf"].branch_angles_deg, st["willow"].branch_angles_deg), 0.1);
}

TEST(SpeciesForm, AConiferHasALeaderThroughItsCrownWithWhorls)
{
    if (test::source_data("recordings/pinch-edit.lrec").empty()) return;
    std::map<std::string, double> top;
    std::map<std::string, int> whorls;
    std::map<std::string, double> tier_span; // height range of the whorls, over the tree's height
    for (const char* sp : {"broadleaf", "conifer"}) {
        const BuiltTree tree = species_tree(sp, 0.0);
        const TreeGraph& g = tree.growth.tree;
        const std::vector<std::vector<int>> children = tree_children(g);
        double skeleton_top = 0.0, lowest = 1e9, highest = -1e9;
        for (std::size_t i = 0; i < tree.growth.skeleton_nodes; ++i) {
            skeleton_top = std::max(skeleton_top, double(g.nodes[i].position.y - g.nodes[0].position.y));
            // A whorl: three or more laterals from one node of the trunk.
            int laterals = 0;
            for (int c : children[i]) laterals += g.nodes[std::size_t(c)].kind == TreeNodeKind::Grown;
            whorls[sp] += laterals >= 3;
            if (laterals >= 3) {
                lowest = std::min(lowest, double(g.nodes[i].position.y));
                highest = std::max(highest, double(g.nodes[i].position.y));
            }
        }
        top[sp] = skeleton_top / graph_height(g);
        tier_span[sp] = highest > lowest ? (highest - lowest) / graph_height(g) : 0.0;
    }
    EXPECT_GT(top["conifer"], 0.85) << "the conifer's trunk goes on up through the crown";
    EXPECT_LT(top["broadleaf"], top["conifer"] - 0.15) << "the broadleaf's trunk ends in the crown's lower part";
    EXPECT_GE(whorls["conifer"], 6);
    EXPECT_GT(tier_span["conifer"], 0.5) << "whorls in tiers all the way up the crown";
    EXPECT_GT(tier_span["conifer"], tier_span["broadleaf"] + 0.2);
}

TEST(RealScale, HeightScalesTheStructureButLeavesAndTwigsKeepTheirSize)
{
    if (test::source_data("recordings/pinch-edit.lrec").empty()) return;
    Document doc;
    const BuiltTree sketch = species_tree("broadleaf", 0.0);
    const BuiltTree tall = species_tree("broadleaf", 8.0, &doc);
    EXPECT_NEAR(graph_height(tall.growth.tree), 8.0, 1e-4);
    EXPECT_NEAR(tall.scale, 8.0 / graph_height(sketch.growth.tree), 1e-6);
    // Twigs keep the species' tip radius (millimetres); the trunk is 2–5 % of the height.
    float thinnest = 1.0f;
    for (const TreeNode& n : tall.growth.tree.nodes) thinnest = std::min(thinnest, n.radius);
    EXPECT_NEAR(thinnest, doc.settings.branches.tip_radius_m, 1e-6);
    const double dbh = tree_form_stats(tall.growth.tree).dbh_m;
    EXPECT_NEAR(dbh / 8.0, doc.settings.branches.dbh_ratio, 0.002);
    // Leaves keep their length in centimetres: LOD0 quads are length_m × width_m.
    const TreeGeometry geo = document_tree_geometry(doc, tall);
    const SurfaceGeometry& leaves = geo.lods[0].leaves;
    ASSERT_GE(leaves.positions.size(), 4u);
    for (std::size_t q = 0; q + 3 < leaves.positions.size() && q < 400; q += 4) {
        double longest = 0.0;
        for (int a = 0; a < 4; ++a)
            for (int b = a + 1; b < 4; ++b)
                longest = std::max(longest, double(glm::distance(leaves.positions[q + a], leaves.positions[q + b])));
        EXPECT_LT(longest, 1.01 * std::hypot(doc.settings.leaves.length_m, doc.settings.leaves.width_m));
    }
    // Leaf density: long shoots carry their leaves along them, so the tall tree has more leaves.
    const TreeGeometry small = document_tree_geometry(doc, sketch);
    EXPECT_GT(2 * leaves.triangle_count(), 3 * small.lods[0].leaves.triangle_count());
}

TEST(RealScale, EverySpeciesTrunkIsItsShareOfTheHeight)
{
    if (test::source_data("recordings/pinch-edit.lrec").empty()) return;
    for (const char* sp : kSpecies) {
        Document doc;
        const BuiltTree tree = species_tree(sp, 8.0, &doc);
        const double ratio = tree_form_stats(tree.growth.tree).dbh_m / 8.0;
        EXPECT_NEAR(ratio, doc.settings.branches.dbh_ratio, 0.002) << sp;
        EXPECT_GE(ratio, 0.015) << sp;
        EXPECT_LE(ratio, 0.05) << sp;
    }
}

} // namespace
} // namespace lobe
