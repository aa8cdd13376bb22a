#pragma once
/// \file bark_texture.h
/// A procedural bark texture for the branch meshes' bark UVs (growth/branch_geometry.h:
/// u around the branch, mirrored 0 → 1 → 0; v along it in half circumferences). Light and
/// nearly grey, so the material's bark colour tints it; periodic in v (and in u), so it tiles
/// along a branch with REPEAT sampling.

#include "growth/tree_geometry.h"

namespace lobe {

/// `size` × `size` RGBA8 (rows along v), opaque: one tile covers as much bark along the
/// branch as around it (half a circumference each way). Deterministic: same pixels every time. \throw InvalidInput when size is outside [8, 2048].
RgbaImage make_bark_texture(int size = 128);

} // namespace lobe
