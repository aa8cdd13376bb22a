#pragma once
/// \file lsystem_sketch_view.h
/// What the L-system sketch mode (lsystem_sketch_mode.h) shows in the live apps' scene: the
/// platform as a ring, the sketch's sections as tubes and its nodes as beads (the dragged one
/// larger), the preview of the next section, and the full-size tree beside the platform as
/// tubes of its pipe-model radii. The tree's mesh is made again only when the mode regrew (or
/// the scene moved), and moves between frames' items rather than being copied (reclaim).

#include <cstdint>

#include "app/live/lsystem_sketch_mode.h"
#include "app/render/renderer.h"
#include "input/pipeline.h"

namespace lobe {

class LSystemSketchView {
public:
    /// Render keys of the mode's items: kKeyBase | n.
    static constexpr std::uint64_t kKeyBase = std::uint64_t{0x4C53} << 48;
    /// The tree's item: kKeyBase | kTreeItem.
    static constexpr std::uint64_t kTreeItem = 4;

    /// Appends the mode's items to `scene` (nothing while the mode is off), taken from stage
    /// space (where the mode works) into the document's through `scene_transform` (the VR
    /// app's two-handed grab; the renderer draws the document's space moved by it).
    void append(const LSystemSketchMode& mode, RenderScene& scene, const SceneTransform& scene_transform = {});

    /// Takes back the tree's mesh from last frame's item among `items` (moved, not copied),
    /// so that append() moves it into this frame's item again: call it before the items are
    /// cut back. Without it append() makes the mesh again every frame.
    void reclaim(std::vector<RenderItem>& items);

private:
    std::uint64_t tree_generation_ = ~std::uint64_t{0};
    std::uint64_t version_ = 0, tree_version_ = 0;
    SceneTransform last_transform_;
    SurfaceGeometry tree_mesh_; ///< the tree's mesh (document space), while held_
    bool held_ = false;
};

} // namespace lobe
