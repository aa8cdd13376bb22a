#include "growth/radii.h"

#include <cmath>
#include <vector>

#include <glm/geometric.hpp>

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

namespace lobe {

void assign_leader_radii(TreeGraph& graph, double exponent, double tip_radius_m)
{
    if (!(exponent >= 1.0) || !(tip_radius_m > 0.0)) throw InvalidInput("pipe model: exponent must be >= 1 and the tip radius > 0");
    const std::size_t n = graph.nodes.size();
    if (n == 0) return;
    // Pipes of each node's subtree, and each node's leader child, from the back.
    std::vector<double> pipe(n, 0.0), rest(n, 0.0); // rest: length of the axis from the node to its tip
    std::vector<int> leader(n, -1);
    const double tip = std::pow(tip_radius_m, exponent);
    for (std::size_t i = n; i-- > 0;) {
        if (pipe[i] == 0.0) pipe[i] = tip; // no child reported: a tip
        const int p = graph.nodes[i].parent;
        if (p < 0 || static_cast<std::size_t>(p) >= i) continue;
        const auto pp = static_cast<std::size_t>(p);
        pipe[pp] += pipe[i];
        // Children are visited from the last: on a tie the earlier child wins.
        if (leader[pp] < 0 || pipe[i] >= pipe[static_cast<std::size_t>(leader[pp])]) leader[pp] = static_cast<int>(i);
    }
    for (std::size_t i = n; i-- > 0;) {
        if (leader[i] < 0) continue;
        const auto c = static_cast<std::size_t>(leader[i]);
        rest[i] = rest[c] + static_cast<double>(glm::distance(graph.nodes[i].position, graph.nodes[c].position));
    }
    // From the root: a leader continues its parent's axis, tapering linearly to the tip radius
    // over what is left of the axis; any other child starts an axis at its pipe radius.
    std::vector<double> r(n, tip_radius_m);
    for (std::size_t i = 0; i < n; ++i) {
        const int p = graph.nodes[i].parent;
        const double own = std::pow(pipe[i], 1.0 / exponent);
        if (p < 0 || static_cast<std::size_t>(p) >= i) {
            r[i] = own;
        } else {
            const auto pp = static_cast<std::size_t>(p);
            if (leader[pp] == static_cast<int>(i) && rest[pp] > 0.0)
                r[i] = tip_radius_m + (r[pp] - tip_radius_m) * (rest[i] / rest[pp]);
            else if (leader[pp] == static_cast<int>(i))
                r[i] = r[pp];
            else
                r[i] = std::min(own, r[pp]);
        }
        r[i] = std::max(r[i], tip_radius_m);
        graph.nodes[i].radius = static_cast<float>(r[i]);
    }
}

} // namespace lobe
