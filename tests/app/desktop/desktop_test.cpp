// The desktop app: the simulated hand, the session logic without a window, and the real
// window under Xvfb driven by a scripted mouse session (docs/desktop.md).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>
#include <glm/common.hpp>
#include <nlohmann/json.hpp>

#include "app/desktop/desktop_script.h"
#include "app/desktop/desktop_session.h"
#include "app/session/edit_hooks.h"
#include "app/session/panel_controls.h"
#include "app/session/session_file.h"
#include "app/session/tree_pipeline.h"
#include "growth/wood.h"
#include "core/atomic_file.h"
#include "core/errors.h"
#include "growth/grower.h"
#include "input/desktop_hand.h"
#include "input/gestures.h"
#include "input/pipeline.h"
#include "input/recording.h"
#include "app/session/session_builder.h"
#include "input/tools.h"
#include "tests/support/cli_run.h"
#include "tests/support/test_data.h"
#include "tests/support/test_paths.h"

namespace lobe {
namespace {

namespace fs = std::filesystem;
using test::cli_path;
using test::run_cli;
using test::temp_dir;

constexpr int kW = 640, kH = 360;

/// Drives a session like a person with a mouse: one frame per call at 60 Hz.
struct Driver {
    DesktopSession& s;
    int frame = 0;
    void step(int n = 1)
    {
        for (int i = 0; i < n; ++i) s.frame(++frame / 60.0, kW, kH);
    }
    void move(float x, float y)
    {
        s.mouse_move(x, y);
        step();
    }
    void press(int key)
    {
        s.key(key, true);
        s.key(key, false);
        step();
    }
    /// A left-button drag around a circle of `r` pixels (one turn and a little more).
    void circle(float cx, float cy, float r, int frames = 50, int button = desktop_keys::kMouseLeft)
    {
        move(cx + r, cy);
        s.mouse_button(button, true);
        step();
        for (int i = 1; i <= frames; ++i) {
            const double a = 2.0 * M_PI * 1.06 * i / frames;
            move(cx + r * float(std::cos(a)), cy - r * float(std::sin(a)));
        }
        s.mouse_button(button, false);
        step(6);
    }
    void drag(float x0, float y0, float x1, float y1, int frames, int button = desktop_keys::kMouseLeft)
    {
        move(x0, y0);
        s.mouse_button(button, true);
        step();
        for (int i = 1; i <= frames; ++i) {
            const float u = float(i) / float(frames);
            move(x0 + (x1 - x0) * u, y0 + (y1 - y0) * u);
        }
        s.mouse_button(button, false);
        step(6);
    }
};

DesktopOptions quiet_options(const std::string& dir = "")
{
    DesktopOptions o;
    o.background_regrowth = false;
    if (!dir.empty()) {
        o.session_path = dir + "/session.json";
        o.autosave_path = dir + "/session.autosave.json";
        o.record_path = dir + "/session.lrec";
        o.export_path = dir + "/session.glb";
    }
    return o;
}

// ---------------------------------------------------------------------------------------------
TEST(DesktopHand, PinchedHandPinchesWithTheIndexTipExactlyAtTheCursorPoint)
{
    const DesktopHandPose pose{glm::vec3(0.3f, 1.2f, -0.1f), glm::normalize(glm::vec3(0.2f, -0.3f, -1.0f)), true};
    const HandState h = desktop_hand(pose);
    EXPECT_TRUE(h.active);
    EXPECT_LT(glm::distance(h[Joint::IndexTip].pose.position, pose.tip), 1e-5f);
    const float gap = glm::distance(h[Joint::IndexTip].pose.position, h[Joint::ThumbTip].pose.position) -
                      h[Joint::IndexTip].radius - h[Joint::ThumbTip].radius;
    EXPECT_LT(gap, 0.004f) << "a pinched hand's thumb touches the index tip";

    DesktopHandPose open = pose;
    open.pinched = false;
    const HandState o = desktop_hand(open);
    const float open_gap = glm::distance(o[Joint::IndexTip].pose.position, o[Joint::ThumbTip].pose.position) -
                           o[Joint::IndexTip].radius - o[Joint::ThumbTip].radius;
    EXPECT_GT(open_gap, 0.03f);
}

TEST(DesktopHand, GestureRecogniserSeesPinchesAndNeverAGrab)
{
    GestureRecognizer g;
    int pinching = 0, grabbing = 0;
    for (int i = 0; i < 120; ++i) {
        const bool pinched = (i / 30) % 2 == 1; // open, pinched, open, pinched
        const DesktopHandPose pose{glm::vec3(0.01f * float(i), 1.1f, 0.0f), glm::vec3(0, 0, -1), pinched};
        const auto& hands = g.update(desktop_frame(i / 60.0, pose));
        const HandGesture& r = hands[static_cast<int>(Hand::Right)];
        if (r.pinch_started) ++pinching;
        if (r.grabbing) ++grabbing;
        if (i % 30 == 29) {
            EXPECT_EQ(r.pinching, pinched) << "frame " << i;
        }
    }
    EXPECT_EQ(pinching, 2);
    EXPECT_EQ(grabbing, 0);
}

TEST(OrbitCamera, CentrePixelRayLooksAtTheTargetAndEdgesSpanTheFieldOfView)
{
    OrbitCamera c;
    c.azimuth_deg = 30.0f;
    c.elevation_deg = 20.0f;
    const glm::vec3 centre = c.ray({kW / 2.0f - 0.5f, kH / 2.0f - 0.5f}, kW, kH);
    EXPECT_GT(glm::dot(centre, glm::normalize(c.target - c.eye())), 0.99999f);
    const glm::vec3 top = c.ray({kW / 2.0f - 0.5f, -0.5f}, kW, kH);
    EXPECT_NEAR(glm::degrees(std::acos(glm::dot(top, centre))), c.fov_y_deg / 2.0f, 0.05f);
}

// ---------------------------------------------------------------------------------------------
TEST(DesktopSession, MouseCircleDrawsOneLobeStrokeOnTheCameraFacingDepthPlane)
{
    DesktopSession s(Document{}, quiet_options());
    Driver d{s};
    d.move(320, 180);
    s.mouse_wheel(3.0f); // the plane moves 3 notches away
    d.step();
    const float depth = s.status().depth_m;
    EXPECT_GT(depth, s.orbit().distance_m);
    d.circle(320, 180, 60);
    ASSERT_EQ(s.document().strokes.size(), 1u);
    ASSERT_EQ(s.document().lobes.size(), 1u);
    const glm::vec3 eye = s.orbit().eye(), f = s.orbit().forward();
    for (const StrokePoint& p : s.document().strokes[0].points)
        EXPECT_NEAR(glm::dot(p.position - eye, f), depth, 0.004f); // the One Euro filter lags a little
    EXPECT_EQ(s.document().strokes[0].kind, StrokeKind::Lobe);
}

TEST(DesktopSession, PressOnThePanelNeverPinches)
{
    DesktopSession s(Document{}, quiet_options());
    Driver d{s};
    d.move(100, 100);
    s.set_ui_capture(true); // the cursor is over the panel when the button goes down
    d.circle(100, 100, 40);
    EXPECT_TRUE(s.document().strokes.empty());
}

TEST(DesktopSession, RightDragOrbitsMiddleDragPansShiftWheelZooms)
{
    DesktopSession s(Document{}, quiet_options());
    Driver d{s};
    const float az = s.orbit().azimuth_deg, dist = s.orbit().distance_m;
    const glm::vec3 target = s.orbit().target;
    d.drag(300, 200, 400, 200, 10, desktop_keys::kMouseRight);
    EXPECT_NEAR(s.orbit().azimuth_deg, az - 30.0f, 1e-3f);
    d.drag(300, 200, 300, 250, 10, desktop_keys::kMouseMiddle);
    EXPECT_GT(glm::distance(s.orbit().target, target), 0.1f);
    s.key(desktop_keys::kLeftShift, true);
    s.mouse_wheel(2.0f);
    s.key(desktop_keys::kLeftShift, false);
    d.step();
    EXPECT_NEAR(s.orbit().distance_m, dist * 0.81f, 1e-3f);
    EXPECT_TRUE(s.document().strokes.empty()) << "camera moves are not strokes";
}

/// Three rings seen from three sides, a trunk, a grown tree, a stroke edit and a move.
void sketch_tree(Driver& d)
{
    d.move(320, 180);
    d.circle(320, 180, 60);
    d.drag(480, 300, 680, 300, 8, desktop_keys::kMouseRight);
    d.circle(320, 180, 60);
    d.drag(480, 300, 680, 300, 8, desktop_keys::kMouseRight);
    d.circle(320, 180, 60);
    d.drag(680, 300, 280, 300, 8, desktop_keys::kMouseRight);
    d.press(keys::kDrawTrunk);
    d.drag(320, 335, 320, 244, 30);
    d.press(keys::kGrow);
    d.press(keys::kEditStroke);
    d.drag(380, 180, 396, 180, 12);
    d.press(keys::kMoveLobe);
    d.drag(320, 180, 336, 180, 12);
}

TEST(DesktopSession, SketchBuildsLobeAndTreeAndEveryChangeIsAutosaved)
{
    const std::string dir = temp_dir("desktop_autosave");
    DesktopSession s(Document{}, quiet_options(dir));
    Driver d{s};
    sketch_tree(d);
    s.wait_for_regrowth();
    d.step();
    const Document& doc = s.document();
    ASSERT_EQ(doc.lobes.size(), 1u);
    EXPECT_EQ(doc.lobes[0].stroke_ids.size(), 3u);
    EXPECT_EQ(doc.strokes.size(), 4u);
    ASSERT_EQ(doc.edits.size(), 2u) << s.status().last_message;
    EXPECT_STREQ(edit_kind_name(doc.edits[0].kind()), "drag:edit-stroke");
    EXPECT_STREQ(edit_kind_name(doc.edits[1].kind()), "drag:move-lobe");
    EXPECT_TRUE(s.status().grown);
    EXPECT_TRUE(s.status().tree_error.empty()) << s.status().tree_error;
    EXPECT_GT(s.status().tree_triangles, 1000u);
    // The panel's wood and CO2 are those of the tree shown (docs/wood-and-co2.md).
    const BuiltTree shown = build_document_tree(doc);
    const WoodEstimate wood = estimate_wood(shown.growth.tree, basic_wood_density(doc.settings.growth.species));
    EXPECT_GT(wood.co2_kg, 0.0);
    EXPECT_DOUBLE_EQ(s.status().wood_m3, wood.wood_volume_m3);
    EXPECT_DOUBLE_EQ(s.status().co2_kg, wood.co2_kg);
    // The autosave holds exactly the document as it is now, stamped with how much of the
    // recording it holds (docs/crash-safety.md).
    const auto unstamped = [](Document saved) {
        EXPECT_TRUE(saved.recording_frames.has_value());
        saved.recording_frames.reset();
        saved.recording_finished = false;
        return document_to_json(saved);
    };
    EXPECT_EQ(unstamped(load_document(dir + "/session.autosave.json")), document_to_json(doc));
    EXPECT_FALSE(fs::exists(dir + "/session.json")) << "only Save writes the session file";
    EXPECT_TRUE(s.save());
    EXPECT_EQ(unstamped(load_document(dir + "/session.json")), document_to_json(doc));
    EXPECT_TRUE(s.export_tree());
    EXPECT_GT(fs::file_size(dir + "/session.glb"), 10000u);
}

/// The lobe item of a desktop scene (one lobe).
const RenderItem* lobe_item(const DesktopSession& s)
{
    for (const RenderItem& item : s.scene().items)
        if (item.material == RenderMaterial::Lobe) return &item;
    return nullptr;
}

double largest_move(const SurfaceGeometry& a, const SurfaceGeometry& b)
{
    double most = 0.0;
    for (std::size_t v = 0; v < std::min(a.positions.size(), b.positions.size()); ++v)
        most = std::max(most, double(glm::distance(a.positions[v], b.positions[v])));
    return most;
}

/// `rings` loops drawn around one lobe, the view turned between them, and its lobe built.
void draw_rings(Driver& d, int rings)
{
    d.move(320, 180);
    for (int k = 0; k < rings; ++k) {
        if (k > 0) d.drag(480, 300, 680, 300, 8, desktop_keys::kMouseRight);
        d.circle(320, 180, 60);
    }
    d.s.wait_for_regrowth();
    d.step();
}

/// Picks `tool` and pinches at (x, y), until the pinch is recognised (a few frames after the
/// button goes down).
void start_drag(Driver& d, int tool, float x, float y)
{
    d.press(tool);
    d.move(x, y);
    d.s.mouse_button(desktop_keys::kMouseLeft, true);
    d.step(6);
    ASSERT_TRUE(d.s.status().drawing);
}

TEST(DesktopSession, PinchDeformedLobeFollowsTheFingertipFrameByFrameAndKeepsItsShapeAtRelease)
{
    DesktopSession s(Document{}, quiet_options());
    Driver d{s};
    draw_rings(d, 2);
    ASSERT_EQ(s.document().lobes.size(), 1u);
    ASSERT_NE(lobe_item(s), nullptr);
    const SurfaceGeometry before = lobe_item(s)->geometry;

    // Pinch on the second ring's rim (on the lobe) and pull outwards, frame by frame.
    start_drag(d, keys::kDeformLobe, 380, 180);
    const glm::vec3 start = s.status().tip;
    double last = 0.0;
    for (int i = 1; i <= 12; ++i) {
        d.move(380.0f + float(i), 180.0f);
        const RenderItem* item = lobe_item(s);
        ASSERT_NE(item, nullptr);
        ASSERT_EQ(item->geometry.positions.size(), before.positions.size());
        // The handle follows the fingertip (the pipeline's filtered tip lags the cursor a
        // little): what moved most moved about as far as the fingertip, and further each frame.
        const double moved = largest_move(item->geometry, before);
        const double pulled = glm::distance(s.status().tip, start);
        EXPECT_GT(moved, last) << "frame " << i;
        EXPECT_LT(moved, pulled + 0.002) << "frame " << i;
        EXPECT_GT(moved, pulled - 0.01) << "frame " << i;
        last = moved;
    }
    EXPECT_GT(last, 0.01);
    EXPECT_TRUE(s.document().edits.empty()) << "the edit is made at release";
    d.step(6); // held still: the fingertip filter catches up with the cursor
    const SurfaceGeometry dragged = lobe_item(s)->geometry;
    s.mouse_button(desktop_keys::kMouseLeft, false);
    d.step(6);
    ASSERT_EQ(s.document().edits.size(), 1u) << s.status().last_message;
    EXPECT_STREQ(edit_kind_name(s.document().edits[0].kind()), "drag:deform-lobe");
    // After the release the lobe is the one built with the finished edit: where the drag left it.
    const RenderItem* after = lobe_item(s);
    ASSERT_NE(after, nullptr);
    ASSERT_EQ(after->geometry.positions.size(), dragged.positions.size());
    EXPECT_LT(largest_move(after->geometry, dragged), 0.001);
    EXPECT_GT(largest_move(after->geometry, before), 0.01);
}

/// The scene's tubes of the document's strokes, by item key.
std::map<std::uint64_t, SurfaceGeometry> stroke_items(const DesktopSession& s)
{
    std::map<std::uint64_t, SurfaceGeometry> out;
    for (const RenderItem& item : s.scene().items)
        if (item.material == RenderMaterial::Stroke && (item.key >> 56) == 4) // 4: tree_render_scene's stroke items
            out.emplace(item.key, item.geometry);
    return out;
}

/// The largest distance of a vertex of `b` from where `a`'s moved by `t` (same vertex count).
double largest_miss(const SurfaceGeometry& a, const SurfaceGeometry& b, const glm::vec3& t)
{
    EXPECT_EQ(a.positions.size(), b.positions.size());
    double most = 0.0;
    for (std::size_t v = 0; v < std::min(a.positions.size(), b.positions.size()); ++v)
        most = std::max(most, double(glm::distance(a.positions[v] + t, b.positions[v])));
    return most;
}

TEST(DesktopSession, MovedLobeAndItsStrokesFollowTheFingertipFrameByFrameAndStayWhereReleased)
{
    DesktopSession s(Document{}, quiet_options());
    Driver d{s};
    draw_rings(d, 3);
    ASSERT_EQ(s.document().lobes.size(), 1u);
    ASSERT_NE(lobe_item(s), nullptr);
    const SurfaceGeometry before = lobe_item(s)->geometry;
    const auto strokes_before = stroke_items(s);
    ASSERT_EQ(strokes_before.size(), 3u);

    start_drag(d, keys::kMoveLobe, 320, 180);
    double last = 0.0;
    for (int i = 1; i <= 12; ++i) {
        d.move(320.0f + 2.0f * float(i), 180.0f);
        const RenderItem* item = lobe_item(s);
        ASSERT_NE(item, nullptr);
        // Every vertex of the lobe and of its strokes moved by one vector, further each frame.
        const glm::vec3 t = item->geometry.positions[0] - before.positions[0];
        EXPECT_LT(largest_miss(before, item->geometry, t), 1e-4) << "frame " << i;
        for (const auto& [key, tube] : stroke_items(s)) {
            ASSERT_TRUE(strokes_before.count(key));
            EXPECT_LT(largest_miss(strokes_before.at(key), tube, t), 1e-4) << "frame " << i;
        }
        EXPECT_GE(double(glm::length(t)), last) << "frame " << i;
        last = double(glm::length(t));
    }
    EXPECT_GT(last, 0.01);
    EXPECT_TRUE(s.document().edits.empty()) << "the edit is made at release";
    d.step(6); // held still: the fingertip filter catches up with the cursor
    const SurfaceGeometry dragged = lobe_item(s)->geometry;
    const auto strokes_dragged = stroke_items(s);
    s.mouse_button(desktop_keys::kMouseLeft, false);
    d.step(6);
    ASSERT_EQ(s.document().edits.size(), 1u) << s.status().last_message;
    EXPECT_STREQ(edit_kind_name(s.document().edits[0].kind()), "drag:move-lobe");
    // After the release the lobe and strokes are the ones built with the finished edit:
    // where the drag left them.
    const RenderItem* after = lobe_item(s);
    ASSERT_NE(after, nullptr);
    EXPECT_LT(largest_miss(dragged, after->geometry, glm::vec3(0.0f)), 0.001);
    for (const auto& [key, tube] : stroke_items(s)) EXPECT_LT(largest_miss(strokes_dragged.at(key), tube, glm::vec3(0.0f)), 0.001);
    EXPECT_GT(largest_move(after->geometry, before), 0.01);
}

TEST(DesktopSession, TurnedAndScaledLobesShowLiveWhatTheFinishedEditBuilds)
{
    for (const int tool : {keys::kRotateLobe, keys::kScaleLobe}) {
        SCOPED_TRACE(tool == keys::kRotateLobe ? "rotate" : "scale");
        DesktopSession s(Document{}, quiet_options());
        Driver d{s};
        draw_rings(d, 2);
        ASSERT_NE(lobe_item(s), nullptr);
        const SurfaceGeometry before = lobe_item(s)->geometry;
        const auto strokes_before = stroke_items(s);

        start_drag(d, tool, 380, 180); // on the rim: a lever arm of about the lobe's radius
        for (int i = 1; i <= 10; ++i) d.move(380.0f + 2.0f * float(i), 180.0f - 3.0f * float(i));
        d.step(30); // held still: the fingertip filter catches up with the cursor
        EXPECT_TRUE(s.document().edits.empty()) << "the edit is made at release";
        const SurfaceGeometry dragged = lobe_item(s)->geometry;
        const auto strokes_dragged = stroke_items(s);
        EXPECT_GT(largest_move(dragged, before), 0.01) << "the lobe is shown turned or scaled while dragged";
        for (const auto& [key, tube] : strokes_dragged) EXPECT_GT(largest_move(tube, strokes_before.at(key)), 0.005);
        s.mouse_button(desktop_keys::kMouseLeft, false);
        d.step(6);
        ASSERT_EQ(s.document().edits.size(), 1u) << s.status().last_message;
        EXPECT_EQ(s.document().edits[0].kind(), tool == keys::kRotateLobe ? EditKind::RotateLobe : EditKind::ScaleLobe);
        // As shown at the last frame of the drag.
        EXPECT_LT(largest_miss(dragged, lobe_item(s)->geometry, glm::vec3(0.0f)), 0.001);
        for (const auto& [key, tube] : stroke_items(s)) EXPECT_LT(largest_miss(strokes_dragged.at(key), tube, glm::vec3(0.0f)), 0.001);
    }
}

TEST(DesktopSession, BentStrokeFollowsTheFingertipFrameByFrameAndStaysWhereReleased)
{
    DesktopSession s(Document{}, quiet_options());
    Driver d{s};
    draw_rings(d, 2);
    const auto before = stroke_items(s);
    ASSERT_EQ(before.size(), 2u);

    start_drag(d, keys::kEditStroke, 380, 180); // on a ring: the drag picks it
    double last = 0.0;
    for (int i = 1; i <= 12; ++i) {
        d.move(380.0f + 2.0f * float(i), 180.0f);
        // One stroke bends further each frame; the other stays where it was.
        std::vector<double> moved;
        for (const auto& [key, tube] : stroke_items(s)) moved.push_back(largest_move(tube, before.at(key)));
        ASSERT_EQ(moved.size(), 2u);
        std::sort(moved.begin(), moved.end());
        EXPECT_EQ(moved[0], 0.0) << "frame " << i;
        EXPECT_GE(moved[1], last) << "frame " << i;
        last = moved[1];
    }
    EXPECT_GT(last, 0.01);
    EXPECT_TRUE(s.document().edits.empty()) << "the edit is made at release";
    d.step(6);
    const auto dragged = stroke_items(s);
    s.mouse_button(desktop_keys::kMouseLeft, false);
    d.step(6);
    ASSERT_EQ(s.document().edits.size(), 1u) << s.status().last_message;
    EXPECT_STREQ(edit_kind_name(s.document().edits[0].kind()), "drag:edit-stroke");
    // The document's stroke, bent by the finished edit, is where the drag left it.
    for (const auto& [key, tube] : stroke_items(s)) EXPECT_LT(largest_miss(dragged.at(key), tube, glm::vec3(0.0f)), 0.001);
}

/// The mean of the vertices of the scene's items of `material`.
glm::dvec3 items_mean(const DesktopSession& s, RenderMaterial material)
{
    glm::dvec3 sum(0.0);
    std::size_t n = 0;
    for (const RenderItem& item : s.scene().items)
        if (item.material == material)
            for (const glm::vec3& p : item.geometry.positions) {
                sum += glm::dvec3(p);
                ++n;
            }
    return n ? sum / double(n) : glm::dvec3(0.0);
}

TEST(DesktopSession, TheTreeRegrowsIntoALobeWhileItIsDraggedAndTheDocumentGetsOnlyTheFinishedEdit)
{
    DesktopSession s(Document{}, quiet_options());
    Driver d{s};
    d.move(320, 180);
    d.circle(320, 180, 60);
    d.drag(480, 300, 680, 300, 8, desktop_keys::kMouseRight);
    d.circle(320, 180, 60);
    d.press(keys::kDrawTrunk);
    d.drag(320, 335, 320, 244, 30);
    d.press(keys::kGrow);
    s.wait_for_regrowth();
    d.step();
    ASSERT_TRUE(s.status().grown);
    const std::size_t edits = s.document().edits.size();
    const std::string doc_before = document_to_json(s.document()).dump();
    const glm::dvec3 lobe0 = items_mean(s, RenderMaterial::Lobe), leaves0 = items_mean(s, RenderMaterial::Leaf);
    ASSERT_NE(leaves0, glm::dvec3(0.0));

    start_drag(d, keys::kMoveLobe, 320, 180);
    for (int i = 1; i <= 12; ++i) d.move(320.0f + 3.0f * float(i), 180.0f);
    d.step(6);
    // Before the release: the leaves grew again in the moved lobe, about as far over as it
    // went, and the document has no new edit yet.
    const glm::dvec3 moved = items_mean(s, RenderMaterial::Lobe) - lobe0;
    const glm::dvec3 leaves = items_mean(s, RenderMaterial::Leaf) - leaves0;
    EXPECT_GT(glm::length(moved), 0.02);
    EXPECT_GT(glm::dot(leaves, moved), 0.5 * glm::dot(moved, moved)) << "the crown follows the lobe while it is dragged";
    EXPECT_EQ(document_to_json(s.document()).dump(), doc_before);
    EXPECT_EQ(s.status().last_message.find("tree:"), std::string::npos);
    const glm::dvec3 leaves_dragged = items_mean(s, RenderMaterial::Leaf);
    s.mouse_button(desktop_keys::kMouseLeft, false);
    d.step(6);
    ASSERT_EQ(s.document().edits.size(), edits + 1);
    EXPECT_STREQ(edit_kind_name(s.document().edits.back().kind()), "drag:move-lobe");
    EXPECT_LT(glm::length(items_mean(s, RenderMaterial::Leaf) - leaves_dragged), 0.01);

    // A drag that edits nothing (it starts far from every lobe) leaves the tree as it was.
    const glm::dvec3 leaves_kept = items_mean(s, RenderMaterial::Leaf);
    d.drag(40, 40, 60, 60, 10);
    EXPECT_EQ(s.document().edits.size(), edits + 1);
    EXPECT_LT(glm::length(items_mean(s, RenderMaterial::Leaf) - leaves_kept), 1e-6);
}

TEST(DesktopSession, ADragThatWouldBreakALobeSaysSoWhileItGoesOnAndLeavesTheMessagesToTheDocument)
{
    DesktopSession s(Document{}, quiet_options());
    Driver d{s};
    draw_rings(d, 2);
    const std::size_t messages = s.messages().size();

    // Bend a point of a ring into the lobe's centre: a stroke through the centre cannot join.
    start_drag(d, keys::kEditStroke, 380, 180);
    for (int i = 1; i <= 15; ++i) d.move(380.0f - 4.0f * float(i), 180.0f);
    d.step(6);
    EXPECT_EQ(s.status().last_message.rfind("if released here: ", 0), 0u) << s.status().last_message;
    EXPECT_EQ(s.messages().size(), messages) << "nothing of a preview goes to the message list";
    EXPECT_TRUE(s.document().edits.empty());
}

TEST(DesktopSession, RecordingReplaysToTheSameDocument)
{
    const std::string dir = temp_dir("desktop_replay");
    Document live;
    {
        DesktopSession s(Document{}, quiet_options(dir));
        Driver d{s};
        sketch_tree(d);
        d.press(keys::kUndo);
        s.finish(d.frame / 60.0 + 0.1);
        live = s.document();
    }
    const Recording rec = read_recording(dir + "/session.lrec");
    EXPECT_GT(rec.frames.size(), 250u);
    const InputResult input = run_input_pipeline(rec, Document{}.settings.input);
    SessionBuilder builder(Document{}, EditPickOptions{}, meshing_edit_hooks());
    builder.apply(input.actions);
    Document replayed = builder.take_document();
    replayed.source_recording = live.source_recording;
    EXPECT_EQ(document_to_json(replayed), document_to_json(live));
    EXPECT_EQ(live.edits.size(), 1u) << "the undo took back the move";
}

/// A press of the Grower section's step button: what desktop_panel.cpp sends.
void press_step(DesktopSession& s, int delta)
{
    const std::optional<double> v = growth_steps_after(scene_grower(s.document()), delta);
    ASSERT_TRUE(v) << "the grower has no step buttons";
    s.setting(static_cast<int>(SettingId::GrowthSteps), 0, *v);
}

TEST(DesktopSession, TheGrowerStepButtonsStepTheGrowthOnAndBackAndTheRecordingReplaysThem)
{
    const std::string dir = temp_dir("desktop_steps");
    Document start;
    GrowerChoice selforg;
    selforg.name = "self-organizing";
    selforg.params["iterations"] = std::int64_t{3};
    set_scene_grower(start, selforg);
    Document live;
    {
        DesktopSession s(start, quiet_options(dir));
        Driver d{s};
        d.step(2);
        const auto iterations = [&] { return std::get<std::int64_t>(scene_grower(s.document()).params.at("iterations")); };
        press_step(s, +1);
        d.step();
        EXPECT_EQ(iterations(), 4);
        press_step(s, -1);
        d.step();
        press_step(s, -1);
        d.step();
        EXPECT_EQ(iterations(), 2);
        EXPECT_EQ(growth_steps(scene_grower(s.document())), 2);
        // The subtrees grower has no step buttons; a step sent anyway is refused, in one line.
        s.setting(static_cast<int>(SettingId::Grower), 0, find_grower("subtrees")->panel_code());
        d.step();
        EXPECT_FALSE(growth_steps_after(scene_grower(s.document()), +1));
        s.setting(static_cast<int>(SettingId::GrowthSteps), 0, 5);
        d.step();
        ASSERT_FALSE(s.messages().empty());
        EXPECT_NE(s.messages().back().find("does not grow in steps"), std::string::npos) << s.messages().back();
        EXPECT_EQ(scene_grower(s.document()).name, "subtrees");
        s.finish(d.frame / 60.0 + 0.1);
        live = s.document();
    }
    const Recording rec = read_recording(dir + "/session.lrec");
    const InputResult input = run_input_pipeline(rec, start.settings.input);
    SessionBuilder builder(start, EditPickOptions{}, meshing_edit_hooks());
    builder.apply(input.actions);
    Document replayed = builder.take_document();
    replayed.source_recording = live.source_recording;
    EXPECT_EQ(document_to_json(replayed), document_to_json(live));
}

TEST(DesktopSession, ImportedMeshIsALobeAtTheFingertipAndTheRecordingReplaysIt)
{
    const std::string spot = test::shared_data("data/models/spot.obj");
    if (spot.empty()) return;
    const std::string dir = temp_dir("desktop_import");
    Document live;
    glm::vec3 tip(0.0f);
    {
        DesktopSession s(Document{}, quiet_options(dir));
        Driver d{s};
        d.move(320, 180);
        d.step(3);
        EXPECT_FALSE(s.import_mesh(dir + "/missing.obj"));
        EXPECT_EQ(s.status().last_message.rfind("import: ", 0), 0u) << s.status().last_message;
        ASSERT_TRUE(s.import_mesh(spot, 0.5)) << s.status().last_message;
        // Made on its own thread: it goes in with the first frame after it is done.
        EXPECT_TRUE(s.status().importing);
        EXPECT_TRUE(s.document().lobes.empty());
        s.wait_for_import();
        EXPECT_FALSE(s.status().importing);
        tip = s.status().tip;
        d.step();
        ASSERT_EQ(s.document().lobes.size(), 1u) << s.status().last_message;
        const LobeRecord& l = s.document().lobes[0];
        ASSERT_TRUE(l.model);
        EXPECT_EQ(l.model->source, "session.lrec.import-1.ply");
        glm::vec3 lo(1e9f), hi(-1e9f);
        for (const glm::vec3& p : l.model->mesh.positions) {
            lo = glm::min(lo, p);
            hi = glm::max(hi, p);
        }
        EXPECT_LT(glm::distance(0.5f * (lo + hi), tip), 0.005f) << "centred on the fingertip";
        EXPECT_NEAR(std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z}), 0.5f, 0.02f);
        EXPECT_TRUE(fs::exists(dir + "/session.lrec.import-1.ply"));
        // It grows a tree like a lobe of strokes, and undo takes the import back.
        d.press(keys::kGrow);
        s.wait_for_regrowth();
        d.step();
        EXPECT_TRUE(s.status().tree_error.empty()) << s.status().tree_error;
        EXPECT_GT(s.status().tree_triangles, 1000u);
        d.press(keys::kUndo);
        EXPECT_TRUE(s.document().lobes.empty());
        d.press(keys::kRedo);
        EXPECT_EQ(s.document().lobes.size(), 1u);
        s.finish(d.frame / 60.0 + 0.1);
        live = s.document();
    }
    const test::CliRun run = run_cli("replay " + dir + "/session.lrec --out " + dir + "/replayed");
    ASSERT_EQ(run.code, 0) << run.out;
    Document replayed = load_document(dir + "/replayed/session.json");
    ASSERT_EQ(replayed.lobes.size(), 1u);
    EXPECT_EQ(replayed.lobes[0].mesh_file, "lobes/lobe_1.ply"); // replay writes the lobe's mesh
    replayed.lobes[0].mesh_file.clear();
    EXPECT_EQ(document_to_json(replayed)["lobes"], document_to_json(live)["lobes"]);
}

TEST(DesktopSession, AnImportIsMadeBesideTheFramesOneAtATimeAndABadFileIsReportedWhenItEnds)
{
    const std::string cow = test::shared_data("data/models/cow.obj");
    if (cow.empty()) return;
    const std::string dir = temp_dir("desktop_import_async");
    DesktopSession s(Document{}, quiet_options(dir));
    Driver d{s};
    d.move(320, 180);
    d.step(3);
    // A file that exists but is no mesh: the import starts, and says why when it ends.
    const std::string bad = dir + "/bad.obj";
    {
        std::ofstream out(bad);
        out << "v 0 0 0\nv 1 0 0\nf 1 2 7\n";
    }
    ASSERT_TRUE(s.import_mesh(bad));
    // One import at a time: a second one while the first is being made is refused.
    EXPECT_FALSE(s.import_mesh(cow));
    EXPECT_EQ(s.status().last_message, "import: another import is still being made");
    s.wait_for_import();
    d.step(2);
    EXPECT_FALSE(s.status().importing);
    EXPECT_EQ(s.status().last_message.rfind("import: ", 0), 0u) << s.status().last_message;
    EXPECT_EQ(s.status().last_message.find('\n'), std::string::npos);
    EXPECT_TRUE(s.document().lobes.empty());
    // The next import works; frames drawn while it is being made go on as usual.
    ASSERT_TRUE(s.import_mesh(cow, 0.8)) << s.status().last_message;
    const std::uint64_t revision = s.status().revision;
    while (s.status().importing) {
        d.step();
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    d.step();
    EXPECT_GT(s.status().revision, revision);
    ASSERT_EQ(s.document().lobes.size(), 1u) << s.status().last_message;
    EXPECT_TRUE(s.document().lobes[0].model);
}

// ---------------------------------------------------------------------------------------------
TEST(DesktopScript, ParsesMacrosAndRefusesBadLinesWithTheirLineNumber)
{
    const auto steps = parse_desktop_script("0 move 1 2\n3 circle 100 100 10 4 # comment\n10 ui undo\n", "s.script");
    // move; circle: move, down, 4 moves, up; ui
    ASSERT_EQ(steps.size(), 9u);
    EXPECT_EQ(steps[2].kind, ScriptStep::Kind::Down);
    EXPECT_EQ(steps[2].frame, 4);
    EXPECT_EQ(steps[7].kind, ScriptStep::Kind::Up);
    EXPECT_EQ(steps[7].frame, 9);
    EXPECT_EQ(steps[8].kind, ScriptStep::Kind::Panel);
    const auto imports = parse_desktop_script("1 import models/cow.obj 0.8\n2 import spot.off\n", "s.script");
    ASSERT_EQ(imports.size(), 2u);
    EXPECT_EQ(imports[0].kind, ScriptStep::Kind::Import);
    EXPECT_EQ(imports[0].name, "models/cow.obj");
    EXPECT_EQ(imports[0].value, 0.8);
    EXPECT_EQ(imports[1].value, 1.5);
    // The bounds themselves are accepted.
    const auto far = parse_desktop_script("0 move 1000000 -1000000\n1 wheel -10000\n2 set seed 1000000000\n", "s.script");
    ASSERT_EQ(far.size(), 3u);
    EXPECT_EQ(far[0].x, 1e6f);
    EXPECT_EQ(far[1].y, -1e4f);
    for (const char* bad : {"0 fly 1 2", "x move 1 2", "5 move 1 2\n4 move 1 2", "0 move 1", "0 key nosuchkey",
                            "0 set split-angle nan", "0 circle 1 2 3 1", "0 ui nothing", "0 move 1e999 2", "0 import",
                            "0 import a.obj 0", "0 import a.obj 2 3",
                            // Finite, but beyond what the input events' floats hold (found by
                            // the desktop_script fuzz target: a circle centre of 5.5e107).
                            "0 move 1e300 0", "0 move 0 -2e6", "0 wheel 1e5", "0 set seed 1e12",
                            "0 circle 360 5e107 60 50", "0 line 0 0 3e38 0 8"}) {
        try {
            parse_desktop_script(bad, "s.script");
            ADD_FAILURE() << "accepted: " << bad;
        } catch (const InvalidInput& e) {
            EXPECT_NE(std::string(e.what()).find("s.script:"), std::string::npos) << e.what();
            EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
        }
    }
}

// ---------------------------------------------------------------------------------------------
// The real window: `lobesketch desktop` under Xvfb (package xvfb, installed by scripts/setup.sh).
bool have_xvfb() { return std::system("command -v xvfb-run >/dev/null 2>&1") == 0; }

std::string xvfb(const std::string& args)
{
    return "xvfb-run -a -s '-screen 0 800x600x24' " + cli_path() + " desktop " + args;
}

test::CliRun run_shell(const std::string& cmd)
{
    test::CliRun r;
    FILE* p = ::popen((cmd + " 2>&1").c_str(), "r");
    if (!p) return r;
    char buf[4096];
    while (std::size_t n = std::fread(buf, 1, sizeof buf, p)) r.out.append(buf, n);
    const int status = ::pclose(p);
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    return r;
}

std::vector<nlohmann::json> read_marks(const std::string& path)
{
    std::vector<nlohmann::json> marks;
    std::ifstream in(path);
    for (std::string line; std::getline(in, line);)
        if (!line.empty()) marks.push_back(nlohmann::json::parse(line));
    return marks;
}

TEST(DesktopApp, ScriptedMouseSessionInAWindowExercisesEveryToolAndReplaysAlike)
{
    if (!have_xvfb()) GTEST_SKIP() << "xvfb-run is missing (scripts/setup.sh installs package xvfb)";
    const std::string script = test::source_data("tests/data/desktop_every_tool.script");
    if (script.empty()) return;
    const std::string dir = temp_dir("desktop_app");
    const std::string session = dir + "/tree.json";
    const test::CliRun r = run_shell(xvfb(session + " --size 720x360 --software --samples 1 --script " +
                                          script + " --script-log " + dir +
                                          "/marks.jsonl --record " + dir + "/tree.lrec --screenshot " + dir + "/shot.png"));
    ASSERT_EQ(r.code, 0) << r.out;
    const auto marks = read_marks(dir + "/marks.jsonl");
    std::map<std::string, nlohmann::json> m;
    for (const auto& j : marks) m[j["mark"].get<std::string>()] = j;
    ASSERT_EQ(marks.size(), 17u) << r.out;
    auto n = [&](const char* mark, const char* what) { return m.at(mark).at(what).size(); };
    auto last_edit = [&](const char* mark) { return m.at(mark).at("edits").back().at("type").get<std::string>(); };

    EXPECT_EQ(n("start", "strokes"), 0u);
    EXPECT_EQ(n("lobe", "strokes"), 3u);
    ASSERT_EQ(n("lobe", "lobes"), 1u);
    EXPECT_EQ(m["lobe"]["lobes"][0]["strokes"].size(), 3u);
    EXPECT_EQ(n("trunk", "strokes"), 4u);
    EXPECT_EQ(m["trunk"]["strokes"][3]["kind"], "trunk");
    EXPECT_TRUE(m["grown"]["grown"].get<bool>());
    EXPECT_GT(m["grown"]["tree_triangles"].get<int>(), 1000) << m["grown"]["tree_error"];
    ASSERT_EQ(n("edit-stroke", "edits"), 1u) << m["edit-stroke"]["last_message"];
    EXPECT_EQ(last_edit("edit-stroke"), "drag:edit-stroke");
    ASSERT_EQ(n("deform", "edits"), 2u) << m["deform"]["last_message"];
    EXPECT_EQ(last_edit("deform"), "drag:deform-lobe");
    ASSERT_EQ(n("move", "edits"), 3u) << m["move"]["last_message"];
    EXPECT_EQ(last_edit("move"), "drag:move-lobe");
    ASSERT_EQ(n("rotate", "edits"), 4u) << m["rotate"]["last_message"];
    EXPECT_EQ(last_edit("rotate"), "drag:rotate-lobe");
    EXPECT_EQ(n("undo", "edits"), 3u);
    EXPECT_EQ(n("redo", "edits"), 4u);
    EXPECT_EQ(n("duplicate", "lobes"), 2u) << m["duplicate"]["last_message"];
    EXPECT_EQ(n("duplicate", "strokes"), 7u);
    EXPECT_EQ(n("mirror", "lobes"), 3u) << m["mirror"]["last_message"];
    EXPECT_EQ(n("mirror", "strokes"), 10u);
    EXPECT_EQ(n("delete-stroke", "strokes"), 9u) << m["delete-stroke"]["last_message"];
    EXPECT_EQ(n("undo-delete", "strokes"), 10u);
    EXPECT_EQ(m["settings"]["settings"]["growth"]["split_angle_deg"].get<double>(), 45.0);
    EXPECT_EQ(m["settings"]["lobes"][0]["species"], "conifer");
    EXPECT_TRUE(m["grown"]["tree_error"].get<std::string>().empty());

    // Saved and exported; the saved session is the document of the last mark.
    ASSERT_TRUE(fs::exists(session)) << r.out;
    const Document saved = load_document(session);
    EXPECT_EQ(saved.strokes.size(), 10u);
    EXPECT_EQ(saved.lobes.size(), 3u);
    EXPECT_GT(fs::file_size(dir + "/tree.glb"), 10000u);
    EXPECT_GT(fs::file_size(dir + "/shot.png"), 1000u);

    // The recording replays to the same document.
    const test::CliRun rp = run_cli("replay " + dir + "/tree.lrec --out " + dir + "/replayed");
    ASSERT_EQ(rp.code, 0) << rp.out;
    Document replayed = load_document(dir + "/replayed/session.json");
    replayed.source_recording = saved.source_recording;
    EXPECT_EQ(document_to_json(replayed)["strokes"], document_to_json(saved)["strokes"]);
    auto lobes_without_mesh_files = [](const Document& d) { // replay writes lobe meshes beside its session
        nlohmann::json lobes = document_to_json(d)["lobes"];
        for (auto& l : lobes) l.erase("mesh");
        return lobes;
    };
    EXPECT_EQ(lobes_without_mesh_files(replayed), lobes_without_mesh_files(saved));
    EXPECT_EQ(document_to_json(replayed)["edits"], document_to_json(saved)["edits"]);
    EXPECT_EQ(document_to_json(replayed)["settings"], document_to_json(saved)["settings"]);
}

TEST(DesktopApp, CorruptSessionOffersTheAutosaveAndOverwritesNothing)
{
    if (!have_xvfb()) GTEST_SKIP() << "xvfb-run is missing (scripts/setup.sh installs package xvfb)";
    const std::string script = test::source_data("tests/data/desktop_save.script");
    if (script.empty()) return;
    const std::string dir = temp_dir("desktop_corrupt");
    const std::string session = dir + "/tree.json";
    const std::string corrupt = "{\"version\": 1, \"strokes\": [ {\"id\": 1, \"points\": [[0, 1,";
    write_file_atomic(session, corrupt);
    Document good;
    good.seed = 7;
    save_document(dir + "/tree.autosave.json", good);
    const std::string autosave_before = read_file_limited(dir + "/tree.autosave.json", 1u << 20);

    const test::CliRun r = run_shell(xvfb(session + " --size 320x240 --software --frames 2"));
    EXPECT_EQ(r.code, 1) << r.out;
    EXPECT_NE(r.out.find("tree.json"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("--recover"), std::string::npos) << r.out;
    EXPECT_EQ(read_file_limited(session, 1u << 20), corrupt) << "the damaged file is left as it was";

    const test::CliRun rec = run_shell(xvfb(session + " --recover --size 320x240 --software --frames 3 --script " +
                                            script));
    ASSERT_EQ(rec.code, 0) << rec.out;
    EXPECT_EQ(read_file_limited(session, 1u << 20), corrupt);
    const Document recovered = load_document(dir + "/tree.recovered.json");
    EXPECT_EQ(recovered.seed, 7u);
    EXPECT_EQ(read_file_limited(dir + "/tree.autosave.json", 1u << 20), autosave_before);
}

TEST(DesktopApp, NewerDifferentAutosaveIsPointedOutWhenTheSessionOpens)
{
    if (!have_xvfb()) GTEST_SKIP() << "xvfb-run is missing (scripts/setup.sh installs package xvfb)";
    const std::string dir = temp_dir("desktop_newer_autosave");
    const std::string session = dir + "/tree.json";
    save_document(session, Document{});
    Document later;
    later.seed = 9;
    save_document(dir + "/tree.autosave.json", later);
    fs::last_write_time(dir + "/tree.autosave.json", fs::last_write_time(session) + std::chrono::seconds(5));
    const std::string before = read_file_limited(session, 1u << 20);
    const test::CliRun r = run_shell(xvfb(session + " --size 320x240 --software --frames 2"));
    EXPECT_EQ(r.code, 0) << r.out;
    EXPECT_NE(r.out.find("is newer than"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("--recover"), std::string::npos) << r.out;
    EXPECT_EQ(read_file_limited(session, 1u << 20), before) << "opening never writes the session";
}

TEST(DesktopApp, WithoutADisplayItSaysHowToGetOneAndFails)
{
    const test::CliRun r = run_cli("desktop --frames 1", "env -u DISPLAY -u WAYLAND_DISPLAY");
    EXPECT_EQ(r.code, 1) << r.out;
    EXPECT_NE(r.out.find("xvfb-run"), std::string::npos) << r.out;
}

} // namespace
} // namespace lobe
