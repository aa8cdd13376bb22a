// A session tree's grower as the document reader sees it (core/grower_choice.h): its shape is
// checked at load, its contents by the growers (tests/growth/grower_test.cpp,
// tests/app/session/session_file_test.cpp).
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "core/document.h"
#include "core/errors.h"

using namespace lobe;
using nlohmann::json;

namespace {

json session_with_tree(json tree)
{
    return json{{"format", "lobesketch-session"}, {"version", 1}, {"trees", json::array({std::move(tree)})}};
}

std::string refusal(const json& j)
{
    try {
        document_from_json(j);
    } catch (const InvalidInput& e) {
        return e.what();
    }
    return "";
}

} // namespace

TEST(GrowerChoice, ATreeWrittenBeforeTreesNamedTheirGrowerLoadsWithTheDefaultGrower)
{
    const Document d = document_from_json(session_with_tree({{"id", 1}, {"seed", 3u}, {"lobes", json::array()}}));
    ASSERT_EQ(d.trees.size(), 1u);
    EXPECT_EQ(d.trees[0].grower, GrowerChoice{});
    EXPECT_EQ(d.trees[0].grower.name, kDefaultGrowerName);
    EXPECT_EQ(scene_grower(Document{}).name, kDefaultGrowerName);
}

TEST(GrowerChoice, NameVersionAndEveryKindOfParameterRoundTrip)
{
    Document d;
    TreeInstance t;
    t.id = 4;
    t.grower.name = "self-organizing";
    t.grower.version = 3;
    t.grower.params = {{"iterations", std::int64_t{12}}, {"shadow", true}, {"xi", 0.25}, {"species", std::string("pine")}};
    d.trees.push_back(t);
    const json j = document_to_json(d);
    EXPECT_EQ(j["trees"][0]["grower"]["name"], "self-organizing");
    EXPECT_TRUE(j["trees"][0]["grower"]["params"]["iterations"].is_number_integer());
    const Document e = document_from_json(j);
    EXPECT_EQ(e.trees.at(0).grower, t.grower);
    EXPECT_EQ(scene_grower(e).name, "self-organizing");
    EXPECT_EQ(document_to_json(e), j);
}

TEST(GrowerChoice, MalformedGrowersAreRefusedAtLoadNamingTheField)
{
    auto grower = [](json g) { return session_with_tree({{"id", 1}, {"grower", std::move(g)}}); };
    EXPECT_NE(refusal(grower("subtrees")).find("trees[0].grower: expected an object"), std::string::npos);
    EXPECT_NE(refusal(grower({{"version", 1}})).find("trees[0].grower.name:"), std::string::npos);
    EXPECT_NE(refusal(grower({{"name", "Sub Trees"}})).find("trees[0].grower.name:"), std::string::npos);
    EXPECT_NE(refusal(grower({{"name", std::string(65, 'a')}})).find("trees[0].grower.name:"), std::string::npos);
    EXPECT_NE(refusal(grower({{"name", "subtrees"}, {"version", 0}})).find("trees[0].grower.version:"),
              std::string::npos);
    EXPECT_NE(refusal(grower({{"name", "subtrees"}, {"colour", "red"}})).find("trees[0].grower: unknown key 'colour'"),
              std::string::npos);
    EXPECT_NE(refusal(grower({{"name", "subtrees"}, {"params", {{"a", json::array({1, 2})}}}}))
                  .find("trees[0].grower.params.a: expected true, false, a number or a text"),
              std::string::npos);
    EXPECT_NE(refusal(grower({{"name", "subtrees"}, {"params", {{"a", nullptr}}}})).find("trees[0].grower.params.a:"),
              std::string::npos);
    EXPECT_NE(refusal(session_with_tree({{"id", 1}, {"forest", true}})).find("trees[0]: unknown key 'forest'"),
              std::string::npos);
}
