#include "input/session_builder.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include <glm/geometric.hpp>

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

nlohmann::json point_json(const glm::dvec3& p) { return nlohmann::json::array({p.x, p.y, p.z}); }

const Stroke* find_stroke(const std::vector<Stroke>& strokes, std::int64_t id)
{
    for (const Stroke& s : strokes)
        if (s.id == id) return &s;
    return nullptr;
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
}

namespace {

/// Smallest distance between (up to 256 evenly spread) points of `stroke` and (up to 4,096)
/// points of the lobe's strokes; also the lobe's radius around the centroid of its points.
void lobe_distance(const Document& doc, const LobeRecord& lobe, const Stroke& stroke, double& distance, double& radius)
{
    std::vector<glm::vec3> pts;
    for (std::int64_t id : lobe.stroke_ids)
        for (const Stroke& s : doc.strokes)
            if (s.id == id)
                for (const StrokePoint& p : s.points) pts.push_back(p.position);
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

void SessionBuilder::add_stroke(const Stroke& stroke)
{
    doc_.strokes.push_back(stroke);
    if (stroke.kind != StrokeKind::Lobe) return;
    // A stroke joins the lobe it is drawn into: the current lobe when it comes near it, else
    // the nearest lobe it comes near; far from every lobe (or after "new lobe") it starts one.
    LobeRecord* target = nullptr;
    if (!new_lobe_pending_ && !doc_.lobes.empty()) {
        auto near = [&](const LobeRecord& l, double& d) {
            double radius = 0;
            lobe_distance(doc_, l, stroke, d, radius);
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
    if (!target) {
        doc_.lobes.push_back(LobeRecord{next_lobe_id_++, {}, {}, std::nullopt, {}});
        target = &doc_.lobes.back();
    }
    new_lobe_pending_ = false;
    target->stroke_ids.push_back(stroke.id);
}

void SessionBuilder::snapshot()
{
    undo_.push_back(doc_);
    if (undo_.size() > kMaxUndo) undo_.erase(undo_.begin());
    redo_.clear();
}

bool SessionBuilder::add_drag(const InputAction& a)
{
    const Drag& drag = a.drag;
    const std::string tool = tool_name(drag.tool);
    auto nothing = [&](const std::string& why) {
        char when[96];
        std::snprintf(when, sizeof when, "%s drag at t=%.2fs edits nothing: ", tool.c_str(),
                      drag.path.empty() ? a.time : drag.path.front().time);
        messages_.push_back(when + why);
        return false;
    };
    if (drag.path.empty()) return nothing("it has no points");
    if (drag.tool == Tool::DrawLobe || drag.tool == Tool::DrawTrunk) return nothing("not an editing tool");
    const glm::dvec3 start(drag.path.front().position);
    const std::vector<Stroke> view = hooks_.current_strokes ? hooks_.current_strokes(doc_) : doc_.strokes;

    EditOperation op;
    op.id = next_edit_id_;
    op.type = "drag:" + tool;
    nlohmann::json path = nlohmann::json::array();
    for (const StrokePoint& p : drag.path) path.push_back({p.position.x, p.position.y, p.position.z, p.time});
    op.params = {{"hand", hand_name(drag.hand)}, {"path", std::move(path)}};

    if (drag.tool == Tool::EditStroke) {
        // The stroke with the point nearest to the drag start (the first on a tie).
        const Stroke* best = nullptr;
        double best_d = std::numeric_limits<double>::infinity();
        for (const Stroke& s : view) {
            const double d = distance_to_stroke(s, start);
            if (d < best_d) {
                best_d = d;
                best = &s;
            }
        }
        if (!best) return nothing("there are no strokes");
        if (best_d > pick_.stroke_pick_distance_m)
            return nothing("its start is " + cm(best_d) + " from the nearest stroke (pick distance " +
                           cm(pick_.stroke_pick_distance_m) + ")");
        if (drag.other_tip) {
            const double d = distance_to_stroke(*best, glm::dvec3(*drag.other_tip));
            if (d > pick_.stroke_pick_distance_m)
                return nothing("the pointing fingertip is " + cm(d) + " from stroke " + std::to_string(best->id) +
                               " (pick distance " + cm(pick_.stroke_pick_distance_m) + ")");
            op.params["other_tip"] = point_json(glm::dvec3(*drag.other_tip));
        }
        op.target = best->id;
        op.params["pick_distance_m"] = pick_.stroke_pick_distance_m;
        op.params["half_length_m"] = pick_.stroke_half_length_m;
    } else {
        // Lobe tools: the lobe whose strokes are nearest the drag start, among those it is
        // near or inside.
        const LobeRecord* best = nullptr;
        double best_d = std::numeric_limits<double>::infinity(), nearest_any = best_d;
        glm::dvec3 best_centre(0.0);
        for (const LobeRecord& lobe : doc_.lobes) {
            glm::dvec3 c;
            if (!lobe_centre(lobe, view, c)) continue;
            double d = std::numeric_limits<double>::infinity(), radius = 0.0;
            for (std::int64_t id : lobe.stroke_ids)
                if (const Stroke* s = find_stroke(view, id)) {
                    d = std::min(d, distance_to_stroke(*s, start));
                    for (const StrokePoint& p : s->points) radius = std::max(radius, glm::distance(glm::dvec3(p.position), c));
                }
            nearest_any = std::min(nearest_any, d);
            const bool near = d <= pick_.lobe_pick_distance_m || glm::distance(start, c) <= radius;
            if (near && d < best_d) {
                best_d = d;
                best = &lobe;
                best_centre = c;
            }
        }
        if (!best) {
            if (!std::isfinite(nearest_any)) return nothing("there are no lobes");
            return nothing("its start is outside every lobe and " + cm(nearest_any) +
                           " from the nearest lobe stroke (pick distance " + cm(pick_.lobe_pick_distance_m) + ")");
        }
        op.target = best->id;
        if (drag.tool == Tool::MoveLobe || drag.tool == Tool::RotateLobe || drag.tool == Tool::ScaleLobe) {
            op.params["centre"] = point_json(best_centre);
            op.params["strokes"] = best->stroke_ids;
        }
    }
    if (hooks_.check) {
        const std::string why = hooks_.check(doc_, op);
        if (!why.empty()) return nothing(why);
    }
    snapshot();
    ++next_edit_id_;
    doc_.edits.push_back(std::move(op));
    return true;
}

bool SessionBuilder::apply(const InputAction& a)
{
    switch (a.type) {
    case InputAction::Type::StrokeCompleted:
        snapshot();
        add_stroke(a.stroke);
        return true;
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
    case InputAction::Type::StrokeDiscarded:
    case InputAction::Type::ToolChanged:
    case InputAction::Type::Grow:
        return false;
    }
    return false;
}

void SessionBuilder::apply(const std::vector<InputAction>& actions)
{
    for (const InputAction& a : actions) apply(a);
}

} // namespace lobe
