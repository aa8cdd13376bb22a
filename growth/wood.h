#pragma once
/// \file wood.h
/// How much wood, carbon and CO₂ a grown tree holds: the wood volume is the sum of the
/// internode frusta (each node to its parent, radii from the pipe model, growth/radii.h);
/// dry biomass = volume × basic wood density; carbon = 50 % of dry biomass; CO₂ = carbon ×
/// 44/12 (the molar masses of CO₂ and C). Sources of the constants: docs/wood-and-co2.md.

#include <string_view>

#include "core/tree.h"

namespace lobe {

/// Carbon as a fraction of dry woody biomass.
inline constexpr double kCarbonFraction = 0.5;
/// kg of CO₂ per kg of carbon: 44/12.
inline constexpr double kCo2PerCarbon = 44.0 / 12.0;

struct WoodEstimate {
    double wood_volume_m3 = 0.0;
    double dry_biomass_kg = 0.0;
    double carbon_kg = 0.0;
    double co2_kg = 0.0;
    double density_kg_m3 = 0.0; ///< basic density used (dry mass per green volume)
};

/// Sum over non-root nodes of the frustum to the parent: π·L/3·(r₁² + r₁r₂ + r₂²), m³.
/// Nodes with a non-finite position or radius count 0. \pre parents precede children.
double wood_volume_m3(const TreeGraph& graph);

/// Basic wood density (kg/m³) of a species preset: broadleaf (oak), conifer (pine), birch,
/// willow; any other name gets broadleaf's.
double basic_wood_density(std::string_view species);

/// The estimate for `graph` scaled uniformly by `scale` (volume × scale³; 1: as grown).
/// \throw InvalidInput when density_kg_m3 or scale is not a positive finite number.
WoodEstimate estimate_wood(const TreeGraph& graph, double density_kg_m3, double scale = 1.0);

} // namespace lobe
