#pragma once
/// \file export_obj.h
/// Wavefront OBJ + MTL export of a tree, for tools without glTF.
///
/// One level of detail per OBJ, so importers do not stack the levels: `X.obj` holds the
/// lowest LOD written (`o <name>_branches_LOD<k>`, `o <name>_leaves_LOD<k>`, with `v`/`vt`/`vn`
/// and `usemtl bark|leaf`) and, with the extras, `o lobe_<id>` (`usemtl lobe`, faces without
/// vt/vn) and `o stroke_<id>` (`l` polylines, `usemtl stroke`); every further LOD k written
/// goes into `X_LODk.obj`. `X.mtl` (shared) defines the materials and `X_leaf.png`,
/// `X_bark.png` are the textures with the tree's colours baked in (Kd 1 1 1 then: importers
/// that read only map_Kd show the right colours), all in the folder of X.obj. Same origin and
/// height rules as the glTF export (app/export/export_scene.h); texture v is flipped to OBJ's
/// bottom-up convention. Full layout: docs/export.md.

#include <string>
#include <utility>
#include <vector>

#include "app/export/export_scene.h"

namespace lobe {

/// The three files' contents, for tests and in-memory use.
struct ObjFiles {
    std::string obj;                                  ///< the lowest LOD written, and the extras
    std::vector<std::pair<int, std::string>> lod_objs; ///< (k, OBJ of LOD k) for every further LOD, ascending
    std::string mtl;
    std::vector<std::uint8_t> leaf_png; ///< empty when the tree has no leaf texture
    std::vector<std::uint8_t> bark_png; ///< empty when the tree has no bark texture (or no branches are written)
    std::vector<std::uint8_t> bark_normal_png; ///< with ExportOptions::bark_normal_map: X_bark_normal.png (map_Bump)
    std::vector<std::uint8_t> billboard_png; ///< the billboard's picture; empty without a billboard level
};

/// Builds the OBJ/MTL/PNG contents; `mtl_name`, `png_name` and `bark_png_name` are the file
/// names the OBJ and MTL refer to (`mtllib`, `map_Kd`).
/// \throw InvalidInput as prepare_export.
ObjFiles encode_obj(const ExportScene& scene, const ExportOptions& options, const std::string& mtl_name,
                    const std::string& png_name, const std::string& bark_png_name = "bark.png",
                    const std::string& billboard_png_name = "billboard.png");

/// Writes `path` (X.obj), X_LODk.obj for every further LOD, X.mtl and the PNGs beside it,
/// each atomically; the PNGs and MTL are written first so an OBJ never refers to a missing
/// file. X_leaf.png is written only when the export has leaves and the tree a leaf texture,
/// X_bark.png likewise for branches, X_billboard.png with the billboard level. Returns the files written: X.obj, X.mtl, then the PNGs
/// and further OBJs.
/// \throw InvalidInput as prepare_export (nothing is written); FileError(file, …) when a
/// write fails (files written before it keep their new contents, the failed one its old).
std::vector<std::string> write_obj(const std::string& path, const ExportScene& scene, const ExportOptions& options = {});

} // namespace lobe
