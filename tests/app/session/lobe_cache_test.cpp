// The lobe cache's key (app/session/lobe_cache.h): every setting of the lobes section,
// through the settings table, and nothing else.
#include <gtest/gtest.h>

#include <array>
#include <map>
#include <string>

#include "app/session/lobe_cache.h"
#include "core/settings_table.h"
#include "tests/support/replay_fixture.h"

using namespace lobe;

namespace {

/// `s` with one setting changed to another value within its own range.
Settings changed(const SettingInfo& info)
{
    Settings s;
    const SettingValue v = get_setting(s, info);
    if (const double* d = std::get_if<double>(&v)) {
        set_setting(s, info, *d == 0.0 ? 0.01 : *d * 1.001);
    } else if (const int* i = std::get_if<int>(&v)) {
        set_setting(s, info, *i + 1);
    } else if (const std::string* n = std::get_if<std::string>(&v)) {
        const std::string other = info.choices.empty() ? *n + "x" : info.choices.back() == *n ? info.choices.front()
                                                                                               : info.choices.back();
        set_setting(s, info, other);
    } else if (const auto* c = std::get_if<std::array<double, 3>>(&v)) {
        set_setting(s, info, std::array<double, 3>{(*c)[0] / 2, (*c)[1], (*c)[2]});
    } else {
        set_setting(s, info, std::map<std::string, double>{{"fork", 1.0}});
    }
    return s;
}

} // namespace

TEST(LobeCache, TheKeyChangesWithEveryLobesSettingAndWithNoOther)
{
    const std::string plain = lobe_build_key(Settings{});
    std::size_t lobes = 0;
    for (const SettingInfo& info : settings_table()) {
        const Settings s = changed(info);
        ASSERT_FALSE(settings_equal(s, Settings{})) << info.key;
        if (info.section == "lobes") {
            ++lobes;
            EXPECT_NE(lobe_build_key(s), plain) << info.key;
        } else {
            EXPECT_EQ(lobe_build_key(s), plain) << info.key;
        }
    }
    EXPECT_GT(lobes, 0u);
}

TEST(LobeCache, ALobeIsBuiltAgainWhenALobesSettingChanges)
{
    Document doc = test::replay_document("table1-1lobe-5strokes");
    ASSERT_EQ(doc.lobes.size(), 1u);
    LobeBuildCache cache;
    build_document_lobes(doc, nullptr, cache);
    build_document_lobes(doc, nullptr, cache);
    EXPECT_EQ(cache.last_build().kept, 1u);
    doc.settings.growth.split_angle_deg = 40.0; // growth does not touch the lobes
    build_document_lobes(doc, nullptr, cache);
    EXPECT_EQ(cache.last_build().kept, 1u);
    doc.settings.lobes.closed_gap_max_m = 0.07;
    build_document_lobes(doc, nullptr, cache);
    EXPECT_EQ(cache.last_build().built, 1u);
}
