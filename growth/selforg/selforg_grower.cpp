#include "growth/selforg/selforg_grower.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "core/errors.h"
#include "growth/mesh_raycast.h"
#include "growth/selforg/markers.h"
#include "growth/selforg/shadow_grid.h"
#include "growth/skeleton.h"

namespace lobe {

namespace {

constexpr char kName[] = "self-organizing";

const std::string& text_param(const GrowerChoice& c, const std::string& key, const std::string& where,
                              const std::string& fallback)
{
    const auto it = c.params.find(key);
    if (it == c.params.end()) return fallback;
    if (const auto* s = std::get_if<std::string>(&it->second)) return *s;
    throw InvalidInput(where + ".params." + key + ": expected a text");
}

double number_param(const GrowerChoice& c, const std::string& key, const std::string& where, double fallback)
{
    const auto it = c.params.find(key);
    if (it == c.params.end()) return fallback;
    if (const auto* i = std::get_if<std::int64_t>(&it->second)) return static_cast<double>(*i);
    if (const auto* d = std::get_if<double>(&it->second)) return *d;
    throw InvalidInput(where + ".params." + key + ": expected a number");
}

double mesh_volume(const TriangleMesh& mesh)
{
    double six_v = 0.0;
    for (const auto& t : mesh.triangles) {
        const glm::dvec3 a = mesh.positions[static_cast<std::size_t>(t[0])];
        const glm::dvec3 b = mesh.positions[static_cast<std::size_t>(t[1])];
        const glm::dvec3 c = mesh.positions[static_cast<std::size_t>(t[2])];
        six_v += glm::dot(a, glm::cross(b, c));
    }
    return std::abs(six_v) / 6.0;
}

/// The sketched skeleton as fixed metamers; those inside a lobe carry an axillary bud at right
/// angles to the skeleton (the preset's branch angle tilts them up and left the lower half of
/// the lobes bare), its tips a terminal bud. Every metamer casts shadow and clears the markers around it.
MetamerTree skeleton_metamers(const Skeleton& sk, const std::vector<MeshRaycaster>& rays, const SelfOrgRun& run,
                              MarkerCloud* markers, ShadowGrid& shadow)
{
    MetamerTree tree;
    const auto& nodes = sk.graph.nodes;
    tree.root = nodes.empty() ? glm::vec3(0.0f) : nodes[0].position;
    std::vector<char> has_child(nodes.size(), 0);
    for (std::size_t i = 1; i < nodes.size(); ++i) has_child[static_cast<std::size_t>(nodes[i].parent)] = 1;
    const double angle = 0.5 * std::numbers::pi;
    for (std::size_t i = 1; i < nodes.size(); ++i) {
        Metamer m;
        m.base = nodes[static_cast<std::size_t>(nodes[i].parent)].position;
        m.tip = nodes[i].position;
        const glm::vec3 d = m.tip - m.base;
        m.dir = glm::length(d) > 1e-9f ? glm::normalize(d) : glm::vec3(0.0f, 1.0f, 0.0f);
        m.parent = nodes[i].parent - 1;
        m.fixed = true;
        m.lobe = i < sk.owner.size() ? sk.owner[i] : -1;
        for (std::size_t l = 0; l < rays.size() && m.lobe < 0; ++l)
            if (rays[l].inside(m.tip)) m.lobe = static_cast<int>(l);
        m.phyllotaxis = static_cast<float>(static_cast<double>(i) * run.species.phyllotaxis_deg * std::numbers::pi / 180.0);
        m.lateral_dir = lateral_bud_direction(m.dir, m.phyllotaxis, angle);
        m.lateral_bud = m.lobe >= 0 && static_cast<std::size_t>(m.lobe) < rays.size() &&
                        rays[static_cast<std::size_t>(m.lobe)].inside(m.tip);
        m.terminal_bud = !has_child[i];
        const bool lateral = m.parent >= 0 ? tree.metamers[static_cast<std::size_t>(m.parent)].main_child >= 0
                                           : tree.first_root >= 0;
        tree.add(m, lateral);
        shadow.cast(m.tip);
        if (markers) markers->remove_within(m.tip, run.species.occupancy_radius * run.internode_m);
    }
    return tree;
}

GrowthResult finish(const MetamerTree& tree, const SelfOrgStats& stats, std::size_t lobes,
                    const std::vector<std::string>& messages)
{
    GrowthResult out;
    out.tree = metamer_tree_graph(tree);
    for (const TreeNode& n : out.tree.nodes)
        if (n.kind != TreeNodeKind::Grown) ++out.skeleton_nodes;
    out.lobes.assign(lobes, LobeGrowthStats{});
    for (const TreeNode& n : out.tree.nodes)
        if (n.kind == TreeNodeKind::Grown && n.lobe >= 0 && static_cast<std::size_t>(n.lobe) < lobes)
            ++out.lobes[static_cast<std::size_t>(n.lobe)].nodes;
    for (LobeGrowthStats& l : out.lobes) {
        l.iterations = stats.iterations;
        l.node_cap = stats.metamer_cap;
    }
    out.messages = messages;
    if (stats.metamer_cap)
        out.messages.push_back("self-organizing: growth stopped at the tree's limit of " +
                               std::to_string(tree.metamers.size() + 1) + " nodes");
    return out;
}

GrowthResult grow_in_lobes(const GrowerInput& in, SelfOrgRun run, const SelfOrgChoice& c)
{
    std::vector<TriangleMesh> meshes;
    std::vector<MeshRaycaster> rays;
    double volume = 0.0;
    glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
    float largest_side = 0.0f; ///< of the lobes' bounding boxes' smallest sides
    for (const GrowthLobe& l : in.lobes) {
        meshes.push_back(l.mesh);
        rays.emplace_back(l.mesh);
        volume += mesh_volume(l.mesh);
        glm::vec3 a(std::numeric_limits<float>::max()), b(-std::numeric_limits<float>::max());
        for (const glm::vec3& p : l.mesh.positions) {
            a = glm::min(a, p);
            b = glm::max(b, p);
        }
        lo = glm::min(lo, a);
        hi = glm::max(hi, b);
        largest_side = std::max(largest_side, std::min(b.x - a.x, std::min(b.y - a.y, b.z - a.z)));
    }
    if (!(volume > 0.0) || !std::isfinite(volume)) throw InvalidInput("self-organizing: the lobes enclose no volume");
    run.internode_m = c.internode_m > 0.0 ? c.internode_m : std::cbrt(volume / kSelfOrgLobeCells);
    if (!(largest_side >= 2.0f * static_cast<float>(run.internode_m)))
        throw InvalidInput("self-organizing: the lobes are too small for an internode of " +
                           std::to_string(run.internode_m) + " m");
    std::vector<std::string> messages;
    SkeletonOptions so;
    so.spacing_m = in.settings.growth.skeleton_spacing_m;
    const Skeleton sk = build_skeleton(in.trunk_strokes, meshes, so, &rays);
    messages = sk.messages;
    for (const TreeNode& n : sk.graph.nodes) {
        lo = glm::min(lo, n.position);
        hi = glm::max(hi, n.position);
    }
    const glm::vec3 pad(static_cast<float>(2.0 * run.internode_m));
    ShadowGrid shadow(lo - pad, hi + pad, run.internode_m,
                      {run.species.shadow_a, run.species.shadow_b, run.species.shadow_q_max, run.species.light_c});
    std::vector<std::size_t> marker_end;
    std::vector<glm::vec3> points;
    if (run.environment == SelfOrgEnvironment::Markers)
        for (std::size_t i = 0; i < in.lobes.size(); ++i) {
            const std::vector<glm::vec3> p = markers_in_meshes({meshes[i]}, run.species.marker_spacing * run.internode_m,
                                                              run.seed ^ static_cast<std::uint64_t>(in.lobes[i].id));
            if (points.size() + p.size() > kMaxSelfOrgMarkers)
                throw InvalidInput("self-organizing: the lobes need more than " + std::to_string(kMaxSelfOrgMarkers) +
                                   " markers (use a longer internode)");
            points.insert(points.end(), p.begin(), p.end());
            marker_end.push_back(points.size());
        }
    MarkerCloud cloud(std::move(points), run.species.perception_radius * run.internode_m);
    MarkerCloud* markers = run.environment == SelfOrgEnvironment::Markers ? &cloud : nullptr;
    MetamerTree tree = skeleton_metamers(sk, rays, run, markers, shadow);
    run.confine = &rays;
    run.max_metamers = in.max_tree_nodes > 1 ? in.max_tree_nodes - 1 : 0;
    const SelfOrgStats stats = grow_metamers(tree, run, markers, shadow);
    GrowthResult out = finish(tree, stats, in.lobes.size(), messages);
    for (std::size_t i = 0; i < marker_end.size(); ++i) {
        const std::size_t begin = i ? marker_end[i - 1] : 0;
        out.lobes[i].attractors = marker_end[i] - begin;
        for (std::size_t k = begin; k < marker_end[i]; ++k) out.lobes[i].reached += cloud.alive(k) ? 0 : 1;
    }
    return out;
}

GrowthResult grow_free(const GrowerInput& in, SelfOrgRun run, const SelfOrgChoice& c)
{
    const SelfOrgSpecies& sp = run.species;
    run.internode_m = c.internode_m > 0.0 ? c.internode_m : sp.internode_m;
    const float l = static_cast<float>(run.internode_m);
    SkeletonOptions so;
    so.spacing_m = in.settings.growth.skeleton_spacing_m;
    const Skeleton sk = build_skeleton(in.trunk_strokes, {}, so);
    const glm::vec3 root = sk.graph.empty() ? glm::vec3(0.0f) : sk.graph.nodes[0].position;
    const glm::vec3 centre = root + glm::vec3(0.0f, static_cast<float>(sp.crown_centre_height) * l, 0.0f);
    const float reach = static_cast<float>(sp.crown_radius + sp.perception_radius + 2.0) * l;
    glm::vec3 lo = glm::vec3(centre.x - reach, root.y - 2.0f * l, centre.z - reach);
    glm::vec3 hi = centre + glm::vec3(reach);
    for (const TreeNode& n : sk.graph.nodes) {
        lo = glm::min(lo, n.position);
        hi = glm::max(hi, n.position);
    }
    ShadowGrid shadow(lo, hi, run.internode_m, {sp.shadow_a, sp.shadow_b, sp.shadow_q_max, sp.light_c});
    std::vector<glm::vec3> points;
    if (run.environment == SelfOrgEnvironment::Markers)
        points = markers_in_sphere(centre, sp.crown_radius * run.internode_m, sp.marker_spacing * run.internode_m, run.seed);
    MarkerCloud cloud(std::move(points), sp.perception_radius * run.internode_m);
    MarkerCloud* markers = run.environment == SelfOrgEnvironment::Markers ? &cloud : nullptr;
    const std::vector<MeshRaycaster> no_lobes;
    MetamerTree tree = skeleton_metamers(sk, no_lobes, run, markers, shadow);
    if (tree.metamers.empty()) {
        // No strokes: a stem from the ground to the crown's lower edge (markers), or one
        // internode (shadow), carrying a terminal bud.
        tree.root = root;
        const int stem = run.environment == SelfOrgEnvironment::Markers
                             ? std::max(1, static_cast<int>(sp.crown_centre_height - sp.crown_radius) + 1)
                             : 1;
        for (int k = 0; k < stem; ++k) {
            Metamer m;
            m.base = root + glm::vec3(0.0f, static_cast<float>(k) * l, 0.0f);
            m.tip = m.base + glm::vec3(0.0f, l, 0.0f);
            m.parent = k - 1;
            m.fixed = true;
            m.terminal_bud = k + 1 == stem;
            m.lateral_dir = lateral_bud_direction(m.dir, 0.0f, sp.branch_angle_deg * std::numbers::pi / 180.0);
            tree.add(m, false);
            shadow.cast(m.tip);
        }
    } else {
        for (Metamer& m : tree.metamers) m.lateral_bud = !m.terminal_bud; // a sketched trunk branches all along
    }
    run.max_metamers = in.max_tree_nodes > 1 ? in.max_tree_nodes - 1 : 0;
    const SelfOrgStats stats = grow_metamers(tree, run, markers, shadow);
    return finish(tree, stats, 0, sk.messages);
}

class SelfOrganizingGrower final : public Grower {
public:
    std::string_view name() const override { return kName; }
    std::string_view title() const override { return "Self-organizing tree (Palubicki et al. 2009): light, buds, shedding"; }
    int version() const override { return 1; }
    int panel_code() const override { return 2; }
    void check_params(const GrowerChoice& choice, const std::string& where) const override
    {
        if (choice.version > version())
            throw InvalidInput(where + ".version: " + std::to_string(choice.version) + " is newer than this build reads (" +
                               std::to_string(version()) + ")");
        parse_selforg_choice(choice, where);
    }
    /// Iterations 1 … 500: k iterations grow the first k of a longer growth.
    std::string_view steps_param() const override { return "iterations"; }
    int default_steps(const GrowerChoice& choice) const override
    {
        const SelfOrgChoice c = parse_selforg_choice(choice, "grower");
        return c.iterations > 0 ? c.iterations : selforg_species(c.species).iterations;
    }
    GrowthResult grow(const GrowerInput& in) const override
    {
        const SelfOrgChoice c = parse_selforg_choice(in.choice, "grower.params");
        SelfOrgRun run;
        run.species = selforg_species(c.species);
        run.environment = c.environment;
        run.bud_fate = c.bud_fate;
        run.iterations = c.iterations > 0 ? c.iterations : run.species.iterations;
        run.seed = in.seed;
        return in.lobes.empty() ? grow_free(in, run, c) : grow_in_lobes(in, run, c);
    }
};

const SelfOrganizingGrower kGrower;

} // namespace

SelfOrgChoice parse_selforg_choice(const GrowerChoice& choice, const std::string& where)
{
    SelfOrgChoice c;
    for (const auto& [key, value] : choice.params)
        if (key != "environment" && key != "bud_fate" && key != "iterations" && key != "species" && key != "internode_m")
            throw InvalidInput(where + ".params." + key + ": unknown parameter of the " + kName +
                               " grower (known: environment, bud_fate, iterations, species, internode_m)");
    const std::string env = text_param(choice, "environment", where, "markers");
    if (env == "shadow") c.environment = SelfOrgEnvironment::Shadow;
    else if (env != "markers")
        throw InvalidInput(where + ".params.environment: \"" + env + "\" is neither markers nor shadow");
    const std::string fate = text_param(choice, "bud_fate", where, "borchert-honda");
    if (fate == "priority") c.bud_fate = BudFate::Priority;
    else if (fate != "borchert-honda")
        throw InvalidInput(where + ".params.bud_fate: \"" + fate + "\" is neither borchert-honda nor priority");
    const auto it = choice.params.find("iterations");
    if (it != choice.params.end()) {
        const auto* n = std::get_if<std::int64_t>(&it->second);
        if (!n) throw InvalidInput(where + ".params.iterations: expected a whole number");
        if (*n < 1 || *n > 500) throw InvalidInput(where + ".params.iterations: " + std::to_string(*n) + " is outside [1, 500]");
        c.iterations = static_cast<int>(*n);
    }
    c.species = text_param(choice, "species", where, c.species);
    try {
        selforg_species(c.species);
    } catch (const InvalidInput& e) {
        throw InvalidInput(where + ".params.species: " + e.what());
    }
    c.internode_m = number_param(choice, "internode_m", where, 0.0);
    if (!(c.internode_m == 0.0 || (c.internode_m >= 0.001 && c.internode_m <= 1.0)))
        throw InvalidInput(where + ".params.internode_m: " + std::to_string(c.internode_m) +
                           " is neither 0 (automatic) nor in [0.001, 1]");
    return c;
}

const Grower& self_organizing_grower() { return kGrower; }

TreeGraph metamer_tree_graph(const MetamerTree& tree)
{
    TreeGraph g;
    TreeNode root;
    root.position = tree.root;
    root.kind = TreeNodeKind::Root;
    g.nodes.push_back(root);
    std::vector<int> node_of(tree.metamers.size(), -1);
    for (std::size_t m = 0; m < tree.metamers.size(); ++m) {
        const Metamer& mm = tree.metamers[m];
        if (!mm.alive) continue;
        TreeNode n;
        n.position = mm.tip;
        n.parent = mm.parent >= 0 ? node_of[static_cast<std::size_t>(mm.parent)] : 0;
        if (n.parent < 0) continue; // under a shed metamer (not reached: shedding takes whole branches)
        n.kind = mm.fixed ? TreeNodeKind::Skeleton : TreeNodeKind::Grown;
        n.lobe = mm.lobe;
        node_of[m] = static_cast<int>(g.nodes.size());
        g.nodes.push_back(n);
    }
    return g;
}

} // namespace lobe
