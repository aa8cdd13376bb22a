// Delete, duplicate and mirror (keys acting on what the fingertip is at) and appearance
// settings (Setting events) applied by app/session/session_builder.h, with undo/redo, and replayed
// from recordings.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <functional>
#include <iterator>
#include <map>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include "app/session/edit_hooks.h"
#include "core/document.h"
#include "core/errors.h"
#include "core/settings_json.h"
#include "growth/species.h"
#include "input/pipeline.h"
#include "input/recording.h"
#include "app/session/session_builder.h"
#include "app/session/edit_ops.h"
#include "app/session/lobe_document.h"
#include "meshing/mesh_quality.h"
#include "tests/support/hand_fixtures.h"

using namespace lobe;

namespace {

constexpr double kPi = 3.14159265358979323846;
const glm::dvec3 kCentre(0.05, 1.40, -0.42);
const glm::dvec3 kSecond = kCentre + glm::dvec3(0.6, 0, 0);

/// A raw lobe loop: n points, `plane` 0 horizontal (XZ), 1 frontal (XY), 2 sagittal (YZ);
/// `tilt` turns it about the z axis.
Stroke loop(std::int64_t id, int plane, glm::dvec3 centre = kCentre, double radius = 0.15, double tilt = 0.0,
            int n = 180)
{
    Stroke s;
    s.id = id;
    for (int i = 0; i < n; ++i) {
        const double a = 2 * kPi * i / n, c = radius * std::cos(a), d = radius * std::sin(a);
        glm::dvec3 off = plane == 0 ? glm::dvec3(c, 0, d) : plane == 1 ? glm::dvec3(c, d, 0) : glm::dvec3(0, c, d);
        off = glm::dvec3(off.x * std::cos(tilt) - off.y * std::sin(tilt), off.x * std::sin(tilt) + off.y * std::cos(tilt),
                         off.z);
        s.points.push_back({glm::vec3(centre + off), 1.0 * double(id) + 0.01 * i});
    }
    return s;
}

/// A trunk stroke rising from (−0.10, 0.90, −0.42) to (0.05, 1.20, −0.42): its base is at x = −0.10.
Stroke trunk(std::int64_t id)
{
    Stroke s;
    s.id = id;
    s.kind = StrokeKind::Trunk;
    for (int i = 0; i <= 60; ++i)
        s.points.push_back({glm::vec3(-0.10f + 0.0025f * float(i), 0.9f + 0.005f * float(i), -0.42f), 0.01 * i});
    return s;
}

InputAction stroke_action(const Stroke& s)
{
    InputAction a;
    a.type = InputAction::Type::StrokeCompleted;
    a.stroke = s;
    return a;
}

InputAction simple(InputAction::Type t)
{
    InputAction a;
    a.type = t;
    a.time = 50.0;
    return a;
}

InputAction at(InputAction::Type t, std::optional<glm::dvec3> tip)
{
    InputAction a = simple(t);
    if (tip) a.tip = glm::vec3(*tip);
    return a;
}

InputAction drag_action(Tool tool, glm::dvec3 from, glm::dvec3 to, double t0 = 100.0)
{
    InputAction a;
    a.type = InputAction::Type::DragCompleted;
    a.time = t0 + 1.0;
    a.drag.tool = tool;
    for (int i = 0; i <= 10; ++i)
        a.drag.path.push_back({glm::vec3(from + (to - from) * (double(i) / 10.0)), t0 + 0.1 * i});
    return a;
}

InputAction setting(SettingId id, double value, std::int64_t lobe = 0)
{
    InputAction a = simple(InputAction::Type::SettingChanged);
    a.setting.id = id;
    a.setting.value = value;
    a.setting.lobe = lobe;
    return a;
}

EditHooks hooks()
{
    EditHooks h = meshing_edit_hooks();
    h.apply_species = [](Settings& s, const std::string& name) {
        try {
            apply_species(s, load_species(name));
            return std::string();
        } catch (const InvalidInput& e) {
            return std::string(e.what());
        }
    };
    return h;
}

/// Lobe 1: three loops (strokes 1–3) at kCentre; trunk stroke 4; lobe 2: one loop (5) at kSecond.
SessionBuilder scene()
{
    SessionBuilder b(Document{}, EditPickOptions{}, hooks());
    b.apply({stroke_action(loop(1, 0)), stroke_action(loop(2, 1)), stroke_action(loop(3, 2)), stroke_action(trunk(4)),
             simple(InputAction::Type::NewLobe), stroke_action(loop(5, 0, kSecond, 0.1))});
    return b;
}

std::string text(const Document& d) { return document_to_json(d).dump(); }

std::map<std::int64_t, Stroke> seen(const Document& d)
{
    std::map<std::int64_t, Stroke> out;
    for (const Stroke& s : effective_strokes(d)) out.emplace(s.id, s);
    return out;
}

const Stroke& by_id(const Document& d, std::int64_t id)
{
    for (const Stroke& s : d.strokes)
        if (s.id == id) return s;
    throw std::logic_error("no stroke " + std::to_string(id));
}

const LobeRecord& lobe_by_id(const Document& d, std::int64_t id)
{
    for (const LobeRecord& l : d.lobes)
        if (l.id == id) return l;
    throw std::logic_error("no lobe " + std::to_string(id));
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

/// A point of stroke `id` as the person sees it.
glm::dvec3 seen_point(const Document& d, std::int64_t id, std::size_t i) { return glm::dvec3(seen(d).at(id).points[i].position); }

/// Undo gives `before` back exactly and redo `after`.
void expect_undo_redo(SessionBuilder& b, const std::string& before, const std::string& after)
{
    EXPECT_TRUE(b.apply(simple(InputAction::Type::Undo)));
    EXPECT_EQ(text(b.document()), before);
    EXPECT_TRUE(b.apply(simple(InputAction::Type::Redo)));
    EXPECT_EQ(text(b.document()), after);
}

/// Lobe `id`'s bounding radius about lobe_centre, as seen.
double seen_radius(const Document& d, std::int64_t id)
{
    const std::vector<Stroke> v = effective_strokes(d);
    glm::dvec3 c;
    EXPECT_TRUE(lobe_centre(lobe_by_id(d, id), v, c));
    const std::map<std::int64_t, Stroke> strokes = seen(d);
    double r = 0;
    for (std::int64_t s : lobe_by_id(d, id).stroke_ids)
        for (const StrokePoint& p : strokes.at(s).points) r = std::max(r, glm::distance(glm::dvec3(p.position), c));
    return r;
}

const BuiltLobe& built(const std::vector<BuiltLobe>& lobes, std::int64_t id)
{
    for (const BuiltLobe& b : lobes)
        if (b.lobe_id == id) return b;
    throw std::logic_error("lobe not built");
}

} // namespace

// ---------------------------------------------------------------------------------------
// Delete
// ---------------------------------------------------------------------------------------

TEST(SessionDelete, StrokeUnderTheFingertipLeavesItsLobeWithItsEditsAndUndoRestoresIt)
{
    SessionBuilder b = scene();
    // A stroke edit on stroke 1 (to go with it) and one on stroke 3 (to stay).
    ASSERT_TRUE(b.apply(drag_action(Tool::EditStroke, seen_point(b.document(), 1, 22), seen_point(b.document(), 1, 22) +
                                                                                            glm::dvec3(0, 0.03, 0))));
    ASSERT_TRUE(b.apply(drag_action(Tool::EditStroke, seen_point(b.document(), 3, 22),
                                    seen_point(b.document(), 3, 22) + glm::dvec3(0.03, 0, 0), 110.0)));
    const std::string before = text(b.document());
    const auto seen_before = seen(b.document());

    // 1 cm off the edited stroke 1 at 44°, far from strokes 2 and 3.
    const glm::dvec3 tip = glm::dvec3(seen_before.at(1).points[22].position) + glm::dvec3(0, 0.01, 0);
    ASSERT_TRUE(b.apply(at(InputAction::Type::DeleteStroke, tip)));
    const Document& d = b.document();
    EXPECT_EQ(d.strokes.size(), 4u);
    EXPECT_THROW(by_id(d, 1), std::logic_error);
    EXPECT_EQ(lobe_by_id(d, 1).stroke_ids, (std::vector<std::int64_t>{2, 3}));
    ASSERT_EQ(d.edits.size(), 1u);
    EXPECT_EQ(d.edits[0].target, 3);
    for (std::int64_t id : {2, 3, 4, 5}) EXPECT_TRUE(same_bits(seen(d).at(id), seen_before.at(id))) << id;
    EXPECT_TRUE(b.messages().empty());
    expect_undo_redo(b, before, text(b.document()));
}

TEST(SessionDelete, LastStrokeOfALobeTakesTheLobeItsOperationsAndItsTreeWithIt)
{
    SessionBuilder start = scene();
    Document doc = start.take_document();
    doc.trees = {TreeInstance{1, glm::mat4(1.0f), 1, {2}, {}}, TreeInstance{2, glm::mat4(1.0f), 2, {1, 2}, {}},
                 TreeInstance{3, glm::mat4(1.0f), 3, {}, {}}};
    SessionBuilder b(doc, EditPickOptions{}, hooks());
    ASSERT_TRUE(b.apply(drag_action(Tool::MoveLobe, kSecond, kSecond + glm::dvec3(0, 0.05, 0))));
    const glm::dvec3 top = kSecond + glm::dvec3(0.1, 0.05, 0); // on the moved loop
    ASSERT_TRUE(b.apply(drag_action(Tool::DeformLobe, top, top + glm::dvec3(0.03, 0, 0), 110.0)));
    ASSERT_TRUE(b.apply(drag_action(Tool::RotateLobe, kCentre + glm::dvec3(0, 0.15, 0),
                                    kCentre + glm::dvec3(0.05, 0.15, 0), 120.0)));
    ASSERT_EQ(b.document().edits.size(), 3u);
    const std::string before = text(b.document());

    ASSERT_TRUE(b.apply(at(InputAction::Type::DeleteStroke, top)));
    const Document& d = b.document();
    ASSERT_EQ(d.lobes.size(), 1u);
    EXPECT_EQ(d.lobes[0].id, 1);
    ASSERT_EQ(d.edits.size(), 1u);
    EXPECT_STREQ(edit_kind_name(d.edits[0].kind()), "drag:rotate-lobe");
    ASSERT_EQ(d.trees.size(), 2u); // tree 1 showed only lobe 2; "every lobe" (tree 3) stays
    EXPECT_EQ(d.trees[0].id, 2);
    EXPECT_EQ(d.trees[0].lobe_ids, (std::vector<std::int64_t>{1}));
    EXPECT_TRUE(d.trees[1].lobe_ids.empty());
    expect_undo_redo(b, before, text(b.document()));
}

TEST(SessionDelete, StrokeOfAMovedLobeKeepsTheRestOfTheLobeWhereThePersonSawIt)
{
    SessionBuilder b = scene();
    // Move lobe 1, draw a loop into it where it now is, bend stroke 3, then turn the lobe.
    const glm::dvec3 move(0.06, 0.03, 0);
    ASSERT_TRUE(b.apply(drag_action(Tool::MoveLobe, kCentre, kCentre + move)));
    ASSERT_TRUE(b.apply(stroke_action(loop(6, 0, kCentre + move + glm::dvec3(0, -0.08, 0), 0.1, 0.3))));
    ASSERT_EQ(lobe_by_id(b.document(), 1).stroke_ids, (std::vector<std::int64_t>{1, 2, 3, 6}));
    ASSERT_TRUE(b.apply(drag_action(Tool::EditStroke, seen_point(b.document(), 3, 22),
                                    seen_point(b.document(), 3, 22) + glm::dvec3(0.03, 0, 0), 110.0)));
    const glm::dvec3 c = kCentre + move;
    ASSERT_TRUE(b.apply(drag_action(Tool::RotateLobe, c + glm::dvec3(0.15, 0, 0), c + glm::dvec3(0.14, 0, 0.05), 120.0)));
    ASSERT_EQ(b.document().edits.size(), 3u);
    const std::string before = text(b.document());
    const auto seen_before = seen(b.document());

    // Stroke 2 (the frontal loop) at 44°, where the person sees it.
    ASSERT_TRUE(b.apply(at(InputAction::Type::DeleteStroke, glm::dvec3(seen_before.at(2).points[22].position))));
    const Document& d = b.document();
    EXPECT_EQ(lobe_by_id(d, 1).stroke_ids, (std::vector<std::int64_t>{1, 3, 6}));
    ASSERT_EQ(d.edits.size(), 3u); // every operation stays, applying as before
    using Ids = std::vector<std::int64_t>;
    EXPECT_EQ(d.edits[0].transform_params()->strokes.value(), Ids({1, 3}));    // the move: stroke 2 forgotten
    EXPECT_EQ(d.edits[2].transform_params()->strokes.value(), Ids({1, 3, 6})); // the turn
    std::vector<SkippedEdit> skipped;
    effective_strokes(d, {}, &skipped);
    EXPECT_TRUE(skipped.empty());
    for (std::int64_t id : {1, 3, 4, 5, 6}) EXPECT_TRUE(same_bits(seen(d).at(id), seen_before.at(id))) << id;
    expect_undo_redo(b, before, text(b.document()));
}

TEST(SessionDelete, LobeUnderTheFingertipGoesWithItsStrokesAndTheirOperationsOnly)
{
    SessionBuilder b = scene();
    ASSERT_TRUE(b.apply(drag_action(Tool::EditStroke, seen_point(b.document(), 1, 22), seen_point(b.document(), 1, 22) +
                                                                                            glm::dvec3(0, 0.03, 0))));
    ASSERT_TRUE(b.apply(drag_action(Tool::MoveLobe, kCentre, kCentre + glm::dvec3(0, 0.02, 0), 110.0)));
    ASSERT_TRUE(b.apply(drag_action(Tool::MoveLobe, kSecond, kSecond + glm::dvec3(0, 0.02, 0), 120.0)));
    const std::string before = text(b.document());
    const auto seen_before = seen(b.document());

    ASSERT_TRUE(b.apply(at(InputAction::Type::DeleteLobe, kCentre))); // inside lobe 1
    const Document& d = b.document();
    ASSERT_EQ(d.lobes.size(), 1u);
    EXPECT_EQ(d.lobes[0].id, 2);
    ASSERT_EQ(d.strokes.size(), 2u);
    EXPECT_EQ(d.strokes[0].id, 4);
    EXPECT_EQ(d.strokes[1].id, 5);
    ASSERT_EQ(d.edits.size(), 1u);
    EXPECT_EQ(d.edits[0].target, 2);
    EXPECT_TRUE(same_bits(seen(d).at(5), seen_before.at(5)));
    expect_undo_redo(b, before, text(b.document()));
}

TEST(SessionDelete, DuplicateAndMirrorThatPickNothingChangeNothingAndWarn)
{
    SessionBuilder b = scene();
    const std::string before = text(b.document());
    const glm::dvec3 far = kCentre + glm::dvec3(0, 0, 0.5);
    const InputAction::Type types[] = {InputAction::Type::DeleteStroke, InputAction::Type::DeleteLobe,
                                       InputAction::Type::Duplicate, InputAction::Type::Mirror};
    for (InputAction::Type t : types) {
        EXPECT_FALSE(b.apply(at(t, std::nullopt)));
        EXPECT_FALSE(b.apply(at(t, far)));
    }
    EXPECT_EQ(text(b.document()), before);
    ASSERT_EQ(b.messages().size(), 8u);
    EXPECT_EQ(b.messages()[0], "delete-stroke at t=50.00s changes nothing: no hand was tracked");
    EXPECT_EQ(b.messages()[1], "delete-stroke at t=50.00s changes nothing: the fingertip is 35.0 cm from the nearest "
                               "stroke (pick distance 3.0 cm)");
    EXPECT_NE(b.messages()[3].find("delete-lobe at t=50.00s changes nothing: the fingertip is outside every lobe"),
              std::string::npos)
        << b.messages()[3];
    EXPECT_NE(b.messages()[7].find("from the nearest trunk stroke (pick distance 3.0 cm)"), std::string::npos)
        << b.messages()[7];
    for (const std::string& m : b.messages()) EXPECT_EQ(m.find('\n'), std::string::npos);
    // Nothing to undo: the first undo takes back the last stroke of the scene.
    EXPECT_TRUE(b.apply(simple(InputAction::Type::Undo)));
    EXPECT_EQ(b.document().strokes.size(), 4u);

    SessionBuilder empty;
    EXPECT_FALSE(empty.apply(at(InputAction::Type::Duplicate, kCentre)));
    EXPECT_EQ(empty.messages().back(),
              "duplicate at t=50.00s changes nothing: there are no lobes, and there are no trunk strokes");
}

// ---------------------------------------------------------------------------------------
// Duplicate and mirror
// ---------------------------------------------------------------------------------------

TEST(SessionDuplicate, LobeCopyIsTheLobeAsSeenShiftedByItsDiameterPlus5cm)
{
    SessionBuilder b = scene();
    ASSERT_TRUE(b.apply(drag_action(Tool::EditStroke, seen_point(b.document(), 1, 22), seen_point(b.document(), 1, 22) +
                                                                                            glm::dvec3(0, 0.03, 0))));
    ASSERT_TRUE(b.apply(drag_action(Tool::MoveLobe, kCentre, kCentre + glm::dvec3(0, 0.05, 0.02), 110.0)));
    ASSERT_TRUE(b.apply(setting(SettingId::SplitAngle, 20.0, 1)));
    ASSERT_TRUE(b.apply(setting(SettingId::Species, 2.0, 1)));
    const std::string before = text(b.document());
    const auto seen_before = seen(b.document());
    const double shift = 2.0 * seen_radius(b.document(), 1) + 0.05;
    EXPECT_NEAR(shift, 0.355, 0.01);

    ASSERT_TRUE(b.apply(at(InputAction::Type::Duplicate, kCentre + glm::dvec3(0, 0.05, 0.02))));
    const Document& d = b.document();
    ASSERT_EQ(d.lobes.size(), 3u);
    const LobeRecord& copy = d.lobes.back();
    EXPECT_EQ(copy.id, 3);
    EXPECT_EQ(copy.stroke_ids, (std::vector<std::int64_t>{6, 7, 8}));
    EXPECT_EQ(copy.split_angle_deg, std::optional<double>(20.0));
    EXPECT_EQ(copy.species, "willow");
    EXPECT_EQ(d.edits.size(), 2u); // the edit and the move are baked into the copy's strokes
    for (int k = 0; k < 3; ++k) {
        const Stroke& original = seen_before.at(k + 1);
        const Stroke& c = by_id(d, copy.stroke_ids[std::size_t(k)]);
        EXPECT_EQ(c.kind, original.kind);
        EXPECT_EQ(c.closed, original.closed);
        EXPECT_EQ(c.hand, original.hand);
        ASSERT_EQ(c.points.size(), original.points.size());
        for (std::size_t i = 0; i < c.points.size(); ++i) {
            const glm::vec3 want(glm::dvec3(original.points[i].position) + glm::dvec3(shift, 0, 0));
            EXPECT_EQ(c.points[i].position, want) << k << " " << i;
            EXPECT_EQ(c.points[i].time, original.points[i].time);
        }
        // Nothing edits or moves the copy: it is seen as stored.
        EXPECT_TRUE(same_bits(seen(d).at(c.id), c));
    }
    for (std::int64_t id : {1, 2, 3, 4, 5}) EXPECT_TRUE(same_bits(seen(d).at(id), seen_before.at(id))) << id;
    expect_undo_redo(b, before, text(b.document()));

    // The next drawn stroke (the pipeline's id 6 is taken by the copy) gets a fresh id.
    ASSERT_TRUE(b.apply(stroke_action(loop(6, 0, kCentre + glm::dvec3(0, 0, -0.6)))));
    EXPECT_EQ(b.document().strokes.back().id, 9);
}

TEST(SessionDuplicate, TrunkStrokeCopyIsShifted10cmAlongX)
{
    SessionBuilder b = scene();
    const std::string before = text(b.document());
    const Stroke original = by_id(b.document(), 4);
    ASSERT_TRUE(b.apply(at(InputAction::Type::Duplicate, glm::dvec3(original.points[10].position) + glm::dvec3(0, 0, 0.02))));
    const Document& d = b.document();
    ASSERT_EQ(d.strokes.size(), 6u);
    EXPECT_EQ(d.lobes.size(), 2u);
    const Stroke& c = d.strokes.back();
    EXPECT_EQ(c.id, 6);
    EXPECT_EQ(c.kind, StrokeKind::Trunk);
    ASSERT_EQ(c.points.size(), original.points.size());
    for (std::size_t i = 0; i < c.points.size(); ++i) {
        EXPECT_EQ(c.points[i].position, glm::vec3(glm::dvec3(original.points[i].position) + glm::dvec3(0.1, 0, 0)));
        EXPECT_EQ(c.points[i].time, original.points[i].time);
    }
    expect_undo_redo(b, before, text(b.document()));
}

TEST(SessionMirror, CopiesAreExactMirrorImagesAcrossThePlaneThroughTheTrunkBase)
{
    SessionBuilder b = scene();
    ASSERT_TRUE(b.apply(drag_action(Tool::MoveLobe, kCentre, kCentre + glm::dvec3(0.04, 0, 0))));
    const std::string before = text(b.document());
    const auto seen_before = seen(b.document());
    const double x0 = double(-0.10f); // the trunk's lowest point
    auto expect_mirror = [&](const Stroke& m, const Stroke& o) {
        ASSERT_EQ(m.points.size(), o.points.size());
        EXPECT_EQ(m.kind, o.kind);
        for (std::size_t i = 0; i < m.points.size(); ++i) {
            const glm::vec3 p = m.points[i].position, q = o.points[i].position;
            EXPECT_EQ(p.x, static_cast<float>(2 * x0 - double(q.x))) << i;
            EXPECT_NEAR(0.5 * (double(p.x) + double(q.x)), x0, 1e-7) << i;
            EXPECT_EQ(p.y, q.y);
            EXPECT_EQ(p.z, q.z);
            EXPECT_EQ(m.points[i].time, o.points[i].time);
        }
    };
    ASSERT_TRUE(b.apply(at(InputAction::Type::Mirror, kCentre + glm::dvec3(0.04, 0, 0))));
    const Document& d = b.document();
    ASSERT_EQ(d.lobes.size(), 3u);
    EXPECT_EQ(d.lobes.back().stroke_ids, (std::vector<std::int64_t>{6, 7, 8}));
    for (int k = 0; k < 3; ++k) expect_mirror(by_id(d, 6 + k), seen_before.at(1 + k));
    expect_undo_redo(b, before, text(b.document()));

    // A trunk stroke is mirrored too (here onto the other side of its own base).
    ASSERT_TRUE(b.apply(at(InputAction::Type::Mirror, glm::dvec3(by_id(d, 4).points[30].position))));
    expect_mirror(b.document().strokes.back(), by_id(b.document(), 4));

    // Without trunk strokes the plane is x = 0.
    SessionBuilder no_trunk(Document{}, EditPickOptions{}, hooks());
    no_trunk.apply(stroke_action(loop(1, 0)));
    ASSERT_TRUE(no_trunk.apply(at(InputAction::Type::Mirror, kCentre)));
    const Stroke& m = no_trunk.document().strokes.back();
    for (std::size_t i = 0; i < m.points.size(); ++i)
        EXPECT_EQ(m.points[i].position.x, -by_id(no_trunk.document(), 1).points[i].position.x);
}

TEST(SessionMirror, MirroredLobeIsBuiltClosedAndOutwardAsTheMirrorOfTheOriginal)
{
    // A lobe that leans towards +x: a wide loop with a smaller one above it, off to the side.
    SessionBuilder b(Document{}, EditPickOptions{}, hooks());
    b.apply({stroke_action(loop(1, 0, kCentre, 0.15)), stroke_action(loop(2, 0, kCentre + glm::dvec3(0.04, 0.07, 0), 0.1)),
             stroke_action(trunk(3))});
    ASSERT_EQ(b.document().lobes.size(), 1u);
    ASSERT_TRUE(b.apply(at(InputAction::Type::Mirror, kCentre)));
    std::vector<std::string> warnings;
    const std::vector<BuiltLobe> lobes = build_document_lobes(b.document(), &warnings);
    EXPECT_TRUE(warnings.empty()) << warnings.front();
    const TriangleMesh& original = built(lobes, 1).mesh;
    const TriangleMesh& mirrored = built(lobes, 2).mesh;
    const MeshQuality q = measure_quality(mirrored);
    EXPECT_TRUE(q.closed);
    EXPECT_TRUE(q.manifold);
    EXPECT_TRUE(q.outward);
    EXPECT_NEAR(q.signed_volume_m3, measure_quality(original).signed_volume_m3,
                0.02 * measure_quality(original).signed_volume_m3);
    // The original mirrored by hand (positions across x = −0.10, triangles turned to stay outward).
    TriangleMesh reflected = original;
    for (glm::vec3& p : reflected.positions) p.x = static_cast<float>(-0.2 - double(p.x));
    for (auto& t : reflected.triangles) std::swap(t[1], t[2]);
    EXPECT_LT(max_vertex_distance(mirrored, reflected), 0.004);
    EXPECT_LT(max_vertex_distance(reflected, mirrored), 0.004);
    // A shifted copy is not a mirror image: the lobe leans enough to tell.
    TriangleMesh shifted = original;
    for (glm::vec3& p : shifted.positions) p.x = static_cast<float>(double(p.x) - 0.2 - 2 * kCentre.x);
    EXPECT_GT(max_vertex_distance(mirrored, shifted), 0.03);
}

TEST(SessionDuplicate, PinchDeformsOfAMovedAndTurnedLobeGoWithTheCopy)
{
    SessionBuilder b = scene();
    const glm::dvec3 move(0.0, 0.04, 0.0);
    ASSERT_TRUE(b.apply(drag_action(Tool::MoveLobe, kCentre, kCentre + move)));
    // Pull the top of the moved lobe 4 cm up, then turn the lobe 20° about the vertical.
    const glm::dvec3 top = kCentre + move + glm::dvec3(0, 0.15, 0);
    ASSERT_TRUE(b.apply(drag_action(Tool::DeformLobe, top, top + glm::dvec3(0.02, 0.04, 0), 110.0)));
    const glm::dvec3 c = kCentre + move, lever(0.15, 0, 0);
    const glm::dvec3 turned(0.15 * std::cos(0.35), 0, 0.15 * std::sin(0.35));
    ASSERT_TRUE(b.apply(drag_action(Tool::RotateLobe, c + lever, c + turned, 120.0)));
    const double shift = 2.0 * seen_radius(b.document(), 1) + 0.05;

    ASSERT_TRUE(b.apply(at(InputAction::Type::Duplicate, c)));
    const Document& d = b.document();
    ASSERT_EQ(d.edits.size(), 4u);
    const EditOperation& op = d.edits.back();
    EXPECT_STREQ(edit_kind_name(op.kind()), "drag:deform-lobe");
    EXPECT_EQ(op.target, 3);
    EXPECT_EQ(op.id, 4);
    EXPECT_EQ(op.path.size(), d.edits[1].path.size());
    // The copy is written as the file format says and read back the same.
    const std::string written = document_to_json(d).dump(1);
    EXPECT_EQ(document_to_json(document_from_json(nlohmann::json::parse(written))).dump(1), written);
    EXPECT_TRUE(b.messages().empty()) << b.messages().front();

    std::vector<std::string> warnings;
    const std::vector<BuiltLobe> lobes = build_document_lobes(d, &warnings);
    EXPECT_TRUE(warnings.empty()) << warnings.front();
    EXPECT_EQ(built(lobes, 1).edits_applied, 1u);
    EXPECT_EQ(built(lobes, 3).edits_applied, 1u);
    TriangleMesh want = built(lobes, 1).mesh;
    for (glm::vec3& p : want.positions) p.x = static_cast<float>(double(p.x) + shift);
    const TriangleMesh& copy = built(lobes, 3).mesh;
    // Remeshed apart (the copy's strokes are rounded to floats where it is), the two differ
    // by the remeshing (1.5 mm without any edit) and the deform's region on another mesh.
    EXPECT_LT(max_vertex_distance(copy, want), 0.015);
    EXPECT_LT(max_vertex_distance(want, copy), 0.015);
    // The bump is there and in the same place: the tops agree, 4 cm above the undeformed lobe.
    auto top_vertex = [](const TriangleMesh& m) {
        glm::vec3 best(0.0f, -1e9f, 0.0f);
        for (const glm::vec3& p : m.positions)
            if (p.y > best.y) best = p;
        return best;
    };
    EXPECT_LT(glm::distance(top_vertex(copy), top_vertex(want)), 0.002f);
    EXPECT_GT(top_vertex(copy).y, top.y + 0.035);
}

TEST(SessionDuplicate, ScaledLobeIsCopiedWithoutItsDeformsAndSaysSo)
{
    SessionBuilder b = scene();
    const glm::dvec3 top = kCentre + glm::dvec3(0, 0.15, 0);
    ASSERT_TRUE(b.apply(drag_action(Tool::DeformLobe, top, top + glm::dvec3(0, 0.03, 0))));
    ASSERT_TRUE(b.apply(drag_action(Tool::ScaleLobe, kCentre + glm::dvec3(0.1, 0, 0), kCentre + glm::dvec3(0.12, 0, 0),
                                    110.0)));
    ASSERT_TRUE(b.apply(at(InputAction::Type::Duplicate, kCentre)));
    const Document& d = b.document();
    EXPECT_EQ(d.lobes.size(), 3u);
    EXPECT_EQ(d.edits.size(), 2u);
    ASSERT_EQ(b.messages().size(), 1u);
    const std::string& m = b.messages()[0];
    EXPECT_EQ(m.rfind("duplicate of lobe 1 as lobe 3: its pinch deforms were not copied: lobe 1 was scaled (x1.", 0), 0u)
        << m;
    EXPECT_NE(m.find("), so a pinch deform's region would not match"), std::string::npos) << m;
}

// ---------------------------------------------------------------------------------------
// Settings
// ---------------------------------------------------------------------------------------

TEST(SessionSettings, EachSettingChangesTheDocumentAndUndoRestoresItExactly)
{
    SessionBuilder b = scene();
    auto step = [&](const InputAction& a, const std::function<void(const Document&)>& check) {
        const std::string before = text(b.document());
        ASSERT_TRUE(b.apply(a));
        check(b.document());
        EXPECT_TRUE(b.messages().empty()) << b.messages().front();
        expect_undo_redo(b, before, text(b.document()));
    };
    step(setting(SettingId::SplitAngle, 22.5), [](const Document& d) { EXPECT_EQ(d.settings.growth.split_angle_deg, 22.5); });
    step(setting(SettingId::AttractorSpacing, 0.02),
         [](const Document& d) { EXPECT_EQ(d.settings.lobes.edge_length_m, 0.02); });
    const double ratio = b.document().settings.leaves.width_m / b.document().settings.leaves.length_m;
    step(setting(SettingId::LeafLength, 0.08), [&](const Document& d) {
        EXPECT_EQ(d.settings.leaves.length_m, 0.08);
        EXPECT_DOUBLE_EQ(d.settings.leaves.width_m / d.settings.leaves.length_m, ratio);
    });
    step(setting(SettingId::LeavesPerNode, 7), [](const Document& d) { EXPECT_EQ(d.settings.leaves.per_node, 7); });
    step(setting(SettingId::Seed, 1234567), [](const Document& d) { EXPECT_EQ(d.seed, 1234567u); });
    step(setting(SettingId::SplitAngle, 12, 2), [](const Document& d) {
        EXPECT_EQ(lobe_by_id(d, 2).split_angle_deg, std::optional<double>(12.0));
        EXPECT_FALSE(lobe_by_id(d, 1).split_angle_deg.has_value());
    });
    step(setting(SettingId::Species, 3, 1), [](const Document& d) {
        EXPECT_EQ(lobe_by_id(d, 1).species, "birch");
        EXPECT_EQ(d.settings.growth.species, "broadleaf");
    });
    // A lobe's own leaves and seed; the tree's stay as they are.
    step(setting(SettingId::LeafLength, 0.12, 2), [](const Document& d) {
        EXPECT_EQ(lobe_by_id(d, 2).leaf_length_m, std::optional<double>(0.12));
        EXPECT_EQ(d.settings.leaves.length_m, 0.08);
        EXPECT_FALSE(lobe_by_id(d, 1).leaf_length_m.has_value());
    });
    step(setting(SettingId::LeavesPerNode, 9, 2), [](const Document& d) {
        EXPECT_EQ(lobe_by_id(d, 2).leaves_per_node, std::optional<int>(9));
        EXPECT_EQ(d.settings.leaves.per_node, 7);
    });
    step(setting(SettingId::Seed, 4242, 1), [](const Document& d) {
        EXPECT_EQ(lobe_by_id(d, 1).seed, std::optional<std::uint64_t>(4242));
        EXPECT_EQ(d.seed, 1234567u);
        EXPECT_FALSE(lobe_by_id(d, 2).seed.has_value());
    });
    // Tree-wide species: what `--species conifer` does to the same settings.
    Settings want = b.document().settings;
    apply_species(want, load_species("conifer"));
    step(setting(SettingId::Species, 1), [&](const Document& d) {
        EXPECT_EQ(settings_json(d.settings), settings_json(want));
        EXPECT_EQ(d.settings.growth.species, "conifer");
    });
    // Without the species hook only the name changes.
    SessionBuilder plain;
    ASSERT_TRUE(plain.apply(setting(SettingId::Species, 1)));
    Settings named;
    named.growth.species = "conifer";
    EXPECT_EQ(settings_json(plain.document().settings), settings_json(named));
    // Setting the value it already has is no change and no undo step.
    EXPECT_FALSE(b.apply(setting(SettingId::Seed, 1234567)));
}

TEST(SessionSettings, OutOfRangeUnknownOrPerLobeTreeWideSettingsAreRefusedWithAWarning)
{
    SessionBuilder b = scene();
    const std::string before = text(b.document());
    const InputAction refused[] = {
        setting(SettingId::SplitAngle, 2.0),         setting(SettingId::SplitAngle, 200.0, 1),
        setting(SettingId::AttractorSpacing, 0.001), setting(SettingId::AttractorSpacing, 0.02, 1),
        setting(SettingId::LeafLength, 5.0),         setting(SettingId::LeavesPerNode, 2.5),
        setting(SettingId::LeavesPerNode, 65),       setting(SettingId::Species, 4),
        setting(SettingId::Species, 0.5, 2),         setting(SettingId::Seed, 0),
        setting(SettingId::Seed, 16777216),          setting(SettingId::Seed, 3.5),
        setting(SettingId::SplitAngle, 30, 9),       setting(static_cast<SettingId>(9), 1),
        setting(SettingId::SplitAngle, std::nan("")),  setting(SettingId::LeafLength, 0.0001, 1),
        setting(SettingId::LeavesPerNode, 65, 2),      setting(SettingId::Seed, 0, 1),
    };
    for (const InputAction& a : refused) EXPECT_FALSE(b.apply(a));
    EXPECT_EQ(text(b.document()), before);
    const std::vector<std::string>& m = b.messages();
    ASSERT_EQ(m.size(), std::size(refused));
    EXPECT_EQ(m[0], "setting split-angle at t=50.00s changes nothing: settings.growth.split_angle_deg must be in [5, 180]");
    EXPECT_EQ(m[2], "setting attractor-spacing at t=50.00s changes nothing: settings.lobes.edge_length_m must be in "
                    "[0.005, 0.5]");
    EXPECT_EQ(m[3], "setting attractor-spacing at t=50.00s changes nothing: attractor-spacing is a tree-wide setting "
                    "(lobe 1 given): every lobe carries the same attractor density");
    EXPECT_EQ(m[7], "setting species at t=50.00s changes nothing: the species index must be 0 to 3 (broadleaf, "
                    "conifer, willow, birch)");
    EXPECT_EQ(m[12], "setting split-angle at t=50.00s changes nothing: there is no lobe 9");
    EXPECT_EQ(m[13], "setting at t=50.00s changes nothing: unknown setting id 9");
    for (const std::string& line : m) EXPECT_EQ(line.find('\n'), std::string::npos);
}

TEST(SessionSettings, ASliderRunOfOneSettingIsOneUndoStep)
{
    SessionBuilder b = scene();
    const std::string before = text(b.document());
    for (double v : {31.0, 32.0, 33.5, 40.0}) ASSERT_TRUE(b.apply(setting(SettingId::SplitAngle, v)));
    EXPECT_FALSE(b.apply(setting(SettingId::SplitAngle, 900.0))); // refused: the run goes on
    ASSERT_TRUE(b.apply(setting(SettingId::SplitAngle, 41.0)));
    const std::string run = text(b.document());
    ASSERT_TRUE(b.apply(setting(SettingId::Seed, 5)));           // another setting: its own step
    ASSERT_TRUE(b.apply(setting(SettingId::SplitAngle, 45.0))); // and a new run
    EXPECT_TRUE(b.apply(simple(InputAction::Type::Undo)));
    EXPECT_EQ(b.document().settings.growth.split_angle_deg, 41.0);
    EXPECT_TRUE(b.apply(simple(InputAction::Type::Undo)));
    EXPECT_EQ(text(b.document()), run);
    EXPECT_TRUE(b.apply(simple(InputAction::Type::Undo)));
    EXPECT_EQ(text(b.document()), before);
    // After an undo a setting starts a new step (the run is over).
    EXPECT_TRUE(b.apply(setting(SettingId::SplitAngle, 50.0)));
    EXPECT_TRUE(b.apply(simple(InputAction::Type::Undo)));
    EXPECT_EQ(text(b.document()), before);
}

// ---------------------------------------------------------------------------------------
// Replay from raw input
// ---------------------------------------------------------------------------------------

namespace {

/// Writes hand frames (the right hand) and events for a scripted session at 90 Hz.
struct Script {
    Recording rec;
    double t = 0.0;
    glm::vec3 tip{0.05f, 1.2f, -0.25f};
    float gap = 0.06f;

    void frame()
    {
        rec.frames.push_back(test::make_frame(t, test::make_hand(tip, gap)));
        t += 1.0 / 90.0;
    }
    void hold(double s)
    {
        for (int i = 0; i < int(s * 90.0); ++i) frame();
    }
    /// Moves the open hand to `to` at 0.4 m/s, then holds still for a second so the filtered
    /// tip settles.
    void go(glm::vec3 to)
    {
        const glm::vec3 from = tip;
        const int n = std::max(1, int(glm::distance(from, to) / 0.4f * 90.0f));
        for (int i = 1; i <= n; ++i) {
            tip = from + (to - from) * (float(i) / float(n));
            frame();
        }
        hold(1.0);
    }
    /// Pinches, follows `points` (one per frame), opens.
    void draw(const std::vector<glm::vec3>& points)
    {
        go(points.front());
        for (int i = 0; i < 20; ++i) {
            gap = 0.06f - 0.0031f * float(i);
            frame();
        }
        gap = 0.0f;
        for (const glm::vec3& p : points) {
            tip = p;
            frame();
        }
        for (int i = 0; i < 20; ++i) {
            gap = 0.0031f * float(i);
            frame();
        }
        gap = 0.06f;
        hold(0.3);
    }
    void key(int code)
    {
        rec.events.push_back({t, InputEventKind::Key, code, 1, 0, 0});
        rec.events.push_back({t + 0.05, InputEventKind::Key, code, 0, 0, 0});
        hold(0.2);
    }
    void set(SettingId id, int lobe, float x)
    {
        InputEvent e;
        e.time = t;
        e.kind = InputEventKind::Setting;
        e.code = static_cast<std::int32_t>(id);
        e.value = lobe;
        e.x = x;
        rec.events.push_back(e);
        frame();
    }
};

std::vector<glm::vec3> loop_points(const Stroke& s)
{
    std::vector<glm::vec3> p;
    for (const StrokePoint& q : s.points) p.push_back(q.position);
    p.push_back(p.front());
    return p;
}

Document replay(const Recording& rec, std::vector<std::string>* messages = nullptr)
{
    const InputResult r = run_input_pipeline(rec);
    SessionBuilder b(Document{}, EditPickOptions{}, hooks());
    b.apply(r.actions);
    if (messages) *messages = b.messages();
    return b.take_document();
}

} // namespace

TEST(SessionReplay, KeysAndSettingsInARecordingReplayToTheSameDocumentFromBothForms)
{
    Script s;
    s.draw(loop_points(loop(1, 0, kCentre, 0.12, 0.0, 120)));
    s.draw(loop_points(loop(2, 1, kCentre, 0.12, 0.0, 120)));
    s.key(keys::kDrawTrunk);
    std::vector<glm::vec3> trunk_points;
    for (const StrokePoint& p : trunk(3).points) trunk_points.push_back(p.position);
    s.draw(trunk_points);
    s.key(keys::kDrawLobe);
    s.set(SettingId::SplitAngle, 0, 25.0f);
    for (float v : {0.05f, 0.06f, 0.07f}) s.set(SettingId::LeafLength, 0, v); // a slider
    s.set(SettingId::Species, 1, 2.0f);
    s.set(SettingId::Seed, 0, 99.0f);
    s.set(SettingId::AttractorSpacing, 0, 0.001f); // refused
    s.go(glm::vec3(kCentre));
    s.key(keys::kDuplicate);
    s.key(keys::kMirror);
    s.go(glm::vec3(kCentre) + glm::vec3(0, 0, 0.6f));
    s.key(keys::kDeleteLobe); // picks nothing
    s.go(trunk_points[20]);
    s.key(keys::kDeleteStroke);
    s.key(keys::kUndo);
    s.key(keys::kRedo);

    std::vector<std::string> messages;
    const Document doc = replay(s.rec, &messages);
    ASSERT_EQ(doc.lobes.size(), 3u);
    EXPECT_EQ(doc.lobes[0].species, "willow");
    EXPECT_EQ(doc.lobes[1].species, "willow"); // copied with the lobe
    EXPECT_EQ(doc.lobes[2].species, "willow");
    EXPECT_EQ(doc.strokes.size(), 6u);          // two loops and their two copies; the trunk deleted
    for (const Stroke& st : doc.strokes) EXPECT_EQ(st.kind, StrokeKind::Lobe);
    EXPECT_EQ(doc.settings.growth.split_angle_deg, 25.0);
    EXPECT_EQ(doc.settings.leaves.length_m, 0.07);
    EXPECT_EQ(doc.settings.lobes.edge_length_m, 0.03);
    EXPECT_EQ(doc.seed, 99u);
    ASSERT_EQ(messages.size(), 2u);
    EXPECT_NE(messages[0].find("setting attractor-spacing"), std::string::npos) << messages[0];
    EXPECT_NE(messages[1].find("delete-lobe"), std::string::npos) << messages[1];

    const std::string want = text(doc);
    for (bool binary : {true, false}) {
        ReadReport report;
        const Recording back = parse_recording(binary ? encode_recording_binary(s.rec) : encode_recording_text(s.rec),
                                               "session", &report);
        EXPECT_EQ(report.events_dropped + report.frames_dropped, 0u);
        EXPECT_EQ(text(replay(back)), want) << (binary ? "binary" : "text");
    }
}

namespace {

/// A deform dragged live (LivePinch) on the lobes as built before it, through every point of
/// the drag's path, against the lobes built after the finished drag.
void expect_live_pinch_ends_as_built(const SessionBuilder& before_drag, const InputAction& drag, double tolerance)
{
    const Document before = before_drag.document();
    const std::vector<BuiltLobe> lobes = build_document_lobes(before);
    const glm::dvec3 from(drag.drag.path.front().position);
    const std::int64_t id = before_drag.lobe_at(from);
    ASSERT_GT(id, 0);
    const BuiltLobe* lobe = nullptr;
    for (const BuiltLobe& l : lobes)
        if (l.lobe_id == id) lobe = &l;
    ASSERT_NE(lobe, nullptr);
    LivePinch live(before, *lobe, glm::vec3(from));
    EXPECT_EQ(live.lobe_id(), id);
    double moved_most = 0.0;
    for (const StrokePoint& p : drag.drag.path) {
        const TriangleMesh& m = live.drag_to(p.position);
        ASSERT_EQ(m.positions.size(), lobe->mesh.positions.size());
        moved_most = 0.0;
        for (std::size_t v = 0; v < m.positions.size(); ++v)
            moved_most = std::max(moved_most, glm::distance(glm::dvec3(m.positions[v]), glm::dvec3(lobe->mesh.positions[v])));
        // The surface follows the fingertip: the handle moves with it, nothing moves more.
        const double pulled = glm::distance(glm::dvec3(p.position), from);
        EXPECT_NEAR(moved_most, pulled, 1e-4) << "at " << p.time;
    }
    ASSERT_GT(moved_most, 0.03);

    SessionBuilder after_drag = before_drag;
    ASSERT_TRUE(after_drag.apply(drag));
    const std::vector<BuiltLobe> after = build_document_lobes(after_drag.document());
    const BuiltLobe* done = nullptr;
    for (const BuiltLobe& l : after)
        if (l.lobe_id == id) done = &l;
    ASSERT_NE(done, nullptr);
    EXPECT_EQ(done->edits_applied, lobe->edits_applied + 1);
    ASSERT_EQ(done->mesh.triangles, live.mesh().triangles);
    ASSERT_EQ(done->mesh.positions.size(), live.mesh().positions.size());
    double worst = 0.0;
    for (std::size_t v = 0; v < done->mesh.positions.size(); ++v)
        worst = std::max(worst, double(glm::distance(done->mesh.positions[v], live.mesh().positions[v])));
    EXPECT_LE(worst, tolerance);
}

} // namespace

TEST(LivePinch, OnAnUnmovedLobeEndsExactlyAsTheFinishedDeformBuilds)
{
    const SessionBuilder b = scene();
    const glm::dvec3 top = kCentre + glm::dvec3(0, 0.15, 0);
    expect_live_pinch_ends_as_built(b, drag_action(Tool::DeformLobe, top, top + glm::dvec3(0.02, 0.04, 0), 110.0), 0.0);
}

TEST(LivePinch, OnAMovedTurnedAndScaledLobeEndsAsTheFinishedDeformBuildsWithinAMicrometre)
{
    SessionBuilder b = scene();
    const glm::dvec3 move(0.0, 0.04, 0.0), c = kCentre + move;
    ASSERT_TRUE(b.apply(drag_action(Tool::MoveLobe, kCentre, c)));
    const glm::dvec3 lever(0.15, 0, 0), turned(0.15 * std::cos(0.35), 0, 0.15 * std::sin(0.35));
    ASSERT_TRUE(b.apply(drag_action(Tool::RotateLobe, c + lever, c + turned, 105.0)));
    ASSERT_TRUE(b.apply(drag_action(Tool::ScaleLobe, c + turned, c + 1.2 * turned, 107.0)));
    ASSERT_TRUE(b.messages().empty()) << b.messages().front();
    // The top of the moved, turned and scaled lobe (1.2 × 15 cm above its centre).
    const glm::dvec3 top = c + glm::dvec3(0, 0.18, 0);
    expect_live_pinch_ends_as_built(b, drag_action(Tool::DeformLobe, top, top + glm::dvec3(-0.03, 0.03, 0.01), 110.0),
                                    1e-6);
}

TEST(LivePinch, APinchFarFromTheLobeSaysSoInOneLine)
{
    const SessionBuilder b = scene();
    const Document& d = b.document();
    const std::vector<BuiltLobe> lobes = build_document_lobes(d);
    ASSERT_FALSE(lobes.empty());
    try {
        LivePinch live(d, lobes.front(), glm::vec3(kCentre + glm::dvec3(0, 0.6, 0)));
        FAIL() << "a pinch 45 cm off the lobe picked a vertex";
    } catch (const InvalidInput& e) {
        const std::string m = e.what();
        EXPECT_EQ(m.find('\n'), std::string::npos) << m;
        EXPECT_NE(m.find("cm from the nearest vertex"), std::string::npos) << m;
    }
}
