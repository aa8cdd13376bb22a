#pragma once
/// \file sketch.h
/// A sketched tree (a trunk and branches drawn as nodes, metres) and the parametric
/// 2L-system derived from it, after Steiner 2023 ("seed 000"): the sketch is stored as
/// blueprints that the turtle reads section by section, wrapping modulo the number of sketched
/// sections (the seed's Algorithm 3.1), and a few productions make the tree grow from them:
/// the trunk gains one section every iteration, a branch of each sketched type grows out every
/// n trunk sections (n: the trunk node the type was drawn from), a branch grows at the rate
/// its sketch implies and branches again every n of its own sections, and successive branches
/// of one axis diverge by the divergence angle (the golden angle by default).
/// docs/lsystem-sketch.md describes the file, the rules and the numbers.
///
/// The rules are an ordinary cpfg `.l` text (lsystem.h) with its `.v` view text: growing them
/// with the `lsystem` grower (lsystem_grower.h) is growing the sketch. Everything here is
/// deterministic and allocation-bounded by the limits below.

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>

#include "growth/grower.h"

namespace lobe::lsystem {

/// Most nodes of the trunk, and of one branch.
inline constexpr std::size_t kMaxSketchNodes = 1000;
/// Most branch types (each drawn from its own trunk node).
inline constexpr std::size_t kMaxSketchBranches = 8;
/// Most iterations a sketch (or a growth value) may ask for.
inline constexpr int kMaxSketchIterations = 200;
/// Largest coordinate, metres, and the shortest section, metres.
inline constexpr double kMaxSketchCoordinateM = 1000.0;
inline constexpr double kMinSketchSectionM = 1e-4;
/// Most bytes of a sketch file.
inline constexpr std::size_t kMaxSketchFileBytes = std::size_t{4} << 20;
/// The divergence angle when the sketch gives none (the golden angle, rounded as the seed's
/// user study used it to a tenth of a degree: 360°·(1 − 1/φ) = 137.5078°).
inline constexpr double kDefaultDivergenceDeg = 137.5;
/// Straight steps the turtle draws per sketched section (the section's Bézier curve).
inline constexpr int kDefaultCurveSteps = 4;

/// One branch type: drawn from trunk node `attach` (1 … trunk sections − 1; node k is where
/// trunk section k − 1 ends, node 0 the root) through `points` (metres, at least one; the
/// branch's sections run attach node → points[0] → points[1] …).
struct SketchBranch {
    int attach = 0;
    std::vector<glm::dvec3> points;
};

/// A sketch: trunk nodes from the root up (metres, session axes, +Y up; at least two, so at
/// least one section), branch types, the iteration the tree is shown at and the divergence.
struct Sketch {
    std::vector<glm::dvec3> trunk;
    std::vector<SketchBranch> branches;
    int iterations = 0;                          ///< 1 … kMaxSketchIterations; 0: the trunk's section count
    double divergence_deg = kDefaultDivergenceDeg; ///< [0, 360]

    int trunk_sections() const { return trunk.empty() ? 0 : static_cast<int>(trunk.size()) - 1; }
    /// iterations, or the trunk's section count when 0.
    int shown_iterations() const { return iterations > 0 ? iterations : trunk_sections(); }
};

/// Checks a sketch: at least two trunk nodes, every coordinate finite and within
/// kMaxSketchCoordinateM, no section shorter than kMinSketchSectionM, at most the limits above,
/// each branch attached to an existing trunk node other than the root and the tip (1 …
/// trunk sections − 1), no two branch types on one node, at least one point per branch,
/// iterations 0 … kMaxSketchIterations, divergence in [0, 360].
/// \throw InvalidInput, one line starting with `where`, for the first fault.
void check_sketch(const Sketch& sketch, const std::string& where);

/// Reads a sketch file: `{"trunk": [[x, y, z], …], "branches": [{"attach": i, "points":
/// [[x, y, z], …]}], "iterations": n, "divergence_deg": d}` (metres; branches, iterations and
/// divergence_deg optional; no other keys). \throw InvalidInput "NAME: …", one line, for
/// malformed JSON, a wrong type or key, more than the limits, or what check_sketch refuses.
Sketch parse_sketch(std::string_view json_text, const std::string& name);

/// The sketch as that JSON text (one line, numbers in shortest round-trip form).
std::string sketch_json(const Sketch& sketch);

/// How one branch type grows, as derived from the sketch.
struct SketchBranchRule {
    char section = 'C';  ///< the module of its sections (C(x, t))
    char apex = 'Y';     ///< the module of its growing tip (Y(c, b, s))
    int interval = 0;    ///< n: it grows out of every n-th trunk node and branches every n of its nodes
    int sections = 0;    ///< sketched sections (its blueprints)
    /// Growth rate: rate_num / rate_den sections per iteration after the first (which comes
    /// with the branch), so that the first branch has all its sketched sections when the
    /// trunk has all of its own; at most 1.
    int rate_num = 1;
    int rate_den = 1;
};

/// The parametric 2L-system of a sketch, and what it was derived from.
struct SketchRules {
    int trunk_sections = 0;            ///< N: the trunk's blueprints
    std::vector<SketchBranchRule> branches; ///< in the sketch's order
    double growth = 0.0;               ///< the growth value drawn (iterations, 1 …)
    int derivation_length = 0;         ///< ceil(growth) − 1 (iteration 1 is the axiom)
    std::string lsystem;               ///< the `.l` text
    std::string view;                  ///< the `.v` text (angles in degrees, one unit = 1 m)
};

struct SketchRulesOptions {
    /// The growth value, in iterations (iteration 1 is the axiom, one trunk section): k.f
    /// shows iteration k + 1 with the sections grown in it at fraction f of their length. 0:
    /// the sketch's iterations. At most kMaxSketchIterations.
    double growth = 0.0;
    int curve_steps = kDefaultCurveSteps; ///< 1 (straight sections) … 16
};

/// Derives the rules of a (checked) sketch. \throw InvalidInput as check_sketch ("sketch: …"),
/// and for a growth value outside (0, kMaxSketchIterations] or curve_steps outside 1 … 16.
SketchRules sketch_rules(const Sketch& sketch, const SketchRulesOptions& options = {});

/// Points of the Bézier curve through `nodes` (a Catmull-Rom spline: each node's tangent is
/// half the difference of its neighbours, one-sided at the ends), `steps` per section, the
/// nodes themselves included: nodes.size() − 1 sections give (size − 1)·steps + 1 points.
std::vector<glm::dvec3> sketch_curve(const std::vector<glm::dvec3>& nodes, int steps);

/// The `lsystem` grower's choice that grows `rules` (their `.l` as source, named `name` in
/// messages, and their `.v` as view).
GrowerChoice sketch_grower_choice(const SketchRules& rules, const std::string& name = "sketch.l");

/// A sketch's tree: the rules derived and grown by the `lsystem` grower (no lobes, model
/// units metres, the root at the model's origin, so sketched point p lands at p − trunk[0]).
/// Radii are not set (GrowthResult::radii_set false: the pipe model's, growth/radii.h).
/// \throw InvalidInput as sketch_rules, or a derivation past the engine's limits.
struct SketchGrown {
    SketchRules rules;
    GrowthResult growth;
    std::size_t modules = 0; ///< of the derived word
};
SketchGrown grow_sketch(const Sketch& sketch, const SketchRulesOptions& options = {}, std::uint64_t seed = 1,
                        std::size_t max_tree_nodes = 2000000);

} // namespace lobe::lsystem
