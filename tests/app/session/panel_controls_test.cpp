// The panel settings (app/session/panel_controls.h): one per Setting event id, each naming a
// setting of the settings table (or the document's seed), with a panel range inside what
// the session builder accepts.
#include <gtest/gtest.h>

#include <set>
#include <string>

#include "app/session/panel_controls.h"
#include "app/session/session_builder.h"
#include "growth/grower.h"
#include "core/settings_table.h"

using namespace lobe;

TEST(PanelControls, EverySettingEventIdHasAControlNamingATableSetting)
{
    std::set<int> ids;
    for (const PanelControl& c : panel_controls()) {
        SCOPED_TRACE(c.label);
        EXPECT_TRUE(ids.insert(static_cast<int>(c.id)).second);
        EXPECT_EQ(find_panel_control(c.id), &c);
        EXPECT_TRUE(known_setting_id(static_cast<std::int32_t>(c.id)));
        const std::string key = c.key;
        EXPECT_TRUE(c.setting() || key == "seed" || key == "grower" || key == "growth-steps") << c.key;
        EXPECT_FALSE(std::string(c.label).empty());
        // The widget's range lies within what a Setting event may carry, and its step fits it.
        const SettingRange accepts = c.accepts();
        EXPECT_GT(c.step, 0.0);
        if (key == "grower") {
            EXPECT_LE(c.lo, c.hi); // the growers' panel codes: one grower is a range of one
        } else {
            EXPECT_LT(c.lo, c.hi);
            EXPECT_LE(c.step, c.hi - c.lo);
        }
        EXPECT_TRUE(accepts.contains(c.lo)) << accepts.text();
        EXPECT_TRUE(accepts.contains(c.hi)) << accepts.text();
        // A number's range is the table's; a colour's is its packed 0xRRGGBB values.
        if (c.setting() && (c.setting()->type == SettingType::Number || c.setting()->type == SettingType::Integer)) {
            EXPECT_EQ(accepts.text(), c.setting()->range.text());
        }
    }
    for (std::int32_t id = 1; id < 100; ++id) EXPECT_EQ(ids.count(id), known_setting_id(id) ? 1u : 0u) << id;
    EXPECT_EQ(find_panel_control(static_cast<SettingId>(99)), nullptr);
    EXPECT_STREQ(find_panel_control(SettingId::Species)->setting()->key.c_str(), "growth.species");
    EXPECT_EQ(find_panel_control(SettingId::Species)->hi, kSettingSpeciesCount - 1.0);
}

TEST(PanelControls, TheSessionBuilderAcceptsWhatTheControlsSay)
{
    SessionBuilder b;
    auto setting = [](SettingId id, double v, std::int64_t lobe = 0) {
        InputAction a;
        a.type = InputAction::Type::SettingChanged;
        a.time = 1.0;
        a.setting.id = id;
        a.setting.value = v;
        a.setting.lobe = lobe;
        return a;
    };
    // Both ends of every control's range are accepted (the growth steps by the grower whose
    // range is the control's: lsystem's derivation steps, 0 … kMaxDerivationLength).
    for (const PanelControl& c : panel_controls())
        for (double v : {c.lo, c.hi}) {
            if (c.id == SettingId::GrowthSteps) b.apply(setting(SettingId::Grower, find_grower("lsystem")->panel_code()));
            b.apply(setting(c.id, v));
            EXPECT_TRUE(b.messages().empty()) << c.label << " " << v << ": " << b.messages().back();
        }
    EXPECT_EQ(b.document().seed, 16777215u);
    EXPECT_EQ(b.document().settings.growth.split_angle_deg, 90.0);
    // Beyond what the seed control accepts, and a tree-wide control given a lobe.
    EXPECT_FALSE(b.apply(setting(SettingId::Seed, 16777216)));
    EXPECT_EQ(b.messages().back(),
              "setting seed at t=1.00s changes nothing: the seed must be a whole number from 1 to 16777215");
    EXPECT_FALSE(b.apply(setting(SettingId::AttractorSpacing, 0.03, 4)));
    EXPECT_NE(b.messages().back().find(find_panel_control(SettingId::AttractorSpacing)->tree_wide_only),
              std::string::npos);
}

TEST(PanelControls, TheAppearanceControlsSetLeafWidthColoursAndRadiiOfTheWholeTree)
{
    SessionBuilder b;
    auto setting = [](SettingId id, double v, std::int64_t lobe = 0) {
        InputAction a;
        a.type = InputAction::Type::SettingChanged;
        a.time = 1.0;
        a.setting.id = id;
        a.setting.value = v;
        a.setting.lobe = lobe;
        return a;
    };
    const double length = b.document().settings.leaves.length_m;
    EXPECT_TRUE(b.apply(setting(SettingId::LeafWidth, 0.021)));
    EXPECT_EQ(b.document().settings.leaves.width_m, 0.021);
    EXPECT_EQ(b.document().settings.leaves.length_m, length); // the width alone
    EXPECT_TRUE(b.apply(setting(SettingId::LeafColor, 0x336619)));
    EXPECT_EQ(b.document().settings.leaves.color[0], 0x33 / 255.0);
    EXPECT_EQ(b.document().settings.leaves.color[1], 0x66 / 255.0);
    EXPECT_EQ(b.document().settings.leaves.color[2], 0x19 / 255.0);
    EXPECT_TRUE(b.apply(setting(SettingId::BarkColor, 0xC8C2B4)));
    EXPECT_EQ(pack_color(b.document().settings.branches.bark_color), 0xC8C2B4);
    EXPECT_TRUE(b.apply(setting(SettingId::PipeExponent, 2.5)));
    EXPECT_EQ(b.document().settings.branches.pipe_exponent, 2.5);
    EXPECT_TRUE(b.apply(setting(SettingId::TipRadius, 0.002)));
    EXPECT_EQ(b.document().settings.branches.tip_radius_m, 0.002);
    // Whole numbers only for a colour; every one of them tree-wide only.
    EXPECT_FALSE(b.apply(setting(SettingId::LeafColor, 0.5)));
    EXPECT_NE(b.messages().back().find("0xRRGGBB"), std::string::npos) << b.messages().back();
    EXPECT_FALSE(b.apply(setting(SettingId::LeafWidth, 2.0)));
    EXPECT_NE(b.messages().back().find("leaves.width_m"), std::string::npos) << b.messages().back();
    for (SettingId id : {SettingId::LeafWidth, SettingId::LeafColor, SettingId::BarkColor, SettingId::PipeExponent,
                         SettingId::TipRadius})
        EXPECT_NE(find_panel_control(id)->tree_wide_only, nullptr) << setting_name(id);
    // A packed colour reads back as itself.
    for (int packed : {0, 0x336619, 0xFFFFFF, 0x5C402B}) {
        double rgb[3];
        unpack_color(packed, rgb);
        EXPECT_EQ(pack_color(rgb), packed);
    }
}
