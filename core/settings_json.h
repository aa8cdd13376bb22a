#pragma once
/// \file settings_json.h
/// Settings to and from JSON (the "settings" object of session documents and settings
/// files, the sections of species presets), through the settings table (settings_table.h):
/// every key, type and range comes from there. Only the files that read or write settings
/// as JSON include this; it declares nlohmann::json without defining it.

#include <string>
#include <string_view>

#include <nlohmann/json_fwd.hpp>

#include "core/settings.h"

namespace lobe {

struct SettingsOverlay;

/// The settings object of a session document: one object per section ("input" holding
/// "filter" and "gap_filter"), every setting written, integers as JSON integers.
nlohmann::json settings_json(const Settings& s);

/// Reads a settings object over the defaults: every key optional, unknown keys and values
/// of the wrong type refused, then every setting range-checked (validate_settings).
/// \throw InvalidInput naming `settings.SECTION.KEY` (one line).
Settings settings_from_json(const nlohmann::json& j);

/// Reads one section's object (e.g. a species preset's partial "growth") into
/// `overlay.values`, marking each key read. Unknown keys and wrong types are refused, naming
/// `where.KEY`; ranges are not checked (validate_settings_section).
/// \throw InvalidInput
void read_settings_section(const nlohmann::json& j, std::string_view section, SettingsOverlay& overlay,
                           const std::string& where);

} // namespace lobe
