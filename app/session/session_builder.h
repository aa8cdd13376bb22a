#pragma once
/// \file session_builder.h
/// Applies the actions derived from raw input to a session document: completed strokes are
/// added (lobe strokes to the current lobe, "new lobe" starts another), drags become edit
/// operations aimed at what they picked, delete/duplicate/mirror act on what the fingertip
/// is at, panel settings change the settings, undo/redo walk the history of those changes.
/// Operation types and params: docs/session-format.md; gestures: docs/editing.md.

#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/document.h"
#include "input/pipeline.h"
#include "meshing/stroke_edit.h"

namespace lobe {

/// Where a drag picks what it edits. The paper gives no numbers; these are ours.
struct EditPickOptions {
    /// Edit-stroke drags: the drag start (and the pointing fingertip of the other hand)
    /// must be within this of a stroke point (metres). Recorded in the operation; stroke
    /// editing (meshing/stroke_edit.h) falls back to the same default for an operation
    /// without it, so it is that default.
    double stroke_pick_distance_m = StrokeEditOptions{}.pick_distance_m;
    /// Edit-stroke drags with one hand: arc length of the bent segment on each side of the
    /// picked point (metres). Recorded in the operation, as stroke_pick_distance_m.
    double stroke_half_length_m = StrokeEditOptions{}.half_length_m;
    /// Lobe drags (deform, move, rotate, scale) pick a lobe when they start within this of
    /// one of its stroke points, or inside its bounding sphere (centre: lobe_centre; radius:
    /// its farthest stroke point). Another distance than settings.lobes.pinch_pick_distance_m,
    /// which then picks the pinch's handle among the picked lobe's mesh vertices.
    double lobe_pick_distance_m = 0.05;
};

/// How a SessionBuilder sees the geometry that drags pick from. The defaults see the
/// strokes as drawn and accept every operation; the meshing stage provides hooks that see
/// earlier edits applied and check that an operation applies (app/session/edit_hooks.h), so that a
/// drag on a moved lobe or a bent stroke picks what the person saw.
struct EditHooks {
    /// Every stroke of the document (same ids) where the person sees it now, stage space.
    std::function<std::vector<Stroke>(const Document&)> current_strokes;
    /// Empty when the operation, appended to the document, applies; else why not (one line).
    std::function<std::string(const Document&, const EditOperation&)> check;
    /// A tree-wide species setting (SettingId::Species, lobe 0): overlays the named preset
    /// on `settings` as `--species NAME` does (growth/species.h: apply_species(settings,
    /// load_species(name))); empty when it did, else why not, `settings` unchanged. Absent:
    /// only settings.growth.species is set to the name.
    std::function<std::string(Settings&, const std::string&)> apply_species;
    /// A lobe made from a mesh (LobeRecord::model) where the person sees it now: its mesh
    /// moved, rotated and scaled by the lobe's transform operations, stage space. Absent:
    /// the model's mesh as stored.
    std::function<TriangleMesh(const Document&, const LobeRecord&)> model_in_stage;
    /// The mesh of import number N (InputAction::ImportMesh), as the import made it
    /// (centred on the origin). Throws Error (one line) when it cannot be had. Absent:
    /// imports are refused with a warning.
    std::function<std::shared_ptr<const LobeModel>(int)> import_model;
};

/// Centre of a lobe used by rotate and scale: the length-weighted barycentre of its strokes
/// (each stroke's segments weighted by their length, so dense sampling does not pull it),
/// the mean of the points for strokes of zero length. `strokes` holds the strokes to look
/// the lobe's ids up in (e.g. EditHooks::current_strokes).
/// \return false when none of the lobe's strokes is there.
bool lobe_centre(const LobeRecord& lobe, const std::vector<Stroke>& strokes, glm::dvec3& centre);

class SessionBuilder {
public:
    /// A lobe stroke whose points all stay farther than this (or half the lobe's radius,
    /// when larger) from every lobe's strokes starts a new lobe.
    static constexpr double kJoinDistanceM = 0.10;

    /// Duplicate: a lobe's copy goes its diameter (twice its bounding radius) plus this far
    /// along +X; a trunk stroke's copy goes kTrunkCopyOffsetM along +X.
    static constexpr double kDuplicateGapM = 0.05;
    static constexpr double kTrunkCopyOffsetM = 0.10;

    explicit SessionBuilder(Document doc = {}, EditPickOptions pick = {}, EditHooks hooks = {});

    /// Applies one action; returns true when the document changed. A drag, delete,
    /// duplicate or mirror that picks nothing (too far from every stroke or lobe, no hand
    /// tracked, or an edit that does not apply) and a setting that is refused (unknown id,
    /// out of range, per-lobe where only tree-wide is allowed) change nothing and add a
    /// warning to messages(). Every change is one undo step, except that consecutive
    /// settings of the same id and lobe (a slider being dragged) make one step together.
    ///
    /// Stroke ids: a completed stroke keeps its id unless the document already has that id
    /// (a copy took it), then it gets the next id above every id used so far; copies get
    /// such ids too.
    ///
    /// A completed stroke that no session may hold is refused with a warning and changes
    /// nothing (docs/limits.md): fewer than 2 points, fewer points or shorter than
    /// settings.input asks (min_stroke_points, min_stroke_length_m: what the pipeline
    /// discards), a coordinate or time that is not finite, a coordinate beyond
    /// kMaxStrokeCoordinateM, more than kMaxStrokePoints points, all points at one place,
    /// a lobe stroke whose points all lie on one straight line (it cannot bound a lobe), or
    /// a stroke or lobe past kMaxDocumentStrokes / kMaxDocumentLobes. Drags, copies and
    /// imports past the document limits are refused the same way.
    bool apply(const InputAction& action);
    void apply(const std::vector<InputAction>& actions);

    const Document& document() const { return doc_; }
    Document take_document() { return std::move(doc_); }
    /// The lobe that a lobe-tool drag (deform, move, rotate, scale) starting at `point`
    /// (document space) edits: the one whose strokes are nearest among those it is near or
    /// inside, as a completed drag picks it. 0 when none.
    std::int64_t lobe_at(const glm::dvec3& point) const;
    /// What a lobe-tool drag starting at `point` picks: the lobe (lobe_at; 0 when none) and
    /// the centre a move, rotate or scale drag records, about which it turns and scales it.
    struct LobeDragTarget {
        std::int64_t lobe = 0;
        glm::dvec3 centre{0.0};
    };
    LobeDragTarget lobe_drag_target(const glm::dvec3& point) const;
    /// The edit operation a completed `drag` would append (what it picks, its parameters, the
    /// edit hooks' check), without appending it: what the live views show while a drag goes
    /// on. Nothing, with the one-line reason in `why` when given, where the drag would edit
    /// nothing.
    std::optional<EditOperation> drag_operation(const Drag& drag, std::string* why = nullptr) const;
    /// Warnings (one line each) about drags that edited nothing, in order.
    const std::vector<std::string>& messages() const { return messages_; }

private:
    bool add_stroke(const InputAction& action);
    bool add_drag(const InputAction& action);
    bool delete_at_tip(const InputAction& action);
    bool copy_at_tip(const InputAction& action);
    bool apply_setting(const InputAction& action);
    bool import_mesh(const InputAction& action);
    /// The lobe's pinch deforms as copies for a lobe copied by `place` (see docs/editing.md):
    /// their paths where the person sees them now, placed. Empty, with `note` saying why,
    /// when they cannot be carried over faithfully.
    std::vector<EditOperation> placed_deforms(const LobeRecord& lobe, bool mirror, const glm::dvec3& shift,
                                              double mirror_x, std::string& note) const;
    std::vector<Stroke> view() const;
    void snapshot();

    Document doc_;
    EditPickOptions pick_;
    EditHooks hooks_;
    bool new_lobe_pending_ = false;
    std::vector<Document> undo_, redo_;
    std::vector<std::string> messages_;
    std::int64_t next_edit_id_ = 1;
    std::int64_t next_lobe_id_ = 1;
    std::int64_t next_stroke_id_ = 1;
    /// The setting (id, lobe) the last action changed, while only settings followed.
    std::optional<std::pair<SettingId, std::int64_t>> setting_run_;
};

} // namespace lobe
