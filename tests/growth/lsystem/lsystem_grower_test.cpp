// The `lsystem` grower (growth/lsystem/lsystem_grower.h): its parameters, units and
// placement, radii and leaves from the model, and L-systems shaped by lobes.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <string>

#include <glm/geometric.hpp>

#include "core/errors.h"
#include "growth/grower.h"
#include "growth/lsystem/lsystem_grower.h"
#include "growth/mesh_raycast.h"
#include "input/truth_surface.h"
#include "tests/support/expect_throw.h"

using namespace lobe;

namespace {

using Params = std::map<std::string, GrowerParam>;

GrowerInput lsystem_input(Params params = {})
{
    GrowerInput in;
    in.choice.name = "lsystem";
    in.choice.params = std::move(params);
    in.seed = 3;
    return in;
}

GrowthLobe sphere_lobe(const glm::dvec3& centre, double radius, std::int64_t id = 1)
{
    TruthSurface s;
    s.center = centre;
    s.radii = {radius, radius, radius};
    GrowthLobe l;
    l.id = id;
    l.mesh = truth_surface_mesh(s, 3);
    return l;
}

double tree_height(const TreeGraph& g)
{
    double top = g.nodes[0].position.y;
    for (const TreeNode& n : g.nodes) top = std::max(top, static_cast<double>(n.position.y));
    return top - g.nodes[0].position.y;
}

/// Branch length of `g` (drawn segments: not into Detached nodes) outside `lobe`, and in
/// all, counting only what lies above `above_y`; sampled every millimetre or so.
std::pair<double, double> length_outside(const TreeGraph& g, const MeshRaycaster& lobe, double above_y)
{
    double outside = 0.0, total = 0.0;
    for (const TreeNode& n : g.nodes) {
        if (n.parent < 0 || n.kind == TreeNodeKind::Detached) continue;
        const glm::dvec3 a(g.nodes[static_cast<std::size_t>(n.parent)].position), b(n.position);
        const double len = glm::length(b - a);
        const int samples = std::max(1, static_cast<int>(len / 0.001));
        for (int k = 0; k < samples; ++k) {
            const glm::dvec3 p = a + (b - a) * ((k + 0.5) / samples);
            if (p.y <= above_y) continue;
            total += len / samples;
            if (!lobe.inside(glm::vec3(p))) outside += len / samples;
        }
    }
    return {outside, total};
}

/// A topiary in metres (ABOP §1.10's pruning, with a lobe for the box): an apex grows an
/// internode only when its end lies in the lobe, branching for its first six steps.
constexpr char kTopiary[] = R"(
#define S 0.04
Lsystem: 1
derivation length: 30
Axiom: !(0.02)A(0)?H(0,0,0)?P(0,0,0)
A(n) > ?H(u,v,w)?P(x,y,z) : inside(x+S*u, y+S*v, z+S*w) && n < 6 --> F(S)[+(40)/(90)A(n+1)?H(0,0,0)?P(0,0,0)]/(137.5)A(n+1)
A(n) > ?H(u,v,w)?P(x,y,z) : inside(x+S*u, y+S*v, z+S*w) && n >= 6 --> F(S)A(n)
A(n) > ?H(u,v,w)?P(x,y,z) : !inside(x+S*u, y+S*v, z+S*w) --> %
endlsystem
)";

} // namespace

TEST(LSystemGrower, IsListedWithItsOwnPanelCodeAndTitle)
{
    const Grower* g = find_grower("lsystem");
    ASSERT_NE(g, nullptr);
    EXPECT_EQ(g->title(), "L-system");
    EXPECT_EQ(g->panel_code(), lsystem::kGrowerPanelCode);
    EXPECT_NE(g->panel_code(), find_grower(kDefaultGrowerName)->panel_code());
    EXPECT_EQ(growers().front()->name(), kDefaultGrowerName);
    EXPECT_NE(grower_names().find("lsystem"), std::string::npos);
    EXPECT_EQ(lsystem::preset_names().front(), "default");
}

TEST(LSystemGrower, TheDefaultGrowsAFreeTreeOfTheStatedHeightWithItsWidthsAndLeaves)
{
    const GrowthResult r = lsystem_grower().grow(lsystem_input());
    ASSERT_GT(r.tree.size(), 100u);
    EXPECT_EQ(r.tree.nodes[0].kind, TreeNodeKind::Root);
    EXPECT_EQ(r.tree.nodes[0].position, glm::vec3(0.0f));
    EXPECT_NEAR(tree_height(r.tree), lsystem::kDefaultFreeHeightM, 1e-4);
    EXPECT_TRUE(r.radii_set);
    ASSERT_TRUE(r.leaves.has_value());
    EXPECT_GT(r.leaves->size(), 50u);
    for (const TreeNode& n : r.tree.nodes) EXPECT_GT(n.radius, 0.0f);
    EXPECT_TRUE(r.messages.empty()) << r.messages.front();
    // height_m sets the height; the same input grows the same tree.
    const GrowthResult tall = lsystem_grower().grow(lsystem_input({{"height_m", 5.0}}));
    EXPECT_NEAR(tree_height(tall.tree), 5.0, 1e-4);
    const GrowthResult again = lsystem_grower().grow(lsystem_input());
    ASSERT_EQ(again.tree.size(), r.tree.size());
    for (std::size_t i = 0; i < r.tree.size(); ++i) EXPECT_EQ(again.tree.nodes[i].position, r.tree.nodes[i].position);
}

TEST(LSystemGrower, SourceViewAndStepsComeFromTheParameters)
{
    const std::string source = "Lsystem: 1\nderivation length: 2\nAxiom: F(1)A\nA --> F(1)[+F(1)~l(2)]A\nendlsystem\n";
    GrowerInput in = lsystem_input({{"source", source}, {"source_name", std::string("tree.l")}});
    GrowthResult r = lsystem_grower().grow(in);
    EXPECT_EQ(r.tree.size(), 5u); // F(1)F(1) one segment to the first fork, two branch tips, the second fork
    EXPECT_FALSE(r.radii_set);    // no widths: the pipe model's radii
    ASSERT_EQ(r.leaves->size(), 2u);
    EXPECT_NEAR(r.leaves->front().length_m, 2 * in.settings.leaves.length_m, 1e-6); // ~ then l(2) from the engine
    in.choice.params["steps"] = std::int64_t{5};
    EXPECT_EQ(lsystem_grower().grow(in).leaves->size(), 5u);
    // The view file's angle: +(90) by default becomes the increment.
    in.choice.params["source"] = std::string("Lsystem: 1\nAxiom: F+F\nendlsystem\n");
    in.choice.params["view"] = std::string("angle increment: 90\nbogus line: 3\n");
    in.choice.params.erase("steps");
    r = lsystem_grower().grow(in);
    ASSERT_EQ(r.tree.size(), 3u);
    const glm::vec3 d = r.tree.nodes[2].position - r.tree.nodes[1].position;
    EXPECT_NEAR(d.y, 0.0f, 1e-5f);
    ASSERT_EQ(r.messages.size(), 1u); // the view line it does not read, naming the view file
    EXPECT_EQ(r.messages[0].rfind("tree.v:2", 0), 0u) << r.messages[0];
}

TEST(LSystemGrower, AMalformedSourceIsRefusedInOneLineNamingFileLineAndColumn)
{
    GrowerInput in = lsystem_input({{"source", std::string("Lsystem: 1\nAxiom: F[F\nendlsystem\n")},
                                    {"source_name", std::string("bad.l")}});
    const std::string what = test::expect_one_line_throw<InvalidInput>([&] { lsystem_grower().grow(in); });
    EXPECT_EQ(what.rfind("bad.l:2:", 0), 0u) << what;
}

TEST(LSystemGrower, ParametersAreCheckedNamingTheField)
{
    const Grower& g = lsystem_grower();
    auto refusal = [&](Params p, int version = 1) {
        GrowerChoice c;
        c.name = "lsystem";
        c.version = version;
        c.params = std::move(p);
        return test::invalid_input_message([&] { g.check_params(c, "trees[0].grower"); });
    };
    EXPECT_EQ(refusal({}), "");
    EXPECT_EQ(refusal({{"preset", std::string("default")}, {"steps", std::int64_t{4}}, {"height_m", std::int64_t{2}}}), "");
    EXPECT_NE(refusal({{"colour", true}}).find("trees[0].grower.params.colour: unknown parameter"), std::string::npos);
    EXPECT_NE(refusal({{"preset", std::string("oak")}}).find("no L-system preset \"oak\" (known: default"), std::string::npos);
    EXPECT_NE(refusal({{"steps", std::int64_t{-1}}}).find("params.steps"), std::string::npos);
    EXPECT_NE(refusal({{"steps", 2.5}}).find("params.steps"), std::string::npos);
    EXPECT_NE(refusal({{"height_m", 0.0}}).find("params.height_m"), std::string::npos);
    EXPECT_NE(refusal({{"source", true}}).find("params.source: expected a text"), std::string::npos);
    EXPECT_NE(refusal({{"source", std::string("x")}, {"preset", std::string("default")}}).find("not both"), std::string::npos);
    EXPECT_NE(refusal({}, 2).find("trees[0].grower.version"), std::string::npos);
}

TEST(LSystemGrower, AModelThatAsksWhereItIsStaysInsideItsLobe)
{
    // The trunk base is inside the lobe (a trunk stroke starts there): the whole tree is crown.
    GrowerInput in = lsystem_input({{"source", std::string(kTopiary)}});
    in.lobes.push_back(sphere_lobe({0.0, 1.2, 0.0}, 0.4));
    in.trunk_strokes = {{{0.0f, 0.9f, 0.0f}, {0.0f, 1.0f, 0.0f}}};
    const GrowthResult r = lsystem_grower().grow(in);
    ASSERT_GT(r.tree.size(), 100u);
    EXPECT_EQ(r.tree.nodes[0].position, glm::vec3(0.0f, 0.9f, 0.0f));
    const MeshRaycaster ray(in.lobes[0].mesh);
    const auto [outside, total] = length_outside(r.tree, ray, -1.0);
    EXPECT_GT(total, 3.0);
    EXPECT_LE(outside / total, 0.02) << outside << " of " << total << " m outside";
    // It reaches the lobe's surface: some node within 5 cm of its top.
    double top = 0.0;
    for (const TreeNode& n : r.tree.nodes) top = std::max(top, static_cast<double>(n.position.y));
    EXPECT_GT(top, 1.55);
    // Nodes in the lobe record it.
    ASSERT_EQ(r.lobes.size(), 1u);
    EXPECT_GT(r.lobes[0].nodes, r.tree.size() / 2);
}

TEST(LSystemGrower, TheDefaultRisesFromTheGroundAndFillsTheLobeAboveIt)
{
    GrowerInput in = lsystem_input();
    in.lobes.push_back(sphere_lobe({0.0, 1.3, 0.0}, 0.45));
    const GrowthResult r = lsystem_grower().grow(in);
    ASSERT_GT(r.tree.size(), 100u);
    EXPECT_LT(r.tree.nodes[0].position.y, 0.8f); // the default trunk's base, below the lobe
    const MeshRaycaster ray(in.lobes[0].mesh);
    const auto [outside, total] = length_outside(r.tree, ray, 1.3 - 0.45);
    EXPECT_GT(total, 3.0);
    EXPECT_LE(outside / total, 0.02) << outside << " of " << total << " m of the crown outside";
    // The leaves hang in the crown.
    std::size_t in_lobe = 0;
    for (const PlacedLeaf& l : *r.leaves) in_lobe += ray.inside(l.base);
    EXPECT_GT(in_lobe, r.leaves->size() * 9 / 10);
}

TEST(LSystemGrower, EveryLobeGetsItsOwnCrownWhereTheSketchedSkeletonEntersIt)
{
    // Two lobes apart and a third high above: the default trunk reaches into each (with limbs
    // where it misses one), and the model grows a crown from each entry, in that lobe alone.
    GrowerInput in = lsystem_input({{"source", std::string(kTopiary)}});
    in.lobes.push_back(sphere_lobe({0.6, 1.0, 0.0}, 0.3, 1));
    in.lobes.push_back(sphere_lobe({-0.6, 1.1, 0.1}, 0.3, 2));
    in.lobes.push_back(sphere_lobe({0.0, 1.9, 0.0}, 0.3, 3));
    const GrowthResult r = lsystem_grower().grow(in);
    ASSERT_EQ(r.lobes.size(), 3u);
    ASSERT_GT(r.skeleton_nodes, 1u);
    for (std::size_t i = 0; i < 3; ++i) {
        EXPECT_GT(r.lobes[i].nodes, 20u) << "lobe " << i;
        // The crown hangs from the skeleton: its first node's parent is a skeleton node.
        TreeGraph crown;
        crown.nodes.push_back(r.tree.nodes[0]);
        std::size_t first = 0;
        for (std::size_t k = r.skeleton_nodes; k < r.tree.size(); ++k) {
            if (r.tree.nodes[k].lobe != static_cast<int>(i)) continue;
            if (first == 0) {
                first = k;
                EXPECT_LT(r.tree.nodes[k].parent, static_cast<int>(r.skeleton_nodes)) << "lobe " << i;
            }
            TreeNode n = r.tree.nodes[k];
            // Measured on its own: parents in this crown keep their place, its root stands for the entry.
            n.parent = n.parent < static_cast<int>(r.skeleton_nodes) ? 0 : n.parent;
            crown.nodes.push_back(n);
        }
        // Re-index the crown's parents (global → local).
        std::map<int, int> local;
        for (std::size_t k = r.skeleton_nodes, c = 1; k < r.tree.size(); ++k)
            if (r.tree.nodes[k].lobe == static_cast<int>(i)) local[static_cast<int>(k)] = static_cast<int>(c++);
        for (std::size_t c = 1; c < crown.nodes.size(); ++c)
            if (crown.nodes[c].parent != 0) crown.nodes[c].parent = local.at(crown.nodes[c].parent);
        crown.nodes[0].position = r.tree.nodes[static_cast<std::size_t>(r.tree.nodes[first].parent)].position;
        const MeshRaycaster ray(in.lobes[i].mesh);
        const auto [outside, total] = length_outside(crown, ray, -1.0);
        EXPECT_GT(total, 1.0) << "lobe " << i;
        EXPECT_LE(outside / total, 0.02) << "lobe " << i << ": " << outside << " of " << total << " m outside";
    }
}

TEST(LSystemGrower, AModelThatDoesNotAskIsScaledToReachTheTopOfTheLobes)
{
    GrowerInput in = lsystem_input({{"source", std::string("Lsystem: 1\nAxiom: F(3)[+F(2)]F(7)\nendlsystem\n")}});
    in.lobes.push_back(sphere_lobe({0.5, 1.5, 0.0}, 0.5));
    in.lobes.push_back(sphere_lobe({-0.5, 1.8, 0.0}, 0.4, 2));
    const GrowthResult r = lsystem_grower().grow(in);
    double top = 0.0;
    for (const TreeNode& n : r.tree.nodes) top = std::max(top, static_cast<double>(n.position.y));
    EXPECT_NEAR(top, 2.2, 0.01); // the highest lobe's top
}
