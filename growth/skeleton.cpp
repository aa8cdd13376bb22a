#include "growth/skeleton.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "growth/mesh_raycast.h"
#include "growth/species_form.h"

namespace lobe {

namespace {

constexpr float kTouchDistance = 0.05f;
// A trunk stroke farther than this from every lobe's box is reported (it carries no branches).
constexpr float kFarFromLobes = 0.3f;

bool finite(const glm::vec3& p)
{
    return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z) && std::fabs(p.x) < 1e3f &&
           std::fabs(p.y) < 1e3f && std::fabs(p.z) < 1e3f;
}

double polyline_length(const std::vector<glm::vec3>& pts)
{
    double l = 0.0;
    for (std::size_t i = 1; i < pts.size(); ++i) l += glm::distance(pts[i - 1], pts[i]);
    return l;
}

// Points every `spacing` along the polyline, both ends kept.
std::vector<glm::vec3> resample(const std::vector<glm::vec3>& pts, double spacing)
{
    const double length = polyline_length(pts);
    const int pieces = std::max(1, static_cast<int>(std::ceil(length / spacing)));
    const double step = length / pieces;
    std::vector<glm::vec3> out{pts.front()};
    double walked = 0.0, next = step;
    for (std::size_t i = 1; i < pts.size() && static_cast<int>(out.size()) < pieces; ++i) {
        const double seg = glm::distance(pts[i - 1], pts[i]);
        while (seg > 0.0 && next <= walked + seg && static_cast<int>(out.size()) < pieces) {
            const float f = static_cast<float>((next - walked) / seg);
            out.push_back(pts[i - 1] + f * (pts[i] - pts[i - 1]));
            next += step;
        }
        walked += seg;
    }
    out.push_back(pts.back());
    return out;
}

struct LobeBox {
    glm::vec3 centroid{0.0f}, lo{0.0f}, hi{0.0f};
};

LobeBox lobe_box(const TriangleMesh& m)
{
    LobeBox b;
    b.lo = glm::vec3(std::numeric_limits<float>::max());
    b.hi = -b.lo;
    for (const glm::vec3& p : m.positions) {
        b.centroid += p;
        b.lo = glm::min(b.lo, p);
        b.hi = glm::max(b.hi, p);
    }
    if (!m.positions.empty()) b.centroid /= static_cast<float>(m.positions.size());
    return b;
}

class Builder {
public:
    Builder(Skeleton& s, double spacing) : s_(s), spacing_(spacing) {}

    int add(const glm::vec3& p, int parent, int owner)
    {
        TreeNode n;
        n.position = p;
        n.parent = parent;
        n.kind = parent < 0 ? TreeNodeKind::Root : TreeNodeKind::Skeleton;
        s_.graph.nodes.push_back(n);
        s_.owner.push_back(owner);
        return static_cast<int>(s_.graph.nodes.size()) - 1;
    }
    // Adds the points of `pts` after node `from` (pts[0] is dropped when it sits on `from`).
    int chain(int from, const std::vector<glm::vec3>& pts, int owner)
    {
        int last = from;
        for (std::size_t i = 0; i < pts.size(); ++i) {
            if (i == 0 && last >= 0 && glm::distance(pts[0], s_.graph.nodes[static_cast<std::size_t>(last)].position) < 1e-4f)
                continue;
            last = add(pts[i], last, owner);
        }
        return last;
    }
    // A straight or bent segment from node `from` to `to`, resampled.
    void limb(int from, const glm::vec3& to, int owner, bool rise_first)
    {
        const glm::vec3 a = s_.graph.nodes[static_cast<std::size_t>(from)].position;
        std::vector<glm::vec3> pts;
        const float len = glm::distance(a, to);
        const glm::vec3 ctrl = rise_first ? a + glm::vec3(0.0f, 0.5f * len, 0.0f) : 0.5f * (a + to);
        const int pieces = std::max(1, static_cast<int>(std::ceil(len / spacing_)));
        for (int i = 0; i <= pieces; ++i) {
            const float t = static_cast<float>(i) / static_cast<float>(pieces);
            pts.push_back((1 - t) * (1 - t) * a + 2 * (1 - t) * t * ctrl + t * t * to); // quadratic Bézier
        }
        chain(from, pts, owner);
    }
    // Nearest node shared by every lobe (limbs made for one lobe are not joined to).
    int nearest(const glm::vec3& p, float* dist = nullptr) const
    {
        int best = 0;
        float bd = std::numeric_limits<float>::max();
        for (std::size_t i = 0; i < s_.graph.nodes.size(); ++i) {
            if (s_.owner[i] != -1) continue;
            const glm::vec3 d = s_.graph.nodes[i].position - p;
            const float d2 = glm::dot(d, d);
            if (d2 < bd) {
                bd = d2;
                best = static_cast<int>(i);
            }
        }
        if (dist) *dist = std::sqrt(bd);
        return best;
    }

private:
    Skeleton& s_;
    double spacing_;
};

/// An excurrent tree (SkeletonOptions::leader): the trunk goes on from its highest point up
/// through the crown (default_leader_points).
void add_leader(Builder& b, const Skeleton& s, const std::vector<TriangleMesh>& lobes, const std::vector<LobeBox>& boxes,
                const SkeletonOptions& options)
{
    glm::vec3 lo(std::numeric_limits<float>::max()), hi = -lo;
    for (std::size_t i = 0; i < lobes.size(); ++i) {
        if (lobes[i].positions.empty()) continue;
        lo = glm::min(lo, boxes[i].lo);
        hi = glm::max(hi, boxes[i].hi);
    }
    if (s.graph.nodes.empty() || !(lo.y <= hi.y)) return;
    std::size_t top = 0;
    for (std::size_t i = 0; i < s.graph.nodes.size(); ++i)
        if (s.owner[i] == -1 && s.graph.nodes[i].position.y > s.graph.nodes[top].position.y) top = i;
    b.chain(static_cast<int>(top),
            default_leader_points(s.graph.nodes[top].position, lo.y, hi.y, options.whorl_spacing, options.spacing_m), -1);
}

} // namespace

Skeleton build_skeleton(const std::vector<std::vector<glm::vec3>>& trunk_strokes,
                        const std::vector<TriangleMesh>& lobes, const SkeletonOptions& options,
                        const std::vector<MeshRaycaster>* rays)
{
    Skeleton s;
    double spacing = std::max(options.spacing_m, 1e-3);

    // Usable strokes: finite points, at least two, longer than the spacing.
    std::vector<std::vector<glm::vec3>> strokes;
    std::vector<std::size_t> stroke_number; // 1-based, in the caller's list
    for (std::size_t i = 0; i < trunk_strokes.size(); ++i) {
        if (strokes.size() >= kMaxTrunkStrokes) {
            s.messages.push_back("trunk strokes beyond the first " + std::to_string(kMaxTrunkStrokes) + " are left out");
            break;
        }
        std::vector<glm::vec3> pts;
        for (const glm::vec3& p : trunk_strokes[i])
            if (finite(p) && (pts.empty() || glm::distance(pts.back(), p) > 1e-5f)) pts.push_back(p);
        if (pts.size() < 2 || polyline_length(pts) < spacing) {
            s.messages.push_back("trunk stroke " + std::to_string(i + 1) + " is too short or not finite: left out");
            continue;
        }
        strokes.push_back(std::move(pts));
        stroke_number.push_back(i + 1);
    }
    // Keep the node count bounded however long the strokes are.
    double total = 0.0;
    for (const auto& st : strokes) total += polyline_length(st);
    if (total / spacing > static_cast<double>(kMaxSkeletonNodes) * 0.5) {
        spacing = total / (static_cast<double>(kMaxSkeletonNodes) * 0.5);
        s.messages.push_back("trunk strokes are very long: skeleton spacing raised to " + std::to_string(spacing) + " m");
    }
    Builder b(s, spacing);

    std::vector<LobeBox> boxes;
    for (const TriangleMesh& m : lobes) boxes.push_back(lobe_box(m));
    // A stroke far from every lobe joins the skeleton but carries no branches: say so.
    if (!lobes.empty())
        for (std::size_t i = 0; i < strokes.size(); ++i) {
            float nearest = std::numeric_limits<float>::max();
            for (const glm::vec3& p : strokes[i])
                for (std::size_t l = 0; l < lobes.size(); ++l)
                    if (!lobes[l].positions.empty())
                        nearest = std::min(nearest, glm::length(glm::max(glm::max(boxes[l].lo - p, p - boxes[l].hi), glm::vec3(0.0f))));
            if (nearest > kFarFromLobes)
                s.messages.push_back("trunk stroke " + std::to_string(stroke_number[i]) + " is more than " +
                                     std::to_string(static_cast<int>(kFarFromLobes * 100)) +
                                     " cm from every lobe: it grows no branches");
        }

    if (!strokes.empty()) {
        s.from_strokes = true;
        // §5.1: the stroke with the lowest point is the main branch, from its lower end.
        std::size_t main = 0;
        float lowest = std::numeric_limits<float>::max();
        for (std::size_t i = 0; i < strokes.size(); ++i)
            for (const glm::vec3& p : strokes[i])
                if (p.y < lowest) {
                    lowest = p.y;
                    main = i;
                }
        std::vector<glm::vec3> m = resample(strokes[main], spacing);
        if (m.back().y < m.front().y) std::reverse(m.begin(), m.end());
        const int root = b.add(m.front(), -1, -1);
        b.chain(root, std::vector<glm::vec3>(m.begin() + 1, m.end()), -1);

        std::vector<std::vector<glm::vec3>> rest;
        for (std::size_t i = 0; i < strokes.size(); ++i)
            if (i != main) rest.push_back(resample(strokes[i], spacing));
        // The others join one by one, the nearest to the skeleton first (§5.1): each at the
        // skeleton node nearest the stroke, through the stroke's point nearest that node. A
        // stroke that touches the skeleton at an end grows from there; one that touches it in
        // its middle grows both ways from there.
        while (!rest.empty()) {
            std::size_t pick = 0, at = 0;
            int attach = 0;
            float best = std::numeric_limits<float>::max();
            for (std::size_t i = 0; i < rest.size(); ++i)
                for (std::size_t k = 0; k < rest[i].size(); ++k) {
                    float d = 0.0f;
                    const int n = b.nearest(rest[i][k], &d);
                    if (d < best) {
                        best = d;
                        pick = i;
                        at = k;
                        attach = n;
                    }
                }
            std::vector<glm::vec3> st = std::move(rest[pick]);
            rest.erase(rest.begin() + static_cast<std::ptrdiff_t>(pick));
            // The longer side from the attachment point first (it continues the joint).
            std::vector<glm::vec3> ahead(st.begin() + static_cast<std::ptrdiff_t>(at), st.end());
            std::vector<glm::vec3> behind(st.begin(), st.begin() + static_cast<std::ptrdiff_t>(at) + 1);
            std::reverse(behind.begin(), behind.end());
            if (polyline_length(behind) > polyline_length(ahead)) std::swap(ahead, behind);
            const int joint = b.chain(attach, {ahead.front()}, -1);
            b.chain(joint, ahead, -1);
            if (behind.size() >= 2 && polyline_length(behind) >= 0.5 * spacing) b.chain(joint, behind, -1);
        }
    } else if (!lobes.empty()) {
        // Default trunk: from the ground below the lobes up to a fork under the lowest lobe.
        glm::vec3 lo(std::numeric_limits<float>::max()), hi = -lo, centre(0.0f);
        float weight = 0.0f;
        for (std::size_t i = 0; i < lobes.size(); ++i) {
            lo = glm::min(lo, boxes[i].lo);
            hi = glm::max(hi, boxes[i].hi);
            const float w = static_cast<float>(lobes[i].positions.size());
            centre += w * boxes[i].centroid;
            weight += w;
        }
        if (weight > 0.0f) centre /= weight;
        const float height = std::max(hi.y - lo.y, 0.05f);
        float base_y = lo.y - static_cast<float>(options.default_trunk_fraction) * height;
        if (lo.y >= 0.0f) base_y = std::max(base_y, 0.0f);
        const glm::vec3 base(centre.x, base_y, centre.z);
        const glm::vec3 fork(centre.x, std::max(base_y + 0.5f * (lo.y - base_y), lo.y - 0.1f * height), centre.z);
        const int root = b.add(base, -1, -1);
        b.limb(root, fork, -1, false);
    } else {
        return s;
    }

    if (options.leader) add_leader(b, s, lobes, boxes, options);

    // Every lobe must be reached: a lobe that no skeleton node enters gets a limb to its centre.
    for (std::size_t l = 0; l < lobes.size(); ++l) {
        if (lobes[l].positions.empty()) continue;
        std::optional<MeshRaycaster> own;
        if (!rays || rays->size() != lobes.size()) own.emplace(lobes[l]);
        const MeshRaycaster& ray = own ? *own : (*rays)[l];
        bool reached = false;
        for (const TreeNode& n : s.graph.nodes)
            if (ray.inside(n.position)) {
                reached = true;
                break;
            }
        if (reached) continue;
        float d = 0.0f;
        const int from = b.nearest(boxes[l].centroid, &d);
        // How far the trunk stays from the lobe: a stroke that ends just short of it (within
        // kTouchDistance) touches it and simply continues into it.
        const glm::vec3 at = s.graph.nodes[static_cast<std::size_t>(from)].position;
        float gap2 = std::numeric_limits<float>::max();
        for (const glm::vec3& v : lobes[l].positions) gap2 = std::min(gap2, glm::dot(v - at, v - at));
        b.limb(from, boxes[l].centroid, static_cast<int>(l), !s.from_strokes);
        if (s.from_strokes && std::sqrt(gap2) > kTouchDistance)
            s.messages.push_back("lobe " + std::to_string(l + 1) + ": no trunk stroke reaches it (the nearest ends " +
                                 std::to_string(static_cast<int>(std::lround(std::sqrt(gap2) * 100))) +
                                 " cm away); a limb joins it to the nearest trunk point");
    }
    return s;
}

} // namespace lobe
