#pragma once
/// \file panel_controls.h
/// The settings the apps' panels change: each is recorded as a Setting event (SettingId,
/// input/recording.h) and applied by SessionBuilder (apply_setting). For each: the setting it
/// changes (a settings-table key, or the document's seed), the panel's label, the range and
/// step its widget offers, and whether it may target one lobe. What a value may be is the
/// setting's range in the settings table (core/settings_table.h); the panel's range lies
/// within it. Formats and per-lobe overrides: docs/recording-format.md, docs/editing.md.

#include <optional>
#include <string>
#include <vector>

#include "core/grower_choice.h"
#include "core/settings_table.h"
#include "input/recording.h"

namespace lobe {

struct PanelControl {
    SettingId id;
    /// The settings-table key it sets ("growth.split_angle_deg"), "seed" for Document::seed
    /// "grower" for the scene's grower (by its panel code, growth/grower.h) or
    /// "growth-steps" for its growth steps (Grower::steps_param). Species sets
    /// growth.species by an index into kSettingSpecies.
    const char* key;
    const char* label;   ///< shown on the panel
    double lo, hi, step; ///< what the widget offers, in the setting's unit (Species: the index)
    /// Why it may not target one lobe (then it is tree-wide only); nullptr when it may.
    const char* tree_wide_only;

    /// The settings-table row it sets; nullptr for the seed.
    const SettingInfo* setting() const;
    /// What a Setting event's value must lie in: the setting's range in the table, or for
    /// Species, Seed, Grower, GrowthSteps, LeafColor and BarkColor, [lo, hi] (whole numbers;
    /// a colour packed as pack_color, input/recording.h).
    SettingRange accepts() const;
};

/// The growth steps of the grower `choice` names: its steps parameter (Grower::steps_param),
/// else the grower's default; nullopt for a grower that does not grow in steps.
std::optional<int> growth_steps(const GrowerChoice& choice);
/// What a panel's step button sends (a GrowthSteps Setting event's value): growth_steps
/// moved by `delta`, at least 1 (0 would mean the default again); nullopt as growth_steps.
std::optional<double> growth_steps_after(const GrowerChoice& choice, int delta);

/// Every panel setting, in SettingId order: what the apps' panels show.
const std::vector<PanelControl>& panel_controls();
/// The control of a Setting event's id; nullptr for an id this build does not know.
const PanelControl* find_panel_control(SettingId id);

} // namespace lobe
