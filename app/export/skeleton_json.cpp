#include "app/export/skeleton_json.h"

#include <cstdio>

#include "core/atomic_file.h"

namespace lobe {

namespace {

void append_float(std::string& out, float v)
{
    char buf[32];
    const int n = std::snprintf(buf, sizeof buf, "%.9g", static_cast<double>(v));
    out.append(buf, static_cast<std::size_t>(n));
}

} // namespace

std::string skeleton_json(const TreeGraph& tree, const std::vector<std::int64_t>& lobe_ids)
{
    std::string out;
    out.reserve(32 + tree.nodes.size() * 112);
    out += "{\"nodes\": [";
    for (std::size_t i = 0; i < tree.nodes.size(); ++i) {
        const TreeNode& n = tree.nodes[i];
        const std::int64_t lobe =
            n.lobe >= 0 && static_cast<std::size_t>(n.lobe) < lobe_ids.size() ? lobe_ids[static_cast<std::size_t>(n.lobe)] : 0;
        out += i ? ",\n  " : "\n  ";
        out += "{\"id\": " + std::to_string(i) + ", \"parent\": " + std::to_string(n.parent) + ", \"position\": [";
        append_float(out, n.position.x);
        out += ", ";
        append_float(out, n.position.y);
        out += ", ";
        append_float(out, n.position.z);
        out += "], \"radius\": ";
        append_float(out, n.radius);
        out += ", \"lobe\": " + std::to_string(lobe);
        if (n.kind == TreeNodeKind::Detached) out += ", \"detached\": true";
        out += "}";
    }
    out += tree.nodes.empty() ? "]}\n" : "\n]}\n";
    return out;
}

void write_skeleton_json(const std::string& path, const TreeGraph& tree, const std::vector<std::int64_t>& lobe_ids)
{
    write_file_atomic(path, skeleton_json(tree, lobe_ids));
}

void write_skeleton_json(const std::string& path, const BuiltTree& tree)
{
    std::vector<std::int64_t> ids;
    for (const BuiltLobe& l : tree.lobes) ids.push_back(l.lobe_id);
    write_skeleton_json(path, tree.growth.tree, ids);
}

} // namespace lobe
