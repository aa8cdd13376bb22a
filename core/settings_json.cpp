#include "core/settings_json.h"

#include <cmath>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/errors.h"
#include "core/settings_table.h"

namespace lobe {

using nlohmann::json;

namespace {

json value_json(const SettingValue& v)
{
    return std::visit(
        [](const auto& x) -> json {
            using T = std::decay_t<decltype(x)>;
            if constexpr (std::is_same_v<T, std::array<double, 3>>) {
                return json::array({x[0], x[1], x[2]});
            } else if constexpr (std::is_same_v<T, std::map<std::string, double>>) {
                json weights = json::object();
                for (const auto& [name, w] : x) weights[name] = w;
                return weights;
            } else {
                return json(x);
            }
        },
        v);
}

/// A JSON number that is finite. \throw InvalidInput naming `w`
double finite_number(const json& v, const std::string& w)
{
    if (!v.is_number()) throw InvalidInput(w + ": expected a number");
    const double d = v.get<double>();
    if (!std::isfinite(d)) throw InvalidInput(w + ": not a finite number");
    return d;
}

/// One setting's JSON value, of its type; `w` is `where.KEY`.
SettingValue read_value(const json& v, const SettingInfo& info, const std::string& w)
{
    switch (info.type) {
    case SettingType::Number: return finite_number(v, w);
    case SettingType::Integer: {
        const double d = finite_number(v, w);
        // Casting an out-of-range double to an integer is undefined: refuse it first.
        if (d != std::floor(d) || d < -1e9 || d > 1e9) throw InvalidInput(w + ": expected an integer in [-1e9, 1e9]");
        return static_cast<int>(d);
    }
    case SettingType::Name:
        if (!v.is_string()) throw InvalidInput(w + ": expected a string");
        return v.get<std::string>();
    case SettingType::Color: {
        if (!v.is_array() || v.size() != 3) throw InvalidInput(w + ": expected [r, g, b]");
        std::array<double, 3> c{};
        for (std::size_t i = 0; i < 3; ++i) {
            if (!v[i].is_number()) throw InvalidInput(w + ": expected [r, g, b] numbers");
            c[i] = v[i].get<double>();
            if (!(c[i] >= 0.0 && c[i] <= 1.0)) throw InvalidInput(w + ": components must be in [0, 1]");
        }
        return c;
    }
    case SettingType::Weights: {
        if (!v.is_object()) throw InvalidInput(w + ": expected an object of name: weight");
        if (v.size() > 256) throw InvalidInput(w + ": too many entries");
        std::map<std::string, double> weights;
        for (auto e = v.begin(); e != v.end(); ++e) {
            if (!e->is_number()) throw InvalidInput(w + "." + e.key() + ": expected a number");
            const double d = e->get<double>();
            if (!(d >= 0.0 && d <= 1e6)) throw InvalidInput(w + "." + e.key() + ": must be in [0, 1e6]");
            weights[e.key()] = d;
        }
        return weights;
    }
    }
    return {};
}

std::string child(std::string_view section, const std::string& key)
{
    return section.empty() ? key : std::string(section) + "." + key;
}

bool is_section(const std::string& path)
{
    for (const std::string& s : settings_sections())
        if (s == path) return true;
    return false;
}

/// The subsections directly below `section` ("" is the settings object itself).
std::vector<std::string> subsections(std::string_view section)
{
    std::vector<std::string> out;
    for (const std::string& s : settings_sections()) {
        const std::size_t dot = s.rfind('.');
        if (section.empty() ? dot == std::string::npos : dot == section.size() && s.compare(0, dot, section) == 0)
            out.push_back(s);
    }
    return out;
}

/// Reads the object `obj` of `section` ("" for the settings object): unknown keys first,
/// then its subsections, then its own settings in table order.
void read_section(const json& obj, std::string_view section, Settings& out, const std::string& where,
                  std::vector<std::string>* read)
{
    for (auto it = obj.begin(); it != obj.end(); ++it) {
        const std::string path = child(section, it.key());
        if (!find_setting(path) && !is_section(path)) throw InvalidInput(where + ": unknown key '" + it.key() + "'");
    }
    for (const std::string& sub : subsections(section)) {
        const std::string name = sub.substr(section.empty() ? 0 : section.size() + 1);
        const auto it = obj.find(name);
        if (it == obj.end()) continue;
        const std::string w = where + "." + name;
        if (!it->is_object()) throw InvalidInput(w + ": expected an object");
        read_section(*it, sub, out, w, read);
    }
    for (const SettingInfo& info : settings_table()) {
        if (info.section != section) continue;
        const auto it = obj.find(info.name);
        if (it == obj.end()) continue; // missing keys keep their values
        set_setting(out, info, read_value(*it, info, where + "." + info.name));
        if (read) read->push_back(info.key);
    }
}

} // namespace

json settings_json(const Settings& s)
{
    json out = json::object();
    for (const SettingInfo& info : settings_table()) {
        json* section = &out;
        for (std::size_t from = 0;;) {
            const std::size_t dot = info.section.find('.', from);
            section = &(*section)[info.section.substr(from, dot == std::string::npos ? dot : dot - from)];
            if (dot == std::string::npos) break;
            from = dot + 1;
        }
        (*section)[info.name] = value_json(get_setting(s, info));
    }
    return out;
}

Settings settings_from_json(const json& j)
{
    if (!j.is_object()) throw InvalidInput("settings: expected an object");
    Settings s;
    read_section(j, "", s, "settings", nullptr);
    validate_settings(s);
    return s;
}

void read_settings_section(const json& j, std::string_view section, SettingsOverlay& overlay, const std::string& where)
{
    if (!j.is_object()) throw InvalidInput(where + ": expected an object");
    std::vector<std::string> read;
    read_section(j, section, overlay.values, where, &read);
    for (const std::string& key : read) overlay.mark(key);
}

} // namespace lobe
