#include "growth/lsystem/presets.h"

#include <algorithm>
#include <system_error>

#include "core/errors.h"
#include "growth/embedded_data.h"

namespace lobe::lsystem {
namespace {

constexpr std::string_view kDir = "lsystems/";

bool ends_with(std::string_view s, std::string_view suffix)
{
    return s.size() >= suffix.size() && s.substr(s.size() - suffix.size()) == suffix;
}

std::vector<Preset> collect_presets()
{
    std::vector<Preset> out;
    for (const EmbeddedFile& f : embedded_growth_data()) {
        const std::string_view name = f.name;
        if (name.substr(0, kDir.size()) != kDir || !ends_with(name, ".l")) continue;
        Preset p;
        p.name = std::string(name.substr(kDir.size(), name.size() - kDir.size() - 2));
        p.lsystem = f.text;
        const std::string view_name = std::string(kDir) + p.name + ".v";
        for (const EmbeddedFile& v : embedded_growth_data())
            if (v.name == view_name) p.view = v.text;
        out.push_back(std::move(p));
    }
    std::sort(out.begin(), out.end(), [](const Preset& a, const Preset& b) { return a.name < b.name; });
    return out;
}

std::string preset_list()
{
    std::string names;
    for (const Preset& p : presets()) {
        if (!names.empty()) names += ", ";
        names += p.name;
    }
    return names;
}

} // namespace

const std::vector<Preset>& presets()
{
    static const std::vector<Preset> all = collect_presets();
    return all;
}

const Preset* find_preset(std::string_view name)
{
    for (const Preset& p : presets())
        if (p.name == name) return &p;
    return nullptr;
}

LSystemFile load_preset(std::string_view name)
{
    const Preset* p = find_preset(name);
    if (!p) throw InvalidInput("no L-system preset named '" + std::string(name) + "' (presets: " + preset_list() + ")");
    LSystemFile file;
    file.system = parse_lsystem(p->lsystem, p->name + ".l", &file.warnings);
    if (!p->view.empty()) {
        file.view = parse_view(p->view, p->name + ".v", &file.warnings);
        file.has_view = true;
    }
    return file;
}

LSystemFile load_lsystem_or_preset(const std::filesystem::path& file_or_preset)
{
    std::error_code ec;
    if (std::filesystem::exists(file_or_preset, ec)) return load_lsystem_file(file_or_preset);
    const std::string name = file_or_preset.string();
    if (find_preset(name)) return load_preset(name);
    throw FileError(name, "no such file, and no L-system preset of that name (presets: " + preset_list() + ")");
}

} // namespace lobe::lsystem
