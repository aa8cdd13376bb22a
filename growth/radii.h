#pragma once
/// \file radii.h
/// Branch radii by the pipe model (Shinozaki et al. 1964; Macdonald 1983): every tip has
/// the tip radius and a parent's radius r satisfies r^e = Σ r_child^e, accumulated from the
/// tips to the root in one backward pass.

#include "core/settings.h"
#include "core/tree.h"

namespace lobe {

/// Sets TreeNode::radius of every node of `graph`. Radii never increase from the root to a
/// tip. \pre the graph's parents precede their children (TreeGraph).
/// \throw InvalidInput when exponent < 1 or tip_radius_m <= 0.
void assign_pipe_radii(TreeGraph& graph, double exponent = BranchSettings{}.pipe_exponent,
                       double tip_radius_m = BranchSettings{}.tip_radius_m);

} // namespace lobe

namespace lobe {

/// Radii by the pipe model with a leader (the subtree grower's, docs/growth.md "Radii"): at
/// each branching the child carrying the most pipes (Σ r_tip^e of its subtree; ties to the
/// earlier child) is the leader and continues the node's axis. An axis (a chain of leaders
/// from where it starts to its tip) tapers linearly in arc length from its first radius to the
/// tip radius, so it never steps; a child that is not a leader starts its own axis at its pipe
/// radius (r^e = Σ r_tip^e), at most its parent's. The root's axis starts at the root's pipe
/// radius. Radii never increase from the root to a tip; tips have the tip radius.
/// \pre the graph's parents precede their children (TreeGraph).
/// \throw InvalidInput when exponent < 1 or tip_radius_m <= 0.
void assign_leader_radii(TreeGraph& graph, double exponent = BranchSettings{}.pipe_exponent,
                         double tip_radius_m = BranchSettings{}.tip_radius_m);

} // namespace lobe
