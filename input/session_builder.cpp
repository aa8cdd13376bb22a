#include "input/session_builder.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/geometric.hpp>

namespace lobe {

namespace {
// Undo depth: a document snapshot per change; sessions have tens to hundreds of changes.
constexpr std::size_t kMaxUndo = 256;
} // namespace

SessionBuilder::SessionBuilder(Document doc) : doc_(std::move(doc))
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
        doc_.lobes.push_back(LobeRecord{next_lobe_id_++, {}, {}});
        target = &doc_.lobes.back();
    }
    new_lobe_pending_ = false;
    target->stroke_ids.push_back(stroke.id);
}

bool SessionBuilder::apply(const InputAction& a)
{
    auto snapshot = [&] {
        undo_.push_back(doc_);
        if (undo_.size() > kMaxUndo) undo_.erase(undo_.begin());
        redo_.clear();
    };
    switch (a.type) {
    case InputAction::Type::StrokeCompleted:
        snapshot();
        add_stroke(a.stroke);
        return true;
    case InputAction::Type::DragCompleted: {
        snapshot();
        EditOperation op;
        op.id = next_edit_id_++;
        op.type = std::string("drag:") + tool_name(a.drag.tool);
        op.target = 0; // resolved against the lobes/strokes when the edit is applied
        nlohmann::json path = nlohmann::json::array();
        for (const StrokePoint& p : a.drag.path) path.push_back({p.position.x, p.position.y, p.position.z, p.time});
        op.params = {{"hand", hand_name(a.drag.hand)}, {"path", std::move(path)}};
        doc_.edits.push_back(std::move(op));
        return true;
    }
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
