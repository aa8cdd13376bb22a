// The shipped recording recordings/edit-stroke-transform.lrec replayed through the input
// pipeline and the session builder: one lobe of five loops, then a stroke edit (E), a move
// (M), a rotation (R) and a scale (K), each checked against the scenario's ground truth.
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

#include "app/session/edit_hooks.h"
#include "input/pipeline.h"
#include "app/session/session_builder.h"
#include "input/synth.h"
#include "app/session/edit_ops.h"
#include "tests/support/test_data.h"
#include "tests/support/test_paths.h"

using namespace lobe;

namespace {

constexpr double kPi = 3.14159265358979323846;
// From recordings/edit-stroke-transform.scenario.json.
const glm::dvec3 kCentre(0.05, 1.40, -0.42);
const glm::dvec3 kShift(-0.06, 0.03, 0.0); // the move drag
constexpr double kTurnDeg = 25.0;          // the rotate drag, about +Y
constexpr double kScale = 1.3;             // the scale drag: 14 cm → 18.2 cm from the centre

struct Replayed {
    Document doc;
    std::vector<std::string> messages;
    std::vector<GroundTruthStroke> drags; ///< ground truth of the four drags, in order
};

/// recordings/edit-stroke-transform replayed, once; null when its recording or ground truth
/// is missing (the test has then failed with one line).
const Replayed* replayed()
{
    const std::string stem = test::source_path("recordings/edit-stroke-transform");
    if (!test::require_data(stem + ".lrec") || !test::require_data(stem + ".truth.json")) return nullptr;
    static const Replayed r = [&] {
        Replayed out;
        const Recording rec = read_recording(stem + ".lrec");
        const InputResult input = run_input_pipeline(rec);
        out.messages = input.messages;
        SessionBuilder builder(Document{}, EditPickOptions{}, meshing_edit_hooks());
        builder.apply(input.actions);
        out.messages.insert(out.messages.end(), builder.messages().begin(), builder.messages().end());
        out.doc = builder.document();
        for (const GroundTruthStroke& g : load_ground_truth(stem + ".truth.json"))
            if (g.drag) out.drags.push_back(g);
        return out;
    }();
    return &r;
}

glm::dvec3 apply(const glm::dmat4& m, const glm::dvec3& p) { return glm::dvec3(m * glm::dvec4(p, 1.0)); }

/// The transform the k-th operation (0-based) added to lobe 1: T_{k+1} T_k⁻¹.
glm::dmat4 step(const Document& doc, std::size_t k)
{
    return lobe_transform(doc, 1, k + 1) * glm::inverse(lobe_transform(doc, 1, k));
}

std::vector<glm::dvec3> lobe_points(const std::vector<Stroke>& strokes)
{
    std::vector<glm::dvec3> out;
    for (const Stroke& s : strokes)
        for (const StrokePoint& p : s.points) out.emplace_back(p.position);
    return out;
}

glm::dvec3 truth_move(const GroundTruthStroke& g) { return glm::dvec3(g.points.back()) - glm::dvec3(g.points.front()); }

} // namespace

TEST(ReplayEdits, EachDragBecomesAnEditOperationWithItsTarget)
{
    const Replayed* found = replayed();
    if (!found) return;
    const Replayed& r = *found;
    for (const std::string& m : r.messages) ADD_FAILURE() << m;
    const Document& doc = r.doc;
    ASSERT_EQ(doc.strokes.size(), 5u);
    ASSERT_EQ(doc.lobes.size(), 1u);
    EXPECT_EQ(doc.lobes[0].stroke_ids, (std::vector<std::int64_t>{1, 2, 3, 4, 5}));
    ASSERT_EQ(r.drags.size(), 4u);
    ASSERT_EQ(doc.edits.size(), 4u);

    const EditKind kinds[] = {EditKind::EditStroke, EditKind::MoveLobe, EditKind::RotateLobe, EditKind::ScaleLobe};
    for (std::size_t k = 0; k < 4; ++k) {
        const EditOperation& op = doc.edits[k];
        const char* name = edit_kind_name(kinds[k]);
        EXPECT_EQ(op.kind(), kinds[k]) << name;
        EXPECT_EQ(op.hand, Hand::Right) << name;
        // The recorded fingertip path starts and ends where the scenario's drag did, each
        // point with its time.
        const std::vector<DragPoint>& path = op.path;
        ASSERT_GE(path.size(), 2u);
        for (const DragPoint& p : path) EXPECT_TRUE(p.time.has_value()) << name;
        EXPECT_LT(glm::distance(path.front().position, glm::dvec3(r.drags[k].points.front())), 0.003) << name;
        EXPECT_LT(glm::distance(path.back().position, glm::dvec3(r.drags[k].points.back())), 0.003) << name;
    }
    // The stroke edit targets the equator loop (the first stroke), drawn with one hand.
    EXPECT_EQ(doc.edits[0].target, 1);
    const EditStrokeParams* bend = doc.edits[0].stroke_params();
    ASSERT_NE(bend, nullptr);
    EXPECT_FALSE(bend->other_tip.has_value());
    EXPECT_EQ(bend->pick_distance_m, std::optional<double>(0.03));
    EXPECT_EQ(bend->half_length_m, std::optional<double>(0.08));
    for (std::size_t k = 1; k < 4; ++k) {
        EXPECT_EQ(doc.edits[k].target, 1);
        ASSERT_NE(doc.edits[k].transform_params(), nullptr);
        EXPECT_EQ(doc.edits[k].transform_params()->strokes, (std::vector<std::int64_t>{1, 2, 3, 4, 5}));
    }
    // Each centre is the lobe's centre where the lobe was when the drag began.
    auto centre = [&](std::size_t k) { return doc.edits[k].transform_params()->centre.value(); };
    EXPECT_LT(glm::distance(centre(1), kCentre), 0.004);
    EXPECT_LT(glm::distance(centre(2), kCentre + kShift), 0.005);
    EXPECT_LT(glm::distance(centre(3), centre(2)), 0.001); // a rotation about the centre keeps it
}

TEST(ReplayEdits, StrokeEditMovesThePickedPointByTheDragAndNothingElse)
{
    const Replayed* found = replayed();
    if (!found) return;
    const Document& doc = found->doc;
    ASSERT_EQ(doc.edits.size(), 4u);
    Document only_edit = doc;
    only_edit.edits.resize(1);
    std::vector<SkippedEdit> skipped;
    const std::vector<Stroke> edited = edited_strokes(only_edit, {}, &skipped);
    for (const SkippedEdit& s : skipped) ADD_FAILURE() << s.message;
    ASSERT_EQ(edited.size(), 5u);

    const GroundTruthStroke& drag = found->drags[0];
    const Stroke& raw = doc.strokes[0];
    const std::size_t k = nearest_stroke_point(raw, drag.points.front());
    const glm::dvec3 moved = glm::dvec3(edited[0].points[k].position) - glm::dvec3(raw.points[k].position);
    EXPECT_LT(glm::distance(moved, truth_move(drag)), 0.003) << "moved (" << moved.x << ", " << moved.y << ", "
                                                              << moved.z << ")";
    EXPECT_NEAR(glm::length(truth_move(drag)), 0.05, 1e-4); // a 5 cm pull

    // The equator loop is closed as drawn; about 16 cm of it (8 cm each side) moved, and the
    // rest of it and the four other loops are bit for bit as drawn.
    EXPECT_TRUE(stroke_edit_closed(raw));
    std::size_t changed = 0;
    double changed_length = 0.0;
    for (std::size_t i = 0; i < raw.points.size(); ++i)
        if (edited[0].points[i].position != raw.points[i].position) {
            ++changed;
            changed_length += glm::distance(glm::dvec3(raw.points[i].position),
                                            glm::dvec3(raw.points[(i + 1) % raw.points.size()].position));
        }
    EXPECT_GT(changed, 10u);
    EXPECT_GT(changed_length, 0.14);
    EXPECT_LT(changed_length, 0.20);
    for (std::size_t s = 1; s < 5; ++s)
        for (std::size_t i = 0; i < doc.strokes[s].points.size(); ++i)
            ASSERT_EQ(edited[s].points[i].position, doc.strokes[s].points[i].position) << "stroke " << s + 1;
    // The later operations are lobe transforms: the strokes in the lobe's frame are the same.
    const std::vector<Stroke> all = edited_strokes(doc);
    for (std::size_t s = 0; s < 5; ++s)
        for (std::size_t i = 0; i < all[s].points.size(); ++i)
            ASSERT_EQ(all[s].points[i].position, edited[s].points[i].position);
}

TEST(ReplayEdits, LobeTransformsMoveRotateAndScaleTheLobeAsTheDragsSay)
{
    const Replayed* found = replayed();
    if (!found) return;
    const Replayed& r = *found;
    const Document& doc = r.doc;
    ASSERT_EQ(doc.edits.size(), 4u);
    const std::vector<glm::dvec3> local = lobe_points(edited_strokes(doc));

    // Move: every point by the drag (ground truth: end − start of the scenario's pull).
    const glm::dmat4 move = step(doc, 1);
    EXPECT_LT(glm::distance(truth_move(r.drags[1]), kShift), 1e-6);
    for (const glm::dvec3& p : local) ASSERT_LT(glm::distance(apply(move, p) - p, kShift), 0.003);

    // Rotate: 25° about the vertical through the moved centre.
    const glm::dmat4 rot = step(doc, 2);
    const glm::dmat3 lin(rot);
    const double angle = std::acos(std::clamp((lin[0][0] + lin[1][1] + lin[2][2] - 1.0) / 2.0, -1.0, 1.0));
    EXPECT_NEAR(angle * 180.0 / kPi, kTurnDeg, 2.0);
    const glm::dvec3 axis = glm::normalize(glm::dvec3(lin[1][2] - lin[2][1], lin[2][0] - lin[0][2], lin[0][1] - lin[1][0]));
    EXPECT_GT(axis.y, std::cos(5.0 * kPi / 180.0)); // +Y within 5°
    EXPECT_NEAR(glm::determinant(lin), 1.0, 1e-9);
    const double a = kTurnDeg * kPi / 180.0;
    const glm::dvec3 c1 = kCentre + kShift;
    for (const glm::dvec3& p0 : local) {
        const glm::dvec3 p = apply(move, p0) - c1;
        const glm::dvec3 want = c1 + glm::dvec3(p.x * std::cos(a) + p.z * std::sin(a), p.y,
                                                -p.x * std::sin(a) + p.z * std::cos(a));
        ASSERT_LT(glm::distance(apply(rot, apply(move, p0)), want), 0.006);
    }

    // Scale: 1.3 about the centre.
    const glm::dmat4 sc = step(doc, 3);
    EXPECT_NEAR(similarity_scale(sc), kScale, 0.03 * kScale);
    EXPECT_NEAR(glm::determinant(glm::dmat3(sc)), std::pow(similarity_scale(sc), 3.0), 1e-9);
    const glm::dmat4 before_scale = rot * move;
    for (const glm::dvec3& p0 : local) {
        const glm::dvec3 p = apply(before_scale, p0);
        ASSERT_LT(glm::distance(apply(sc, p), c1 + kScale * (p - c1)), 0.006);
    }

    // All together, in order, and what the person sees at the end.
    const glm::dmat4 total = lobe_transform(doc, 1);
    const std::vector<glm::dvec3> seen = lobe_points(effective_strokes(doc));
    ASSERT_EQ(seen.size(), local.size());
    for (std::size_t i = 0; i < local.size(); ++i) {
        ASSERT_LT(glm::distance(apply(total, local[i]), seen[i]), 1e-5);
        ASSERT_LT(glm::distance(apply(sc * rot * move, local[i]), seen[i]), 1e-5);
    }
}
