#include "app/session/stage_options.h"

namespace lobe {

LobeOptions lobe_options(const Settings& s)
{
    LobeOptions o;
    o.closure.max_gap_fraction = s.lobes.closed_gap_fraction;
    o.closure.max_gap_m = s.lobes.closed_gap_max_m;
    o.surface.fill_edge_m = s.lobes.edge_length_m;
    // Without remeshing the fill is the lobe's attractors: laid at the spacing itself.
    if (s.lobes.remesh_iterations <= 0) o.surface.fill_coarseness = 1.0;
    o.sampling.seed = 0;
    return o;
}

RemeshOptions stroke_lobe_remesh_options(const Settings& s)
{
    RemeshOptions o;
    o.target_edge_length_m = s.lobes.edge_length_m;
    o.iterations = static_cast<unsigned>(s.lobes.remesh_iterations);
    o.relax_feature_edges = true;
    return o;
}

RemeshOptions model_lobe_remesh_options(const Settings& s)
{
    RemeshOptions o;
    o.target_edge_length_m = s.lobes.edge_length_m;
    o.iterations = static_cast<unsigned>(s.lobes.remesh_iterations);
    o.protect_feature_edges = false;
    o.relax_feature_edges = false;
    return o;
}

LobeFromModelOptions model_import_options(const Settings& s, double size_m)
{
    LobeFromModelOptions o;
    o.size_m = size_m;
    o.target_edge_length_m = s.lobes.edge_length_m;
    o.iterations = static_cast<unsigned>(s.lobes.remesh_iterations);
    return o;
}

PinchEditOptions pinch_edit_options(const Settings& s)
{
    PinchEditOptions o;
    o.roi_radius_m = s.lobes.pinch_roi_radius_m;
    return o;
}

double pinch_pick_distance_m(const Settings& s) { return s.lobes.pinch_pick_distance_m; }

EditApplyOptions edit_apply_options(const Settings&) { return {}; }

EditPickOptions edit_pick_options(const Settings&) { return {}; }

const InputOptions& input_options(const Settings& s) { return s.input; }

const GrowthSettings& growth_options(const Settings& s) { return s.growth; }

PipeRadiiOptions pipe_radii_options(const Settings& s) { return {s.branches.pipe_exponent, s.branches.tip_radius_m}; }

const BranchSettings& branch_geometry_options(const Settings& s) { return s.branches; }

const LeafSettings& leaf_options(const Settings& s) { return s.leaves; }

} // namespace lobe
