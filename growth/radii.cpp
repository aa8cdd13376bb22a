#include "growth/radii.h"

#include <cmath>
#include <vector>

#include "core/errors.h"

namespace lobe {

void assign_pipe_radii(TreeGraph& graph, double exponent, double tip_radius_m)
{
    if (!(exponent >= 1.0) || !(tip_radius_m > 0.0)) throw InvalidInput("pipe model: exponent must be >= 1 and the tip radius > 0");
    const std::size_t n = graph.nodes.size();
    // Σ r^e of each node's subtree, accumulated from the back (children follow parents).
    std::vector<double> pipe(n, 0.0);
    const double tip = std::pow(tip_radius_m, exponent);
    for (std::size_t i = n; i-- > 0;) {
        if (pipe[i] == 0.0) pipe[i] = tip; // no child reported: a tip
        const int p = graph.nodes[i].parent;
        if (p >= 0 && static_cast<std::size_t>(p) < i) pipe[static_cast<std::size_t>(p)] += pipe[i];
    }
    for (std::size_t i = 0; i < n; ++i)
        graph.nodes[i].radius = static_cast<float>(std::pow(pipe[i], 1.0 / exponent));
}

} // namespace lobe
