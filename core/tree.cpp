#include "core/tree.h"

namespace lobe {

std::vector<std::vector<int>> tree_children(const TreeGraph& graph)
{
    std::vector<std::vector<int>> children(graph.nodes.size());
    for (std::size_t i = 1; i < graph.nodes.size(); ++i) {
        const int p = graph.nodes[i].parent;
        if (p >= 0 && static_cast<std::size_t>(p) < i) children[static_cast<std::size_t>(p)].push_back(static_cast<int>(i));
    }
    return children;
}

} // namespace lobe
