#include "growth/species.h"

#include <algorithm>

#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "core/errors.h"
#include "core/settings_json.h"
#include "core/settings_table.h"
#include "growth/embedded_data.h"

namespace lobe {

using nlohmann::json;

namespace {
constexpr std::size_t kMaxSpeciesBytes = 1u << 20;
const std::string kPrefix = "species/";
} // namespace

std::vector<std::string> species_names()
{
    std::vector<std::string> names;
    for (const EmbeddedFile& f : embedded_growth_data())
        if (f.name.rfind(kPrefix, 0) == 0 && f.name.size() > kPrefix.size() + 5)
            names.push_back(f.name.substr(kPrefix.size(), f.name.size() - kPrefix.size() - 5));
    std::sort(names.begin(), names.end());
    return names;
}

SpeciesPreset parse_species(const std::string& text, const std::string& where)
{
    const json j = json::parse(text, nullptr, /*allow_exceptions=*/false);
    if (j.is_discarded()) throw InvalidInput(where + ": not valid JSON");
    // Not j.value("format", …): it throws a json type_error when "format" is not a string.
    const auto format = j.find("format");
    if (!j.is_object() || format == j.end() || !format->is_string() ||
        format->get<std::string>() != "lobesketch-species")
        throw InvalidInput(where + ": not a species preset (missing \"format\": \"lobesketch-species\")");
    if (!j.contains("version") || !j["version"].is_number_integer() || j["version"].get<int>() != 1)
        throw InvalidInput(where + ": unsupported species preset version (this program reads version 1)");
    for (auto it = j.begin(); it != j.end(); ++it) {
        const std::string& k = it.key();
        if (k != "format" && k != "version" && k != "name" && k != "description" && k != "growth" &&
            k != "branches" && k != "leaves")
            throw InvalidInput(where + ": unknown key '" + k + "'");
    }
    SpeciesPreset p;
    if (!j.contains("name") || !j["name"].is_string() || j["name"].get<std::string>().empty() ||
        j["name"].get<std::string>().size() > 64)
        throw InvalidInput(where + ": \"name\" must be a name of 1 to 64 characters");
    p.name = j["name"].get<std::string>();
    if (j.contains("description")) {
        if (!j["description"].is_string()) throw InvalidInput(where + ": \"description\" must be a string");
        p.description = j["description"].get<std::string>();
    }
    const char* const sections[] = {"growth", "branches", "leaves"};
    for (const char* key : sections)
        if (j.contains(key) && !j[key].is_object()) throw InvalidInput(where + ": \"" + key + "\" must be an object");
    if (j.contains("growth") && j["growth"].contains("species"))
        throw InvalidInput(where + ": growth.species is the preset's own name");
    try {
        for (const char* key : sections)
            if (j.contains(key)) read_settings_section(j[key], key, p.settings, key);
    } catch (const InvalidInput& e) {
        throw InvalidInput(where + ": species '" + p.name + "': " + e.what());
    }
    // Every key and type is checked above and every range now, so a bad preset fails when it
    // is read, not when used.
    Settings probe;
    try {
        apply_species(probe, p);
    } catch (const InvalidInput& e) {
        throw InvalidInput(where + ": " + e.what());
    }
    return p;
}

SpeciesPreset load_species(const std::string& name_or_path)
{
    const bool is_file = name_or_path.size() > 5 && name_or_path.compare(name_or_path.size() - 5, 5, ".json") == 0;
    if (is_file) {
        const std::string text = read_file_limited(name_or_path, kMaxSpeciesBytes);
        return parse_species(text, name_or_path);
    }
    for (const EmbeddedFile& f : embedded_growth_data())
        if (f.name == kPrefix + name_or_path + ".json") return parse_species(std::string(f.text), f.name);
    std::string known;
    for (const std::string& n : species_names()) known += (known.empty() ? "" : ", ") + n;
    throw InvalidInput("unknown species '" + name_or_path + "' (known: " + known + ", or a preset .json file)");
}

void apply_species(Settings& settings, const SpeciesPreset& preset)
{
    Settings s = settings;
    preset.settings.apply_to(s);
    s.growth.species = preset.name;
    try {
        for (const char* section : {"growth", "branches", "leaves"}) validate_settings_section(s, section);
    } catch (const InvalidInput& e) {
        throw InvalidInput("species '" + preset.name + "': " + e.what());
    }
    settings = std::move(s);
}

} // namespace lobe
