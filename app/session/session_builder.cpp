#include "app/session/session_builder.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <set>
#include <unordered_map>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "app/session/panel_controls.h"
#include "app/session/session_file.h"
#include "growth/grower.h"
#include "core/errors.h"
#include "core/settings_table.h"

namespace lobe {

namespace {
// Undo depth: a document snapshot per change; sessions have tens to hundreds of changes.
constexpr std::size_t kMaxUndo = 256;

std::string cm(double m)
{
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.1f cm", m * 100.0);
    return buf;
}

/// Distance from p to the nearest point of the stroke (infinity for a stroke with none).
double distance_to_stroke(const Stroke& s, const glm::dvec3& p)
{
    double best = std::numeric_limits<double>::infinity();
    for (const StrokePoint& q : s.points) best = std::min(best, glm::distance(glm::dvec3(q.position), p));
    return best;
}

const Stroke* find_stroke(const std::vector<Stroke>& strokes, std::int64_t id)
{
    for (const Stroke& s : strokes)
        if (s.id == id) return &s;
    return nullptr;
}

/// The kind of edit a drag under tool `t` makes ("drag:" + the tool's name in the file);
/// nullopt for the drawing tools.
std::optional<EditKind> edit_kind_of(Tool t)
{
    switch (t) {
    case Tool::DeformLobe: return EditKind::DeformLobe;
    case Tool::EditStroke: return EditKind::EditStroke;
    case Tool::MoveLobe: return EditKind::MoveLobe;
    case Tool::RotateLobe: return EditKind::RotateLobe;
    case Tool::ScaleLobe: return EditKind::ScaleLobe;
    case Tool::DrawLobe:
    case Tool::DrawTrunk: break;
    }
    return std::nullopt;
}

/// The stroke (of `kind`, or any when none is given) with the point nearest `p`, and that
/// distance (infinity when there is none).
const Stroke* nearest_stroke(const std::vector<Stroke>& view, const glm::dvec3& p, double& distance,
                             std::optional<StrokeKind> kind = std::nullopt)
{
    const Stroke* best = nullptr;
    distance = std::numeric_limits<double>::infinity();
    for (const Stroke& s : view) {
        if (kind && s.kind != *kind) continue;
        const double d = distance_to_stroke(s, p);
        if (d < distance) {
            distance = d;
            best = &s;
        }
    }
    return best;
}

/// Centre of a lobe made from a mesh: the middle of its bounding box.
glm::dvec3 model_centre(const TriangleMesh& mesh)
{
    glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
    for (const glm::vec3& q : mesh.positions) {
        lo = glm::min(lo, glm::dvec3(q));
        hi = glm::max(hi, glm::dvec3(q));
    }
    return mesh.positions.empty() ? glm::dvec3(0.0) : 0.5 * (lo + hi);
}

/// What a lobe pick found: `lobe` is null when it picked nothing; `nearest_any` is the
/// distance to the nearest lobe stroke (infinity when no lobe has strokes to see).
struct LobePick {
    const LobeRecord* lobe = nullptr;
    glm::dvec3 centre{0.0};
    double radius = 0.0;
    double nearest_any = std::numeric_limits<double>::infinity();
};

/// Among the lobes whose strokes (as seen in `view`) come within `pick_distance` of `p`,
/// or whose bounding sphere (centre: lobe_centre, radius: its farthest stroke point) holds
/// it, the one whose strokes are nearest. A lobe made from a mesh counts its vertices as
/// its stroke points and the middle of their bounding box as its centre.
LobePick pick_lobe(const Document& doc, const std::vector<Stroke>& view, const glm::dvec3& p, double pick_distance,
                   const EditHooks& hooks)
{
    LobePick pick;
    double best_d = std::numeric_limits<double>::infinity();
    for (const LobeRecord& lobe : doc.lobes) {
        glm::dvec3 c;
        double d = std::numeric_limits<double>::infinity(), radius = 0.0;
        if (lobe.model) {
            // A lobe made from a mesh: its vertices where the person sees them.
            const TriangleMesh mesh = hooks.model_in_stage ? hooks.model_in_stage(doc, lobe) : lobe.model->mesh;
            if (mesh.positions.empty()) continue;
            c = model_centre(mesh);
            for (const glm::vec3& q : mesh.positions) {
                d = std::min(d, glm::distance(glm::dvec3(q), p));
                radius = std::max(radius, glm::distance(glm::dvec3(q), c));
            }
        } else {
            if (!lobe_centre(lobe, view, c)) continue;
            for (std::int64_t id : lobe.stroke_ids)
                if (const Stroke* s = find_stroke(view, id)) {
                    d = std::min(d, distance_to_stroke(*s, p));
                    for (const StrokePoint& q : s->points) radius = std::max(radius, glm::distance(glm::dvec3(q.position), c));
                }
        }
        pick.nearest_any = std::min(pick.nearest_any, d);
        const bool near = d <= pick_distance || glm::distance(p, c) <= radius;
        if (near && d < best_d) {
            best_d = d;
            pick.lobe = &lobe;
            pick.centre = c;
            pick.radius = radius;
        }
    }
    return pick;
}

/// Removes the strokes `strokes` and the lobes `lobes` from `doc`, with every lobe left
/// without strokes, the operations that target any of them and the removed lobes' trees;
/// the remaining transform operations forget the removed strokes in their `strokes` lists.
void erase_from_document(Document& doc, const std::set<std::int64_t>& strokes, std::set<std::int64_t> lobes)
{
    doc.strokes.erase(std::remove_if(doc.strokes.begin(), doc.strokes.end(),
                                     [&](const Stroke& s) { return strokes.count(s.id) > 0; }),
                      doc.strokes.end());
    for (LobeRecord& l : doc.lobes) {
        const std::size_t before = l.stroke_ids.size();
        l.stroke_ids.erase(std::remove_if(l.stroke_ids.begin(), l.stroke_ids.end(),
                                          [&](std::int64_t id) { return strokes.count(id) > 0; }),
                           l.stroke_ids.end());
        if (l.stroke_ids.empty() && before > 0) lobes.insert(l.id);
    }
    doc.lobes.erase(std::remove_if(doc.lobes.begin(), doc.lobes.end(),
                                   [&](const LobeRecord& l) { return lobes.count(l.id) > 0; }),
                    doc.lobes.end());
    // A stroke edit targets a stroke id, the other kinds a lobe id.
    doc.edits.erase(std::remove_if(doc.edits.begin(), doc.edits.end(),
                                   [&](const EditOperation& op) {
                                       if (op.kind() == EditKind::EditStroke) return strokes.count(op.target) > 0;
                                       return lobes.count(op.target) > 0;
                                   }),
                    doc.edits.end());
    for (EditOperation& op : doc.edits) {
        LobeTransformParams* t = op.transform_params();
        if (!t || !t->strokes) continue;
        std::erase_if(*t->strokes, [&](std::int64_t id) { return strokes.count(id) > 0; });
    }
    // A tree that listed only removed lobes would otherwise mean "every lobe" (empty list).
    doc.trees.erase(std::remove_if(doc.trees.begin(), doc.trees.end(),
                                   [&](TreeInstance& t) {
                                       if (t.lobe_ids.empty()) return false;
                                       t.lobe_ids.erase(std::remove_if(t.lobe_ids.begin(), t.lobe_ids.end(),
                                                                       [&](std::int64_t id) { return lobes.count(id) > 0; }),
                                                        t.lobe_ids.end());
                                       return t.lobe_ids.empty();
                                   }),
                    doc.trees.end());
}

/// x of the lowest point of all trunk strokes (the trunk's base); 0 when there are none.
double trunk_base_x(const std::vector<Stroke>& view)
{
    double lowest = std::numeric_limits<double>::infinity(), x = 0.0;
    for (const Stroke& s : view) {
        if (s.kind != StrokeKind::Trunk) continue;
        for (const StrokePoint& p : s.points)
            if (p.position.y < lowest) {
                lowest = p.position.y;
                x = p.position.x;
            }
    }
    return x;
}

/// A point of a copy: mirrored across the plane x = mirror_x, or shifted.
glm::vec3 place_point(const glm::vec3& p, bool mirror, const glm::dvec3& shift, double mirror_x)
{
    if (mirror) return {static_cast<float>(2.0 * mirror_x - static_cast<double>(p.x)), p.y, p.z};
    return glm::vec3(glm::dvec3(p) + shift);
}

/// Empty when `doc` can take `strokes` more strokes, `lobes` more lobes and `edits` more
/// edits within the document limits (core/document.h); else why not.
std::string over_limits(const Document& doc, std::size_t strokes, std::size_t lobes, std::size_t edits)
{
    auto full = [](std::size_t have, std::size_t more, std::size_t limit, const char* what) {
        if (have + more <= limit) return std::string();
        return "the session holds " + std::to_string(have) + " " + what + " and may hold at most " +
               std::to_string(limit);
    };
    std::string why = full(doc.strokes.size(), strokes, kMaxDocumentStrokes, "strokes");
    if (why.empty()) why = full(doc.lobes.size(), lobes, kMaxDocumentLobes, "lobes");
    if (why.empty()) why = full(doc.edits.size(), edits, kMaxDocumentEdits, "edits");
    return why;
}

std::string when(const char* what, double t)
{
    char buf[96];
    std::snprintf(buf, sizeof buf, "%s at t=%.2fs changes nothing: ", what, t);
    return buf;
}

} // namespace

bool lobe_centre(const LobeRecord& lobe, const std::vector<Stroke>& strokes, glm::dvec3& centre)
{
    glm::dvec3 weighted(0.0), plain(0.0);
    double length = 0.0;
    std::size_t count = 0;
    for (std::int64_t id : lobe.stroke_ids) {
        const Stroke* s = find_stroke(strokes, id);
        if (!s) continue;
        for (std::size_t i = 0; i < s->points.size(); ++i) {
            const glm::dvec3 p(s->points[i].position);
            plain += p;
            ++count;
            if (i == 0) continue;
            const glm::dvec3 q(s->points[i - 1].position);
            const double l = glm::distance(p, q);
            weighted += l * 0.5 * (p + q);
            length += l;
        }
    }
    if (count == 0) return false;
    centre = length > 0.0 ? weighted / length : plain / static_cast<double>(count);
    return true;
}

SessionBuilder::SessionBuilder(Document doc, EditPickOptions pick, EditHooks hooks)
    : doc_(std::move(doc)), pick_(pick), hooks_(std::move(hooks))
{
    for (const LobeRecord& l : doc_.lobes) next_lobe_id_ = std::max(next_lobe_id_, l.id + 1);
    for (const EditOperation& e : doc_.edits) next_edit_id_ = std::max(next_edit_id_, e.id + 1);
    for (const Stroke& st : doc_.strokes) next_stroke_id_ = std::max(next_stroke_id_, st.id + 1);
}

std::vector<Stroke> SessionBuilder::view() const
{
    return hooks_.current_strokes ? hooks_.current_strokes(doc_) : doc_.strokes;
}

namespace {

/// Smallest distance between (up to 256 evenly spread) points of `stroke` and (up to 4,096)
/// points of the lobe's strokes; also the lobe's radius around the centroid of its points.
void lobe_distance(const std::unordered_map<std::int64_t, const Stroke*>& by_id, const LobeRecord& lobe,
                   const Stroke& stroke, double& distance, double& radius)
{
    std::vector<glm::vec3> pts;
    for (std::int64_t id : lobe.stroke_ids)
        if (const auto it = by_id.find(id); it != by_id.end())
            for (const StrokePoint& p : it->second->points) pts.push_back(p.position);
    distance = 0; // without geometry to compare, the stroke stays with the lobe
    radius = 0;
    if (pts.empty() || stroke.points.empty()) return;
    distance = std::numeric_limits<double>::infinity();
    glm::dvec3 centroid(0.0);
    for (const glm::vec3& p : pts) centroid += glm::dvec3(p);
    centroid /= static_cast<double>(pts.size());
    for (const glm::vec3& p : pts) radius = std::max(radius, glm::distance(glm::dvec3(p), centroid));
    const std::size_t step_a = std::max<std::size_t>(1, stroke.points.size() / 256);
    const std::size_t step_b = std::max<std::size_t>(1, pts.size() / 4096);
    for (std::size_t i = 0; i < stroke.points.size(); i += step_a)
        for (std::size_t j = 0; j < pts.size(); j += step_b)
            distance = std::min(distance, static_cast<double>(glm::distance(stroke.points[i].position, pts[j])));
}

} // namespace

bool SessionBuilder::add_stroke(const InputAction& a)
{
    const Stroke& drawn = a.stroke;
    auto refuse = [&](const std::string& why) {
        char buf[128];
        std::snprintf(buf, sizeof buf, "%s stroke %lld at t=%.2fs refused: ", stroke_kind_name(drawn.kind),
                      static_cast<long long>(drawn.id), drawn.points.empty() ? a.time : drawn.points.front().time);
        messages_.push_back(buf + why);
        return false;
    };
    // What no session may hold is refused before anything changes (docs/limits.md).
    if (std::string why = stroke_points_problem(drawn); !why.empty()) return refuse(why);
    const InputOptions& in = doc_.settings.input;
    const double length = drawn.length();
    const auto n = static_cast<long long>(drawn.points.size());
    if (length <= 0.0) return refuse("all its points lie at one place (zero length)");
    if (length < in.min_stroke_length_m || n < in.min_stroke_points) {
        char buf[160];
        std::snprintf(buf, sizeof buf, "too short (%.1f cm, %lld points; need %.1f cm and %d points)", length * 100.0,
                      n, in.min_stroke_length_m * 100.0, in.min_stroke_points);
        return refuse(buf);
    }
    if (drawn.kind == StrokeKind::Lobe && stroke_is_straight(drawn))
        return refuse("all its points lie on one straight line, so it cannot bound a lobe");
    if (doc_.strokes.size() >= kMaxDocumentStrokes)
        return refuse("the session already holds " + std::to_string(kMaxDocumentStrokes) +
                      " strokes, the most it may hold");

    Stroke stroke = drawn;
    if (find_stroke(doc_.strokes, stroke.id)) stroke.id = next_stroke_id_;
    if (stroke.kind != StrokeKind::Lobe) {
        snapshot();
        next_stroke_id_ = std::max(next_stroke_id_, stroke.id + 1);
        doc_.strokes.push_back(stroke);
        return true;
    }
    // A stroke joins the lobe it is drawn into: the current lobe when it comes near it, else
    // the nearest lobe it comes near; far from every lobe (or after "new lobe") it starts one.
    LobeRecord* target = nullptr;
    if (!new_lobe_pending_ && !doc_.lobes.empty()) {
        // Strokes by id, once: a session may hold up to kMaxDocumentStrokes.
        std::unordered_map<std::int64_t, const Stroke*> by_id;
        by_id.reserve(doc_.strokes.size());
        for (const Stroke& s : doc_.strokes) by_id.emplace(s.id, &s);
        auto near = [&](const LobeRecord& l, double& d) {
            if (l.model) return false; // a lobe made from a mesh takes no strokes
            double radius = 0;
            lobe_distance(by_id, l, stroke, d, radius);
            return d <= std::max(kJoinDistanceM, 0.5 * radius);
        };
        double d = 0;
        if (near(doc_.lobes.back(), d)) {
            target = &doc_.lobes.back();
        } else {
            double best = std::numeric_limits<double>::infinity();
            for (LobeRecord& l : doc_.lobes)
                if (near(l, d) && d < best) {
                    best = d;
                    target = &l;
                }
        }
    }
    if (!target && doc_.lobes.size() >= kMaxDocumentLobes)
        return refuse("it would start a new lobe, and the session already holds " + std::to_string(kMaxDocumentLobes) +
                      " lobes, the most it may hold");
    // The lobe the stroke joins, by index: the snapshot and the push below move lobes.
    const std::size_t target_index = target ? static_cast<std::size_t>(target - doc_.lobes.data()) : doc_.lobes.size();
    snapshot();
    next_stroke_id_ = std::max(next_stroke_id_, stroke.id + 1);
    doc_.strokes.push_back(stroke);
    if (target_index == doc_.lobes.size()) doc_.lobes.push_back(LobeRecord::of_strokes(next_lobe_id_++));
    new_lobe_pending_ = false;
    doc_.lobes[target_index].stroke_ids.push_back(stroke.id);
    return true;
}

void SessionBuilder::snapshot()
{
    undo_.push_back(doc_);
    if (undo_.size() > kMaxUndo) undo_.erase(undo_.begin());
    redo_.clear();
}

bool SessionBuilder::add_drag(const InputAction& a)
{
    std::string why;
    std::optional<EditOperation> op = drag_operation(a.drag, &why);
    if (!op) {
        char when[96];
        std::snprintf(when, sizeof when, "%s drag at t=%.2fs edits nothing: ", tool_name(a.drag.tool),
                      a.drag.path.empty() ? a.time : a.drag.path.front().time);
        messages_.push_back(when + why);
        return false;
    }
    snapshot();
    ++next_edit_id_;
    doc_.edits.push_back(std::move(*op));
    return true;
}

std::optional<EditOperation> SessionBuilder::drag_operation(const Drag& drag, std::string* reason) const
{
    auto nothing = [&](const std::string& why) -> std::optional<EditOperation> {
        if (reason) *reason = why;
        return std::nullopt;
    };
    if (drag.path.empty()) return nothing("it has no points");
    const std::optional<EditKind> kind = edit_kind_of(drag.tool);
    if (!kind) return nothing("not an editing tool");
    if (doc_.edits.size() >= kMaxDocumentEdits)
        return nothing("the session already holds " + std::to_string(kMaxDocumentEdits) + " edits, the most it may hold");
    {
        Stroke path;
        path.points = drag.path;
        if (drag.path.size() == 1) path.points.push_back(drag.path.front()); // a tap: one point is a path
        if (std::string why = stroke_points_problem(path); !why.empty()) return nothing("its path: " + why);
        if (drag.other_tip && !(std::isfinite(drag.other_tip->x) && std::isfinite(drag.other_tip->y) &&
                                std::isfinite(drag.other_tip->z)))
            return nothing("the pointing fingertip is not at a finite position");
    }
    const glm::dvec3 start(drag.path.front().position);
    const std::vector<Stroke> view = this->view();

    EditOperation op;
    op.id = next_edit_id_;
    op.params = edit_params_of(*kind);
    op.hand = drag.hand;
    op.path.reserve(drag.path.size());
    for (const StrokePoint& p : drag.path) op.path.push_back({glm::dvec3(p.position), p.time});

    if (EditStrokeParams* bend = std::get_if<EditStrokeParams>(&op.params)) {
        // The stroke with the point nearest to the drag start (the first on a tie).
        double best_d = 0.0;
        const Stroke* best = nearest_stroke(view, start, best_d);
        if (!best) return nothing("there are no strokes");
        if (best_d > pick_.stroke_pick_distance_m)
            return nothing("its start is " + cm(best_d) + " from the nearest stroke (pick distance " +
                           cm(pick_.stroke_pick_distance_m) + ")");
        if (drag.other_tip) {
            const double d = distance_to_stroke(*best, glm::dvec3(*drag.other_tip));
            if (d > pick_.stroke_pick_distance_m)
                return nothing("the pointing fingertip is " + cm(d) + " from stroke " + std::to_string(best->id) +
                               " (pick distance " + cm(pick_.stroke_pick_distance_m) + ")");
            bend->other_tip = glm::dvec3(*drag.other_tip);
        }
        op.target = best->id;
        bend->pick_distance_m = pick_.stroke_pick_distance_m;
        bend->half_length_m = pick_.stroke_half_length_m;
    } else {
        // Lobe tools: the lobe whose strokes are nearest the drag start, among those it is
        // near or inside.
        const LobePick pick = pick_lobe(doc_, view, start, pick_.lobe_pick_distance_m, hooks_);
        if (!pick.lobe) {
            if (!std::isfinite(pick.nearest_any)) return nothing("there are no lobes");
            return nothing("its start is outside every lobe and " + cm(pick.nearest_any) +
                           " from the nearest lobe stroke (pick distance " + cm(pick_.lobe_pick_distance_m) + ")");
        }
        op.target = pick.lobe->id;
        if (LobeTransformParams* t = op.transform_params()) {
            t->centre = pick.centre;
            t->strokes = pick.lobe->stroke_ids;
        }
    }
    // What a session file may not hold (document_from_json) is not made here either: the
    // checks above leave only a pointing fingertip just past 1 km, near a stroke at the limit.
    if (std::string why = edit_operation_problem(op); !why.empty()) return nothing(why);
    if (hooks_.check) {
        const std::string why = hooks_.check(doc_, op);
        if (!why.empty()) return nothing(why);
    }
    return op;
}

std::int64_t SessionBuilder::lobe_at(const glm::dvec3& point) const { return lobe_drag_target(point).lobe; }

SessionBuilder::LobeDragTarget SessionBuilder::lobe_drag_target(const glm::dvec3& point) const
{
    const LobePick pick = pick_lobe(doc_, view(), point, pick_.lobe_pick_distance_m, hooks_);
    if (!pick.lobe) return {};
    return {pick.lobe->id, pick.centre};
}

bool SessionBuilder::apply(const InputAction& a)
{
    if (a.type != InputAction::Type::SettingChanged) setting_run_.reset();
    switch (a.type) {
    case InputAction::Type::StrokeCompleted: return add_stroke(a);
    case InputAction::Type::DragCompleted: return add_drag(a);
    case InputAction::Type::NewLobe:
        // Only a pending flag: an empty lobe is never created.
        new_lobe_pending_ = !doc_.lobes.empty();
        return false;
    case InputAction::Type::Undo:
        if (undo_.empty()) return false;
        redo_.push_back(std::move(doc_));
        doc_ = std::move(undo_.back());
        undo_.pop_back();
        return true;
    case InputAction::Type::Redo:
        if (redo_.empty()) return false;
        undo_.push_back(std::move(doc_));
        doc_ = std::move(redo_.back());
        redo_.pop_back();
        return true;
    case InputAction::Type::DeleteStroke:
    case InputAction::Type::DeleteLobe: return delete_at_tip(a);
    case InputAction::Type::Duplicate:
    case InputAction::Type::Mirror: return copy_at_tip(a);
    case InputAction::Type::SettingChanged: return apply_setting(a);
    case InputAction::Type::ImportMesh: return import_mesh(a);
    case InputAction::Type::StrokeDiscarded:
    case InputAction::Type::ToolChanged:
    case InputAction::Type::Grow:
        return false;
    }
    return false;
}

bool SessionBuilder::delete_at_tip(const InputAction& a)
{
    const bool lobe_wanted = a.type == InputAction::Type::DeleteLobe;
    const std::string prefix = when(action_name(a.type), a.time);
    auto nothing = [&](const std::string& why) {
        messages_.push_back(prefix + why);
        return false;
    };
    if (!a.tip) return nothing("no hand was tracked");
    const glm::dvec3 tip(*a.tip);
    const std::vector<Stroke> view = this->view();
    if (lobe_wanted) {
        const LobePick pick = pick_lobe(doc_, view, tip, pick_.lobe_pick_distance_m, hooks_);
        if (!pick.lobe) {
            if (!std::isfinite(pick.nearest_any)) return nothing("there are no lobes");
            return nothing("the fingertip is outside every lobe and " + cm(pick.nearest_any) +
                           " from the nearest lobe stroke (pick distance " + cm(pick_.lobe_pick_distance_m) + ")");
        }
        const std::set<std::int64_t> strokes(pick.lobe->stroke_ids.begin(), pick.lobe->stroke_ids.end());
        const std::int64_t lobe = pick.lobe->id;
        snapshot();
        erase_from_document(doc_, strokes, {lobe});
        return true;
    }
    double d = 0.0;
    const Stroke* s = nearest_stroke(view, tip, d);
    if (!s) return nothing("there are no strokes");
    if (d > pick_.stroke_pick_distance_m)
        return nothing("the fingertip is " + cm(d) + " from the nearest stroke (pick distance " +
                       cm(pick_.stroke_pick_distance_m) + ")");
    const std::int64_t id = s->id;
    snapshot();
    erase_from_document(doc_, {id}, {});
    return true;
}

std::vector<EditOperation> SessionBuilder::placed_deforms(const LobeRecord& lobe, bool mirror, const glm::dvec3& shift,
                                                          double mirror_x, std::string& note) const
{
    std::vector<std::size_t> deforms;
    for (std::size_t i = 0; i < doc_.edits.size(); ++i)
        if (doc_.edits[i].kind() == EditKind::DeformLobe && doc_.edits[i].target == lobe.id) deforms.push_back(i);
    if (deforms.empty()) return {};

    // Where each deform's path is now: a deform made after k operations sits where a stroke
    // drawn into the lobe at that moment would, so each path becomes a probe stroke of the
    // lobe that the transform operations made before it do not list and the later ones do
    // (see app/session/edit_ops.h, "Frames"). One more probe, listed by every transform, gives
    // the lobe's scale now.
    Document probe = doc_;
    LobeRecord* pl = nullptr;
    for (LobeRecord& l : probe.lobes)
        if (l.id == lobe.id) pl = &l;
    std::int64_t next_id = next_stroke_id_;
    for (const Stroke& st : doc_.strokes) next_id = std::max(next_id, st.id + 1);
    const std::int64_t scale_id = next_id++;
    Stroke unit;
    unit.id = scale_id;
    unit.points = {{glm::vec3(0.0f), 0.0}, {glm::vec3(1.0f, 0.0f, 0.0f), 0.0}};
    probe.strokes.push_back(unit);
    pl->stroke_ids.push_back(scale_id);
    std::vector<std::int64_t> probe_ids;
    for (std::size_t k : deforms) {
        const EditOperation& deform = doc_.edits[k];
        // A document read from a file holds no malformed operation; one made in code may.
        if (!edit_operation_problem(deform).empty()) {
            note = "edit " + std::to_string(deform.id) + " has no readable path";
            return {};
        }
        Stroke st;
        st.id = next_id++;
        for (const DragPoint& q : deform.path) st.points.push_back({glm::vec3(q.position), 0.0});
        probe.strokes.push_back(std::move(st));
        pl->stroke_ids.push_back(next_id - 1);
        probe_ids.push_back(next_id - 1);
    }
    for (std::size_t i = 0; i < probe.edits.size(); ++i) {
        EditOperation& op = probe.edits[i];
        LobeTransformParams* t = op.transform_params();
        if (!t || op.target != lobe.id) continue;
        // Without a list a transform applies to every stroke of the lobe: list them.
        std::vector<std::int64_t> ids = t->strokes ? *t->strokes : lobe.stroke_ids;
        ids.push_back(scale_id);
        for (std::size_t j = 0; j < deforms.size(); ++j)
            if (deforms[j] < i) ids.push_back(probe_ids[j]);
        t->strokes = std::move(ids);
    }
    const std::vector<Stroke> now = hooks_.current_strokes ? hooks_.current_strokes(probe) : probe.strokes;
    const Stroke* u = find_stroke(now, scale_id);
    const double scale = u && u->points.size() == 2 ? glm::distance(glm::dvec3(u->points[0].position),
                                                                    glm::dvec3(u->points[1].position))
                                                    : 1.0;
    if (std::abs(scale - 1.0) > 1e-4) {
        // The lobe builder deforms a lobe in its own frame, before its scale: the region and
        // pick distance of a deform would not scale with the copy.
        char buf[160];
        std::snprintf(buf, sizeof buf, "lobe %lld was scaled (x%.3f), so a pinch deform's region would not match",
                      static_cast<long long>(lobe.id), scale);
        note = buf;
        return {};
    }
    std::vector<EditOperation> out;
    for (std::size_t j = 0; j < deforms.size(); ++j) {
        const Stroke* p = find_stroke(now, probe_ids[j]);
        EditOperation op = doc_.edits[deforms[j]];
        if (!p || p->points.size() != op.path.size()) {
            note = "edit " + std::to_string(op.id) + " could not be placed";
            return {};
        }
        // Each point keeps its time (or its lack of one).
        for (std::size_t i = 0; i < p->points.size(); ++i)
            op.path[i].position = glm::dvec3(place_point(p->points[i].position, mirror, shift, mirror_x));
        out.push_back(std::move(op));
    }
    return out;
}

bool SessionBuilder::copy_at_tip(const InputAction& a)
{
    const bool mirror = a.type == InputAction::Type::Mirror;
    const char* what = action_name(a.type);
    const std::string prefix = when(what, a.time);
    auto nothing = [&](const std::string& why) {
        messages_.push_back(prefix + why);
        return false;
    };
    if (!a.tip) return nothing("no hand was tracked");
    const glm::dvec3 tip(*a.tip);
    const std::vector<Stroke> view = this->view();
    const double mirror_x = mirror ? trunk_base_x(view) : 0.0;
    auto copy_of = [&](const Stroke& s, const glm::dvec3& shift) {
        Stroke c = s;
        c.id = next_stroke_id_++;
        for (StrokePoint& p : c.points) p.position = place_point(p.position, mirror, shift, mirror_x);
        return c;
    };

    const LobePick pick = pick_lobe(doc_, view, tip, pick_.lobe_pick_distance_m, hooks_);
    if (pick.lobe) {
        const LobeRecord source = *pick.lobe;
        const glm::dvec3 shift(2.0 * pick.radius + kDuplicateGapM, 0.0, 0.0);
        std::string note;
        std::vector<EditOperation> deforms = placed_deforms(source, mirror, shift, mirror_x, note);
        if (std::string why = over_limits(doc_, source.stroke_ids.size(), 1, deforms.size()); !why.empty())
            return nothing(why);
        snapshot();
        LobeRecord copy = source;
        copy.id = next_lobe_id_++;
        copy.stroke_ids.clear();
        copy.mesh_file.clear();
        if (source.model) {
            // The mesh where the person sees it, placed; a mirror image turns its triangles
            // over so that they still face outwards.
            TriangleMesh m = hooks_.model_in_stage ? hooks_.model_in_stage(doc_, source) : source.model->mesh;
            for (glm::vec3& p : m.positions) p = place_point(p, mirror, shift, mirror_x);
            if (mirror)
                for (std::array<int, 3>& t : m.triangles) std::swap(t[1], t[2]);
            copy.model = std::make_shared<const LobeModel>(LobeModel{source.model->source, std::move(m)});
        }
        for (std::int64_t id : source.stroke_ids)
            if (const Stroke* s = find_stroke(view, id)) {
                doc_.strokes.push_back(copy_of(*s, shift));
                copy.stroke_ids.push_back(doc_.strokes.back().id);
            }
        for (EditOperation& op : deforms) {
            op.id = next_edit_id_++;
            op.target = copy.id;
            doc_.edits.push_back(std::move(op));
        }
        if (!note.empty())
            messages_.push_back(std::string(what) + " of lobe " + std::to_string(source.id) + " as lobe " +
                                std::to_string(copy.id) + ": its pinch deforms were not copied: " + note);
        doc_.lobes.push_back(std::move(copy));
        return true;
    }
    double d = 0.0;
    const Stroke* s = nearest_stroke(view, tip, d, StrokeKind::Trunk);
    if (!s || d > pick_.stroke_pick_distance_m) {
        std::string why = std::isfinite(pick.nearest_any)
                              ? "the fingertip is outside every lobe and " + cm(pick.nearest_any) +
                                    " from the nearest lobe stroke (pick distance " + cm(pick_.lobe_pick_distance_m) + ")"
                              : std::string("there are no lobes");
        why += s ? ", and " + cm(d) + " from the nearest trunk stroke (pick distance " +
                       cm(pick_.stroke_pick_distance_m) + ")"
                 : ", and there are no trunk strokes";
        return nothing(why);
    }
    const Stroke source = *s;
    if (std::string why = over_limits(doc_, 1, 0, 0); !why.empty()) return nothing(why);
    snapshot();
    doc_.strokes.push_back(copy_of(source, glm::dvec3(kTrunkCopyOffsetM, 0.0, 0.0)));
    return true;
}

namespace {

/// A whole-tree appearance setting (leaf width, leaf and bark colour, pipe exponent, tip
/// radius) into `s`: a colour packed as pack_color (input/recording.h), a number checked
/// against the settings table. Returns why it is refused, or "".
/// \throw InvalidInput from the table's checks.
std::string apply_tree_appearance(Settings& s, const SettingInfo& setting, double v, const SettingRange& accepts)
{
    if (setting.type == SettingType::Color) {
        if (!(v >= accepts.lo && v <= accepts.hi && v == std::floor(v)))
            return "a colour must be a whole number from 0 to 16777215 (0xRRGGBB)";
        double rgb[3];
        unpack_color(static_cast<int>(v), rgb);
        set_setting(s, setting, std::array<double, 3>{rgb[0], rgb[1], rgb[2]});
        return "";
    }
    Settings probe = s;
    set_setting(probe, setting, v);
    validate_settings(probe);
    s = std::move(probe);
    return "";
}

} // namespace

bool SessionBuilder::apply_setting(const InputAction& a)
{
    const SettingChange& c = a.setting;
    const char* name = setting_name(c.id);
    const std::string label = name ? std::string("setting ") + name : "setting";
    auto refuse = [&](const std::string& why) {
        messages_.push_back(when(label.c_str(), a.time) + why);
        return false;
    };
    // What the panels change, and what each accepts: app/session/panel_controls.h.
    const PanelControl* control = find_panel_control(c.id);
    if (!name || !control) return refuse("unknown setting id " + std::to_string(static_cast<std::int32_t>(c.id)));
    const double v = c.value;
    if (!std::isfinite(v)) return refuse("the value is not a finite number");
    const SettingRange accepts = control->accepts();
    // Whole numbers the control accepts (an integer setting's range is checked by the table).
    auto whole = [&](double lo, double hi) { return v >= lo && v <= hi && v == std::floor(v); };
    const SettingInfo* setting = control->setting();

    Settings s = doc_.settings;
    std::uint64_t seed = doc_.seed;
    LobeRecord* lobe = nullptr;
    LobeRecord lobe_after; // the lobe's overrides after this setting
    std::optional<GrowerChoice> grower_after; // the scene's grower, when this setting picks another
    if (c.lobe != 0) {
        if (control->tree_wide_only)
            return refuse(std::string(name) + " is a tree-wide setting (lobe " + std::to_string(c.lobe) +
                          " given): " + control->tree_wide_only);
        for (LobeRecord& l : doc_.lobes)
            if (l.id == c.lobe) lobe = &l;
        if (!lobe) return refuse("there is no lobe " + std::to_string(c.lobe));
        lobe_after = *lobe;
    }
    try {
        switch (c.id) {
        case SettingId::SplitAngle: {
            Settings probe = s;
            set_setting(probe, *setting, v);
            validate_settings_section(probe, "growth");
            if (lobe) lobe_after.split_angle_deg = v;
            else s = std::move(probe);
            break;
        }
        case SettingId::AttractorSpacing:
            set_setting(s, *setting, v);
            validate_settings(s);
            break;
        case SettingId::LeafLength: {
            Settings probe = s;
            LeafSettings& l = probe.leaves;
            const double ratio = l.width_m / l.length_m;
            set_setting(probe, *setting, v);
            l.width_m = v * ratio;
            validate_settings_section(probe, "leaves");
            if (lobe) lobe_after.leaf_length_m = v;
            else s.leaves = l;
            break;
        }
        case SettingId::LeavesPerNode: {
            if (!whole(-1e9, 1e9)) return refuse("leaves per node must be a whole number");
            Settings probe = s;
            set_setting(probe, *setting, static_cast<int>(v));
            validate_settings_section(probe, "leaves");
            if (lobe) lobe_after.leaves_per_node = probe.leaves.per_node;
            else s.leaves = probe.leaves;
            break;
        }
        case SettingId::Species: {
            if (!whole(accepts.lo, accepts.hi)) {
                std::string names;
                for (int i = 0; i < kSettingSpeciesCount; ++i) names += (i ? ", " : "") + std::string(kSettingSpecies[i]);
                return refuse("the species index must be " + number_text(accepts.lo) + " to " + number_text(accepts.hi) +
                              " (" + names + ")");
            }
            const std::string chosen = kSettingSpecies[static_cast<int>(v)];
            if (lobe) {
                lobe_after.species = chosen;
            } else if (hooks_.apply_species) {
                const std::string why = hooks_.apply_species(s, chosen);
                if (!why.empty()) return refuse(why);
            } else {
                set_setting(s, *setting, chosen);
            }
            break;
        }
        case SettingId::Grower: {
            const Grower* chosen = nullptr;
            for (const Grower* g : growers())
                if (whole(accepts.lo, accepts.hi) && g->panel_code() == static_cast<int>(v)) chosen = g;
            if (!chosen) return refuse("no grower has panel code " + number_text(v) + " (growers: " + grower_names() + ")");
            if (chosen->name() != scene_grower(doc_).name) {
                GrowerChoice choice;
                choice.name = chosen->name();
                choice.version = chosen->version();
                grower_after = std::move(choice);
            }
            break;
        }
        case SettingId::GrowthSteps: {
            // The scene grower's steps parameter (growth/grower.h steps_param); 0 removes it
            // (the grower's default).
            const GrowerChoice& now = scene_grower(doc_);
            const Grower* g = find_grower(now.name);
            if (!g || g->steps_param().empty())
                return refuse("the " + now.name + " grower does not grow in steps");
            if (!whole(accepts.lo, accepts.hi))
                return refuse("the growth steps must be a whole number from " + number_text(accepts.lo) + " to " +
                              number_text(accepts.hi) + " (0: the grower's default)");
            GrowerChoice choice = now;
            const std::string param(g->steps_param());
            if (v == 0.0) choice.params.erase(param);
            else choice.params[param] = static_cast<std::int64_t>(v);
            g->check_params(choice, "grower");
            if (choice != now) grower_after = std::move(choice);
            break;
        }
        case SettingId::LeafWidth:
        case SettingId::PipeExponent:
        case SettingId::TipRadius:
        case SettingId::LeafColor:
        case SettingId::BarkColor:
            if (const std::string why = apply_tree_appearance(s, *setting, v, accepts); !why.empty()) return refuse(why);
            break;
        case SettingId::Seed:
            if (!whole(accepts.lo, accepts.hi))
                return refuse("the seed must be a whole number from " + number_text(accepts.lo) + " to " +
                              number_text(accepts.hi));
            if (lobe) lobe_after.seed = static_cast<std::uint64_t>(v);
            else seed = static_cast<std::uint64_t>(v);
            break;
        }
    } catch (const InvalidInput& e) {
        return refuse(e.what());
    }
    const bool lobe_changed = lobe && (lobe_after.split_angle_deg != lobe->split_angle_deg ||
                                       lobe_after.species != lobe->species ||
                                       lobe_after.leaf_length_m != lobe->leaf_length_m ||
                                       lobe_after.leaves_per_node != lobe->leaves_per_node || lobe_after.seed != lobe->seed);
    const bool changed = seed != doc_.seed || !settings_equal(s, doc_.settings) || lobe_changed || grower_after;
    if (!changed) return false;
    // A slider being dragged: one undo step for the whole run.
    const bool merge = setting_run_ && setting_run_->first == c.id && setting_run_->second == c.lobe && !undo_.empty();
    if (!merge) snapshot();
    doc_.settings = std::move(s);
    doc_.seed = seed;
    if (lobe) *lobe = std::move(lobe_after);
    if (grower_after) set_scene_grower(doc_, std::move(*grower_after));
    setting_run_ = std::make_pair(c.id, c.lobe);
    return true;
}

bool SessionBuilder::import_mesh(const InputAction& a)
{
    const std::string prefix = when(action_name(a.type), a.time);
    auto nothing = [&](const std::string& why) {
        messages_.push_back(prefix + why);
        return false;
    };
    if (!hooks_.import_model) return nothing("this session cannot read imported meshes");
    if (std::string why = over_limits(doc_, 0, 1, 0); !why.empty()) return nothing(why);
    std::shared_ptr<const LobeModel> model;
    try {
        model = hooks_.import_model(a.import_number);
    } catch (const Error& e) {
        return nothing(e.what());
    }
    if (!model || model->mesh.triangles.empty() || model->mesh.positions.empty())
        return nothing("import " + std::to_string(a.import_number) + " holds no mesh");
    // Centred on the fingertip; with no hand tracked, standing on the trunk's side of the
    // origin as `grow MESH` places it: lowest point half its height above the ground.
    TriangleMesh mesh = model->mesh;
    const glm::dvec3 centre = model_centre(mesh);
    glm::dvec3 target;
    if (a.tip) {
        target = glm::dvec3(*a.tip);
    } else {
        double lo = std::numeric_limits<double>::infinity(), hi = -lo;
        for (const glm::vec3& p : mesh.positions) {
            lo = std::min(lo, static_cast<double>(p.y));
            hi = std::max(hi, static_cast<double>(p.y));
        }
        target = glm::dvec3(0.0, (hi - lo), 0.0);
    }
    for (glm::vec3& p : mesh.positions) p = glm::vec3(glm::dvec3(p) - centre + target);
    // What the session could not save and load again is not taken in.
    LobeModel placed{model->source, std::move(mesh)};
    try {
        validate_lobe_model(placed, "import " + std::to_string(a.import_number));
    } catch (const InvalidInput& e) {
        return nothing(e.what());
    }
    snapshot();
    LobeRecord r = LobeRecord::of_strokes(next_lobe_id_++);
    r.model = std::make_shared<const LobeModel>(std::move(placed));
    doc_.lobes.push_back(std::move(r));
    return true;
}

void SessionBuilder::apply(const std::vector<InputAction>& actions)
{
    for (const InputAction& a : actions) apply(a);
}

} // namespace lobe
