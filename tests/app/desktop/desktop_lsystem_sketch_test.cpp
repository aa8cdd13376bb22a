// The L-system sketch mode in the real desktop window (`lobesketch desktop --script` under
// Xvfb, tests/data/desktop_lsystem_sketch.script): clicks sketch a trunk and a branch on the
// platform, a node is dragged and one erased, the growth and divergence keys act, the lobe
// tools draw nothing meanwhile, Save writes the sketch beside the session, and the recording
// replays (`lobesketch lsystem --sketch REC.lrec`) to the same sketch, byte for byte.
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <sys/wait.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/document.h"
#include "growth/lsystem/sketch.h"
#include "tests/support/cli_run.h"
#include "tests/support/test_data.h"
#include "tests/support/test_paths.h"

using namespace lobe;

namespace {

bool have_xvfb() { return std::system("command -v xvfb-run >/dev/null 2>&1") == 0; }

test::CliRun run_shell(const std::string& cmd)
{
    test::CliRun r;
    FILE* p = ::popen((cmd + " 2>&1").c_str(), "r");
    if (!p) return r;
    char buf[4096];
    while (std::size_t n = std::fread(buf, 1, sizeof buf, p)) r.out.append(buf, n);
    const int status = ::pclose(p);
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    return r;
}

std::string read_all(const std::string& path)
{
    std::ifstream in(path, std::ios::binary);
    std::ostringstream os;
    os << in.rdbuf();
    return os.str();
}

/// The marks of a script log by name.
std::map<std::string, nlohmann::json> read_marks(const std::string& path)
{
    std::map<std::string, nlohmann::json> m;
    std::ifstream in(path);
    for (std::string line; std::getline(in, line);)
        if (!line.empty()) {
            const nlohmann::json j = nlohmann::json::parse(line);
            m[j["mark"].get<std::string>()] = j;
        }
    return m;
}

/// `lobesketch desktop DIR/tree.json --script SCRIPT`, DIR/tree.json an empty session and
/// `sketch` beside it as tree.lsystem-sketch.json.
test::CliRun open_session_with_sketch(const std::string& dir, const std::string& sketch, const std::string& script)
{
    save_document(dir + "/tree.json", Document{});
    std::ofstream(dir + "/tree.lsystem-sketch.json", std::ios::binary) << sketch;
    return run_shell("xvfb-run -a -s '-screen 0 800x600x24' " + test::cli_path() + " desktop " + dir +
                     "/tree.json --size 720x360 --software --samples 1 --script " + script + " --script-log " + dir +
                     "/marks.jsonl --record " + dir + "/tree.lrec");
}

} // namespace

TEST(DesktopLSystemSketch, ScriptedClicksSketchATreeThatTheRecordingReplaysAlike)
{
    if (!have_xvfb()) GTEST_SKIP() << "xvfb-run is missing (scripts/setup.sh installs package xvfb)";
    const std::string script = test::source_data("tests/data/desktop_lsystem_sketch.script");
    if (script.empty()) return;
    const std::string dir = test::temp_dir("desktop_lsystem_sketch");
    const test::CliRun r = run_shell("xvfb-run -a -s '-screen 0 800x600x24' " + test::cli_path() + " desktop " + dir +
                                     "/tree.json --size 720x360 --software --samples 1 --script " + script +
                                     " --script-log " + dir + "/marks.jsonl --record " + dir + "/tree.lrec");
    ASSERT_EQ(r.code, 0) << r.out;
    std::map<std::string, nlohmann::json> m;
    std::ifstream in(dir + "/marks.jsonl");
    for (std::string line; std::getline(in, line);)
        if (!line.empty()) {
            const nlohmann::json j = nlohmann::json::parse(line);
            m[j["mark"].get<std::string>()] = j;
        }
    ASSERT_EQ(m.size(), 5u) << r.out;
    auto ls = [&](const char* mark) { return m.at(mark).at("lsystem_sketch"); };
    EXPECT_TRUE(ls("on")["active"].get<bool>());
    EXPECT_EQ(ls("on")["trunk_sections"], 0);
    EXPECT_EQ(ls("trunk")["trunk_sections"], 4);
    EXPECT_GT(ls("trunk")["tree_nodes"].get<int>(), 4);
    EXPECT_EQ(ls("branch")["trunk_sections"], 5);
    ASSERT_EQ(ls("branch")["branches"].size(), 1u);
    EXPECT_EQ(ls("branch")["branches"][0]["attach"], 2);
    EXPECT_EQ(ls("branch")["branches"][0]["points"], 2);
    EXPECT_EQ(ls("end")["trunk_sections"], 4); // the top node erased
    EXPECT_EQ(ls("end")["growth"], 5.0);       // one on from the trunk's four
    EXPECT_EQ(ls("end")["divergence_deg"], 142.5);
    for (const auto& [name, mark] : m) EXPECT_TRUE(mark["strokes"].empty()) << name; // no lobe strokes drawn

    // Saved beside the session; the recording replays to the same sketch.
    const std::string saved = dir + "/tree.lsystem-sketch.json";
    ASSERT_TRUE(std::filesystem::exists(saved)) << r.out;
    const test::CliRun rp = test::run_cli("-q lsystem --sketch " + dir + "/tree.lrec --sketch-out " + dir + "/replayed.json --out " +
                                          dir + "/replayed.glb");
    ASSERT_EQ(rp.code, 0) << rp.out;
    EXPECT_EQ(read_all(dir + "/replayed.json"), read_all(saved));
    // The dragged node: trunk node 4 (clicked at x = 360) moved 10 pixels (about 5 cm on the
    // 1:5 platform, 25 cm full size) along +X.
    const nlohmann::json sketch = nlohmann::json::parse(read_all(saved));
    EXPECT_GT(sketch["trunk"][4][0].get<double>(), 0.15);
}

TEST(DesktopLSystemSketch, OpeningASessionLoadsTheSketchSavedBesideIt)
{
    if (!have_xvfb()) GTEST_SKIP() << "xvfb-run is missing (scripts/setup.sh installs package xvfb)";
    const std::string maple_path = test::source_data("tests/data/sketches/maple.json");
    if (maple_path.empty()) return;
    const std::string maple = read_all(maple_path);
    const std::string script = test::source_data("tests/data/desktop_lsystem_sketch_open.script");
    if (script.empty()) return;
    const std::string dir = test::temp_dir("desktop_lsystem_sketch_open");
    const test::CliRun r = open_session_with_sketch(dir, maple, script);
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_EQ(r.out.find("warning"), std::string::npos) << r.out;
    std::map<std::string, nlohmann::json> m = read_marks(dir + "/marks.jsonl");
    ASSERT_EQ(m.size(), 3u) << r.out;
    auto ls = [&](const char* mark) { return m.at(mark).at("lsystem_sketch"); };
    // Loaded, the mode off until it is turned on; its growth is the file's iterations.
    EXPECT_FALSE(ls("opened")["active"].get<bool>());
    EXPECT_EQ(ls("opened")["trunk_sections"], 5);
    ASSERT_EQ(ls("opened")["branches"].size(), 2u);
    EXPECT_EQ(ls("opened")["branches"][1]["attach"], 3);
    EXPECT_EQ(ls("opened")["growth"], 8.0);
    EXPECT_GT(ls("opened")["tree_nodes"].get<int>(), 20);
    EXPECT_TRUE(ls("on")["active"].get<bool>());
    EXPECT_EQ(ls("on")["trunk_sections"], 5);
    EXPECT_EQ(ls("drawn")["trunk_sections"], 6); // drawn on from the loaded trunk

    // Save writes the sketch as it is now: the loaded one and the new section.
    const lsystem::Sketch loaded = lsystem::parse_sketch(maple, "maple.json");
    const lsystem::Sketch saved = lsystem::parse_sketch(read_all(dir + "/tree.lsystem-sketch.json"), "saved");
    ASSERT_EQ(saved.trunk.size(), 7u);
    EXPECT_EQ(std::vector<glm::dvec3>(saved.trunk.begin(), saved.trunk.begin() + 6), loaded.trunk);
    EXPECT_EQ(saved.branches.size(), 2u);
    EXPECT_EQ(saved.iterations, 8);
    // The recording holds only what was done in this run: replayed alone, its sketch starts
    // empty (docs/lsystem-sketch.md), here the one section drawn.
    const test::CliRun rp = test::run_cli("-q lsystem --sketch " + dir + "/tree.lrec --sketch-out " + dir +
                                          "/replayed.json --out " + dir + "/replayed.glb");
    ASSERT_EQ(rp.code, 0) << rp.out;
    EXPECT_EQ(lsystem::parse_sketch(read_all(dir + "/replayed.json"), "replayed").trunk.size(), 2u);
}

TEST(DesktopLSystemSketch, ADamagedSketchBesideTheSessionIsOneLineAndLeftAsItIs)
{
    if (!have_xvfb()) GTEST_SKIP() << "xvfb-run is missing (scripts/setup.sh installs package xvfb)";
    const std::string dir = test::temp_dir("desktop_lsystem_sketch_damaged");
    const std::string damaged = R"({"trunk": [[0, 0, 0], [0, 0, 0]], "iterations": 3})"; // a zero-length section
    // Opened, the mode turned on, saved: nothing was drawn.
    std::ofstream(dir + "/open.script") << "0 mark opened\n2 ui lsystem\n4 mark on\n6 ui save\n8 mark saved\n10 quit\n";
    const test::CliRun r = open_session_with_sketch(dir, damaged, dir + "/open.script");
    ASSERT_EQ(r.code, 0) << r.out;
    int warnings = 0;
    std::istringstream in(r.out);
    for (std::string line; std::getline(in, line);)
        if (line.rfind("lobesketch: warning: ", 0) == 0) {
            ++warnings;
            EXPECT_NE(line.find("L-system sketch not loaded: "), std::string::npos) << line;
            EXPECT_NE(line.find("tree.lsystem-sketch.json"), std::string::npos) << line;
        }
    EXPECT_EQ(warnings, 1) << r.out;
    std::map<std::string, nlohmann::json> m = read_marks(dir + "/marks.jsonl");
    ASSERT_EQ(m.size(), 3u) << r.out;
    EXPECT_EQ(m.at("opened").at("lsystem_sketch")["trunk_sections"], 0); // the session opened without it
    EXPECT_TRUE(m.at("on").at("lsystem_sketch")["active"].get<bool>());
    EXPECT_EQ(m.at("on").at("lsystem_sketch")["trunk_sections"], 0);
    EXPECT_EQ(m.at("saved")["last_message"], "saved " + dir + "/tree.json");
    // No sketch was drawn: Save leaves the damaged file as it is.
    EXPECT_EQ(read_all(dir + "/tree.lsystem-sketch.json"), damaged);
}
