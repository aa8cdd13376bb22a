// The live L-system sketch mode (app/live/lsystem_sketch_mode.h) driven by the shipped
// synthesized recordings (recordings/lsystem-sketch/): the seed's Japanese maple attempt (a
// trunk and a branch) and an editing session (drag, erase, branch, platform grab, divergence,
// growth) replay to the sketch and tree they made; bad edits are refused and change nothing;
// the input pipeline leaves the hands to the mode.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

#include <glm/geometric.hpp>

#include "app/live/lsystem_sketch_mode.h"
#include "growth/lsystem/sketch.h"
#include "growth/radii.h"
#include "input/pipeline.h"
#include "input/recording.h"
#include "input/synth.h"
#include "input/tools.h"
#include "tests/support/test_paths.h"

using namespace lobe;
using namespace lobe::lsystem;

namespace {

std::string read_all(const std::string& path)
{
    std::ifstream in(path, std::ios::binary);
    std::ostringstream os;
    os << in.rdbuf();
    return os.str();
}

std::string rec_path(const std::string& name) { return test::source_path("recordings/lsystem-sketch/" + name + ".lrec"); }

InputEvent key(int code, double t = 1e6)
{
    InputEvent e;
    e.time = t;
    e.kind = InputEventKind::Key;
    e.code = code;
    e.value = 1;
    return e;
}

void expect_same_tree(const TreeGraph& a, const TreeGraph& b)
{
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
        EXPECT_EQ(a.nodes[i].position, b.nodes[i].position) << i;
        EXPECT_EQ(a.nodes[i].parent, b.nodes[i].parent) << i;
        EXPECT_EQ(a.nodes[i].radius, b.nodes[i].radius) << i;
    }
}

} // namespace

TEST(LSystemSketchMode, TheMapleRecordingReplaysToItsTrunkBranchAndTree)
{
    const Recording rec = read_recording(rec_path("maple"));
    const LSystemSketchMode mode = replay_lsystem_sketch(rec);
    const Sketch& s = mode.sketch();
    const Sketch maple = parse_sketch(read_all(test::source_path("tests/data/sketches/maple.json")), "maple.json");
    // Pinched at the fingertip on a 1:10 platform: within a centimetre of the full-size nodes
    // meant (the synthesized hand's tracking noise and filter, a millimetre on the platform).
    ASSERT_EQ(s.trunk.size(), 6u);
    for (std::size_t i = 0; i < s.trunk.size(); ++i) EXPECT_LT(glm::length(s.trunk[i] - maple.trunk[i]), 0.01) << i;
    ASSERT_EQ(s.branches.size(), 1u);
    EXPECT_EQ(s.branches[0].attach, 2);
    ASSERT_EQ(s.branches[0].points.size(), 3u);
    for (std::size_t i = 0; i < 3; ++i) EXPECT_LT(glm::length(s.branches[0].points[i] - maple.branches[0].points[i]), 0.01) << i;
    EXPECT_EQ(mode.growth(), 7.0);                 // two iterations on from the sketch's five
    EXPECT_EQ(s.divergence_deg, 142.5);            // ] once
    // The tree beside the platform is the sketch's tree at that growth, moved there.
    SketchRulesOptions o;
    o.growth = 7;
    SketchGrown g = grow_sketch(s, o);
    assign_pipe_radii(g.growth.tree);
    TreeGraph expected = g.growth.tree;
    for (TreeNode& n : expected.nodes) n.position = glm::vec3(mode.tree_point(glm::dvec3(n.position)));
    expect_same_tree(mode.tree(), expected);
    // And replays to the same tree again.
    expect_same_tree(replay_lsystem_sketch(rec).tree(), mode.tree());
}

TEST(LSystemSketchMode, TheEditsRecordingDragsErasesBranchesAndMovesThePlatform)
{
    const LSystemSketchMode mode = replay_lsystem_sketch(read_recording(rec_path("edits")));
    const Sketch& s = mode.sketch();
    // Four pinched, node 3 dragged 2 cm (20 cm full size) along +X, node 4 erased, one more.
    ASSERT_EQ(s.trunk.size(), 5u);
    const glm::dvec3 expected[] = {{0, 0, 0}, {0, 0.5, 0}, {0.1, 1.0, 0}, {0.2, 1.5, 0}, {0.1, 2.0, 0}};
    for (std::size_t i = 0; i < 5; ++i) EXPECT_LT(glm::length(s.trunk[i] - expected[i]), 0.015) << i;
    ASSERT_EQ(s.branches.size(), 1u);
    EXPECT_EQ(s.branches[0].attach, 1);
    EXPECT_EQ(s.branches[0].points.size(), 2u);
    EXPECT_EQ(s.divergence_deg, 127.5);
    EXPECT_EQ(mode.growth(), 3.0); // one back from the trunk's four
    EXPECT_EQ(mode.drawing_from(), 0);
    // The platform moved with the left hand, the tree with it.
    EXPECT_LT(glm::length(mode.platform().position - glm::dvec3(-0.1, 1.0, -0.40)), 0.01);
    ASSERT_FALSE(mode.tree().empty());
    EXPECT_LT(glm::length(glm::dvec3(mode.tree().nodes[0].position) - mode.tree_point(glm::dvec3(0.0))), 1e-6);
}

TEST(LSystemSketchMode, ShippedRecordingsAreUpToDateWithTheirScenarios)
{
    for (const std::string name : {"maple", "edits"}) {
        SCOPED_TRACE(name);
        const SynthResult fresh = synthesize(load_scenario(test::source_path("recordings/lsystem-sketch/" + name + ".scenario.json")));
        EXPECT_TRUE(encode_recording_binary(fresh.recording) == read_all(rec_path(name)))
            << name << ".lrec is stale: run scripts/make-recordings.sh";
    }
}

TEST(LSystemSketchMode, ThePipelineLeavesTheHandsToTheMode)
{
    // Every pinch of the recordings is the mode's: the pipeline draws no stroke from them.
    for (const std::string name : {"maple", "edits"}) {
        const InputResult r = run_input_pipeline(read_recording(rec_path(name)));
        EXPECT_TRUE(r.strokes.empty()) << name;
        EXPECT_TRUE(r.drags.empty()) << name;
    }
}

TEST(LSystemSketchMode, BadEditsAreRefusedInOneLineAndChangeNothing)
{
    LSystemSketchMode mode = replay_lsystem_sketch(read_recording(rec_path("maple")));
    const Sketch before = mode.sketch();
    const std::uint64_t generation = mode.tree_generation();
    // B with the fingertip nowhere near a trunk node: refused, nothing changes.
    const std::size_t messages = mode.messages().size();
    mode.push_event(key(lsystem_sketch_keys::kBranch));
    ASSERT_EQ(mode.messages().size(), messages + 1);
    EXPECT_EQ(mode.messages().back().find('\n'), std::string::npos);
    EXPECT_EQ(mode.sketch().trunk, before.trunk);
    EXPECT_EQ(mode.tree_generation(), generation);
    // Keys while the mode is off are not its own.
    mode.push_event(key(keys::kLSystemSketch));
    EXPECT_FALSE(mode.active());
    EXPECT_FALSE(mode.push_event(key(lsystem_sketch_keys::kScrap)));
    EXPECT_EQ(mode.sketch().trunk, before.trunk);
    // Scrap: the sketch is the root alone and no tree grows.
    mode.push_event(key(keys::kLSystemSketch));
    EXPECT_TRUE(mode.push_event(key(lsystem_sketch_keys::kScrap)));
    EXPECT_EQ(mode.sketch().trunk.size(), 1u);
    EXPECT_TRUE(mode.sketch().branches.empty());
    EXPECT_TRUE(mode.tree().empty());
    // With one trunk section a branch cannot start.
    const std::size_t m2 = mode.messages().size();
    mode.push_event(key(lsystem_sketch_keys::kBranch));
    EXPECT_EQ(mode.messages().size(), m2 + 1);
    EXPECT_NE(mode.messages().back().find("two trunk sections"), std::string::npos);
}
