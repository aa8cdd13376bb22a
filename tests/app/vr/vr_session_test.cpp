// The VR session without a headset: scripted hands (tests/support/vr_script.h) poke the panel, draw,
// edit, grab the scene with both hands and undo; every change is checked on the document, and
// the recording the session wrote replays to the same document.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>
#include <glm/gtc/constants.hpp>
#include <nlohmann/json.hpp>

#include "app/cli/cli_common.h"
#include "app/render/render_scene.h"
#include "app/export/tree_output.h"
#include "app/session/session_file.h"
#include "app/session/tree_pipeline.h"
#include "app/vr/vr_session.h"
#include "core/document.h"
#include "input/recording.h"
#include "app/session/edit_ops.h"
#include "tests/support/vr_script.h"

namespace lobe {
namespace {

namespace fs = std::filesystem;
using test::HandPose;
using test::VrScript;

fs::path scratch(const std::string& name)
{
    const fs::path dir = fs::temp_directory_path() / ("lobesketch_vr_session_" + name);
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

std::vector<glm::vec3> circle(glm::vec3 centre, glm::vec3 u, glm::vec3 v, float r, int n = 48)
{
    std::vector<glm::vec3> out;
    for (int i = 0; i <= n; ++i) {
        const float a = glm::two_pi<float>() * float(i) / float(n);
        out.push_back(centre + r * (std::cos(a) * u + std::sin(a) * v));
    }
    return out;
}

const VrButton& button(const VrSession& s, const std::string& text)
{
    for (const VrButton& b : s.panel().buttons)
        if (b.text == text) return b;
    throw std::runtime_error("no button " + text);
}

glm::vec3 board_normal(const VrSession& s) { return s.panel().orientation * glm::vec3(0, 0, 1); }

void poke(VrScript& script, const VrSession& s, const std::string& text)
{
    script.poke(Hand::Right, button(s, text).centre, board_normal(s));
}

float extent(const Stroke& stroke)
{
    glm::vec3 lo(1e9f), hi(-1e9f);
    for (const StrokePoint& p : stroke.points) {
        lo = glm::min(lo, p.position);
        hi = glm::max(hi, p.position);
    }
    return glm::length(hi - lo);
}

TEST(VrSession, PanelLayoutStandsInFrontOfAndBelowTheFirstHeadPoseFacingIt)
{
    Pose head;
    head.position = {0.3f, 1.7f, -0.2f};
    head.orientation = glm::angleAxis(glm::radians(90.0f), glm::vec3(0, 1, 0)); // looking along -X
    const VrPanel p = vr_panel_layout(head);
    EXPECT_LT(p.origin.x, head.position.x - 0.3f); // in front
    EXPECT_LT(p.origin.y, head.position.y - 0.2f); // below the eyes
    const glm::vec3 n = p.orientation * glm::vec3(0, 0, 1);
    EXPECT_GT(glm::dot(n, glm::normalize(head.position - p.origin)), 0.99f); // faces the eyes
    EXPECT_EQ(p.buttons.size(), 47u); // 30, the L-system sketch mode's 9 and the tree's appearance 8
    for (const char* appearance : {"WIDTH -", "WIDTH +", "LEAF COLOUR", "BARK COLOUR", "TWIG -", "TWIG +", "PIPE -", "PIPE +"})
        EXPECT_EQ(std::count_if(p.buttons.begin(), p.buttons.end(), [&](const VrButton& b) { return b.text == appearance; }), 1)
            << appearance << ": the tree's leaf width, colours and radii";
    EXPECT_EQ(std::count_if(p.buttons.begin(), p.buttons.end(), [](const VrButton& b) { return b.text == "GROWER"; }), 1)
        << "the panel lists the growers";
    for (const char* step : {"STEP -", "STEP +"})
        EXPECT_EQ(std::count_if(p.buttons.begin(), p.buttons.end(), [&](const VrButton& b) { return b.text == step; }), 1)
            << step << ": the grower's growth one step back or on";
    for (std::size_t i = 0; i < p.buttons.size(); ++i)
        for (std::size_t j = i + 1; j < p.buttons.size(); ++j)
            EXPECT_GT(glm::distance(p.buttons[i].centre, p.buttons[j].centre), 0.04f) << p.buttons[i].text;
}

TEST(VrSession, ScriptedSessionExercisesEveryInteractionAndItsRecordingReplaysToTheSameDocument)
{
    const fs::path dir = scratch("scripted");
    VrOptions o;
    o.record_path = (dir / "vr.lrec").string();
    o.autosave_path = (dir / "autosave.json").string();
    o.session_path = (dir / "session.json").string();
    o.background_regrowth = false;
    VrSession s(Document{}, o);
    VrScript script([&](const HandFrame& f) { s.frame(f); });
    script.hand(Hand::Right) = {true, HandPose::Open, {0.25f, 1.3f, -0.3f}, 0.05f};
    script.wait(0.3);
    ASSERT_EQ(s.panel().buttons.size(), vr_panel_layout(script.head()).buttons.size());

    // Three loops around one lobe, drawn with a pinch.
    const glm::vec3 c(0.15f, 1.45f, -0.45f);
    const glm::vec3 X(1, 0, 0), Y(0, 1, 0), Z(0, 0, 1);
    script.pinch_along(Hand::Right, circle(c, X, Z, 0.12f));
    ASSERT_EQ(s.document().strokes.size(), 1u) << (s.messages().empty() ? "" : s.messages().back());
    script.pinch_along(Hand::Right, circle(c, X, Y, 0.12f));
    script.pinch_along(Hand::Right, circle(c, Z, Y, 0.12f));
    ASSERT_EQ(s.document().strokes.size(), 3u);
    ASSERT_EQ(s.document().lobes.size(), 1u);
    EXPECT_FALSE(fs::is_empty(o.autosave_path)); // autosaved after each stroke
    EXPECT_EQ(load_document(o.autosave_path).strokes.size(), 3u);

    // The panel: TRUNK, then a trunk stroke below the lobe.
    poke(script, s, "TRUNK");
    EXPECT_EQ(s.status().tool, Tool::DrawTrunk);
    EXPECT_EQ(s.document().strokes.size(), 3u); // poking draws nothing
    script.pinch_along(Hand::Right, {c + glm::vec3(0, -0.45f, 0), c + glm::vec3(0.005f, -0.30f, 0), c + glm::vec3(0, -0.12f, 0)});
    ASSERT_EQ(s.document().strokes.size(), 4u);
    EXPECT_EQ(s.document().strokes.back().kind, StrokeKind::Trunk);

    // Pinch-deform the lobe's top 5 cm upwards.
    poke(script, s, "PINCH");
    EXPECT_EQ(s.status().tool, Tool::DeformLobe);
    const std::size_t edits0 = s.document().edits.size();
    script.pinch_along(Hand::Right, {c + glm::vec3(0, 0.12f, 0), c + glm::vec3(0, 0.17f, 0)}, 0.1);
    ASSERT_EQ(s.document().edits.size(), edits0 + 1);
    EXPECT_STREQ(edit_kind_name(s.document().edits.back().kind()), "drag:deform-lobe");

    // Bend a stroke: drag a point of the horizontal loop outwards.
    poke(script, s, "BEND");
    EXPECT_EQ(s.status().tool, Tool::EditStroke);
    script.pinch_along(Hand::Right, {c + glm::vec3(0, 0, 0.12f), c + glm::vec3(0, 0, 0.16f)}, 0.1);
    ASSERT_EQ(s.document().edits.size(), edits0 + 2);
    EXPECT_STREQ(edit_kind_name(s.document().edits.back().kind()), "drag:edit-stroke");

    // Grab the lobe and move it 8 cm to the right.
    poke(script, s, "MOVE");
    script.pinch_along(Hand::Right, {c + glm::vec3(0.05f, 0, 0), c + glm::vec3(0.13f, 0, 0)}, 0.15);
    ASSERT_EQ(s.document().edits.size(), edits0 + 3);
    EXPECT_STREQ(edit_kind_name(s.document().edits.back().kind()), "drag:move-lobe");

    // Undo and redo the move.
    poke(script, s, "UNDO");
    EXPECT_EQ(s.document().edits.size(), edits0 + 2);
    poke(script, s, "REDO");
    EXPECT_EQ(s.document().edits.size(), edits0 + 3);

    // Appearance: the split angle goes up by 5 degrees, the seed changes.
    const double angle0 = s.document().settings.growth.split_angle_deg;
    poke(script, s, "ANGLE +");
    EXPECT_DOUBLE_EQ(s.document().settings.growth.split_angle_deg, angle0 + 5.0);
    const std::uint64_t seed0 = s.document().seed;
    poke(script, s, "SEED");
    EXPECT_NE(s.document().seed, seed0);

    // Both fists pulled apart to twice their distance: the scene doubles in size about them.
    script.move(Hand::Right, {0.15f, 1.25f, -0.35f}, 0.6);
    script.fist(Hand::Right, true);
    const glm::vec3 right_palm = script.hand(Hand::Right).tip;
    script.hand(Hand::Left) = {true, HandPose::Fist, right_palm - glm::vec3(0.3f, 0, 0), 0.05f};
    script.wait(0.3);
    const glm::vec3 mid = right_palm - glm::vec3(0.15f, 0, 0);
    script.move_both(mid - glm::vec3(0.3f, 0, 0), mid + glm::vec3(0.3f, 0, 0), 0.8);
    script.wait(0.3);
    EXPECT_NEAR(s.scene_transform().scale, 2.0f, 0.05f);
    EXPECT_NEAR(s.scene_transform().yaw, 0.0f, 0.02f);
    // The point between the hands stays where it was in the document.
    EXPECT_LT(glm::distance(s.scene_transform().to_document(mid), mid), 0.01f);
    const SceneTransform scaled = s.scene_transform();
    script.hand(Hand::Left).active = false;
    script.fist(Hand::Right, false);
    script.wait(0.3);
    EXPECT_EQ(s.scene_transform().scale, scaled.scale); // letting go keeps it

    // A loop of 10 cm drawn now is 5 cm in the document, and starts a new lobe there.
    poke(script, s, "NEW LOBE");
    EXPECT_EQ(s.status().tool, Tool::DrawLobe);
    const std::size_t strokes0 = s.document().strokes.size();
    script.pinch_along(Hand::Right, circle({0.35f, 1.5f, -0.5f}, X, Z, 0.05f));
    ASSERT_EQ(s.document().strokes.size(), strokes0 + 1);
    EXPECT_NEAR(extent(s.document().strokes.back()), 0.5f * 0.1f * std::sqrt(2.0f), 0.01f);
    EXPECT_EQ(s.document().lobes.size(), 2u);

    // Grow: the tree is built; the label says so.
    poke(script, s, "GROW");
    EXPECT_TRUE(s.status().grown);
    EXPECT_NE(s.status().label.find("TREE"), std::string::npos) << s.status().label;
    EXPECT_NE(s.status().label.find("CO2 "), std::string::npos) << s.status().label; // the tree's CO2, kg
    EXPECT_TRUE(s.status().tree_error.empty()) << s.status().tree_error;
    script.wait(0.2);

    const Document live = s.document();
    s.finish(script.time() + 0.01);
    EXPECT_EQ(load_document(o.session_path).strokes.size(), live.strokes.size());

    // The recording holds the panel's presses as key and setting events and the scene grab as
    // scene events; replayed without the panel it gives the same document.
    Recording rec = read_recording(o.record_path);
    int keys = 0, settings = 0, scene = 0;
    for (const InputEvent& e : rec.events) {
        keys += e.kind == InputEventKind::Key && e.value == 1;
        settings += e.kind == InputEventKind::Setting;
        scene += e.kind == InputEventKind::Scene;
    }
    EXPECT_EQ(keys, 8); // TRUNK, PINCH, BEND, MOVE, UNDO, REDO, NEW LOBE, GROW
    EXPECT_EQ(settings, 2);
    EXPECT_GT(scene, 5);
    Document replayed = cli::replay_into_document(o.record_path, Document{});
    replayed.source_recording = live.source_recording;
    EXPECT_EQ(document_to_json(replayed).dump(), document_to_json(live).dump());
}

// The live path: regrowth and autosave off the frame thread. What it draws once the regrowth
// arrived is what a scene built in one go from the same document draws (the tree's items are
// made on the worker, each stroke's tube only when the stroke changed), and the autosave on
// disk when the session ends is its last document.
/// The right hand raised, then three 12 cm loops drawn around one lobe (in three planes);
/// returns the lobe's centre.
glm::vec3 draw_three_loops(VrScript& script)
{
    script.hand(Hand::Right) = {true, HandPose::Open, {0.25f, 1.3f, -0.3f}, 0.05f};
    script.wait(0.3);
    const glm::vec3 c(0.15f, 1.45f, -0.45f);
    const glm::vec3 X(1, 0, 0), Y(0, 1, 0), Z(0, 0, 1);
    script.pinch_along(Hand::Right, circle(c, X, Z, 0.12f));
    script.pinch_along(Hand::Right, circle(c, X, Y, 0.12f));
    script.pinch_along(Hand::Right, circle(c, Z, Y, 0.12f));
    return c;
}

/// The vertices of the scene's items of `material` that show the document: its lobes or its
/// strokes' tubes (not the hands, the panel or its labels, whose keys start with 10).
std::vector<glm::vec3> scene_points(const VrSession& s, RenderMaterial material)
{
    std::vector<glm::vec3> out;
    for (const RenderItem& item : s.scene().items)
        if (item.material == material && (item.key >> 56) != 10)
            out.insert(out.end(), item.geometry.positions.begin(), item.geometry.positions.end());
    return out;
}

/// The farthest reach of those vertices along `axis` (0: x, 1: y, 2: z).
float farthest(const VrSession& s, RenderMaterial material, int axis)
{
    float most = -1e9f;
    for (const glm::vec3& p : scene_points(s, material)) most = std::max(most, p[axis]);
    return most;
}

/// Their mean.
glm::vec3 items_mean(const VrSession& s, RenderMaterial material)
{
    glm::dvec3 sum(0.0);
    const std::vector<glm::vec3> points = scene_points(s, material);
    for (const glm::vec3& p : points) sum += glm::dvec3(p);
    return points.empty() ? glm::vec3(0.0f) : glm::vec3(sum / double(points.size()));
}

/// A VR session that regrows on the frame thread, and the script that drives it.
struct ScriptedVr {
    VrSession s{Document{}, [] {
                    VrOptions o;
                    o.background_regrowth = false;
                    return o;
                }()};
    VrScript script{[this](const HandFrame& f) { s.frame(f); }};
};

/// The highest point of the scene's lobe (one lobe).
float lobe_top(const VrSession& s) { return farthest(s, RenderMaterial::Lobe, 1); }

TEST(VrSession, PinchDeformedLobeRisesWithTheFingertipWhileDraggedAndStaysWhereReleased)
{
    ScriptedVr vr;
    VrSession& s = vr.s;
    VrScript& script = vr.script;
    const glm::vec3 c = draw_three_loops(script);
    ASSERT_EQ(s.document().lobes.size(), 1u);
    const float top0 = lobe_top(s);
    EXPECT_NEAR(top0, c.y + 0.12f, 0.01f);

    poke(script, s, "PINCH");
    ASSERT_EQ(s.status().tool, Tool::DeformLobe);
    script.hand(Hand::Right).pose = HandPose::Open;
    script.move(Hand::Right, c + glm::vec3(0, 0.12f, 0), 0.5);
    script.pinch(Hand::Right, true);
    // Up 5 cm in five steps: after each the lobe's top is where the fingertip is.
    for (int k = 1; k <= 5; ++k) {
        script.move(Hand::Right, c + glm::vec3(0, 0.12f + 0.01f * float(k), 0), 0.1);
        script.wait(0.1);
        EXPECT_NEAR(lobe_top(s), top0 + 0.01f * float(k), 0.004f) << "step " << k;
    }
    EXPECT_EQ(s.document().edits.size(), 0u) << "the edit is made at release";
    const float dragged = lobe_top(s);
    script.pinch(Hand::Right, false);
    script.wait(0.2);
    ASSERT_EQ(s.document().edits.size(), 1u);
    EXPECT_STREQ(edit_kind_name(s.document().edits.back().kind()), "drag:deform-lobe");
    EXPECT_NEAR(lobe_top(s), dragged, 0.002f) << "the lobe built with the finished edit is where the drag left it";
}

TEST(VrSession, MovedLobeAndItsStrokesGoWithTheFingertipWhileDraggedAndStayWhereReleased)
{
    ScriptedVr vr;
    VrSession& s = vr.s;
    VrScript& script = vr.script;
    const glm::vec3 c = draw_three_loops(script);
    ASSERT_EQ(s.document().lobes.size(), 1u);
    const glm::vec3 lobe0 = items_mean(s, RenderMaterial::Lobe);
    const glm::vec3 strokes0 = items_mean(s, RenderMaterial::Stroke);

    poke(script, s, "MOVE");
    ASSERT_EQ(s.status().tool, Tool::MoveLobe);
    script.hand(Hand::Right).pose = HandPose::Open;
    script.move(Hand::Right, c, 0.5);
    script.pinch(Hand::Right, true);
    // 5 cm to the side in five steps: after each the lobe and its strokes have gone as far
    // again as the fingertip (the drag starts once the pinch is recognised, a little into the
    // first step), and nothing else moved. Exactly as far as the drag went is checked at the
    // release, against the path the edit recorded.
    glm::vec3 first(0.0f);
    for (int k = 1; k <= 5; ++k) {
        script.move(Hand::Right, c + glm::vec3(0.01f * float(k), 0, 0), 0.1);
        script.wait(0.1);
        const glm::vec3 lobe = items_mean(s, RenderMaterial::Lobe) - lobe0;
        const glm::vec3 strokes = items_mean(s, RenderMaterial::Stroke) - strokes0;
        if (k == 1) first = lobe;
        EXPECT_NEAR(lobe.x - first.x, 0.01f * float(k - 1), 0.005f) << "step " << k; // the tip filter lags a little
        EXPECT_NEAR(glm::length(lobe - strokes), 0.0f, 1e-4f) << "step " << k << ": the strokes go with the lobe";
        EXPECT_NEAR(lobe.y, 0.0f, 0.002f);
        EXPECT_NEAR(lobe.z, 0.0f, 0.002f);
    }
    EXPECT_GT(first.x, 0.0f);
    EXPECT_LE(first.x, 0.012f);
    EXPECT_EQ(s.document().edits.size(), 0u) << "the edit is made at release";
    const glm::vec3 lobe_dragged = items_mean(s, RenderMaterial::Lobe);
    const glm::vec3 strokes_dragged = items_mean(s, RenderMaterial::Stroke);
    script.pinch(Hand::Right, false);
    script.wait(0.2);
    ASSERT_EQ(s.document().edits.size(), 1u);
    EXPECT_STREQ(edit_kind_name(s.document().edits.back().kind()), "drag:move-lobe");
    // The lobe and strokes built with the finished edit are where the drag left them.
    EXPECT_LT(glm::distance(items_mean(s, RenderMaterial::Lobe), lobe_dragged), 0.002f);
    EXPECT_LT(glm::distance(items_mean(s, RenderMaterial::Stroke), strokes_dragged), 0.002f);
    // The edit is the drag as shown: from where the pinch began to where it was released.
    const std::vector<DragPoint>& path = s.document().edits.back().path;
    const glm::vec3 from(path.front().position), to(path.back().position);
    EXPECT_LT(glm::distance(lobe_dragged - lobe0, to - from), 0.001f);
    EXPECT_GT(glm::distance(items_mean(s, RenderMaterial::Lobe), lobe0), 0.04f);
}

TEST(VrSession, BentStrokeGoesWithTheFingertipWhileDraggedAndStaysWhereReleased)
{
    ScriptedVr vr;
    VrSession& s = vr.s;
    VrScript& script = vr.script;
    const glm::vec3 c = draw_three_loops(script);
    const float front0 = farthest(s, RenderMaterial::Stroke, 2);
    EXPECT_NEAR(front0, c.z + 0.12f, 0.01f);

    poke(script, s, "BEND");
    ASSERT_EQ(s.status().tool, Tool::EditStroke);
    script.hand(Hand::Right).pose = HandPose::Open;
    script.move(Hand::Right, c + glm::vec3(0, 0, 0.12f), 0.5);
    script.pinch(Hand::Right, true);
    // Out 4 cm in four steps: after each the bent loop reaches about as far as the fingertip.
    float last = front0;
    for (int k = 1; k <= 4; ++k) {
        script.move(Hand::Right, c + glm::vec3(0, 0, 0.12f + 0.01f * float(k)), 0.1);
        script.wait(0.1);
        const float front = farthest(s, RenderMaterial::Stroke, 2);
        EXPECT_GT(front, last) << "step " << k;
        EXPECT_NEAR(front, front0 + 0.01f * float(k), 0.006f) << "step " << k; // the tip filter lags a little
        last = front;
    }
    EXPECT_EQ(s.document().edits.size(), 0u) << "the edit is made at release";
    script.pinch(Hand::Right, false);
    script.wait(0.2);
    ASSERT_EQ(s.document().edits.size(), 1u);
    EXPECT_STREQ(edit_kind_name(s.document().edits.back().kind()), "drag:edit-stroke");
    EXPECT_NEAR(farthest(s, RenderMaterial::Stroke, 2), last, 0.002f) << "the stroke bent by the finished edit is where the drag left it";
}

TEST(VrSession, OffTheFrameThreadTheSceneIsTheOneBuiltInOneGoAndTheAutosaveIsTheLastDocument)
{
    const fs::path dir = scratch("background");
    VrOptions o;
    o.record_path = (dir / "vr.lrec").string();
    o.autosave_path = (dir / "autosave.json").string();
    o.background_regrowth = true;
    VrSession s(Document{}, o);
    VrScript script([&](const HandFrame& f) { s.frame(f); });
    const glm::vec3 c = draw_three_loops(script);
    poke(script, s, "TRUNK");
    script.pinch_along(Hand::Right, {c + glm::vec3(0, -0.45f, 0), c + glm::vec3(0.005f, -0.30f, 0), c + glm::vec3(0, -0.12f, 0)});
    poke(script, s, "GROW");
    // A stroke bent after the growth: its tube is made again, the others are kept.
    poke(script, s, "BEND");
    script.pinch_along(Hand::Right, {c + glm::vec3(0, 0, 0.12f), c + glm::vec3(0, 0, 0.16f)}, 0.1);
    ASSERT_EQ(s.document().edits.size(), 1u);
    s.wait_for_regrowth();
    script.wait(0.05); // one more frame: the hands and panel are drawn again

    const Document& doc = s.document();
    const BuiltTree tree = build_document_tree(doc);
    const TreeGeometry geometry = document_tree_geometry(doc, tree);
    std::vector<TriangleMesh> lobes;
    for (const BuiltLobe& l : tree.lobes) lobes.push_back(l.mesh);
    RenderContent content;
    content.lobes = content.strokes = true;
    content.lod = 1;
    const RenderScene expected = tree_render_scene(geometry, lobes, effective_strokes(doc), 0.0f, content);
    std::vector<std::pair<std::uint64_t, std::uint64_t>> want, got;
    for (const RenderItem& i : expected.items) want.emplace_back(i.key, i.version);
    for (const RenderItem& i : s.scene().items)
        if ((i.key >> 56) != 10) got.emplace_back(i.key, i.version); // 10: the hands, panel, labels
    std::sort(want.begin(), want.end());
    std::sort(got.begin(), got.end());
    EXPECT_EQ(got, want);
    EXPECT_GT(want.size(), 6u); // branches, leaves, a lobe, four strokes
    EXPECT_EQ(s.scene().leaf_texture.pixels, expected.leaf_texture.pixels);
    const Bounds area = scene_bounds(expected);
    EXPECT_LT(glm::distance(s.scene().ground_area.lo, area.lo), 1e-5f);
    EXPECT_LT(glm::distance(s.scene().ground_area.hi, area.hi), 1e-5f);

    const Document live = s.document();
    s.finish(script.time() + 0.01);
    Document saved = load_document(o.autosave_path);
    EXPECT_TRUE(saved.recording_finished);
    saved.recording_frames.reset();
    saved.recording_finished = false;
    EXPECT_EQ(document_to_json(saved).dump(), document_to_json(live).dump());
    for (const std::string& m : s.messages()) EXPECT_EQ(m.find("autosave failed"), std::string::npos) << m;
}

TEST(VrSession, AnAutosaveThatCannotBeWrittenIsReportedAndTheSessionGoesOn)
{
    const fs::path dir = scratch("autosave_fails");
    VrOptions o;
    o.autosave_path = (dir / "missing-folder" / "autosave.json").string();
    o.background_regrowth = true;
    VrSession s(Document{}, o);
    VrScript script([&](const HandFrame& f) { s.frame(f); });
    script.hand(Hand::Right) = {true, HandPose::Open, {0.25f, 1.3f, -0.3f}, 0.05f};
    script.wait(0.3);
    script.pinch_along(Hand::Right, circle({0.15f, 1.45f, -0.45f}, {1, 0, 0}, {0, 0, 1}, 0.12f));
    ASSERT_EQ(s.document().strokes.size(), 1u);
    s.finish(script.time() + 0.01);
    int failures = 0;
    for (const std::string& m : s.messages())
        if (m.rfind("autosave failed: ", 0) == 0) {
            ++failures;
            EXPECT_NE(m.find("missing-folder"), std::string::npos) << m;
            EXPECT_EQ(m.find('\n'), std::string::npos) << m;
        }
    EXPECT_GE(failures, 1);
    EXPECT_EQ(s.document().strokes.size(), 1u);
}

TEST(VrSession, HandsThatAreNeverTrackedMakeNoStrokesAndNoMessages)
{
    VrOptions o;
    o.background_regrowth = false;
    VrSession s(Document{}, o);
    for (int i = 0; i < 300; ++i) {
        HandFrame f;
        f.time = i / 90.0;
        f.head.position = {0, 1.6f, 0};
        f.head_valid = true;
        s.frame(f);
    }
    s.finish(4.0);
    EXPECT_TRUE(s.document().strokes.empty());
    EXPECT_TRUE(s.messages().empty()) << s.messages().front();
    EXPECT_FALSE(s.status().hands_tracked[0] || s.status().hands_tracked[1]);
    EXPECT_FALSE(s.status().regrowing) << "nothing was asked to regrow";
}

TEST(VrSession, EventTrackGivenIsAppliedAtItsTimesAndRecorded)
{
    const fs::path dir = scratch("events");
    VrOptions o;
    o.background_regrowth = false;
    o.record_path = (dir / "vr.lrec").string();
    InputEvent trunk;
    trunk.time = 0.5;
    trunk.kind = InputEventKind::Key;
    trunk.code = keys::kDrawTrunk;
    trunk.value = 1;
    o.events = {trunk};
    VrSession s(Document{}, o);
    VrScript script([&](const HandFrame& f) { s.frame(f); });
    script.wait(0.4);
    EXPECT_EQ(s.status().tool, Tool::DrawLobe);
    script.wait(0.2);
    EXPECT_EQ(s.status().tool, Tool::DrawTrunk);
    s.finish(script.time());
    const Recording rec = read_recording(o.record_path);
    ASSERT_EQ(rec.events.size(), 1u);
    EXPECT_EQ(rec.events[0].time, 0.5);
}

TEST(VrSession, TheStepButtonsSendTheGrowthStepsSettingAndStepTheGrowthOnAndBack)
{
    const fs::path dir = scratch("steps");
    VrOptions o;
    o.background_regrowth = false;
    o.record_path = (dir / "vr.lrec").string();
    Document start;
    GrowerChoice selforg;
    selforg.name = "self-organizing";
    selforg.params["iterations"] = std::int64_t{3};
    set_scene_grower(start, selforg);
    VrSession s(start, o);
    VrScript script([&](const HandFrame& f) { s.frame(f); });
    script.hand(Hand::Right) = {true, HandPose::Open, {0.25f, 1.3f, -0.3f}, 0.05f};
    script.wait(0.3);
    const auto iterations = [&] { return std::get<std::int64_t>(scene_grower(s.document()).params.at("iterations")); };
    poke(script, s, "STEP +");
    EXPECT_EQ(iterations(), 4);
    poke(script, s, "STEP -");
    poke(script, s, "STEP -");
    EXPECT_EQ(iterations(), 2);
    s.finish(script.time());
    const Recording rec = read_recording(o.record_path);
    std::vector<float> sent;
    for (const InputEvent& e : rec.events)
        if (e.kind == InputEventKind::Setting && e.code == static_cast<int>(SettingId::GrowthSteps)) sent.push_back(e.x);
    EXPECT_EQ(sent, (std::vector<float>{4.0f, 3.0f, 2.0f}));
}

TEST(VrSession, EyeInDocumentSeesTheScaledSceneAsTheStageEyeSeesItsStageImage)
{
    VrOptions o;
    o.background_regrowth = false;
    o.events = {InputEvent{0.0, InputEventKind::Scene, int(SceneComponent::Scale), 0, 0.5f, 0},
                InputEvent{0.0, InputEventKind::Scene, int(SceneComponent::Yaw), 0, 0.3f, 0},
                InputEvent{0.0, InputEventKind::Scene, int(SceneComponent::TranslationY), 0, 0.2f, 0}};
    VrSession s(Document{}, o);
    HandFrame f;
    f.time = 0.01;
    s.frame(f);
    const SceneTransform& t = s.scene_transform();
    ASSERT_FLOAT_EQ(t.scale, 0.5f);
    EyeView eye;
    eye.position = {0.1f, 1.6f, 0.2f};
    eye.orientation = glm::angleAxis(0.4f, glm::vec3(0, 1, 0));
    const EyeView d = s.eye_in_document(eye);
    // A document point seen along the eye's -Z in the stage is along the document eye's -Z.
    const glm::vec3 stage_point = eye.position + eye.orientation * glm::vec3(0, 0, -1.0f);
    const glm::vec3 doc_dir = glm::normalize(t.to_document(stage_point) - d.position);
    EXPECT_GT(glm::dot(doc_dir, d.orientation * glm::vec3(0, 0, -1)), 0.99999f);
    EXPECT_FLOAT_EQ(d.near_m, eye.near_m / 0.5f);
}

} // namespace
} // namespace lobe
