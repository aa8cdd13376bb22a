#include "app/live/lsystem_sketch_view.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>

#include "app/render/render_scene.h"
#include "app/render/scene_parts.h"

namespace lobe {

namespace {

constexpr std::array<float, 4> kPlatformColor{0.55f, 0.5f, 0.42f, 1.0f};
constexpr std::array<float, 4> kTrunkColor{0.85f, 0.45f, 0.15f, 1.0f};
constexpr std::array<float, 4> kBranchColor{0.3f, 0.6f, 0.95f, 1.0f};
constexpr std::array<float, 4> kPreviewColor{0.95f, 0.95f, 0.6f, 1.0f};
constexpr std::array<float, 4> kTreeColor{0.36f, 0.25f, 0.17f, 1.0f};
constexpr float kSectionRadiusM = 0.0025f, kNodeRadiusM = 0.005f, kMinTreeRadiusM = 0.002f;

/// The Bézier curve through `nodes` (as the rules draw the sections), on the platform.
std::vector<glm::vec3> platform_points(const LSystemSketchMode& mode, const std::vector<glm::dvec3>& nodes)
{
    std::vector<glm::vec3> out;
    for (const glm::dvec3& p : lsystem::sketch_curve(nodes, lsystem::kDefaultCurveSteps)) out.emplace_back(mode.platform_point(p));
    return out;
}

/// Each segment of `tree` as an open prism of kTreeSides sides and its end node's radius (at
/// least kMinTreeRadiusM), into `g` (its storage reused).
void build_tree_mesh(const TreeGraph& tree, SurfaceGeometry& g)
{
    constexpr int kTreeSides = 5;
    g.positions.clear();
    g.normals.clear();
    g.uvs.clear();
    g.triangles.clear();
    const std::size_t segments = tree.nodes.empty() ? 0 : tree.nodes.size() - 1;
    g.positions.reserve(segments * 2 * kTreeSides);
    g.normals.reserve(segments * 2 * kTreeSides);
    g.triangles.reserve(segments * 2 * kTreeSides);
    std::array<glm::vec3, kTreeSides> ring{};
    for (int k = 0; k < kTreeSides; ++k) {
        const float a = 6.2831853f * static_cast<float>(k) / kTreeSides;
        ring[static_cast<std::size_t>(k)] = {std::cos(a), std::sin(a), 0.0f};
    }
    for (const TreeNode& node : tree.nodes) {
        if (node.parent < 0) continue;
        const glm::vec3 a = tree.nodes[static_cast<std::size_t>(node.parent)].position, b = node.position;
        const glm::vec3 d = b - a;
        const float len = glm::length(d);
        if (!(len > 1e-7f)) continue;
        const glm::vec3 w = d / len;
        const glm::vec3 helper = std::fabs(w.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
        const glm::vec3 u = glm::normalize(glm::cross(helper, w)), v = glm::cross(w, u);
        const float r = std::max(kMinTreeRadiusM, node.radius);
        const auto base = static_cast<std::uint32_t>(g.positions.size());
        for (int end = 0; end < 2; ++end)
            for (const glm::vec3& c : ring) {
                const glm::vec3 n = u * c.x + v * c.y;
                g.positions.push_back((end ? b : a) + n * r);
                g.normals.push_back(n);
            }
        for (std::uint32_t k = 0; k < kTreeSides; ++k) {
            const std::uint32_t k1 = (k + 1) % kTreeSides;
            g.triangles.push_back({base + k, base + k1, base + kTreeSides + k1});
            g.triangles.push_back({base + k, base + kTreeSides + k1, base + kTreeSides + k});
        }
    }
}

} // namespace

void LSystemSketchView::append(const LSystemSketchMode& mode, RenderScene& scene, const SceneTransform& t)
{
    if (!mode.active()) return;
    const bool moved = t.scale != last_transform_.scale || t.yaw != last_transform_.yaw ||
                       t.translation != last_transform_.translation;
    last_transform_ = t;
    const glm::quat inverse = glm::inverse(t.rotation());
    auto add = [&](std::array<float, 4> color, SurfaceGeometry g, std::uint64_t version, std::uint64_t index,
                   bool in_stage = true) {
        const std::uint64_t key = kKeyBase | index;
        if (g.triangles.empty()) return;
        if (g.uvs.size() != g.positions.size()) g.uvs.clear(); // tubes and beads together: no texture
        if (in_stage && !t.identity()) {
            for (glm::vec3& p : g.positions) p = t.to_document(p);
            for (glm::vec3& v : g.normals) v = inverse * v;
        }
        RenderItem item;
        item.key = key;
        item.version = version;
        item.material = RenderMaterial::Stroke;
        item.color = color;
        item.geometry = std::move(g);
        scene.items.push_back(std::move(item));
    };
    ++version_;
    // The platform: a ring of its grab radius at the root.
    const SketchPlatform& pf = mode.platform();
    std::vector<glm::vec3> ring;
    for (int i = 0; i <= 48; ++i) {
        const double a = 2.0 * 3.14159265358979 * i / 48.0;
        ring.emplace_back(pf.position + glm::dvec3(std::cos(a), 0.0, std::sin(a)) * LSystemSketchMode::kGrabRadiusM);
    }
    add(kPlatformColor, polyline_tube(ring, 0.004f, 6), version_, 0);

    // The sketch: sections and nodes, the dragged node larger.
    const lsystem::Sketch& s = mode.sketch();
    SurfaceGeometry trunk = polyline_tube(platform_points(mode, s.trunk), kSectionRadiusM, 6);
    for (std::size_t i = 0; i < s.trunk.size(); ++i) {
        const bool dragged = mode.dragging() && mode.dragging()->first < 0 && mode.dragging()->second == static_cast<int>(i);
        append_sphere(trunk, glm::vec3(mode.platform_point(s.trunk[i])), dragged ? 2.0f * kNodeRadiusM : kNodeRadiusM);
    }
    add(kTrunkColor, std::move(trunk), version_, 1);
    SurfaceGeometry branches;
    for (std::size_t b = 0; b < s.branches.size(); ++b) {
        std::vector<glm::dvec3> nodes{s.trunk[static_cast<std::size_t>(s.branches[b].attach)]};
        nodes.insert(nodes.end(), s.branches[b].points.begin(), s.branches[b].points.end());
        append_geometry(branches, polyline_tube(platform_points(mode, nodes), kSectionRadiusM, 6));
        for (std::size_t i = 1; i < nodes.size(); ++i) {
            const bool dragged = mode.dragging() && mode.dragging()->first == static_cast<int>(b) &&
                                 mode.dragging()->second == static_cast<int>(i - 1);
            append_sphere(branches, glm::vec3(mode.platform_point(nodes[i])), dragged ? 2.0f * kNodeRadiusM : kNodeRadiusM);
        }
    }
    add(kBranchColor, std::move(branches), version_, 2);
    if (mode.preview())
        add(kPreviewColor, polyline_tube({glm::vec3(mode.preview()->first), glm::vec3(mode.preview()->second)}, 0.0015f, 5),
            version_, 3);

    // The full-size tree: a prism per segment, made again only after a regrowth or when the
    // scene moved, else taken back from last frame's item (reclaim).
    if (moved || !held_ || mode.tree_generation() != tree_generation_) {
        ++tree_version_;
        tree_generation_ = mode.tree_generation();
        build_tree_mesh(mode.tree(), tree_mesh_);
        if (!t.identity()) {
            for (glm::vec3& p : tree_mesh_.positions) p = t.to_document(p);
            for (glm::vec3& v : tree_mesh_.normals) v = inverse * v;
        }
    }
    held_ = false;
    add(kTreeColor, std::move(tree_mesh_), tree_version_, kTreeItem, /*in_stage=*/false);
}

void LSystemSketchView::reclaim(std::vector<RenderItem>& items)
{
    for (RenderItem& item : items)
        if (item.key == (kKeyBase | kTreeItem) && item.version == tree_version_) {
            tree_mesh_ = std::move(item.geometry);
            item.geometry = SurfaceGeometry{};
            held_ = true;
            return;
        }
}

} // namespace lobe
