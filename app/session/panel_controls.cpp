#include "app/session/panel_controls.h"

#include <algorithm>
#include <variant>

#include "core/errors.h"

#include "growth/grower.h"

namespace lobe {

namespace {

int highest_panel_code()
{
    int code = 0;
    for (const Grower* g : growers()) code = std::max(code, g->panel_code());
    return code;
}

} // namespace

const std::vector<PanelControl>& panel_controls()
{
    static const std::vector<PanelControl> controls = {
        {SettingId::SplitAngle, "growth.split_angle_deg", "split t", 5.0, 90.0, 5.0, nullptr},
        {SettingId::AttractorSpacing, "lobes.edge_length_m", "spacing", 0.01, 0.10, 0.001,
         "every lobe carries the same attractor density"},
        {SettingId::LeafLength, "leaves.length_m", "leaf size", 0.01, 0.20, 0.001, nullptr},
        {SettingId::LeavesPerNode, "leaves.per_node", "leaves", 0.0, 16.0, 1.0, nullptr},
        {SettingId::Species, "growth.species", "species", 0.0, kSettingSpeciesCount - 1.0, 1.0, nullptr},
        {SettingId::Seed, "seed", "seed", 1.0, 16777215.0, 1.0, nullptr},
        {SettingId::Grower, "grower", "grower", 0.0, double(highest_panel_code()), 1.0,
         "the scene's tree grows with one grower"},
        // The most any grower takes (lsystem's kMaxDerivationLength); each grower's
        // check_params says what it takes.
        {SettingId::GrowthSteps, "growth-steps", "step", 0.0, 100000.0, 1.0,
         "the scene's tree grows with one grower"},
        // Appearance of the whole tree: leaf width and colours, and the radii (pipe model).
        {SettingId::LeafWidth, "leaves.width_m", "leaf width", 0.002, 0.10, 0.001, "one leaf shape for the tree"},
        {SettingId::LeafColor, "leaves.color", "leaf colour", 0.0, 16777215.0, 1.0, "one leaf colour for the tree"},
        {SettingId::BarkColor, "branches.bark_color", "bark colour", 0.0, 16777215.0, 1.0, "one bark for the tree"},
        {SettingId::PipeExponent, "branches.pipe_exponent", "pipe exponent", 1.5, 3.5, 0.1,
         "one radius model for the tree"},
        {SettingId::TipRadius, "branches.tip_radius_m", "twig radius", 0.0003, 0.005, 0.0001,
         "one radius model for the tree"},
    };
    return controls;
}

const PanelControl* find_panel_control(SettingId id)
{
    for (const PanelControl& c : panel_controls())
        if (c.id == id) return &c;
    return nullptr;
}

std::optional<int> growth_steps(const GrowerChoice& choice)
{
    const Grower* g = find_grower(choice.name);
    if (!g || g->steps_param().empty()) return std::nullopt;
    if (const auto it = choice.params.find(std::string(g->steps_param())); it != choice.params.end())
        if (const auto* n = std::get_if<std::int64_t>(&it->second)) return static_cast<int>(*n);
    try {
        return g->default_steps(choice);
    } catch (const Error&) {
        return 0;
    }
}

std::optional<double> growth_steps_after(const GrowerChoice& choice, int delta)
{
    const std::optional<int> now = growth_steps(choice);
    if (!now) return std::nullopt;
    // 1 at least: 0 would be the grower's default again.
    return double(std::clamp(*now + delta, 1, int(find_panel_control(SettingId::GrowthSteps)->hi)));
}

const SettingInfo* PanelControl::setting() const { return find_setting(key); }

SettingRange PanelControl::accepts() const
{
    const SettingInfo* info = setting();
    if (info && (info->type == SettingType::Number || info->type == SettingType::Integer)) return info->range;
    SettingRange r;
    r.lo = lo;
    r.hi = hi;
    return r;
}

} // namespace lobe
