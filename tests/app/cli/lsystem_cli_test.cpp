// `lobesketch lsystem FILE.l`, `render FILE.l` and `grow --grower lsystem --lsystem FILE.l` as a
// user runs them: files written, the glTF validator's verdict, the word and the tree graph
// written beside, and bad input refused in one line.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "tests/support/cli_run.h"
#include "tests/support/gltf_check.h"
#include "tests/support/test_data.h"
#include "tests/support/test_paths.h"

using namespace lobe;

namespace {

test::CliRun run(const std::string& args) { return test::run_cli(args); }

using test::lines_of;
std::string read(const std::string& path) { return test::read_file(path); }
void write(const std::string& path, const std::string& text) { test::write_file(path, text); }

/// A small branching tree with widths, tropism (its .v) and leaves, in `dir`/tree.l.
std::string tree_file(const std::string& dir)
{
    write(dir + "/tree.l", "/* a small tree */\n#define R 0.7\nLsystem: 1\nderivation length: 4\n"
                           "Axiom: !(0.2)F(2)A(0.2)\n"
                           "A(w) --> !(w)F(1)[&(35)!(w*R)F(1)A(w*R)~l]/(120)[&(35)!(w*R)F(1)A(w*R)]\n"
                           "endlsystem\n");
    write(dir + "/tree.v", "angle increment: 30\ntropism direction: 0,-1,0\ninitial elasticity: 0.1\n");
    return dir + "/tree.l";
}

} // namespace

TEST(LSystemCli, WritesAGlbTheValidatorAcceptsAndAnObj)
{
    const std::string dir = test::temp_dir("lsystem-cli-out");
    const std::string file = tree_file(dir);
    test::CliRun r = run("lsystem " + file + " --out " + dir + "/tree.glb");
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_NE(r.out.find("wrote " + dir + "/tree.glb"), std::string::npos) << r.out;
    nlohmann::json report;
    ASSERT_TRUE(test::validate_gltf(dir + "/tree.glb", report));
    EXPECT_EQ(report["issues"]["numErrors"], 0) << test::describe_gltf_issues(report);
    EXPECT_EQ(report["issues"]["numWarnings"], 0) << test::describe_gltf_issues(report);
    r = run("lsystem " + file + " --out " + dir + "/tree.obj");
    ASSERT_EQ(r.code, 0) << r.out;
    const std::string obj = read(dir + "/tree.obj");
    EXPECT_NE(obj.find("\nv "), std::string::npos);
    EXPECT_NE(obj.find("\nf "), std::string::npos);
    EXPECT_TRUE(std::filesystem::exists(dir + "/tree.mtl"));
}

TEST(LSystemCli, StringOutWritesTheDerivedWordInOneLine)
{
    const std::string dir = test::temp_dir("lsystem-cli-word");
    write(dir + "/d0l.l", "Lsystem: 1\nderivation length: 5\nAxiom: b\na --> ab\nb --> a\nendlsystem\n");
    test::CliRun r = run("lsystem " + dir + "/d0l.l --out " + dir + "/t.glb --string-out " + dir + "/w.txt");
    // A word with nothing to draw writes the word, then fails: there is no tree to export.
    EXPECT_EQ(r.code, 1) << r.out;
    EXPECT_NE(r.out.find("drew no branch"), std::string::npos) << r.out;
    EXPECT_EQ(read(dir + "/w.txt"), "abaababa\n");
    // --steps overrides the file's derivation length; --seed keys the stochastic choices.
    write(dir + "/s.l", "Lsystem: 1\nderivation length: 6\nAxiom: A\nA --> F[+A]A : 0.5\nA --> F[-A]A : 0.5\n"
                        "endlsystem\n");
    auto word = [&](const std::string& extra) {
        const test::CliRun w = run("lsystem " + dir + "/s.l --out " + dir + "/s.glb --string-out " + dir + "/s.txt " + extra);
        EXPECT_EQ(w.code, 0) << w.out;
        return read(dir + "/s.txt");
    };
    EXPECT_EQ(word("--steps 1"), "F[+A]A\n");
    const std::string seed1 = word("--seed 1"), seed2 = word("--seed 2");
    EXPECT_EQ(lines_of(seed1), 1u);
    EXPECT_EQ(seed1, word("--seed 1"));
    EXPECT_NE(seed1, seed2);
}

TEST(LSystemCli, SkeletonOutWritesTheTreeGraphInMetres)
{
    const std::string dir = test::temp_dir("lsystem-cli-skeleton");
    write(dir + "/gap.l", "Lsystem: 1\nAxiom: !(0.5)F(1)f(1)F(2)\nendlsystem\n");
    write(dir + "/gap.v", "line style: cylinder\n"); // widths in model units
    const test::CliRun r = run("lsystem " + dir + "/gap.l --height 4 --out " + dir + "/t.glb --skeleton-out " + dir + "/t.json");
    ASSERT_EQ(r.code, 0) << r.out;
    const nlohmann::json j = nlohmann::json::parse(read(dir + "/t.json"));
    const auto& nodes = j["nodes"];
    ASSERT_EQ(nodes.size(), 4u);
    EXPECT_EQ(nodes[0]["id"], 0);
    EXPECT_EQ(nodes[0]["parent"], -1);
    EXPECT_EQ(nodes[1]["parent"], 0);
    EXPECT_EQ(nodes[3]["parent"], 2);
    // 4 model units tall scaled to 4 m: one metre per unit; radius half the width.
    EXPECT_NEAR(nodes[3]["position"][1].get<double>(), 4.0, 1e-6);
    EXPECT_NEAR(nodes[1]["radius"].get<double>(), 0.25, 1e-6);
    EXPECT_EQ(nodes[1]["lobe"], 0);
    // The node after the move is not joined to the one before it.
    EXPECT_EQ(nodes[2]["detached"], true);
    EXPECT_FALSE(nodes[1].contains("detached"));
    EXPECT_NEAR(nodes[2]["position"][1].get<double>(), 2.0, 1e-6);
}

TEST(LSystemCli, GrowsInTheLobesOfASessionAndWithGrow)
{
    const std::string recording = test::source_data("recordings/table1-1lobe-5strokes.lrec");
    if (recording.empty()) return;
    const std::string dir = test::temp_dir("lsystem-cli-lobes");
    ASSERT_EQ(run("lobes " + recording + " --out " + dir + "/s").code, 0);
    // A model that asks where it is: branches only where the next internode's end is in a lobe.
    write(dir + "/topiary.l", "#define S 0.03\nLsystem: 1\nderivation length: 40\n"
                              "Axiom: !(0.02)A(0)?H(0,0,0)?P(0,0,0)\n"
                              "A(n) > ?H(u,v,w)?P(x,y,z) : inside(x,y,z) == 0 && n == 0 --> F(S)A(0)\n"
                              "A(n) > ?H(u,v,w)?P(x,y,z) : inside(x,y,z) && n == 0 --> A(1)\n"
                              "A(n) > ?H(u,v,w)?P(x,y,z) : n > 0 && inside(x+S*u,y+S*v,z+S*w) && n < 5 --> "
                              "F(S)[+(40)A(n+1)?H(0,0,0)?P(0,0,0)]/(137.5)A(n+1)\n"
                              "A(n) > ?H(u,v,w)?P(x,y,z) : n >= 5 && inside(x+S*u,y+S*v,z+S*w) --> F(S)/(30)A(n)\n"
                              "A(n) > ?H(u,v,w)?P(x,y,z) : n > 0 && !inside(x+S*u,y+S*v,z+S*w) --> %\n"
                              "endlsystem\n");
    test::CliRun r = run("lsystem " + dir + "/topiary.l --lobes " + dir + "/s/session.json --out " + dir +
                         "/t.glb --skeleton-out " + dir + "/t.json");
    ASSERT_EQ(r.code, 0) << r.out;
    const nlohmann::json j = nlohmann::json::parse(read(dir + "/t.json"));
    // The sketched trunk (lobe 0) and, where it enters the lobe, the model's crown (lobe 1).
    std::size_t trunk = 0, crown = 0;
    for (const auto& n : j["nodes"]) {
        trunk += n["lobe"] == 0;
        crown += n["lobe"] == 1;
    }
    EXPECT_GT(trunk, 10u);
    EXPECT_GT(crown, 20u);
    EXPECT_EQ(trunk + crown, j["nodes"].size());

    // grow: the recording's tree with the L-system file as its grower.
    r = run("grow " + recording + " --grower lsystem --lsystem " + dir + "/topiary.l --out " + dir + "/g.glb");
    ASSERT_EQ(r.code, 0) << r.out;
    nlohmann::json report;
    ASSERT_TRUE(test::validate_gltf(dir + "/g.glb", report));
    EXPECT_EQ(report["issues"]["numErrors"], 0) << test::describe_gltf_issues(report);
    r = run("grow " + recording + " --grower subtrees --lsystem " + dir + "/topiary.l --out " + dir + "/h.glb");
    EXPECT_EQ(r.code, 2) << r.out;
    EXPECT_NE(r.out.find("--lsystem"), std::string::npos) << r.out;
}

TEST(LSystemCli, APresetsNameStandsForItsShippedFile)
{
    const std::string dir = test::temp_dir("lsystem-cli-preset");
    // One file name in two folders: node names come from the file's stem.
    std::filesystem::create_directories(dir + "/named");
    std::filesystem::create_directories(dir + "/file");
    const test::CliRun named = run("lsystem abop-monopodial --out " + dir + "/named/tree.glb");
    ASSERT_EQ(named.code, 0) << named.out;
    const test::CliRun file =
        run("lsystem " + test::source_path("growth/data/lsystems/abop-monopodial.l") + " --out " + dir + "/file/tree.glb");
    ASSERT_EQ(file.code, 0) << file.out;
    EXPECT_EQ(read(dir + "/named/tree.glb"), read(dir + "/file/tree.glb"));
    const test::CliRun neither = run("lsystem no-such-preset --out " + dir + "/x.glb");
    EXPECT_NE(neither.code, 0);
    EXPECT_NE(neither.out.find("no-such-preset"), std::string::npos) << neither.out;
}

TEST(LSystemCli, RenderDrawsAnLSystemFile)
{
    const std::string dir = test::temp_dir("lsystem-cli-render");
    const std::string file = tree_file(dir);
    const test::CliRun r = run("render " + file + " --out " + dir + "/t.png --size 96x64");
    ASSERT_EQ(r.code, 0) << r.out;
    const std::string png = read(dir + "/t.png");
    ASSERT_GT(png.size(), 24u);
    EXPECT_EQ(png.compare(0, 8, "\x89PNG\r\n\x1a\n"), 0);
}

TEST(LSystemCli, BadInputFailsWithOneLine)
{
    const std::string dir = test::temp_dir("lsystem-cli-bad");
    auto expect_one_error_line = [](const test::CliRun& r, int code, const std::string& needle) {
        EXPECT_EQ(r.code, code) << r.out;
        EXPECT_EQ(lines_of(r.out), 1u) << r.out;
        EXPECT_NE(r.out.find(needle), std::string::npos) << r.out;
    };
    expect_one_error_line(run("lsystem " + dir + "/missing.l --out " + dir + "/t.glb"), 1, "missing.l");
    write(dir + "/bad.l", "Lsystem: 1\nAxiom: F[F\nendlsystem\n");
    expect_one_error_line(run("lsystem " + dir + "/bad.l --out " + dir + "/t.glb"), 1, "bad.l:2:");
    write(dir + "/ok.l", "Lsystem: 1\nAxiom: F\nendlsystem\n");
    expect_one_error_line(run("lsystem " + dir + "/ok.l --out " + dir + "/t.stl"), 2, ".glb");
    write(dir + "/badview.l", "Lsystem: 1\nAxiom: F\nendlsystem\n");
    write(dir + "/badview.v", "angle increment: many\n");
    expect_one_error_line(run("lsystem " + dir + "/badview.l --out " + dir + "/t.glb"), 1, "badview.v:1:");
    EXPECT_EQ(run("lsystem " + dir + "/ok.l --out " + dir + "/t.glb --steps -1").code, 2);
    EXPECT_FALSE(std::filesystem::exists(dir + "/t.glb"));
    // A reader's warning is one line on stderr, and the tree is still written.
    write(dir + "/warn.l", "Lsystem: 1\nAxiom: F\nendlsystem\ntrailing words\n");
    const test::CliRun w = run("-q lsystem " + dir + "/warn.l --out " + dir + "/w.glb");
    EXPECT_EQ(w.code, 0) << w.out;
    EXPECT_EQ(lines_of(w.out), 1u) << w.out;
    EXPECT_NE(w.out.find("warning: " + dir + "/warn.l:4:"), std::string::npos) << w.out;
}
