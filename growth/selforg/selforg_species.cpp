#include "growth/selforg/selforg_species.h"

#include <array>
#include <cmath>

#include "core/errors.h"

namespace lobe {

namespace {

// Values and their sources: docs/self-organizing.md, "Species presets".
SelfOrgSpecies broadleaf()
{
    SelfOrgSpecies s;
    s.name = "broadleaf";
    return s;
}

SelfOrgSpecies conifer()
{
    SelfOrgSpecies s;
    s.name = "conifer";
    s.lambda = 0.56;           // strong apical control: an excurrent stem
    s.branch_angle_deg = 75.0; // near-horizontal whorls
    s.xi = 0.1;
    s.eta = 0.6;
    s.shed_threshold = 0.3;
    s.crown_radius = 22.0;
    s.crown_centre_height = 50.0;
    return s;
}

SelfOrgSpecies birch()
{
    SelfOrgSpecies s;
    s.name = "birch";
    s.lambda = 0.48; // weak apical control: a rounded, decurrent crown
    s.branch_angle_deg = 35.0;
    s.eta = 0.35;
    s.shed_threshold = 0.2;
    s.crown_radius = 26.0;
    return s;
}

SelfOrgSpecies willow()
{
    SelfOrgSpecies s;
    s.name = "willow";
    s.lambda = 0.46;
    s.branch_angle_deg = 50.0;
    s.tropism = glm::vec3(0.0f, -1.0f, 0.0f); // positive gravitropism: weeping shoots
    s.eta = 0.25;
    s.xi = 0.3;
    s.shed_threshold = 0.2;
    s.crown_radius = 32.0;
    s.crown_centre_height = 40.0;
    return s;
}

const std::array<SelfOrgSpecies, 4>& presets()
{
    static const std::array<SelfOrgSpecies, 4> all{broadleaf(), conifer(), birch(), willow()};
    return all;
}

void check_range(double v, double lo, double hi, const std::string& where, const char* field)
{
    if (!(std::isfinite(v) && v >= lo && v <= hi))
        throw InvalidInput(where + "." + field + ": " + std::to_string(v) + " is outside [" + std::to_string(lo) + ", " +
                           std::to_string(hi) + "]");
}

} // namespace

const SelfOrgSpecies& selforg_species(std::string_view name)
{
    for (const SelfOrgSpecies& s : presets())
        if (s.name == name) return s;
    throw InvalidInput("unknown self-organizing species \"" + std::string(name) + "\" (known: " +
                       selforg_species_names() + ")");
}

std::vector<std::string> selforg_species_list()
{
    std::vector<std::string> out;
    for (const SelfOrgSpecies& s : presets()) out.push_back(s.name);
    return out;
}

std::string selforg_species_names()
{
    const std::vector<std::string> names = selforg_species_list();
    std::string out;
    for (std::size_t i = 0; i < names.size(); ++i) {
        if (i > 0) out += i + 1 == names.size() ? " and " : ", ";
        out += names[i];
    }
    return out;
}

void check_selforg_species(const SelfOrgSpecies& s, const std::string& where)
{
    check_range(s.occupancy_radius, 0.1, 10.0, where, "occupancy_radius");
    check_range(s.perception_radius, s.occupancy_radius, 20.0, where, "perception_radius");
    check_range(s.perception_angle_deg, 1.0, 360.0, where, "perception_angle_deg");
    check_range(s.marker_spacing, 0.25, 10.0, where, "marker_spacing");
    check_range(s.shadow_a, 0.0, 10.0, where, "shadow_a");
    check_range(s.shadow_b, 1.0, 10.0, where, "shadow_b");
    check_range(s.shadow_q_max, 0, 18, where, "shadow_q_max");
    check_range(s.light_c, 0.01, 100.0, where, "light_c");
    check_range(s.alpha, 0.0, 100.0, where, "alpha");
    check_range(s.lambda, 0.0, 1.0, where, "lambda");
    check_range(s.priority_w_min, 0.0, 1.0, where, "priority_w_min");
    check_range(s.priority_w_max, s.priority_w_min, 1.0, where, "priority_w_max");
    check_range(s.priority_kappa, 0.0, 1.0, where, "priority_kappa");
    check_range(s.max_shoot_metamers, 1, 64, where, "max_shoot_metamers");
    check_range(s.xi, 0.0, 100.0, where, "xi");
    check_range(s.eta, -100.0, 100.0, where, "eta");
    check_range(s.branch_angle_deg, 0.0, 180.0, where, "branch_angle_deg");
    check_range(s.phyllotaxis_deg, 0.0, 360.0, where, "phyllotaxis_deg");
    check_range(s.jitter, 0.0, 1.0, where, "jitter");
    check_range(s.shed_threshold, 0.0, 100.0, where, "shed_threshold");
    check_range(s.shed_min_internodes, 1, 1000000, where, "shed_min_internodes");
    check_range(s.iterations, 1, 1000, where, "iterations");
    check_range(s.internode_m, 1e-4, 10.0, where, "internode_m");
    check_range(s.crown_radius, 1.0, 1000.0, where, "crown_radius");
    check_range(s.crown_centre_height, 0.0, 2000.0, where, "crown_centre_height");
    const double t2 = static_cast<double>(s.tropism.x) * s.tropism.x + static_cast<double>(s.tropism.y) * s.tropism.y +
                      static_cast<double>(s.tropism.z) * s.tropism.z;
    if (!(std::abs(t2 - 1.0) < 1e-3)) throw InvalidInput(where + ".tropism: must be a unit vector");
}

} // namespace lobe
