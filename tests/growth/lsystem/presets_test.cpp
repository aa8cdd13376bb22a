// The L-system presets Lobesketch ships (growth/data/lsystems/, docs/lsystems.md): each one
// is compiled into the program, reads without warnings, derives a balanced word that draws,
// and exports a .glb that passes the Khronos glTF validator; the lobe filler keeps its
// branches inside a lobe.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "app/session/session_file.h"
#include "app/session/tree_pipeline.h"
#include "core/document.h"
#include "core/errors.h"
#include "growth/lsystem/lsystem.h"
#include "growth/lsystem/lsystem_grower.h"
#include "growth/lsystem/presets.h"
#include "growth/lsystem/turtle.h"
#include "tests/support/cli_run.h"
#include "tests/support/gltf_check.h"
#include "input/truth_surface.h"
#include "tests/support/test_paths.h"

using namespace lobe;
using namespace lobe::lsystem;
namespace fs = std::filesystem;

namespace {

const std::vector<std::string> kPresets = {
    "abop-monopodial", "abop-sympodial", "bush",           "default", "lobe-filler",
    "ordinary-tree",   "seaweed",        "stochastic-bush", "sympodial-tree", "willow",
};

/// How many modules named `name` the word holds.
std::size_t count(const LSystem& system, const Word& word, std::string_view name)
{
    const int id = system.find_symbol(name);
    if (id < 0) return 0;
    return static_cast<std::size_t>(std::count_if(word.modules.begin(), word.modules.end(),
                                                  [&](const Module& m) { return m.symbol == id; }));
}

/// A ball: the space a topiary model is given in the tests.
struct Ball final : Environment {
    glm::dvec3 centre{0.0, 0.8, 0.0};
    double radius = 0.3;
    bool inside(const glm::dvec3& p) const override { return glm::length(p - centre) <= radius; }
};

/// The drawn branch length of `tree` (metres), and how much of it lies where `inside`
/// says (each segment sampled at 20 points).
template <class Inside>
std::pair<double, double> length_inside(const TreeGraph& tree, const Inside& inside)
{
    double all = 0.0, in = 0.0;
    for (std::size_t i = 1; i < tree.size(); ++i) {
        const TreeNode& n = tree.nodes[i];
        if (n.kind == TreeNodeKind::Detached) continue; // a move: nothing drawn
        const glm::dvec3 a(tree.nodes[static_cast<std::size_t>(n.parent)].position), b(n.position);
        const double piece = glm::length(b - a) / 20.0;
        for (int k = 0; k < 20; ++k) {
            all += piece;
            if (inside(a + (b - a) * ((k + 0.5) / 20.0))) in += piece;
        }
    }
    return {all, in};
}

std::string read_file(const std::string& path)
{
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

} // namespace

TEST(LSystemPresets, TheProgramCarriesEveryPresetFileOfTheSourceTreeByItsStem)
{
    std::vector<std::string> names;
    for (const Preset& p : presets()) names.push_back(p.name);
    EXPECT_EQ(names, kPresets);
    // Each compiled-in preset is byte for byte the file in growth/data/lsystems/, its view
    // file included exactly when one is there.
    for (const Preset& p : presets()) {
        const std::string dir = test::source_path("growth/data/lsystems/");
        EXPECT_EQ(p.lsystem, read_file(dir + p.name + ".l")) << p.name;
        if (fs::exists(dir + p.name + ".v"))
            EXPECT_EQ(p.view, read_file(dir + p.name + ".v")) << p.name;
        else
            EXPECT_TRUE(p.view.empty()) << p.name;
    }
}

TEST(LSystemPresets, EveryPresetReadsWithoutWarningsAndDerivesABalancedWordThatDraws)
{
    for (const std::string& name : kPresets) {
        SCOPED_TRACE(name);
        const LSystemFile f = load_preset(name);
        EXPECT_TRUE(f.warnings.empty()) << f.warnings.front();
        EXPECT_GT(f.system.derivation_length(), 0);
        const Word w = derive(f.system);
        // Balanced: every ] closes an earlier [.
        const int open = f.system.find_symbol("["), close = f.system.find_symbol("]");
        long depth = 0;
        for (const Module& m : w.modules) {
            if (m.symbol == open) ++depth;
            if (m.symbol == close) {
                ASSERT_GT(depth, 0);
                --depth;
            }
        }
        EXPECT_EQ(depth, 0);
        EXPECT_GE(count(f.system, w, "F") + count(f.system, w, "G"), 20u); // a tree, not a twig
        EXPECT_LT(w.size(), 2'000'000u);                                   // and small enough to draw at once
    }
}

TEST(LSystemPresets, ThePresetsWithAViewFileSetTheirAnglesAndTropism)
{
    const LSystemFile seaweed = load_preset("seaweed");
    ASSERT_TRUE(seaweed.has_view);
    EXPECT_DOUBLE_EQ(seaweed.view.angle_increment_deg, 22.0);
    const LSystemFile bush = load_preset("bush");
    EXPECT_DOUBLE_EQ(bush.view.angle_increment_deg, 22.5);
    const LSystemFile willow = load_preset("willow");
    EXPECT_TRUE(willow.view.tropism);
    EXPECT_DOUBLE_EQ(willow.view.elasticity, 0.35);
    EXPECT_EQ(willow.view.tropism_direction.y, -1.0);
    EXPECT_FALSE(load_preset("abop-monopodial").has_view);
}

TEST(LSystemPresets, TheSeaweedDrawsItsThirdBranchWithGWhichNoProductionRewrites)
{
    const LSystemFile f = load_preset("seaweed");
    DeriveOptions one;
    one.steps = 1;
    EXPECT_EQ(to_string(f.system, derive(f.system, one)), "FF+[^F&F&F]-[&F^F^F]\\[&G&G^G]");
    // Each F becomes 8 F and 3 G; G's stay: after three steps 8³ = 512 F and
    // 3·(1 + 8 + 64) = 219 G.
    const Word w = derive(f.system);
    EXPECT_EQ(count(f.system, w, "F"), 512u);
    EXPECT_EQ(count(f.system, w, "G"), 219u);
    EXPECT_EQ(count(f.system, w, "f"), 0u);
}

TEST(LSystemPresets, TheWillowDependsOnTheSeedAndOnlyOnIt)
{
    const LSystemFile f = load_preset("willow");
    DeriveOptions a, b, c;
    a.seed = b.seed = 11;
    c.seed = 12;
    const std::string wa = to_string(f.system, derive(f.system, a));
    EXPECT_EQ(wa, to_string(f.system, derive(f.system, b)));
    EXPECT_NE(wa, to_string(f.system, derive(f.system, c)));
}

TEST(LSystemPresets, ANameIsReadAsAFileWhenOneExistsElseAsAPreset)
{
    const std::string dir = test::temp_dir("lsystem-presets-lookup");
    // A file of a preset's name in the working folder wins over the preset.
    const std::string own = dir + "/willow";
    std::ofstream(own) << "Lsystem: 1\nderivation length: 1\nAxiom: F\nF --> FF\nendlsystem\n";
    EXPECT_EQ(load_lsystem_or_preset(own).system.derivation_length(), 1);
    EXPECT_EQ(load_lsystem_or_preset("willow").system.derivation_length(), 12);
    try {
        load_lsystem_or_preset(dir + "/no-such-tree");
        FAIL() << "no error for a name that is neither a file nor a preset";
    } catch (const FileError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("no-such-tree"), std::string::npos) << what;
        EXPECT_NE(what.find("ordinary-tree"), std::string::npos) << what; // lists the presets
        EXPECT_EQ(what.find('\n'), std::string::npos);
    }
    EXPECT_THROW(load_preset("Willow"), InvalidInput);
}

TEST(LSystemPresets, TheLobeFillerPrunesWhatGrowsOutOfItsSpaceAndKeepsItsBranchesInside)
{
    const LSystemFile f = load_preset("lobe-filler");
    ASSERT_TRUE(f.system.has_queries());
    // The turtle starts at the origin, 0.5 m below a ball of radius 0.3 m: the trunk rises
    // into it, then the crown grows until the ball prunes it.
    const Ball ball;
    DeriveOptions o;
    o.environment = &ball;
    o.answer_queries = query_answerer(f.system, f.view, &ball);
    const Word in_ball = derive(f.system, o);
    TurtleOptions t;
    t.view = f.view;
    const TurtleResult r = interpret(f.system, in_ball, t);
    const auto [all, in] = length_inside(r.tree, [&](const glm::dvec3& p) { return ball.inside(p); });
    EXPECT_GT(all, 10.0);      // a crown, not a stick: metres of twigs
    EXPECT_GE(in / all, 0.95); // only the trunk below the ball (0.5 m) is outside
    // Of the crown (above the ball's lowest point) nothing is outside: a shoot leaving a
    // ball cannot point back into it, so every one that left was pruned.
    double crown_out = 0.0;
    for (std::size_t i = 1; i < r.tree.size(); ++i) {
        const glm::dvec3 p(r.tree.nodes[i].position);
        if (p.y > ball.centre.y - ball.radius && !ball.inside(p)) crown_out += 1.0;
    }
    EXPECT_EQ(crown_out, 0.0);
    EXPECT_GT(r.leaves.size(), 100u);
    // Without a space nothing is pruned: the same model grows well over twice as much (only
    // the axes' lengths bound it).
    DeriveOptions free;
    free.answer_queries = query_answerer(f.system, f.view);
    const TurtleResult unpruned = interpret(f.system, derive(f.system, free), t);
    EXPECT_GT(unpruned.segments, 2 * r.segments);
}

TEST(LSystemPresets, TheLobeFillerGrownInALobeKeeps98PercentOfItsBranchLengthInsideIt)
{
    // A session with one lobe, an ellipsoid 0.8 × 0.7 × 0.8 m, and the lsystem grower with
    // the lobe-filler preset; no trunk strokes, so the tree starts at the default trunk's
    // base below the lobe.
    Document doc;
    doc.seed = 5;
    TruthSurface s;
    s.center = {0.0, 1.3, 0.0};
    s.radii = {0.4, 0.35, 0.4};
    LobeRecord lobe = LobeRecord::of_strokes(1);
    lobe.model = std::make_shared<const LobeModel>(LobeModel{"ellipsoid.obj", truth_surface_mesh(s, 3)});
    doc.lobes.push_back(std::move(lobe));
    GrowerChoice choice;
    choice.name = "lsystem";
    choice.params["preset"] = std::string("lobe-filler");
    set_scene_grower(doc, choice);
    const BuiltTree tree = build_document_tree(doc);
    ASSERT_EQ(tree.lobes.size(), 1u);
    const lsystem::LobeEnvironment lobes(growth_lobes(doc, tree.lobes), glm::dvec3(0.0));
    const auto in_lobe = [&](const glm::dvec3& p) { return lobes.lobe_at(glm::vec3(p)) >= 0; };
    const TreeGraph& g = tree.growth.tree;
    const auto [all, in] = length_inside(g, in_lobe);
    // The trunk rises from the trunk base to the lobe outside it; of everything after the
    // trunk's first node in the lobe (the crown), at least 98 % lies in the lobe.
    std::size_t first_in = 0;
    while (first_in < g.size() && !in_lobe(glm::dvec3(g.nodes[first_in].position))) ++first_in;
    ASSERT_LT(first_in, g.size()) << "the trunk never reached the lobe";
    const glm::dvec3 entry(g.nodes[first_in].position);
    const double trunk = glm::length(entry - glm::dvec3(g.nodes[0].position));
    EXPECT_GT(all, 10.0) << "a crown, not a stick";
    EXPECT_GE(in / (all - trunk), 0.98) << "crown length " << all - trunk << " m, inside " << in << " m";
    EXPECT_GT(tree.growth.leaves ? tree.growth.leaves->size() : 0u, 100u);
}

TEST(LSystemPresets, EveryPresetExportsAGlbThatPassesTheGltfValidator)
{
    const std::string out = test::temp_dir("lsystem-presets-glb");
    for (const std::string& name : kPresets) {
        SCOPED_TRACE(name);
        const std::string glb = out + "/" + name + ".glb";
        const test::CliRun r = test::run_cli("lsystem " + test::source_path("growth/data/lsystems/" + name + ".l") +
                                             " --out " + glb);
        ASSERT_EQ(r.code, 0) << r.out;
        EXPECT_EQ(r.out.find("warning"), std::string::npos) << r.out; // the presets read without warnings
        nlohmann::json report;
        ASSERT_TRUE(test::validate_gltf(glb, report));
        EXPECT_EQ(report["issues"]["numErrors"], 0) << test::describe_gltf_issues(report);
        EXPECT_EQ(report["issues"]["numWarnings"], 0) << test::describe_gltf_issues(report);
    }
}
