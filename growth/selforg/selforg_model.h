#pragma once
/// \file selforg_model.h
/// The self-organizing tree model of Palubicki et al. 2009 ("Self-organizing tree models for
/// image synthesis", SIGGRAPH 2009), one iteration after another:
///  (a) the environment gives each bud its light Q and optimal direction V (markers.h:
///      space colonization; shadow_grid.h: shadow propagation);
///  (b) bud fate: the light collected is summed from the buds to the base, the resource
///      v = α·Q_base is sent back up, and a bud with resource v grows ⌊v⌋ metamers of length
///      v/⌊v⌋ internodes (extended Borchert–Honda, or the priority model);
///  (c) each new metamer points along default + ξ·V + η·tropism, normalised;
///  (d) lateral branches whose light per internode falls below a threshold are shed;
///  (e) diameters follow the pipe model (growth/radii.h, applied to the resulting TreeGraph).
/// Deterministic: every random number comes from a SplitMix64 stream keyed by the seed and
/// the new metamer's index. docs/self-organizing.md.

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "growth/selforg/selforg_species.h"

namespace lobe {

class MarkerCloud;
class MeshRaycaster;
class ShadowGrid;

/// One metamer: an internode from `base` to `tip`, the leaf and axillary (lateral) bud at its
/// tip, and the terminal bud at the tip when it ends its axis.
struct Metamer {
    glm::vec3 base{0.0f}, tip{0.0f}; ///< metres
    glm::vec3 dir{0.0f, 1.0f, 0.0f}; ///< unit, base → tip
    glm::vec3 lateral_dir{1.0f, 0.0f, 0.0f}; ///< unit direction of the axillary bud
    int parent = -1;        ///< metamer whose tip is this one's base; -1: starts at the root
    int main_child = -1;    ///< the next metamer of the same axis
    int first_lateral = -1; ///< first lateral branch at this tip (others by next_lateral)
    int next_lateral = -1;  ///< next lateral branch of the same parent (or next root)
    int lobe = -1;          ///< lobe the metamer grew in; -1 when none
    float phyllotaxis = 0.0f; ///< radians: azimuth of the axillary bud about `dir`
    bool terminal_bud = false; ///< a live bud at the tip continues the axis
    bool lateral_bud = false;  ///< a live axillary bud not grown yet
    bool fixed = false;        ///< part of the sketched skeleton: never shed
    bool alive = true;         ///< false once shed
};

/// A tree of metamers; a metamer's parent always comes before it.
struct MetamerTree {
    glm::vec3 root{0.0f};        ///< the trunk base, metres
    std::vector<Metamer> metamers;
    int first_root = -1;         ///< first metamer starting at the root (others by next_lateral)

    /// Appends `m` as the main or a lateral child of m.parent (or a root); returns its index.
    int add(Metamer m, bool lateral);
};

/// Light and resource of every bud: index m holds the terminal and the lateral bud of metamer m.
struct BudValues {
    std::vector<double> terminal, lateral;
    void assign(std::size_t n) { terminal.assign(n, 0.0); lateral.assign(n, 0.0); }
};

/// Q summed from the buds towards the base (Palubicki §4.2, first pass): sub[m] = light of
/// metamer m's live buds plus sub of its children (shed metamers count 0). Returns Q_base,
/// the sum over the roots.
double accumulate_light(const MetamerTree& tree, const BudValues& q, std::vector<double>& sub);

/// Extended Borchert–Honda (Palubicki §4.2): v = α·Q_base at the base; at every branching
/// the main axis gets v·λQ_m/(λQ_m + (1−λ)Q_l) and each lateral v·(1−λ)Q_l/(λQ_m + (1−λ)Q_l),
/// so the resource is conserved. `into` receives the resource entering each metamer, `v` the
/// resource of each bud. \pre sub from accumulate_light(tree, q, sub).
void distribute_borchert_honda(const MetamerTree& tree, const BudValues& q, const std::vector<double>& sub,
                               double alpha, double lambda, std::vector<double>& into, BudValues& v);

/// Priority model (Palubicki §4.2, one ranking over the tree's buds): v = α·Q_base; buds
/// with Q > 0 ranked by Q (ties by index, terminal first); the first ⌈κN⌉ weigh w_max, the
/// rest fall linearly to w_min; bud k gets v·Q_k w_k / Σ Q_j w_j.
void distribute_priority(const MetamerTree& tree, const BudValues& q, double alpha, double w_max, double w_min,
                         double kappa, BudValues& v);

/// Shoot direction (Palubicki §4.3): normalise(default + ξ·optimal + η·tropism);
/// `default_dir` when that sum vanishes. Directions unit (optimal may be zero: none).
glm::vec3 shoot_direction(const glm::vec3& default_dir, const glm::vec3& optimal, const glm::vec3& tropism, double xi,
                          double eta);

/// Direction of the axillary bud of a metamer along `dir` (unit): `angle_rad` away from it, at
/// azimuth `phi` (radians) about it, measured from a fixed reference perpendicular to `dir`.
glm::vec3 lateral_bud_direction(const glm::vec3& dir, float phi, double angle_rad);

/// Shedding (Palubicki §4.4): a lateral branch (not fixed) of at least `min_internodes` live
/// metamers whose mean `light` per metamer is below `threshold` is shed with everything it
/// carries. Sums are taken before anything is shed. Returns the roots of the shed branches;
/// their metamers get alive = false.
std::vector<int> shed_starved(MetamerTree& tree, const std::vector<float>& light, double threshold, int min_internodes);

/// Where a tree grows and how far.
struct SelfOrgRun {
    SelfOrgSpecies species;
    SelfOrgEnvironment environment = SelfOrgEnvironment::Shadow;
    BudFate bud_fate = BudFate::BorchertHonda;
    int iterations = 24;
    double internode_m = 0.02;
    std::uint64_t seed = 1;
    std::size_t max_metamers = 1000000; ///< growth stops when the tree holds this many
    /// When given: a new metamer whose tip leaves every one of these lobes while its base is
    /// in one is not made (the bud dies). Same order as the lobe indices of metamers.
    const std::vector<MeshRaycaster>* confine = nullptr;
};

struct SelfOrgStats {
    int iterations = 0;              ///< iterations run
    std::size_t grown = 0;           ///< metamers made
    std::size_t shed = 0;            ///< metamers shed
    std::size_t markers_removed = 0; ///< markers taken by occupancy zones
    bool metamer_cap = false;        ///< stopped at max_metamers
};

/// Grows `tree` (its live buds) for run.iterations iterations, or until no bud grows.
/// `markers` is used (and consumed) in SelfOrgEnvironment::Markers; `shadow` always (light
/// for shedding, and for Q in the shadow environment) and receives every new metamer's
/// shadow. The tree's existing metamers must already have cast theirs.
SelfOrgStats grow_metamers(MetamerTree& tree, const SelfOrgRun& run, MarkerCloud* markers, ShadowGrid& shadow);

/// Several trees in one environment (a stand): each iteration grows every tree in turn, so
/// they compete for the same markers and shade each other through the same grid. Each tree
/// stops on its own (no bud grew, or max_metamers). Returns the stats of each.
std::vector<SelfOrgStats> grow_metamer_trees(std::span<MetamerTree> trees, const SelfOrgRun& run, MarkerCloud* markers,
                                             ShadowGrid& shadow);

} // namespace lobe
