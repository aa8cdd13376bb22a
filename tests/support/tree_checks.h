#pragma once
// Measures of a grown tree against its lobes, as issue #37 states them: how much of the lobe
// surface a branch tip comes near, how much grown branch length leaves the lobes, and how the
// radii taper (docs/growth.md, "Checks").
#include <vector>

#include "core/mesh.h"
#include "core/tree.h"

namespace lobe::test {

/// Share of the lobes' vertices with a branch tip (a node without children) within `within_m`.
double tip_reach_share(const TreeGraph& tree, const std::vector<TriangleMesh>& lobes, double within_m = 0.04);
/// Share of grown branch length (TreeNodeKind::Grown segments, by midpoint) outside every lobe.
double outside_share(const TreeGraph& tree, const std::vector<TriangleMesh>& lobes);
/// Share of the nodes with children whose thickest child is at least `ratio` × their radius.
double leader_share(const TreeGraph& tree, double ratio = 0.5);
/// True when no node is thicker than its parent and every radius is finite and > 0.
bool radii_non_increasing(const TreeGraph& tree);

} // namespace lobe::test
