#pragma once
/// \file settings_table.h
/// The settings table: every setting of core/settings.h once, one table per section, each
/// row its key, the member it lives in, its range or allowed values and a one-line doc.
/// Defaults are the structs' member initializers, read from a default-constructed Settings.
/// The session JSON (settings_json.h), range validation, the CLI (`--set`, `lobesketch
/// settings`), the panels (app/session/panel_controls.h) and the lobe cache key all go
/// through it; docs/settings.md is generated from it.
///
/// Adding a setting: the member with its default in core/settings.h, one row in its
/// section's table in core/settings_table.cpp. Nothing else lists settings.

#include <array>
#include <limits>
#include <map>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "core/settings.h"

namespace lobe {

enum class SettingType {
    Number,  ///< double
    Integer, ///< int (written to JSON as an integer)
    Name,    ///< std::string: one of `choices`, or any name of 1 to 64 characters when there are none
    Color,   ///< double[3]: linear RGB, each component in [0, 1]
    Weights, ///< std::map<std::string, double>: name → weight in [0, 1e6], at most 256 names
};

/// Bounds of a Number or Integer setting. An end may be another setting of the same section
/// (`lo_key`, `hi_key`: its name), e.g. pinch_release_m in (pinch_start_m, 0.2).
struct SettingRange {
    double lo = 0.0, hi = 0.0;
    bool lo_open = false, hi_open = false;
    std::string lo_key, hi_key;

    /// Parses interval notation: "[0.005, 0.5]", "(0, 1000]", "(pinch_start_m, 0.2)".
    static SettingRange parse(std::string_view text);
    /// Interval notation, numbers as number_text writes them: "[0.005, 0.5]".
    std::string text() const;
    /// Whether `v` is finite and lies within, with `lo_value`/`hi_value` standing for the
    /// keyed ends (NaN: that end is not checked).
    bool contains(double v, double lo_value = std::numeric_limits<double>::quiet_NaN(),
                  double hi_value = std::numeric_limits<double>::quiet_NaN()) const;
};

/// One setting.
struct SettingInfo {
    std::string key;     ///< dotted path below "settings": "lobes.edge_length_m", "input.filter.beta"
    std::string section; ///< the key without its last part: "lobes", "input.filter"
    std::string name;    ///< the last part: "edge_length_m"
    SettingType type = SettingType::Number;
    SettingRange range;               ///< Number and Integer
    std::vector<std::string> choices; ///< Name: the values allowed (empty: any name of 1 to 64 characters)
    std::string doc;                  ///< one line

    /// What the setting accepts, in words: "[0.005, 0.5]", "\"ovate\", \"round\" or \"needle\"",
    /// "a name of 1 to 64 characters", "r,g,b each in [0, 1]", "up to 256 name:weight in [0, 1e6]".
    std::string allowed() const;
};

/// The value of one setting, by its type (SettingType order).
using SettingValue = std::variant<double, int, std::string, std::array<double, 3>, std::map<std::string, double>>;

/// Every setting in the order of core/settings.h: input (its two filters first), lobes,
/// growth, branches, leaves.
const std::vector<SettingInfo>& settings_table();
/// Every section, parents before their subsections: "input", "input.filter",
/// "input.gap_filter", "lobes", "growth", "branches", "leaves".
const std::vector<std::string>& settings_sections();
/// The setting of a dotted key ("growth.split_angle_deg"); nullptr for none.
const SettingInfo* find_setting(std::string_view key);

SettingValue get_setting(const Settings& s, const SettingInfo& info);
/// Sets a value of the setting's type (no range check). \throw InvalidInput for another type.
void set_setting(Settings& s, const SettingInfo& info, const SettingValue& value);
/// Copies one setting's value from `from` to `to`.
void copy_setting(const Settings& from, Settings& to, const SettingInfo& info);

/// A number as the table writes it: the shortest decimal that reads back as the same
/// double, without an exponent ("0.005", "5000000").
std::string number_text(double v);
/// A value as text, the form `--set` reads: "0.03", "4", "ovate", "0.2,0.42,0.12",
/// "fork:3,lateral:2" (empty for no weights). Reads back as the same value.
std::string setting_text(const Settings& s, const SettingInfo& info);
/// Parses `text` (the form setting_text writes) into `s` and checks the value against its
/// own range (not against other settings: validate_settings does that).
/// \throw InvalidInput naming `settings.KEY` (one line).
void set_setting_text(Settings& s, const SettingInfo& info, std::string_view text);

/// Checks one setting of `s` against its range or allowed values (ends that are other
/// settings read from `s`). \throw InvalidInput naming `settings.KEY`.
void check_setting(const Settings& s, const SettingInfo& info);
/// Checks every setting of a section and its subsections ("growth"; "input" includes
/// "input.filter"), in table order. \throw InvalidInput naming the first bad setting.
void validate_settings_section(const Settings& s, std::string_view section);
/// Checks every setting, in table order. \throw InvalidInput naming the first bad setting.
void validate_settings(const Settings& s);

/// Whether two settings hold the same values, every setting compared.
bool settings_equal(const Settings& a, const Settings& b);
/// Every setting of a section and its subsections as "key=text" lines (setting_text, exact):
/// equal exactly when the section's settings are equal, so a key of what was built from
/// them. A setting added to the table is in it without more.
std::string settings_key(const Settings& s, std::string_view section);

/// Values of some settings, to lay over others: a species preset's partial sections, the
/// CLI's `--set` list.
struct SettingsOverlay {
    Settings values;               ///< holds the values of the settings in `keys` (the rest unused)
    std::vector<std::string> keys; ///< the settings it sets, each once, in the order first set

    /// Sets `key` from text (set_setting_text). \throw InvalidInput naming the key: an
    /// unknown key, a value of the wrong form or out of its own range.
    void set_text(std::string_view key, std::string_view text);
    /// Records that `values` holds a value for `key` (an existing key).
    void mark(std::string_view key);
    bool empty() const { return keys.empty(); }
    /// Copies the overlaid settings into `s` (no range check).
    void apply_to(Settings& s) const;
};

} // namespace lobe
