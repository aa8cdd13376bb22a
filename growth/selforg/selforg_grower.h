#pragma once
/// \file selforg_grower.h
/// The `self-organizing` grower (growth/grower.h): Palubicki et al. 2009 (selforg_model.h)
/// inside the sketched lobes — markers fill the lobes' volumes, every node (the sketched
/// skeleton included) casts shadow, and no new internode leaves the lobes — or, with no
/// lobes, free: markers in a default spherical crown envelope, or shadow propagation alone.
///
/// Parameters (GrowerChoice::params), all optional:
/// - `environment`: "markers" (default) or "shadow";
/// - `bud_fate`: "borchert-honda" (default) or "priority";
/// - `iterations`: 1 … 500 (default: the species');
/// - `species`: a preset of selforg_species.h (default "broadleaf");
/// - `internode_m`: internode length in metres, 0.001 … 1, or 0 (default) for the species'
///   in free growth and, in lobes, the length that divides the lobes' volume into
///   kSelfOrgLobeCells cubes.

#include <cstddef>
#include <string>

#include "growth/grower.h"
#include "growth/selforg/selforg_model.h"

namespace lobe {

/// In lobes with `internode_m` = 0: the internode is the side of the cube of volume
/// (lobes' volume)/kSelfOrgLobeCells.
inline constexpr double kSelfOrgLobeCells = 40000.0;

/// The grower's parsed parameters.
struct SelfOrgChoice {
    SelfOrgEnvironment environment = SelfOrgEnvironment::Markers;
    BudFate bud_fate = BudFate::BorchertHonda;
    int iterations = 0;      ///< 0: the species'
    std::string species = "broadleaf";
    double internode_m = 0.0; ///< 0: automatic
};

/// \throw InvalidInput one line starting with `where` (e.g. "trees[0].grower.params.iterations: …").
SelfOrgChoice parse_selforg_choice(const GrowerChoice& choice, const std::string& where);

/// The grower listed in growers() (panel code 2, name "self-organizing").
const Grower& self_organizing_grower();

/// Converts a grown metamer tree: node 0 the root, then every live metamer's tip in metamer
/// order (fixed metamers are TreeNodeKind::Skeleton, the others Grown, lobe = Metamer::lobe).
TreeGraph metamer_tree_graph(const MetamerTree& tree);

} // namespace lobe
