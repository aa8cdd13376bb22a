#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "core/document.h"
#include "core/errors.h"
#include "tests/support/test_paths.h"

using namespace lobe;

namespace {
Document sample_document()
{
    Document d;
    d.seed = 42;
    d.source_recording = "recordings/demo.lrec";
    Stroke s;
    s.id = 3;
    s.kind = StrokeKind::Trunk;
    s.hand = Hand::Left;
    s.closed = true;
    s.points = {{{0.1f, 1.2f, -0.3f}, 0.5}, {{0.11f, 1.25f, -0.31f}, 0.51}};
    d.strokes.push_back(s);
    LobeRecord lobe7 = LobeRecord::of_strokes(7, {3}, "lobes/lobe_7.ply");
    lobe7.split_angle_deg = 22.5;
    lobe7.species = "willow";
    lobe7.leaf_length_m = 0.07;
    lobe7.leaves_per_node = 6;
    lobe7.seed = 12345678901ull;
    d.lobes.push_back(lobe7);
    d.settings.growth.split_angle_deg = 40;
    d.settings.growth.subtree_weights = {{"fork", 2.0}, {"whorl", 0.5}};
    d.settings.branches.radial_segments = 11;
    d.settings.leaves.shape = "needle";
    d.settings.leaves.color[1] = 0.7;
    EditOperation deform;
    deform.id = 1;
    deform.target = 7;
    deform.hand = Hand::Left;
    deform.path = {{{0.1, 0.2, 0.3}, 1.5}, {{0.1, 0.25, 0.3}, std::nullopt}};
    d.edits.push_back(deform);
    TreeInstance t;
    t.id = 1;
    t.seed = 9;
    t.transform[3][0] = 2.0f;
    d.trees.push_back(t);
    d.settings.input.pinch_start_m = 0.007;
    return d;
}
} // namespace

TEST(Document, SaveLoadRoundTripKeepsEveryField)
{
    std::string dir = test::temp_dir("doc-roundtrip");
    Document d = sample_document();
    save_document(dir + "/s.json", d);
    Document e = load_document(dir + "/s.json");
    EXPECT_EQ(document_to_json(d), document_to_json(e));
    EXPECT_EQ(e.strokes.at(0).kind, StrokeKind::Trunk);
    EXPECT_EQ(e.strokes.at(0).hand, Hand::Left);
    EXPECT_FLOAT_EQ(e.trees.at(0).transform[3][0], 2.0f);
    EXPECT_DOUBLE_EQ(e.settings.input.pinch_start_m, 0.007);
    EXPECT_EQ(e.lobes.at(0).leaf_length_m, std::optional<double>(0.07));
    EXPECT_EQ(e.lobes.at(0).leaves_per_node, std::optional<int>(6));
    EXPECT_EQ(e.lobes.at(0).seed, std::optional<std::uint64_t>(12345678901ull));
}

TEST(Document, AtomicSaveLeavesNoTemporaryFilesAndReplacesOldVersion)
{
    std::string dir = test::temp_dir("doc-atomic");
    Document d = sample_document();
    save_document(dir + "/s.json", d);
    d.seed = 43;
    save_document(dir + "/s.json", d);
    int files = 0;
    for ([[maybe_unused]] auto& e : std::filesystem::directory_iterator(dir)) ++files;
    EXPECT_EQ(files, 1);
    EXPECT_EQ(load_document(dir + "/s.json").seed, 43u);
}

TEST(Document, FailedSaveKeepsThePreviousFile)
{
    std::string dir = test::temp_dir("doc-failsave");
    save_document(dir + "/s.json", sample_document());
    // The target folder of the second save does not exist: the save must fail cleanly.
    EXPECT_THROW(save_document(dir + "/missing/s.json", sample_document()), FileError);
    EXPECT_NO_THROW(load_document(dir + "/s.json"));
}

TEST(Document, BadDocumentsGiveOneLineMessagesNamingTheFile)
{
    std::string dir = test::temp_dir("doc-bad");
    struct Case {
        const char* text;
        const char* expect;
    };
    const Case cases[] = {
        {"", "not valid JSON"},
        {"{\"format\":\"lobesketch-session\",\"version\":99}", "unsupported session version 99"},
        {"[1,2]", "not a session document"},
        {"{\"format\":\"lobesketch-session\",\"version\":1,\"strokes\":[{\"id\":1,\"kind\":\"leaf\",\"points\":[]}]}",
         "unknown stroke kind"},
        {"{\"format\":\"lobesketch-session\",\"version\":1,\"strokes\":[{\"id\":1,\"kind\":\"lobe\",\"points\":[[0,1]]}]}",
         "expected [x, y, z]"},
        {"{\"format\":\"lobesketch-session\",\"version\":1,\"settings\":{\"input\":{\"pinch_start_m\":\"x\"}}}",
         "expected a number"},
        {"{\"format\":\"lobesketch-session\",\"version\":1,\"settings\":{\"input\":{\"bogus\":1}}}", "unknown key 'bogus'"},
        {"{\"format\":\"lobesketch-session\",\"version\":1,\"settings\":{\"input\":{\"pinch_start_m\":5}}}",
         "pinch_start_m must be"},
        {"{\"format\":\"lobesketch-session\",\"version\":1,\"settings\":{\"growth\":{\"split_angle_deg\":2}}}",
         "settings.growth.split_angle_deg must be in [5, 180]"},
        {"{\"format\":\"lobesketch-session\",\"version\":1,\"settings\":{\"growth\":{\"max_nodes\":1e30}}}",
         "settings.growth.max_nodes: expected an integer"},
        {"{\"format\":\"lobesketch-session\",\"version\":1,\"settings\":{\"leaves\":{\"shape\":\"star\"}}}",
         "settings.leaves.shape must be"},
        {"{\"format\":\"lobesketch-session\",\"version\":1,\"settings\":{\"branches\":{\"bark_color\":[1,2]}}}",
         "settings.branches.bark_color: expected [r, g, b]"},
        {"{\"format\":\"lobesketch-session\",\"version\":1,\"lobes\":[{\"id\":1,\"split_angle_deg\":500}]}",
         "lobes[0].split_angle_deg: must be in [5, 180]"},
        {"{\"format\":\"lobesketch-session\",\"version\":1,\"lobes\":[{\"id\":1,\"leaf_length_m\":2}]}",
         "lobes[0].leaf_length_m: must be in [0.002, 1]"},
        {"{\"format\":\"lobesketch-session\",\"version\":1,\"lobes\":[{\"id\":1,\"leaves_per_node\":2.5}]}",
         "lobes[0].leaves_per_node: expected an integer"},
        {"{\"format\":\"lobesketch-session\",\"version\":1,\"lobes\":[{\"id\":1,\"leaves_per_node\":65}]}",
         "lobes[0].leaves_per_node: must be in [0, 64]"},
        {"{\"format\":\"lobesketch-session\",\"version\":1,\"lobes\":[{\"id\":1,\"seed\":-3}]}",
         "lobes[0].seed: expected a non-negative integer"},
    };
    for (const Case& c : cases) {
        std::string path = dir + "/bad.json";
        std::ofstream(path) << c.text;
        try {
            load_document(path);
            ADD_FAILURE() << "accepted: " << c.text;
        } catch (const FileError& e) {
            std::string msg = e.what();
            EXPECT_NE(msg.find(path), std::string::npos) << msg;
            EXPECT_NE(msg.find(c.expect), std::string::npos) << msg;
            EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
        }
    }
    EXPECT_THROW(load_document(dir + "/does-not-exist.json"), FileError);
}
