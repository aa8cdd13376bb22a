// The degenerate-input corpus (tests/data/degenerate/, README.md there): every bad session,
// settings file, species preset, recording, mesh and live stroke gives exactly one line that
// says what is wrong (naming the file when a reader is given one), never a crash, and the
// document it was meant for stays as it was. Also the document, builder, remeshing and
// growth limits of docs/limits.md, each hit with a small generated input.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "app/cli/cli_common.h"
#include "core/document.h"
#include "core/errors.h"
#include "core/settings_json.h"
#include "core/settings_table.h"
#include "growth/branch_geometry.h"
#include "growth/grow.h"
#include "growth/species.h"
#include "growth/subtree_library.h"
#include "input/recording.h"
#include "app/session/session_builder.h"
#include "tests/support/shapes.h"
#include "app/session/lobe_document.h"
#include "meshing/mesh_io.h"
#include "meshing/model_import.h"
#include "meshing/remesh.h"
#include "tests/support/cli_run.h"
#include "tests/support/test_data.h"
#include "tests/support/test_paths.h"

using namespace lobe;
using nlohmann::json;
namespace fs = std::filesystem;

namespace {

const std::string kRoot = "tests/data/degenerate";

struct Case {
    std::string file; ///< relative to kRoot
    std::string kind;
    std::string expect;
    std::string note;
    std::string path() const { return test::source_path(kRoot + "/" + file); }
};

/// True when the corpus files named (relative to kRoot) are there; else the test has failed
/// with one line naming the first one missing.
bool have_corpus(std::initializer_list<const char*> files, const char* file = __builtin_FILE(), int line = __builtin_LINE())
{
    for (const char* f : files)
        if (test::source_data(kRoot + "/" + f, file, line).empty()) return false;
    return true;
}

std::vector<Case> load_cases()
{
    std::ifstream in(test::source_path(kRoot + "/cases.json"));
    const json j = json::parse(in);
    std::vector<Case> out;
    for (const json& c : j.at("cases"))
        out.push_back({c.at("file").get<std::string>(), c.at("kind").get<std::string>(),
                       c.at("expect").get<std::string>(), c.at("note").get<std::string>()});
    return out;
}

const std::vector<Case>& cases()
{
    static const std::vector<Case> c = load_cases();
    return c;
}

std::vector<Case> cases_of(const std::string& kind)
{
    std::vector<Case> out;
    for (const Case& c : cases())
        if (c.kind == kind) out.push_back(c);
    return out;
}

/// The checks every message gets: one line, the expected words, and the file's name when the
/// reader was given a file.
void expect_message(const Case& c, const std::string& msg, bool names_file)
{
    EXPECT_EQ(msg.find_first_of("\r\n"), std::string::npos) << "more than one line: " << msg;
    EXPECT_NE(msg.find(c.expect), std::string::npos) << "expected \"" << c.expect << "\" in: " << msg;
    if (names_file) {
        EXPECT_NE(msg.find(fs::path(c.file).filename().string()), std::string::npos) << msg;
    }
    EXPECT_FALSE(msg.empty());
}

/// Runs `read` on the case's file, which must throw lobe::Error with the expected message.
template <typename Read>
void expect_refused(const Case& c, Read read)
{
    try {
        read(c.path());
        ADD_FAILURE() << "no error";
    } catch (const Error& e) {
        expect_message(c, e.what(), true);
    }
}

Document base_document() { return load_document(test::source_path(kRoot + "/base-session.json")); }

/// A number of a stroke case: JSON numbers, or "nan", "inf", "-inf".
double case_number(const json& v)
{
    if (v.is_number()) return v.get<double>();
    const std::string s = v.get<std::string>();
    if (s == "nan") return std::numeric_limits<double>::quiet_NaN();
    if (s == "inf") return std::numeric_limits<double>::infinity();
    if (s == "-inf") return -std::numeric_limits<double>::infinity();
    throw std::runtime_error("bad number in a stroke case: " + s);
}

InputAction stroke_action(const Case& c)
{
    std::ifstream in(c.path());
    const json j = json::parse(in);
    InputAction a;
    a.type = InputAction::Type::StrokeCompleted;
    a.time = 5.0;
    a.stroke.id = 100;
    a.stroke.kind = stroke_kind_from_name(j.at("kind").get<std::string>());
    const json& pts = j.at("points");
    for (std::size_t i = 0; i < pts.size(); ++i) {
        StrokePoint p;
        for (int k = 0; k < 3; ++k) p.position[k] = static_cast<float>(case_number(pts[i][static_cast<std::size_t>(k)]));
        p.time = j.contains("times") ? case_number(j["times"][i]) : 5.0 + 0.01 * static_cast<double>(i);
        a.stroke.points.push_back(p);
    }
    return a;
}

} // namespace

TEST(DegenerateInput, CorpusCoversEveryKindAndEveryFileIsListed)
{
    if (!have_corpus({"cases.json"})) return;
    std::map<std::string, int> count;
    std::set<std::string> listed;
    for (const Case& c : cases()) {
        ++count[c.kind];
        EXPECT_TRUE(listed.insert(c.file).second) << "listed twice: " << c.file;
        EXPECT_TRUE(fs::is_regular_file(c.path())) << c.file;
        EXPECT_FALSE(c.expect.empty()) << c.file;
    }
    for (const char* kind : {"session", "lobes", "stroke", "settings", "species", "recording", "mesh", "model"})
        EXPECT_GE(count[kind], 5) << kind;
    // Every file of the kind folders has its case (a file without one would never be read).
    for (const auto& [kind, n] : count) {
        const std::string folder = test::source_path(kRoot + "/" + kind);
        if (!test::require_data(folder)) continue;
        for (const auto& f : fs::directory_iterator(folder))
            EXPECT_TRUE(listed.count(kind + "/" + f.path().filename().string())) << "not in cases.json: " << f.path();
    }
    RecordProperty("cases", static_cast<int>(cases().size()));
}

TEST(DegenerateInput, SessionDocumentsAreRefusedInOneLineAndTheOpenDocumentStays)
{
    if (!have_corpus({"cases.json", "base-session.json"})) return;
    for (const Case& c : cases_of("session")) {
        if (!test::require_data(c.path())) continue;
        SCOPED_TRACE(c.file + " (" + c.note + ")");
        Document doc = base_document();
        const json before = document_to_json(doc);
        expect_refused(c, [&](const std::string& p) { doc = load_document(p); });
        EXPECT_EQ(document_to_json(doc), before);
    }
}

TEST(DegenerateInput, LobeStrokesThatCannotJoinAreReportedInOneLineAndTheDocumentStays)
{
    if (!have_corpus({"cases.json"})) return;
    for (const Case& c : cases_of("lobes")) {
        if (!test::require_data(c.path())) continue;
        SCOPED_TRACE(c.file + " (" + c.note + ")");
        Document doc;
        ASSERT_NO_THROW(doc = load_document(c.path())) << "a session that loads, whose lobes report a problem";
        const json before = document_to_json(doc);
        std::vector<std::string> warnings;
        ASSERT_NO_THROW(build_document_lobes(doc, &warnings));
        bool found = false;
        for (const std::string& w : warnings) {
            EXPECT_EQ(w.find_first_of("\r\n"), std::string::npos) << w;
            found = found || w.find(c.expect) != std::string::npos;
        }
        std::string all;
        for (const std::string& w : warnings) all += "\n  " + w;
        EXPECT_TRUE(found) << "expected \"" << c.expect << "\" among:" << all;
        EXPECT_EQ(document_to_json(doc), before);
    }
}

TEST(DegenerateInput, LiveStrokesAreRefusedWithOneMessageAndChangeNothing)
{
    if (!have_corpus({"cases.json", "base-session.json"})) return;
    for (const Case& c : cases_of("stroke")) {
        if (!test::require_data(c.path())) continue;
        SCOPED_TRACE(c.file + " (" + c.note + ")");
        SessionBuilder builder(base_document());
        const json before = document_to_json(builder.document());
        EXPECT_FALSE(builder.apply(stroke_action(c)));
        ASSERT_EQ(builder.messages().size(), 1u);
        expect_message(c, builder.messages().front(), false);
        EXPECT_EQ(document_to_json(builder.document()), before);
        // Nothing was recorded for undo either.
        InputAction undo;
        undo.type = InputAction::Type::Undo;
        EXPECT_FALSE(builder.apply(undo));
    }
}

TEST(DegenerateInput, GoodLiveStrokesStillJoin)
{
    if (!have_corpus({"base-session.json"})) return;
    // The control: a bent lobe stroke and a straight trunk stroke are taken.
    SessionBuilder builder(base_document());
    InputAction a;
    a.type = InputAction::Type::StrokeCompleted;
    a.stroke.id = 100;
    for (int i = 0; i < 30; ++i) {
        const double t = 0.2 * i;
        a.stroke.points.push_back({glm::vec3(static_cast<float>(0.2 * std::cos(t)), 1.4f + static_cast<float>(0.2 * std::sin(t)), -0.3f), 5.0 + 0.01 * i});
    }
    EXPECT_TRUE(builder.apply(a));
    a.stroke.id = 101;
    a.stroke.kind = StrokeKind::Trunk;
    a.stroke.points.clear();
    for (int i = 0; i < 30; ++i) a.stroke.points.push_back({glm::vec3(0.0f, 0.8f + 0.02f * static_cast<float>(i), -0.4f), 6.0});
    EXPECT_TRUE(builder.apply(a));
    EXPECT_TRUE(builder.messages().empty());
    EXPECT_EQ(builder.document().strokes.size(), base_document().strokes.size() + 2);
}

TEST(DegenerateInput, SettingsFilesAreRefusedInOneLine)
{
    if (!have_corpus({"cases.json", "base-session.json"})) return;
    for (const Case& c : cases_of("settings")) {
        if (!test::require_data(c.path())) continue;
        SCOPED_TRACE(c.file + " (" + c.note + ")");
        Document doc = base_document();
        const json before = settings_json(doc.settings);
        expect_refused(c, [&](const std::string& p) {
            doc.settings = cli::load_settings_file(p);
            validate_settings(doc.settings);
        });
        EXPECT_EQ(settings_json(doc.settings), before);
    }
}

TEST(DegenerateInput, SpeciesPresetsAreRefusedInOneLineAndSettingsStay)
{
    if (!have_corpus({"cases.json"})) return;
    for (const Case& c : cases_of("species")) {
        if (!test::require_data(c.path())) continue;
        SCOPED_TRACE(c.file + " (" + c.note + ")");
        Settings s;
        const json before = settings_json(s);
        expect_refused(c, [&](const std::string& p) { apply_species(s, load_species(p)); });
        EXPECT_EQ(settings_json(s), before);
    }
}

TEST(DegenerateInput, RecordingsAreRefusedInOneLine)
{
    if (!have_corpus({"cases.json"})) return;
    for (const Case& c : cases_of("recording")) {
        if (!test::require_data(c.path())) continue;
        SCOPED_TRACE(c.file + " (" + c.note + ")");
        expect_refused(c, [](const std::string& p) { read_recording(p); });
    }
}

TEST(DegenerateInput, MeshesAreRefusedInOneLine)
{
    if (!have_corpus({"cases.json"})) return;
    for (const Case& c : cases_of("mesh")) {
        if (!test::require_data(c.path())) continue;
        SCOPED_TRACE(c.file + " (" + c.note + ")");
        expect_refused(c, [](const std::string& p) { read_mesh(p); });
    }
}

TEST(DegenerateInput, MeshesThatReadButCannotBecomeALobeAreRefusedInOneLine)
{
    if (!have_corpus({"cases.json"})) return;
    for (const Case& c : cases_of("model")) {
        if (!test::require_data(c.path())) continue;
        SCOPED_TRACE(c.file + " (" + c.note + ")");
        expect_refused(c, [](const std::string& p) { lobe_from_model(p); });
    }
}

TEST(DegenerateInput, TheCommandLineSaysOneLineAndExitsWithOne)
{
    if (!have_corpus({"recording/wrong-magic.lrec", "recording/text-nan-joints.txt", "session/version-unknown.json",
                      "session/stroke-duplicate-id.json", "base-session.json", "settings/max-nodes-range.json",
                      "species/max-nodes-range.json"}))
        return;
    const std::string out = test::temp_dir("degenerate_cli");
    const struct {
        std::string args, file, expect;
    } runs[] = {
        {"replay " + test::source_path(kRoot + "/recording/wrong-magic.lrec") + " --out " + out + "/r1",
         "wrong-magic.lrec", "wrong magic bytes"},
        {"replay " + test::source_path(kRoot + "/recording/text-nan-joints.txt") + " --out " + out + "/r2",
         "text-nan-joints.txt", "no usable frames"},
        {"grow " + test::source_path(kRoot + "/session/version-unknown.json") + " -o " + out + "/t.glb",
         "version-unknown.json", "unsupported session version 99"},
        {"grow " + test::source_path(kRoot + "/session/stroke-duplicate-id.json") + " -o " + out + "/t.glb",
         "stroke-duplicate-id.json", "stroke id 1 is used twice"},
        {"grow " + test::source_path(kRoot + "/base-session.json") + " --settings " +
             test::source_path(kRoot + "/settings/max-nodes-range.json") + " -o " + out + "/t.glb",
         "max-nodes-range.json", "max_nodes must be in [100, 5000000]"},
        {"grow " + test::source_path(kRoot + "/base-session.json") + " --species " +
             test::source_path(kRoot + "/species/max-nodes-range.json") + " -o " + out + "/t.glb",
         "max-nodes-range.json", "max_nodes must be in [100, 5000000]"},
    };
    for (const auto& r : runs) {
        SCOPED_TRACE(r.args);
        const test::CliRun run = test::run_cli(r.args);
        EXPECT_EQ(run.code, 1) << run.out;
        std::string text = run.out;
        while (!text.empty() && text.back() == '\n') text.pop_back();
        EXPECT_EQ(text.find('\n'), std::string::npos) << "more than one line:\n" << run.out;
        EXPECT_NE(text.find(r.file), std::string::npos) << run.out;
        EXPECT_NE(text.find(r.expect), std::string::npos) << run.out;
    }
    EXPECT_FALSE(fs::exists(out + "/t.glb"));
}

// ------------------------------------------------------------------ limits (docs/limits.md)

namespace {

json minimal_session()
{
    return json{{"format", "lobesketch-session"}, {"version", 1}};
}

std::string refusal(const json& j)
{
    try {
        document_from_json(j);
    } catch (const InvalidInput& e) {
        return e.what();
    }
    return "(accepted)";
}

} // namespace

TEST(Limits, DocumentListsBeyondTheirLimitsAreRefusedNamingTheList)
{
    // The counts are checked before the entries are read, so zeros stand for the entries.
    json j = minimal_session();
    j["strokes"] = json::array();
    for (std::size_t i = 0; i <= kMaxDocumentStrokes; ++i) j["strokes"].push_back(0);
    EXPECT_EQ(refusal(j), "strokes: 100001 strokes, more than the 100000 a session may hold");

    j = minimal_session();
    j["lobes"] = json::array({json{{"id", 1}, {"strokes", json(std::vector<int>(kMaxDocumentStrokes + 1, 1))}}});
    EXPECT_EQ(refusal(j), "lobes[0].strokes: 100001 stroke ids, more than the 100000 a session may hold");

    j = minimal_session();
    j["trees"] = json::array({json{{"id", 1}, {"lobes", json(std::vector<int>(kMaxDocumentLobes + 1, 1))}}});
    EXPECT_EQ(refusal(j), "trees[0].lobes: 1001 lobe ids, more than the 1000 a session may hold");

    j = minimal_session();
    j["edits"] = json(std::vector<int>(kMaxDocumentEdits + 1, 0));
    EXPECT_EQ(refusal(j), "edits: 20001 edits, more than the 20000 a session may hold");
}

TEST(Limits, AStrokeOfTooManyPointsIsRefused)
{
    json j = minimal_session();
    json pts = json(std::vector<int>(kMaxStrokePoints + 1, 0));
    j["strokes"] = json::array({json{{"id", 1}, {"kind", "lobe"}, {"points", std::move(pts)}}});
    EXPECT_EQ(refusal(j), "strokes[0].points: 1000001 points, more than the 1000000 a session may hold");

    // The same limit holds for a stroke drawn live.
    SessionBuilder builder;
    InputAction a;
    a.type = InputAction::Type::StrokeCompleted;
    a.stroke.kind = StrokeKind::Trunk;
    a.stroke.points.resize(kMaxStrokePoints + 1);
    for (std::size_t i = 0; i < a.stroke.points.size(); ++i)
        a.stroke.points[i].position = glm::vec3(0.0f, 1e-5f * static_cast<float>(i), 0.0f);
    EXPECT_FALSE(builder.apply(a));
    ASSERT_EQ(builder.messages().size(), 1u);
    EXPECT_NE(builder.messages()[0].find("1000001 points, more than the 1000000 a stroke may have"), std::string::npos)
        << builder.messages()[0];
    EXPECT_TRUE(builder.document().strokes.empty());
}

TEST(Limits, TheBuilderRefusesStrokesLobesAndEditsPastTheDocumentLimits)
{
    auto trunk = [](std::int64_t id) {
        Stroke s;
        s.id = id;
        s.kind = StrokeKind::Trunk;
        for (int i = 0; i < 8; ++i) s.points.push_back({glm::vec3(0.0f, 0.8f + 0.01f * static_cast<float>(i), 0.0f), 0.0});
        return s;
    };
    {
        Document doc;
        for (std::size_t i = 0; i < kMaxDocumentStrokes; ++i) doc.strokes.push_back(trunk(static_cast<std::int64_t>(i) + 1));
        SessionBuilder builder(std::move(doc));
        InputAction a;
        a.type = InputAction::Type::StrokeCompleted;
        a.stroke = trunk(0);
        EXPECT_FALSE(builder.apply(a));
        ASSERT_EQ(builder.messages().size(), 1u);
        EXPECT_NE(builder.messages()[0].find("the session already holds 100000 strokes, the most it may hold"),
                  std::string::npos)
            << builder.messages()[0];
        EXPECT_EQ(builder.document().strokes.size(), kMaxDocumentStrokes);
    }
    {
        Document doc;
        for (std::size_t i = 0; i < kMaxDocumentLobes; ++i)
            doc.lobes.push_back(LobeRecord::of_strokes(static_cast<std::int64_t>(i) + 1));
        SessionBuilder builder(std::move(doc));
        InputAction n;
        n.type = InputAction::Type::NewLobe;
        builder.apply(n);
        InputAction a;
        a.type = InputAction::Type::StrokeCompleted;
        for (int i = 0; i < 30; ++i) {
            const double t = 0.2 * i;
            a.stroke.points.push_back({glm::vec3(static_cast<float>(0.2 * std::cos(t)), 1.4f + static_cast<float>(0.2 * std::sin(t)), 0.0f), 0.0});
        }
        EXPECT_FALSE(builder.apply(a));
        ASSERT_EQ(builder.messages().size(), 1u);
        EXPECT_NE(builder.messages()[0].find("it would start a new lobe, and the session already holds 1000 lobes"),
                  std::string::npos)
            << builder.messages()[0];
        EXPECT_EQ(builder.document().lobes.size(), kMaxDocumentLobes);
        EXPECT_TRUE(builder.document().strokes.empty());
    }
    {
        Document doc;
        for (std::size_t i = 0; i < kMaxDocumentEdits; ++i) {
            EditOperation op;
            op.id = static_cast<std::int64_t>(i) + 1;
            op.params = MoveLobeParams{};
            doc.edits.push_back(op);
        }
        SessionBuilder builder(std::move(doc));
        InputAction a;
        a.type = InputAction::Type::DragCompleted;
        a.drag.tool = Tool::MoveLobe;
        a.drag.path = {{glm::vec3(0.0f, 1.0f, 0.0f), 1.0}, {glm::vec3(0.1f, 1.0f, 0.0f), 1.1}};
        EXPECT_FALSE(builder.apply(a));
        ASSERT_EQ(builder.messages().size(), 1u);
        EXPECT_NE(builder.messages()[0].find("the session already holds 20000 edits"), std::string::npos)
            << builder.messages()[0];
        EXPECT_EQ(builder.document().edits.size(), kMaxDocumentEdits);
    }
}

TEST(Limits, RemeshingRefusesASurfaceThatWouldMakeTooManyTriangles)
{
    // About 50 m²: 4.6 million triangles at 5 mm.
    const TriangleMesh sphere = test::ellipsoid({0.0, 0.0, 0.0}, {2.0, 2.0, 2.0}, 2);
    RemeshOptions o;
    o.target_edge_length_m = 0.005;
    try {
        remesh_isotropic(sphere, o);
        ADD_FAILURE() << "no error";
    } catch (const InvalidInput& e) {
        const std::string msg = e.what();
        EXPECT_NE(msg.find("remesh_isotropic:"), std::string::npos) << msg;
        EXPECT_NE(msg.find("more than the 4000000 allowed"), std::string::npos) << msg;
    }
    o.target_edge_length_m = 0.5; // the same surface at a coarse spacing is remeshed
    EXPECT_NO_THROW(remesh_isotropic(sphere, o));
}

TEST(Limits, TheWholeTreeStopsAtItsNodeCapAndSaysWhichLobesItCut)
{
    GrowthLobe a, b;
    a.id = 1;
    a.mesh = test::ellipsoid({0.0, 1.4, 0.0}, {0.17, 0.14, 0.16}, 3);
    b.id = 2;
    b.mesh = test::ellipsoid({0.5, 1.4, 0.0}, {0.17, 0.14, 0.16}, 3);
    const std::vector<std::vector<glm::vec3>> trunk{{{0, 1.0f, 0}, {0, 1.1f, 0}, {0, 1.2f, 0}, {0, 1.3f, 0}}};
    GrowthSettings settings;
    const GrowthResult free = grow_tree(trunk, {a, b}, settings, default_subtree_library(), 1);
    ASSERT_GT(free.tree.size(), free.skeleton_nodes + 200);
    const std::size_t cap = free.skeleton_nodes + 50;
    const GrowthResult capped = grow_tree(trunk, {a, b}, settings, default_subtree_library(), 1, cap);
    EXPECT_LE(capped.tree.size(), cap + 64); // the last subtree may finish past the cap
    // The lobes grow together (one tree): each lobe the cap cut short says so in one line.
    std::size_t said = 0;
    for (const std::string& m : capped.messages) {
        EXPECT_EQ(m.find('\n'), std::string::npos) << m;
        if (m.find(": node cap of") != std::string::npos || m.find(": not grown, the tree already has") != std::string::npos)
            ++said;
    }
    std::size_t cut = 0;
    for (const LobeGrowthStats& l : capped.lobes) cut += l.node_cap ? 1 : 0;
    EXPECT_GE(cut, 1u);
    EXPECT_EQ(said, cut);
}

TEST(Limits, TreeGeometryRefusesMoreTrianglesThanItsLimit)
{
    // One branch 1 km long, rings every 2 mm with 64 segments: about 64 million triangles.
    TreeGraph g;
    TreeNode root;
    root.kind = TreeNodeKind::Root;
    root.radius = 0.05f;
    g.nodes.push_back(root);
    TreeNode tip;
    tip.parent = 0;
    tip.position = glm::vec3(0.0f, 1000.0f, 0.0f);
    tip.radius = 0.01f;
    tip.kind = TreeNodeKind::Skeleton;
    g.nodes.push_back(tip);
    BranchSettings branches;
    branches.radial_segments = 64;
    branches.ring_spacing_m = 0.002;
    LeafSettings leaves;
    leaves.per_node = 0;
    try {
        build_tree_geometry(g, branches, leaves, 1);
        ADD_FAILURE() << "no error";
    } catch (const InvalidInput& e) {
        const std::string msg = e.what();
        EXPECT_NE(msg.find("tree geometry: LOD0 would have about"), std::string::npos) << msg;
        EXPECT_NE(msg.find("more than the 50000000 allowed"), std::string::npos) << msg;
    }
}
