// Opening a session for use (app/session/session_file.h): the growers a document names are
// checked at load, and `--grower` picks the scene's grower.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <set>
#include <iterator>

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "app/session/panel_controls.h"
#include "app/session/session_builder.h"
#include "app/session/session_file.h"
#include "growth/grower.h"
#include "core/errors.h"
#include "core/settings_json.h"
#include "core/settings_table.h"
#include "tests/support/cli_run.h"
#include "tests/support/test_paths.h"

namespace lobe {
namespace {

std::string bytes(const std::string& path)
{
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

TEST(SessionFile, AGrowerNoGrowerKnowsIsRefusedAtLoadNamingTheFileAndTheField)
{
    const std::string dir = test::temp_dir("session-file-grower");
    Document doc;
    TreeInstance t;
    t.id = 1;
    t.grower.name = "no-such-grower";
    doc.trees.push_back(t);
    save_document(dir + "/s.json", doc);
    EXPECT_NO_THROW(load_document(dir + "/s.json")); // the shape is right
    try {
        load_session(dir + "/s.json");
        FAIL() << "a session naming an unknown grower was opened";
    } catch (const FileError& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find(dir + "/s.json"), std::string::npos) << m;
        EXPECT_NE(m.find("trees[0].grower.name: unknown grower \"no-such-grower\""), std::string::npos) << m;
        EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    }
    doc.trees[0].grower = GrowerChoice{};
    doc.trees[0].grower.params["depth"] = std::int64_t{3};
    save_document(dir + "/p.json", doc);
    EXPECT_THROW(load_session(dir + "/p.json"), FileError);
}

TEST(SessionFile, SettingTheSceneGrowerAddsATreeOfEveryLobeOnlyWhenThereIsNone)
{
    Document doc;
    doc.seed = 5;
    set_scene_grower(doc, GrowerChoice{});
    ASSERT_EQ(doc.trees.size(), 1u);
    EXPECT_EQ(doc.trees[0].seed, 5u);
    EXPECT_TRUE(doc.trees[0].lobe_ids.empty());
    set_scene_grower(doc, GrowerChoice{});
    EXPECT_EQ(doc.trees.size(), 1u);
    GrowerChoice unknown;
    unknown.name = "nope";
    EXPECT_THROW(set_scene_grower(doc, unknown), InvalidInput);
    EXPECT_EQ(doc.trees[0].grower.name, kDefaultGrowerName);
}

TEST(SessionFile, GrowWithTheDefaultGrowerNamedGivesTheSameTreeAndAnUnknownOneIsABadCommandLine)
{
    const std::string out = test::temp_dir("grow-grower");
    const std::string rec = test::source_path("recordings/table1-1lobe-5strokes.lrec");
    // One file name in two folders: node names come from the file's stem.
    std::filesystem::create_directories(out + "/a");
    std::filesystem::create_directories(out + "/b");
    ASSERT_EQ(test::run_cli("grow " + rec + " --out " + out + "/a/tree.glb").code, 0);
    const test::CliRun named = test::run_cli("grow " + rec + " --grower " + kDefaultGrowerName + " --out " + out + "/b/tree.glb");
    ASSERT_EQ(named.code, 0) << named.out;
    EXPECT_EQ(bytes(out + "/a/tree.glb"), bytes(out + "/b/tree.glb"));
    const test::CliRun bad = test::run_cli("grow " + rec + " --grower l-sistem --out " + out + "/c.glb");
    EXPECT_EQ(bad.code, 2) << bad.out;
    EXPECT_NE(bad.out.find("--grower"), std::string::npos) << bad.out;
    const test::CliRun help = test::run_cli("grow --help");
    EXPECT_NE(help.out.find(kDefaultGrowerName), std::string::npos) << help.out;
}

// tests/data/sessions/ holds sessions written by the build before growers, typed edits and the
// settings table (`replay` and `desktop --script` output): every edit kind, settings in full.
TEST(SessionFile, SessionsWrittenBeforeGrowersAndTypedEditsLoadUpgradeAndSaveToTheSameBytes)
{
    const std::string dir = test::temp_dir("session-file-before");
    std::size_t files = 0;
    std::set<EditKind> kinds;
    for (const std::filesystem::directory_entry& e :
         std::filesystem::directory_iterator(test::source_path("tests/data/sessions"))) {
        if (e.path().extension() != ".json") continue;
        const std::string name = e.path().filename().string();
        const Document doc = load_session(e.path().string());
        EXPECT_EQ(scene_grower(doc).name, kDefaultGrowerName) << name; // no grower named: the paper's
        EXPECT_FALSE(doc.edits.empty()) << name;
        for (const EditOperation& op : doc.edits) kinds.insert(op.kind());
        save_document(dir + "/" + name, doc);
        // Settings added to the table after these were written are saved with their defaults;
        // without them the saved file is the old one byte for byte.
        nlohmann::json saved = nlohmann::json::parse(bytes(dir + "/" + name));
        const nlohmann::json old = nlohmann::json::parse(bytes(e.path().string()));
        const nlohmann::json defaults = settings_json(Settings{});
        bool added = false;
        for (const SettingInfo& info : settings_table()) {
            std::string path = "/" + info.key;
            std::replace(path.begin(), path.end(), '.', '/');
            const nlohmann::json::json_pointer in_settings(path), at("/settings" + path);
            if (old.contains(at) || !saved.contains(at)) continue;
            EXPECT_EQ(saved[at], defaults[in_settings]) << name << " " << info.key;
            saved[at.parent_pointer()].erase(info.name);
            added = true;
        }
        EXPECT_EQ(saved, old) << name;
        if (!added) {
            EXPECT_EQ(bytes(dir + "/" + name), bytes(e.path().string())) << name;
        }
        ++files;
    }
    EXPECT_EQ(files, 2u);
    EXPECT_EQ(kinds.size(), 5u); // deform, move, rotate and scale a lobe; edit a stroke
}

TEST(SessionFile, AnOldSessionWithAMalformedEditOrSettingIsRefusedAtLoadNamingTheField)
{
    const std::string dir = test::temp_dir("session-file-malformed");
    const std::string good = bytes(test::source_path("tests/data/sessions/edit-stroke-transform.json"));
    struct Case {
        std::string from, to, field;
    };
    const std::vector<Case> cases = {
        {"\"hand\": \"right\"", "\"hand\": \"middle\"", "edits[0].params.hand"},
        {"\"remesh_iterations\": 4", "\"remesh_iterations\": -3", "settings.lobes.remesh_iterations"},
    };
    for (const Case& c : cases) {
        std::string text = good;
        const std::size_t at = text.find(c.from);
        ASSERT_NE(at, std::string::npos) << c.from;
        text.replace(at, c.from.size(), c.to);
        const std::string path = dir + "/bad.json";
        std::ofstream(path, std::ios::binary) << text;
        try {
            load_session(path);
            ADD_FAILURE() << "opened a session with " << c.to;
        } catch (const FileError& e) {
            const std::string m = e.what();
            EXPECT_NE(m.find(c.field), std::string::npos) << m;
            EXPECT_EQ(m.find('\n'), std::string::npos) << m;
        }
    }
}

InputAction grower_setting(double code, std::int64_t lobe = 0)
{
    InputAction a;
    a.type = InputAction::Type::SettingChanged;
    a.time = 1.0;
    a.setting.id = SettingId::Grower;
    a.setting.value = code;
    a.setting.lobe = lobe;
    return a;
}

TEST(SessionFile, ThePanelsGrowerSettingPicksAGrowerByItsPanelCodeAndRefusesOthersInOneLine)
{
    const PanelControl* control = find_panel_control(SettingId::Grower);
    ASSERT_NE(control, nullptr);
    EXPECT_STREQ(setting_name(SettingId::Grower), "grower");
    SessionBuilder b;
    // Every grower listed; the one already growing the tree changes nothing (no undo step).
    for (const Grower* g : growers()) {
        EXPECT_GE(g->panel_code(), control->accepts().lo);
        EXPECT_LE(g->panel_code(), control->accepts().hi);
        if (g->name() == kDefaultGrowerName) {
            EXPECT_FALSE(b.apply(grower_setting(g->panel_code())));
        }
    }
    EXPECT_TRUE(b.document().trees.empty());
    EXPECT_FALSE(b.apply(grower_setting(control->accepts().hi + 1)));
    EXPECT_FALSE(b.apply(grower_setting(0.5)));
    EXPECT_FALSE(b.apply(grower_setting(growers().front()->panel_code(), 3))); // tree-wide only
    ASSERT_EQ(b.messages().size(), 3u);
    EXPECT_NE(b.messages()[0].find("setting grower"), std::string::npos) << b.messages()[0];
    EXPECT_NE(b.messages()[0].find("no grower has panel code"), std::string::npos) << b.messages()[0];
    EXPECT_NE(b.messages()[2].find("tree-wide"), std::string::npos) << b.messages()[2];
    for (const std::string& m : b.messages()) EXPECT_EQ(m.find('\n'), std::string::npos) << m;
}

} // namespace
} // namespace lobe
