// An L-system tree in a session (docs/session-format.md, trees[].grower): the grower and its
// source travel in the file, and the session regrows the same tree, byte for byte.
#include <filesystem>
#include <gtest/gtest.h>

#include <fstream>
#include <memory>
#include <sstream>
#include <string>

#include "app/export/tree_output.h"
#include "app/session/panel_controls.h"
#include "app/session/session_builder.h"
#include "app/session/session_file.h"
#include "app/session/tree_pipeline.h"
#include "core/document.h"
#include "core/errors.h"
#include "growth/lsystem/lsystem_grower.h"
#include "input/truth_surface.h"
#include "tests/support/test_paths.h"

using namespace lobe;

namespace {

std::string read(const std::string& path)
{
    std::ifstream in(path, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

/// A document whose tree grows with an L-system from its own text, in one lobe imported
/// from a mesh (so the file holds the lobe too).
Document lsystem_document()
{
    Document doc;
    doc.seed = 11;
    TruthSurface s;
    s.center = {0.0, 1.3, 0.0};
    s.radii = {0.4, 0.35, 0.4};
    LobeRecord lobe = LobeRecord::of_strokes(1);
    lobe.model = std::make_shared<const LobeModel>(LobeModel{"ball.obj", truth_surface_mesh(s, 3)});
    doc.lobes.push_back(std::move(lobe));
    GrowerChoice choice;
    choice.name = "lsystem";
    choice.params["source"] = std::string(
        "#define S 0.04\nLsystem: 1\nderivation length: 30\nAxiom: !(0.03)A?H(0,0,0)?P(0,0,0)\n"
        "A > ?H(u,v,w)?P(x,y,z) : inside(x+S*u,y+S*v,z+S*w) || y < 0.9 --> F(S)[+(35)~l(1)]/(137.5)A : 0.8\n"
        "A > ?H(u,v,w)?P(x,y,z) : inside(x+S*u,y+S*v,z+S*w) || y < 0.9 --> F(S)[&(40)A?H(0,0,0)?P(0,0,0)]/(90)A : 0.2\n"
        "A > ?H(u,v,w)?P(x,y,z) : !inside(x+S*u,y+S*v,z+S*w) && y >= 0.9 --> %\n"
        "endlsystem\n");
    choice.params["view"] = std::string("angle increment: 30\ntropism direction: 0,1,0\ninitial elasticity: 0.05\n");
    choice.params["source_name"] = std::string("crown.l");
    set_scene_grower(doc, choice);
    return doc;
}

std::string grown_glb(const Document& doc, const std::string& path)
{
    const BuiltTree tree = build_document_tree(doc);
    EXPECT_GT(tree.growth.tree.size(), 20u);
    EXPECT_FALSE(tree.growth.radii_set); // in lobes: the pipe model over the trunk and the crowns
    write_tree_file(path, doc, tree, document_tree_geometry(doc, tree), ExportOptions{});
    return read(path);
}

} // namespace

TEST(LSystemGrowerSession, TheGrowerAndItsSourceRoundTripAndRegrowTheSameBytes)
{
    const std::string dir = test::temp_dir("lsystem-session");
    const Document doc = lsystem_document();
    save_document(dir + "/session.json", doc);
    EXPECT_NE(read(dir + "/session.json").find("\"source\""), std::string::npos);
    const Document loaded = load_session(dir + "/session.json");
    EXPECT_EQ(scene_grower(loaded), scene_grower(doc));
    // One file name in two folders: node names come from the file's stem.
    std::filesystem::create_directories(dir + "/a");
    std::filesystem::create_directories(dir + "/b");
    std::filesystem::create_directories(dir + "/c");
    const std::string a = grown_glb(doc, dir + "/a/tree.glb");
    const std::string b = grown_glb(loaded, dir + "/b/tree.glb");
    ASSERT_GT(a.size(), 1000u);
    EXPECT_TRUE(a == b) << "the reloaded session grew another tree";
    // Another seed picks other stochastic productions: another tree.
    Document other = loaded;
    other.seed = 12;
    EXPECT_FALSE(grown_glb(other, dir + "/c/tree.glb") == a);
}

TEST(LSystemGrowerSession, ASessionNamingABadParameterIsRefusedWhenLoaded)
{
    const std::string dir = test::temp_dir("lsystem-session-bad");
    Document doc = lsystem_document();
    save_document(dir + "/session.json", doc);
    std::string text = read(dir + "/session.json");
    const std::size_t at = text.find("\"source_name\"");
    ASSERT_NE(at, std::string::npos);
    text.replace(at, 13, "\"colour\"");
    std::ofstream(dir + "/bad.json", std::ios::binary) << text;
    try {
        load_session(dir + "/bad.json");
        FAIL() << "a session with an unknown lsystem parameter loaded";
    } catch (const FileError& e) {
        EXPECT_NE(std::string(e.what()).find("params.colour: unknown parameter"), std::string::npos) << e.what();
    }
}

TEST(LSystemGrowerSession, ThePanelsPickItByItsCodeAndItsDefaultGrowsInTheLobes)
{
    // The panels' grower setting (desktop combo, VR GROWER button) takes panel codes from
    // growers(): code 1 makes the scene's tree an L-system tree with default parameters.
    const PanelControl* control = find_panel_control(SettingId::Grower);
    ASSERT_NE(control, nullptr);
    EXPECT_LE(lsystem::kGrowerPanelCode, control->accepts().hi);
    Document start = lsystem_document();
    start.trees.clear();
    SessionBuilder b(start);
    InputAction a;
    a.type = InputAction::Type::SettingChanged;
    a.time = 1.0;
    a.setting.id = SettingId::Grower;
    a.setting.value = lsystem::kGrowerPanelCode;
    ASSERT_TRUE(b.apply(a));
    const GrowerChoice& chosen = scene_grower(b.document());
    EXPECT_EQ(chosen.name, "lsystem");
    EXPECT_TRUE(chosen.params.empty());
    const BuiltTree tree = build_document_tree(b.document());
    ASSERT_GT(tree.growth.tree.size(), 50u);
    ASSERT_EQ(tree.growth.lobes.size(), 1u);
    EXPECT_GT(tree.growth.lobes[0].nodes, 20u); // the crown is in the lobe
    EXPECT_FALSE(tree.growth.leaves->empty());
}
