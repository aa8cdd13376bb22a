#pragma once
/// \file settings.h
/// Options structs, one per pipeline stage, with the defaults documented once here.
/// Every field is settable from the CLI/settings files and stored in the session document,
/// through the settings table (core/settings_table.h), which lists each once with its key,
/// range and doc (docs/settings.md). A new field needs its row there.

#include <cstdint>
#include <map>
#include <string>

namespace lobe {

/// One Euro filter (Casiez et al., CHI 2012) on the joints that matter.
struct OneEuroOptions {
    double min_cutoff_hz = 1.0; ///< cutoff at rest: lower removes more jitter
    double beta = 8.0;          ///< speed coefficient (per m/s): higher removes more lag when moving
    double d_cutoff_hz = 1.0;   ///< cutoff of the speed estimate
};

/// Gesture recognition and stroke capture (hands → pen events → raw strokes).
struct InputOptions {
    /// Filter of the drawing fingertip: strong at rest (jitter), light when moving.
    OneEuroOptions filter;
    /// Filter of the thumb/index gap: lighter, so pinches register without delay.
    OneEuroOptions gap_filter{5.0, 8.0, 1.0};
    /// Pinch starts when the thumb-tip/index-tip gap (centre distance minus both joint
    /// radii) falls below this, and ends when it rises above pinch_release_m.
    double pinch_start_m = 0.008;
    double pinch_release_m = 0.016;
    /// A pinch needs the gap below pinch_start_m for this long (debounces single-frame dips).
    double pinch_min_hold_s = 0.03;
    /// Curl (total bend angle over 270°, see finger_curl) of middle, ring and little above
    /// which they count as curled; all three curled = grab, which is never a pinch. 0.48 is
    /// 130°: a relaxed pinching hand bends them 55–80°, a fist 150–190° (shipped Leap clips).
    double curl_grab = 0.48;
    double curl_release = 0.41;
    /// Index finger straight and middle/ring/little curled = point.
    double curl_point_index_max = 0.25;
    /// The paper keeps a new stroke point only when the fingertip moved at least this far.
    double min_point_distance_m = 0.005;
    /// Tracking loss shorter than this is bridged; longer ends the stroke.
    double bridge_loss_s = 0.15;
    /// Strokes shorter than this (polyline length) or with fewer points are discarded.
    double min_stroke_length_m = 0.03;
    int min_stroke_points = 4;
    /// A hand position jump faster than this between two frames is a tracking glitch (snap to
    /// the origin or the head) and the frame counts as lost.
    double max_hand_speed_mps = 8.0;
};

/// Lobes (§4): closing, remeshing, pinch editing. The paper gives no numbers; these are ours.
struct LobeSettings {
    /// Attractor spacing: one absolute target edge length for every lobe, so small and
    /// large lobes carry the same attractor density.
    double edge_length_m = 0.03;
    /// Rounds of isotropic remeshing, of lobes from strokes and from models alike. With the
    /// stroke vertices relaxed along their strokes and the small-angle repairs after the last
    /// round, 3 rounds would do for stroke lobes, but the trees grown in model lobes (the cow
    /// above all) change with the rounds (docs/lobes.md, "Measured").
    int remesh_iterations = 4;
    /// A stroke is closed when the gap between its ends is below this fraction of its length
    /// (and below closed_gap_max_m).
    double closed_gap_fraction = 0.15;
    double closed_gap_max_m = 0.08;
    /// Region of interest of a pinch edit: vertices within this distance of the handle.
    double pinch_roi_radius_m = 0.08;
    /// A pinch edit picks the lobe vertex nearest the pinch within this distance (the lobe
    /// itself is picked by the drag, EditPickOptions::lobe_pick_distance_m).
    double pinch_pick_distance_m = 0.05;
};

/// Tree growth inside the lobes (§5.2). α and β are the paper's; the rest are ours, since the
/// paper's thresholds are in scene units of unknown scale. docs/growth.md explains each.
struct GrowthSettings {
    /// Species preset (growth/data/species/<name>.json) the appearance settings came from.
    std::string species = "broadleaf";
    /// Split angle t: a cluster whose horizontal or vertical span exceeds it is split into
    /// ⌈θh/t⌉ × ⌈θv/t⌉ pieces. Smaller t gives denser branching.
    double split_angle_deg = 30.0;
    double alpha = 0.8;  ///< weight of the node's own direction in V_A
    double beta = -0.3;  ///< weight of gravity (0, −1, 0) in V_A: negative grows upwards
    /// A subtree's length is this fraction of the signed distance from its node to the lobe
    /// surface along V_A.
    double growth_ratio = 0.45;
    /// A node whose signed distance to the surface along V_A falls below this stops; its
    /// attractors leave the next iteration. This rule decides where growth ends.
    double stop_distance_m = 0.025;
    /// Most distance at which a node reaches (and removes) an attractor; the distance follows
    /// the node's subtree scale (a quarter of its subtree's length) below it.
    double kill_distance_m = 0.05;
    /// Spacing of skeleton nodes along trunk strokes.
    double skeleton_spacing_m = 0.02;
    int max_iterations = 64;
    int max_nodes = 500000;
    /// Relative weights of the library subtrees (growth/data/subtrees.json) by name; missing
    /// names weigh 0. Empty: all subtrees weigh the same.
    std::map<std::string, double> subtree_weights;
    /// Form of the species (growth/species_form.h). 1 continues the trunk (the default one or
    /// the sketched one) from its highest point as a leader up through the crown (an
    /// excurrent tree: a conifer); 0 ends it where it ends (the default trunk below the crown,
    /// where the limbs fork: a decurrent tree).
    int leader = 0;
    /// Spacing of the leader's nodes as a fraction of the crown's height: the laterals grow
    /// from them in tiers (whorls). 0: the leader's nodes are skeleton_spacing_m apart.
    double whorl_spacing = 0.0;
    /// Share by which a lateral's outer end turns from its grown direction towards straight
    /// down, growing along the lateral from its base (gravity bending a branch): 0 none.
    double droop = 0.0;
    /// Share by which the outer part of every lateral turns to hang straight down (a weeping
    /// tree's twigs): 0 none, 1 the outer two thirds hang plumb.
    double hang = 0.0;
    /// Height of the exported tree in metres (real scale, docs/export.md): the tree's structure
    /// is scaled about its base so its highest branch node lies this high, while leaves, leaf
    /// spacing and twig radii keep their sizes in metres. 0: the size it was sketched at.
    double height_m = 0.0;
};

/// Branch radii (pipe model) and generalised-cylinder geometry.
struct BranchSettings {
    double pipe_exponent = 2.0;   ///< r_parent^e = Σ r_child^e
    double tip_radius_m = 0.0012; ///< radius at every tip
    int radial_segments = 8;      ///< around a branch at LOD0
    double ring_spacing_m = 0.015; ///< largest distance between rings along a branch at LOD0
    int smoothing_iterations = 2; ///< Laplacian smoothing passes of branch curves
    double bark_color[3] = {0.36, 0.25, 0.17}; ///< linear RGB
    int lod_count = 3;            ///< levels of detail written (LOD0 … LOD{n−1})
    /// At real scale (GrowthSettings::height_m > 0): the trunk's diameter at breast height as
    /// a share of the tree's height; > 0 fits the pipe exponent to it (tips keep tip_radius_m,
    /// growth/real_scale.h), 0 uses pipe_exponent. docs/growth.md gives each species' figure.
    double dbh_ratio = 0.03;
};

/// Leaves: alpha-tested textured quads at tip nodes.
struct LeafSettings {
    double length_m = 0.055;
    double width_m = 0.032;
    int per_node = 4;            ///< leaves at each tip node
    double deviation_deg = 35.0; ///< random deviation from the branch direction
    double color[3] = {0.20, 0.42, 0.12}; ///< linear RGB
    std::string shape = "ovate"; ///< leaf texture: "ovate", "round" or "needle"
    /// Distance between leaves along a shoot (the segment from a tip to its parent): a shoot
    /// longer than per_node × spacing_m carries one leaf per spacing_m along it (at most 64)
    /// instead of per_node at its tip; 0: every leaf at the tip. Keeps the leaf density of a
    /// tree scaled to real height (growth.height_m) at the species' value.
    double spacing_m = 0.02;
};

/// All settings of a session.
struct Settings {
    InputOptions input;
    LobeSettings lobes;
    GrowthSettings growth;
    BranchSettings branches;
    LeafSettings leaves;
};

} // namespace lobe
