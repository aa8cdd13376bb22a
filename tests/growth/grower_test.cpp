// The growers behind one interface (growth/grower.h).
#include <set>

#include <gtest/gtest.h>

#include "core/errors.h"
#include "growth/grower.h"
#include "growth/subtree_library.h"
#include "input/truth_surface.h"

namespace lobe {
namespace {

GrowerInput two_lobes_and_a_trunk()
{
    GrowerInput in;
    TruthSurface a, b;
    a.center = {-0.25, 1.4, 0};
    a.radii = {0.15, 0.12, 0.15};
    b.center = {0.25, 1.45, 0.05};
    b.radii = {0.14, 0.13, 0.14};
    int id = 1;
    for (const TruthSurface& s : {a, b}) {
        GrowthLobe l;
        l.id = id++;
        l.mesh = truth_surface_mesh(s, 3);
        in.lobes.push_back(std::move(l));
    }
    in.trunk_strokes = {{{0.0f, 0.0f, 0.0f}, {0.0f, 0.5f, 0.0f}, {0.0f, 1.0f, 0.0f}}};
    in.seed = 7;
    return in;
}

TEST(Growers, TheDefaultIsListedFirstAndNamesAndPanelCodesAreUnique)
{
    ASSERT_FALSE(growers().empty());
    EXPECT_EQ(growers().front()->name(), kDefaultGrowerName);
    std::set<std::string_view> names;
    std::set<int> codes;
    for (const Grower* g : growers()) {
        EXPECT_TRUE(names.insert(g->name()).second) << g->name();
        EXPECT_TRUE(codes.insert(g->panel_code()).second) << g->name();
        EXPECT_GE(g->version(), 1);
        EXPECT_FALSE(g->title().empty());
        EXPECT_EQ(find_grower(g->name()), g);
    }
    EXPECT_EQ(find_grower("no-such-grower"), nullptr);
}

TEST(Growers, TheSubtreeGrowerGrowsExactlyWhatTheSection5GrowthGrows)
{
    const GrowerInput in = two_lobes_and_a_trunk();
    const GrowthResult via = checked_grower(in.choice, "grower").grow(in);
    const GrowthResult direct =
        grow_tree(in.trunk_strokes, in.lobes, in.settings.growth, default_subtree_library(), in.seed);
    ASSERT_GT(via.tree.size(), via.skeleton_nodes + 100);
    ASSERT_EQ(via.tree.size(), direct.tree.size());
    for (std::size_t i = 0; i < via.tree.size(); ++i) {
        EXPECT_EQ(via.tree.nodes[i].position, direct.tree.nodes[i].position) << i;
        EXPECT_EQ(via.tree.nodes[i].parent, direct.tree.nodes[i].parent) << i;
    }
    EXPECT_EQ(via.lobes.size(), 2u);
}

TEST(Growers, AnUnknownGrowerIsRefusedNamingTheFieldAndTheKnownGrowers)
{
    GrowerChoice c;
    c.name = "l-sistem";
    try {
        checked_grower(c, "trees[0].grower");
        FAIL() << "an unknown grower was accepted";
    } catch (const InvalidInput& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find("trees[0].grower.name: unknown grower \"l-sistem\""), std::string::npos) << m;
        EXPECT_NE(m.find(kDefaultGrowerName), std::string::npos) << m;
    }
}

TEST(Growers, TheSubtreeGrowerRefusesParametersAndANewerVersion)
{
    GrowerChoice c;
    c.params["split_angle_deg"] = 20.0;
    EXPECT_THROW(
        {
            try {
                checked_grower(c, "trees[0].grower");
            } catch (const InvalidInput& e) {
                EXPECT_NE(std::string(e.what()).find("trees[0].grower.params.split_angle_deg"), std::string::npos);
                throw;
            }
        },
        InvalidInput);
    GrowerChoice newer;
    newer.version = 2;
    EXPECT_THROW(checked_grower(newer, "g"), InvalidInput);
    EXPECT_NO_THROW(checked_grower(GrowerChoice{}, "g"));
}

} // namespace
} // namespace lobe
