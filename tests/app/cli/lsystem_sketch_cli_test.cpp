// `lobesketch lsystem --sketch SKETCH.json` as a user runs it: the derived rules written with
// --rules-out grow the same tree bytes through `lobesketch lsystem rules.l`, --growth draws a
// tree between iterations, and bad sketches and bad command lines are refused in one line.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "tests/support/cli_run.h"
#include "tests/support/gltf_check.h"
#include "tests/support/test_paths.h"

using namespace lobe;

namespace {

test::CliRun run(const std::string& args) { return test::run_cli(args); }

using test::lines_of;
std::string read(const std::string& path) { return test::read_file(path); }
void write(const std::string& path, const std::string& text) { test::write_file(path, text); }

std::string maple() { return test::source_path("tests/data/sketches/maple.json"); }

} // namespace

TEST(LSystemSketchCli, TheWrittenRulesGrowTheSameTreeBytes)
{
    const std::string dir = test::temp_dir("lsystem-sketch-cli-same");
    // Same output file names, so the same node names (they follow the stem).
    std::filesystem::create_directories(dir + "/a");
    std::filesystem::create_directories(dir + "/b");
    const test::CliRun a = run("-q lsystem --sketch " + maple() + " --rules-out " + dir + "/rules.l --out " + dir +
                               "/a/tree.glb --skeleton-out " + dir + "/a.json");
    ASSERT_EQ(a.code, 0) << a.out;
    ASSERT_TRUE(std::filesystem::exists(dir + "/rules.l"));
    ASSERT_TRUE(std::filesystem::exists(dir + "/rules.v"));
    EXPECT_NE(read(dir + "/rules.l").find("A(x,t) < B(b,s)"), std::string::npos);
    const test::CliRun b = run("-q lsystem " + dir + "/rules.l --out " + dir + "/b/tree.glb --skeleton-out " + dir + "/b.json");
    ASSERT_EQ(b.code, 0) << b.out;
    // (Compared as booleans: a failure would print megabytes of binary.)
    EXPECT_TRUE(read(dir + "/a/tree.glb") == read(dir + "/b/tree.glb"));
    EXPECT_EQ(read(dir + "/a.json"), read(dir + "/b.json"));
    nlohmann::json report;
    ASSERT_TRUE(test::validate_gltf(dir + "/a/tree.glb", report));
    EXPECT_EQ(report["issues"]["numErrors"], 0) << test::describe_gltf_issues(report);
    // In metres as sketched, and past the sketch's 2.3 m by iteration 8 (its sections repeat).
    const nlohmann::json sk = nlohmann::json::parse(read(dir + "/a.json"));
    double top = 0;
    for (const auto& n : sk["nodes"]) top = std::max(top, n["position"][1].get<double>());
    EXPECT_GT(top, 2.5);
    EXPECT_LT(top, 4.5);
}

TEST(LSystemSketchCli, GrowthDrawsATreeBetweenIterations)
{
    const std::string dir = test::temp_dir("lsystem-sketch-cli-growth");
    auto nodes = [&](const std::string& growth) {
        const test::CliRun r = run("-q lsystem --sketch " + maple() + " --growth " + growth + " --out " + dir + "/t.glb --skeleton-out " +
                                   dir + "/t.json");
        EXPECT_EQ(r.code, 0) << r.out;
        return nlohmann::json::parse(read(dir + "/t.json"))["nodes"].size();
    };
    const std::size_t n3 = nodes("3"), n34 = nodes("3.4"), n4 = nodes("4");
    EXPECT_EQ(n34, n4); // the sections of iteration 4, grown to 0.4 of their length
    EXPECT_LT(n3, n34);
}

TEST(LSystemSketchCli, ARecordingOfTheSketchModeGrowsAsItsReplayedSketch)
{
    // The maple recording (recordings/lsystem-sketch/): `replay` writes its sketch, and
    // `lsystem --sketch REC.lrec` grows the same bytes as that sketch file at the growth the
    // recording left (7).
    const std::string dir = test::temp_dir("lsystem-sketch-cli-rec");
    // Same output file names, so the same node names (they follow the stem).
    std::filesystem::create_directories(dir + "/a");
    std::filesystem::create_directories(dir + "/b");
    const std::string rec = test::source_path("recordings/lsystem-sketch/maple.lrec");
    const test::CliRun rp = run("-q replay " + rec + " --out " + dir + "/replayed");
    ASSERT_EQ(rp.code, 0) << rp.out;
    ASSERT_TRUE(std::filesystem::exists(dir + "/replayed/lsystem-sketch.json"));
    const test::CliRun a = run("-q lsystem --sketch " + rec + " --sketch-out " + dir + "/s.json --out " + dir + "/a/tree.glb");
    ASSERT_EQ(a.code, 0) << a.out;
    EXPECT_EQ(read(dir + "/s.json"), read(dir + "/replayed/lsystem-sketch.json"));
    const test::CliRun b = run("-q lsystem --sketch " + dir + "/s.json --growth 7 --out " + dir + "/b/tree.glb");
    ASSERT_EQ(b.code, 0) << b.out;
    EXPECT_TRUE(read(dir + "/a/tree.glb") == read(dir + "/b/tree.glb"));
    // A recording without the mode is no sketch.
    const test::CliRun c = run("lsystem --sketch " + test::source_path("recordings/pinch-edit.lrec") + " --out " + dir + "/c.glb");
    EXPECT_EQ(c.code, 1) << c.out;
    EXPECT_NE(c.out.find("sketches no L-system trunk"), std::string::npos) << c.out;
}

TEST(LSystemSketchCli, BadSketchesAndCommandLinesAreRefusedInOneLine)
{
    const std::string dir = test::temp_dir("lsystem-sketch-cli-bad");
    auto expect_one_error_line = [](const test::CliRun& r, int code, const std::string& needle) {
        EXPECT_EQ(r.code, code) << r.out;
        EXPECT_EQ(lines_of(r.out), 1u) << r.out;
        EXPECT_NE(r.out.find(needle), std::string::npos) << r.out;
    };
    write(dir + "/one.json", R"({"trunk": [[0,0,0]]})");
    expect_one_error_line(run("lsystem --sketch " + dir + "/one.json --out " + dir + "/t.glb"), 1, "at least two");
    write(dir + "/attach.json", R"({"trunk": [[0,0,0],[0,1,0],[0,2,0]], "branches": [{"attach": 7, "points": [[1,1,0]]}]})");
    expect_one_error_line(run("lsystem --sketch " + dir + "/attach.json --out " + dir + "/t.glb"), 1, "does not exist");
    write(dir + "/zero.json", R"({"trunk": [[0,0,0],[0,1,0],[0,1,0]]})");
    expect_one_error_line(run("lsystem --sketch " + dir + "/zero.json --out " + dir + "/t.glb"), 1, "zero-length");
    write(dir + "/nan.json", R"({"trunk": [[0,0,0],[0,NaN,0]]})");
    expect_one_error_line(run("lsystem --sketch " + dir + "/nan.json --out " + dir + "/t.glb"), 1, "nan.json");
    expect_one_error_line(run("lsystem --sketch " + dir + "/missing.json --out " + dir + "/t.glb"), 1, "missing.json");
    EXPECT_FALSE(std::filesystem::exists(dir + "/t.glb"));
    // Bad command lines: exit 2 before any work.
    expect_one_error_line(run("lsystem --out " + dir + "/t.glb"), 2, "error:");
    expect_one_error_line(run("lsystem tree.l --sketch " + maple() + " --out " + dir + "/t.glb"), 2, "error:");
    expect_one_error_line(run("lsystem --sketch " + maple() + " --steps 3 --out " + dir + "/t.glb"), 2, "error:");
    expect_one_error_line(run("lsystem --sketch " + maple() + " --growth 0 --out " + dir + "/t.glb"), 2, "error:");
    expect_one_error_line(run("lsystem --sketch " + maple() + " --growth nan --out " + dir + "/t.glb"), 2, "error:");
    expect_one_error_line(run("lsystem --sketch " + maple() + " --rules-out " + dir + "/r.txt --out " + dir + "/t.glb"), 2,
                          "error:");
    expect_one_error_line(run("lsystem " + maple() + " --growth 2 --out " + dir + "/t.glb"), 2, "error:");
    EXPECT_FALSE(std::filesystem::exists(dir + "/t.glb"));
}
