// Drags becoming edit operations (app/session/session_builder.h) and operations re-applied to a
// document's strokes and lobes (app/session/edit_ops.h).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include "app/session/edit_hooks.h"
#include "core/document.h"
#include "app/session/session_builder.h"
#include "app/session/edit_ops.h"

using namespace lobe;

namespace {

constexpr double kPi = 3.14159265358979323846;
const glm::dvec3 kCentre(0.05, 1.40, -0.42);

/// A raw lobe loop as the pipeline gives it: n points, no repeated end point, closed=false.
/// `plane` 0: horizontal (XZ), 1: frontal (XY), 2: sagittal (YZ).
Stroke loop(std::int64_t id, int plane, glm::dvec3 centre = kCentre, double radius = 0.15, int n = 180)
{
    Stroke s;
    s.id = id;
    for (int i = 0; i < n; ++i) {
        const double a = 2 * kPi * i / n, c = radius * std::cos(a), d = radius * std::sin(a);
        glm::dvec3 off = plane == 0 ? glm::dvec3(c, 0, d) : plane == 1 ? glm::dvec3(c, d, 0) : glm::dvec3(0, c, d);
        s.points.push_back({glm::vec3(centre + off), 1.0 * double(id) + 0.01 * i});
    }
    return s;
}

/// An open trunk stroke going up from below the lobe.
Stroke trunk(std::int64_t id)
{
    Stroke s;
    s.id = id;
    s.kind = StrokeKind::Trunk;
    for (int i = 0; i <= 60; ++i) s.points.push_back({glm::vec3(0.05f, 0.9f + 0.005f * float(i), -0.42f), 0.01 * i});
    return s;
}

InputAction stroke_action(const Stroke& s)
{
    InputAction a;
    a.type = InputAction::Type::StrokeCompleted;
    a.stroke = s;
    return a;
}

InputAction new_lobe()
{
    InputAction a;
    a.type = InputAction::Type::NewLobe;
    return a;
}

InputAction drag_action(Tool tool, glm::vec3 from, glm::vec3 to, std::optional<glm::vec3> other = std::nullopt,
                        double t0 = 100.0)
{
    InputAction a;
    a.type = InputAction::Type::DragCompleted;
    a.time = t0 + 1.0;
    a.drag.tool = tool;
    a.drag.hand = Hand::Right;
    for (int i = 0; i <= 10; ++i)
        a.drag.path.push_back({from + (to - from) * (float(i) / 10.0f), t0 + 0.1 * i});
    a.drag.other_tip = other;
    return a;
}

InputAction simple(InputAction::Type t)
{
    InputAction a;
    a.type = t;
    return a;
}

/// Three loops in lobe 1 (strokes 1–3), a trunk (4), and a second lobe of one loop (5) 60 cm
/// to the right.
SessionBuilder scene(EditHooks hooks = {})
{
    SessionBuilder b(Document{}, EditPickOptions{}, std::move(hooks));
    b.apply({stroke_action(loop(1, 0)), stroke_action(loop(2, 1)), stroke_action(loop(3, 2)), stroke_action(trunk(4)),
             new_lobe(), stroke_action(loop(5, 0, kCentre + glm::dvec3(0.6, 0, 0), 0.1))});
    return b;
}

glm::vec3 point(const Document& d, std::int64_t stroke, std::size_t i)
{
    for (const Stroke& s : d.strokes)
        if (s.id == stroke) return s.points[i].position;
    throw std::logic_error("no stroke");
}

const Stroke& by_id(const std::vector<Stroke>& v, std::int64_t id)
{
    for (const Stroke& s : v)
        if (s.id == id) return s;
    throw std::logic_error("no stroke");
}

bool same_bits(const Stroke& a, const Stroke& b)
{
    if (a.points.size() != b.points.size()) return false;
    for (std::size_t i = 0; i < a.points.size(); ++i)
        if (std::memcmp(&a.points[i].position, &b.points[i].position, sizeof(glm::vec3)) != 0 ||
            a.points[i].time != b.points[i].time)
            return false;
    return true;
}

/// The first or last point of an operation's recorded path.
glm::dvec3 path_end(const EditOperation& op, bool last)
{
    return last ? op.path.back().position : op.path.front().position;
}

glm::dvec3 recorded_centre(const EditOperation& op) { return op.transform_params()->centre.value(); }

/// A transform operation's `strokes` list as the operation holds it.
std::optional<std::vector<std::int64_t>> ids(std::initializer_list<std::int64_t> list)
{
    return std::vector<std::int64_t>(list);
}

void expect_near(const glm::vec3& a, const glm::vec3& b, float tol)
{
    EXPECT_LE(glm::distance(a, b), tol) << "(" << a.x << ", " << a.y << ", " << a.z << ") vs (" << b.x << ", " << b.y
                                        << ", " << b.z << ")";
}

} // namespace

TEST(SessionBuilder, EditStrokeDragTargetsTheStrokeNearestItsStart)
{
    SessionBuilder b = scene();
    ASSERT_EQ(b.document().lobes.size(), 2u);
    // 1 cm above point 45 of the frontal loop (stroke 2), pulled 4 cm outwards.
    const glm::vec3 p = point(b.document(), 2, 45) + glm::vec3(0.0f, 0.01f, 0.0f);
    EXPECT_TRUE(b.apply(drag_action(Tool::EditStroke, p, p + glm::vec3(0.0f, 0.04f, 0.0f))));
    ASSERT_EQ(b.document().edits.size(), 1u);
    const EditOperation op = b.document().edits[0];
    EXPECT_STREQ(edit_kind_name(op.kind()), "drag:edit-stroke");
    EXPECT_STREQ(edit_kind_name(op.kind()), "drag:edit-stroke");
    EXPECT_EQ(op.target, 2);
    EXPECT_EQ(op.hand, Hand::Right);
    EXPECT_EQ(op.path.size(), 11u);
    EXPECT_TRUE(op.path[0].time.has_value()); // x, y, z, t
    ASSERT_NE(op.stroke_params(), nullptr);
    EXPECT_EQ(op.stroke_params()->pick_distance_m, std::optional<double>(0.03));
    EXPECT_EQ(op.stroke_params()->half_length_m, std::optional<double>(0.08));
    EXPECT_FALSE(op.stroke_params()->other_tip.has_value());
    EXPECT_TRUE(b.messages().empty());

    // With the other hand pointing at another point of the same stroke.
    const glm::vec3 q = point(b.document(), 2, 80);
    EXPECT_TRUE(b.apply(drag_action(Tool::EditStroke, p, p + glm::vec3(0.0f, 0.04f, 0.0f), q)));
    const EditOperation& two = b.document().edits.back();
    EXPECT_EQ(two.target, 2);
    ASSERT_TRUE(two.stroke_params()->other_tip.has_value());
    EXPECT_EQ(two.stroke_params()->other_tip->y, static_cast<double>(q.y));
    EXPECT_GT(two.id, op.id);

    // The trunk is a stroke too.
    const glm::vec3 t = point(b.document(), 4, 30) + glm::vec3(0.01f, 0.0f, 0.0f);
    EXPECT_TRUE(b.apply(drag_action(Tool::EditStroke, t, t + glm::vec3(0.03f, 0.0f, 0.0f))));
    EXPECT_EQ(b.document().edits.back().target, 4);

    // Undo and redo walk the edits like strokes.
    b.apply(simple(InputAction::Type::Undo));
    EXPECT_EQ(b.document().edits.size(), 2u);
    b.apply(simple(InputAction::Type::Redo));
    EXPECT_EQ(b.document().edits.size(), 3u);
}

TEST(SessionBuilder, DragThatPicksNothingIsRecordedAsNothingWithAWarning)
{
    SessionBuilder b = scene();
    const std::size_t strokes = b.document().strokes.size();
    const glm::vec3 far(0.05f, 2.2f, -0.42f); // 65 cm above the lobe
    EXPECT_FALSE(b.apply(drag_action(Tool::EditStroke, far, far + glm::vec3(0.0f, 0.05f, 0.0f))));
    EXPECT_FALSE(b.apply(drag_action(Tool::MoveLobe, far, far + glm::vec3(0.0f, 0.05f, 0.0f))));
    const glm::vec3 off = point(b.document(), 2, 45) + glm::vec3(0.0f, 0.01f, 0.0f);
    EXPECT_FALSE(b.apply(drag_action(Tool::EditStroke, off, off + glm::vec3(0.0f, 0.04f, 0.0f), far)));
    EXPECT_TRUE(b.document().edits.empty());
    ASSERT_EQ(b.messages().size(), 3u);
    EXPECT_EQ(b.messages()[0],
              "edit-stroke drag at t=100.00s edits nothing: its start is 65.0 cm from the nearest stroke (pick "
              "distance 3.0 cm)");
    EXPECT_EQ(b.messages()[1].rfind("move-lobe drag at t=100.00s edits nothing: its start is outside every lobe", 0),
              0u)
        << b.messages()[1];
    EXPECT_NE(b.messages()[2].find("the pointing fingertip is"), std::string::npos) << b.messages()[2];
    for (const std::string& m : b.messages()) EXPECT_EQ(m.find('\n'), std::string::npos);
    // Nothing was recorded, so undo takes back the last stroke.
    b.apply(simple(InputAction::Type::Undo));
    EXPECT_EQ(b.document().strokes.size(), strokes - 1);

    SessionBuilder empty;
    EXPECT_FALSE(empty.apply(drag_action(Tool::RotateLobe, far, far)));
    EXPECT_FALSE(empty.apply(drag_action(Tool::EditStroke, far, far)));
    ASSERT_EQ(empty.messages().size(), 2u);
    EXPECT_NE(empty.messages()[0].find("there are no lobes"), std::string::npos);
    EXPECT_NE(empty.messages()[1].find("there are no strokes"), std::string::npos);
}

TEST(SessionBuilder, MakesNoEditASessionFileCouldNotHold)
{
    // A trunk stroke 1 cm inside the 1 km limit: the pointing fingertip 2 cm from it, within
    // the pick distance but beyond the limit, where a session may not hold it.
    Stroke edge = trunk(1);
    for (StrokePoint& p : edge.points) p.position.x = 999.99f;
    SessionBuilder b;
    ASSERT_TRUE(b.apply(stroke_action(edge)));
    const glm::vec3 p = edge.points[30].position;
    EXPECT_FALSE(b.apply(drag_action(Tool::EditStroke, p, p + glm::vec3(0.0f, 0.02f, 0.0f), p + glm::vec3(0.02f, 0.0f, 0.0f))));
    ASSERT_EQ(b.messages().size(), 1u);
    EXPECT_NE(b.messages()[0].find("edits nothing: params.other_tip: a coordinate is not finite or beyond 1 km"),
              std::string::npos)
        << b.messages()[0];
    EXPECT_TRUE(b.document().edits.empty());
    // Inside the limit it is made.
    EXPECT_TRUE(b.apply(drag_action(Tool::EditStroke, p, p + glm::vec3(0.0f, 0.02f, 0.0f), p - glm::vec3(0.02f, 0.0f, 0.0f))));
    EXPECT_EQ(b.document().edits.size(), 1u);
}

TEST(SessionBuilder, LobeDragsTargetTheNearestLobeAndRecordItsCentreAndStrokes)
{
    SessionBuilder b = scene();
    // 3 cm outside the second lobe's loop.
    const glm::vec3 near2 = glm::vec3(kCentre + glm::dvec3(0.6 + 0.13, 0, 0));
    EXPECT_TRUE(b.apply(drag_action(Tool::MoveLobe, near2, near2 + glm::vec3(0.0f, 0.0f, 0.1f))));
    const EditOperation& move = b.document().edits.back();
    EXPECT_STREQ(edit_kind_name(move.kind()), "drag:move-lobe");
    EXPECT_EQ(move.target, 2);
    EXPECT_EQ(move.transform_params()->strokes, ids({5}));
    glm::dvec3 c2;
    ASSERT_TRUE(lobe_centre(b.document().lobes[1], b.document().strokes, c2));
    EXPECT_EQ(recorded_centre(move), c2);
    // The loop as drawn has no closing segment: its barycentre is a little off the circle's.
    EXPECT_LT(glm::distance(c2, kCentre + glm::dvec3(0.6, 0, 0)), 0.001);

    // Inside lobe 1, at its centre (16 cm from every stroke): inside its bounding sphere.
    const glm::vec3 c(kCentre);
    EXPECT_TRUE(b.apply(drag_action(Tool::ScaleLobe, c, c + glm::vec3(0.05f, 0.0f, 0.0f))));
    EXPECT_EQ(b.document().edits.back().target, 1);
    EXPECT_EQ(b.document().edits.back().transform_params()->strokes, ids({1, 2, 3}));
    glm::dvec3 centre;
    ASSERT_TRUE(lobe_centre(b.document().lobes[0], b.document().strokes, centre));
    EXPECT_LT(glm::distance(centre, kCentre), 0.001);
    EXPECT_EQ(recorded_centre(b.document().edits.back()), centre);

    // Rotate and pinch-deform: the lobe whose strokes are nearest.
    const glm::vec3 top = point(b.document(), 2, 45);
    EXPECT_TRUE(b.apply(drag_action(Tool::RotateLobe, top, top + glm::vec3(0.05f, 0.0f, 0.0f))));
    EXPECT_STREQ(edit_kind_name(b.document().edits.back().kind()), "drag:rotate-lobe");
    EXPECT_EQ(b.document().edits.back().target, 1);
    EXPECT_TRUE(b.apply(drag_action(Tool::DeformLobe, top, top + glm::vec3(0.0f, 0.05f, 0.0f))));
    EXPECT_STREQ(edit_kind_name(b.document().edits.back().kind()), "drag:deform-lobe");
    EXPECT_EQ(b.document().edits.back().target, 1);
    EXPECT_EQ(b.document().edits.back().transform_params(), nullptr); // a deform has no centre
}

TEST(SessionBuilder, PickDefaultsMatchTheMeshingDefaults)
{
    EXPECT_EQ(EditPickOptions{}.stroke_pick_distance_m, StrokeEditOptions{}.pick_distance_m);
    EXPECT_EQ(EditPickOptions{}.stroke_half_length_m, StrokeEditOptions{}.half_length_m);
}

TEST(EditOps, StrokeEditsApplyInOrderAndTheDocumentKeepsTheStrokesAsDrawn)
{
    SessionBuilder b = scene();
    const glm::vec3 p = point(b.document(), 1, 20), q = point(b.document(), 1, 30);
    const glm::vec3 d1(0.0f, 0.05f, 0.0f), d2(0.02f, 0.0f, -0.03f);
    b.apply(drag_action(Tool::EditStroke, p, p + d1));
    b.apply(drag_action(Tool::EditStroke, q, q + d2));
    const Document doc = b.document();
    ASSERT_EQ(doc.edits.size(), 2u);

    // By hand: the same two edits, one after the other, on the loop (closed as drawn).
    Stroke expected = doc.strokes[0];
    ASSERT_TRUE(stroke_edit_closed(expected));
    edit_stroke(expected, true, {p, p + d1, std::nullopt});
    edit_stroke(expected, true, {q, q + d2, std::nullopt}); // picks the stroke as the first edit left it

    std::vector<SkippedEdit> skipped;
    const std::vector<Stroke> edited = edited_strokes(doc, {}, &skipped);
    EXPECT_TRUE(skipped.empty());
    ASSERT_EQ(edited.size(), doc.strokes.size());
    EXPECT_TRUE(same_bits(edited[0], expected));
    EXPECT_FALSE(same_bits(edited[0], doc.strokes[0]));
    for (std::size_t i = 1; i < edited.size(); ++i) EXPECT_TRUE(same_bits(edited[i], doc.strokes[i])) << i;
    // The document is as drawn.
    EXPECT_TRUE(same_bits(doc.strokes[0], loop(1, 0)));

    // The operations survive a save and a reload: the same strokes come out.
    const Document back = document_from_json(document_to_json(doc));
    const std::vector<Stroke> again = edited_strokes(back);
    for (std::size_t i = 0; i < again.size(); ++i) EXPECT_TRUE(same_bits(again[i], edited[i])) << i;
    // And adding a stroke afterwards changes nothing about them.
    SessionBuilder more(back);
    more.apply(stroke_action(loop(9, 1, kCentre, 0.12)));
    const std::vector<Stroke> after = edited_strokes(more.document());
    EXPECT_TRUE(same_bits(by_id(after, 1), edited[0]));
}

TEST(EditOps, LobeTransformComposesItsOperationsInOrder)
{
    SessionBuilder b = scene(meshing_edit_hooks());
    const glm::vec3 top = point(b.document(), 2, 45); // top of the frontal loop: kCentre + 0.15 Y
    const glm::vec3 shift(-0.06f, 0.03f, 0.0f);
    b.apply(drag_action(Tool::MoveLobe, top, top + shift));
    // Rotate 90° about Y through the moved centre: the drag goes from +X to −Z around it.
    const glm::dvec3 c1 = kCentre + glm::dvec3(shift);
    b.apply(drag_action(Tool::RotateLobe, glm::vec3(c1 + glm::dvec3(0.15, 0, 0)), glm::vec3(c1 + glm::dvec3(0, 0, -0.15))));
    // A move of the other lobe in between must not count.
    const glm::vec3 other(kCentre + glm::dvec3(0.7, 0, 0));
    b.apply(drag_action(Tool::MoveLobe, other, other + glm::vec3(0.0f, 0.2f, 0.0f)));
    // Scale × 1.5 from 14 cm above the centre.
    b.apply(drag_action(Tool::ScaleLobe, glm::vec3(c1 + glm::dvec3(0, 0.14, 0)), glm::vec3(c1 + glm::dvec3(0, 0.21, 0))));
    const Document& doc = b.document();
    ASSERT_EQ(doc.edits.size(), 4u);
    for (const EditOperation& op : doc.edits) EXPECT_NE(op.target, 0);

    // Each operation's own transform about its recorded centre, composed later-on-the-left.
    const auto& e = doc.edits;
    const glm::dmat4 m = move_transform(path_end(e[0], false), path_end(e[0], true));
    EXPECT_LT(glm::distance(recorded_centre(e[0]), kCentre), 0.001);
    EXPECT_LT(glm::distance(recorded_centre(e[1]) - recorded_centre(e[0]), glm::dvec3(shift)), 1e-6); // where the lobe was then
    const glm::dmat4 r = rotate_transform(path_end(e[1], false), path_end(e[1], true), recorded_centre(e[1]));
    const glm::dmat4 s = scale_transform(path_end(e[3], false), path_end(e[3], true), recorded_centre(e[3]));
    const glm::dmat4 expected = s * r * m;
    const glm::dmat4 got = lobe_transform(doc, 1);
    for (int c = 0; c < 4; ++c)
        for (int k = 0; k < 4; ++k) EXPECT_NEAR(got[c][k], expected[c][k], 1e-12);
    EXPECT_NEAR(similarity_scale(got), 1.5, 0.01);
    // Prefixes: after the first operation only the move.
    const glm::dmat4 first = lobe_transform(doc, 1, 1);
    for (int c = 0; c < 4; ++c)
        for (int k = 0; k < 4; ++k) EXPECT_NEAR(first[c][k], m[c][k], 1e-15);
    EXPECT_NEAR(lobe_transform(doc, 2)[3][1], 0.2, 1e-6);
    EXPECT_EQ(lobe_transform(doc, 99), glm::dmat4(1.0));

    // What the person sees: the point 15 cm along +X from the centre went along with the
    // centre, turned to −Z, and is 22.5 cm out.
    const std::vector<Stroke> now = effective_strokes(doc);
    expect_near(by_id(now, 1).points[0].position, glm::vec3(c1 + glm::dvec3(0, 0, -0.225)), 0.002f);
    expect_near(by_id(now, 1).points[0].position,
                glm::vec3(expected * glm::dvec4(glm::dvec3(doc.strokes[0].points[0].position), 1.0)), 1e-6f);
    // Lobe 1's strokes come back in its own frame from edited_strokes (unchanged here).
    EXPECT_TRUE(same_bits(by_id(edited_strokes(doc), 1), doc.strokes[0]));
    // The trunk belongs to no lobe and never moves.
    EXPECT_TRUE(same_bits(by_id(now, 4), doc.strokes[3]));
}

TEST(EditOps, StrokeEditOnAMovedLobeAppliesWhereThePersonSawTheStroke)
{
    // Move lobe 1 up by 20 cm and scale it by 1.5, then bend stroke 1 where it is seen now.
    auto run = [](EditHooks hooks) {
        SessionBuilder b = scene(std::move(hooks));
        const glm::vec3 top = point(b.document(), 2, 45);
        b.apply(drag_action(Tool::MoveLobe, top, top + glm::vec3(0.0f, 0.2f, 0.0f)));
        const glm::dvec3 c = kCentre + glm::dvec3(0, 0.2, 0);
        b.apply(drag_action(Tool::ScaleLobe, glm::vec3(c + glm::dvec3(0.1, 0, 0)), glm::vec3(c + glm::dvec3(0.15, 0, 0))));
        const glm::vec3 seen = by_id(effective_strokes(b.document()), 1).points[20].position;
        b.apply(drag_action(Tool::EditStroke, seen, seen + glm::vec3(0.0f, 0.05f, 0.0f)));
        return std::make_pair(b.document(), seen);
    };
    // Seen as drawn, the scale and the bend start 11 cm or more from every stroke and outside
    // the lobe: they pick nothing.
    EXPECT_EQ(run({}).first.edits.size(), 1u);

    const auto [doc, seen] = run(meshing_edit_hooks());
    ASSERT_EQ(doc.edits.size(), 3u);
    EXPECT_EQ(doc.edits[2].target, 1);
    EXPECT_NEAR(glm::distance(glm::dvec3(seen), kCentre + glm::dvec3(0, 0.2, 0)), 0.225, 0.002); // 15 cm × 1.5
    const std::vector<Stroke> now = effective_strokes(doc);
    // The picked point followed the drag in stage space, at the lobe's new place and size.
    expect_near(by_id(now, 1).points[20].position, seen + glm::vec3(0.0f, 0.05f, 0.0f), 2e-6f);
    // In the lobe's own frame the pull is a third shorter (the lobe was scaled by 1.5).
    const glm::dmat4 t = lobe_transform(doc, 1);
    EXPECT_NEAR(similarity_scale(t), 1.5, 0.01);
    const std::vector<Stroke> local = edited_strokes(doc);
    const glm::vec3 moved = by_id(local, 1).points[20].position - doc.strokes[0].points[20].position;
    expect_near(moved, glm::vec3(0.0f, float(0.05 / similarity_scale(t)), 0.0f), 2e-6f);
    // lobe_transform takes the local strokes to what the person sees.
    for (std::size_t i = 0; i < now[0].points.size(); i += 7)
        expect_near(glm::vec3(t * glm::dvec4(glm::dvec3(local[0].points[i].position), 1.0)), now[0].points[i].position,
                    1e-6f);
}

TEST(EditOps, StrokesDrawnAfterALobeMovedStayWhereTheyWereDrawn)
{
    // Two loops, the lobe moved 10 cm along +X, then a third loop drawn around it where it
    // is now.
    SessionBuilder one(Document{}, EditPickOptions{}, meshing_edit_hooks());
    one.apply({stroke_action(loop(1, 0)), stroke_action(loop(2, 1))});
    const glm::vec3 top1 = point(one.document(), 2, 45);
    one.apply(drag_action(Tool::MoveLobe, top1, top1 + glm::vec3(0.1f, 0.0f, 0.0f)));
    const Stroke drawn_later = loop(3, 2, kCentre + glm::dvec3(0.1, 0, 0));
    one.apply(stroke_action(drawn_later));
    const Document& doc = one.document();
    ASSERT_EQ(doc.lobes.size(), 1u);
    EXPECT_EQ(doc.lobes[0].stroke_ids, (std::vector<std::int64_t>{1, 2, 3}));

    const std::vector<Stroke> now = effective_strokes(doc);
    for (std::size_t i = 0; i < drawn_later.points.size(); ++i)
        expect_near(now[2].points[i].position, drawn_later.points[i].position, 1e-6f);
    expect_near(now[0].points[0].position, doc.strokes[0].points[0].position + glm::vec3(0.1f, 0.0f, 0.0f), 1e-6f);
    // In the lobe's frame the late stroke sits where the lobe was before the move.
    expect_near(edited_strokes(doc)[2].points[0].position, drawn_later.points[0].position - glm::vec3(0.1f, 0.0f, 0.0f),
                1e-6f);
    // A later rotation turns all three together.
    const glm::dvec3 c = kCentre + glm::dvec3(0.1, 0, 0);
    one.apply(drag_action(Tool::RotateLobe, glm::vec3(c + glm::dvec3(0.15, 0, 0)), glm::vec3(c + glm::dvec3(0, 0, -0.15))));
    const EditOperation& rot = one.document().edits.back();
    EXPECT_EQ(rot.transform_params()->strokes, ids({1, 2, 3}));
    const std::vector<Stroke> turned = effective_strokes(one.document());
    const glm::dvec3 rc = recorded_centre(rot);
    const glm::dmat4 r = rotate_transform(path_end(rot, false), path_end(rot, true), rc);
    for (const Stroke& s : turned) {
        const Stroke& before = by_id(now, s.id);
        for (std::size_t i = 0; i < s.points.size(); i += 9) {
            expect_near(s.points[i].position, glm::vec3(r * glm::dvec4(glm::dvec3(before.points[i].position), 1.0)),
                        1e-6f);
            // About a quarter turn about +Y: (x, z) → (z, −x) around the centre (which is
            // within a millimetre of the loops' common centre).
            const glm::dvec3 a = glm::dvec3(before.points[i].position) - rc, e = glm::dvec3(s.points[i].position) - rc;
            EXPECT_NEAR(e.x, a.z, 0.002) << s.id;
            EXPECT_NEAR(e.z, -a.x, 0.002) << s.id;
            EXPECT_NEAR(e.y, a.y, 0.002) << s.id;
        }
    }
}

// Malformed params never come from a file (document_from_json refuses them at load,
// tests/core/edits_test.cpp); re-application still skips an operation made in code with them.
TEST(EditOps, OperationsThatCannotApplyAreSkippedWithAReason)
{
    SessionBuilder b = scene();
    const glm::vec3 p = point(b.document(), 1, 20);
    b.apply(drag_action(Tool::EditStroke, p, p + glm::vec3(0.0f, 0.05f, 0.0f)));
    Document doc = b.document();
    const std::vector<Stroke> good = edited_strokes(doc);

    EditOperation bad = doc.edits[0];
    bad.id = 50;
    bad.target = 99;
    EditOperation no_path = doc.edits[0];
    no_path.id = 51;
    no_path.path.clear();
    EditOperation nan_path = doc.edits[0];
    nan_path.id = 52;
    nan_path.path[0].position.y = std::numeric_limits<double>::quiet_NaN();
    EditOperation no_centre;
    no_centre.id = 53;
    no_centre.params = RotateLobeParams{};
    no_centre.target = 1;
    no_centre.path = {{{0.1, 1.4, -0.4}, 0.0}, {{0.1, 1.5, -0.4}, 1.0}};
    EditOperation no_lobe = no_centre;
    no_lobe.id = 54;
    no_lobe.params = MoveLobeParams{};
    no_lobe.target = 7;
    EditOperation far = doc.edits[0];
    far.id = 55;
    far.path[0] = {{0.05, 2.0, -0.42}, 0.0};
    EditOperation deform;
    deform.id = 56;
    deform.params = DeformLobeParams{};
    deform.target = 1;
    doc.edits.insert(doc.edits.begin(), {bad, no_path, nan_path, no_centre, no_lobe, far, deform});

    std::vector<SkippedEdit> skipped;
    const std::vector<Stroke> edited = edited_strokes(doc, {}, &skipped);
    ASSERT_EQ(skipped.size(), 6u);
    // Transform operations are read first, then the stroke edits in order.
    EXPECT_EQ(skipped[0].message, "edit 53 (drag:rotate-lobe): params.centre: missing");
    EXPECT_EQ(skipped[1].message, "edit 54 (drag:move-lobe): no lobe 7");
    EXPECT_EQ(skipped[2].message, "edit 50 (drag:edit-stroke): no stroke 99");
    EXPECT_NE(skipped[3].message.find("edit 51 (drag:edit-stroke): params.path"), std::string::npos);
    EXPECT_NE(skipped[4].message.find("edit 52 (drag:edit-stroke): params.path[0]"), std::string::npos);
    EXPECT_NE(skipped[5].message.find("edit 55 (drag:edit-stroke): stroke edit: the fingertip is"), std::string::npos)
        << skipped[5].message;
    for (const SkippedEdit& s : skipped) EXPECT_EQ(s.message.find('\n'), std::string::npos);
    // The good edit still applies, exactly as before.
    for (std::size_t i = 0; i < edited.size(); ++i) EXPECT_TRUE(same_bits(edited[i], good[i])) << i;
    EXPECT_EQ(lobe_transform(doc, 1), glm::dmat4(1.0));
    EXPECT_EQ(check_edit_operation(b.document(), far).rfind("stroke edit: the fingertip is", 0), 0u);
    EXPECT_EQ(check_edit_operation(b.document(), deform), "");
}

TEST(SessionBuilder, MeshingHooksRefuseAStrokeEditThatWouldNotApply)
{
    // Near the open end of the trunk, the point that follows the drag would sit next to the
    // segment's fixed end: the edit is refused when it is made, not skipped later.
    SessionBuilder b = scene(meshing_edit_hooks());
    const glm::vec3 end = point(b.document(), 4, 1) + glm::vec3(0.01f, 0.0f, 0.0f);
    EXPECT_FALSE(b.apply(drag_action(Tool::EditStroke, end, end + glm::vec3(0.03f, 0.0f, 0.0f))));
    EXPECT_TRUE(b.document().edits.empty());
    ASSERT_EQ(b.messages().size(), 1u);
    EXPECT_EQ(b.messages()[0].rfind("edit-stroke drag at t=100.00s edits nothing: stroke edit: the point that follows", 0),
              0u)
        << b.messages()[0];
    EXPECT_NE(b.messages()[0].find("stroke's end"), std::string::npos) << b.messages()[0];
    // Farther up it applies.
    const glm::vec3 mid = point(b.document(), 4, 30) + glm::vec3(0.01f, 0.0f, 0.0f);
    EXPECT_TRUE(b.apply(drag_action(Tool::EditStroke, mid, mid + glm::vec3(0.03f, 0.0f, 0.0f))));
    EXPECT_EQ(b.document().edits.back().target, 4);
}
