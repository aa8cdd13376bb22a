// The settings on the command line: `--set KEY=VALUE` on the tree commands, the order the
// tree options apply in, and `lobesketch settings`.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "app/cli/cli_common.h"
#include "core/errors.h"
#include "core/settings_json.h"
#include "core/settings_table.h"
#include "growth/species.h"
#include "tests/support/cli_run.h"
#include "tests/support/test_paths.h"

using namespace lobe;

namespace {

const std::string kRecording = "recordings/table1-1lobe-5strokes.lrec";

test::CliRun grow(const std::string& name, const std::string& options)
{
    return test::run_cli("-q grow " + test::source_path(kRecording) + " --out " + test::temp_dir(name) + "/tree.glb " +
                         options);
}

} // namespace

TEST(CliSettings, SetChangesTheSettingTheTreeIsBuiltWith)
{
    // Three LODs by default (and the billboard LOD3); branches.lod_count=1 leaves only LOD0
    // and the billboard LOD1, so LOD 2 cannot be written.
    const test::CliRun plain = grow("cli-set-plain", "--lod 2");
    EXPECT_EQ(plain.code, 0) << plain.out;
    const test::CliRun one = grow("cli-set-one-lod", "--set branches.lod_count=1 --lod 2");
    EXPECT_EQ(one.code, 1) << one.out;
    EXPECT_NE(one.out.find("the tree has LOD0 to LOD0; settings.branches.lod_count, and the billboard LOD1"), std::string::npos)
        << one.out;
    // Repeated, with a value holding commas.
    const test::CliRun two = grow("cli-set-two", "--set branches.lod_count=1 --set leaves.color=0.2,0.4,0.1 --lod 0");
    EXPECT_EQ(two.code, 0) << two.out;
}

TEST(CliSettings, BadSetIsABadCommandLineNamingTheSetting)
{
    const test::CliRun range = grow("cli-set-range", "--set growth.split_angle_deg=200");
    EXPECT_EQ(range.code, 2);
    EXPECT_NE(range.out.find("--set: settings.growth.split_angle_deg must be in [5, 180]"), std::string::npos) << range.out;
    const test::CliRun unknown = grow("cli-set-unknown", "--set growth.split_angle=25");
    EXPECT_EQ(unknown.code, 2);
    EXPECT_NE(unknown.out.find("unknown setting 'growth.split_angle'"), std::string::npos) << unknown.out;
    const test::CliRun form = grow("cli-set-form", "--set leaves.per_node=many");
    EXPECT_EQ(form.code, 2);
    EXPECT_NE(form.out.find("settings.leaves.per_node: expected an integer, not 'many'"), std::string::npos) << form.out;
    // The single options take their range from the table too.
    const test::CliRun split = grow("cli-split-range", "--split-angle 2");
    EXPECT_EQ(split.code, 2);
    EXPECT_NE(split.out.find("--split-angle: settings.growth.split_angle_deg must be in [5, 180]"), std::string::npos)
        << split.out;
    // Values that are fine alone but contradict the others fail the work, naming the setting.
    const test::CliRun contradict = grow("cli-set-contradict", "--set input.pinch_release_m=0.005");
    EXPECT_EQ(contradict.code, 1);
    EXPECT_NE(contradict.out.find("settings.input.pinch_release_m must be in (pinch_start_m, 0.2)"), std::string::npos)
        << contradict.out;
}

TEST(CliSettings, OptionsApplyAsSpeciesThenEachSetThenTheSingleOptions)
{
    cli::TreeInputOptions o;
    o.species = "conifer";
    o.set = {"growth.beta=0.1", "leaves.per_node=7", "leaves.per_node=8", "growth.split_angle_deg=50"};
    Settings s;
    cli::apply_tree_input_options(s, o);
    Settings conifer;
    apply_species(conifer, load_species("conifer"));
    EXPECT_EQ(s.growth.species, "conifer");
    EXPECT_EQ(s.leaves.shape, conifer.leaves.shape); // the preset's, where --set says nothing
    EXPECT_EQ(s.growth.beta, 0.1);                   // --set over the preset
    EXPECT_EQ(s.leaves.per_node, 8);                 // the last --set of a key
    EXPECT_EQ(s.growth.split_angle_deg, 50.0);
    o.split_angle = 40.0; // --split-angle over --set
    o.spacing = 0.05;
    Settings t;
    cli::apply_tree_input_options(t, o);
    EXPECT_EQ(t.growth.split_angle_deg, 40.0);
    EXPECT_EQ(t.lobes.edge_length_m, 0.05);
}

TEST(CliSettings, SettingsCommandPrintsTheTableAndTheDefaultsAsASettingsFile)
{
    const test::CliRun table = test::run_cli("settings");
    ASSERT_EQ(table.code, 0) << table.out;
    for (const SettingInfo& info : settings_table()) EXPECT_NE(table.out.find(info.key), std::string::npos) << info.key;
    // A row: key, default, range, meaning.
    const std::size_t row = table.out.find("\nlobes.remesh_iterations ");
    ASSERT_NE(row, std::string::npos) << table.out;
    std::istringstream line(table.out.substr(row + 1, table.out.find('\n', row + 1) - row - 1));
    std::string key, value, lo, hi;
    line >> key >> value >> lo >> hi;
    EXPECT_EQ(value, std::to_string(LobeSettings{}.remesh_iterations));
    EXPECT_EQ(lo + " " + hi, "[0, 20]");

    const test::CliRun json = test::run_cli("settings --json");
    ASSERT_EQ(json.code, 0) << json.out;
    const nlohmann::json j = nlohmann::json::parse(json.out);
    EXPECT_EQ(j, settings_json(Settings{}));
    EXPECT_TRUE(settings_equal(settings_from_json(j), Settings{}));
    EXPECT_TRUE(j["lobes"]["remesh_iterations"].is_number_integer());

    EXPECT_EQ(test::run_cli("settings --json --markdown").code, 2);
}

TEST(CliSettings, DocsSettingsMdIsTheTableAsTheCommandPrintsIt)
{
    const test::CliRun md = test::run_cli("settings --markdown");
    ASSERT_EQ(md.code, 0) << md.out;
    std::ifstream in(test::source_path("docs/settings.md"), std::ios::binary);
    ASSERT_TRUE(in) << "docs/settings.md is missing";
    const std::string doc((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    // Line by line, so a failure shows the row that disagrees.
    std::istringstream want(md.out), have(doc);
    std::string w, h;
    int line = 0;
    while (true) {
        const bool more_w = static_cast<bool>(std::getline(want, w)), more_h = static_cast<bool>(std::getline(have, h));
        ++line;
        if (!more_w && !more_h) break;
        if (w != h || more_w != more_h) {
            ADD_FAILURE() << "docs/settings.md:" << line << " disagrees with the settings table\n  doc:   " << h
                          << "\n  table: " << w
                          << "\nregenerate it: lobesketch settings --markdown > docs/settings.md";
            break;
        }
    }
    EXPECT_TRUE(doc == md.out);
    for (const SettingInfo& info : settings_table())
        EXPECT_NE(doc.find("| `" + info.key + "` | `"), std::string::npos) << info.key;
}

TEST(CliSettings, EverySettingTheDocsNameIsInTheTable)
{
    // `settings.SECTION.KEY` anywhere in the docs (session-format.md, growth.md, limits.md, …)
    // names a setting or a section the table has, so a renamed setting cannot be left behind.
    const std::regex mention(R"(settings\.([a-z_]+(?:\.[a-z_]+)*))");
    std::size_t checked = 0;
    for (const auto& f : std::filesystem::directory_iterator(test::source_path("docs"))) {
        if (f.path().extension() != ".md") continue;
        std::ifstream in(f.path());
        const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        for (auto m = std::sregex_iterator(text.begin(), text.end(), mention); m != std::sregex_iterator(); ++m) {
            const std::string key = (*m)[1];
            if (key == "md" || key == "h") continue; // settings.md, core/settings.h
            const bool section = std::find(settings_sections().begin(), settings_sections().end(), key) !=
                                 settings_sections().end();
            EXPECT_TRUE(section || find_setting(key)) << f.path().filename().string() << ": settings." << key;
            ++checked;
        }
    }
    EXPECT_GT(checked, 10u);
}
