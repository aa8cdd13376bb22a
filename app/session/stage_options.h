#pragma once
/// \file stage_options.h
/// Each stage's options from a session's settings, one function per stage: every place in
/// app/ that runs a stage with a session's settings takes its options from here, so a setting
/// is read in one place. The stages' own option structs keep defaults for use without a
/// session (tests, benchmarks); where such a default is a setting's, it is that setting's
/// default (core/settings.h), not a second number. Settings: docs/settings.md.

#include "app/session/edit_ops.h"
#include "app/session/session_builder.h"
#include "core/settings.h"
#include "meshing/laplacian_edit.h"
#include "meshing/lobe.h"
#include "meshing/model_import.h"
#include "meshing/remesh.h"

namespace lobe {

/// Progressive lobes of strokes (meshing/lobe.h): closing (closed_gap_*), the surface fill at
/// the attractor spacing (coarser when the lobe is remeshed after).
LobeOptions lobe_options(const Settings& s);
/// Remeshing a lobe of strokes to the attractor spacing, its strokes relaxed along themselves.
RemeshOptions stroke_lobe_remesh_options(const Settings& s);
/// Remeshing a session's imported lobe again to the attractor spacing: no feature edges.
RemeshOptions model_lobe_remesh_options(const Settings& s);
/// Importing a mesh as a lobe whose largest side is `size_m` (meshing/model_import.h).
LobeFromModelOptions model_import_options(const Settings& s, double size_m);
/// Pinch editing (meshing/laplacian_edit.h): the region a pinch moves.
PinchEditOptions pinch_edit_options(const Settings& s);
/// Pinch editing: the handle is the lobe vertex nearest the pinch within this (metres).
double pinch_pick_distance_m(const Settings& s);
/// Re-applying stroke edits and lobe transforms (app/session/edit_ops.h). No setting changes
/// them today: the stages' defaults.
EditApplyOptions edit_apply_options(const Settings& s);
/// What drags pick (app/session/session_builder.h). No setting changes them today.
EditPickOptions edit_pick_options(const Settings& s);
/// The input pipeline: filters, gestures, stroke capture (input/pipeline.h).
const InputOptions& input_options(const Settings& s);
/// Growth in the lobes (growth/grow.h).
const GrowthSettings& growth_options(const Settings& s);
/// Pipe-model radii (growth/radii.h).
struct PipeRadiiOptions {
    double exponent = BranchSettings{}.pipe_exponent;
    double tip_radius_m = BranchSettings{}.tip_radius_m;
};
PipeRadiiOptions pipe_radii_options(const Settings& s);
/// Branch geometry: rings, segments, smoothing, bark, LODs (growth/branch_geometry.h).
const BranchSettings& branch_geometry_options(const Settings& s);
/// Leaves at the tips (growth/leaves.h).
const LeafSettings& leaf_options(const Settings& s);

} // namespace lobe
