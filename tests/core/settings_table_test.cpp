// The settings table (core/settings_table.h) and the settings JSON it drives
// (core/settings_json.h): every setting once, read strictly, written with its type,
// checked against its range.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <functional>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/errors.h"
#include "core/settings_json.h"
#include "core/settings_table.h"

using namespace lobe;
using nlohmann::json;

namespace {

std::string message_of(const std::function<void()>& f)
{
    try {
        f();
    } catch (const InvalidInput& e) {
        return e.what();
    }
    return "(no error)";
}

/// A value of the setting's type that differs from `s`'s and is within its own range.
SettingValue other_value(const Settings& s, const SettingInfo& info)
{
    const SettingValue v = get_setting(s, info);
    switch (info.type) {
    case SettingType::Number: {
        // A step of 0.1 %, away from the end it is at: within the ranges that are other settings too.
        const double x = std::get<double>(v);
        if (x == 0.0) return (info.range.lo + info.range.hi) / 2.0;
        return info.range.contains(x * 1.001) ? x * 1.001 : x * 0.999;
    }
    case SettingType::Integer: {
        const int x = std::get<int>(v);
        return x < static_cast<int>(info.range.hi) ? x + 1 : x - 1;
    }
    case SettingType::Name:
        if (info.choices.empty()) return std::get<std::string>(v) + "x";
        return std::get<std::string>(v) == info.choices.back() ? info.choices.front() : info.choices.back();
    case SettingType::Color: {
        auto c = std::get<std::array<double, 3>>(v);
        c[1] = c[1] > 0.5 ? 0.25 : 0.75;
        return c;
    }
    case SettingType::Weights: {
        auto w = std::get<std::map<std::string, double>>(v);
        w["fork"] = w.count("fork") ? w["fork"] + 1.0 : 2.5;
        return w;
    }
    }
    return v;
}

const json* at_key(const json& j, const std::string& key)
{
    const json* at = &j;
    std::size_t from = 0;
    for (;;) {
        const std::size_t dot = key.find('.', from);
        const std::string part = key.substr(from, dot == std::string::npos ? dot : dot - from);
        if (!at->is_object() || !at->contains(part)) return nullptr;
        at = &(*at)[part];
        if (dot == std::string::npos) return at;
        from = dot + 1;
    }
}

} // namespace

TEST(SettingsTable, DefaultsAreTheStructsMemberInitializers)
{
    const Settings d;
    EXPECT_EQ(std::get<int>(get_setting(d, *find_setting("lobes.remesh_iterations"))), LobeSettings{}.remesh_iterations);
    EXPECT_EQ(std::get<double>(get_setting(d, *find_setting("lobes.edge_length_m"))), LobeSettings{}.edge_length_m);
    EXPECT_EQ(std::get<double>(get_setting(d, *find_setting("input.gap_filter.min_cutoff_hz"))),
              InputOptions{}.gap_filter.min_cutoff_hz);
    EXPECT_EQ(std::get<double>(get_setting(d, *find_setting("input.filter.min_cutoff_hz"))),
              InputOptions{}.filter.min_cutoff_hz);
    EXPECT_EQ(std::get<std::string>(get_setting(d, *find_setting("leaves.shape"))), LeafSettings{}.shape);
    EXPECT_EQ((std::get<std::array<double, 3>>(get_setting(d, *find_setting("branches.bark_color"))))[2],
              BranchSettings{}.bark_color[2]);
    // The defaults are valid, and their text reads back as the same values.
    EXPECT_NO_THROW(validate_settings(d));
    for (const SettingInfo& info : settings_table()) {
        Settings s;
        set_setting(s, info, other_value(s, info));
        set_setting_text(s, info, setting_text(d, info));
        EXPECT_TRUE(get_setting(s, info) == get_setting(d, info)) << info.key;
    }
}

TEST(SettingsTable, EveryRowIsItsOwnMemberAndEveryKeyIsWrittenWithItsType)
{
    std::set<std::string> keys;
    const json defaults = settings_json(Settings{});
    for (const SettingInfo& info : settings_table()) {
        SCOPED_TRACE(info.key);
        EXPECT_TRUE(keys.insert(info.key).second) << "listed twice";
        EXPECT_FALSE(info.doc.empty());
        EXPECT_EQ(find_setting(info.key), &info);
        // Changing this setting changes this setting alone.
        Settings s;
        set_setting(s, info, other_value(s, info));
        for (const SettingInfo& other : settings_table())
            EXPECT_EQ(get_setting(s, other) == get_setting(Settings{}, other), &other != &info) << other.key;
        EXPECT_NO_THROW(check_setting(s, info));
        // Written where its key says, integers as integers, and read back the same.
        const json* v = at_key(defaults, info.key);
        ASSERT_NE(v, nullptr);
        if (info.type == SettingType::Integer) {
            EXPECT_TRUE(v->is_number_integer());
        }
        if (info.type == SettingType::Number) {
            EXPECT_TRUE(v->is_number_float());
        }
        EXPECT_TRUE(settings_equal(settings_from_json(settings_json(s)), s));
        EXPECT_FALSE(settings_equal(s, Settings{}));
    }
    // Nothing else is written: as many values as rows.
    std::size_t values = 0;
    std::function<void(const json&)> count = [&](const json& j) {
        for (auto it = j.begin(); it != j.end(); ++it) {
            const bool section = it->is_object() && it.key() != "subtree_weights";
            if (section) count(*it);
            else ++values;
        }
    };
    count(defaults);
    EXPECT_EQ(values, settings_table().size());
}

TEST(SettingsTable, ReadingRefusesUnknownKeysAndWrongTypesNamingTheKey)
{
    auto read = [](const char* text) { return message_of([&] { settings_from_json(json::parse(text)); }); };
    EXPECT_EQ(read(R"({"lobes": {"edge_lenght_m": 0.03}})"), "settings.lobes: unknown key 'edge_lenght_m'");
    EXPECT_EQ(read(R"({"trunk": {}})"), "settings: unknown key 'trunk'");
    EXPECT_EQ(read(R"({"input": {"gap_filter": {"beta": "x"}}})"), "settings.input.gap_filter.beta: expected a number");
    EXPECT_EQ(read(R"({"input": {"filter": []}})"), "settings.input.filter: expected an object");
    EXPECT_EQ(read(R"({"growth": {"max_nodes": 1.5}})"), "settings.growth.max_nodes: expected an integer in [-1e9, 1e9]");
    EXPECT_EQ(read(R"({"leaves": {"shape": 3}})"), "settings.leaves.shape: expected a string");
    EXPECT_EQ(read(R"({"leaves": {"color": [0.1, 0.2]}})"), "settings.leaves.color: expected [r, g, b]");
    EXPECT_EQ(read(R"({"growth": {"subtree_weights": {"fork": -1}}})"),
              "settings.growth.subtree_weights.fork: must be in [0, 1e6]");
    EXPECT_EQ(read(R"([1])"), "settings: expected an object");
    // A partial object keeps the other defaults.
    const Settings s = settings_from_json(json::parse(R"({"growth": {"split_angle_deg": 25}})"));
    EXPECT_EQ(s.growth.split_angle_deg, 25.0);
    EXPECT_EQ(s.growth.alpha, GrowthSettings{}.alpha);
}

TEST(SettingsTable, EveryValueOutOfItsRangeIsRefusedNamingTheKeyAndTheRange)
{
    for (const SettingInfo& info : settings_table()) {
        if (info.type != SettingType::Number && info.type != SettingType::Integer) continue;
        SCOPED_TRACE(info.key);
        const std::string want = "settings." + info.key + " must be in " + info.range.text();
        const double outside[] = {info.range.lo_key.empty() ? info.range.lo - 1.0 : NAN,
                                  info.range.hi_key.empty() ? info.range.hi + 1.0 : NAN};
        for (double v : outside) {
            if (std::isnan(v)) continue;
            Settings s;
            if (info.type == SettingType::Number) set_setting(s, info, v);
            else set_setting(s, info, static_cast<int>(v));
            EXPECT_EQ(message_of([&] { validate_settings(s); }), want);
            EXPECT_EQ(message_of([&] { settings_from_json(settings_json(s)); }), want);
            Settings t;
            EXPECT_EQ(message_of([&] { set_setting_text(t, info, setting_text(s, info)); }), want);
        }
    }
    // An end that is another setting.
    Settings s;
    s.input.pinch_start_m = 0.02;
    s.input.pinch_release_m = 0.01;
    EXPECT_EQ(message_of([&] { validate_settings(s); }), "settings.input.pinch_release_m must be in (pinch_start_m, 0.2)");
    s.leaves.shape = "star";
    EXPECT_EQ(message_of([&] { validate_settings_section(s, "leaves"); }),
              "settings.leaves.shape must be \"ovate\", \"round\" or \"needle\"");
    s.growth.species.clear();
    EXPECT_EQ(message_of([&] { validate_settings_section(s, "growth"); }),
              "settings.growth.species must be a name of 1 to 64 characters");
}

TEST(SettingsTable, TextValuesParseByTypeAndBadOnesNameTheKey)
{
    Settings s;
    set_setting_text(s, *find_setting("leaves.color"), "0.2,0.4,0.1");
    EXPECT_EQ(s.leaves.color[1], 0.4);
    set_setting_text(s, *find_setting("growth.subtree_weights"), "fork:3,whorl:0.5");
    EXPECT_EQ(s.growth.subtree_weights, (std::map<std::string, double>{{"fork", 3.0}, {"whorl", 0.5}}));
    EXPECT_EQ(setting_text(s, *find_setting("growth.subtree_weights")), "fork:3,whorl:0.5");
    set_setting_text(s, *find_setting("branches.lod_count"), "2");
    EXPECT_EQ(s.branches.lod_count, 2);
    set_setting_text(s, *find_setting("branches.lod_count"), "+1");
    EXPECT_EQ(s.branches.lod_count, 1);
    set_setting_text(s, *find_setting("growth.split_angle_deg"), "+25");
    EXPECT_EQ(s.growth.split_angle_deg, 25.0);
    EXPECT_EQ(message_of([&] { set_setting_text(s, *find_setting("branches.lod_count"), "2.5"); }),
              "settings.branches.lod_count: expected an integer, not '2.5'");
    EXPECT_EQ(message_of([&] { set_setting_text(s, *find_setting("leaves.color"), "1,2"); }),
              "settings.leaves.color: expected r,g,b (three numbers), not '1,2'");
    EXPECT_EQ(message_of([&] { set_setting_text(s, *find_setting("leaves.color"), "1,2,0"); }),
              "settings.leaves.color: components must be in [0, 1]");
    EXPECT_EQ(message_of([&] { set_setting_text(s, *find_setting("growth.alpha"), "nan"); }),
              "settings.growth.alpha: expected a number, not 'nan'");
    EXPECT_EQ(number_text(5000000.0), "5000000");
    EXPECT_EQ(number_text(0.0012), "0.0012");
}

TEST(SettingsTable, AnOverlaySetsOnlyItsKeys)
{
    SettingsOverlay o;
    o.set_text("growth.split_angle_deg", "25");
    o.set_text("leaves.shape", "round");
    EXPECT_EQ(message_of([&] { o.set_text("growth.split_angle", "25"); }),
              "unknown setting 'growth.split_angle' (`lobesketch settings` lists them)");
    EXPECT_EQ(message_of([&] { o.set_text("growth.split_angle_deg", "200"); }),
              "settings.growth.split_angle_deg must be in [5, 180]");
    Settings s;
    s.growth.alpha = 0.5;
    o.apply_to(s);
    EXPECT_EQ(s.growth.split_angle_deg, 25.0);
    EXPECT_EQ(s.leaves.shape, "round");
    EXPECT_EQ(s.growth.alpha, 0.5);
    EXPECT_EQ(o.keys, (std::vector<std::string>{"growth.split_angle_deg", "leaves.shape"}));
}
