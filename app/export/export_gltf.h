#pragma once
/// \file export_gltf.h
/// glTF 2.0 binary (.glb) export of a tree for Blender, Unity, Unreal and the web.
///
/// One scene; a root node `<name>` whose children are the nodes `<name>_branches_LOD<k>` and
/// `<name>_leaves_LOD<k>` (each with the mesh of the same name), the suffix convention engine
/// importers read as LOD levels. Materials `bark` (opaque PBR, baseColorFactor = bark_color,
/// metallic 0, roughness 0.9) and `leaf` (baseColorFactor = leaf_color times the leaf texture,
/// embedded as PNG in the binary chunk; alphaMode MASK, alphaCutoff 0.5, double-sided).
/// Optional sketch extras under a second root node `<name>_sketch`: `lobe_<i>` (translucent,
/// alphaMode BLEND) and `stroke_<id>` (LINE_STRIP, KHR_materials_unlit). Vertex data are in
/// metres with the trunk base at the origin (and scaled, see ExportOptions); node transforms
/// are identity. Same input, same bytes. Full layout: docs/export.md.

#include <cstdint>
#include <string>
#include <vector>

#include "app/export/export_scene.h"

namespace lobe {

/// The .glb bytes of `scene`.
/// \throw InvalidInput as prepare_export (app/export/export_scene.h), or when the result would not
/// fit the 4 GiB limit of a .glb.
std::vector<std::uint8_t> encode_glb(const ExportScene& scene, const ExportOptions& options = {});

/// Writes encode_glb(scene, options) to `path` atomically (temporary file, flush, rename):
/// an existing file is either replaced whole or left as it was.
/// \throw InvalidInput as encode_glb (nothing is written); FileError(path, …) when writing fails.
void write_glb(const std::string& path, const ExportScene& scene, const ExportOptions& options = {});

} // namespace lobe
