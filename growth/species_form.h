#pragma once
/// \file species_form.h
/// What a species changes in a tree's branching besides its leaves (docs/growth.md, "Species
/// form"): an excurrent leader for the default trunk (GrowthSettings::leader, whorl_spacing),
/// and laterals that droop or hang (GrowthSettings::droop, hang), applied to the grown graph.
/// Also the measures that tell species apart (branch angles, tip elevations, trunk diameter).

#include <cstddef>
#include <vector>

#include <glm/vec3.hpp>

#include "core/settings.h"
#include "core/tree.h"

namespace lobe {

/// The default trunk's leader: points from `from` (the top of the default trunk, below the
/// crown) straight up to 95 % of the way from `crown_bottom_y` to `crown_top_y`, `from`
/// itself left out. Spaced whorl_spacing × the crown's height apart when whorl_spacing > 0,
/// else `spacing_m`. Empty when the crown's top is not above `from`.
std::vector<glm::vec3> default_leader_points(const glm::vec3& from, float crown_bottom_y, float crown_top_y,
                                             double whorl_spacing, double spacing_m);

/// Bends every lateral of `graph` by settings.droop and settings.hang (no-op when both are 0).
/// A lateral is everything grown from one skeleton node; along it, t is the path length from
/// that node over the lateral's longest path. Each grown segment keeps its length and
/// azimuth; its elevation e (radians, −π/2 … π/2) becomes e − w·(e + π/2) with
/// w = 1 − (1 − droop·t)(1 − hang·clamp(1.5·(t − 1/3), 0, 1)); positions follow from the
/// root outwards. Skeleton nodes (index < skeleton_nodes) do not move.
/// \pre parents precede children (TreeGraph).
void apply_species_form(TreeGraph& graph, std::size_t skeleton_nodes, const GrowthSettings& settings);

/// Measures of a tree's form, for comparing species (tests, docs/growth.md).
struct TreeFormStats {
    /// Branching angles (degrees): at every node with two or more children, the angle between
    /// each child's segment and the segment into the node; sorted.
    std::vector<double> branch_angles_deg;
    /// Elevation (degrees, −90 … 90) of the last segment of every grown tip; sorted.
    std::vector<double> tip_elevations_deg;
    /// Share of grown tips whose last segment points below the horizontal.
    double drooping_tip_share = 0.0;
    double height_m = 0.0; ///< highest node above the root
    /// Trunk diameter at breast height (1.3 m above the root, or 16 % of the height when the
    /// tree is lower than 8 m: 1.3/8 of its height), along the trunk (from the root, always the thickest child).
    double dbh_m = 0.0;
};
TreeFormStats tree_form_stats(const TreeGraph& graph);
/// TreeFormStats::dbh_m alone; `children` is tree_children(graph).
double trunk_dbh(const TreeGraph& graph, const std::vector<std::vector<int>>& children);

/// The value at quantile q ∈ [0, 1] of a sorted list (nearest rank); 0 for an empty list.
double quantile(const std::vector<double>& sorted, double q);

} // namespace lobe
