// Lives in lobe_meshing_cgal (hence the name): it builds lobe surfaces and remeshes them.
#include "app/session/lobe_document.h"

#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <utility>

#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

#include "core/errors.h"
#include "core/settings_table.h"
#include "app/session/edit_ops.h"
#include "meshing/laplacian_edit.h"
#include "app/session/lobe_cache.h"
#include "app/session/stage_options.h"
#include "meshing/lobe_remesh.h"
#include "meshing/lobe_transform.h"
#include "meshing/mesh_quality.h"
#include "meshing/remesh.h"
#include "meshing/repair.h"

namespace lobe {

namespace {

const Stroke* find_stroke(const std::vector<Stroke>& strokes, std::int64_t id)
{
    for (const Stroke& s : strokes)
        if (s.id == id) return &s;
    return nullptr;
}

/// The start and end of an edit's fingertip path; false when it has none.
bool drag_ends(const EditOperation& op, glm::vec3& from, glm::vec3& to)
{
    if (op.path.empty()) return false;
    auto point = [](const DragPoint& p, glm::vec3& out) {
        for (int k = 0; k < 3; ++k)
            if (!(std::abs(p.position[k]) <= 1e30)) return false; // not finite, or beyond what a float holds
        out = glm::vec3(p.position);
        return true;
    };
    return point(op.path.front(), from) && point(op.path.back(), to);
}

double nearest_vertex_distance(const TriangleMesh& mesh, const glm::vec3& p)
{
    double best = std::numeric_limits<double>::infinity();
    for (const glm::vec3& v : mesh.positions) best = std::min(best, static_cast<double>(glm::distance(v, p)));
    return best;
}

/// A pinch edit in the frame the mesh is in: `frame` maps that frame to stage space, where
/// the pinch was recorded. Picks the handle nearest the pinch's start.
/// \throw InvalidInput when no vertex is within the pick distance.
struct FramedPinch {
    glm::dmat4 back;          ///< stage space → the mesh's frame
    glm::vec3 from;           ///< the pinch's start in the mesh's frame
    int handle = -1;
    PinchEditOptions options;

    FramedPinch(const Document& doc, const TriangleMesh& mesh, const glm::vec3& stage_from, const glm::dmat4& frame)
        : back(glm::inverse(frame)), from(to_frame(stage_from))
    {
        options = pinch_edit_options(doc.settings);
        handle = pick_handle(mesh, from, pinch_pick_distance_m(doc.settings));
    }
    glm::vec3 to_frame(const glm::vec3& p) const { return glm::vec3(back * glm::dvec4(glm::dvec3(p), 1.0)); }
    /// Where the handle goes for the pinch at `stage_to`.
    glm::vec3 target(const TriangleMesh& rest, const glm::vec3& stage_to) const
    {
        return rest.positions[static_cast<std::size_t>(handle)] + (to_frame(stage_to) - from);
    }
};

/// Applies one pinch edit to `mesh`; false (and a warning) when it cannot be applied.
/// `frame` maps the lobe's own frame to stage space at the time of the edit: the pinch,
/// recorded in stage space, is mapped back into the frame the mesh is in.
bool apply_pinch(const Document& doc, const EditOperation& op, TriangleMesh& mesh, std::vector<std::string>* warnings,
                 const glm::dmat4& frame = glm::dmat4(1.0))
{
    glm::vec3 from, to;
    const std::string who = "edit " + std::to_string(op.id);
    if (!drag_ends(op, from, to)) {
        if (warnings) warnings->push_back(who + ": no fingertip path, skipped");
        return false;
    }
    try {
        const FramedPinch pinch(doc, mesh, from, frame);
        laplacian_deform(mesh, pinch.handle, pinch.target(mesh, to), pinch.options);
    } catch (const InvalidInput& e) {
        if (warnings) warnings->push_back(who + ": " + e.what());
        return false;
    } catch (const SolverError& e) {
        if (warnings) warnings->push_back(who + ": " + e.what());
        return false;
    }
    return true;
}

/// Mean edge length of `mesh` (each interior edge counted twice, which leaves the mean as is).
double mean_edge_length(const TriangleMesh& mesh)
{
    double sum = 0.0;
    std::size_t n = 0;
    for (const std::array<int, 3>& t : mesh.triangles)
        for (int k = 0; k < 3; ++k) {
            sum += glm::distance(mesh.positions[static_cast<std::size_t>(t[static_cast<std::size_t>(k)])],
                                 mesh.positions[static_cast<std::size_t>(t[static_cast<std::size_t>((k + 1) % 3)])]);
            ++n;
        }
    return n ? sum / static_cast<double>(n) : 0.0;
}

/// A lobe imported from a mesh (LobeRecord::model): the mesh as stored, remeshed again
/// (`remesh`: model_lobe_remesh_options) only when the attractor spacing has since moved more
/// than 25 % away from its edge length.
/// \throw InvalidInput when the stored mesh cannot be remeshed (not a 2-manifold).
BuiltLobe model_document_lobe(const LobeRecord& rec, const RemeshOptions& remesh)
{
    BuiltLobe built;
    built.lobe_id = rec.id;
    built.surface.mesh = rec.model->mesh;
    built.surface.mesh.feature_edges.clear();
    glm::dvec3 centre(0.0);
    for (const glm::vec3& p : built.surface.mesh.positions) centre += glm::dvec3(p);
    built.surface.centre = centre / std::max<double>(1.0, static_cast<double>(built.surface.mesh.positions.size()));
    // A session file may hold any triangles: growth needs a closed, consistently oriented surface.
    const MeshQuality q = measure_quality(built.surface.mesh);
    if (!q.closed || !q.manifold || !q.outward)
        throw InvalidInput("its mesh is not a closed, outward-oriented 2-manifold");
    check_encloses_volume(built.surface.mesh, q, "its mesh"); // a sliver passes "volume > 0" by rounding
    const double edge = mean_edge_length(built.surface.mesh);
    const double target = remesh.target_edge_length_m;
    if (remesh.iterations > 0 && (edge < 0.75 * target || edge > 1.25 * target)) {
        built.mesh = remesh_isotropic(built.surface.mesh, remesh);
    } else {
        built.mesh = built.surface.mesh;
    }
    return built;
}

} // namespace

struct LobeBuildCache::Impl {
    /// One entry of a lobe's stroke list: the stroke as edited, or a stroke that is missing.
    struct Step {
        std::int64_t id = 0;
        bool missing = false;
        std::vector<glm::vec3> raw;
        bool operator==(const Step& o) const { return id == o.id && missing == o.missing && raw == o.raw; }
    };
    /// A lobe after its steps: the joined strokes, what joining said, and the remeshed mesh.
    struct Entry {
        std::string key;                   ///< the settings the lobe is built with (lobe_build_key)
        std::vector<Step> steps;
        Lobe lobe;
        std::vector<std::int64_t> accepted;
        std::vector<std::string> warnings; ///< of the steps, in order
        bool remeshed = false;             ///< mesh / remesh_error are those of `steps`
        TriangleMesh mesh;
        std::string remesh_error;
        LobeRemeshCache regions;           ///< the regions `mesh` was remeshed from
    };
    std::map<std::int64_t, Entry> lobes;
};

LobeBuildCache::LobeBuildCache() : impl_(std::make_unique<Impl>()) {}

std::string lobe_build_key(const Settings& settings) { return settings_key(settings, "lobes"); }
LobeBuildCache::~LobeBuildCache() = default;

namespace {

/// Every lobe of `doc`, before pinch edits and transforms; with `cache`, lobes are taken from
/// it or continued where their strokes only grew, and it is left holding this build.
std::vector<BuiltLobe> build_lobes(const Document& doc, std::vector<std::string>* warnings, LobeBuildCache::Impl* cache,
                                   LobeBuildCache::Counts* counts)
{
    using Entry = LobeBuildCache::Impl::Entry;
    using Step = LobeBuildCache::Impl::Step;
    const LobeOptions options = lobe_options(doc.settings);
    const std::string key = lobe_build_key(doc.settings);
    const RemeshOptions remesh = stroke_lobe_remesh_options(doc.settings);
    // Strokes with their stroke edits (Bézier, Fig. 6a) applied, each lobe's in its own frame.
    std::vector<SkippedEdit> skipped;
    const std::vector<Stroke> strokes = edited_strokes(doc, {}, &skipped);
    for (const SkippedEdit& e : skipped)
        if (warnings) warnings->push_back(e.message);
    std::vector<BuiltLobe> out;
    std::set<std::int64_t> seen;
    for (const LobeRecord& rec : doc.lobes) {
        if (rec.model) {
            try {
                out.push_back(model_document_lobe(rec, model_lobe_remesh_options(doc.settings)));
            } catch (const InvalidInput& e) {
                if (warnings) warnings->push_back("lobe " + std::to_string(rec.id) + ": " + e.what() + "; the lobe is left out");
            }
            continue;
        }
        seen.insert(rec.id);
        std::vector<Step> steps;
        for (std::size_t k = 0; k < rec.stroke_ids.size() && k < kMaxStrokesPerLobe; ++k) {
            Step step;
            step.id = rec.stroke_ids[k];
            const Stroke* s = find_stroke(strokes, step.id);
            step.missing = s == nullptr;
            if (s) {
                step.raw.reserve(s->points.size());
                for (const StrokePoint& p : s->points) step.raw.push_back(p.position);
            }
            steps.push_back(std::move(step));
        }
        // The kept state of this lobe when its steps begin this lobe's steps (taken out of the
        // cache while it is worked on: an exception leaves no half-made entry behind).
        Entry work{key, {}, Lobe(options), {}, {}, false, {}, {}, {}};
        if (cache) {
            const auto it = cache->lobes.find(rec.id);
            if (it != cache->lobes.end() && it->second.key == key && it->second.steps.size() <= steps.size() &&
                std::equal(it->second.steps.begin(), it->second.steps.end(), steps.begin())) {
                work = std::move(it->second);
            } else if (it != cache->lobes.end()) {
                // Built again (a stroke edited, undone or moved): the regions of its last
                // remeshing that the change left alone are still good (lobe_remesh.h).
                work.regions = std::move(it->second.regions);
            }
            if (it != cache->lobes.end()) cache->lobes.erase(it);
        }
        const std::size_t from = work.steps.size();
        if (counts) ++(from == steps.size() && work.remeshed ? counts->kept : from > 0 ? counts->continued : counts->built);
        for (std::size_t k = from; k < steps.size(); ++k) {
            const Step& step = steps[k];
            if (step.missing) {
                work.warnings.push_back("lobe " + std::to_string(rec.id) + ": stroke " + std::to_string(step.id) + " is missing");
                continue;
            }
            try {
                work.lobe.add_stroke(step.id, step.raw);
                work.accepted.push_back(step.id);
            } catch (const InvalidInput& e) {
                work.warnings.push_back("lobe " + std::to_string(rec.id) + ": " + e.what() +
                                        "; the stroke is left out of the lobe");
            }
        }
        if (from < steps.size()) work.remeshed = false;
        work.steps = std::move(steps);
        if (warnings) {
            warnings->insert(warnings->end(), work.warnings.begin(), work.warnings.end());
            if (rec.stroke_ids.size() > kMaxStrokesPerLobe)
                warnings->push_back("lobe " + std::to_string(rec.id) + ": " +
                                    std::to_string(rec.stroke_ids.size() - kMaxStrokesPerLobe) + " strokes beyond the first " +
                                    std::to_string(kMaxStrokesPerLobe) + " are left out");
        }
        auto keep = [&] {
            if (cache) cache->lobes.insert_or_assign(rec.id, std::move(work));
        };
        if (work.lobe.empty()) {
            keep();
            continue;
        }
        BuiltLobe built;
        built.lobe_id = rec.id;
        built.stroke_ids = work.accepted;
        built.surface = work.lobe.surface();
        if (remesh.iterations > 0) {
            if (!work.remeshed) {
                try {
                    LobeRemeshStats stats;
                    work.mesh = remesh_lobe_surface(built.surface, remesh, cache ? &work.regions : nullptr, &stats);
                    work.remesh_error.clear();
                    if (counts) {
                        counts->regions_remeshed += static_cast<std::size_t>(stats.whole ? stats.regions : stats.remeshed);
                        counts->regions_reused += static_cast<std::size_t>(stats.reused);
                    }
                } catch (const InvalidInput& e) {
                    // Too large for the spacing (kMaxRemeshTriangles), or a surface remeshing refuses.
                    work.mesh = TriangleMesh{};
                    work.remesh_error = e.what();
                }
                work.remeshed = true;
            }
            if (!work.remesh_error.empty()) {
                if (warnings)
                    warnings->push_back("lobe " + std::to_string(rec.id) + ": " + work.remesh_error + "; the lobe is left out");
                keep();
                continue;
            }
            built.mesh = work.mesh;
        } else {
            built.mesh = built.surface.mesh;
        }
        keep();
        out.push_back(std::move(built));
    }
    if (cache)
        for (auto it = cache->lobes.begin(); it != cache->lobes.end();)
            it = seen.count(it->first) ? std::next(it) : cache->lobes.erase(it);
    return out;
}

/// Pinch edits, then moves, rotations and scales, on lobes as build_lobes made them.
std::vector<BuiltLobe> finish_lobes(const Document& doc, std::vector<BuiltLobe> out, std::vector<std::string>* warnings)
{
    // Edits in document order. A pinch edit goes to its target lobe, or (no target) to the
    // lobe with a vertex nearest the pinch.
    for (std::size_t k = 0; k < doc.edits.size(); ++k) {
        const EditOperation& op = doc.edits[k];
        if (op.kind() != EditKind::DeformLobe) continue;
        BuiltLobe* target = nullptr;
        if (op.target > 0) {
            for (BuiltLobe& b : out)
                if (b.lobe_id == op.target) target = &b;
        } else {
            glm::vec3 from, to;
            if (drag_ends(op, from, to)) {
                double best = std::numeric_limits<double>::infinity();
                for (BuiltLobe& b : out) {
                    const double d = nearest_vertex_distance(b.mesh, from);
                    if (d < best) {
                        best = d;
                        target = &b;
                    }
                }
            }
        }
        if (!target) {
            if (warnings) warnings->push_back("edit " + std::to_string(op.id) + ": no lobe to edit, skipped");
            continue;
        }
        if (apply_pinch(doc, op, target->mesh, warnings, lobe_transform(doc, target->lobe_id, k)))
            ++target->edits_applied;
    }
    // Move, rotate and scale (in document order) take each lobe to where the person put it.
    // Scales compose: many of them could take a lobe anywhere, so a lobe that ends up beyond
    // kMaxStrokeCoordinateM (or not finite) is left out, as its strokes would be.
    std::vector<BuiltLobe> placed;
    placed.reserve(out.size());
    for (BuiltLobe& b : out) {
        const glm::dmat4 t = lobe_transform(doc, b.lobe_id);
        if (t != glm::dmat4(1.0)) transform_mesh(b.mesh, t);
        bool inside = true;
        for (const glm::vec3& p : b.mesh.positions)
            for (int k = 0; k < 3; ++k) inside = inside && std::abs(p[k]) <= static_cast<float>(kMaxStrokeCoordinateM);
        if (!inside) {
            if (warnings)
                warnings->push_back("lobe " + std::to_string(b.lobe_id) + ": its moves and scales take it beyond " +
                                    std::to_string(static_cast<int>(kMaxStrokeCoordinateM)) +
                                    " m from the origin; the lobe is left out");
            continue;
        }
        placed.push_back(std::move(b));
    }
    return placed;
}

} // namespace

std::vector<BuiltLobe> build_document_lobes(const Document& doc, std::vector<std::string>* warnings)
{
    return finish_lobes(doc, build_lobes(doc, warnings, nullptr, nullptr), warnings);
}

std::vector<BuiltLobe> build_document_lobes(const Document& doc, std::vector<std::string>* warnings, LobeBuildCache& cache)
{
    cache.counts_ = {};
    return finish_lobes(doc, build_lobes(doc, warnings, cache.impl_.get(), &cache.counts_), warnings);
}

struct LivePinch::Impl {
    std::int64_t lobe_id = 0;
    glm::dmat4 frame{1.0};       ///< the lobe's frame → stage space
    TriangleMesh rest;           ///< the lobe in its own frame when the pinch started
    TriangleMesh work;           ///< the same, deformed
    TriangleMesh stage;          ///< work mapped to stage space
    std::optional<FramedPinch> pinch;
    std::optional<PinchEditor> editor;
};

LivePinch::LivePinch(const Document& doc, const BuiltLobe& lobe, const glm::vec3& from) : impl_(std::make_unique<Impl>())
{
    Impl& m = *impl_;
    m.lobe_id = lobe.lobe_id;
    // A new edit comes after every operation so far: the lobe's frame is its whole transform
    // (finish_lobes' lobe_transform(doc, id, k) with k = the number of operations).
    m.frame = lobe_transform(doc, lobe.lobe_id, doc.edits.size());
    m.rest = lobe.mesh;
    if (m.frame != glm::dmat4(1.0)) transform_mesh(m.rest, glm::inverse(m.frame));
    m.pinch.emplace(doc, m.rest, from, m.frame);
    m.editor.emplace(m.rest, m.pinch->handle, m.pinch->options);
    m.work = m.rest;
    m.stage = lobe.mesh;
}

LivePinch::~LivePinch() = default;
LivePinch::LivePinch(LivePinch&&) noexcept = default;
LivePinch& LivePinch::operator=(LivePinch&&) noexcept = default;

const TriangleMesh& LivePinch::drag_to(const glm::vec3& to)
{
    Impl& m = *impl_;
    m.editor->drag_to(m.pinch->target(m.rest, to), m.work);
    // Only the region moves: map its vertices out to stage space (exactly, for the identity).
    for (int v : m.editor->roi())
        m.stage.positions[static_cast<std::size_t>(v)] =
            glm::vec3(m.frame * glm::dvec4(glm::dvec3(m.work.positions[static_cast<std::size_t>(v)]), 1.0));
    return m.stage;
}

std::int64_t LivePinch::lobe_id() const { return impl_->lobe_id; }
const TriangleMesh& LivePinch::mesh() const { return impl_->stage; }

std::size_t apply_pinch_edits(const Document& doc, std::int64_t lobe_id, TriangleMesh& mesh,
                              std::vector<std::string>* warnings)
{
    std::size_t applied = 0;
    for (const EditOperation& op : doc.edits) {
        if (op.kind() != EditKind::DeformLobe) continue;
        if (op.target > 0 && op.target != lobe_id) continue;
        if (op.target == 0) {
            glm::vec3 from, to;
            if (!drag_ends(op, from, to) ||
                nearest_vertex_distance(mesh, from) > pinch_pick_distance_m(doc.settings))
                continue;
        }
        if (apply_pinch(doc, op, mesh, warnings)) ++applied;
    }
    return applied;
}

} // namespace lobe
