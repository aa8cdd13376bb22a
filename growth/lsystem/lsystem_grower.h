#pragma once
/// \file lsystem_grower.h
/// The grower named `lsystem` (growth/grower.h): a tree from an L-system in cpfg's language
/// (lsystem.h), derived and drawn by the turtle (turtle.h), alone or shaped by the lobes.
///
/// Parameters (a session's `trees[].grower.params`, all optional):
///   preset    a shipped L-system's name (growth/data/lsystems/NAME.l with NAME.v; "default"
///             is the built-in one); the default when neither preset nor source is given
///   source    the `.l` text itself, so a session holds its L-system whole
///   view      the `.v` text (with source; with a preset it replaces the preset's)
///   source_name  the file the source came from, for messages (default "lsystem.l")
///   steps     derivation steps, 0 … kMaxDerivationLength (default: the file's)
///   height_m  a free tree's height in metres, (0, 100] (default 3)
///
/// Units and placement. The turtle starts at the trunk base: the lower end of the trunk
/// strokes, else the default trunk's base below the lobes (growth/skeleton.h), else the stage
/// origin; the model's axes are the stage's (+Y up). Then:
///   - A model that asks where it is (`?P`, `?E`, lsystem.h has_queries) growing in lobes
///     grows in metres: one model unit is one metre, `?P` answers metres from the trunk base,
///     and `inside(x, y, z)` and `?E` say whether that point is in a lobe (LobeEnvironment).
///   - Any other model is scaled after it is drawn: with lobes so that its top reaches the
///     top of the highest lobe, without lobes to `height_m`.
/// Radii are the model's widths (`!`, `#`) when it sets any, else the pipe model's. Leaves
/// are the model's surfaces (`~`, `@o`): a model without surfaces has no leaves. A node in a
/// lobe records that lobe (TreeNode::lobe). docs/lsystem-turtle.md.

#include <cstdint>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "growth/grow.h"
#include "growth/grower.h"
#include "growth/lsystem/lsystem.h"
#include "growth/mesh_raycast.h"

namespace lobe {

/// The `lsystem` grower (listed in growers()).
const Grower& lsystem_grower();

namespace lsystem {

/// The grower's name, its panel code and its built-in preset's name.
inline constexpr char kGrowerName[] = "lsystem";
inline constexpr int kGrowerPanelCode = 1;
inline constexpr char kDefaultPreset[] = "default";
/// A free tree's height when the session gives none, metres.
inline constexpr double kDefaultFreeHeightM = 3.0;

/// The lobes as an L-system environment: a point (model units = metres from `origin`, the
/// stage's axes) is inside when some lobe holds it.
class LobeEnvironment final : public Environment {
public:
    LobeEnvironment(const std::vector<GrowthLobe>& lobes, const glm::dvec3& origin);
    bool inside(const glm::dvec3& p) const override;
    /// Moves the model's origin (what inside() adds to its points); lobe_at is unchanged.
    void set_origin(const glm::dvec3& origin) { origin_ = origin; }
    /// The index of the first lobe holding stage point `p` (metres), or -1.
    int lobe_at(const glm::vec3& p) const;

private:
    std::vector<MeshRaycaster> rays_;
    std::vector<glm::vec3> lo_, hi_;
    glm::dvec3 origin_;
};

/// An L-system's text, as the grower reads it.
struct LSystemSource {
    std::string name;      ///< for messages ("tree.l", "lsystems/willow.l")
    std::string text;      ///< the `.l` text
    std::string view_name; ///< for messages
    std::string view_text; ///< the `.v` text; used when has_view
    bool has_view = false;
};

/// Names of the presets: "default" and every shipped growth/data/lsystems/NAME.l, sorted.
std::vector<std::string> preset_names();
/// preset_names() as "default, abop-monopodial, …" (for messages).
std::string preset_names_text();
/// The preset's `.l` (and `.v` when shipped). \throw InvalidInput for an unknown name.
LSystemSource preset_source(const std::string& name);

/// What a grown L-system leaves besides the tree.
struct LSystemRun {
    GrowthResult growth;
    LSystem system;
    Word word;                  ///< the derived word (before homomorphism)
    double metres_per_unit = 1; ///< the scale the turtle drew with
};

/// Grows the L-system of `in.choice` (parameters as the grower checks them).
/// \throw InvalidInput as parse_lsystem, parse_view and derive (one line naming the file,
/// line and column, or the step), or for parameters check_params refuses.
LSystemRun run_lsystem(const GrowerInput& in);

} // namespace lsystem
} // namespace lobe
