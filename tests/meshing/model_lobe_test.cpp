// Lobes made from imported meshes in a session (LobeRecord::model): stored in the session
// document, imported by an ImportMesh action at the fingertip, picked, moved, deformed,
// copied, deleted and undone like a lobe of strokes, rebuilt by build_document_lobes, and
// replayed from a recording whose meshes lie beside it (docs/lobes-from-models.md).
#include <cmath>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include "app/session/edit_hooks.h"
#include "core/errors.h"
#include "input/recording.h"
#include "app/session/session_builder.h"
#include "app/session/lobe_document.h"
#include "meshing/mesh_io.h"
#include "meshing/mesh_quality.h"
#include "meshing/model_import.h"
#include "tests/support/cli_run.h"
#include "tests/support/test_data.h"
#include "tests/support/test_paths.h"

namespace lobe {
namespace {

namespace fs = std::filesystem;

/// Spot (../shared/data/models/spot.obj) as a 40 cm lobe, centred on the origin: what an
/// import makes of it. Built once; null when the model is missing (the test has then failed
/// with one line), so a test that imports it starts with `if (!spot()) return;`.
const LobeModel* spot()
{
    const std::string path = test::shared_data("data/models/spot.obj");
    if (path.empty()) return nullptr;
    static const LobeModel model = [&] {
        LobeFromModelOptions o;
        o.size_m = 0.4;
        LobeModel m{"spot.obj", lobe_from_model(path, o)};
        glm::dvec3 lo, hi;
        bounding_box(m.mesh, lo, hi);
        for (glm::vec3& p : m.mesh.positions) p = glm::vec3(glm::dvec3(p) - 0.5 * (lo + hi));
        return m;
    }();
    return &model;
}

EditHooks hooks_with_spot()
{
    EditHooks h = meshing_edit_hooks();
    h.import_model = [](int n) {
        if (n != 1) throw InvalidInput("import " + std::to_string(n) + " does not exist");
        const LobeModel* model = spot();
        if (!model) throw InvalidInput("import 1: spot.obj is missing");
        return std::make_shared<const LobeModel>(*model);
    };
    return h;
}

InputAction action(InputAction::Type t, std::optional<glm::vec3> tip = std::nullopt, double time = 10.0)
{
    InputAction a;
    a.type = t;
    a.time = time;
    a.tip = tip;
    a.import_number = 1;
    return a;
}

InputAction drag(Tool tool, glm::vec3 from, glm::vec3 to)
{
    InputAction a = action(InputAction::Type::DragCompleted);
    a.drag.tool = tool;
    for (int i = 0; i <= 10; ++i) a.drag.path.push_back({from + (to - from) * (float(i) / 10.0f), 20.0 + 0.1 * i});
    return a;
}

std::string text(const Document& d) { return document_to_json(d).dump(); }

glm::dvec3 box_centre(const TriangleMesh& m)
{
    glm::dvec3 lo, hi;
    bounding_box(m, lo, hi);
    return 0.5 * (lo + hi);
}

const glm::vec3 kTip(0.3f, 1.2f, -0.4f);

/// A session holding spot imported at kTip.
SessionBuilder imported()
{
    SessionBuilder b(Document{}, EditPickOptions{}, hooks_with_spot());
    EXPECT_TRUE(b.apply(action(InputAction::Type::ImportMesh, kTip)));
    return b;
}

void expect_closed_outward(const TriangleMesh& m)
{
    const MeshQuality q = measure_quality(m);
    EXPECT_TRUE(q.closed);
    EXPECT_TRUE(q.manifold);
    EXPECT_TRUE(q.outward);
}

// ---------------------------------------------------------------------------------------------
TEST(ModelLobe, ImportPlacesTheMeshCentredOnTheFingertipAsOneUndoStep)
{
    if (!spot()) return;
    SessionBuilder b(Document{}, EditPickOptions{}, hooks_with_spot());
    const std::string empty = text(b.document());
    ASSERT_TRUE(b.apply(action(InputAction::Type::ImportMesh, kTip)));
    ASSERT_EQ(b.document().lobes.size(), 1u);
    const LobeRecord& l = b.document().lobes[0];
    ASSERT_TRUE(l.model);
    EXPECT_TRUE(l.stroke_ids.empty());
    EXPECT_EQ(l.model->source, "spot.obj");
    EXPECT_EQ(l.model->mesh.triangles, spot()->mesh.triangles);
    EXPECT_LT(glm::distance(box_centre(l.model->mesh), glm::dvec3(kTip)), 1e-5);
    const std::string after = text(b.document());
    ASSERT_TRUE(b.apply(action(InputAction::Type::Undo)));
    EXPECT_EQ(text(b.document()), empty);
    ASSERT_TRUE(b.apply(action(InputAction::Type::Redo)));
    EXPECT_EQ(text(b.document()), after);
}

TEST(ModelLobe, WithoutAHandTheMeshStandsAboveTheOriginHalfItsHeightOffTheGround)
{
    if (!spot()) return;
    SessionBuilder b(Document{}, EditPickOptions{}, hooks_with_spot());
    ASSERT_TRUE(b.apply(action(InputAction::Type::ImportMesh)));
    glm::dvec3 lo, hi;
    bounding_box(b.document().lobes.at(0).model->mesh, lo, hi);
    EXPECT_NEAR(0.5 * (lo.x + hi.x), 0.0, 1e-6);
    EXPECT_NEAR(0.5 * (lo.z + hi.z), 0.0, 1e-6);
    EXPECT_NEAR(lo.y, 0.5 * (hi.y - lo.y), 1e-5);
}

TEST(ModelLobe, ImportsThatCannotBeHadChangeNothingAndSayWhyInOneLine)
{
    SessionBuilder none; // no import hook
    EXPECT_FALSE(none.apply(action(InputAction::Type::ImportMesh, kTip)));
    ASSERT_EQ(none.messages().size(), 1u);
    EXPECT_NE(none.messages()[0].find("cannot read imported meshes"), std::string::npos);
    SessionBuilder b(Document{}, EditPickOptions{}, hooks_with_spot());
    InputAction missing = action(InputAction::Type::ImportMesh, kTip);
    missing.import_number = 2;
    EXPECT_FALSE(b.apply(missing));
    EXPECT_TRUE(b.document().lobes.empty());
    ASSERT_EQ(b.messages().size(), 1u);
    EXPECT_EQ(b.messages()[0], "import-mesh at t=10.00s changes nothing: import 2 does not exist");
}

TEST(ModelLobe, AnImportTheSessionCouldNotSaveAndLoadIsRefused)
{
    if (!spot()) return;
    EditHooks h = meshing_edit_hooks();
    h.import_model = [](int) {
        LobeModel m = *spot();
        m.mesh.triangles[3][1] = m.mesh.triangles[3][0];
        return std::make_shared<const LobeModel>(m);
    };
    SessionBuilder b(Document{}, EditPickOptions{}, h);
    EXPECT_FALSE(b.apply(action(InputAction::Type::ImportMesh, kTip)));
    EXPECT_TRUE(b.document().lobes.empty());
    ASSERT_EQ(b.messages().size(), 1u);
    EXPECT_EQ(b.messages()[0], "import-mesh at t=10.00s changes nothing: import 1.triangles: a triangle repeats a vertex");
}

TEST(ModelLobe, AStoredMeshThatIsNotClosedIsLeftOutWithAWarning)
{
    if (!spot()) return;
    Document d = imported().document();
    LobeModel open = *d.lobes[0].model;
    open.mesh.triangles.pop_back();
    d.lobes[0].model = std::make_shared<const LobeModel>(open);
    std::vector<std::string> warnings;
    EXPECT_TRUE(build_document_lobes(d, &warnings).empty());
    ASSERT_EQ(warnings.size(), 1u);
    EXPECT_EQ(warnings[0], "lobe 1: its mesh is not a closed, outward-oriented 2-manifold; the lobe is left out");
}

TEST(ModelLobe, AStoredMeshOfNoVolumeIsLeftOutWithAWarning)
{
    if (!spot()) return;
    // A tetrahedron a nanometre high: closed, 2-manifold and of positive volume, but flat.
    Document d = imported().document();
    LobeModel flat = *d.lobes[0].model;
    flat.mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1e-9f}};
    flat.mesh.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
    flat.mesh.feature_edges.clear();
    ASSERT_TRUE(measure_quality(flat.mesh).outward);
    d.lobes[0].model = std::make_shared<const LobeModel>(flat);
    std::vector<std::string> warnings;
    EXPECT_TRUE(build_document_lobes(d, &warnings).empty());
    ASSERT_EQ(warnings.size(), 1u);
    EXPECT_EQ(warnings[0].rfind("lobe 1: its mesh encloses no volume", 0), 0u) << warnings[0];
    EXPECT_EQ(warnings[0].find('\n'), std::string::npos);
}

TEST(ModelLobe, AStrokeDrawnIntoAMeshLobeStartsALobeOfItsOwn)
{
    if (!spot()) return;
    SessionBuilder b = imported();
    InputAction s = action(InputAction::Type::StrokeCompleted);
    s.stroke.id = 1;
    for (int i = 0; i < 60; ++i) {
        const double a = 2.0 * M_PI * i / 60;
        s.stroke.points.push_back({kTip + glm::vec3(0.1f * float(std::cos(a)), 0.0f, 0.1f * float(std::sin(a))), 0.01 * i});
    }
    ASSERT_TRUE(b.apply(s));
    ASSERT_EQ(b.document().lobes.size(), 2u);
    EXPECT_TRUE(b.document().lobes[0].stroke_ids.empty());
    EXPECT_EQ(b.document().lobes[1].stroke_ids, std::vector<std::int64_t>{1});
}

TEST(ModelLobe, MoveDragOnTheMeshMovesTheBuiltLobeAndDeleteRemovesIt)
{
    if (!spot()) return;
    SessionBuilder b = imported();
    const glm::vec3 on = b.document().lobes[0].model->mesh.positions[0];
    const glm::vec3 by(0.1f, -0.05f, 0.2f);
    ASSERT_TRUE(b.apply(drag(Tool::MoveLobe, on, on + by))) << b.messages().back();
    ASSERT_EQ(b.document().edits.size(), 1u);
    EXPECT_EQ(b.document().edits[0].target, b.document().lobes[0].id);
    std::vector<std::string> warnings;
    const std::vector<BuiltLobe> built = build_document_lobes(b.document(), &warnings);
    EXPECT_TRUE(warnings.empty()) << warnings.front();
    ASSERT_EQ(built.size(), 1u);
    expect_closed_outward(built[0].mesh);
    EXPECT_LT(glm::distance(box_centre(built[0].mesh), glm::dvec3(kTip + by)), 1e-4);
    // Delete picks it where it now is (the fingertip inside its bounding sphere).
    EXPECT_FALSE(b.apply(action(InputAction::Type::DeleteLobe, kTip - 3.0f * by)));
    ASSERT_TRUE(b.apply(action(InputAction::Type::DeleteLobe, kTip + by)));
    EXPECT_TRUE(b.document().lobes.empty());
    EXPECT_TRUE(b.document().edits.empty()) << "the lobe's operations go with it";
}

TEST(ModelLobe, PinchDeformMovesTheHandleByTheDragAndSurvivesAReload)
{
    if (!spot()) return;
    SessionBuilder b = imported();
    const TriangleMesh& m = b.document().lobes[0].model->mesh;
    // The topmost vertex, pulled up by 5 cm.
    std::size_t top = 0;
    for (std::size_t i = 0; i < m.positions.size(); ++i)
        if (m.positions[i].y > m.positions[top].y) top = i;
    const glm::vec3 handle = m.positions[top];
    ASSERT_TRUE(b.apply(drag(Tool::DeformLobe, handle, handle + glm::vec3(0, 0.05f, 0))));
    const std::string dir = test::temp_dir("model_lobe_reload");
    save_document(dir + "/s.json", b.document());
    const Document loaded = load_document(dir + "/s.json");
    EXPECT_EQ(text(loaded), text(b.document()));
    const std::vector<BuiltLobe> built = build_document_lobes(loaded);
    ASSERT_EQ(built.size(), 1u);
    EXPECT_EQ(built[0].edits_applied, 1u);
    float highest = -1e9f;
    for (const glm::vec3& p : built[0].mesh.positions) highest = std::max(highest, p.y);
    EXPECT_NEAR(highest, handle.y + 0.05f, 0.002f);
    expect_closed_outward(built[0].mesh);
}

TEST(ModelLobe, DuplicateShiftsAndMirrorReflectsTheMeshKeepingItOutward)
{
    if (!spot()) return;
    SessionBuilder b = imported();
    ASSERT_TRUE(b.apply(action(InputAction::Type::Duplicate, kTip)));
    ASSERT_TRUE(b.apply(action(InputAction::Type::Mirror, kTip)));
    const Document& d = b.document();
    ASSERT_EQ(d.lobes.size(), 3u);
    const TriangleMesh& orig = d.lobes[0].model->mesh;
    const TriangleMesh& dup = d.lobes[1].model->mesh;
    const TriangleMesh& mir = d.lobes[2].model->mesh;
    glm::dvec3 lo, hi;
    bounding_box(orig, lo, hi);
    double radius = 0.0;
    for (const glm::vec3& p : orig.positions) radius = std::max(radius, glm::distance(glm::dvec3(p), 0.5 * (lo + hi)));
    const glm::dvec3 shift = box_centre(dup) - box_centre(orig);
    EXPECT_NEAR(shift.x, 2.0 * radius + SessionBuilder::kDuplicateGapM, 1e-4);
    EXPECT_NEAR(shift.y, 0.0, 1e-6);
    // No trunk: the mirror plane is x = 0.
    ASSERT_EQ(mir.positions.size(), orig.positions.size());
    for (std::size_t i = 0; i < orig.positions.size(); ++i)
        ASSERT_EQ(mir.positions[i], glm::vec3(-orig.positions[i].x, orig.positions[i].y, orig.positions[i].z));
    for (const BuiltLobe& l : build_document_lobes(d)) expect_closed_outward(l.mesh);
}

TEST(ModelLobe, PerLobeSettingsApplyToAMeshLobe)
{
    if (!spot()) return;
    SessionBuilder b = imported();
    InputAction a = action(InputAction::Type::SettingChanged);
    a.setting = {SettingId::LeavesPerNode, b.document().lobes[0].id, 6.0};
    ASSERT_TRUE(b.apply(a));
    EXPECT_EQ(b.document().lobes[0].leaves_per_node, std::optional<int>(6));
}

TEST(ModelLobe, ChangedAttractorSpacingRemeshesTheStoredMesh)
{
    if (!spot()) return;
    SessionBuilder b = imported();
    Document d = b.document();
    const std::size_t stored = d.lobes[0].model->mesh.positions.size();
    ASSERT_EQ(build_document_lobes(d).at(0).mesh.positions.size(), stored) << "at its own spacing it is used as stored";
    d.settings.lobes.edge_length_m = 0.015;
    const TriangleMesh fine = build_document_lobes(d).at(0).mesh;
    EXPECT_GT(fine.positions.size(), 3 * stored);
    expect_closed_outward(fine);
    const MeshQuality q = measure_quality(fine);
    EXPECT_NEAR(q.edge_mean_m, 0.015, 0.004);
}

TEST(ModelLobe, SessionDocumentsRefuseBrokenMeshesWithOneLine)
{
    if (!spot()) return;
    Document d = imported().document();
    const nlohmann::json good = document_to_json(d);
    auto refused = [&](const std::function<void(nlohmann::json&)>& spoil, const std::string& says) {
        nlohmann::json j = good;
        spoil(j["lobes"][0]["model"]);
        try {
            document_from_json(j);
            ADD_FAILURE() << "accepted: " << says;
        } catch (const InvalidInput& e) {
            EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
            EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
        }
    };
    refused([](nlohmann::json& m) { m["triangles"][4] = 1000000; }, "lobes[0].model.triangles: vertex index 1000000 out of range");
    refused([](nlohmann::json& m) { m["triangles"][4] = -1; }, "out of range");
    refused([](nlohmann::json& m) { m["positions"][7] = "x"; }, "lobes[0].model.positions: expected numbers");
    refused([](nlohmann::json& m) { m["positions"][7] = 1e9; }, "beyond 1 km");
    refused([](nlohmann::json& m) { m["positions"].erase(0); }, "expected an array of x, y, z numbers");
    refused([](nlohmann::json& m) { m["triangles"] = nlohmann::json::array({0, 1, 2}); }, "at least 4 triangles");
    refused([](nlohmann::json& m) { m["triangles"][1] = m["triangles"][0]; }, "repeats a vertex");
    refused([](nlohmann::json& m) { m["colour"] = 1; }, "unknown key 'colour'");
    refused([](nlohmann::json& m) { m = 3; }, "lobes[0].model: expected an object");
    nlohmann::json with_strokes = good;
    with_strokes["lobes"][0]["strokes"] = {1};
    EXPECT_THROW(document_from_json(with_strokes), InvalidInput);
    // And the stored mesh comes back bit for bit.
    EXPECT_EQ(document_from_json(good).lobes[0].model->mesh.positions, d.lobes[0].model->mesh.positions);
}

TEST(ModelLobe, ReplayImportsTheMeshBesideTheRecordingOrSaysItIsMissing)
{
    if (!spot()) return;
    const std::string dir = test::temp_dir("model_lobe_replay");
    // A short recording: the right hand held still, an import at 0.5 s.
    Recording rec;
    for (int i = 0; i < 60; ++i) {
        HandFrame f;
        f.time = i / 60.0;
        rec.frames.push_back(f);
    }
    InputEvent e;
    e.time = 0.5;
    e.kind = InputEventKind::ImportMesh;
    e.code = 1;
    rec.events.push_back(e);
    const std::string path = dir + "/imported.lrec";
    write_recording_binary(path, rec);
    write_recording_text(dir + "/imported.txt", rec);
    EXPECT_EQ(read_recording(dir + "/imported.txt").events.at(0).kind, InputEventKind::ImportMesh);

    const test::CliRun missing = test::run_cli("replay " + path + " --out " + dir + "/missing");
    EXPECT_NE(missing.out.find("imported.lrec.import-1.ply"), std::string::npos) << missing.out;

    write_ply(import_mesh_path(path, 1), spot()->mesh);
    const test::CliRun run = test::run_cli("replay " + path + " --out " + dir + "/out");
    ASSERT_EQ(run.code, 0) << run.out;
    const Document d = load_document(dir + "/out/session.json");
    ASSERT_EQ(d.lobes.size(), 1u);
    ASSERT_TRUE(d.lobes[0].model);
    EXPECT_EQ(d.lobes[0].model->source, "imported.lrec.import-1.ply");
    EXPECT_EQ(d.lobes[0].model->mesh.triangles, spot()->mesh.triangles);
    const TriangleMesh written = read_mesh(dir + "/out/lobes/lobe_1.ply");
    expect_closed_outward(written);
    EXPECT_TRUE(fs::exists(dir + "/out/tree.glb"));
}

} // namespace
} // namespace lobe
