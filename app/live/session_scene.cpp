#include "app/live/session_scene.h"

#include <algorithm>
#include <iterator>
#include <map>
#include <utility>

#include "app/export/tree_output.h"
#include "app/render/render_scene.h"

namespace lobe {

namespace {

/// What a stroke's tube is made from (its points, round again when closed), hashed.
std::uint64_t stroke_fingerprint(const Stroke& st)
{
    std::vector<glm::vec3> pts;
    pts.reserve(st.points.size() + 1);
    for (const StrokePoint& p : st.points) pts.push_back(p.position);
    if (st.closed && pts.size() > 2) pts.push_back(pts.front());
    return bytes_hash(pts.data(), pts.size() * sizeof(glm::vec3));
}

bool shows_tree(const RegrowResult& r) { return r.grown && !r.geometry.lods.empty(); }

int clamped_lod(const RegrowResult& r, int lod) { return shows_tree(r) ? std::min(lod, int(r.geometry.lods.size()) - 1) : 0; }

} // namespace

void SessionScene::make_grown_items(RegrowResult& r, int lod) const
{
    std::vector<TriangleMesh> lobes;
    lobes.reserve(r.tree.lobes.size());
    for (const BuiltLobe& l : r.tree.lobes) lobes.push_back(l.mesh);
    RenderContent content;
    content.tree = content.leaves = shows_tree(r);
    content.lobes = true;
    content.strokes = false;
    content.lod = clamped_lod(r, lod);
    r.scene = tree_render_scene(r.geometry, lobes, {}, 0.0f, content);
    r.scene.ground_area = scene_bounds(r.scene);
    r.scene_lod = lod;
}

void SessionScene::prepare(RegrowResult& result) const { make_grown_items(result, lod_.load()); }

void SessionScene::take(RegrowResult& result)
{
    if (result.scene_lod != lod_.load()) make_grown_items(result, lod_.load());
    // The regrowth's items replace the old ones; the strokes' items stay as they are.
    scene_.items.resize(static_items_); // the app's items of this frame are added again
    scene_.items.erase(scene_.items.begin(), scene_.items.begin() + std::ptrdiff_t(grown_items_));
    static_items_ -= grown_items_;
    grown_items_ = result.scene.items.size();
    static_items_ += grown_items_;
    scene_.items.insert(scene_.items.begin(), std::make_move_iterator(result.scene.items.begin()),
                        std::make_move_iterator(result.scene.items.end()));
    result.scene.items.clear();
    scene_.leaf_texture = std::move(result.scene.leaf_texture);
    scene_.leaf_texture_version = result.scene.leaf_texture_version;
    grown_bounds_ = result.scene.ground_area;
    lod_shown_ = clamped_lod(result, lod_.load());
    tree_triangles_ = shows_tree(result) ? lod_triangles(result.geometry.lods[std::size_t(lod_shown_)]) : 0;
    update_ground_area();
}

void SessionScene::set_lod(int lod, RegrowResult* built)
{
    if (lod == lod_.load()) return;
    lod_.store(lod);
    if (!built || !shows_tree(*built)) return;
    // The grown items were moved into the scene: the tree's are made again, the lobes' too (a
    // lobe shown live is put back by the live session's next update).
    make_grown_items(*built, lod);
    take(*built);
}

void SessionScene::set_strokes(const std::vector<Stroke>& strokes)
{
    // A tube only for a stroke that is new or changed (most changes add one); the others are
    // moved from the scene's stroke items as they are.
    std::map<std::int64_t, std::pair<std::uint64_t, RenderItem>> old;
    for (std::size_t i = 0; i < stroke_tubes_.size(); ++i)
        old.emplace(stroke_tubes_[i].id,
                    std::make_pair(stroke_tubes_[i].fingerprint, std::move(scene_.items[grown_items_ + i])));
    scene_.items.resize(grown_items_);
    stroke_tubes_.clear();
    stroke_bounds_ = Bounds{};
    for (const Stroke& st : strokes) {
        const std::uint64_t fingerprint = stroke_fingerprint(st);
        const auto it = old.find(st.id);
        RenderItem item;
        if (it != old.end() && it->second.first == fingerprint) item = std::move(it->second.second);
        else {
            RenderContent content;
            content.tree = content.leaves = content.lobes = false;
            content.strokes = true;
            RenderScene one = tree_render_scene(TreeGeometry{}, {}, {st}, 0.0f, content);
            if (one.items.empty()) continue;
            item = std::move(one.items.front());
        }
        for (const glm::vec3& p : item.geometry.positions) stroke_bounds_.add(p);
        scene_.items.push_back(std::move(item));
        stroke_tubes_.push_back({st.id, fingerprint});
    }
    static_items_ = scene_.items.size();
    update_ground_area();
}

void SessionScene::refresh_stroke(const Stroke& stroke)
{
    // The tube and the fingerprint set_strokes keeps for it, so that the next set_strokes
    // makes the tube again exactly when the document's points differ from these.
    for (std::size_t i = 0; i < stroke_tubes_.size(); ++i)
        if (stroke_tubes_[i].id == stroke.id && grown_items_ + i < scene_.items.size()) {
            if (!replace_stroke_item(scene_, stroke)) return;
            stroke_tubes_[i].fingerprint = stroke_fingerprint(stroke);
            return;
        }
}

bool SessionScene::replace_lobe(std::size_t index, const TriangleMesh& mesh) { return replace_lobe_item(scene_, index, mesh); }

void SessionScene::set_empty_area(const Bounds& area)
{
    empty_area_ = area;
    update_ground_area();
}

RenderScene& SessionScene::begin_frame_items()
{
    scene_.items.resize(static_items_);
    return scene_;
}

void SessionScene::update_ground_area()
{
    Bounds area = grown_bounds_;
    if (!stroke_bounds_.empty()) {
        area.add(stroke_bounds_.lo);
        area.add(stroke_bounds_.hi);
    }
    if (area.empty()) area = empty_area_;
    scene_.ground_area = area;
}

} // namespace lobe
