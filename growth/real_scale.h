#pragma once
/// \file real_scale.h
/// Real scale (docs/export.md, "Size"): a tree sketched at arm's length scaled to its
/// real height while its leaves, leaf spacing and twig radii keep their sizes in metres,
/// which the species gives.

#include <cstddef>
#include <vector>

#include <glm/vec3.hpp>

#include "core/settings.h"
#include "core/tree.h"
#include "growth/leaves.h"

namespace lobe {

/// Height of the highest node of `graph` above its root (nodes[0]); 0 for an empty graph.
double graph_height(const TreeGraph& graph);

/// Scales every node's position about the root by `factor` (> 0, finite); radii unchanged.
void scale_tree_structure(TreeGraph& graph, double factor);

/// Leaves along the shoots (LeafSettings::spacing_m): each tip whose shoot (the segment to
/// its parent, length L) is longer than its leaf count k × spacing_m gets n = min(64, ⌊L /
/// spacing_m⌋) leaves instead of k, leaf j at the distance L·j/n back from the tip along the
/// shoot, its orientation that of the tip's leaf j mod k turned about the shoot by j golden
/// angles (no new random draws, so every other tip is unchanged). Other tips are left as
/// they are; no-op when spacing_m is 0.
void spread_leaves_along_shoots(LeafCloud& cloud, const TreeGraph& graph, const LeafSettings& leaves);

/// Pipe-model radii (growth/radii.h: assign_leader_radii when `leader`, else
/// assign_pipe_radii) with tip radius `tip_radius_m` and the exponent in [1, 4] that brings
/// the trunk's diameter at breast height (trunk_dbh) closest to `dbh_ratio` × graph_height
/// (bisection, 40 steps: the diameter falls as the exponent grows). Returns the exponent.
/// \pre dbh_ratio > 0, tip_radius_m > 0.
double fit_pipe_exponent(TreeGraph& graph, double tip_radius_m, double dbh_ratio, bool leader);

/// How many leaves the tips of `graph` carry with `most` leaves per tip, spread as
/// spread_leaves_along_shoots would (an upper bound for the triangle estimate).
double spread_leaf_count(const TreeGraph& graph, const LeafSettings& leaves, int most);

} // namespace lobe
