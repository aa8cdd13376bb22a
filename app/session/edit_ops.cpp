#include "app/session/edit_ops.h"

#include <cmath>
#include <map>
#include <optional>
#include <set>

#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

#include "core/errors.h"
#include "meshing/polyline.h"
#include "meshing/sampling.h"

namespace lobe {

namespace {

/// The path's points in the precision the meshing stage works in.
std::vector<glm::vec3> path_positions(const EditOperation& op)
{
    std::vector<glm::vec3> out;
    out.reserve(op.path.size());
    for (const DragPoint& p : op.path) out.emplace_back(p.position);
    return out;
}

std::optional<LobeTransformKind> transform_kind(EditKind kind)
{
    switch (kind) {
    case EditKind::MoveLobe: return LobeTransformKind::Move;
    case EditKind::RotateLobe: return LobeTransformKind::Rotate;
    case EditKind::ScaleLobe: return LobeTransformKind::Scale;
    case EditKind::DeformLobe:
    case EditKind::EditStroke: break;
    }
    return std::nullopt;
}

/// Throws the problem edit_operation_problem finds in `op`. A document read from a file
/// holds none (document_from_json refuses them); an operation made in code may.
void require_well_formed(const EditOperation& op)
{
    if (std::string why = edit_operation_problem(op); !why.empty()) throw InvalidInput(why);
}

void report(std::vector<SkippedEdit>* skipped, const EditOperation& op, const std::string& why)
{
    if (skipped)
        skipped->push_back({op.id, "edit " + std::to_string(op.id) + " (" + edit_kind_name(op.kind()) + "): " + why});
}

/// A transform operation made ready to compose.
struct TransformOp {
    std::size_t index = 0; ///< position in Document::edits
    std::int64_t lobe = 0;
    glm::dmat4 matrix{1.0};
    std::optional<std::set<std::int64_t>> strokes;
};

/// The valid transform operations among the first `edit_count`, in order; the others are
/// reported.
std::vector<TransformOp> transform_ops(const Document& doc, std::size_t edit_count, const EditApplyOptions& options,
                                       std::vector<SkippedEdit>* skipped)
{
    std::set<std::int64_t> lobes;
    for (const LobeRecord& l : doc.lobes) lobes.insert(l.id);
    std::vector<TransformOp> out;
    for (std::size_t i = 0; i < doc.edits.size() && i < edit_count; ++i) {
        const EditOperation& op = doc.edits[i];
        const auto kind = transform_kind(op.kind());
        if (!kind) continue;
        try {
            if (!lobes.count(op.target)) throw InvalidInput("no lobe " + std::to_string(op.target));
            require_well_formed(op);
            const LobeTransformParams& p = *op.transform_params();
            TransformOp t;
            t.index = i;
            t.lobe = op.target;
            t.matrix = drag_transform(*kind, path_positions(op), p.centre.value_or(glm::dvec3(0.0)), options.transform);
            if (p.strokes) t.strokes.emplace(p.strokes->begin(), p.strokes->end());
            out.push_back(std::move(t));
        } catch (const InvalidInput& e) {
            report(skipped, op, e.what());
        }
    }
    return out;
}

glm::vec3 map_point(const glm::dmat4& m, const glm::vec3& p) { return glm::vec3(m * glm::dvec4(glm::dvec3(p), 1.0)); }

bool is_identity(const glm::dmat4& m) { return m == glm::dmat4(1.0); }

} // namespace

bool stroke_edit_closed(const Stroke& stroke)
{
    if (stroke.closed) return true;
    try {
        return is_closed_stroke(stroke_positions(stroke));
    } catch (const InvalidInput&) {
        return false;
    }
}

std::vector<Stroke> edited_strokes(const Document& doc, const EditApplyOptions& options,
                                   std::vector<SkippedEdit>* skipped)
{
    std::vector<Stroke> strokes = doc.strokes;
    std::map<std::int64_t, std::size_t> stroke_at;
    for (std::size_t i = 0; i < strokes.size(); ++i) stroke_at.emplace(strokes[i].id, i);
    // The lobe of each stroke (the first that lists it).
    std::map<std::int64_t, std::int64_t> lobe_of;
    std::map<std::int64_t, const LobeRecord*> lobe_at;
    for (const LobeRecord& l : doc.lobes) {
        lobe_at.emplace(l.id, &l);
        for (std::int64_t s : l.stroke_ids) lobe_of.emplace(s, l.id);
    }

    const std::vector<TransformOp> transforms = transform_ops(doc, doc.edits.size(), options, skipped);

    // Strokes drawn into a lobe after some of its transforms were drawn where the lobe was
    // then: take them back to the lobe's frame through those transforms.
    std::map<std::int64_t, glm::dmat4> before_drawn;
    for (const TransformOp& t : transforms) {
        if (!t.strokes) continue; // no list: the transform applies to every stroke of the lobe
        for (std::int64_t s : lobe_at.at(t.lobe)->stroke_ids)
            if (!t.strokes->count(s) && lobe_of.at(s) == t.lobe) {
                auto [it, fresh] = before_drawn.emplace(s, glm::dmat4(1.0));
                it->second = t.matrix * it->second;
            }
    }
    for (const auto& [id, m] : before_drawn) {
        auto at = stroke_at.find(id);
        if (at == stroke_at.end()) continue;
        const glm::dmat4 inv = glm::inverse(m);
        for (StrokePoint& p : strokes[at->second].points) p.position = map_point(inv, p.position);
    }

    // Closedness as drawn: edits do not change whether a stroke is a loop.
    std::map<std::int64_t, bool> closed;
    std::map<std::int64_t, glm::dmat4> lobe_now; // each lobe's transform so far
    std::size_t next_transform = 0;
    for (std::size_t i = 0; i < doc.edits.size(); ++i) {
        const EditOperation& op = doc.edits[i];
        if (next_transform < transforms.size() && transforms[next_transform].index == i) {
            const TransformOp& t = transforms[next_transform++];
            auto [it, fresh] = lobe_now.emplace(t.lobe, glm::dmat4(1.0));
            it->second = t.matrix * it->second;
            continue;
        }
        const EditStrokeParams* d = op.stroke_params();
        if (!d) continue;
        try {
            auto at = stroke_at.find(op.target);
            if (at == stroke_at.end()) throw InvalidInput("no stroke " + std::to_string(op.target));
            require_well_formed(op);
            Stroke& stroke = strokes[at->second];
            auto c = closed.find(stroke.id);
            if (c == closed.end()) c = closed.emplace(stroke.id, stroke_edit_closed(doc.strokes[at->second])).first;

            StrokeEditOptions o = options.stroke;
            if (d->pick_distance_m) o.pick_distance_m = *d->pick_distance_m;
            if (d->half_length_m) o.half_length_m = *d->half_length_m;
            StrokeDrag drag{glm::vec3(op.path.front().position), glm::vec3(op.path.back().position), std::nullopt};
            if (d->other_tip) drag.other_tip = glm::vec3(*d->other_tip);
            // The drag was made in stage space: take it to the lobe's frame, with lengths.
            auto lobe = lobe_of.find(stroke.id);
            auto now = lobe == lobe_of.end() ? lobe_now.end() : lobe_now.find(lobe->second);
            if (now != lobe_now.end() && !is_identity(now->second)) {
                const glm::dmat4 inv = glm::inverse(now->second);
                const double s = similarity_scale(now->second);
                drag.start = map_point(inv, drag.start);
                drag.end = map_point(inv, drag.end);
                if (drag.other_tip) drag.other_tip = map_point(inv, *drag.other_tip);
                o.pick_distance_m /= s;
                o.half_length_m /= s;
            }
            // Replay tolerance: the pick was checked in stage space when the edit was made;
            // rounding through the frames must not turn it away now.
            o.pick_distance_m *= 1.0 + 1e-6;
            o.pick_distance_m += 1e-7;
            edit_stroke(stroke, c->second, drag, o);
        } catch (const InvalidInput& e) {
            report(skipped, op, e.what());
        }
    }
    return strokes;
}

glm::dmat4 lobe_transform(const Document& doc, std::int64_t lobe_id, std::size_t edit_count,
                          const EditApplyOptions& options, std::vector<SkippedEdit>* skipped)
{
    glm::dmat4 m(1.0);
    for (const TransformOp& t : transform_ops(doc, edit_count, options, skipped))
        if (t.lobe == lobe_id) m = t.matrix * m;
    return m;
}

std::vector<Stroke> effective_strokes(const Document& doc, const EditApplyOptions& options,
                                      std::vector<SkippedEdit>* skipped)
{
    std::vector<Stroke> strokes = edited_strokes(doc, options, skipped);
    std::map<std::int64_t, std::size_t> stroke_at;
    for (std::size_t i = 0; i < strokes.size(); ++i) stroke_at.emplace(strokes[i].id, i);
    std::map<std::int64_t, glm::dmat4> lobes;
    for (const TransformOp& t : transform_ops(doc, doc.edits.size(), options, nullptr)) {
        auto [it, fresh] = lobes.emplace(t.lobe, glm::dmat4(1.0));
        it->second = t.matrix * it->second;
    }
    std::set<std::int64_t> done;
    for (const LobeRecord& l : doc.lobes) {
        auto m = lobes.find(l.id);
        if (m == lobes.end()) continue;
        for (std::int64_t s : l.stroke_ids) {
            auto at = stroke_at.find(s);
            if (at == stroke_at.end() || !done.insert(s).second) continue;
            for (StrokePoint& p : strokes[at->second].points) p.position = map_point(m->second, p.position);
        }
    }
    return strokes;
}

std::string check_edit_operation(const Document& doc, const EditOperation& op, const EditApplyOptions& options)
{
    if (op.kind() == EditKind::DeformLobe) return {};
    Document with = doc;
    with.edits.push_back(op);
    std::vector<SkippedEdit> skipped;
    if (op.kind() == EditKind::EditStroke) edited_strokes(with, options, &skipped);
    else lobe_transform(with, op.target, with.edits.size(), options, &skipped);
    // Only the new operation's fate matters (earlier ones were reported when they were
    // made); being the last operation, it is reported last.
    if (skipped.empty() || skipped.back().id != op.id) return {};
    // The operation is not in any document yet: the reason without "edit N (type): ".
    const std::string prefix = "edit " + std::to_string(op.id) + " (" + edit_kind_name(op.kind()) + "): ";
    const std::string& m = skipped.back().message;
    return m.rfind(prefix, 0) == 0 ? m.substr(prefix.size()) : m;
}

} // namespace lobe
