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
        if (c.setting() && c.setting()->type != SettingType::Name) {
            EXPECT_EQ(accepts.text(), c.setting()->range.text());
        }
    }
    for (std::int32_t id = 1; known_setting_id(id); ++id) EXPECT_EQ(ids.count(id), 1u) << id;
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
