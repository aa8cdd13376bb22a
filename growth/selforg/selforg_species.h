#pragma once
/// \file selforg_species.h
/// Parameters of the self-organizing tree model (Palubicki et al. 2009, "Self-organizing tree
/// models for image synthesis") and the species presets that set them. Lengths are in
/// internode lengths (the model's unit) unless a name ends in _m; angles in degrees. Where the
/// values come from: docs/self-organizing.md.

#include <string>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>

namespace lobe {

/// How buds perceive their surroundings (Palubicki §4.1).
enum class SelfOrgEnvironment {
    Markers, ///< space colonization: marker points, an occupancy zone and a perception cone per bud
    Shadow,  ///< shadow propagation alone on a voxel grid
};

/// How the resource reaching the base is shared among buds (Palubicki §4.2).
enum class BudFate {
    BorchertHonda, ///< extended Borchert–Honda: split at every branching by λ
    Priority,      ///< buds ranked by light; weights w_max … w_min
};

struct SelfOrgSpecies {
    std::string name;
    // (a) environment
    double occupancy_radius = 2.0;      ///< ρ: markers this close to a new node are removed
    double perception_radius = 4.0;     ///< r: a bud sees markers up to this distance
    double perception_angle_deg = 90.0; ///< θ: full opening angle of a bud's perception cone
    double marker_spacing = 1.5;        ///< markers lie on a jittered grid of this spacing
    double shadow_a = 0.1;              ///< a: shadow a bud adds to its own voxel
    double shadow_b = 1.75;             ///< b: Δs = a·b^(−q) q voxels below
    int shadow_q_max = 6;               ///< q_max: depth of the shadow pyramid
    double light_c = 1.0;               ///< C: full light, Q = max(C − s + a, 0)
    // (b) bud fate
    double alpha = 2.0;  ///< α: resource at the base v = α·Q_base
    double lambda = 0.5; ///< λ: apical control, share of the main axis at each branching
    double priority_w_max = 1.0; ///< priority model: weight of the best-lit κ fraction of buds
    double priority_w_min = 0.05; ///< … falling linearly to this for the least lit bud
    double priority_kappa = 0.3;  ///< κ
    int max_shoot_metamers = 8;   ///< most metamers one bud makes in one iteration
    // (c) shoot direction: default + ξ·optimal + η·tropism
    double xi = 0.2;                      ///< ξ: weight of the optimal (environment) direction
    double eta = 0.5;                     ///< η: weight of tropism
    glm::vec3 tropism{0.0f, 1.0f, 0.0f};  ///< unit tropism direction (up: negative gravitropism)
    double branch_angle_deg = 45.0;       ///< lateral bud direction from its internode
    double phyllotaxis_deg = 137.5;       ///< divergence between successive lateral buds
    double jitter = 0.05;                 ///< random tilt of each new metamer (seeded)
    // (d) shedding
    double shed_threshold = 0.25; ///< light per internode below which a branch is shed
    int shed_min_internodes = 3;  ///< branches smaller than this are never shed
    // free growth
    int iterations = 24;             ///< default iterations
    double internode_m = 0.02;       ///< internode length of free growth (lobes: from their volume)
    double crown_radius = 30.0;      ///< default envelope (free growth): a sphere of this radius …
    double crown_centre_height = 45.0; ///< … centred this high above the base
};

/// Presets by name: "broadleaf", "conifer", "birch", "willow".
/// \throw InvalidInput naming the known ones for any other name.
const SelfOrgSpecies& selforg_species(std::string_view name);

/// The preset names, "a, b, c and d".
std::string selforg_species_names();

/// The preset names in order.
std::vector<std::string> selforg_species_list();

/// Checks every field's range. \throw InvalidInput "where.field: …" (one line).
void check_selforg_species(const SelfOrgSpecies& s, const std::string& where);

} // namespace lobe
