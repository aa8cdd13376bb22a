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
