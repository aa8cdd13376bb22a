#include "growth/lsystem/lsystem_grower.h"
#include "growth/lsystem/presets.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <variant>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "core/errors.h"
#include "core/random.h"
#include "growth/lsystem/turtle.h"
#include "growth/skeleton.h"

namespace lobe {
namespace lsystem {

namespace {

constexpr char kPresetFolder[] = "lsystems/";

/// A text parameter, or null when absent (or not a text: check_params refuses that).
const std::string* text_param(const GrowerChoice& c, const std::string& key)
{
    const auto it = c.params.find(key);
    if (it == c.params.end()) return nullptr;
    return std::get_if<std::string>(&it->second);
}

/// A number parameter (whole or not), or nullopt.
std::optional<double> number_param(const GrowerChoice& c, const std::string& key)
{
    const auto it = c.params.find(key);
    if (it == c.params.end()) return std::nullopt;
    if (const auto* i = std::get_if<std::int64_t>(&it->second)) return static_cast<double>(*i);
    if (const auto* d = std::get_if<double>(&it->second)) return *d;
    return std::nullopt;
}

std::string view_name_of(const std::string& name)
{
    const std::size_t dot = name.rfind('.');
    const std::size_t slash = name.find_last_of("/\\");
    if (dot != std::string::npos && (slash == std::string::npos || dot > slash)) return name.substr(0, dot) + ".v";
    return name + ".v";
}

/// The source the grower's parameters name (checked).
LSystemSource choice_source(const GrowerChoice& c)
{
    LSystemSource src;
    if (const std::string* text = text_param(c, "source")) {
        const std::string* name = text_param(c, "source_name");
        src.name = name && !name->empty() ? *name : "lsystem.l";
        src.text = *text;
        src.view_name = view_name_of(src.name);
    } else {
        const std::string* preset = text_param(c, "preset");
        src = preset_source(preset ? *preset : kDefaultPreset);
    }
    if (const std::string* view = text_param(c, "view")) {
        src.view_text = *view;
        src.has_view = true;
    }
    return src;
}

/// Where the turtle starts: the trunk base of the skeleton the strokes and lobes make.
glm::dvec3 trunk_base(const GrowerInput& in)
{
    if (in.trunk_strokes.empty() && in.lobes.empty()) return glm::dvec3(0.0);
    std::vector<TriangleMesh> meshes;
    meshes.reserve(in.lobes.size());
    for (const GrowthLobe& l : in.lobes) meshes.push_back(l.mesh);
    SkeletonOptions o;
    o.spacing_m = in.settings.growth.skeleton_spacing_m;
    const Skeleton s = build_skeleton(in.trunk_strokes, meshes, o);
    return s.graph.empty() ? glm::dvec3(0.0) : glm::dvec3(s.graph.nodes[0].position);
}

/// Highest lobe point, metres; -inf without lobes.
double lobes_top(const std::vector<GrowthLobe>& lobes)
{
    double top = -std::numeric_limits<double>::infinity();
    for (const GrowthLobe& l : lobes)
        for (const glm::vec3& p : l.mesh.positions) top = std::max(top, static_cast<double>(p.y));
    return top;
}

/// Records in each node the lobe holding it, and counts the nodes per lobe.
void assign_lobes(GrowthResult& g, const std::vector<GrowthLobe>& lobes, const LobeEnvironment& env)
{
    g.lobes.assign(lobes.size(), LobeGrowthStats{});
    for (TreeNode& n : g.tree.nodes) {
        if (n.kind == TreeNodeKind::Root) continue;
        n.lobe = env.lobe_at(n.position);
        if (n.lobe >= 0) ++g.lobes[static_cast<std::size_t>(n.lobe)].nodes;
    }
}

class LSystemGrower final : public Grower {
public:
    std::string_view name() const override { return kGrowerName; }
    std::string_view title() const override { return "L-system"; }
    int version() const override { return 1; }
    int panel_code() const override { return kGrowerPanelCode; }
    void check_params(const GrowerChoice& choice, const std::string& where) const override;
    /// Derivation steps 0 … kMaxDerivationLength: k steps derive the first k of a longer
    /// derivation (the turtle draws the word after them).
    std::string_view steps_param() const override { return "steps"; }
    int default_steps(const GrowerChoice& choice) const override;
    GrowthResult grow(const GrowerInput& in) const override { return run_lsystem(in).growth; }
};

int LSystemGrower::default_steps(const GrowerChoice& choice) const
{
    if (const auto it = choice.params.find("steps"); it != choice.params.end())
        if (const auto* n = std::get_if<std::int64_t>(&it->second)) return static_cast<int>(*n);
    // The L-system's own `derivation length:` (its messages are the grower's to give).
    const LSystemSource src = choice_source(choice);
    std::vector<std::string> messages;
    return parse_lsystem(src.text, src.name, &messages).derivation_length();
}

void LSystemGrower::check_params(const GrowerChoice& choice, const std::string& where) const
{
    if (choice.version > version())
        throw InvalidInput(where + ".version: " + std::to_string(choice.version) + " is newer than this build reads (" +
                           std::to_string(version()) + ")");
    for (const auto& [key, value] : choice.params) {
        const std::string at = where + ".params." + key;
        if (key == "preset" || key == "source" || key == "view" || key == "source_name") {
            const std::string* text = std::get_if<std::string>(&value);
            if (!text) throw InvalidInput(at + ": expected a text");
            if (text->size() > kMaxFileBytes)
                throw InvalidInput(at + ": longer than " + std::to_string(kMaxFileBytes) + " bytes");
            if (key == "preset") {
                const std::vector<std::string> names = preset_names();
                if (std::find(names.begin(), names.end(), *text) == names.end())
                    throw InvalidInput(at + ": no L-system preset \"" + *text + "\" (known: " + preset_names_text() + ")");
            }
        } else if (key == "steps") {
            const auto* n = std::get_if<std::int64_t>(&value);
            if (!n || *n < 0 || *n > kMaxDerivationLength)
                throw InvalidInput(at + ": expected a whole number from 0 to " + std::to_string(kMaxDerivationLength));
        } else if (key == "height_m") {
            const std::optional<double> h = number_param(choice, key);
            if (!h || !(*h > 0.0 && *h <= 100.0)) throw InvalidInput(at + ": expected a number of metres in (0, 100]");
        } else {
            throw InvalidInput(at + ": unknown parameter (the " + std::string(kGrowerName) +
                               " grower takes preset, source, view, source_name, steps and height_m)");
        }
    }
    if (choice.params.count("preset") && choice.params.count("source"))
        throw InvalidInput(where + ".params: give preset or source, not both");
}

const LSystemGrower kLSystemGrower;

} // namespace

LobeEnvironment::LobeEnvironment(const std::vector<GrowthLobe>& lobes, const glm::dvec3& origin) : origin_(origin)
{
    rays_.reserve(lobes.size());
    for (const GrowthLobe& l : lobes) {
        rays_.emplace_back(l.mesh);
        glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
        for (const glm::vec3& p : l.mesh.positions) {
            lo = glm::min(lo, p);
            hi = glm::max(hi, p);
        }
        lo_.push_back(lo);
        hi_.push_back(hi);
    }
}

int LobeEnvironment::lobe_at(const glm::vec3& p) const
{
    for (std::size_t i = 0; i < rays_.size(); ++i) {
        const glm::vec3& lo = lo_[i];
        const glm::vec3& hi = hi_[i];
        if (p.x < lo.x || p.y < lo.y || p.z < lo.z || p.x > hi.x || p.y > hi.y || p.z > hi.z) continue;
        if (rays_[i].inside(p)) return static_cast<int>(i);
    }
    return -1;
}

bool LobeEnvironment::inside(const glm::dvec3& p) const
{
    const glm::dvec3 stage = origin_ + p;
    if (!std::isfinite(stage.x) || !std::isfinite(stage.y) || !std::isfinite(stage.z)) return false;
    return lobe_at(glm::vec3(stage)) >= 0;
}

std::vector<std::string> preset_names()
{
    std::vector<std::string> names{kDefaultPreset};
    for (const Preset& p : presets())
        if (p.name != kDefaultPreset) names.push_back(p.name);
    return names;
}

std::string preset_names_text()
{
    std::string list;
    for (const std::string& n : preset_names()) list += (list.empty() ? "" : ", ") + n;
    return list;
}

LSystemSource preset_source(const std::string& name)
{
    const Preset* p = find_preset(name);
    if (!p) throw InvalidInput("no L-system preset \"" + name + "\" (presets: " + preset_names_text() + ")");
    LSystemSource src;
    src.name = std::string(kPresetFolder) + name + ".l";
    src.view_name = std::string(kPresetFolder) + name + ".v";
    src.text = std::string(p->lsystem);
    src.view_text = std::string(p->view);
    src.has_view = !p->view.empty();
    return src;
}

namespace {

/// Where a lobe's crown starts: the first skeleton node (in node order, so nearest the root
/// along the trunk) inside the lobe, else the skeleton node nearest the lobe's centre.
int crown_entry(const Skeleton& skeleton, const LobeEnvironment& lobe_env, const GrowthLobe& lobe)
{
    const std::vector<TreeNode>& nodes = skeleton.graph.nodes;
    for (std::size_t k = 0; k < nodes.size(); ++k)
        if (lobe_env.lobe_at(nodes[k].position) == 0) return static_cast<int>(k);
    glm::dvec3 centre(0.0);
    for (const glm::vec3& p : lobe.mesh.positions) centre += glm::dvec3(p);
    if (!lobe.mesh.positions.empty()) centre /= static_cast<double>(lobe.mesh.positions.size());
    int best = 0;
    double best_d = std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < nodes.size(); ++k) {
        const double d = glm::length(glm::dvec3(nodes[k].position) - centre);
        if (d < best_d) {
            best_d = d;
            best = static_cast<int>(k);
        }
    }
    return best;
}

/// Appends `crown` (its root at node `entry` of `g.tree`) to the tree, its nodes marked as
/// grown in lobe `lobe`; its leaves too.
void graft(GrowthResult& g, TurtleResult& crown, int entry, int lobe)
{
    const int offset = static_cast<int>(g.tree.nodes.size()) - 1; // crown node k → offset + k, k ≥ 1
    for (std::size_t k = 1; k < crown.tree.nodes.size(); ++k) {
        TreeNode n = crown.tree.nodes[k];
        n.parent = n.parent == 0 ? entry : n.parent + offset;
        n.lobe = lobe;
        g.tree.nodes.push_back(n);
    }
    if (!g.leaves) g.leaves.emplace();
    for (PlacedLeaf& leaf : crown.leaves) g.leaves->push_back(leaf);
}

/// A model that asks where it is, in lobes: the sketched skeleton (§5.1: trunk strokes, or
/// the default trunk, with limbs into lobes it misses) and, in each lobe, the model derived
/// and drawn from where the skeleton enters the lobe, heading along it, in the lobe alone.
/// Radii come from the pipe model over the whole tree, so the trunk narrows into the crowns.
void grow_crowns_on_skeleton(const GrowerInput& in, const LSystem& system, const ViewSettings& view,
                             DeriveOptions derive_options, TurtleOptions turtle, LSystemRun& run)
{
    std::vector<TriangleMesh> meshes;
    for (const GrowthLobe& l : in.lobes) meshes.push_back(l.mesh);
    SkeletonOptions so;
    so.spacing_m = in.settings.growth.skeleton_spacing_m;
    Skeleton skeleton = build_skeleton(in.trunk_strokes, meshes, so);
    GrowthResult& g = run.growth;
    for (std::string& m : skeleton.messages) g.messages.push_back(std::move(m));
    g.tree = skeleton.graph;
    g.skeleton_nodes = g.tree.size();
    g.lobes.assign(in.lobes.size(), LobeGrowthStats{});
    g.leaves.emplace(); // the model's own leaves only (none without surfaces)
    if (g.tree.empty()) return;
    for (std::size_t i = 0; i < in.lobes.size(); ++i) {
        LobeEnvironment lobe_env({in.lobes[i]}, glm::dvec3(0.0));
        const int entry = crown_entry(skeleton, lobe_env, in.lobes[i]);
        const TreeNode& at = g.tree.nodes[static_cast<std::size_t>(entry)];
        const glm::dvec3 origin(at.position);
        glm::dvec3 heading(0.0, 1.0, 0.0);
        if (at.parent >= 0) heading = origin - glm::dvec3(g.tree.nodes[static_cast<std::size_t>(at.parent)].position);
        lobe_env.set_origin(origin);
        // Each lobe draws its own numbers: its seed, else the tree's keyed by the lobe's id.
        derive_options.seed = in.lobes[i].seed.value_or(splitmix64(in.seed ^ splitmix64(static_cast<std::uint64_t>(in.lobes[i].id))));
        derive_options.environment = &lobe_env;
        derive_options.answer_queries = query_answerer(system, view, &lobe_env, heading);
        const Word word = derive(system, derive_options);
        turtle.origin = origin;
        turtle.heading = heading;
        turtle.max_nodes = in.max_tree_nodes > g.tree.size() ? in.max_tree_nodes - g.tree.size() : 0;
        if (turtle.max_nodes == 0) {
            g.messages.push_back("lobe " + std::to_string(i + 1) + ": the tree's node cap is reached; not grown");
            continue;
        }
        TurtleResult crown = interpret(system, interpretation_word(system, word, derive_options), turtle);
        for (std::string& m : crown.messages) g.messages.push_back("lobe " + std::to_string(i + 1) + ": " + m);
        g.lobes[i].nodes = crown.tree.empty() ? 0 : crown.tree.size() - 1;
        graft(g, crown, entry, static_cast<int>(i));
        run.word = word;
    }
    g.radii_set = false;
}

} // namespace

LSystemRun run_lsystem(const GrowerInput& in)
{
    kLSystemGrower.check_params(in.choice, "grower");
    const LSystemSource src = choice_source(in.choice);
    LSystemRun run;
    std::vector<std::string>& messages = run.growth.messages;
    run.system = parse_lsystem(src.text, src.name, &messages);
    const ViewSettings view = src.has_view ? parse_view(src.view_text, src.view_name, &messages) : ViewSettings{};

    const bool in_lobes = !in.lobes.empty();
    DeriveOptions derive_options;
    if (const auto it = in.choice.params.find("steps"); it != in.choice.params.end())
        derive_options.steps = static_cast<int>(std::get<std::int64_t>(it->second));
    derive_options.seed = in.seed;
    TurtleOptions turtle;
    turtle.view = view;
    turtle.surface_length_m = in.settings.leaves.length_m;
    turtle.surface_width_m = in.settings.leaves.width_m;
    turtle.max_nodes = in.max_tree_nodes;
    if (in_lobes && run.system.has_queries()) {
        grow_crowns_on_skeleton(in, run.system, view, derive_options, turtle, run);
        return run;
    }

    // Free, or a model that does not ask where it is: one drawing from the trunk base, in
    // its own units, scaled to the lobes' top or to the free height.
    const glm::dvec3 base = trunk_base(in);
    const LobeEnvironment environment(in.lobes, base);
    derive_options.environment = in_lobes ? &environment : nullptr;
    if (run.system.has_queries()) derive_options.answer_queries = query_answerer(run.system, view, derive_options.environment);
    run.word = derive(run.system, derive_options);
    turtle.origin = base;
    const double top = lobes_top(in.lobes) - base.y;
    turtle.fit_height_m = in_lobes && top > 0.01 ? top : number_param(in.choice, "height_m").value_or(kDefaultFreeHeightM);
    if (view.metres_per_unit > 0.0) {
        // The view file fixes the scale (a sketched tree is drawn in metres).
        turtle.fit_height_m = 0.0;
        turtle.metres_per_unit = view.metres_per_unit;
    }
    TurtleResult drawn = interpret(run.system, interpretation_word(run.system, run.word, derive_options), turtle);
    run.metres_per_unit = drawn.metres_per_unit;

    GrowthResult& g = run.growth;
    g.tree = std::move(drawn.tree);
    g.skeleton_nodes = g.tree.empty() ? 0 : 1; // the root
    g.radii_set = drawn.widths_set;
    g.leaves = std::move(drawn.leaves);
    for (std::string& m : drawn.messages) messages.push_back(std::move(m));
    if (g.tree.empty())
        messages.push_back(src.name + ": the derived word (" + std::to_string(run.word.size()) +
                           " modules) draws no branch (no F or G)");
    if (in_lobes) assign_lobes(g, in.lobes, environment);
    return run;
}

} // namespace lsystem

const Grower& lsystem_grower() { return lsystem::kLSystemGrower; }

} // namespace lobe
