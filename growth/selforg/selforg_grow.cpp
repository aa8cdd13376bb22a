// The iteration loop of the self-organizing model (selforg_model.h): perception, bud fate,
// new shoots, shedding.
#include <algorithm>
#include <cmath>
#include <numbers>

#include <glm/geometric.hpp>

#include "core/errors.h"
#include "core/random.h"
#include "growth/mesh_raycast.h"
#include "growth/selforg/markers.h"
#include "growth/selforg/selforg_model.h"
#include "growth/selforg/shadow_grid.h"

namespace lobe {

namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;

/// Per-iteration scratch kept between iterations (no allocation per iteration once grown).
struct Workspace {
    BudValues q, v;
    std::vector<glm::vec3> opt_terminal, opt_lateral;
    std::vector<double> sub, into;
    std::vector<float> best_d2;   ///< per marker: squared distance to the nearest perceiving bud
    std::vector<std::int64_t> best_bud; ///< per marker: that bud (2·metamer + lateral), −1 none
    std::vector<std::uint32_t> touched;
    std::vector<int> marker_count_terminal, marker_count_lateral;
    /// Per bud (2·metamer + lateral): it perceived no marker once, so it never will again
    /// (markers are only removed and a bud's cone never moves): its query is skipped.
    std::vector<std::uint8_t> blind;
    std::vector<float> light;
    std::vector<char> was_alive;
};

/// Markers: each live marker in a bud's cone (r, θ) goes to its nearest such bud; a bud with
/// markers has Q = min(1, light/C) (the shadow of everything dims it) and V towards them.
void perceive_markers(const MetamerTree& tree, const SelfOrgRun& run, const MarkerCloud& markers,
                      const ShadowGrid& shadow, Workspace& ws)
{
    const std::size_t n = tree.metamers.size();
    const SelfOrgSpecies& sp = run.species;
    const double r = sp.perception_radius * run.internode_m;
    const float cos_half = static_cast<float>(std::cos(0.5 * sp.perception_angle_deg * kDegToRad));
    if (ws.best_d2.size() != markers.size()) {
        ws.best_d2.assign(markers.size(), std::numeric_limits<float>::max());
        ws.best_bud.assign(markers.size(), -1);
    }
    ws.touched.clear();
    ws.blind.resize(2 * n, 0);
    for (std::size_t m = 0; m < n; ++m) {
        const Metamer& mm = tree.metamers[m];
        if (!mm.alive) continue;
        // The node's buds that still see markers: terminal (id 2m) before lateral (2m + 1).
        glm::vec3 axes[2];
        std::int64_t ids[2];
        std::size_t seen[2] = {0, 0};
        std::size_t count = 0;
        if (mm.terminal_bud && !ws.blind[2 * m]) {
            axes[count] = mm.dir;
            ids[count++] = static_cast<std::int64_t>(2 * m);
        }
        if (mm.lateral_bud && !ws.blind[2 * m + 1]) {
            axes[count] = mm.lateral_dir;
            ids[count++] = static_cast<std::int64_t>(2 * m + 1);
        }
        if (count == 0) continue;
        markers.for_each_in_cones(mm.tip, r, std::span<const glm::vec3>(axes, count), cos_half,
                                  [&](std::size_t i, float d2, std::size_t cone) {
                                      ++seen[cone];
                                      if (ws.best_bud[i] < 0) ws.touched.push_back(static_cast<std::uint32_t>(i));
                                      if (ws.best_bud[i] < 0 || d2 < ws.best_d2[i]) {
                                          ws.best_d2[i] = d2;
                                          ws.best_bud[i] = ids[cone];
                                      }
                                  });
        for (std::size_t k = 0; k < count; ++k)
            if (seen[k] == 0) ws.blind[static_cast<std::size_t>(ids[k])] = 1;
    }
    ws.marker_count_terminal.assign(n, 0);
    ws.marker_count_lateral.assign(n, 0);
    for (const std::uint32_t i : ws.touched) {
        const std::size_t m = static_cast<std::size_t>(ws.best_bud[i] / 2);
        const bool lateral = ws.best_bud[i] % 2 != 0;
        const glm::vec3 d = glm::normalize(markers.point(i) - tree.metamers[m].tip);
        (lateral ? ws.opt_lateral : ws.opt_terminal)[m] += d;
        ++(lateral ? ws.marker_count_lateral : ws.marker_count_terminal)[m];
        ws.best_bud[i] = -1;
        ws.best_d2[i] = std::numeric_limits<float>::max();
    }
    const double c = sp.light_c;
    for (std::size_t m = 0; m < n; ++m) {
        const Metamer& mm = tree.metamers[m];
        if (!mm.alive || !(ws.marker_count_terminal[m] || ws.marker_count_lateral[m])) continue;
        const double lit = std::min(1.0, static_cast<double>(shadow.light(mm.tip)) / c);
        if (ws.marker_count_terminal[m]) {
            ws.q.terminal[m] = lit;
            ws.opt_terminal[m] = glm::normalize(ws.opt_terminal[m]);
        }
        if (ws.marker_count_lateral[m]) {
            ws.q.lateral[m] = lit;
            ws.opt_lateral[m] = glm::normalize(ws.opt_lateral[m]);
        }
    }
}

/// Shadow alone: Q = max(C − s + a, 0) at the bud.
void perceive_shadow_light(const MetamerTree& tree, const ShadowGrid& shadow, Workspace& ws)
{
    for (std::size_t m = 0; m < tree.metamers.size(); ++m) {
        const Metamer& mm = tree.metamers[m];
        if (!mm.alive || !(mm.terminal_bud || mm.lateral_bud)) continue;
        const double q = shadow.light(mm.tip);
        if (mm.terminal_bud) ws.q.terminal[m] = q;
        if (mm.lateral_bud) ws.q.lateral[m] = q;
    }
}

/// Shadow alone: V towards the least shadowed neighbour voxel inside the perception cone, for
/// the buds that will grow (v ≥ 1), from the shadow as it was when their light was read.
void perceive_shadow_direction(const MetamerTree& tree, const SelfOrgRun& run, const ShadowGrid& shadow, Workspace& ws)
{
    const float cos_half = static_cast<float>(std::cos(0.5 * run.species.perception_angle_deg * kDegToRad));
    for (std::size_t m = 0; m < tree.metamers.size(); ++m) {
        const Metamer& mm = tree.metamers[m];
        if (!mm.alive) continue;
        if (mm.terminal_bud && ws.v.terminal[m] >= 1.0)
            ws.opt_terminal[m] = shadow.least_shadowed_direction(mm.tip, mm.dir, cos_half);
        if (mm.lateral_bud && ws.v.lateral[m] >= 1.0)
            ws.opt_lateral[m] = shadow.least_shadowed_direction(mm.tip, mm.lateral_dir, cos_half);
    }
}

bool inside_any(const std::vector<MeshRaycaster>& lobes, int hint, const glm::vec3& p, int& which)
{
    if (hint >= 0 && static_cast<std::size_t>(hint) < lobes.size() && lobes[static_cast<std::size_t>(hint)].inside(p)) {
        which = hint;
        return true;
    }
    for (std::size_t i = 0; i < lobes.size(); ++i)
        if (static_cast<int>(i) != hint && lobes[i].inside(p)) {
            which = static_cast<int>(i);
            return true;
        }
    return false;
}

/// Bud (m, lateral) with resource v grows ⌊v⌋ metamers (at most max_shoot_metamers) of
/// v/⌊v⌋ internodes each. Returns the metamers made.
std::size_t grow_shoot(MetamerTree& tree, std::size_t m, bool lateral, double v, const glm::vec3& optimal,
                       const SelfOrgRun& run, MarkerCloud* markers, ShadowGrid& shadow, SelfOrgStats& stats)
{
    const SelfOrgSpecies& sp = run.species;
    const double whole = std::floor(v);
    const int n = static_cast<int>(std::min(whole, static_cast<double>(sp.max_shoot_metamers)));
    const float length = static_cast<float>(v / whole * run.internode_m);
    glm::vec3 base = tree.metamers[m].tip;
    glm::vec3 default_dir = lateral ? tree.metamers[m].lateral_dir : tree.metamers[m].dir;
    float phi = tree.metamers[m].phyllotaxis;
    int lobe = tree.metamers[m].lobe;
    int parent = static_cast<int>(m);
    std::size_t made = 0;
    bool stopped = false;
    for (int k = 0; k < n; ++k) {
        if (tree.metamers.size() >= run.max_metamers) {
            stats.metamer_cap = true;
            break;
        }
        const std::size_t index = tree.metamers.size();
        glm::vec3 dir = shoot_direction(default_dir, optimal, sp.tropism, sp.xi, sp.eta);
        if (sp.jitter > 0.0) {
            SplitMix64 rng(splitmix64(run.seed ^ splitmix64(static_cast<std::uint64_t>(index))));
            // Drawn z, y, x in sequence: arguments of one call are evaluated in an unspecified
            // order (GCC right to left, Clang left to right), and a tree must not depend on the
            // compiler. z first is the order GCC builds drew them in before.
            const float jz = static_cast<float>(rng.uniform(-1.0, 1.0));
            const float jy = static_cast<float>(rng.uniform(-1.0, 1.0));
            const float jx = static_cast<float>(rng.uniform(-1.0, 1.0));
            const glm::vec3 j(jx, jy, jz);
            dir = shoot_direction(dir, j, glm::vec3(0.0f), sp.jitter, 0.0);
        }
        const glm::vec3 tip = base + dir * length;
        if (run.confine) {
            // A base known inside lobe `lobe` (a grown metamer's tip): the tip is inside too
            // when the internode crosses no surface of it; else the full parity test.
            const bool base_inside = (k > 0 || !tree.metamers[m].fixed) && lobe >= 0;
            const bool stays = base_inside && (*run.confine)[static_cast<std::size_t>(lobe)].first_hit(base, dir, length) < 0.0f;
            if (!stays && !inside_any(*run.confine, lobe, tip, lobe)) {
                stopped = true;
                break;
            }
        }
        Metamer nm;
        nm.base = base;
        nm.tip = tip;
        nm.dir = dir;
        nm.parent = parent;
        nm.lobe = lobe;
        phi += static_cast<float>(sp.phyllotaxis_deg * kDegToRad);
        nm.phyllotaxis = phi;
        nm.lateral_dir = lateral_bud_direction(dir, phi, sp.branch_angle_deg * kDegToRad);
        nm.lateral_bud = true;
        parent = tree.add(nm, k == 0 && lateral);
        if (markers) stats.markers_removed += markers->remove_within(tip, sp.occupancy_radius * run.internode_m);
        shadow.cast(tip);
        base = tip;
        default_dir = dir;
        ++made;
    }
    Metamer& origin = tree.metamers[m];
    if (made > 0 || stopped) (lateral ? origin.lateral_bud : origin.terminal_bud) = false;
    if (made > 0 && !stopped) tree.metamers[static_cast<std::size_t>(parent)].terminal_bud = true;
    return made;
}

} // namespace

glm::vec3 lateral_bud_direction(const glm::vec3& dir, float phi, double angle_rad)
{
    const glm::vec3 ref = std::abs(dir.y) < 0.9f ? glm::vec3(0.0f, 1.0f, 0.0f) : glm::vec3(1.0f, 0.0f, 0.0f);
    const glm::vec3 u = glm::normalize(glm::cross(dir, ref));
    const glm::vec3 w = glm::cross(dir, u);
    const glm::vec3 radial = std::cos(phi) * u + std::sin(phi) * w;
    return glm::normalize(static_cast<float>(std::cos(angle_rad)) * dir + static_cast<float>(std::sin(angle_rad)) * radial);
}

namespace {

void check_run(const SelfOrgRun& run, const MarkerCloud* markers)
{
    if (!(run.internode_m > 0.0) || !std::isfinite(run.internode_m))
        throw InvalidInput("self-organizing: the internode length must be > 0");
    if (run.iterations < 0) throw InvalidInput("self-organizing: iterations must be ≥ 0");
    if (run.environment == SelfOrgEnvironment::Markers && !markers)
        throw InvalidInput("self-organizing: the markers environment needs markers");
}

/// One iteration on one tree: perception, bud fate, new shoots, shedding. Returns the
/// metamers made.
std::size_t grow_iteration(MetamerTree& tree, const SelfOrgRun& run, MarkerCloud* markers, ShadowGrid& shadow,
                           Workspace& ws, SelfOrgStats& stats)
{
    const bool use_markers = run.environment == SelfOrgEnvironment::Markers;
    const SelfOrgSpecies& sp = run.species;
    const std::size_t n = tree.metamers.size();
    ws.q.assign(n);
    ws.opt_terminal.assign(n, glm::vec3(0.0f));
    ws.opt_lateral.assign(n, glm::vec3(0.0f));
    if (use_markers) perceive_markers(tree, run, *markers, shadow, ws);
    else perceive_shadow_light(tree, shadow, ws);
    if (run.bud_fate == BudFate::BorchertHonda) {
        accumulate_light(tree, ws.q, ws.sub);
        distribute_borchert_honda(tree, ws.q, ws.sub, sp.alpha, sp.lambda, ws.into, ws.v);
    } else {
        distribute_priority(tree, ws.q, sp.alpha, sp.priority_w_max, sp.priority_w_min, sp.priority_kappa, ws.v);
    }
    if (!use_markers) perceive_shadow_direction(tree, run, shadow, ws);
    std::size_t grown = 0;
    for (std::size_t m = 0; m < n && !stats.metamer_cap; ++m) {
        if (!tree.metamers[m].alive) continue;
        if (tree.metamers[m].terminal_bud && ws.v.terminal[m] >= 1.0)
            grown += grow_shoot(tree, m, false, ws.v.terminal[m], ws.opt_terminal[m], run, markers, shadow, stats);
        if (tree.metamers[m].lateral_bud && ws.v.lateral[m] >= 1.0)
            grown += grow_shoot(tree, m, true, ws.v.lateral[m], ws.opt_lateral[m], run, markers, shadow, stats);
    }
    stats.grown += grown;
    ++stats.iterations;
    ws.light.resize(tree.metamers.size());
    for (std::size_t m = 0; m < tree.metamers.size(); ++m)
        ws.light[m] = tree.metamers[m].alive ? shadow.light(tree.metamers[m].tip) : 0.0f;
    ws.was_alive.resize(tree.metamers.size());
    for (std::size_t m = 0; m < tree.metamers.size(); ++m) ws.was_alive[m] = tree.metamers[m].alive;
    shed_starved(tree, ws.light, sp.shed_threshold, sp.shed_min_internodes);
    for (std::size_t m = 0; m < tree.metamers.size(); ++m)
        if (ws.was_alive[m] && !tree.metamers[m].alive) {
            shadow.cast(tree.metamers[m].tip, -1);
            ++stats.shed;
        }
    return grown;
}

} // namespace

SelfOrgStats grow_metamers(MetamerTree& tree, const SelfOrgRun& run, MarkerCloud* markers, ShadowGrid& shadow)
{
    check_run(run, markers);
    SelfOrgStats stats;
    Workspace ws;
    for (int it = 0; it < run.iterations; ++it)
        if (grow_iteration(tree, run, markers, shadow, ws, stats) == 0 || stats.metamer_cap) break;
    return stats;
}

std::vector<SelfOrgStats> grow_metamer_trees(std::span<MetamerTree> trees, const SelfOrgRun& run, MarkerCloud* markers,
                                             ShadowGrid& shadow)
{
    check_run(run, markers);
    std::vector<SelfOrgStats> stats(trees.size());
    std::vector<Workspace> ws(trees.size());
    std::vector<char> done(trees.size(), 0);
    for (int it = 0; it < run.iterations; ++it) {
        bool any = false;
        for (std::size_t t = 0; t < trees.size(); ++t) {
            if (done[t]) continue;
            if (grow_iteration(trees[t], run, markers, shadow, ws[t], stats[t]) == 0 || stats[t].metamer_cap) done[t] = 1;
            any = true;
        }
        if (!any) break;
    }
    return stats;
}

} // namespace lobe
