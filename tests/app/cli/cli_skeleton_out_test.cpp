// `--skeleton-out tree.json` (app/export/skeleton_json.h): every grower's tree graph as a file,
// from `grow`, `export` and `lsystem`.
#include <cmath>
#include <fstream>
#include <iterator>
#include <set>
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

/// The count in "grew N nodes" of the command's output; 0 when it says none.
std::size_t grown_nodes(const std::string& out)
{
    const std::size_t at = out.find("grew ");
    return at == std::string::npos ? 0 : std::stoul(out.substr(at + 5));
}

TEST(SkeletonOut, EveryGrowerWritesItsWholeTreeParentsFirstWithTheLobesIds)
{
    const std::string dir = test::temp_dir("skeleton-out");
    const std::string rec = test::source_path("recordings/table1-3lobes-16strokes.lrec");
    ASSERT_EQ(test::run_cli("replay " + rec + " --out " + dir + "/replay").code, 0);
    std::set<std::int64_t> lobe_ids{0};
    const nlohmann::json session = read_json(dir + "/replay/session.json");
    for (const auto& l : session["lobes"]) lobe_ids.insert(l["id"].get<std::int64_t>());
    ASSERT_EQ(lobe_ids.size(), 4u);
    for (const std::string grower : {"subtrees", "lsystem", "self-organizing"}) {
        const std::string json = dir + "/" + grower + ".json";
        const test::CliRun r = test::run_cli("export " + dir + "/replay/session.json --grower " + grower + " --out " + dir +
                                             "/" + grower + ".glb --skeleton-out " + json);
        ASSERT_EQ(r.code, 0) << grower << ": " << r.out;
        const nlohmann::json j = read_json(json);
        const auto& nodes = j["nodes"];
        EXPECT_EQ(nodes.size(), grown_nodes(r.out)) << grower;
        ASSERT_GT(nodes.size(), 100u) << grower;
        std::set<std::int64_t> used;
        for (std::size_t i = 0; i < nodes.size(); ++i) {
            const auto& n = nodes[i];
            EXPECT_EQ(n["id"].get<std::size_t>(), i);
            const int parent = n["parent"].get<int>();
            if (i == 0) EXPECT_EQ(parent, -1) << grower;
            else EXPECT_TRUE(parent >= 0 && parent < static_cast<int>(i)) << grower << " node " << i;
            for (int k = 0; k < 3; ++k) EXPECT_TRUE(std::isfinite(n["position"][k].get<double>())) << grower;
            EXPECT_GT(n["radius"].get<double>(), 0.0) << grower << " node " << i;
            used.insert(n["lobe"].get<std::int64_t>());
        }
        for (const std::int64_t id : used) EXPECT_TRUE(lobe_ids.count(id)) << grower << ": lobe " << id;
        EXPECT_EQ(used.size(), 4u) << grower << ": the skeleton and each of the three lobes";
    }
}

} // namespace
} // namespace lobe
