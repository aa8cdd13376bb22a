// Growth step by step (issue 41): the panels' growth-steps setting (SettingId::GrowthSteps)
// sets the scene grower's steps parameter (Grower::steps_param, growth/grower.h), so the apps
// step a tree's growth forward and back; k steps grow the first k steps of the growth.
#include <gtest/gtest.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "app/export/skeleton_json.h"
#include "app/session/panel_controls.h"
#include "app/session/session_builder.h"
#include "app/session/session_file.h"
#include "app/session/tree_pipeline.h"
#include "core/document.h"
#include "growth/grower.h"
#include "growth/lsystem/lsystem.h"
#include "input/pipeline.h"
#include "input/recording.h"
#include "input/truth_surface.h"
#include "tests/support/hand_fixtures.h"

namespace lobe {
namespace {

/// One ball lobe imported from a mesh, its tree grown by `grower` (default parameters).
Document ball_document(const std::string& grower)
{
    Document doc;
    doc.seed = 7;
    TruthSurface s;
    s.center = {0.0, 1.3, 0.0};
    s.radii = {0.35, 0.3, 0.35};
    LobeRecord lobe = LobeRecord::of_strokes(1);
    lobe.model = std::make_shared<const LobeModel>(LobeModel{"ball.obj", truth_surface_mesh(s, 3)});
    doc.lobes.push_back(std::move(lobe));
    GrowerChoice choice;
    choice.name = grower;
    if (grower == "self-organizing") choice.params["internode_m"] = 0.04; // a small, quick tree
    set_scene_grower(doc, choice);
    return doc;
}

InputAction steps_setting(double value, std::int64_t lobe = 0)
{
    InputAction a;
    a.type = InputAction::Type::SettingChanged;
    a.time = 1.0;
    a.setting.id = SettingId::GrowthSteps;
    a.setting.value = value;
    a.setting.lobe = lobe;
    return a;
}

InputAction simple(InputAction::Type t)
{
    InputAction a;
    a.type = t;
    a.time = 2.0;
    return a;
}

std::string tree_bytes(const Document& doc)
{
    const BuiltTree tree = build_document_tree(doc);
    return skeleton_json(tree.growth.tree, {});
}

std::int64_t steps_param_of(const Document& doc, const std::string& param)
{
    const GrowerChoice& g = scene_grower(doc);
    const auto it = g.params.find(param);
    return it == g.params.end() ? 0 : std::get<std::int64_t>(it->second);
}

TEST(GrowthSteps, EachGrowerNamesItsStepsParameterAndItsDefault)
{
    EXPECT_STREQ(setting_name(SettingId::GrowthSteps), "growth-steps");
    EXPECT_TRUE(known_setting_id(8));
    ASSERT_NE(find_panel_control(SettingId::GrowthSteps), nullptr);
    // The control takes what the grower with the most steps takes; each grower checks its own.
    EXPECT_EQ(find_panel_control(SettingId::GrowthSteps)->hi, double(lsystem::kMaxDerivationLength));
    EXPECT_EQ(find_grower("subtrees")->steps_param(), "");
    EXPECT_EQ(find_grower("self-organizing")->steps_param(), "iterations");
    EXPECT_EQ(find_grower("lsystem")->steps_param(), "steps");
    GrowerChoice selforg;
    selforg.name = "self-organizing";
    EXPECT_EQ(growth_steps(selforg), 24); // the broadleaf species' iterations
    selforg.params["iterations"] = std::int64_t{9};
    EXPECT_EQ(growth_steps(selforg), 9);
    EXPECT_EQ(growth_steps_after(selforg, +1), 10.0);
    EXPECT_EQ(growth_steps_after(selforg, -1), 8.0);
    selforg.params["iterations"] = std::int64_t{1};
    EXPECT_EQ(growth_steps_after(selforg, -1), 1.0); // never 0, which would be the default again
    GrowerChoice lsystem;
    lsystem.name = "lsystem";
    ASSERT_TRUE(growth_steps(lsystem));
    EXPECT_GT(*growth_steps(lsystem), 0); // the default L-system's derivation length
    EXPECT_FALSE(growth_steps(GrowerChoice{}));
    EXPECT_FALSE(growth_steps_after(GrowerChoice{}, 1));
}

TEST(GrowthSteps, SteppingTheSelfOrganizingGrowerOnGrowsTheFirstKIterationsOfOneTreeNeverShrinking)
{
    const Document start = ball_document("self-organizing");
    SessionBuilder b(start);
    std::size_t nodes_before = 0;
    for (int k = 1; k <= 6; ++k) {
        SCOPED_TRACE(k);
        ASSERT_TRUE(b.apply(steps_setting(k))) << (b.messages().empty() ? "" : b.messages().back());
        EXPECT_EQ(growth_steps(scene_grower(b.document())), k);
        const BuiltTree stepped = build_document_tree(b.document());
        EXPECT_GE(stepped.growth.tree.size(), nodes_before);
        nodes_before = stepped.growth.tree.size();
        // The same tree as one grown with iterations = k from the start.
        Document direct = start;
        GrowerChoice choice = scene_grower(start);
        choice.params["iterations"] = std::int64_t{k};
        set_scene_grower(direct, choice);
        EXPECT_EQ(skeleton_json(stepped.growth.tree, {}), tree_bytes(direct));
    }
    EXPECT_GT(nodes_before, 20u);
    EXPECT_TRUE(b.messages().empty());
    // And back: the tree of 3 steps again.
    ASSERT_TRUE(b.apply(steps_setting(3)));
    Document direct = start;
    GrowerChoice choice = scene_grower(start);
    choice.params["iterations"] = std::int64_t{3};
    set_scene_grower(direct, choice);
    EXPECT_EQ(tree_bytes(b.document()), tree_bytes(direct));
}

TEST(GrowthSteps, TheLSystemGrowersStepsAreItsDerivationSteps)
{
    SessionBuilder b(ball_document("lsystem"));
    ASSERT_TRUE(b.apply(steps_setting(2)));
    EXPECT_EQ(steps_param_of(b.document(), "steps"), 2);
    const std::size_t two = build_document_tree(b.document()).growth.tree.size();
    ASSERT_TRUE(b.apply(steps_setting(4)));
    EXPECT_GE(build_document_tree(b.document()).growth.tree.size(), two);
    ASSERT_TRUE(b.apply(steps_setting(0))); // the grower's default again: no steps parameter
    EXPECT_EQ(scene_grower(b.document()).params.count("steps"), 0u);
    EXPECT_TRUE(b.messages().empty());
}

TEST(GrowthSteps, OnTheSubtreesGrowerTheSettingIsRefusedInOneLineAndChangesNothing)
{
    const Document start = ball_document("subtrees");
    SessionBuilder b(start);
    const std::string before = document_to_json(b.document()).dump();
    EXPECT_FALSE(b.apply(steps_setting(5)));
    ASSERT_EQ(b.messages().size(), 1u);
    EXPECT_EQ(b.messages()[0], "setting growth-steps at t=1.00s changes nothing: the subtrees grower does not grow in steps");
    EXPECT_EQ(document_to_json(b.document()).dump(), before);
    EXPECT_FALSE(b.apply(simple(InputAction::Type::Undo))); // no undo step was made
}

TEST(GrowthSteps, OutOfRangeFractionalOrPerLobeStepsAreRefusedInOneLine)
{
    SessionBuilder b(ball_document("self-organizing"));
    EXPECT_FALSE(b.apply(steps_setting(501))); // the grower's own range: 1 … 500
    EXPECT_FALSE(b.apply(steps_setting(2.5)));
    EXPECT_FALSE(b.apply(steps_setting(-1)));
    EXPECT_FALSE(b.apply(steps_setting(3, 1))); // tree-wide only
    ASSERT_EQ(b.messages().size(), 4u);
    EXPECT_NE(b.messages()[0].find("iterations: 501 is outside [1, 500]"), std::string::npos) << b.messages()[0];
    EXPECT_NE(b.messages()[1].find("whole number"), std::string::npos) << b.messages()[1];
    EXPECT_NE(b.messages()[3].find("tree-wide"), std::string::npos) << b.messages()[3];
    for (const std::string& m : b.messages()) EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    EXPECT_EQ(scene_grower(b.document()).params.count("iterations"), 0u);
}

TEST(GrowthSteps, UndoRestoresThePreviousStepCountAndTheSameValueIsNoUndoStep)
{
    SessionBuilder b(ball_document("self-organizing"));
    ASSERT_TRUE(b.apply(steps_setting(5)));
    EXPECT_FALSE(b.apply(steps_setting(5))); // the same as now: nothing, no undo step
    EXPECT_TRUE(b.messages().empty());
    b.apply(simple(InputAction::Type::Grow)); // ends the run of settings: the next is its own step
    ASSERT_TRUE(b.apply(steps_setting(8)));
    EXPECT_EQ(steps_param_of(b.document(), "iterations"), 8);
    ASSERT_TRUE(b.apply(simple(InputAction::Type::Undo)));
    EXPECT_EQ(steps_param_of(b.document(), "iterations"), 5);
    ASSERT_TRUE(b.apply(simple(InputAction::Type::Redo)));
    EXPECT_EQ(steps_param_of(b.document(), "iterations"), 8);
    // Undone to before the first setting: the grower's default (no iterations parameter).
    ASSERT_TRUE(b.apply(simple(InputAction::Type::Undo)));
    ASSERT_TRUE(b.apply(simple(InputAction::Type::Undo)));
    EXPECT_EQ(scene_grower(b.document()).params.count("iterations"), 0u);
    EXPECT_FALSE(b.apply(simple(InputAction::Type::Undo)));
    EXPECT_EQ(scene_grower(b.document()).name, "self-organizing");
}

TEST(GrowthSteps, ARecordingWithGrowerAndStepSettingsReplaysToTheSameDocumentFromBothForms)
{
    Recording rec;
    double t = 0.0;
    auto frames = [&](int n) {
        for (int i = 0; i < n; ++i) {
            rec.frames.push_back(test::make_frame(t, test::make_hand({0.05f, 1.2f, -0.25f}, 0.06f)));
            t += 1.0 / 90.0;
        }
    };
    auto set = [&](SettingId id, float x) {
        InputEvent e;
        e.time = t;
        e.kind = InputEventKind::Setting;
        e.code = static_cast<std::int32_t>(id);
        e.value = 0;
        e.x = x;
        rec.events.push_back(e);
        frames(5);
    };
    frames(10);
    set(SettingId::GrowthSteps, 3.0f); // refused: the default grower has no steps
    set(SettingId::Grower, float(find_grower("self-organizing")->panel_code()));
    for (float k : {1.0f, 2.0f, 3.0f, 2.0f}) set(SettingId::GrowthSteps, k);
    frames(10);

    auto replay = [](const Recording& r, std::vector<std::string>* messages) {
        SessionBuilder b(ball_document("subtrees"));
        b.apply(run_input_pipeline(r).actions);
        if (messages) *messages = b.messages();
        return b.take_document();
    };
    std::vector<std::string> messages;
    const Document doc = replay(rec, &messages);
    EXPECT_EQ(scene_grower(doc).name, "self-organizing");
    EXPECT_EQ(steps_param_of(doc, "iterations"), 2);
    ASSERT_EQ(messages.size(), 1u);
    EXPECT_NE(messages[0].find("setting growth-steps"), std::string::npos) << messages[0];
    const std::string want = document_to_json(doc).dump();
    for (bool binary : {true, false}) {
        ReadReport report;
        const Recording back =
            parse_recording(binary ? encode_recording_binary(rec) : encode_recording_text(rec), "steps", &report);
        EXPECT_EQ(report.events_dropped + report.frames_dropped, 0u);
        EXPECT_EQ(document_to_json(replay(back, nullptr)).dump(), want) << (binary ? "binary" : "text");
    }
}

} // namespace
} // namespace lobe
