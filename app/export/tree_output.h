#pragma once
/// \file tree_output.h
/// A grown tree turned into geometry and written as .glb or .obj (by the file's extension),
/// shared by `replay`, `grow` and `export`.

#include <string>
#include <vector>

#include "app/export/export_scene.h"
#include "app/session/tree_pipeline.h"
#include "growth/leaves.h"
#include "growth/tree_geometry.h"

namespace lobe {

/// The lobes' own leaf length, count and seed (LobeRecord), in the order `tree` grew its
/// lobes; empty when no lobe has one.
LobeLeafOverrides document_lobe_leaves(const Document& doc, const BuiltTree& tree);

/// Branch and leaf geometry of `tree` at every LOD, with the document's branch and leaf
/// settings and seed (at real scale, BuiltTree::scale > 1, the ring spacing times the scale,
/// at most 1 m), and each lobe's leaf overrides; the leaves the grower placed itself
/// when it did (GrowthResult::leaves).
/// \throw InvalidInput as build_tree_geometry (growth/branch_geometry.h).
TreeGeometry document_tree_geometry(const Document& doc, const BuiltTree& tree);

/// Triangles of one LOD (branches + leaves).
std::size_t lod_triangles(const TreeLod& lod);
/// "LOD0 114392, LOD1 51224, LOD2 15442": the triangles of every LOD, for progress lines.
std::string lod_triangle_summary(const TreeGeometry& geometry);

/// Writes `geometry` of `tree` to `path`: glTF binary for ".glb", OBJ + MTL + PNG for ".obj"
/// (one LOD per OBJ, app/export/export_obj.h). Node and object names start with the file's
/// stem (`oak_branches_LOD0` for oak.glb). The sketch extras (lobes, strokes) come from
/// `tree` and `doc` when `options` asks. Returns the files written, `path` first.
/// \throw InvalidInput for another extension or bad options; FileError when writing fails.
std::vector<std::string> write_tree_file(const std::string& path, const Document& doc, const BuiltTree& tree,
                     const TreeGeometry& geometry, const ExportOptions& options);

/// "wrote a.obj (a.mtl, a_leaf.png, a_bark.png)": a progress line for the files write_tree_file wrote.
std::string wrote_line(const std::vector<std::string>& files);

/// Parses a --lod value: "all" (every LOD) or comma-separated indices ("0", "0,2"); with
/// `billboard`, index lod_count names the billboard level.
/// \throw InvalidInput
std::vector<int> parse_lod_list(const std::string& text, int lod_count, bool billboard = false);

} // namespace lobe
