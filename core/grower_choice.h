#pragma once
/// \file grower_choice.h
/// Which growth model grows a tree of the scene, and with which parameters: a session tree's
/// `grower` (docs/session-format.md). The growers themselves and the parameters each takes are
/// in growth/grower.h; the session reader checks only the shape here, and the session loader
/// of app/session (session_file.h) refuses a grower or a parameter that no grower knows.

#include <cstdint>
#include <map>
#include <string>
#include <variant>

namespace lobe {

/// The grower of a tree with no `grower` (and of a document with no tree): the paper's
/// clustered subtree growth inside the lobes (Zhang et al. 2021, §5).
inline constexpr char kDefaultGrowerName[] = "subtrees";

/// One parameter value of a grower: a flag, a whole number, a number or a text.
using GrowerParam = std::variant<bool, std::int64_t, double, std::string>;

/// Longest grower name, parameter name and parameter text a session may hold.
inline constexpr std::size_t kMaxGrowerNameLength = 64;
inline constexpr std::size_t kMaxGrowerParamTextBytes = 1u << 20;
inline constexpr std::size_t kMaxGrowerParams = 256;

struct GrowerChoice {
    std::string name = kDefaultGrowerName; ///< lower case letters, digits and '-'
    int version = 1;                       ///< of the grower's parameters, ≥ 1
    std::map<std::string, GrowerParam> params; ///< absent keys take the grower's defaults

    bool operator==(const GrowerChoice&) const = default;
};

} // namespace lobe
