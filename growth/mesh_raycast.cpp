#include "growth/mesh_raycast.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/geometric.hpp>

namespace lobe {

namespace {

constexpr int kLeafSize = 4;

// Möller–Trumbore; returns t or a negative number.
float intersect(const glm::vec3& o, const glm::vec3& d, const glm::vec3& a, const glm::vec3& b, const glm::vec3& c)
{
    const glm::vec3 e1 = b - a, e2 = c - a;
    const glm::vec3 p = glm::cross(d, e2);
    const float det = glm::dot(e1, p);
    if (std::fabs(det) < 1e-12f) return -1.0f;
    const float inv = 1.0f / det;
    const glm::vec3 s = o - a;
    const float u = glm::dot(s, p) * inv;
    if (u < 0.0f || u > 1.0f) return -1.0f;
    const glm::vec3 q = glm::cross(s, e1);
    const float v = glm::dot(d, q) * inv;
    if (v < 0.0f || u + v > 1.0f) return -1.0f;
    return glm::dot(e2, q) * inv;
}

bool hits_box(const glm::vec3& o, const glm::vec3& inv_d, const glm::vec3& lo, const glm::vec3& hi, float t_max)
{
    float t0 = 0.0f, t1 = t_max;
    for (int k = 0; k < 3; ++k) {
        float a = (lo[k] - o[k]) * inv_d[k], b = (hi[k] - o[k]) * inv_d[k];
        if (a > b) std::swap(a, b);
        t0 = std::max(t0, a);
        t1 = std::min(t1, b);
        if (t0 > t1) return false;
    }
    return true;
}

} // namespace

MeshRaycaster::MeshRaycaster(const TriangleMesh& mesh) : mesh_(mesh)
{
    const int n = static_cast<int>(mesh_.triangles.size());
    order_.resize(static_cast<std::size_t>(n));
    std::vector<glm::vec3> centroids(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) {
        order_[static_cast<std::size_t>(i)] = i;
        const auto& t = mesh_.triangles[static_cast<std::size_t>(i)];
        centroids[static_cast<std::size_t>(i)] =
            (mesh_.positions[static_cast<std::size_t>(t[0])] + mesh_.positions[static_cast<std::size_t>(t[1])] +
             mesh_.positions[static_cast<std::size_t>(t[2])]) / 3.0f;
    }
    nodes_.reserve(static_cast<std::size_t>(2 * n / kLeafSize + 2));
    if (n > 0) build(0, n, centroids);
}

int MeshRaycaster::build(int begin, int end, std::vector<glm::vec3>& centroids)
{
    const int index = static_cast<int>(nodes_.size());
    nodes_.push_back({});
    glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
    glm::vec3 clo = lo, chi = hi;
    for (int i = begin; i < end; ++i) {
        const int tri = order_[static_cast<std::size_t>(i)];
        for (int v : mesh_.triangles[static_cast<std::size_t>(tri)]) {
            lo = glm::min(lo, mesh_.positions[static_cast<std::size_t>(v)]);
            hi = glm::max(hi, mesh_.positions[static_cast<std::size_t>(v)]);
        }
        clo = glm::min(clo, centroids[static_cast<std::size_t>(tri)]);
        chi = glm::max(chi, centroids[static_cast<std::size_t>(tri)]);
    }
    nodes_[static_cast<std::size_t>(index)].lo = lo;
    nodes_[static_cast<std::size_t>(index)].hi = hi;
    if (end - begin <= kLeafSize) {
        nodes_[static_cast<std::size_t>(index)].first = begin;
        nodes_[static_cast<std::size_t>(index)].count = end - begin;
        return index;
    }
    const glm::vec3 ext = chi - clo;
    const int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
    const int mid = begin + (end - begin) / 2;
    std::nth_element(order_.begin() + begin, order_.begin() + mid, order_.begin() + end,
                     [&](int a, int b) { return centroids[static_cast<std::size_t>(a)][axis] < centroids[static_cast<std::size_t>(b)][axis]; });
    build(begin, mid, centroids);
    const int right = build(mid, end, centroids);
    nodes_[static_cast<std::size_t>(index)].first = right;
    nodes_[static_cast<std::size_t>(index)].count = 0;
    return index;
}

// `visit` returns the ray's new t_max: the boxes beyond it are not visited.
template <typename Visit>
void MeshRaycaster::traverse(const glm::vec3& origin, const glm::vec3& dir, float t_max, Visit&& visit) const
{
    if (nodes_.empty()) return;
    const glm::vec3 inv_d(1.0f / (dir.x != 0.0f ? dir.x : 1e-30f), 1.0f / (dir.y != 0.0f ? dir.y : 1e-30f),
                          1.0f / (dir.z != 0.0f ? dir.z : 1e-30f));
    int stack[64];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const int at = stack[--top];
        const Node& node = nodes_[static_cast<std::size_t>(at)];
        if (!hits_box(origin, inv_d, node.lo, node.hi, t_max)) continue;
        if (node.count > 0) {
            for (int i = node.first; i < node.first + node.count; ++i) {
                const auto& t = mesh_.triangles[static_cast<std::size_t>(order_[static_cast<std::size_t>(i)])];
                const float h = intersect(origin, dir, mesh_.positions[static_cast<std::size_t>(t[0])],
                                          mesh_.positions[static_cast<std::size_t>(t[1])],
                                          mesh_.positions[static_cast<std::size_t>(t[2])]);
                if (h > 1e-7f) t_max = visit(h, t_max);
            }
        } else if (top <= 62) { // median splits keep the depth near log2(F / 4) < 62
            stack[top++] = at + 1;      // left child follows its parent
            stack[top++] = node.first;  // right child
        }
    }
}

void MeshRaycaster::crossings(const glm::vec3& origin, const glm::vec3& dir, std::vector<float>& out) const
{
    out.clear();
    traverse(origin, dir, std::numeric_limits<float>::max(), [&](float t, float t_max) {
        out.push_back(t);
        return t_max;
    });
    std::sort(out.begin(), out.end());
    // A ray through a shared edge or vertex hits each triangle there: count the crossing once.
    out.erase(std::unique(out.begin(), out.end(), [](float a, float b) { return b - a < 1e-6f; }), out.end());
}

float MeshRaycaster::first_hit(const glm::vec3& origin, const glm::vec3& dir, float t_max) const
{
    float best = -1.0f;
    // The nearest crossing so far bounds the search: boxes beyond it are skipped.
    traverse(origin, dir, t_max, [&](float t, float bound) {
        if (t < t_max && (best < 0.0f || t < best)) best = t;
        return best >= 0.0f ? std::min(bound, best) : bound;
    });
    return best;
}

bool MeshRaycaster::inside(const glm::vec3& p) const
{
    // A direction no mesh of ours is aligned with, so rays rarely graze edges.
    static const glm::vec3 kDir = glm::normalize(glm::vec3(0.5773f, 0.6211f, 0.5302f));
    thread_local std::vector<float> hits;
    crossings(p, kDir, hits);
    return hits.size() % 2 == 1;
}

float MeshRaycaster::signed_distance_along(const glm::vec3& p, const glm::vec3& dir, bool* inside) const
{
    thread_local std::vector<float> hits;
    crossings(p, dir, hits);
    if (inside) *inside = hits.size() % 2 == 1;
    if (hits.size() % 2 == 1) return hits.front(); // inside: where the ray leaves
    if (hits.size() >= 2) return hits[1];          // outside, entering: where it leaves again
    float best = std::numeric_limits<float>::max();
    for (const glm::vec3& v : mesh_.positions) best = std::min(best, glm::dot(v - p, v - p));
    return mesh_.positions.empty() ? -1.0f : -std::sqrt(best);
}

} // namespace lobe
