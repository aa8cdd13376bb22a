// The L-system sketch mode in the VR session (app/vr/vr_session.h, its panel's L-system rows):
// the L-SYSTEM button turns it on, right pinches on the 1:10 platform add trunk sections, the
// left hand pokes BRANCH while the right fingertip is on a trunk node, the divergence and
// iteration buttons act, a left pinch on the platform moves it, no lobe stroke is drawn, the
// tree and the sketch are in the scene, and the recording replays to the same sketch and tree.
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "app/live/lsystem_sketch_mode.h"
#include "app/live/lsystem_sketch_view.h"
#include "app/vr/vr_session.h"
#include "core/document.h"
#include "input/recording.h"
#include "tests/support/vr_script.h"

using namespace lobe;
using namespace lobe::test;
namespace fs = std::filesystem;

namespace {

void poke(VrScript& script, const VrSession& s, const std::string& text, Hand h = Hand::Right)
{
    for (const VrButton& b : s.panel().buttons)
        if (b.text == text) {
            script.poke(h, b.centre, s.panel().orientation * glm::vec3(0, 0, 1));
            return;
        }
    FAIL() << "no button " << text;
}

/// A right pinch at `p` (the hand comes from a little in front, pinches, opens, backs off).
void pinch_at(VrScript& script, glm::vec3 p)
{
    script.hand(Hand::Right).pose = HandPose::Open;
    script.move(Hand::Right, p + glm::vec3(0, 0, 0.04f), 0.4);
    script.move(Hand::Right, p, 0.3);
    script.pinch(Hand::Right, true);
    script.pinch(Hand::Right, false);
    script.move(Hand::Right, p + glm::vec3(0, 0, 0.04f), 0.3);
}

} // namespace

TEST(VrLSystemSketch, PanelAndPinchesSketchATreeThatTheRecordingReplaysAlike)
{
    const fs::path dir = fs::temp_directory_path() / "lobesketch_vr_lsystem_sketch";
    fs::remove_all(dir);
    fs::create_directories(dir);
    VrOptions o;
    o.background_regrowth = false;
    o.record_path = (dir / "vr.lrec").string();
    VrSession s(Document{}, o);
    VrScript script([&](const HandFrame& f) { s.frame(f); });
    script.hand(Hand::Right) = {true, HandPose::Open, {0.25f, 1.3f, -0.3f}, 0.05f};
    script.hand(Hand::Left) = {true, HandPose::Open, {-0.25f, 1.2f, -0.3f}, 0.05f};
    script.wait(0.3);
    poke(script, s, "L-SYSTEM");
    ASSERT_TRUE(s.lsystem_sketch().active());

    const glm::vec3 base(0.0f, 1.0f, -0.45f); // the VR platform's centre (1:10)
    const glm::vec3 nodes[] = {base + glm::vec3(0.005f, 0.05f, 0), base + glm::vec3(-0.005f, 0.1f, 0),
                               base + glm::vec3(0.0f, 0.15f, 0.005f)};
    for (const glm::vec3& p : nodes) pinch_at(script, p);
    ASSERT_EQ(s.lsystem_sketch().sketch().trunk_sections(), 3);
    // Full size: ten times the platform's offsets, within a centimetre.
    EXPECT_NEAR(s.lsystem_sketch().sketch().trunk[2].y, 1.0, 0.01);

    // The right fingertip on trunk node 1, the left hand pokes BRANCH; then the branch.
    script.move(Hand::Right, nodes[0], 0.4);
    poke(script, s, "BRANCH", Hand::Left);
    EXPECT_EQ(s.lsystem_sketch().drawing_from(), 1);
    pinch_at(script, base + glm::vec3(0.04f, 0.08f, 0));
    pinch_at(script, base + glm::vec3(0.07f, 0.1f, 0));
    ASSERT_EQ(s.lsystem_sketch().sketch().branches.size(), 1u);
    EXPECT_EQ(s.lsystem_sketch().sketch().branches[0].points.size(), 2u);
    poke(script, s, "DIV +");
    poke(script, s, "ITER +");
    poke(script, s, "GROW +");
    EXPECT_EQ(s.lsystem_sketch().sketch().divergence_deg, 142.5);
    EXPECT_NEAR(s.lsystem_sketch().growth(), 4.1, 1e-9);
    // A left pinch on the platform moves it 5 cm along +X.
    script.hand(Hand::Left).pose = HandPose::Open;
    script.move(Hand::Left, base + glm::vec3(-0.03f, 0.0f, 0.0f), 0.5);
    script.pinch(Hand::Left, true);
    script.move(Hand::Left, base + glm::vec3(0.02f, 0.0f, 0.0f), 0.5);
    script.pinch(Hand::Left, false);
    EXPECT_NEAR(s.lsystem_sketch().platform().position.x, 0.05, 0.006);

    EXPECT_TRUE(s.document().strokes.empty());
    EXPECT_FALSE(s.lsystem_sketch().tree().empty());
    std::size_t items = 0;
    for (const RenderItem& item : s.scene().items) items += (item.key >> 48) == (LSystemSketchView::kKeyBase >> 48);
    EXPECT_GE(items, 4u); // the platform, the trunk, the branch, the tree (and the preview)

    const lsystem::Sketch live = s.lsystem_sketch().sketch();
    const TreeGraph live_tree = s.lsystem_sketch().tree();
    s.finish(script.time());
    const LSystemSketchMode replayed = replay_lsystem_sketch(read_recording(o.record_path));
    EXPECT_EQ(lsystem::sketch_json(replayed.sketch()), lsystem::sketch_json(live));
    EXPECT_EQ(replayed.growth(), 4.1);
    ASSERT_EQ(replayed.tree().size(), live_tree.size());
    for (std::size_t i = 0; i < live_tree.size(); ++i) EXPECT_EQ(replayed.tree().nodes[i].position, live_tree.nodes[i].position);
}
