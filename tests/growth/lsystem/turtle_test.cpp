// The L-system turtle (growth/lsystem/turtle.h): what each symbol does to the turtle, widths
// as radii, tropism, moves without drawing, leaves, queries; and the tree it draws through
// the branch geometry.
#include <gtest/gtest.h>

#include <cctype>
#include <cmath>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "core/errors.h"
#include "growth/branch_geometry.h"
#include "growth/lsystem/turtle.h"
#include "tests/support/expect_throw.h"

using namespace lobe;
using namespace lobe::lsystem;

namespace {

/// A word written as cpfg prints it ("F(1)+(90)[~l(2)]?P(0,0,0)"), read without the engine:
/// one-character symbols, or `@`, `?` or `~` followed by letters; numbers in parentheses.
struct HandWord {
    std::vector<std::string> names;
    Word word;

    SymbolId id(const std::string& name)
    {
        for (std::size_t i = 0; i < names.size(); ++i)
            if (names[i] == name) return static_cast<SymbolId>(i);
        names.push_back(name);
        return static_cast<SymbolId>(names.size() - 1);
    }
    TurtleSymbols symbols() const
    {
        std::vector<std::string_view> views(names.begin(), names.end());
        return TurtleSymbols(views);
    }
};

HandWord hand_word(const std::string& text)
{
    HandWord h;
    std::size_t i = 0;
    while (i < text.size()) {
        std::string name(1, text[i++]);
        if ((name == "@" || name == "?" || name == "~") && i < text.size() && std::isalpha(static_cast<unsigned char>(text[i]))) {
            while (i < text.size() && std::isalpha(static_cast<unsigned char>(text[i]))) name += text[i++];
            if (name.size() > 2 && name[0] == '~') { // `~l` is the surface's name, one letter
                i -= name.size() - 2;
                name.resize(2);
            }
        }
        Module m;
        m.symbol = h.id(name);
        m.first_param = static_cast<std::uint32_t>(h.word.params.size());
        if (i < text.size() && text[i] == '(') {
            ++i;
            while (text[i] != ')') {
                std::size_t used = 0;
                h.word.params.push_back(std::stod(text.substr(i), &used));
                i += used;
                if (text[i] == ',') ++i;
            }
            ++i;
        }
        m.param_count = static_cast<std::uint16_t>(h.word.params.size() - m.first_param);
        h.word.modules.push_back(m);
    }
    return h;
}

TurtleResult draw(const std::string& text, TurtleOptions options = {})
{
    const HandWord h = hand_word(text);
    return interpret(h.symbols(), h.word, options);
}

/// A view with `angle` as its increment and widths in model units.
ViewSettings view_deg(double angle)
{
    ViewSettings v;
    v.angle_increment_deg = angle;
    v.width_unit = ViewSettings::WidthUnit::Model;
    return v;
}

/// The parameters of the word's query modules after answer_queries, in order.
std::vector<double> queried(const std::string& text, const ViewSettings& view = {}, const Environment* env = nullptr)
{
    HandWord h = hand_word(text);
    answer_queries(h.symbols(), h.word, view, env);
    std::vector<double> out;
    for (const Module& m : h.word.modules)
        if (h.names[m.symbol][0] == '?')
            for (double v : h.word.params_of(m)) out.push_back(v);
    return out;
}

void expect_near(const glm::vec3& a, const glm::dvec3& b, double tol = 1e-5)
{
    EXPECT_NEAR(a.x, b.x, tol);
    EXPECT_NEAR(a.y, b.y, tol);
    EXPECT_NEAR(a.z, b.z, tol);
}

} // namespace

TEST(LSystemTurtle, StartsUpwardAndPlusTurnsLeftByTheAngleIncrement)
{
    TurtleOptions o;
    o.view = view_deg(90.0);
    const TurtleResult r = draw("F+F", o);
    ASSERT_EQ(r.tree.size(), 3u);
    expect_near(r.tree.nodes[0].position, {0, 0, 0});
    expect_near(r.tree.nodes[1].position, {0, 1, 0});
    expect_near(r.tree.nodes[2].position, {-1, 1, 0}); // left, seen from the front
    EXPECT_EQ(r.tree.nodes[0].kind, TreeNodeKind::Root);
    EXPECT_EQ(r.tree.nodes[2].parent, 1);
    EXPECT_EQ(r.segments, 2u);
    // A parameter overrides the angle increment and the unit step; - turns the other way.
    const TurtleResult p = draw("F(2)-(45)F(2)", o);
    expect_near(p.tree.nodes[2].position, {std::sqrt(2.0), 2.0 + std::sqrt(2.0), 0});
}

TEST(LSystemTurtle, PitchAndRollTurnAboutLeftAndHeading)
{
    TurtleOptions o;
    o.view = view_deg(90.0);
    // & pitches down: H turns towards −U = −Z; ^ towards +Z.
    expect_near(draw("F&F", o).tree.nodes[2].position, {0, 1, -1});
    expect_near(draw("F^F", o).tree.nodes[2].position, {0, 1, 1});
    // Rolling left by 90° brings U to where L was: a pitch down then goes towards +X.
    expect_near(draw("F\\&F", o).tree.nodes[2].position, {1, 1, 0});
    expect_near(draw("F/&F", o).tree.nodes[2].position, {-1, 1, 0});
}

TEST(LSystemTurtle, BracketsRestorePositionHeadingAndWidth)
{
    TurtleOptions o;
    o.view = view_deg(90.0);
    const TurtleResult r = draw("!(0.2)F[+!(0.1)F]F", o);
    ASSERT_EQ(r.tree.size(), 4u);
    expect_near(r.tree.nodes[2].position, {-1, 1, 0});
    expect_near(r.tree.nodes[3].position, {0, 2, 0}); // back at the fork, heading up again
    EXPECT_EQ(r.tree.nodes[2].parent, 1);
    EXPECT_EQ(r.tree.nodes[3].parent, 1);
    EXPECT_FLOAT_EQ(r.tree.nodes[2].radius, 0.05f);
    EXPECT_FLOAT_EQ(r.tree.nodes[3].radius, 0.1f); // the width before the branch
}

TEST(LSystemTurtle, BarTurnsAroundAndDollarLevelsTheLeftVector)
{
    const TurtleResult r = draw("F|F");
    expect_near(r.tree.nodes[2].position, {0, 0, 0});
    // After a pitch and a roll, $ rolls L back into the horizontal plane with U upward,
    // without changing H.
    const std::vector<double> q = queried("&(30)/(50)?H(0,0,0)?L(0,0,0)?U(0,0,0)$?H(0,0,0)?L(0,0,0)?U(0,0,0)");
    ASSERT_EQ(q.size(), 18u);
    const glm::dvec3 h0(q[0], q[1], q[2]), l0(q[3], q[4], q[5]);
    const glm::dvec3 h(q[9], q[10], q[11]), l(q[12], q[13], q[14]), u(q[15], q[16], q[17]);
    EXPECT_GT(std::abs(l0.y), 0.1); // the roll had tilted L
    EXPECT_NEAR(glm::length(h - h0), 0.0, 1e-12);
    EXPECT_NEAR(l.y, 0.0, 1e-12);
    EXPECT_GT(u.y, 0.0);
    EXPECT_NEAR(glm::length(glm::cross(h, l) - u), 0.0, 1e-12); // still H × L = U
    EXPECT_NEAR(glm::dot(h, l), 0.0, 1e-12);
    // @v does the same.
    const std::vector<double> v = queried("&(30)/(50)@v?L(0,0,0)");
    EXPECT_NEAR(v[1], 0.0, 1e-12);
}

TEST(LSystemTurtle, StraightStepsBecomeOneSegmentAndBranchesKeepTheirForks)
{
    const TurtleResult r = draw("FFF");
    ASSERT_EQ(r.tree.size(), 2u);
    expect_near(r.tree.nodes[1].position, {0, 3, 0});
    EXPECT_EQ(r.segments, 3u);
    // A branch between two steps keeps a node where it leaves; a new width starts a node too.
    EXPECT_EQ(draw("F[+F]F").tree.size(), 4u);
    EXPECT_EQ(draw("F!(0.5)F").tree.size(), 3u);
}

TEST(LSystemTurtle, WidthsBecomeRadiiInMetres)
{
    TurtleOptions o;
    o.metres_per_unit = 0.5;
    o.view.width_unit = ViewSettings::WidthUnit::Model;
    o.view.initial_line_width = 0.8;
    o.view.line_width_increment = 0.3;
    const TurtleResult r = draw("F!F#(0.4)F!(0.1)F#F", o);
    EXPECT_TRUE(r.widths_set);
    ASSERT_EQ(r.tree.size(), 6u);
    const float expected[] = {0.8f, 0.8f, 0.5f, 0.4f, 0.1f, 0.4f}; // widths at each node
    for (std::size_t i = 0; i < 6; ++i) EXPECT_NEAR(r.tree.nodes[i].radius, expected[i] / 2 * 0.5f, 1e-6f) << i;
    expect_near(r.tree.nodes[5].position, {0, 2.5, 0});
    // Widths never go below zero; a word without ! or # says so.
    EXPECT_FLOAT_EQ(draw("!(0.1)!!F").tree.nodes[1].radius, 0.0f);
    EXPECT_FALSE(draw("F+F").widths_set);
}

TEST(LSystemTurtle, PixelWidthsAreAShareOfTheDrawingsExtentWhateverItsScale)
{
    // cpfg's default: widths in pixels, the drawing kPixelsAcrossDrawing pixels across. A
    // trunk of !(10) in a drawing 4 units tall is 10/400 of 4 units across, at any scale.
    for (const double metres_per_unit : {0.01, 1.0, 30.0}) {
        TurtleOptions o;
        o.metres_per_unit = metres_per_unit;
        const TurtleResult r = draw("!(10)F(3)!(5)F", o);
        ASSERT_EQ(r.tree.size(), 3u);
        EXPECT_NEAR(r.tree.nodes[1].radius, 0.5 * 10 / kPixelsAcrossDrawing * 4 * metres_per_unit, 1e-6 * metres_per_unit);
        EXPECT_NEAR(r.tree.nodes[2].radius, 0.5 * 5 / kPixelsAcrossDrawing * 4 * metres_per_unit, 1e-6 * metres_per_unit);
    }
}

TEST(LSystemTurtle, TropismBendsTowardsTheTropismVectorAndMoreWithLargerElasticity)
{
    auto tip_after = [](double e) {
        TurtleOptions o;
        o.view.tropism = true;
        o.view.tropism_direction = {1.0, 0.0, 0.0};
        o.view.elasticity = e;
        const TurtleResult r = draw("FFFFFFFFFF", o);
        return glm::dvec3(r.tree.nodes.back().position);
    };
    const glm::dvec3 none = tip_after(0.0), some = tip_after(0.1), more = tip_after(0.3);
    EXPECT_NEAR(none.x, 0.0, 1e-9);
    EXPECT_NEAR(none.y, 10.0, 1e-5);
    EXPECT_GT(some.x, 0.5);       // towards T = +X
    EXPECT_GT(more.x, some.x + 1.0);
    EXPECT_NEAR(some.z, 0.0, 1e-9);
    // Each step turns H by e·|H × T| (ABOP §2.4): the second segment's direction after one bend.
    TurtleOptions o;
    o.view.tropism = true;
    o.view.tropism_direction = {1.0, 0.0, 0.0};
    o.view.elasticity = 0.2;
    const TurtleResult two = draw("F+(0)F", o); // +(0) keeps the two steps apart
    const glm::dvec3 d = glm::dvec3(two.tree.nodes[2].position - two.tree.nodes[1].position);
    EXPECT_NEAR(std::atan2(d.x, d.y), 0.2, 1e-6);
    // Elasticity is the turtle's: @Ts sets it inside a branch only.
    const std::vector<double> q = queried("[@Ts(0)F?H(0,0,0)]F?H(0,0,0)", o.view);
    EXPECT_NEAR(q[0], 0.0, 1e-12);
    EXPECT_NEAR(q[3], std::sin(0.2), 1e-12);
}

TEST(LSystemTurtle, MovesWithoutDrawingLeaveAGapTheGeometryDoesNotBridge)
{
    const TurtleResult r = draw("FfF");
    ASSERT_EQ(r.tree.size(), 4u);
    EXPECT_EQ(r.tree.nodes[2].kind, TreeNodeKind::Detached);
    EXPECT_EQ(r.tree.nodes[2].parent, 1);
    expect_near(r.tree.nodes[2].position, {0, 2, 0});
    expect_near(r.tree.nodes[3].position, {0, 3, 0});
    EXPECT_EQ(r.tree.nodes[3].parent, 2);
    EXPECT_EQ(r.segments, 2u);
    // Two branches: the second starts at the Detached node with no parent chain.
    TreeGraph g = r.tree;
    for (TreeNode& n : g.nodes) n.radius = 0.05f;
    const std::vector<BranchChain> chains = decompose_branch_chains(g);
    ASSERT_EQ(chains.size(), 2u);
    EXPECT_EQ(chains[1].nodes, (std::vector<int>{2, 3}));
    EXPECT_EQ(chains[1].parent_chain, -1);
    // No part of the bark lies in the gap between y = 1 (and the tip cone's radius) and y = 2.
    BranchSettings b;
    b.lod_count = 1;
    LeafSettings l;
    l.per_node = 0;
    const TreeGeometry geo = build_tree_geometry(g, b, l, 1);
    std::size_t below = 0, above = 0;
    for (const glm::vec3& p : geo.lods[0].branches.positions) {
        EXPECT_FALSE(p.y > 1.06f && p.y < 1.99f) << p.y;
        (p.y < 1.5f ? below : above)++;
    }
    EXPECT_GT(below, 0u);
    EXPECT_GT(above, 0u);
    // g moves as f does; moves in a row make one gap.
    EXPECT_EQ(draw("FgF").tree.nodes[2].kind, TreeNodeKind::Detached);
    EXPECT_EQ(draw("Ff(2)f(3)F").tree.size(), 4u);
    // A word that starts with a move roots the tree where drawing starts.
    const TurtleResult moved = draw("f(2)F");
    ASSERT_EQ(moved.tree.size(), 2u);
    expect_near(moved.tree.nodes[0].position, {0, 2, 0});
}

TEST(LSystemTurtle, SurfacesAndDiscsBecomeLeafCards)
{
    TurtleOptions o;
    o.view = view_deg(90.0);
    o.metres_per_unit = 0.1;
    o.surface_length_m = 0.08;
    o.surface_width_m = 0.05;
    const TurtleResult r = draw("F[+~l(2)]F@o(0.5)F@o", o);
    ASSERT_EQ(r.leaves.size(), 3u);
    const PlacedLeaf& s = r.leaves[0];
    expect_near(s.base, {0, 0.1, 0});
    expect_near(s.axis, {-1, 0, 0}); // along the turned heading
    EXPECT_NEAR(s.length_m, 0.16, 1e-6); // the surface size × its scale, not the model's unit
    EXPECT_NEAR(s.width_m, 0.10, 1e-6);
    EXPECT_NEAR(glm::dot(s.axis, s.across), 0.0, 1e-6);
    const PlacedLeaf& d = r.leaves[1]; // a disc of diameter 0.5 units, centred on the turtle
    EXPECT_NEAR(d.length_m, 0.05, 1e-6);
    EXPECT_NEAR(d.width_m, 0.05, 1e-6);
    expect_near(d.base + 0.5f * d.length_m * d.axis, {0, 0.2, 0});
    EXPECT_NEAR(r.leaves[2].length_m, 0.1, 1e-6); // no parameter: the width (1 unit)
    EXPECT_TRUE(r.messages.empty()) << r.messages[0]; // ~l is the leaf: no warning
    // Another surface name is drawn the same way, with one warning for all its uses.
    const TurtleResult other = draw("F~k~k(3)F~k");
    EXPECT_EQ(other.leaves.size(), 3u);
    ASSERT_EQ(other.messages.size(), 1u);
    EXPECT_NE(other.messages[0].find("~k"), std::string::npos);
    // The leaves become the tree's leaf quads, one each, at every LOD fewer.
    TreeGraph g = r.tree;
    BranchSettings b;
    b.lod_count = 3;
    const TreeGeometry geo = build_tree_geometry(g, b, LeafSettings{}, 4, {}, {}, &r.leaves);
    EXPECT_EQ(geo.lods[0].leaves.triangle_count(), 6u);
    EXPECT_LE(geo.lods[2].leaves.triangle_count(), 6u);
}

TEST(LSystemTurtle, QueriesAnswerPositionVectorsAndEnvironment)
{
    const std::vector<double> q = queried("F(2)+(90)F?P(0,0,0)[&(90)?H(0,0,0)]?U(0,0,0)?P(0,0)");
    ASSERT_EQ(q.size(), 11u);
    EXPECT_NEAR(q[0], -1.0, 1e-12);
    EXPECT_NEAR(q[1], 2.0, 1e-12);
    EXPECT_NEAR(q[2], 0.0, 1e-12);
    EXPECT_NEAR(q[3], 0.0, 1e-12); // pitched down: H = −U = −Z
    EXPECT_NEAR(q[5], -1.0, 1e-12);
    EXPECT_NEAR(q[8], 1.0, 1e-12); // U still +Z after the branch
    EXPECT_NEAR(q[9], -1.0, 1e-12); // fewer parameters: the first coordinates
    EXPECT_NEAR(q[10], 2.0, 1e-12);

    struct Below : Environment {
        bool inside(const glm::dvec3& p) const override { return p.y < 1.5; }
    } below;
    const std::vector<double> e = queried("F?E(5)F?E(5)", {}, &below);
    EXPECT_EQ(e, (std::vector<double>{1.0, 0.0}));
    EXPECT_EQ(queried("F?E(5)F?E(5)"), (std::vector<double>{1.0, 1.0})); // no environment: inside
}

TEST(LSystemTurtle, BadModulesAreSkippedWithOneMessageEach)
{
    TurtleResult r = draw("F]]F(nan)F@Gs@Gs{F.}");
    EXPECT_EQ(r.segments, 3u);
    ASSERT_EQ(r.messages.size(), 4u);
    std::string all;
    for (const std::string& m : r.messages) {
        EXPECT_EQ(m.find('\n'), std::string::npos);
        all += m + "\n";
    }
    EXPECT_NE(all.find("@Gs"), std::string::npos) << all;
    EXPECT_NE(all.find("polygons"), std::string::npos) << all;
    EXPECT_NE(all.find("2 ]"), std::string::npos) << all;
    EXPECT_NE(all.find("1 module"), std::string::npos) << all;
    // A step past the largest numbers stops the turtle, with what it drew so far kept.
    r = draw("FF(1e308)F(1e308)F");
    for (const TreeNode& n : r.tree.nodes) EXPECT_TRUE(std::isfinite(n.position.y));
    EXPECT_FALSE(r.messages.empty());
}

TEST(LSystemTurtle, NodeCapStopsTheTurtleAndDeepNestingIsRefused)
{
    TurtleOptions o;
    o.max_nodes = 10;
    const TurtleResult r = draw("F+F+F+F+F+F+F+F+F+F+F+F+F+F", o);
    EXPECT_LE(r.tree.size(), 10u);
    ASSERT_EQ(r.messages.size(), 1u);
    EXPECT_NE(r.messages[0].find("most it may have"), std::string::npos);

    HandWord h = hand_word("[");
    h.word.modules.assign(kMaxTurtleDepth + 1, h.word.modules[0]);
    const std::string what = test::expect_one_line_throw<InvalidInput>([&] { interpret(h.symbols(), h.word, {}); });
    EXPECT_NE(what.find("deeper"), std::string::npos) << what;
}

TEST(LSystemTurtle, FitsTheTreeToAHeightAroundItsOrigin)
{
    TurtleOptions o;
    o.origin = {1.0, 0.0, 2.0};
    o.fit_height_m = 3.0;
    o.view.width_unit = ViewSettings::WidthUnit::Model;
    o.view.initial_line_width = 0.2;
    const TurtleResult r = draw("F(10)[+F(5)~l]F(10)@o(1)", o);
    EXPECT_NEAR(r.metres_per_unit, 0.15, 1e-9);
    expect_near(r.tree.nodes[0].position, {1.0, 0.0, 2.0});
    EXPECT_NEAR(r.tree.nodes.back().position.y, 3.0, 1e-5);
    EXPECT_NEAR(r.tree.nodes[0].radius, 0.015, 1e-6);
    EXPECT_NEAR(r.leaves[0].length_m, 0.08, 1e-6);  // a surface keeps its size in metres
    EXPECT_NEAR(r.leaves[1].length_m, 0.15, 1e-6);  // a disc scales with the model
}
