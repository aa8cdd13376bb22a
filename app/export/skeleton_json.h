#pragma once
/// \file skeleton_json.h
/// The tree graph as a file (`--skeleton-out tree.json`, docs/growth.md):
///
///   {"nodes": [{"id": 0, "parent": -1, "position": [x, y, z], "radius": r, "lobe": 0}, …]}
///
/// one entry per node of the graph (core/tree.h) in order, `id` its index, `parent` the
/// parent's id (-1 at the root), position and radius in metres in session (stage)
/// coordinates, `lobe` the id of the lobe it grew in (0 for the root, the sketched skeleton and
/// nodes outside every lobe). A node reached without a branch from its parent (an L-system's
/// move without drawing, TreeNodeKind::Detached) also has `"detached": true`. Numbers are
/// written so that they read back to the same floats.

#include <cstdint>
#include <string>
#include <vector>

#include "app/session/tree_pipeline.h"
#include "core/tree.h"

namespace lobe {

/// The JSON text of `tree`; `lobe_ids[i]` is the id of the lobe TreeNode::lobe = i names (an
/// index past its end, or a negative one, is written as 0).
std::string skeleton_json(const TreeGraph& tree, const std::vector<std::int64_t>& lobe_ids);

/// skeleton_json written atomically to `path`. \throw FileError when writing fails.
void write_skeleton_json(const std::string& path, const TreeGraph& tree, const std::vector<std::int64_t>& lobe_ids);

/// A grown tree's graph, its lobes named by their ids (`--skeleton-out` of every command).
void write_skeleton_json(const std::string& path, const BuiltTree& tree);

} // namespace lobe
