#pragma once
/// \file subtree_library.h
/// Elementary subtrees of unit length (§5.2): each active node grows one, scaled to its
/// distance from the lobe surface and turned to its growth direction. The shapes are data
/// (growth/data/subtrees.json, format in docs/growth.md), not code.

#include <map>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

namespace lobe {

/// One subtree in its local frame: nodes[0] = the root at the origin (it sits on the growing
/// node), +Y the growth direction, the farthest node at distance 1 from the root.
struct Subtree {
    std::string name;
    std::vector<glm::vec3> nodes;
    std::vector<int> parents; ///< parents[0] = -1; parents[i] < i
};

struct SubtreeLibrary {
    std::vector<Subtree> subtrees;
};

/// Largest subtree the loader accepts, and most subtrees in a library.
inline constexpr std::size_t kMaxSubtreeNodes = 64;
inline constexpr std::size_t kMaxSubtrees = 256;

/// Parses a library file's text. \throw InvalidInput with a one-line reason naming `where`
/// (wrong format or version, a subtree with fewer than 2 or more than 64 nodes, parents that
/// do not precede their children, non-finite or coincident-with-root-only coordinates,
/// duplicate names).
SubtreeLibrary parse_subtree_library(const std::string& text, const std::string& where);
/// The library shipped with the program (growth/data/subtrees.json, compiled in).
/// \throw InvalidInput when the program was built without it.
const SubtreeLibrary& default_subtree_library();

/// Per-subtree weights from names (GrowthSettings::subtree_weights): missing names weigh 0,
/// an empty map weighs all the same. \throw InvalidInput for a name the library lacks or
/// when every weight is 0.
std::vector<double> subtree_weights(const SubtreeLibrary& library, const std::map<std::string, double>& by_name);

} // namespace lobe
