#include "app/session/tree_pipeline.h"

#include <algorithm>
#include <limits>

#include "growth/grower.h"
#include "growth/radii.h"
#include "growth/real_scale.h"
#include "growth/species.h"
#include "app/session/edit_ops.h"
#include "app/session/stage_options.h"
#include "meshing/model_import.h"

namespace lobe {

std::vector<GrowthLobe> growth_lobes(const Document& doc, const std::vector<BuiltLobe>& lobes)
{
    const SubtreeLibrary& library = default_subtree_library();
    const GrowthSettings& growth = growth_options(doc.settings);
    const std::vector<double> tree_weights = subtree_weights(library, growth.subtree_weights);
    std::vector<GrowthLobe> out;
    for (const BuiltLobe& b : lobes) {
        GrowthLobe g;
        g.id = b.lobe_id;
        g.mesh = b.mesh;
        g.split_angle_deg = growth.split_angle_deg;
        g.subtree_weights = tree_weights;
        for (const LobeRecord& r : doc.lobes) {
            if (r.id != b.lobe_id) continue;
            if (!r.species.empty()) {
                // The lobe's species brings its own split angle and subtree mix.
                Settings s = doc.settings;
                apply_species(s, load_species(r.species));
                g.split_angle_deg = growth_options(s).split_angle_deg;
                g.subtree_weights = subtree_weights(library, growth_options(s).subtree_weights);
            }
            if (r.split_angle_deg) g.split_angle_deg = *r.split_angle_deg;
            g.seed = r.seed;
        }
        out.push_back(std::move(g));
    }
    return out;
}

GrowerInput document_grower_input(const Document& doc, const std::vector<BuiltLobe>& lobes)
{
    std::vector<std::vector<glm::vec3>> trunk;
    for (const Stroke& s : effective_strokes(doc)) {
        if (s.kind != StrokeKind::Trunk) continue;
        std::vector<glm::vec3> pts;
        pts.reserve(s.points.size());
        for (const StrokePoint& p : s.points) pts.push_back(p.position);
        trunk.push_back(std::move(pts));
    }
    GrowerInput in;
    in.trunk_strokes = std::move(trunk);
    in.lobes = growth_lobes(doc, lobes);
    in.settings = doc.settings;
    in.seed = doc.seed;
    in.choice = scene_grower(doc);
    return in;
}

void finish_grown_tree(const Document& doc, BuiltTree& tree)
{
    if (!tree.growth.radii_set) {
        const PipeRadiiOptions radii = pipe_radii_options(doc.settings);
        if (tree.growth.leader_radii)
            assign_leader_radii(tree.growth.tree, radii.exponent, radii.tip_radius_m);
        else
            assign_pipe_radii(tree.growth.tree, radii.exponent, radii.tip_radius_m);
    }
    for (const std::string& m : tree.growth.messages) tree.warnings.push_back("growth: " + m);
}

void apply_real_scale(const Document& doc, BuiltTree& tree)
{
    const double target = doc.settings.growth.height_m;
    const double height = graph_height(tree.growth.tree);
    if (!(target > 0.0) || !(height > 1e-9)) return;
    const double factor = target / height;
    TreeGraph& graph = tree.growth.tree;
    const glm::dvec3 root(graph.nodes[0].position);
    scale_tree_structure(graph, factor);
    const auto scaled = [&](const glm::vec3& p) { return glm::vec3(root + (glm::dvec3(p) - root) * factor); };
    for (BuiltLobe& l : tree.lobes)
        for (glm::vec3& p : l.mesh.positions) p = scaled(p);
    if (tree.growth.radii_set) {
        // The grower's own proportions: its radii and leaves grow with it.
        for (TreeNode& n : graph.nodes) n.radius = static_cast<float>(n.radius * factor);
        if (tree.growth.leaves)
            for (PlacedLeaf& leaf : *tree.growth.leaves) {
                leaf.base = scaled(leaf.base);
                leaf.length_m = static_cast<float>(leaf.length_m * factor);
                leaf.width_m = static_cast<float>(leaf.width_m * factor);
            }
    } else {
        const PipeRadiiOptions radii = pipe_radii_options(doc.settings);
        if (doc.settings.branches.dbh_ratio > 0.0)
            fit_pipe_exponent(graph, radii.tip_radius_m, doc.settings.branches.dbh_ratio, tree.growth.leader_radii);
        else if (tree.growth.leader_radii)
            assign_leader_radii(graph, radii.exponent, radii.tip_radius_m);
        else
            assign_pipe_radii(graph, radii.exponent, radii.tip_radius_m);
    }
    tree.scale *= factor;
}

BuiltTree grow_document_tree(const Document& doc, std::vector<BuiltLobe> lobes)
{
    BuiltTree t;
    t.lobes = std::move(lobes);
    const GrowerInput in = document_grower_input(doc, t.lobes);
    t.growth = checked_grower(in.choice, "trees[0].grower").grow(in);
    finish_grown_tree(doc, t);
    return t;
}

BuiltTree build_document_tree(const Document& doc)
{
    std::vector<std::string> warnings;
    std::vector<BuiltLobe> lobes = build_document_lobes(doc, &warnings);
    BuiltTree t = grow_document_tree(doc, std::move(lobes));
    warnings.insert(warnings.end(), t.warnings.begin(), t.warnings.end());
    t.warnings = std::move(warnings);
    return t;
}

BuiltLobe model_lobe(const std::string& path, const Settings& settings, double size_m, std::int64_t id)
{
    BuiltLobe lobe;
    lobe.lobe_id = id;
    lobe.mesh = lobe_from_model(path, model_import_options(settings, size_m));
    float lo = std::numeric_limits<float>::max(), hi = -lo;
    for (const glm::vec3& p : lobe.mesh.positions) {
        lo = std::min(lo, p.y);
        hi = std::max(hi, p.y);
    }
    for (glm::vec3& p : lobe.mesh.positions) p.y += 0.5f * (hi - lo) - lo;
    return lobe;
}

} // namespace lobe
