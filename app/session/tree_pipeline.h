#pragma once
/// \file tree_pipeline.h
/// From a session document to a tree: its lobes (app/session/lobe_document.h), the trunk
/// strokes as drawn and edited, the tree grown by the document's grower (growth/grower.h:
/// scene_grower, the paper's subtree growth by default) with per-lobe overrides, pipe-model
/// radii (growth/radii.h). Shared by `replay`, `grow`, `export`
/// and the interactive apps, which run it off the thread that draws.

#include <string>
#include <vector>

#include "core/document.h"
#include "growth/grow.h"
#include "growth/grower.h"
#include "app/session/lobe_document.h"

namespace lobe {

struct BuiltTree {
    std::vector<BuiltLobe> lobes;      ///< as grown in, stage space
    GrowthResult growth;               ///< tree graph with radii assigned
    std::vector<std::string> warnings; ///< one line each: lobe and growth messages
    /// How much apply_real_scale scaled the tree's structure (and its lobes) about its root:
    /// 1 when it is the size it was sketched at.
    double scale = 1.0;
};

/// The growth inputs of built lobes: each lobe's mesh, its id, and its effective split angle
/// and subtree weights (the lobe's `split_angle_deg` / `species` overrides, else the tree's).
/// \throw InvalidInput for an unknown species or subtree name.
std::vector<GrowthLobe> growth_lobes(const Document& doc, const std::vector<BuiltLobe>& lobes);

/// What the document's grower is given (growth/grower.h): the trunk strokes as drawn and
/// edited, growth_lobes of `lobes`, the settings, the seed and the grower choice (not checked).
/// \throw InvalidInput as growth_lobes.
GrowerInput document_grower_input(const Document& doc, const std::vector<BuiltLobe>& lobes);

/// After the grower: pipe-model radii (growth/radii.h) unless the grower set its own
/// (GrowthResult::radii_set), and the growth messages as warnings ("growth: …").
void finish_grown_tree(const Document& doc, BuiltTree& tree);

/// Real scale (docs/export.md, "Size"): when settings.growth.height_m > 0, scales the tree's
/// nodes and its lobes about the root so the highest node lies height_m above it, and sets
/// the radii again (the pipe model's twigs keep tip_radius_m). A grower that set its own radii
/// and leaves (an L-system) has them scaled with it. Sets BuiltTree::scale; no-op for 0 or a
/// tree with no height.
void apply_real_scale(const Document& doc, BuiltTree& tree);

/// Grows the document's tree in `lobes` (already built) from its trunk strokes, with its
/// grower: document_grower_input, the grower, finish_grown_tree. \throw InvalidInput when the document names a grower or parameters no grower
/// takes (documents loaded with load_session are checked already).
BuiltTree grow_document_tree(const Document& doc, std::vector<BuiltLobe> lobes);

/// Builds the document's lobes, then grows its tree in them.
BuiltTree build_document_tree(const Document& doc);

/// A mesh file as a lobe (meshing/model_import.h: repaired, scaled so its bounding box's
/// largest side is `size_m`, remeshed to settings.lobes.edge_length_m), then raised so its
/// lowest point is half its height above the ground: the default trunk has room below it.
/// \throw FileError, InvalidInput as lobe_from_model.
BuiltLobe model_lobe(const std::string& path, const Settings& settings, double size_m = 1.5, std::int64_t id = 1);

} // namespace lobe
