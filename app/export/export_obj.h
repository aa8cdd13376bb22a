#pragma once
/// \file export_obj.h
/// Wavefront OBJ + MTL export of a tree, for tools without glTF.
///
/// `X.obj` holds one object per non-empty LOD mesh (`o <name>_branches_LOD<k>`,
/// `o <name>_leaves_LOD<k>`) with `v`/`vt`/`vn` and `usemtl bark|leaf`; with the extras,
/// `o lobe_<i>` (`usemtl lobe`, faces without vt/vn) and `o stroke_<id>` (`l` polylines,
/// `usemtl stroke`). `X.mtl` defines the materials (Kd from the tree's colours; the leaf adds
/// `map_Kd` and `map_d` for the alpha cut-out) and `X_leaf.png` is the leaf texture, all in
/// the folder of X.obj. Same origin and height rules as the glTF export (app/export/export_scene.h);
/// texture v is flipped to OBJ's bottom-up convention. Full layout: docs/export.md.

#include <string>

#include "app/export/export_scene.h"

namespace lobe {

/// The three files' contents, for tests and in-memory use.
struct ObjFiles {
    std::string obj;
    std::string mtl;
    std::vector<std::uint8_t> leaf_png; ///< empty when the tree has no leaf texture
    std::vector<std::uint8_t> bark_png; ///< empty when the tree has no bark texture (or no branches are written)
};

/// Builds the OBJ/MTL/PNG contents; `mtl_name`, `png_name` and `bark_png_name` are the file
/// names the OBJ and MTL refer to (`mtllib`, `map_Kd`).
/// \throw InvalidInput as prepare_export.
ObjFiles encode_obj(const ExportScene& scene, const ExportOptions& options, const std::string& mtl_name,
                    const std::string& png_name, const std::string& bark_png_name = "bark.png");

/// Writes `path` (X.obj), X.mtl and X_leaf.png beside it, each atomically; the PNG and MTL
/// are written first so the OBJ never refers to a missing file. X_leaf.png is written only
/// when the export has leaves and the tree a leaf texture.
/// \throw InvalidInput as prepare_export (nothing is written); FileError(file, …) when a
/// write fails (files written before it keep their new contents, the failed one its old).
void write_obj(const std::string& path, const ExportScene& scene, const ExportOptions& options = {});

} // namespace lobe
