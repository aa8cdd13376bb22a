// The command line's grammar (issue 42): a bad command line exits 2 in one line before any
// work; options that do not apply say so; messages name the real problem.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "tests/support/cli_run.h"
#include "tests/support/test_paths.h"

namespace lobe {
namespace {

namespace fs = std::filesystem;
using test::CliRun;

std::size_t count(const std::string& text, const std::string& needle)
{
    std::size_t n = 0;
    for (std::size_t pos = text.find(needle); pos != std::string::npos; pos = text.find(needle, pos + needle.size())) ++n;
    return n;
}

/// The non-empty lines of `text`.
std::size_t lines_of(const std::string& text)
{
    std::size_t n = 0;
    std::size_t start = 0;
    while (start < text.size()) {
        std::size_t end = text.find('\n', start);
        if (end == std::string::npos) end = text.size();
        if (end > start) ++n;
        start = end + 1;
    }
    return n;
}

/// A small recording and the session `replay` makes of it, in `dir`.
struct Inputs {
    std::string rec, session;
};

Inputs make_inputs(const std::string& dir)
{
    Inputs in;
    in.rec = test::source_path("recordings/table1-1lobe-5strokes.lrec");
    const CliRun r = test::run_cli("-q replay " + in.rec + " --out " + dir + "/r");
    EXPECT_EQ(r.code, 0) << r.out;
    in.session = dir + "/r/session.json";
    return in;
}

void expect_usage_error(const std::string& args, const std::string& expect)
{
    SCOPED_TRACE(args);
    const CliRun r = test::run_cli(args);
    EXPECT_EQ(r.code, 2) << r.out;
    EXPECT_EQ(lines_of(r.out), 1u) << r.out; // one line, and no progress: nothing was replayed or grown
    EXPECT_EQ(r.out.rfind("lobesketch: error: ", 0), 0u) << r.out;
    EXPECT_NE(r.out.find(expect), std::string::npos) << r.out;
}

TEST(CliCommandLine, BadOptionValuesExitTwoInOneLineBeforeAnyWork)
{
    const std::string dir = test::temp_dir("cli-grammar-values");
    const Inputs in = make_inputs(dir);
    const std::string glb = " --out " + dir + "/t.glb";
    const struct {
        std::string args, expect;
    } cases[] = {
        {"grow " + in.rec + glb + " --lod none", "--lod: expected \"all\" or LOD indices"},
        {"grow " + in.rec + glb + " --lod 1,1", "--lod: LOD 1 given twice"},
        {"export " + in.session + glb + " --lod none", "--lod: expected"},
        {"grow " + in.rec + " --out " + dir + "/tree.fbx", "tree.fbx: the tree is written as .glb"},
        {"export " + in.session + " --out " + dir + "/tree.fbx", "tree.fbx: the tree is written as .glb"},
        {"lsystem fern --out " + dir + "/tree.fbx", "tree.fbx: the tree is written as .glb"},
        {"render " + in.rec + " --out " + dir + "/x.jpg", "x.jpg: pictures are written as .png"},
        {"grow " + in.rec + glb + " --species oak", "unknown species 'oak' (known: birch, broadleaf"},
        {"render " + in.rec + " --out " + dir + "/x.png --species oak", "unknown species 'oak'"},
        {"grow " + in.rec + glb + " --height nan", "--height: expected a number from 0 to 1000 (got 'nan')"},
        {"grow " + in.rec + glb + " --height inf", "(got 'inf')"},
        {"grow " + in.rec + glb + " --size nan", "--size: expected a number"},
        {"lsystem fern" + glb + " --height nan", "--height: expected a number"},
        {"grow " + in.rec + glb + " --seed -1", "--seed: a seed is a whole number from 0 to 18446744073709551615"},
        {"grow " + in.rec + glb + " --seed 18446744073709551616", "a seed is a whole number"},
        {"replay " + in.rec + " --out " + dir + "/o --seed -1", "a seed is a whole number"},
        {"lsystem fern" + glb + " --seed -1", "a seed is a whole number"},
        {"sketch " + in.rec + " --session " + dir + "/s.json --seed -1", "a seed is a whole number"},
        {"grow " + in.rec, "--out is required (see 'lobesketch grow --help')"},
        {"grow " + in.rec + glb + " --no-such-option", "--no-such-option"},
    };
    for (const auto& c : cases) expect_usage_error(c.args, c.expect);
    EXPECT_FALSE(fs::exists(dir + "/t.glb"));
    EXPECT_FALSE(fs::exists(dir + "/o"));
    EXPECT_FALSE(fs::exists(dir + "/s.json"));
    // The largest seed is still one.
    EXPECT_EQ(test::run_cli("-q grow " + in.rec + glb + " --seed 18446744073709551615").code, 0);
}

TEST(CliCommandLine, EverySubcommandRefusesABadCommandLineInOneLineAndTakesQuietAfterIt)
{
    for (const char* sub : {"info", "replay", "import-leap", "import-webxr", "synth", "lobes", "grow", "export", "render",
                            "lsystem", "desktop", "vr", "recover", "sketch", "settings"}) {
        // CLI11 names the first thing wrong: the unknown option, or a required --out missing.
        expect_usage_error(std::string(sub) + " x --no-such-option", "(see 'lobesketch " + std::string(sub) + " --help')");
        const CliRun help = test::run_cli(std::string(sub) + " --help -q");
        EXPECT_EQ(help.code, 0) << sub << ": " << help.out;
    }
}

TEST(CliCommandLine, AnUnknownCommandIsNamedWithTheCommandsAndTheNearestOne)
{
    const CliRun r = test::run_cli("grwo recordings/demo.lrec --out t.glb");
    EXPECT_EQ(r.code, 2) << r.out;
    EXPECT_EQ(lines_of(r.out), 1u) << r.out;
    EXPECT_NE(r.out.find("lobesketch: error: unknown command 'grwo' (did you mean 'grow'?)"), std::string::npos) << r.out;
    for (const char* name : {"info", "replay", "grow", "export", "render", "lsystem", "settings"})
        EXPECT_NE(r.out.find(name), std::string::npos) << name << ": " << r.out;
    const CliRun far = test::run_cli("-q frobnicate");
    EXPECT_EQ(far.code, 2) << far.out;
    EXPECT_NE(far.out.find("unknown command 'frobnicate'; the commands are"), std::string::npos) << far.out;
    EXPECT_EQ(far.out.find("did you mean"), std::string::npos) << far.out;
}

TEST(CliCommandLine, QuietWorksBeforeAndAfterTheSubcommand)
{
    const std::string dir = test::temp_dir("cli-grammar-quiet");
    const std::string rec = test::source_path("recordings/table1-1lobe-5strokes.lrec");
    const CliRun loud = test::run_cli("grow " + rec + " --out " + dir + "/a.glb");
    ASSERT_EQ(loud.code, 0) << loud.out;
    EXPECT_NE(loud.out.find("wrote "), std::string::npos) << loud.out;
    for (const std::string& args : {"-q grow " + rec + " --out " + dir + "/b.glb", "grow " + rec + " -q --out " + dir + "/c.glb",
                                    "grow " + rec + " --out " + dir + "/d.glb --quiet"}) {
        const CliRun quiet = test::run_cli(args);
        EXPECT_EQ(quiet.code, 0) << args << "\n" << quiet.out;
        EXPECT_EQ(quiet.out, "") << args;
    }
    EXPECT_TRUE(fs::exists(dir + "/d.glb"));
}

TEST(CliCommandLine, OptionsThatDoNotApplyGetOneWarningLine)
{
    const std::string dir = test::temp_dir("cli-grammar-ignored");
    const Inputs in = make_inputs(dir);
    // --size scales only a mesh input.
    CliRun r = test::run_cli("-q grow " + in.session + " --out " + dir + "/a.glb --size 2");
    EXPECT_EQ(r.code, 0) << r.out;
    EXPECT_EQ(r.out, "lobesketch: warning: --size applies only to a mesh input (.obj/.ply/.off); ignored for " +
                         in.session + "\n");
    r = test::run_cli("-q lobes " + in.rec + " --out " + dir + "/l --size 2");
    EXPECT_EQ(r.code, 0) << r.out;
    EXPECT_EQ(count(r.out, "warning: --size applies only to a mesh input"), 1u) << r.out;
    r = test::run_cli("-q grow " + in.session + " --out " + dir + "/b.glb");
    EXPECT_EQ(r.out, "") << "no warning without --size";
    // A species applied over a settings file says what it replaced and that it wins.
    r = test::run_cli("-q grow " + in.session + " --settings " + in.session + " --species conifer --out " + dir + "/c.glb");
    EXPECT_EQ(r.code, 0) << r.out;
    EXPECT_EQ(lines_of(r.out), 1u) << r.out;
    EXPECT_NE(r.out.find("warning: --species conifer replaces "), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("setting(s) of --settings " + in.session + " (growth.species"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("the species wins"), std::string::npos) << r.out;
    r = test::run_cli("-q grow " + in.session + " --species conifer --out " + dir + "/d.glb");
    EXPECT_EQ(r.out, "") << "no warning without --settings";
}

TEST(CliCommandLine, FramesWithoutAnOrbitGetOneWarningLine)
{
    const std::string dir = test::temp_dir("cli-grammar-frames");
    const Inputs in = make_inputs(dir);
    CliRun r = test::run_cli("-q render " + in.session + " --out " + dir + "/p.png --size 32x32 --frames 4");
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_EQ(r.out, "lobesketch: warning: --frames applies only to --view orbit; one picture is drawn for --view front\n");
    EXPECT_TRUE(fs::exists(dir + "/p.png"));
    EXPECT_FALSE(fs::exists(dir + "/p_000.png"));
    r = test::run_cli("-q render " + in.session + " --out " + dir + "/o.png --size 32x32 --frames 2 --view orbit");
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_EQ(r.out, "");
}

TEST(CliCommandLine, InputsOfTheWrongKindAreNamedForWhatTheyAre)
{
    const std::string dir = test::temp_dir("cli-grammar-kinds");
    const Inputs in = make_inputs(dir);
    fs::copy_file(in.session, dir + "/renamed.autosave");
    fs::copy_file(dir + "/r/tree.glb", dir + "/tree.glb");
    fs::copy_file(dir + "/r/tree.glb", dir + "/tree.lrec");
    std::ofstream(dir + "/leaf.png") << "\x89PNG\r\n\x1a\n";
    std::ofstream(dir + "/notes.txt") << "buy seeds\n";

    // A session is shown as one, whatever its name, and never sent to import-leap.
    for (const std::string& session : {in.session, dir + "/renamed.autosave"}) {
        const CliRun r = test::run_cli("info " + session);
        EXPECT_EQ(r.code, 0) << r.out;
        EXPECT_NE(r.out.find("grower subtrees"), std::string::npos) << r.out;
        EXPECT_EQ(r.out.find("import-leap"), std::string::npos) << r.out;
    }
    // Wrong kinds by their names: a bad command line.
    expect_usage_error("export " + in.rec + " --out " + dir + "/x.glb",
                       "export wants a session document (.json), and a recording is not one; grow takes recordings");
    expect_usage_error("grow " + dir + "/tree.glb --out " + dir + "/x.glb",
                       "tree.glb: a glTF file (an exported tree) is not an input grow takes (a recording, a session "
                       "document (.json) or a mesh (.obj/.ply/.off))");
    expect_usage_error("grow " + dir + "/leaf.png --out " + dir + "/x.glb", "leaf.png: a picture is not an input grow takes");
    expect_usage_error("lobes " + dir + "/leaf.png --out " + dir + "/l", "a picture is not an input lobes takes");
    expect_usage_error("render " + dir + "/leaf.png --out " + dir + "/x.png", "a picture is not an input render takes");
    ASSERT_EQ(test::run_cli("-q export " + in.session + " --out " + dir + "/exported.obj").code, 0);
    expect_usage_error("render " + dir + "/exported.obj --out " + dir + "/x.png",
                       "exported.obj: a tree exported by lobesketch (a mesh input is the lobe a tree grows in) is not "
                       "an input render takes");
    expect_usage_error("grow " + dir + "/exported.obj --out " + dir + "/x.glb", "is not an input grow takes");
    expect_usage_error("replay " + in.session + " --out " + dir + "/o",
                       "a Lobesketch session document is not an input replay takes");
    // Wrong kinds by their content: the work fails in one line naming what the file is.
    CliRun r = test::run_cli("-q grow " + dir + "/tree.lrec --out " + dir + "/x.glb");
    EXPECT_EQ(r.code, 1) << r.out;
    EXPECT_EQ(r.out, "lobesketch: error: " + dir + "/tree.lrec: a glTF binary (an exported tree), not a recording\n");
    r = test::run_cli("-q replay " + dir + "/renamed.autosave --out " + dir + "/o");
    EXPECT_EQ(r.code, 1) << r.out;
    EXPECT_NE(r.out.find("renamed.autosave: a Lobesketch session document, not a recording"), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("import-leap"), std::string::npos) << r.out;
    // An LOD the settings do not make, said before anything is grown (no "grew" line).
    // (LOD n of a tree of n LODs is its billboard.)
    r = test::run_cli("export " + in.session + " --out " + dir + "/x.glb --set branches.lod_count=2 --lod 3");
    EXPECT_EQ(r.code, 1) << r.out;
    EXPECT_EQ(r.out, "lobesketch: error: --lod: LOD 3 does not exist (the tree has LOD0 to LOD1; "
                     "settings.branches.lod_count, and the billboard LOD2)\n");
    r = test::run_cli("export " + in.session + " --out " + dir + "/x.glb --set branches.lod_count=2 --lod 2 --billboard 0");
    EXPECT_EQ(r.code, 1) << r.out;
    EXPECT_EQ(r.out, "lobesketch: error: --lod: LOD 2 does not exist (the tree has LOD0 to LOD1; "
                     "settings.branches.lod_count)\n");
    // A session with nothing to grow: growing it first would warn and say so instead.
    std::ofstream(dir + "/empty.json") << R"({"format": "lobesketch-session", "version": 1})";
    for (const char* command : {"grow", "export"}) {
        r = test::run_cli(std::string(command) + " " + dir + "/empty.json --out " + dir + "/x.glb --lod 4");
        EXPECT_EQ(r.code, 1) << r.out;
        EXPECT_EQ(r.out, "lobesketch: error: --lod: LOD 4 does not exist (the tree has LOD0 to LOD2; "
                         "settings.branches.lod_count, and the billboard LOD3)\n");
    }
    // A folder that does not exist, said before anything is grown.
    r = test::run_cli("grow " + in.rec + " --out " + dir + "/missing/dir/x.glb");
    EXPECT_EQ(r.code, 1) << r.out;
    EXPECT_EQ(r.out, "lobesketch: error: " + dir + "/missing/dir/x.glb: the folder '" + dir + "/missing/dir' does not exist\n");
    r = test::run_cli("export " + in.session + " --out " + dir + "/x.glb --report " + dir + "/missing/r.json");
    EXPECT_EQ(r.code, 1) << r.out;
    EXPECT_NE(r.out.find("the folder '" + dir + "/missing' does not exist"), std::string::npos) << r.out;
    // Not a scenario: one line, no JSON library text.
    r = test::run_cli("synth " + dir + "/notes.txt -o " + dir + "/s.lrec");
    EXPECT_EQ(r.code, 1) << r.out;
    EXPECT_EQ(r.out, "lobesketch: error: " + dir +
                         "/notes.txt: not a scenario: not valid JSON (line 1, column 1); a scenario is a JSON document "
                         "(docs/scenario-format.md)\n");
    EXPECT_FALSE(fs::exists(dir + "/x.glb"));
    EXPECT_FALSE(fs::exists(dir + "/o"));
    EXPECT_FALSE(fs::exists(dir + "/l"));
}

TEST(CliCommandLine, ARenderOfAGlbWithoutTheAskedLodNamesTheLodsItHas)
{
    const std::string dir = test::temp_dir("cli-grammar-lod");
    const std::string rec = test::source_path("recordings/table1-1lobe-5strokes.lrec");
    ASSERT_EQ(test::run_cli("-q grow " + rec + " --out " + dir + "/t.glb --lod 2").code, 0);
    const CliRun r = test::run_cli("-q render " + dir + "/t.glb --out " + dir + "/t.png --size 32x32");
    EXPECT_EQ(r.code, 1) << r.out;
    EXPECT_EQ(r.out, "lobesketch: error: " + dir + "/t.glb: has no LOD0 (it has LOD2; pick one with --lod)\n");
    EXPECT_FALSE(fs::exists(dir + "/t.png"));
}

TEST(CliCommandLine, AFolderUsedBeforeKeepsNoLobeMeshOfTheEarlierRun)
{
    const std::string dir = test::temp_dir("cli-grammar-stale");
    const std::string three = test::source_path("recordings/table1-3lobes-16strokes.lrec");
    const std::string one = test::source_path("recordings/table1-1lobe-5strokes.lrec");
    ASSERT_EQ(test::run_cli("-q replay " + three + " --out " + dir + "/r").code, 0);
    ASSERT_TRUE(fs::exists(dir + "/r/lobes/lobe_3.ply"));
    std::ofstream(dir + "/r/lobes/notes.txt") << "mine\n";
    CliRun r = test::run_cli("-q replay " + one + " --out " + dir + "/r");
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_NE(r.out.find("warning: " + one + ": removed 2 lobe mesh(es) of an earlier run from " + dir + "/r/lobes"),
              std::string::npos)
        << r.out;
    std::size_t plys = 0;
    for (const auto& e : fs::directory_iterator(dir + "/r/lobes")) plys += e.path().extension() == ".ply" ? 1 : 0;
    EXPECT_EQ(plys, 1u);
    EXPECT_TRUE(fs::exists(dir + "/r/lobes/notes.txt")); // only lobe meshes are removed
    // lobes into the same folder: the same.
    ASSERT_EQ(test::run_cli("-q lobes " + three + " --out " + dir + "/l").code, 0);
    r = test::run_cli("-q lobes " + one + " --out " + dir + "/l");
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_FALSE(fs::exists(dir + "/l/lobes/lobe_3.ply"));
    EXPECT_EQ(count(r.out, "removed 2 lobe mesh(es) of an earlier run"), 1u) << r.out;
}

TEST(CliCommandLine, TheSameOptionNamesWorkInEveryCommand)
{
    const std::string dir = test::temp_dir("cli-grammar-names");
    const std::string rec = test::source_path("recordings/table1-1lobe-5strokes.lrec");
    // sketch writes its session with --out too (--session stays).
    CliRun r = test::run_cli("-q sketch " + rec + " --out " + dir + "/s.json");
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_TRUE(fs::exists(dir + "/s.json"));
    // grow and lobes take render's --mesh-size beside --size.
    ASSERT_EQ(test::run_cli("-q lobes " + rec + " --out " + dir + "/l").code, 0);
    const std::string mesh = dir + "/l/lobes/lobe_1.ply";
    // (One file name in three folders: the node names come from it.)
    for (const char* sub : {"/a", "/b", "/c"}) fs::create_directories(dir + sub);
    ASSERT_EQ(test::run_cli("-q grow " + mesh + " --out " + dir + "/a/t.glb --size 0.5").code, 0);
    ASSERT_EQ(test::run_cli("-q grow " + mesh + " --out " + dir + "/b/t.glb --mesh-size 0.5").code, 0);
    ASSERT_EQ(test::run_cli("-q grow " + mesh + " --out " + dir + "/c/t.glb").code, 0);
    auto bytes = [](const std::string& path) {
        std::ifstream in(path, std::ios::binary);
        return std::string(std::istreambuf_iterator<char>(in), {});
    };
    EXPECT_EQ(bytes(dir + "/a/t.glb"), bytes(dir + "/b/t.glb"));
    EXPECT_NE(bytes(dir + "/a/t.glb"), bytes(dir + "/c/t.glb"));
    ASSERT_EQ(test::run_cli("-q lobes " + mesh + " --out " + dir + "/m --mesh-size 0.5").code, 0);
}

TEST(CliCommandLine, ReplayTakesSpeciesAndHeightAsGrowDoes)
{
    const std::string dir = test::temp_dir("cli-grammar-replay-species");
    const std::string rec = test::source_path("recordings/table1-1lobe-5strokes.lrec");
    ASSERT_EQ(test::run_cli("-q replay " + rec + " --out " + dir + "/plain").code, 0);
    CliRun r = test::run_cli("-q replay " + rec + " --out " + dir + "/conifer --species conifer --height 8");
    ASSERT_EQ(r.code, 0) << r.out;
    fs::create_directories(dir + "/grown");
    ASSERT_EQ(test::run_cli("-q grow " + rec + " --out " + dir + "/grown/tree.glb --species conifer --height 8").code, 0);
    auto bytes = [](const std::string& path) {
        std::ifstream in(path, std::ios::binary);
        return std::string(std::istreambuf_iterator<char>(in), {});
    };
    EXPECT_EQ(bytes(dir + "/conifer/tree.glb"), bytes(dir + "/grown/tree.glb"));
    EXPECT_NE(bytes(dir + "/conifer/tree.glb"), bytes(dir + "/plain/tree.glb"));
    EXPECT_NE(bytes(dir + "/conifer/session.json").find("\"species\": \"conifer\""), std::string::npos);
    expect_usage_error("replay " + rec + " --out " + dir + "/x --species oak", "unknown species 'oak'");
    expect_usage_error("replay " + rec + " --out " + dir + "/x --height nan", "--height: expected a number");
}

} // namespace
} // namespace lobe
