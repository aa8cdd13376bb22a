// The lobesketch executable as a user runs it: exit codes, one-line errors, output files.
#include <gtest/gtest.h>

#include <algorithm>

#include <filesystem>

#include <array>
#include <cstdio>
#include <fstream>

#include <sys/wait.h>

#include <nlohmann/json.hpp>

#include "core/document.h"
#include "meshing/mesh_io.h"
#include "meshing/mesh_quality.h"
#include "tests/support/cli_run.h"
#include "tests/support/test_data.h"
#include "tests/support/test_paths.h"

using namespace lobe;

namespace {

using test::CliRun;

CliRun run(const std::string& args) { return test::run_cli(args); }

std::size_t count_lines_with(const std::string& text, const std::string& needle)
{
    std::size_t n = 0, pos = 0;
    while ((pos = text.find(needle, pos)) != std::string::npos) {
        ++n;
        pos += needle.size();
    }
    return n;
}

} // namespace

TEST(Cli, HelpWorksForTheProgramAndEverySubcommand)
{
    CliRun top = run("--help");
    EXPECT_EQ(top.code, 0) << top.out;
    for (const char* sub : {"info", "replay", "import-leap", "import-webxr", "synth"}) {
        EXPECT_NE(top.out.find(sub), std::string::npos) << sub;
        CliRun r = run(std::string(sub) + " --help");
        EXPECT_EQ(r.code, 0) << sub << ": " << r.out;
        EXPECT_NE(r.out.find("Usage"), std::string::npos) << r.out;
    }
}

TEST(Cli, BadCommandLineExitsWithTwo)
{
    EXPECT_EQ(run("no-such-command").code, 2);
    EXPECT_EQ(run("replay").code, 2);
}

TEST(Cli, ReplayWritesStrokesAndASessionThatLoads)
{
    const std::string demo = test::source_data("recordings/demo.lrec");
    if (demo.empty()) return;
    const std::string dir = test::temp_dir("cli-replay");
    CliRun r = run("replay " + demo + " --out " + dir);
    ASSERT_EQ(r.code, 0) << r.out;
    std::ifstream in(dir + "/strokes.json");
    nlohmann::json j = nlohmann::json::parse(in);
    ASSERT_TRUE(j["strokes"].is_array());
    ASSERT_GE(j["strokes"].size(), 5u);
    for (const auto& s : j["strokes"]) {
        EXPECT_TRUE(s["id"].is_number_integer());
        EXPECT_TRUE(s["kind"] == "lobe" || s["kind"] == "trunk");
        EXPECT_TRUE(s["closed"].is_boolean());
        EXPECT_GE(s["points"].size(), 4u);
        EXPECT_EQ(s["points"][0].size(), 3u);
    }
    Document doc = load_document(dir + "/session.json");
    EXPECT_EQ(doc.strokes.size(), j["strokes"].size());
    EXPECT_FALSE(doc.lobes.empty());
    // Every lobe's mesh is written beside the session and recorded in it.
    for (const LobeRecord& l : doc.lobes) {
        EXPECT_EQ(l.mesh_file, "lobes/lobe_" + std::to_string(l.id) + ".ply");
        const TriangleMesh m = read_mesh(dir + "/" + l.mesh_file);
        const MeshQuality q = measure_quality(m);
        EXPECT_TRUE(q.closed && q.manifold && q.outward) << l.mesh_file;
        EXPECT_GT(q.vertices, 100u);
    }
}

TEST(Cli, LobesCommandBuildsLobesFromARecordingASessionAndAMesh)
{
    const std::string recording = test::source_data("recordings/table1-1lobe-5strokes.lrec");
    if (recording.empty()) return;
    const std::string dir = test::temp_dir("cli-lobes");
    CliRun r = run("lobes " + recording + " --out " + dir + "/rec");
    ASSERT_EQ(r.code, 0) << r.out;
    const Document from_rec = load_document(dir + "/rec/session.json");
    ASSERT_EQ(from_rec.lobes.size(), 1u);
    const TriangleMesh rec_mesh = read_mesh(dir + "/rec/" + from_rec.lobes[0].mesh_file);
    // The session it wrote rebuilds the same lobe.
    r = run("lobes " + dir + "/rec/session.json --out " + dir + "/session");
    ASSERT_EQ(r.code, 0) << r.out;
    const Document from_session = load_document(dir + "/session/session.json");
    const TriangleMesh session_mesh = read_mesh(dir + "/session/" + from_session.lobes[0].mesh_file);
    EXPECT_EQ(session_mesh.positions, rec_mesh.positions);
    EXPECT_EQ(session_mesh.triangles, rec_mesh.triangles);
    // A mesh becomes one lobe scaled to --size.
    const std::string spot_obj = test::shared_data("data/models/spot.obj");
    if (spot_obj.empty()) return;
    r = run("lobes " + spot_obj + " --size 0.8 --out " + dir + "/mesh");
    ASSERT_EQ(r.code, 0) << r.out;
    const TriangleMesh spot = read_mesh(dir + "/mesh/lobes/lobe_1.ply");
    glm::dvec3 lo, hi;
    bounding_box(spot, lo, hi);
    EXPECT_NEAR(std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z}), 0.8, 0.02);
    EXPECT_TRUE(measure_quality(spot).closed);
    // Its session holds the lobe itself: rebuilding the lobes from it gives the same mesh.
    const Document mesh_session = load_document(dir + "/mesh/session.json");
    ASSERT_EQ(mesh_session.lobes.size(), 1u);
    ASSERT_TRUE(mesh_session.lobes[0].model);
    EXPECT_EQ(mesh_session.lobes[0].model->source, "spot.obj");
    r = run("lobes " + dir + "/mesh/session.json --out " + dir + "/mesh-again");
    ASSERT_EQ(r.code, 0) << r.out;
    const TriangleMesh again = read_mesh(dir + "/mesh-again/lobes/lobe_1.ply");
    EXPECT_EQ(again.positions, spot.positions);
    EXPECT_EQ(again.triangles, spot.triangles);
    // --simplify-above: a mesh of more triangles is clustered before repair, and says so.
    r = run("lobes " + spot_obj + " --simplify-above 1000 --out " + dir + "/simplified");
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_NE(r.out.find("repaired: simplified 5856 triangles to "), std::string::npos) << r.out;
    const MeshQuality simplified = measure_quality(read_mesh(dir + "/simplified/lobes/lobe_1.ply"));
    EXPECT_TRUE(simplified.closed && simplified.manifold && simplified.outward);
    // A malformed mesh: one line naming the file, exit 1, nothing written.
    const std::string bad = dir + "/bad.obj";
    {
        std::ofstream f(bad);
        f << "v 0 0 0\nv 1 0 0\nf 1 2 7\n";
    }
    r = run("lobes " + bad + " --out " + dir + "/bad");
    EXPECT_EQ(r.code, 1) << r.out;
    EXPECT_EQ(count_lines_with(r.out, "error"), 1u) << r.out;
    EXPECT_NE(r.out.find("bad.obj"), std::string::npos) << r.out;
    EXPECT_FALSE(std::filesystem::exists(dir + "/bad/lobes/lobe_1.ply"));
}

TEST(Cli, InfoSummarisesARecording)
{
    const std::string demo = test::source_data("recordings/demo.lrec");
    if (demo.empty()) return;
    CliRun r = run("info --json " + demo);
    ASSERT_EQ(r.code, 0) << r.out;
    nlohmann::json j = nlohmann::json::parse(r.out);
    EXPECT_GT(j["frames"].get<int>(), 1000);
    EXPECT_GT(j["duration_s"].get<double>(), 10.0);
    EXPECT_GT(j["hands"]["right"]["frames"].get<int>(), 1000);
    EXPECT_GE(j["hands"]["right"]["dropouts"].get<int>(), 1);
    EXPECT_GE(j["events"]["key"].get<int>(), 2);
}

TEST(Cli, UnusableInputsFailWithOneLineNamingTheFile)
{
    const std::string dir = test::temp_dir("cli-bad");
    std::ofstream(dir + "/garbage.lrec") << "this is not a recording at all";
    std::ofstream(dir + "/empty.json") << "";
    const std::string cases[] = {
        "info " + dir + "/garbage.lrec",
        "replay " + dir + "/garbage.lrec --out " + dir + "/o",
        "replay " + dir + "/missing.lrec --out " + dir + "/o",
        "import-leap " + dir + "/empty.json -o " + dir + "/x.lrec",
        "import-webxr " + dir + "/empty.json -o " + dir + "/x.lrec",
        "synth " + dir + "/empty.json -o " + dir + "/x.lrec",
    };
    for (const std::string& c : cases) {
        CliRun r = run(c);
        EXPECT_EQ(r.code, 1) << c << "\n" << r.out;
        EXPECT_EQ(count_lines_with(r.out, "error:"), 1u) << c << "\n" << r.out;
        EXPECT_NE(r.out.find(dir), std::string::npos) << c << "\n" << r.out;
    }
}

TEST(Cli, ImportedLeapCaptureReplaysWithoutStrokesFromAGrab)
{
    const std::string grab = test::shared_data("data/real/leap-grab.json");
    if (grab.empty()) return;
    const std::string dir = test::temp_dir("cli-leap");
    CliRun imp = run("import-leap " + grab + " -o " + dir + "/grab.lrec");
    ASSERT_EQ(imp.code, 0) << imp.out;
    CliRun rep = run("replay " + dir + "/grab.lrec --out " + dir + "/out");
    EXPECT_EQ(rep.code, 1) << rep.out; // nothing drawn: "no strokes"
    EXPECT_NE(rep.out.find("no strokes"), std::string::npos) << rep.out;
}

TEST(Cli, ReplayStoresEditsAndWarnsAboutADragThatPicksNothing)
{
    const std::string recording = test::source_data("recordings/edit-stroke-transform.lrec");
    if (recording.empty()) return;
    const std::string dir = test::temp_dir("cli-edits");
    CliRun shipped = run("replay " + recording + " --out " + dir + "/a");
    ASSERT_EQ(shipped.code, 0) << shipped.out;
    EXPECT_EQ(count_lines_with(shipped.out, "warning:"), 0u) << shipped.out;
    const Document doc = load_document(dir + "/a/session.json");
    ASSERT_EQ(doc.edits.size(), 4u);
    EXPECT_STREQ(edit_kind_name(doc.edits[0].kind()), "drag:edit-stroke");
    EXPECT_STREQ(edit_kind_name(doc.edits[3].kind()), "drag:scale-lobe");

    // One loop, then a move drag 45 cm to its side: recorded as nothing, with a warning.
    {
        std::ofstream sc(dir + "/far.scenario.json");
        sc << R"({"format": "lobesketch-scenario", "version": 1, "seed": 5, "steps": [
            {"type": "stroke", "ellipse": {"center": [0.1, 1.35, -0.4], "radii": [0.1, 0.1]}},
            {"type": "key", "key": "M"},
            {"type": "drag", "from": [0.1, 1.35, 0.05], "to": [0.15, 1.35, 0.05], "speed": 0.15}]})";
    }
    ASSERT_EQ(run("synth " + dir + "/far.scenario.json -o " + dir + "/far.lrec").code, 0);
    CliRun far = run("replay " + dir + "/far.lrec --out " + dir + "/b");
    EXPECT_EQ(far.code, 0) << far.out;
    EXPECT_EQ(count_lines_with(far.out, "warning:"), 1u) << far.out;
    EXPECT_NE(far.out.find("move-lobe drag at t="), std::string::npos) << far.out;
    EXPECT_NE(far.out.find("edits nothing: its start is outside every lobe"), std::string::npos) << far.out;
    EXPECT_TRUE(load_document(dir + "/b/session.json").edits.empty());
}
