// Real scale and the radius options on the command line (docs/export.md "Size",
// docs/growth.md "Radii"): `--height`, `--pipe-exponent`, `--tip-radius` in grow and replay.
#include <algorithm>
#include <fstream>
#include <iterator>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/support/cli_run.h"
#include "tests/support/test_paths.h"

namespace lobe {
namespace {

nlohmann::json read_json(const std::string& path)
{
    std::ifstream in(path, std::ios::binary);
    return nlohmann::json::parse(std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()));
}

struct GraphFigures {
    double height = 0.0, thinnest = 1e9, root_radius = 0.0;
};
GraphFigures figures(const nlohmann::json& tree)
{
    GraphFigures f;
    const auto& nodes = tree["nodes"];
    const double base = nodes[0]["position"][1].get<double>();
    f.root_radius = nodes[0]["radius"].get<double>();
    for (const auto& n : nodes) {
        f.height = std::max(f.height, n["position"][1].get<double>() - base);
        f.thinnest = std::min(f.thinnest, n["radius"].get<double>());
    }
    return f;
}

TEST(RealScaleCli, HeightScalesTheStructureAndTheRadiusOptionsSetTheRadii)
{
    const std::string dir = test::temp_dir("real-scale-cli");
    const std::string rec = test::source_path("recordings/pinch-edit.lrec");
    const auto grow = [&](const std::string& name, const std::string& options) {
        const test::CliRun r =
            test::run_cli("grow " + rec + " --out " + dir + "/" + name + ".glb --skeleton-out " + dir + "/" + name + ".json " + options);
        EXPECT_EQ(r.code, 0) << r.out;
        return figures(read_json(dir + "/" + name + ".json"));
    };
    const GraphFigures sketch = grow("sketch", "");
    EXPECT_LT(sketch.height, 1.5); // trees come out at sketch size
    const GraphFigures tall = grow("tall", "--height 8");
    EXPECT_NEAR(tall.height, 8.0, 1e-3);
    EXPECT_NEAR(tall.thinnest, 0.0012, 1e-6); // twigs keep the broadleaf's 1.2 mm
    EXPECT_NEAR(sketch.thinnest, 0.0012, 1e-6);
    // --tip-radius sets the twigs; --pipe-exponent is used as given (no fit), so the root
    // radius is the pipe model's: larger exponent, thinner trunk.
    const GraphFigures thick = grow("thick", "--height 8 --tip-radius 0.002 --pipe-exponent 2");
    const GraphFigures thin = grow("thin", "--height 8 --tip-radius 0.002 --pipe-exponent 3");
    EXPECT_NEAR(thick.thinnest, 0.002, 1e-6);
    EXPECT_GT(thick.root_radius, 1.5 * thin.root_radius);
    // Bad values are a bad command line.
    for (const char* bad : {"--pipe-exponent 9", "--tip-radius 0", "--height -1", "--height nan"}) {
        const test::CliRun r = test::run_cli("grow " + rec + " --out " + dir + "/bad.glb " + bad);
        EXPECT_EQ(r.code, 2) << bad << ": " << r.out;
        EXPECT_NE(r.out.find("lobesketch: error:"), std::string::npos) << r.out;
    }
}

TEST(RealScaleCli, ReplayStoresTheHeightAndTheRadiiInTheSession)
{
    const std::string dir = test::temp_dir("real-scale-replay");
    const test::CliRun r = test::run_cli("replay " + test::source_path("recordings/pinch-edit.lrec") + " --out " + dir +
                                         " --height 6 --tip-radius 0.0015");
    ASSERT_EQ(r.code, 0) << r.out;
    const nlohmann::json session = read_json(dir + "/session.json");
    EXPECT_EQ(session["settings"]["growth"]["height_m"].get<double>(), 6.0);
    EXPECT_EQ(session["settings"]["branches"]["tip_radius_m"].get<double>(), 0.0015);
    // Exporting that session gives the tree at that height.
    const test::CliRun e =
        test::run_cli("export " + dir + "/session.json --out " + dir + "/again.glb --skeleton-out " + dir + "/again.json");
    ASSERT_EQ(e.code, 0) << e.out;
    EXPECT_NEAR(figures(read_json(dir + "/again.json")).height, 6.0, 1e-3);
}

} // namespace
} // namespace lobe
