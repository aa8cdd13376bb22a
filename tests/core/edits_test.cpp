// Edit operations in a session document (core/edits.h): the kind names of the file format,
// reading every kind and writing it back as it was read, and malformed operations refused
// at load with one line naming the field.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <string>
#include <vector>
#include <nlohmann/json.hpp>

#include "core/document.h"
#include "core/errors.h"
#include "tests/support/test_paths.h"

using namespace lobe;
using nlohmann::json;

namespace {

const EditKind kAllKinds[] = {EditKind::DeformLobe, EditKind::EditStroke, EditKind::MoveLobe, EditKind::RotateLobe,
                              EditKind::ScaleLobe};

/// A session whose only content is `edits` (a JSON array, as text).
json session_with_edits(const std::string& edits)
{
    return json::parse(R"({"format": "lobesketch-session", "version": 1, "edits": )" + edits + "}");
}

/// One edit of each kind, with every optional field somewhere and without it elsewhere;
/// points with and without their time; numbers as the program writes them (floats widened to
/// doubles, whole numbers, negative zero) and ids as integers.
const char* const kEveryKind = R"([
  {"id": 1, "type": "drag:deform-lobe", "target": 7,
   "params": {"hand": "left", "path": [[0.10000000149011612, 1.2000000476837158, -0.4000000059604645, 3.25],
                                       [0.125, 1.0, -0.0, 3.5]]}},
  {"id": 2, "type": "drag:edit-stroke", "target": 3,
   "params": {"hand": "right", "path": [[0.1, 1.2, -0.5, 4.0], [0.1, 1.3, -0.5]],
              "pick_distance_m": 0.03, "half_length_m": 0.08, "other_tip": [0.2, 1.2, -0.5]}},
  {"id": 3, "type": "drag:edit-stroke", "target": 0,
   "params": {"hand": "right", "path": [[0.1, 1.2, -0.5]]}},
  {"id": 4, "type": "drag:move-lobe", "target": 7,
   "params": {"hand": "right", "path": [[0.0, 1.0, 0.0, 0.1], [0.1, 1.0, 0.0, 0.2]], "centre": [0.0, 0.9, 0.0],
              "strokes": []}},
  {"id": 5, "type": "drag:move-lobe", "target": 7, "params": {"hand": "left", "path": [[0.0, 1.0, 0.0, 0.1]]}},
  {"id": 6, "type": "drag:rotate-lobe", "target": 7,
   "params": {"hand": "right", "path": [[0.1, 1.2, -0.5, 6.0], [0.2, 1.2, -0.5, 6.5]],
              "centre": [0.05, 1.4, -0.42], "strokes": [1, 3, 12]}},
  {"id": 7, "type": "drag:scale-lobe", "target": 7,
   "params": {"hand": "right", "path": [[0.1, 1.2, -0.5, 7.0], [0.2, 1.2, -0.5, 7.5]], "centre": [0.05, 1.4, -0.42]}}
])";

/// document_from_json's message for `doc`, or "" when it loads.
std::string refusal(const json& doc)
{
    try {
        document_from_json(doc);
        return {};
    } catch (const InvalidInput& e) {
        return e.what();
    }
}

} // namespace

TEST(EditKinds, NamesAreTheFileFormatsAndRoundTrip)
{
    EXPECT_STREQ(edit_kind_name(EditKind::DeformLobe), "drag:deform-lobe");
    EXPECT_STREQ(edit_kind_name(EditKind::EditStroke), "drag:edit-stroke");
    EXPECT_STREQ(edit_kind_name(EditKind::MoveLobe), "drag:move-lobe");
    EXPECT_STREQ(edit_kind_name(EditKind::RotateLobe), "drag:rotate-lobe");
    EXPECT_STREQ(edit_kind_name(EditKind::ScaleLobe), "drag:scale-lobe");
    for (EditKind k : kAllKinds) {
        EXPECT_EQ(edit_kind_from_name(edit_kind_name(k)), k) << edit_kind_name(k);
        // The default parameters of a kind are that kind's.
        EditOperation op;
        op.params = edit_params_of(k);
        EXPECT_EQ(op.kind(), k) << edit_kind_name(k);
        EXPECT_EQ(op.transform_params() != nullptr, is_lobe_transform(k)) << edit_kind_name(k);
        EXPECT_EQ(op.stroke_params() != nullptr, k == EditKind::EditStroke) << edit_kind_name(k);
    }
    for (const char* other : {"", "drag:", "drag:foo", "move-lobe", "drag:Move-lobe", "drag:move-lobe ", "pinch_deform"})
        EXPECT_EQ(edit_kind_from_name(other), std::nullopt) << other;
}

TEST(EditKinds, EveryKindIsReadAsWrittenAndWrittenBackTheSame)
{
    const json in = session_with_edits(kEveryKind);
    const Document doc = document_from_json(in);
    ASSERT_EQ(doc.edits.size(), 7u);

    // What was read.
    const EditOperation& deform = doc.edits[0];
    EXPECT_EQ(deform.kind(), EditKind::DeformLobe);
    EXPECT_EQ(deform.id, 1);
    EXPECT_EQ(deform.target, 7);
    EXPECT_EQ(deform.hand, Hand::Left);
    ASSERT_EQ(deform.path.size(), 2u);
    EXPECT_EQ(deform.path[0].position, glm::dvec3(0.10000000149011612, 1.2000000476837158, -0.4000000059604645));
    EXPECT_EQ(deform.path[0].time, std::optional<double>(3.25));
    EXPECT_TRUE(std::signbit(deform.path[1].position.z));

    const EditStrokeParams* bend = doc.edits[1].stroke_params();
    ASSERT_NE(bend, nullptr);
    EXPECT_EQ(bend->pick_distance_m, std::optional<double>(0.03));
    EXPECT_EQ(bend->half_length_m, std::optional<double>(0.08));
    EXPECT_EQ(bend->other_tip, std::optional<glm::dvec3>(glm::dvec3(0.2, 1.2, -0.5)));
    EXPECT_EQ(doc.edits[1].path[1].time, std::nullopt); // [x, y, z] stays three numbers
    const EditStrokeParams* plain = doc.edits[2].stroke_params();
    ASSERT_NE(plain, nullptr);
    EXPECT_FALSE(plain->pick_distance_m || plain->half_length_m || plain->other_tip);

    EXPECT_EQ(doc.edits[3].kind(), EditKind::MoveLobe);
    EXPECT_EQ(doc.edits[3].transform_params()->strokes.value(), std::vector<std::int64_t>{});
    EXPECT_EQ(doc.edits[4].transform_params()->centre, std::nullopt); // a move needs no centre
    EXPECT_EQ(doc.edits[4].transform_params()->strokes, std::nullopt);
    EXPECT_EQ(doc.edits[5].kind(), EditKind::RotateLobe);
    EXPECT_EQ(doc.edits[5].transform_params()->strokes.value(), (std::vector<std::int64_t>{1, 3, 12}));
    EXPECT_EQ(doc.edits[5].transform_params()->centre, std::optional<glm::dvec3>(glm::dvec3(0.05, 1.4, -0.42)));
    EXPECT_EQ(doc.edits[6].kind(), EditKind::ScaleLobe);

    // Written back: the same JSON, and the same text.
    const json out = document_to_json(doc);
    EXPECT_EQ(out["edits"], in["edits"]);
    EXPECT_EQ(out["edits"].dump(1), in["edits"].dump(1));
    // And once more through a file.
    const std::string dir = test::temp_dir("edits-roundtrip");
    save_document(dir + "/a.json", doc);
    save_document(dir + "/b.json", load_document(dir + "/a.json"));
    std::ifstream a(dir + "/a.json"), b(dir + "/b.json");
    const std::string ta((std::istreambuf_iterator<char>(a)), {}), tb((std::istreambuf_iterator<char>(b)), {});
    EXPECT_EQ(ta, tb);
}

TEST(EditKinds, AnEditMadeInCodeIsWrittenAsTheFileFormatSays)
{
    Document doc;
    EditOperation op;
    op.id = 4;
    op.target = 2;
    op.hand = Hand::Left;
    op.path = {{{0.5, 1.0, -0.25}, 2.0}, {{0.75, 1.0, -0.25}, std::nullopt}};
    RotateLobeParams turn;
    turn.centre = glm::dvec3(0.5, 1.25, -0.5);
    turn.strokes = std::vector<std::int64_t>{1, 2};
    op.params = turn;
    doc.edits.push_back(op);
    EXPECT_EQ(document_to_json(doc)["edits"].dump(),
              R"([{"id":4,"params":{"centre":[0.5,1.25,-0.5],"hand":"left","path":[[0.5,1.0,-0.25,2.0],[0.75,1.0,-0.25]],)"
              R"("strokes":[1,2]},"target":2,"type":"drag:rotate-lobe"}])");
}

TEST(EditKinds, MalformedEditsAreRefusedAtLoadWithOneLineNamingTheField)
{
    struct Case {
        const char* edit; ///< edits[1] of the document (edits[0] is a good stroke edit)
        const char* message;
    };
    const std::string good = R"({"id": 1, "type": "drag:edit-stroke", "target": 3, "params": {"hand": "right", "path": [[0.1, 1.2, -0.5, 4.0]]}})";
    const Case cases[] = {
        {R"(3)", "edits[1]: expected an object"},
        {R"({"id": 2, "type": "drag:foo", "target": 1, "params": {}})", R"(edits[1].type: unknown edit type "drag:foo")"},
        {R"({"id": 2, "type": 4, "target": 1, "params": {}})", "edits[1].type: expected a string"},
        {R"({"id": 2, "target": 1, "params": {}})", "edits[1].type: expected a string"},
        {R"({"id": "2", "type": "drag:move-lobe", "target": 1, "params": {}})", "edits[1].id: expected an integer"},
        {R"({"id": 2, "type": "drag:move-lobe", "params": {}})", "edits[1].target: expected an integer"},
        {R"({"id": 2, "type": "drag:move-lobe", "target": 1, "params": {}, "note": "x"})", "edits[1]: unknown key 'note'"},
        {R"({"id": 2, "type": "drag:move-lobe", "target": 1})", "edits[1].params: expected an object"},
        {R"({"id": 2, "type": "drag:move-lobe", "target": 1, "params": [1]})", "edits[1].params: expected an object"},
        {R"({"id": 2, "type": "drag:move-lobe", "target": 1, "params": {"path": [[0, 1, 0]]}})",
         R"(edits[1].params.hand: expected "left" or "right")"},
        {R"({"id": 2, "type": "drag:move-lobe", "target": 1, "params": {"hand": "both", "path": [[0, 1, 0]]}})",
         R"(edits[1].params.hand: expected "left" or "right")"},
        {R"({"id": 2, "type": "drag:move-lobe", "target": 1, "params": {"hand": "left"}})",
         "edits[1].params.path: expected a non-empty array of [x, y, z] or [x, y, z, t] points"},
        {R"({"id": 2, "type": "drag:move-lobe", "target": 1, "params": {"hand": "left", "path": []}})",
         "edits[1].params.path: expected a non-empty array of [x, y, z] or [x, y, z, t] points"},
        {R"({"id": 2, "type": "drag:move-lobe", "target": 1, "params": {"hand": "left", "path": [[0, 1, 0], [0, 1, 0], [0, 1]]}})",
         "edits[1].params.path[2]: expected [x, y, z] or [x, y, z, t] numbers"},
        {R"({"id": 2, "type": "drag:move-lobe", "target": 1, "params": {"hand": "left", "path": [[0, 1, 0, 1, 2]]}})",
         "edits[1].params.path[0]: expected [x, y, z] or [x, y, z, t] numbers"},
        {R"({"id": 2, "type": "drag:move-lobe", "target": 1, "params": {"hand": "left", "path": [[0, "x", 0]]}})",
         "edits[1].params.path[0]: expected [x, y, z] or [x, y, z, t] numbers"},
        {R"({"id": 2, "type": "drag:move-lobe", "target": 1, "params": {"hand": "left", "path": [[0, 1, 0, null]]}})",
         "edits[1].params.path[0]: expected [x, y, z] or [x, y, z, t] numbers"},
        {R"({"id": 2, "type": "drag:move-lobe", "target": 1, "params": {"hand": "left", "path": [[0, 1, 0], [5000, 1, 0]]}})",
         "edits[1].params.path[1]: a coordinate is not finite or beyond 1 km"},
        {R"({"id": 2, "type": "drag:move-lobe", "target": 1, "params": {"hand": "left", "path": [[0, 1, 0]], "pick_distance_m": 0.03}})",
         "edits[1].params: unknown key 'pick_distance_m' for drag:move-lobe"},
        {R"({"id": 2, "type": "drag:deform-lobe", "target": 1, "params": {"hand": "left", "path": [[0, 1, 0]], "centre": [0, 1, 0]}})",
         "edits[1].params: unknown key 'centre' for drag:deform-lobe"},
        {R"({"id": 2, "type": "drag:edit-stroke", "target": 1, "params": {"hand": "left", "path": [[0, 1, 0]], "strokes": [1]}})",
         "edits[1].params: unknown key 'strokes' for drag:edit-stroke"},
        {R"({"id": 2, "type": "drag:rotate-lobe", "target": 1, "params": {"hand": "left", "path": [[0, 1, 0]]}})",
         "edits[1].params.centre: missing"},
        {R"({"id": 2, "type": "drag:scale-lobe", "target": 1, "params": {"hand": "left", "path": [[0, 1, 0]], "strokes": [1]}})",
         "edits[1].params.centre: missing"},
        {R"({"id": 2, "type": "drag:scale-lobe", "target": 1, "params": {"hand": "left", "path": [[0, 1, 0]], "centre": [0, 1]}})",
         "edits[1].params.centre: expected [x, y, z] numbers"},
        {R"({"id": 2, "type": "drag:scale-lobe", "target": 1, "params": {"hand": "left", "path": [[0, 1, 0]], "centre": [0, 1, 1e300]}})",
         "edits[1].params.centre: a coordinate is not finite or beyond 1 km"},
        {R"({"id": 2, "type": "drag:move-lobe", "target": 1, "params": {"hand": "left", "path": [[0, 1, 0]], "strokes": 1}})",
         "edits[1].params.strokes: expected an array of stroke ids"},
        {R"({"id": 2, "type": "drag:move-lobe", "target": 1, "params": {"hand": "left", "path": [[0, 1, 0]], "strokes": [1, 2.5]}})",
         "edits[1].params.strokes: expected integer ids"},
        {R"({"id": 2, "type": "drag:edit-stroke", "target": 1, "params": {"hand": "left", "path": [[0, 1, 0]], "pick_distance_m": "3 cm"}})",
         "edits[1].params.pick_distance_m: expected a positive number"},
        {R"({"id": 2, "type": "drag:edit-stroke", "target": 1, "params": {"hand": "left", "path": [[0, 1, 0]], "pick_distance_m": 0}})",
         "edits[1].params.pick_distance_m: expected a positive number"},
        {R"({"id": 2, "type": "drag:edit-stroke", "target": 1, "params": {"hand": "left", "path": [[0, 1, 0]], "half_length_m": -0.08}})",
         "edits[1].params.half_length_m: expected a positive number"},
        {R"({"id": 2, "type": "drag:edit-stroke", "target": 1, "params": {"hand": "left", "path": [[0, 1, 0]], "other_tip": [0, 1, 0, 2]}})",
         "edits[1].params.other_tip: expected [x, y, z] numbers"},
        {R"({"id": 2, "type": "drag:edit-stroke", "target": 1, "params": {"hand": "left", "path": [[0, 1, 0]], "other_tip": [0, -2000, 0]}})",
         "edits[1].params.other_tip: a coordinate is not finite or beyond 1 km"},
    };
    EXPECT_EQ(refusal(session_with_edits("[" + good + "]")), "");
    for (const Case& c : cases) {
        const std::string msg = refusal(session_with_edits("[" + good + ", " + c.edit + "]"));
        EXPECT_EQ(msg, c.message) << c.edit;
    }

    // Numbers JSON text cannot hold (a parser refuses them) but a document built in code can.
    json inf = session_with_edits("[" + good + "]");
    inf["edits"][0]["params"]["path"][0][2] = std::numeric_limits<double>::infinity();
    EXPECT_EQ(refusal(inf), "edits[0].params.path[0]: a coordinate is not finite or beyond 1 km");
    json nan = session_with_edits("[" + good + "]");
    nan["edits"][0]["params"]["path"][0][3] = std::numeric_limits<double>::quiet_NaN();
    EXPECT_EQ(refusal(nan), "edits[0].params.path[0]: the time is not finite");

    // Through a file: one line, naming the file and the field.
    const std::string dir = test::temp_dir("edits-refused");
    std::ofstream(dir + "/bad.json") << session_with_edits("[" + good + ", " + cases[13].edit + "]").dump(1);
    try {
        load_document(dir + "/bad.json");
        ADD_FAILURE() << "accepted";
    } catch (const FileError& e) {
        EXPECT_EQ(std::string(e.what()), dir + "/bad.json: " + cases[13].message);
    }
}

TEST(EditKinds, AWellFormedEditHasNoProblemAndEachMalformedFieldIsNamed)
{
    EditOperation op;
    op.params = RotateLobeParams{};
    op.path = {{{0.0, 1.0, 0.0}, 0.0}};
    EXPECT_EQ(edit_operation_problem(op), "params.centre: missing");
    op.transform_params()->centre = glm::dvec3(0.0, 1.0, 0.0);
    EXPECT_EQ(edit_operation_problem(op), "");
    op.path.push_back({{0.0, std::numeric_limits<double>::infinity(), 0.0}, 1.0});
    EXPECT_EQ(edit_operation_problem(op), "params.path[1]: a coordinate is not finite or beyond 1 km");
    op.path.clear();
    EXPECT_EQ(edit_operation_problem(op), "params.path: expected at least one point");

    EditOperation bend;
    bend.params = EditStrokeParams{};
    bend.path = {{{0.0, 1.0, 0.0}, std::nullopt}};
    EXPECT_EQ(edit_operation_problem(bend), "");
    std::get<EditStrokeParams>(bend.params).half_length_m = std::numeric_limits<double>::quiet_NaN();
    EXPECT_EQ(edit_operation_problem(bend), "params.half_length_m: expected a positive number");
}
