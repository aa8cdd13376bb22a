// A sketched tree as a parametric 2L-system (growth/lsystem/sketch.h, seed 000): the tree
// follows the sketch, the clean rules grow as the seed intends (the trunk every iteration, a
// branch every n sections, sub-branches at the same interval), successive branches diverge
// by the set angle, growth interpolates between iterations, and bad sketches are refused in
// one line.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "core/errors.h"
#include "growth/lsystem/lsystem.h"
#include "growth/lsystem/lsystem_grower.h"
#include "growth/lsystem/sketch.h"
#include "tests/support/expect_throw.h"

using namespace lobe;
using namespace lobe::lsystem;

namespace {

/// A bent five-section trunk (2.3 m) with one branch from node 2, as a person might sketch
/// the seed's Japanese maple: a low, wide, rising limb.
Sketch maple()
{
    Sketch s;
    s.trunk = {{0, 0, 0}, {0.02, 0.5, 0.01}, {-0.03, 1.0, 0.04}, {0.05, 1.45, 0.0}, {0.02, 1.9, -0.05}, {0.0, 2.3, 0.02}};
    s.branches.push_back({2, {{0.3, 1.25, 0.05}, {0.6, 1.4, 0.1}, {0.85, 1.6, 0.05}}});
    s.iterations = 5;
    return s;
}

double nearest(const TreeGraph& g, const glm::dvec3& p)
{
    double best = 1e9;
    for (const TreeNode& n : g.nodes) best = std::min(best, glm::length(glm::dvec3(n.position) - p));
    return best;
}

/// The derived word after `steps` steps of the rules.
Word word_after(const SketchRules& r, int steps)
{
    const LSystem sys = parse_lsystem(r.lsystem, "sketch.l");
    DeriveOptions o;
    o.steps = steps;
    return derive(sys, o);
}

/// Modules of `name` in `w`.
std::size_t count(const LSystem& sys, const Word& w, const std::string& name)
{
    const int id = sys.find_symbol(name);
    std::size_t n = 0;
    for (const Module& m : w.modules) n += m.symbol == id;
    return n;
}

/// The growth the seed describes, counted without the L-system: one trunk section per
/// iteration, a branch of each type at every n-th node (the largest n where several meet),
/// a branch with one section when it appears and then rate_num/rate_den more per iteration,
/// branching at every n-th of its own nodes. Sections per module name after `steps` steps.
std::map<char, std::size_t> reference_counts(const SketchRules& r, int steps)
{
    struct Axis {
        int type; // -1 trunk
        int sections;
        int acc;
    };
    std::vector<Axis> axes{{-1, 1, 0}};
    for (int s = 0; s < steps; ++s) {
        std::vector<Axis> born;
        for (Axis& a : axes) {
            if (a.type < 0) {
                const int node = a.sections; // the new section starts here
                int best = -1;
                for (std::size_t t = 0; t < r.branches.size(); ++t)
                    if (node % r.branches[t].interval == 0 && (best < 0 || r.branches[t].interval > r.branches[best].interval))
                        best = static_cast<int>(t);
                if (best >= 0) born.push_back({best, 1, 0});
                ++a.sections;
            } else {
                const SketchBranchRule& br = r.branches[static_cast<std::size_t>(a.type)];
                if (a.acc + br.rate_num >= br.rate_den) {
                    if (a.sections % br.interval == 0) born.push_back({a.type, 1, 0});
                    ++a.sections;
                    a.acc += br.rate_num - br.rate_den;
                } else {
                    a.acc += br.rate_num;
                }
            }
        }
        axes.insert(axes.end(), born.begin(), born.end());
    }
    std::map<char, std::size_t> out;
    for (const Axis& a : axes) out[a.type < 0 ? 'A' : r.branches[static_cast<std::size_t>(a.type)].section] += a.sections;
    return out;
}

} // namespace

TEST(LSystemSketch, TrunkNodesLieWithinACentimetreOfTheSketchedNodesAtEveryIteration)
{
    const Sketch s = maple();
    for (int it = 1; it <= s.trunk_sections(); ++it) {
        SketchRulesOptions o;
        o.growth = it;
        const SketchGrown g = grow_sketch(s, o);
        for (int k = 0; k <= it; ++k)
            EXPECT_LT(nearest(g.growth.tree, s.trunk[static_cast<std::size_t>(k)] - s.trunk[0]), 0.01)
                << "iteration " << it << ", trunk node " << k;
        // Not yet grown: the node after the tip.
        if (it < s.trunk_sections()) {
            EXPECT_GT(nearest(g.growth.tree, s.trunk[static_cast<std::size_t>(it + 1)] - s.trunk[0]), 0.05) << it;
        }
    }
}

TEST(LSystemSketch, TheFirstBranchHasItsSketchedNodesWhenTheTrunkHasItsOwn)
{
    const Sketch s = maple();
    const SketchGrown g = grow_sketch(s);
    for (const glm::dvec3& p : s.branches[0].points) EXPECT_LT(nearest(g.growth.tree, p - s.trunk[0]), 0.01);
    // Sections are Bézier curves through the nodes: the drawn points between two nodes leave
    // the straight chord where the sketch bends.
    const std::vector<glm::dvec3> curve = sketch_curve(s.trunk, kDefaultCurveSteps);
    ASSERT_EQ(curve.size(), static_cast<std::size_t>(s.trunk_sections() * kDefaultCurveSteps + 1));
    const glm::dvec3 mid = curve[kDefaultCurveSteps + kDefaultCurveSteps / 2];
    const glm::dvec3 chord = (s.trunk[1] + s.trunk[2]) * 0.5;
    EXPECT_GT(glm::length(mid - chord), 0.002);
    EXPECT_LT(nearest(g.growth.tree, mid - s.trunk[0]), 0.001);
}

TEST(LSystemSketch, TheTrunkGrowsEveryIterationAndBranchesEveryNSections)
{
    Sketch s = maple();
    const SketchRules r = sketch_rules(s);
    ASSERT_EQ(r.branches.size(), 1u);
    EXPECT_EQ(r.branches[0].interval, 2);
    const LSystem sys = parse_lsystem(r.lsystem, "sketch.l");
    for (int steps = 0; steps <= 9; ++steps) {
        const Word w = derive(sys, [&] { DeriveOptions o; o.steps = steps; return o; }());
        EXPECT_EQ(count(sys, w, "A"), static_cast<std::size_t>(steps + 1)) << steps;
        // Trunk nodes with a branch: the A after each `[` at depth 0.
        std::vector<int> nodes;
        int depth = 0;
        bool pending = false;
        for (const Module& m : w.modules) {
            const std::string_view name = sys.symbol_name(m.symbol);
            if (name == "[") {
                pending |= depth++ == 0;
            } else if (name == "]") {
                --depth;
            } else if (name == "A" && depth == 0 && pending) {
                nodes.push_back(static_cast<int>(w.params_of(m)[0]));
                pending = false;
            }
        }
        std::vector<int> expected;
        for (int node = 2; node <= steps; node += 2) expected.push_back(node);
        EXPECT_EQ(nodes, expected) << steps;
    }
}

TEST(LSystemSketch, ModuleCountsPerIterationMatchTheRulesIncludingSubBranches)
{
    Sketch s = maple();
    // A second branch type from node 3, short: it grows slower than one section an iteration.
    s.trunk.push_back({0.0, 2.7, 0.0});
    s.trunk.push_back({0.02, 3.1, 0.02});
    s.trunk.push_back({0.0, 3.5, 0.0});
    s.branches.push_back({3, {{-0.3, 1.6, -0.1}, {-0.5, 1.8, -0.2}}});
    const SketchRules r = sketch_rules(s);
    ASSERT_EQ(r.branches.size(), 2u);
    EXPECT_EQ(r.branches[0].rate_num * 1.0 / r.branches[0].rate_den, 0.4); // 2 more sections in 5 iterations
    EXPECT_EQ(r.branches[1].rate_num * 1.0 / r.branches[1].rate_den, 0.25); // 1 more in 4
    const LSystem sys = parse_lsystem(r.lsystem, "sketch.l");
    std::size_t sub_branches = 0;
    for (int steps = 0; steps <= 14; ++steps) {
        const Word w = word_after(r, steps);
        const std::map<char, std::size_t> ref = reference_counts(r, steps);
        for (const char c : {'A', 'C', 'D'}) {
            const auto it = ref.find(c);
            EXPECT_EQ(count(sys, w, std::string(1, c)), it == ref.end() ? 0u : it->second) << c << " after " << steps;
        }
        // Branch tips, one per branch: the branches on the trunk and their sub-branches.
        std::size_t on_trunk = 0;
        int depth = 0;
        for (const Module& m : w.modules) {
            const std::string_view name = sys.symbol_name(m.symbol);
            if (name == "[") on_trunk += depth++ == 0;
            else if (name == "]") --depth;
        }
        sub_branches = count(sys, w, "Q") + count(sys, w, "R") - on_trunk;
    }
    EXPECT_GT(sub_branches, 3u); // sub-branches (and theirs) grew off the branches
}

TEST(LSystemSketch, ConsecutiveBranchesDivergeByTheSetAngle)
{
    for (const double div : {137.5, 90.0, 180.0, 30.0}) {
        Sketch s;
        // Not collinear, so that every sketched node is a node of the tree.
        for (int k = 0; k <= 4; ++k) s.trunk.push_back({0.0, 0.4 * k, 0.0});
        s.branches.push_back({1, {{0.3, 0.5, 0.0}, {0.6, 0.65, 0.0}}});
        s.divergence_deg = div;
        SketchRulesOptions o;
        o.growth = 12;
        o.curve_steps = 1;
        const SketchGrown g = grow_sketch(s, o);
        const TreeGraph& t = g.growth.tree;
        // First nodes of branches off the trunk (on the Y axis), by height.
        std::vector<std::pair<double, double>> az; // (height, azimuth)
        for (const TreeNode& n : t.nodes) {
            if (n.parent < 0) continue;
            const glm::vec3 pp = t.nodes[static_cast<std::size_t>(n.parent)].position;
            if (std::hypot(pp.x, pp.z) > 1e-4 || std::hypot(n.position.x, n.position.z) < 1e-3) continue;
            az.emplace_back(pp.y, std::atan2(n.position.z - pp.z, n.position.x - pp.x) * 180.0 / M_PI);
        }
        std::sort(az.begin(), az.end());
        ASSERT_GE(az.size(), 10u) << div;
        for (std::size_t i = 1; i < az.size(); ++i) {
            double d = std::fmod(az[i].second - az[i - 1].second + 720.0, 360.0);
            const double err = std::min(std::fabs(d - div), std::fabs(360.0 - d - div));
            EXPECT_LT(err, 0.5) << "divergence " << div << ", branches " << i - 1 << " and " << i << ": " << d;
        }
    }
}

TEST(LSystemSketch, GrowthBetweenIterationsGrowsTheNewSectionsIn)
{
    const Sketch s = maple();
    auto height = [&](double growth) {
        SketchRulesOptions o;
        o.growth = growth;
        const SketchGrown g = grow_sketch(s, o);
        double top = 0;
        for (const TreeNode& n : g.growth.tree.nodes) top = std::max(top, static_cast<double>(n.position.y));
        return top;
    };
    const double h3 = height(3.0), h4 = height(4.0);
    EXPECT_NEAR(h3, 1.45, 0.01);
    EXPECT_NEAR(h4, 1.9, 0.01);
    double last = h3;
    for (const double g : {3.25, 3.5, 3.75}) {
        const double h = height(g);
        EXPECT_GT(h, last + 0.05) << g;
        EXPECT_LT(h, h4) << g;
        last = h;
    }
    EXPECT_NEAR(height(3.5), 1.45 + 0.5 * (1.9 - 1.45), 0.03); // the new section at half length, roughly upright
    EXPECT_EQ(sketch_rules(s, {3.5}).derivation_length, 3);
    EXPECT_EQ(sketch_rules(s, {4.0}).derivation_length, 3);
}

TEST(LSystemSketch, TheSketchFileIsReadStrictly)
{
    const std::string good = sketch_json(maple());
    const Sketch back = parse_sketch(good, "s.json");
    EXPECT_EQ(back.trunk, maple().trunk);
    EXPECT_EQ(back.branches[0].attach, 2);
    EXPECT_EQ(back.iterations, 5);
    EXPECT_EQ(parse_sketch(R"({"trunk": [[0,0,0],[0,1,0]]})", "s").divergence_deg, kDefaultDivergenceDeg);

    auto refuses = [](const std::string& text, const std::string& needle) {
        const std::string what = test::expect_one_line_throw<InvalidInput>([&] { parse_sketch(text, "s.json"); });
        EXPECT_NE(what.find(needle), std::string::npos) << what;
        EXPECT_EQ(what.rfind("s.json", 0), 0u) << what;
    };
    refuses(R"({"trunk": [[0,0,0]]})", "at least two");
    refuses(R"({"trunk": []})", "at least two");
    refuses(R"({"trunk": [[0,0,0],[0,1,0],[0,2,0]], "branches": [{"attach": 3, "points": [[1,1,0]]}]})", "does not exist");
    refuses(R"({"trunk": [[0,0,0],[0,1,0],[0,2,0]], "branches": [{"attach": -4, "points": [[1,1,0]]}]})", "does not exist");
    refuses(R"({"trunk": [[0,0,0],[0,1,0],[0,2,0]], "branches": [{"attach": 1, "points": [[0,1,0]]}]})", "zero-length");
    refuses(R"({"trunk": [[0,0,0],[0,0,0]]})", "zero-length");
    refuses(R"({"trunk": [[0,0,0],[0,NaN,0]]})", "not valid JSON");
    refuses(R"({"trunk": [[0,0,0],[0,1e400,0]]})", "");
    refuses(R"({"trunk": [[0,0,0],[0,1,0]], "iterations": 0})", "iterations");
    refuses(R"({"trunk": [[0,0,0],[0,1,0]], "divergence_deg": 400})", "divergence");
    refuses(R"({"trunk": [[0,0,0],[0,1,0]], "colour": 1})", "unknown key");
    refuses(R"({"trunk": [[0,0,0],[0,1]]})", "three numbers");
    refuses("[1,2]", "JSON object");
    std::string huge = R"({"trunk": [)";
    for (int i = 0; i < 5000; ++i) {
        if (i > 0) huge += ',';
        huge += "[0," + std::to_string(i) + ",0]";
    }
    refuses(huge + "]}", "more than 1000");
    // In memory too: a NaN from a live sketch is refused the same way.
    Sketch nan = maple();
    nan.trunk[3].y = std::nan("");
    EXPECT_NE(test::expect_one_line_throw<InvalidInput>([&] { sketch_rules(nan); }).find("not a finite number"), std::string::npos);
}

TEST(LSystemSketch, AViewFileMayFixTheMetresPerUnit)
{
    // `metres per unit:` (the rules' view) draws the model at that scale instead of fitting it
    // to a height; a bad value is refused in one line naming the file and line.
    EXPECT_EQ(parse_view("metres per unit: 0.5\n", "v.v").metres_per_unit, 0.5);
    EXPECT_EQ(parse_view("angle increment: 30\n", "v.v").metres_per_unit, 0.0);
    const std::string what = test::expect_one_line_throw<InvalidInput>([] { parse_view("metres per unit: 0\n", "v.v"); });
    EXPECT_NE(what.find("v.v:1:"), std::string::npos) << what;
    SketchRules r = sketch_rules(maple());
    const SketchGrown g = grow_sketch(maple());
    r.view = "metres per unit: 0.5\n";
    GrowerInput in;
    in.choice = sketch_grower_choice(r);
    const LSystemRun half = run_lsystem(in);
    ASSERT_EQ(half.growth.tree.size(), g.growth.tree.size());
    for (std::size_t i = 0; i < g.growth.tree.size(); ++i)
        EXPECT_LT(glm::length(half.growth.tree.nodes[i].position * 2.0f - g.growth.tree.nodes[i].position), 1e-5f) << i;
}
