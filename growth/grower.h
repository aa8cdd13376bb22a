#pragma once
/// \file grower.h
/// Growth models behind one interface. A grower takes the sketch (trunk strokes, the lobes
/// with their per-lobe settings), the session's settings, a seed and its own parameters,
/// and returns a tree graph (core/tree.h). Branch geometry, leaves, LODs, export, rendering
/// and regrowth work on that graph alone, so they do not care which grower made it.
///
/// A session names the grower of its tree and its parameters (core/grower_choice.h,
/// `trees[].grower` in docs/session-format.md); `--grower NAME` on the command line and the
/// apps' panels pick one from growers(). Adding a grower: a class implementing Grower in
/// growth/, listed in growers() (grower.cpp), with a stable panel code; nothing in app/
/// changes. docs/growth.md lists the growers.

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>

#include "core/grower_choice.h"
#include "core/settings.h"
#include "growth/grow.h"

namespace lobe {

/// What every grower is given.
struct GrowerInput {
    /// The trunk strokes as drawn and edited, stage space, metres (the sketched skeleton).
    std::vector<std::vector<glm::vec3>> trunk_strokes;
    /// The lobes to grow in (closed, outward, stage space), with their per-lobe overrides;
    /// may be empty for a grower that grows without lobes.
    std::vector<GrowthLobe> lobes;
    Settings settings;
    std::uint64_t seed = 1;
    /// The grower's parameters as the session names them (checked by check_params first).
    GrowerChoice choice;
    /// Most nodes of the whole tree (growth/grow.h, kMaxTreeNodes; tests lower it).
    std::size_t max_tree_nodes = kMaxTreeNodes;
};

class Grower {
public:
    virtual ~Grower() = default;
    /// The name a session and `--grower` use: lower case, digits and '-', never changed.
    virtual std::string_view name() const = 0;
    /// One line for panels and `--help`.
    virtual std::string_view title() const = 0;
    /// Newest version of the parameters this grower reads (GrowerChoice::version ≤ it).
    virtual int version() const = 0;
    /// Number the panels record when a person picks this grower (a Setting event's value):
    /// stable across releases, unique among growers.
    virtual int panel_code() const = 0;
    /// \throw InvalidInput, one line starting with `where` (e.g. "trees[0].grower.params.x:
    /// …"), for a version newer than version(), an unknown parameter, a wrong type or a
    /// value out of range.
    virtual void check_params(const GrowerChoice& choice, const std::string& where) const = 0;
    /// The name of its whole-number parameter that counts growth steps, or empty when it has
    /// none. A growth of k steps is the first k steps of the growth (self-organizing:
    /// iterations; lsystem: derivation steps), so the apps can step a tree's growth forward
    /// and back and show it as it happens (a Setting event of id GrowthSteps,
    /// input/recording.h); the same seed gives the same tree at every step. What values the
    /// parameter takes is check_params's to say.
    virtual std::string_view steps_param() const { return {}; }
    /// The number of steps it grows when `choice` does not give steps_param() (it may depend
    /// on the other parameters, e.g. the species or the L-system's `derivation length:`);
    /// 0 for a grower without steps. \pre check_params(choice) passed.
    virtual int default_steps(const GrowerChoice& choice) const
    {
        (void)choice;
        return 0;
    }
    /// Grows the tree. Deterministic for the same input. Radii are left to the caller
    /// (growth/radii.h). \pre check_params(input.choice) passed.
    virtual GrowthResult grow(const GrowerInput& input) const = 0;
};

/// Every grower, the default (kDefaultGrowerName) first.
std::span<const Grower* const> growers();

/// The grower named `name`; null when none is.
const Grower* find_grower(std::string_view name);

/// The grower of `choice`, its parameters checked.
/// \throw InvalidInput starting with `where` for an unknown grower (naming the known ones)
/// or parameters its grower refuses.
const Grower& checked_grower(const GrowerChoice& choice, const std::string& where);

/// The growers' names, "a, b and c" (for messages and help).
std::string grower_names();

} // namespace lobe
