#include <gtest/gtest.h>

#include <cmath>

#include "input/gestures.h"
#include "input/one_euro.h"
#include "input/pipeline.h"
#include "app/session/session_builder.h"
#include "tests/support/hand_fixtures.h"

using namespace lobe;
using lobe::test::make_frame;
using lobe::test::make_hand;

namespace {

constexpr double kDt = 1.0 / 90.0;

// A recording in which the right hand pinches at t0, draws a 20 cm horizontal line at
// 0.25 m/s and releases; `lose` blanks the hand for [lose_from, lose_from + lose_for).
Recording line_recording(double lose_from = -1, double lose_for = 0, HandLoss how = HandLoss::Inactive)
{
    Recording rec;
    const glm::vec3 start(-0.1f, 1.2f, -0.4f);
    double t = 0;
    auto push = [&](glm::vec3 tip, float gap) {
        HandState h = make_hand(tip, gap);
        if (t >= lose_from && t < lose_from + lose_for) {
            if (how == HandLoss::Inactive) h.active = false;
            if (how == HandLoss::AtOrigin)
                for (JointState& j : h.joints) j.pose.position = glm::vec3(0.0f);
            if (how == HandLoss::InvalidJoints)
                for (JointState& j : h.joints) j.flags = 0;
        }
        rec.frames.push_back(make_frame(t, h));
        t += kDt;
    };
    for (int i = 0; i < 30; ++i) push(start, 0.06f);                                  // open
    for (int i = 0; i < 20; ++i) push(start, 0.06f - 0.0031f * static_cast<float>(i)); // closing
    for (int i = 0; i < 72; ++i) push(start + glm::vec3(0.2f * static_cast<float>(i) / 71.0f, 0, 0), 0.0f);
    for (int i = 0; i < 20; ++i) push(start + glm::vec3(0.2f, 0, 0), 0.0031f * static_cast<float>(i));
    for (int i = 0; i < 30; ++i) push(start + glm::vec3(0.2f, 0, 0), 0.06f);
    return rec;
}

} // namespace

TEST(OneEuroFilter, RemovesMillimetreJitterAtRestAndFollowsFastMotion)
{
    OneEuroFilter3 f(OneEuroOptions{});
    double sum_raw = 0, sum_filtered = 0;
    unsigned seed = 1;
    auto noise = [&] {
        seed = seed * 1664525u + 1013904223u;
        return (static_cast<float>(seed >> 8) / 16777216.0f - 0.5f) * 0.004f; // ±2 mm
    };
    for (int i = 0; i < 400; ++i) {
        glm::vec3 x(noise(), 1.0f + noise(), noise());
        glm::vec3 y = f.filter(x, i * kDt);
        if (i > 50) {
            sum_raw += std::abs(x.x);
            sum_filtered += std::abs(y.x);
        }
    }
    EXPECT_LT(sum_filtered, 0.35 * sum_raw);
    // A 30 cm circle drawn at 0.6 m/s: the lag shifts points along the path, but they stay
    // within a millimetre of the circle, so stroke shapes are kept.
    OneEuroFilter3 g(OneEuroOptions{});
    const double r = 0.15, w = 0.6 / r;
    float worst = 0;
    for (int i = 0; i < 300; ++i) {
        const double t = i * kDt;
        glm::vec3 x(static_cast<float>(r * std::cos(w * t)), static_cast<float>(r * std::sin(w * t)), 0);
        glm::vec3 y = g.filter(x, t);
        if (i > 45) worst = std::max(worst, std::abs(glm::length(y) - static_cast<float>(r)));
    }
    EXPECT_LT(worst, 0.001f);
}

TEST(Gestures, PinchNeedsTheGapBelowStartAndEndsAboveRelease)
{
    GestureRecognizer r;
    int starts = 0, ends = 0;
    const float gaps[] = {0.05f, 0.02f, 0.012f, 0.009f, 0.006f, 0.005f, 0.004f, 0.004f, 0.010f, 0.014f,
                          0.012f, 0.017f, 0.03f};
    double t = 0;
    for (float gap : gaps) {
        const auto& g = r.update(make_frame(t, make_hand({0, 1.2f, -0.4f}, gap)));
        starts += g[1].pinch_started;
        ends += g[1].pinch_ended;
        t += 0.02; // 50 Hz: the filter barely smooths at rest
    }
    EXPECT_EQ(starts, 1);
    EXPECT_EQ(ends, 1);
}

TEST(Gestures, ClosedFistIsAGrabNeverAPinchEvenWithTouchingTips)
{
    GestureRecognizer r;
    int pinches = 0, grabs = 0;
    for (int i = 0; i < 60; ++i) {
        const auto& g = r.update(make_frame(i * kDt, make_hand({0, 1.2f, -0.4f}, 0.0f, /*fist=*/true)));
        pinches += g[1].pinch_started;
        grabs += g[1].grab_started;
    }
    EXPECT_EQ(pinches, 0);
    EXPECT_EQ(grabs, 1);
}

TEST(Pipeline, PinchDrawsOneStrokeAlongTheFingertipPath)
{
    InputResult r = run_input_pipeline(line_recording());
    ASSERT_EQ(r.strokes.size(), 1u);
    const Stroke& s = r.strokes[0];
    EXPECT_EQ(s.kind, StrokeKind::Lobe);
    EXPECT_EQ(s.hand, Hand::Right);
    EXPECT_NEAR(s.length(), 0.2, 0.01);
    for (std::size_t i = 1; i < s.points.size(); ++i) {
        EXPECT_GE(glm::distance(s.points[i].position, s.points[i - 1].position), 0.0025f);
        EXPECT_GE(s.points[i].time, s.points[i - 1].time);
    }
    EXPECT_NEAR(s.points.front().position.x, -0.1f, 0.004f);
    EXPECT_NEAR(s.points.back().position.x, 0.1f, 0.004f);
}

TEST(Pipeline, ShortTrackingLossIsBridgedAndLongLossEndsTheStroke)
{
    // 100 ms inside the stroke: one stroke, full length.
    InputResult shortloss = run_input_pipeline(line_recording(0.8, 0.1));
    ASSERT_EQ(shortloss.strokes.size(), 1u);
    EXPECT_NEAR(shortloss.strokes[0].length(), 0.2, 0.01);
    // 300 ms: the stroke ends where tracking was lost; the hand comes back still pinched and
    // starts no new stroke until it opens and pinches again.
    InputResult longloss = run_input_pipeline(line_recording(0.8, 0.3));
    ASSERT_EQ(longloss.strokes.size(), 1u);
    EXPECT_LT(longloss.strokes[0].length(), 0.12);
}

TEST(Pipeline, HandsSnappingToTheOriginOrWithInvalidJointsAddNoStrokePoints)
{
    for (HandLoss how : {HandLoss::AtOrigin, HandLoss::InvalidJoints}) {
        InputResult r = run_input_pipeline(line_recording(0.8, 0.1, how));
        ASSERT_EQ(r.strokes.size(), 1u);
        for (const StrokePoint& p : r.strokes[0].points) EXPECT_GT(p.position.y, 1.1f);
        EXPECT_NEAR(r.strokes[0].length(), 0.2, 0.01);
    }
}

TEST(Pipeline, TooShortStrokeIsDiscardedWithAReason)
{
    Recording rec;
    double t = 0;
    for (int i = 0; i < 10; ++i, t += kDt) rec.frames.push_back(make_frame(t, make_hand({0, 1.2f, -0.4f}, 0.05f)));
    for (int i = 0; i < 20; ++i, t += kDt)
        rec.frames.push_back(make_frame(t, make_hand({0.001f * static_cast<float>(i), 1.2f, -0.4f}, 0.0f)));
    for (int i = 0; i < 10; ++i, t += kDt) rec.frames.push_back(make_frame(t, make_hand({0.02f, 1.2f, -0.4f}, 0.05f)));
    InputResult r = run_input_pipeline(rec);
    EXPECT_TRUE(r.strokes.empty());
    ASSERT_EQ(r.messages.size(), 1u);
    EXPECT_NE(r.messages[0].find("too short"), std::string::npos) << r.messages[0];
}

TEST(Pipeline, ToolKeysDecideWhatAPinchDoes)
{
    Recording rec = line_recording();
    Recording trunk = rec;
    trunk.events.push_back({0.1, InputEventKind::Key, keys::kDrawTrunk, 1, 0, 0});
    InputResult r = run_input_pipeline(trunk);
    ASSERT_EQ(r.strokes.size(), 1u);
    EXPECT_EQ(r.strokes[0].kind, StrokeKind::Trunk);

    Recording deform = rec;
    deform.events.push_back({0.1, InputEventKind::Key, keys::kDeformLobe, 1, 0, 0});
    InputResult d = run_input_pipeline(deform);
    EXPECT_TRUE(d.strokes.empty());
    ASSERT_EQ(d.drags.size(), 1u);
    EXPECT_EQ(d.drags[0].tool, Tool::DeformLobe);
    EXPECT_GT(d.drags[0].path.size(), 10u);
}

TEST(Pipeline, EveryEditingToolKeyMakesDragsThatEndWhereTheFingertipStopped)
{
    const Recording rec = line_recording();
    const std::pair<int, Tool> tools[] = {{keys::kDeformLobe, Tool::DeformLobe}, {keys::kEditStroke, Tool::EditStroke},
                                          {keys::kMoveLobe, Tool::MoveLobe},     {keys::kRotateLobe, Tool::RotateLobe},
                                          {keys::kScaleLobe, Tool::ScaleLobe}};
    for (const auto& [key, tool] : tools) {
        Recording r = rec;
        r.events.push_back({0.1, InputEventKind::Key, key, 1, 0, 0});
        InputResult d = run_input_pipeline(r);
        ASSERT_EQ(d.actions.front().type, InputAction::Type::ToolChanged);
        EXPECT_EQ(d.actions.front().tool, tool);
        EXPECT_TRUE(d.strokes.empty());
        ASSERT_EQ(d.drags.size(), 1u) << tool_name(tool);
        EXPECT_EQ(d.drags[0].tool, tool);
        // The drag's last point is where the tip stopped (the filter settles while the thumb
        // opens), even when that is closer than the point spacing to the point before.
        EXPECT_NEAR(d.drags[0].path.back().position.x, 0.1f, 0.0005f) << tool_name(tool);
        EXPECT_FALSE(d.drags[0].other_tip.has_value());
    }
    EXPECT_EQ(keys::kRotateLobe, 82); // GLFW_KEY_R
    EXPECT_EQ(keys::kScaleLobe, 75);  // GLFW_KEY_K
    EXPECT_STREQ(tool_name(Tool::RotateLobe), "rotate-lobe");
    EXPECT_STREQ(tool_name(Tool::ScaleLobe), "scale-lobe");
}

TEST(Pipeline, StrokeEditDragRecordsTheOtherHandOnlyWhenItPoints)
{
    // The right hand drags under E while the left hand is straight (not pointing), pointing
    // (index straight, the others curled), or pointing under another tool.
    const glm::vec3 left_tip(-0.2f, 1.25f, -0.45f);
    auto with_left = [&](bool pointing, int key) {
        Recording rec = line_recording();
        for (HandFrame& f : rec.frames) f.hand(Hand::Left) = make_hand(left_tip, 0.05f, /*fist=*/pointing);
        rec.events.push_back({0.1, InputEventKind::Key, key, 1, 0, 0});
        return run_input_pipeline(rec);
    };
    InputResult relaxed = with_left(false, keys::kEditStroke);
    ASSERT_EQ(relaxed.drags.size(), 1u);
    EXPECT_FALSE(relaxed.drags[0].other_tip.has_value());

    InputResult pointing = with_left(true, keys::kEditStroke);
    ASSERT_EQ(pointing.drags.size(), 1u);
    ASSERT_TRUE(pointing.drags[0].other_tip.has_value());
    EXPECT_LT(glm::distance(*pointing.drags[0].other_tip, left_tip), 0.001f);
    EXPECT_EQ(pointing.drags[0].hand, Hand::Right);

    InputResult moving = with_left(true, keys::kMoveLobe);
    ASSERT_EQ(moving.drags.size(), 1u);
    EXPECT_FALSE(moving.drags[0].other_tip.has_value());
}

TEST(Pipeline, AnnotationsAreCheckedNeverApplied)
{
    Recording rec = line_recording();
    InputResult clean = run_input_pipeline(rec);
    ASSERT_EQ(clean.strokes.size(), 1u);
    rec.annotations.push_back({2.0, annotation_for(clean.actions.back())});
    InputResult ok = run_input_pipeline(rec);
    EXPECT_TRUE(ok.messages.empty());
    EXPECT_EQ(ok.strokes.size(), 1u); // not doubled by the annotation
    rec.annotations.push_back({2.1, "stroke id=2 kind=lobe points=50"});
    InputResult bad = run_input_pipeline(rec);
    EXPECT_EQ(bad.strokes.size(), 1u);
    ASSERT_EQ(bad.messages.size(), 1u);
    EXPECT_NE(bad.messages[0].find("replay derived 'nothing'"), std::string::npos) << bad.messages[0];
}

TEST(SessionBuilder, NewLobeKeyGroupsStrokesAndUndoRedoRestoreThem)
{
    auto stroke = [](std::int64_t id, StrokeKind k) {
        InputAction a;
        a.type = InputAction::Type::StrokeCompleted;
        a.stroke.id = id;
        a.stroke.kind = k;
        // Lobe strokes: loops around one centre, each turned a little; the trunk: a line.
        for (int i = 0; i < 40; ++i) {
            const float t = 0.16f * static_cast<float>(i), turn = 0.5f * static_cast<float>(id);
            a.stroke.points.push_back(
                {k == StrokeKind::Lobe ? glm::vec3(0.15f * std::cos(t), 1.4f + 0.15f * std::sin(t) * std::cos(turn),
                                                   -0.4f + 0.15f * std::sin(t) * std::sin(turn))
                                       : glm::vec3(0.0f, 0.8f + 0.01f * static_cast<float>(i), -0.4f),
                 0.01 * i});
        }
        return a;
    };
    InputAction newlobe;
    newlobe.type = InputAction::Type::NewLobe;
    InputAction undo;
    undo.type = InputAction::Type::Undo;
    InputAction redo;
    redo.type = InputAction::Type::Redo;
    SessionBuilder b;
    b.apply({stroke(1, StrokeKind::Lobe), stroke(2, StrokeKind::Lobe), newlobe, stroke(3, StrokeKind::Lobe),
             stroke(4, StrokeKind::Trunk)});
    ASSERT_EQ(b.document().lobes.size(), 2u);
    EXPECT_EQ(b.document().lobes[0].stroke_ids, (std::vector<std::int64_t>{1, 2}));
    EXPECT_EQ(b.document().lobes[1].stroke_ids, (std::vector<std::int64_t>{3}));
    b.apply(undo);
    b.apply(undo);
    EXPECT_EQ(b.document().strokes.size(), 2u);
    EXPECT_EQ(b.document().lobes.size(), 1u);
    b.apply(redo);
    EXPECT_EQ(b.document().strokes.size(), 3u);
    EXPECT_EQ(b.document().lobes.size(), 2u);
}

TEST(Pipeline, ActionKeysCarryTheRightFingertipElseTheLeftElseNone)
{
    const glm::vec3 right_tip(0.1f, 1.3f, -0.4f), left_tip(-0.2f, 1.25f, -0.45f);
    auto actions = [&](bool right, bool left) {
        Recording rec;
        for (int i = 0; i < 60; ++i) {
            HandFrame f = make_frame(i * kDt, make_hand(right_tip, 0.06f));
            f.hand(Hand::Right).active = right;
            if (left) f.hand(Hand::Left) = make_hand(left_tip, 0.06f);
            rec.frames.push_back(f);
        }
        for (int key : {keys::kDeleteStroke, keys::kDeleteLobe, keys::kDuplicate, keys::kMirror})
            rec.events.push_back({0.5, InputEventKind::Key, key, 1, 0, 0});
        rec.events.push_back({0.55, InputEventKind::Key, keys::kMirror, 0, 0, 0}); // a release does nothing
        return run_input_pipeline(rec).actions;
    };
    const InputAction::Type types[] = {InputAction::Type::DeleteStroke, InputAction::Type::DeleteLobe,
                                       InputAction::Type::Duplicate, InputAction::Type::Mirror};
    const std::vector<InputAction> both = actions(true, true), left = actions(false, true), none = actions(false, false);
    ASSERT_EQ(both.size(), 4u);
    ASSERT_EQ(left.size(), 4u);
    ASSERT_EQ(none.size(), 4u);
    for (int i = 0; i < 4; ++i) {
        EXPECT_EQ(both[i].type, types[i]);
        ASSERT_TRUE(both[i].tip.has_value());
        EXPECT_EQ(both[i].tip_hand, Hand::Right);
        EXPECT_LT(glm::distance(*both[i].tip, right_tip), 1e-4f); // filtered, at rest
        ASSERT_TRUE(left[i].tip.has_value());
        EXPECT_EQ(left[i].tip_hand, Hand::Left);
        EXPECT_LT(glm::distance(*left[i].tip, left_tip), 1e-4f);
        EXPECT_FALSE(none[i].tip.has_value());
    }
    EXPECT_STREQ(action_name(InputAction::Type::Mirror), "mirror");
    EXPECT_EQ(keys::kDeleteStroke, 259); // GLFW_KEY_BACKSPACE
    EXPECT_EQ(keys::kDeleteLobe, 261);   // GLFW_KEY_DELETE
    EXPECT_EQ(keys::kDuplicate, 67);     // GLFW_KEY_C
    EXPECT_EQ(keys::kMirror, 88);        // GLFW_KEY_X
}

TEST(Pipeline, SettingEventsBecomeSettingActionsWithTheDecimalTheSliderShowed)
{
    Recording rec;
    InputEvent e;
    e.time = 0.25;
    e.kind = InputEventKind::Setting;
    e.code = static_cast<std::int32_t>(SettingId::AttractorSpacing);
    e.value = 0;
    e.x = 0.03f;
    rec.events.push_back(e);
    e.time = 0.5;
    e.code = static_cast<std::int32_t>(SettingId::Species);
    e.value = 2;
    e.x = 1.0f;
    rec.events.push_back(e);
    const InputResult r = run_input_pipeline(rec);
    ASSERT_EQ(r.actions.size(), 2u);
    EXPECT_EQ(r.actions[0].type, InputAction::Type::SettingChanged);
    EXPECT_EQ(r.actions[0].time, 0.25);
    EXPECT_EQ(r.actions[0].setting.id, SettingId::AttractorSpacing);
    EXPECT_EQ(r.actions[0].setting.lobe, 0);
    EXPECT_EQ(r.actions[0].setting.value, 0.03); // not 0.029999999329447746
    EXPECT_EQ(r.actions[1].setting.id, SettingId::Species);
    EXPECT_EQ(r.actions[1].setting.lobe, 2);
    EXPECT_EQ(r.actions[1].setting.value, 1.0);
}
