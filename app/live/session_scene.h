#pragma once
/// \file session_scene.h
/// What the live session draws of its document (live_session.h): the lobes and the tree as
/// the last regrowth built them, made on the regrowth worker's thread (prepare), the strokes
/// as tubes (a tube is made again only when its stroke changed), and what an editing drag
/// shows in their place. The apps append their own items (hands, panels, labels) after
/// static_items() every frame.
///
/// Items: [0, grown) the regrowth's lobes and tree, [grown, static_items()) the strokes, then
/// the app's. Keys and versions are those of tree_render_scene (app/render/render_scene.h),
/// so the scene is the one tree_render_scene would build in one go, and the renderer uploads
/// only what changed.

#include <atomic>
#include <cstdint>
#include <vector>

#include "app/live/regrow_worker.h"
#include "app/render/renderer.h"
#include "core/stroke.h"

namespace lobe {

class SessionScene {
public:
    /// `lod`: the tree's level of detail shown (clamped to the levels it has).
    explicit SessionScene(int lod) : lod_(lod) {}

    /// On the regrowth worker's thread: the grown part of the scene for `result` (lobes, and
    /// the tree at the LOD shown once grown), with its bounds in ground_area.
    void prepare(RegrowResult& result) const;
    /// On the frame thread: `result`'s grown items replace the old ones (made again here when
    /// the LOD changed since prepare). The items are moved out of `result`.
    void take(RegrowResult& result);
    /// Shows the tree at `lod`, rebuilding the grown items from `built` (null: none yet) when it
    /// changes what is shown.
    void set_lod(int lod, RegrowResult* built);
    int lod() const { return lod_.load(); }
    /// The LOD drawn (the one asked for, clamped), and its triangles; 0 and 0 without a tree.
    int lod_shown() const { return lod_shown_; }
    std::size_t tree_triangles() const { return tree_triangles_; }

    /// The strokes' tubes for `strokes` (the document's, with what a drag shows applied): a
    /// tube only for a stroke that is new or changed, the others kept as they are.
    void set_strokes(const std::vector<Stroke>& strokes);
    /// The tube of one stroke already shown, made again from `stroke` (found by its id).
    void refresh_stroke(const Stroke& stroke);
    /// Replaces the mesh of grown lobe item `index` (the index-th lobe built). False when
    /// there is no such item.
    bool replace_lobe(std::size_t index, const TriangleMesh& mesh);

    /// Where the ground is drawn when nothing is: the box given.
    void set_empty_area(const Bounds& area);

    const RenderScene& scene() const { return scene_; }
    /// The scene with only its grown and stroke items, for the app to append this frame's.
    RenderScene& begin_frame_items();
    /// The items as they are, last frame's appended ones included: for an app to take back a
    /// large mesh it appends every frame (moving it, not copying) before begin_frame_items.
    std::vector<RenderItem>& items_before_frame() { return scene_.items; }
    std::size_t static_items() const { return static_items_; }

private:
    void update_ground_area();
    void make_grown_items(RegrowResult& result, int lod) const;

    std::atomic<int> lod_;
    int lod_shown_ = 0;
    std::size_t tree_triangles_ = 0;
    RenderScene scene_;
    std::size_t grown_items_ = 0, static_items_ = 0;
    Bounds grown_bounds_, stroke_bounds_, empty_area_;
    struct StrokeTube {
        std::int64_t id = 0;
        std::uint64_t fingerprint = 0; ///< of the points the tube was made from
    };
    /// What scene_.items[grown_items_, static_items_) were made from, in order.
    std::vector<StrokeTube> stroke_tubes_;
};

} // namespace lobe
