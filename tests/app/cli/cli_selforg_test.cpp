// `lobesketch grow --grower self-organizing` and its options (app/cli/cli_common.h), and the
// wood report (`--report`, growth/wood.h) every grower writes.
#include <filesystem>
#include <fstream>
#include <string>
#include <variant>
#include <iterator>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "app/cli/cli_common.h"
#include "core/document.h"
#include "core/errors.h"
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
    // One file name in two folders: node names come from the file's stem.
    std::filesystem::create_directories(out + "/a");
    std::filesystem::create_directories(out + "/b");
    const test::CliRun a = test::run_cli("grow " + rec + opts + out + "/a/tree.glb");
    ASSERT_EQ(a.code, 0) << a.out;
    const test::CliRun b = test::run_cli("grow " + rec + opts + out + "/b/tree.glb");
    ASSERT_EQ(b.code, 0) << b.out;
    EXPECT_EQ(bytes(out + "/a/tree.glb"), bytes(out + "/b/tree.glb"));
    const test::CliRun markers = test::run_cli("grow " + rec + " --grower self-organizing --out " + out + "/c.glb");
    ASSERT_EQ(markers.code, 0) << markers.out;
    EXPECT_NE(bytes(out + "/a.glb"), bytes(out + "/c.glb"));
}

TEST(SelfOrganizingCli, TheOptionsBecomeTheGrowersParametersAndASpeciesPresetNameIsOneOfThem)
{
    cli::TreeInputOptions o;
    o.grower = "self-organizing";
    o.environment = "shadow";
    o.bud_fate = "priority";
    o.iterations = 9;
    o.species = "birch";
    Document doc;
    cli::apply_document_options(doc, o);
    const GrowerChoice& c = scene_grower(doc);
    EXPECT_EQ(c.name, "self-organizing");
    EXPECT_EQ(std::get<std::string>(c.params.at("environment")), "shadow");
    EXPECT_EQ(std::get<std::string>(c.params.at("bud_fate")), "priority");
    EXPECT_EQ(std::get<std::int64_t>(c.params.at("iterations")), 9);
    EXPECT_EQ(std::get<std::string>(c.params.at("species")), "birch");
    // Without --grower, the options change a session already growing self-organizing; a
    // preset file sets only the appearance.
    cli::TreeInputOptions later;
    later.iterations = 30;
    later.species = "my-preset.json";
    cli::apply_document_options(doc, later);
    EXPECT_EQ(std::get<std::int64_t>(scene_grower(doc).params.at("iterations")), 30);
    EXPECT_EQ(std::get<std::string>(scene_grower(doc).params.at("species")), "birch");
    Document other;
    EXPECT_THROW(cli::apply_document_options(other, later), cli::UsageError);
}

TEST(SelfOrganizingCli, ItsOptionsWithAnotherGrowerOrBadValuesAreRefusedInOneLine)
{
    const std::string out = test::temp_dir("selforg-cli-bad");
    const std::string rec = test::source_path("recordings/table1-1lobe-5strokes.lrec");
    for (const char* opt : {"--environment shadow", "--bud-fate priority", "--iterations 5"}) {
        const test::CliRun r = test::run_cli("grow " + rec + " " + opt + " --out " + out + "/a.glb");
        EXPECT_EQ(r.code, 2) << r.out;
        EXPECT_EQ(r.out.find("replaying"), std::string::npos) << "refused before the recording is replayed: " << r.out;
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

namespace lobe {
namespace {

TEST(WoodReportCli, EveryGrowerWritesTheWoodReportAndHeightGivesTheRealScaleTreesWood)
{
    const std::string out = test::temp_dir("wood-report-cli");
    const std::string rec = test::source_path("recordings/table1-1lobe-5strokes.lrec");
    for (const char* grower : {"subtrees", "self-organizing"}) {
        const std::string base = out + "/" + grower;
        const test::CliRun plain =
            test::run_cli("grow " + rec + " --grower " + grower + " --out " + base + ".glb --report " + base + ".json");
        ASSERT_EQ(plain.code, 0) << plain.out;
        const nlohmann::json r = nlohmann::json::parse(bytes(base + ".json"));
        for (const char* key : {"wood_volume_m3", "dry_biomass_kg", "carbon_kg", "co2_kg", "density_kg_m3"})
            ASSERT_TRUE(r.contains(key)) << grower << " " << key;
        EXPECT_FALSE(r.contains("at_height"));
        const double v = r["wood_volume_m3"].get<double>();
        EXPECT_GT(v, 0.0) << grower;
        EXPECT_NEAR(r["dry_biomass_kg"].get<double>(), v * r["density_kg_m3"].get<double>(), 1e-9);
        EXPECT_NEAR(r["carbon_kg"].get<double>(), 0.5 * r["dry_biomass_kg"].get<double>(), 1e-9);
        EXPECT_NEAR(r["co2_kg"].get<double>(), r["carbon_kg"].get<double>() * 44.0 / 12.0, 1e-9);

        const test::CliRun tall = test::run_cli("grow " + rec + " --grower " + grower + " --height 12 --out " + base +
                                                "-12.glb --report " + base + "-12.json");
        ASSERT_EQ(tall.code, 0) << tall.out;
        const nlohmann::json t = nlohmann::json::parse(bytes(base + "-12.json"));
        ASSERT_TRUE(t.contains("at_height")) << grower;
        // The report is of the tree as written: at real scale (docs/export.md, "Size").
        EXPECT_EQ(t["wood_volume_m3"], t["at_height"]["wood_volume_m3"]);
        EXPECT_EQ(t["at_height"]["height_m"].get<double>(), 12.0);
        const double scale = t["at_height"]["scale"].get<double>();
        EXPECT_GT(scale, 1.0) << grower; // sketches are about 1.5 m tall
        const double ratio = t["at_height"]["wood_volume_m3"].get<double>() / v;
        EXPECT_GT(ratio, 1.0) << grower;
        // Twigs keep their real thickness and the trunk its species' share of the height, so the
        // real tree holds far less wood than the sketch blown up by the scale's cube.
        EXPECT_LT(ratio, 0.5 * scale * scale * scale) << grower;
    }
}

TEST(WoodReportCli, InfoOnASessionPrintsTheSameWoodAsTheGrowReport)
{
    const std::string out = test::temp_dir("wood-info-cli");
    const std::string session = test::source_path("tests/data/sessions/edit-stroke-transform.json");
    const test::CliRun info = test::run_cli("info " + session + " --json");
    ASSERT_EQ(info.code, 0) << info.out;
    const nlohmann::json j = nlohmann::json::parse(info.out.substr(info.out.find('{')));
    const test::CliRun grow = test::run_cli("grow " + session + " --out " + out + "/t.glb --report " + out + "/r.json");
    ASSERT_EQ(grow.code, 0) << grow.out;
    const nlohmann::json r = nlohmann::json::parse(bytes(out + "/r.json"));
    EXPECT_GT(j["nodes"].get<std::size_t>(), 100u);
    for (const char* key : {"wood_volume_m3", "dry_biomass_kg", "carbon_kg", "co2_kg", "density_kg_m3"})
        EXPECT_EQ(j["wood"][key], r[key]) << key;
    const test::CliRun text = test::run_cli("info " + session);
    ASSERT_EQ(text.code, 0) << text.out;
    EXPECT_NE(text.out.find("CO2"), std::string::npos) << text.out;
}

} // namespace
} // namespace lobe
