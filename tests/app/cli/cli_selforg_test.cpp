// `lobesketch grow --grower self-organizing` and its options (app/cli/cli_common.h).
#include <fstream>
#include <iterator>

#include <gtest/gtest.h>

#include "tests/support/cli_run.h"
#include "tests/support/test_paths.h"

namespace lobe {
namespace {

std::string bytes(const std::string& path)
{
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

TEST(SelfOrganizingCli, GrowsWithEveryOptionAndTheSameSeedWritesTheSameBytes)
{
    const std::string out = test::temp_dir("selforg-cli");
    const std::string rec = test::source_path("recordings/table1-1lobe-5strokes.lrec");
    const std::string opts = " --grower self-organizing --environment shadow --bud-fate priority --iterations 12 "
                             "--species conifer --seed 4 --out ";
    const test::CliRun a = test::run_cli("grow " + rec + opts + out + "/a.glb");
    ASSERT_EQ(a.code, 0) << a.out;
    const test::CliRun b = test::run_cli("grow " + rec + opts + out + "/b.glb");
    ASSERT_EQ(b.code, 0) << b.out;
    EXPECT_EQ(bytes(out + "/a.glb"), bytes(out + "/b.glb"));
    const test::CliRun markers = test::run_cli("grow " + rec + " --grower self-organizing --out " + out + "/c.glb");
    ASSERT_EQ(markers.code, 0) << markers.out;
    EXPECT_NE(bytes(out + "/a.glb"), bytes(out + "/c.glb"));
}

TEST(SelfOrganizingCli, ItsOptionsWithAnotherGrowerOrBadValuesAreRefusedInOneLine)
{
    const std::string out = test::temp_dir("selforg-cli-bad");
    const std::string rec = test::source_path("recordings/table1-1lobe-5strokes.lrec");
    for (const char* opt : {"--environment shadow", "--bud-fate priority", "--iterations 5"}) {
        const test::CliRun r = test::run_cli("grow " + rec + " " + opt + " --out " + out + "/a.glb");
        EXPECT_EQ(r.code, 1) << r.out;
        const std::string flag = std::string(opt).substr(0, std::string(opt).find(' '));
        EXPECT_NE(r.out.find(flag + " is only valid with --grower self-organizing"), std::string::npos) << r.out;
    }
    for (const char* opt : {"--environment sun", "--bud-fate random", "--iterations 0", "--iterations 501"}) {
        const test::CliRun r = test::run_cli("grow " + rec + " --grower self-organizing " + opt + " --out " + out + "/a.glb");
        EXPECT_EQ(r.code, 2) << opt << ": " << r.out;
    }
}

} // namespace
} // namespace lobe
