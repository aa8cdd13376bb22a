#pragma once
/// \file tree_pipeline.h
/// From a session document to a tree: its lobes (meshing/lobe_document.h), the trunk
/// strokes as drawn and edited, growth inside the lobes with per-lobe overrides
/// (growth/grow.h), pipe-model radii (growth/radii.h). Shared by `replay`, `grow`, `export`
/// and the interactive apps, which run it off the thread that draws.

#include <string>
#include <vector>

#include "core/document.h"
#include "growth/grow.h"
#include "meshing/lobe_document.h"

namespace lobe {

struct BuiltTree {
    std::vector<BuiltLobe> lobes;      ///< as grown in, stage space
    GrowthResult growth;               ///< tree graph with radii assigned
    std::vector<std::string> warnings; ///< one line each: lobe and growth messages
};

/// The growth inputs of built lobes: each lobe's mesh, its id, and its effective split angle
/// and subtree weights (the lobe's `split_angle_deg` / `species` overrides, else the tree's).
/// \throw InvalidInput for an unknown species or subtree name.
std::vector<GrowthLobe> growth_lobes(const Document& doc, const std::vector<BuiltLobe>& lobes);

/// Grows the document's tree in `lobes` (already built) from its trunk strokes.
BuiltTree grow_document_tree(const Document& doc, std::vector<BuiltLobe> lobes);

/// Builds the document's lobes, then grows its tree in them.
BuiltTree build_document_tree(const Document& doc);

} // namespace lobe
