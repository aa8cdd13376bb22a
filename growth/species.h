#pragma once
/// \file species.h
/// Species presets: settings files that overlay the growth, branch and leaf settings so that
/// one choice gives a visibly different tree (broadleaf, conifer, willow, birch ship in
/// growth/data/species/; format in docs/growth.md).

#include <string>
#include <vector>

#include "core/settings.h"
#include "core/settings_table.h"

namespace lobe {

struct SpeciesPreset {
    std::string name;
    std::string description;
    /// Its partial growth, branches and leaves sections, read through the settings table
    /// (every key and type checked when the preset is parsed; ranges when it is applied).
    SettingsOverlay settings;
};

/// Names of the presets compiled into the program, sorted.
std::vector<std::string> species_names();
/// Parses a preset file's text; checks every key and type against the settings it overlays.
/// \throw InvalidInput with a one-line reason naming `where`.
SpeciesPreset parse_species(const std::string& text, const std::string& where);
/// A shipped preset by name, or a preset file when `name_or_path` ends in ".json".
/// \throw InvalidInput (unknown name, listing the known ones) or FileError (unreadable file).
SpeciesPreset load_species(const std::string& name_or_path);
/// Overlays `preset` on `settings` (its settings; growth.species = its name) and range-checks
/// the growth, branches and leaves sections. Strong guarantee: on a throw `settings` is unchanged.
/// \throw InvalidInput
void apply_species(Settings& settings, const SpeciesPreset& preset);

} // namespace lobe
