#include "growth/wood.h"

#include <cmath>
#include <numbers>
#include <string>

#include <glm/geometric.hpp>

#include "core/errors.h"

namespace lobe {

double wood_volume_m3(const TreeGraph& graph)
{
    double v = 0.0;
    for (std::size_t i = 1; i < graph.nodes.size(); ++i) {
        const TreeNode& n = graph.nodes[i];
        if (n.parent < 0 || static_cast<std::size_t>(n.parent) >= i) continue;
        const TreeNode& p = graph.nodes[static_cast<std::size_t>(n.parent)];
        const double len = glm::length(glm::dvec3(n.position) - glm::dvec3(p.position));
        const double r1 = p.radius, r2 = n.radius;
        const double part = std::numbers::pi * len / 3.0 * (r1 * r1 + r1 * r2 + r2 * r2);
        if (std::isfinite(part)) v += part;
    }
    return v;
}

double basic_wood_density(std::string_view species)
{
    // Specific gravity at green volume × 1000 kg/m³: docs/wood-and-co2.md.
    if (species == "conifer") return 340.0; // eastern white pine
    if (species == "birch") return 480.0;   // paper birch
    if (species == "willow") return 360.0;  // black willow
    return 600.0;                           // broadleaf: white oak
}

WoodEstimate estimate_wood(const TreeGraph& graph, double density_kg_m3, double scale)
{
    if (!(density_kg_m3 > 0.0) || !std::isfinite(density_kg_m3))
        throw InvalidInput("wood density " + std::to_string(density_kg_m3) + " kg/m³ is not a positive number");
    if (!(scale > 0.0) || !std::isfinite(scale))
        throw InvalidInput("scale " + std::to_string(scale) + " is not a positive number");
    WoodEstimate e;
    e.density_kg_m3 = density_kg_m3;
    e.wood_volume_m3 = wood_volume_m3(graph) * scale * scale * scale;
    e.dry_biomass_kg = e.wood_volume_m3 * density_kg_m3;
    e.carbon_kg = e.dry_biomass_kg * kCarbonFraction;
    e.co2_kg = e.carbon_kg * kCo2PerCarbon;
    return e;
}

} // namespace lobe
