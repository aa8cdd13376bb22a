#include "growth/selforg/selforg_model.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <glm/geometric.hpp>

#include "core/errors.h"
#include "core/random.h"
#include "growth/mesh_raycast.h"
#include "growth/selforg/markers.h"
#include "growth/selforg/shadow_grid.h"

namespace lobe {

int MetamerTree::add(Metamer m, bool lateral)
{
    const int index = static_cast<int>(metamers.size());
    m.main_child = m.first_lateral = m.next_lateral = -1;
    auto push_front = [&](int& head) {
        m.next_lateral = head;
        head = index;
    };
    if (m.parent < 0) {
        // Roots keep their order: the first root is the main axis.
        if (first_root < 0) {
            first_root = index;
        } else {
            int r = first_root;
            while (metamers[static_cast<std::size_t>(r)].next_lateral >= 0) r = metamers[static_cast<std::size_t>(r)].next_lateral;
            metamers[static_cast<std::size_t>(r)].next_lateral = index;
        }
    } else if (lateral) {
        push_front(metamers[static_cast<std::size_t>(m.parent)].first_lateral);
    } else {
        metamers[static_cast<std::size_t>(m.parent)].main_child = index;
    }
    metamers.push_back(m);
    return index;
}

double accumulate_light(const MetamerTree& tree, const BudValues& q, std::vector<double>& sub)
{
    const std::size_t n = tree.metamers.size();
    sub.assign(n, 0.0);
    for (std::size_t m = 0; m < n; ++m) {
        const Metamer& mm = tree.metamers[m];
        if (!mm.alive) continue;
        if (mm.terminal_bud) sub[m] += q.terminal[m];
        if (mm.lateral_bud) sub[m] += q.lateral[m];
    }
    double base = 0.0;
    for (std::size_t m = n; m-- > 0;) {
        const Metamer& mm = tree.metamers[m];
        if (!mm.alive) continue;
        if (mm.parent >= 0) sub[static_cast<std::size_t>(mm.parent)] += sub[m];
        else base += sub[m];
    }
    return base;
}

namespace {

/// One branching of Borchert–Honda: `v` split between the main side (light q_main) and the
/// lateral sides. `out` pointers receive the shares.
struct Side {
    double q = 0.0;
    double* out = nullptr;
};

void split_resource(double v, double lambda, Side main, std::span<const Side> laterals)
{
    double q_lateral = 0.0;
    for (const Side& s : laterals) q_lateral += s.q;
    const double denom = lambda * main.q + (1.0 - lambda) * q_lateral;
    if (main.out) *main.out = denom > 0.0 ? v * lambda * main.q / denom : 0.0;
    for (const Side& s : laterals) *s.out = denom > 0.0 ? v * (1.0 - lambda) * s.q / denom : 0.0;
}

} // namespace

void distribute_borchert_honda(const MetamerTree& tree, const BudValues& q, const std::vector<double>& sub,
                               double alpha, double lambda, std::vector<double>& into, BudValues& v)
{
    const std::size_t n = tree.metamers.size();
    into.assign(n, 0.0);
    v.assign(n);
    std::vector<Side> laterals;
    double q_base = 0.0;
    for (int r = tree.first_root; r >= 0; r = tree.metamers[static_cast<std::size_t>(r)].next_lateral)
        if (tree.metamers[static_cast<std::size_t>(r)].alive) q_base += sub[static_cast<std::size_t>(r)];
    // The base: the first root is the main axis, the others laterals.
    Side main_root;
    for (int r = tree.first_root; r >= 0; r = tree.metamers[static_cast<std::size_t>(r)].next_lateral) {
        if (!tree.metamers[static_cast<std::size_t>(r)].alive) continue;
        const Side s{sub[static_cast<std::size_t>(r)], &into[static_cast<std::size_t>(r)]};
        if (!main_root.out) main_root = s;
        else laterals.push_back(s);
    }
    split_resource(alpha * q_base, lambda, main_root, laterals);
    for (std::size_t m = 0; m < n; ++m) {
        const Metamer& mm = tree.metamers[m];
        if (!mm.alive) continue;
        Side main;
        if (mm.main_child >= 0 && tree.metamers[static_cast<std::size_t>(mm.main_child)].alive)
            main = {sub[static_cast<std::size_t>(mm.main_child)], &into[static_cast<std::size_t>(mm.main_child)]};
        else if (mm.terminal_bud)
            main = {q.terminal[m], &v.terminal[m]};
        laterals.clear();
        for (int l = mm.first_lateral; l >= 0; l = tree.metamers[static_cast<std::size_t>(l)].next_lateral)
            if (tree.metamers[static_cast<std::size_t>(l)].alive)
                laterals.push_back({sub[static_cast<std::size_t>(l)], &into[static_cast<std::size_t>(l)]});
        if (mm.lateral_bud) laterals.push_back({q.lateral[m], &v.lateral[m]});
        split_resource(into[m], lambda, main, laterals);
    }
}

void distribute_priority(const MetamerTree& tree, const BudValues& q, double alpha, double w_max, double w_min,
                         double kappa, BudValues& v)
{
    const std::size_t n = tree.metamers.size();
    v.assign(n);
    struct Bud {
        double q;
        std::size_t id; ///< 2·metamer + (1 for the lateral bud)
    };
    std::vector<Bud> buds;
    double q_base = 0.0;
    for (std::size_t m = 0; m < n; ++m) {
        const Metamer& mm = tree.metamers[m];
        if (!mm.alive) continue;
        if (mm.terminal_bud && q.terminal[m] > 0.0) buds.push_back({q.terminal[m], 2 * m});
        if (mm.lateral_bud && q.lateral[m] > 0.0) buds.push_back({q.lateral[m], 2 * m + 1});
    }
    for (const Bud& b : buds) q_base += b.q; // in index order: the same sum as accumulate_light's order may differ
    std::sort(buds.begin(), buds.end(), [](const Bud& a, const Bud& b) { return a.q != b.q ? a.q > b.q : a.id < b.id; });
    const std::size_t count = buds.size();
    const std::size_t top = std::min(count, static_cast<std::size_t>(std::ceil(kappa * static_cast<double>(count))));
    std::vector<double> w(count);
    double denom = 0.0;
    for (std::size_t k = 0; k < count; ++k) {
        w[k] = k < top ? w_max
                       : w_max + (w_min - w_max) * static_cast<double>(k - top + 1) / static_cast<double>(count - top);
        denom += buds[k].q * w[k];
    }
    if (!(denom > 0.0)) return;
    const double total = alpha * q_base;
    for (std::size_t k = 0; k < count; ++k) {
        const std::size_t m = buds[k].id / 2;
        (buds[k].id % 2 ? v.lateral[m] : v.terminal[m]) = total * buds[k].q * w[k] / denom;
    }
}

glm::vec3 shoot_direction(const glm::vec3& default_dir, const glm::vec3& optimal, const glm::vec3& tropism, double xi,
                          double eta)
{
    const glm::vec3 sum = default_dir + static_cast<float>(xi) * optimal + static_cast<float>(eta) * tropism;
    const float len = glm::length(sum);
    return len > 1e-6f ? sum / len : default_dir;
}

std::vector<int> shed_starved(MetamerTree& tree, const std::vector<float>& light, double threshold, int min_internodes)
{
    const std::size_t n = tree.metamers.size();
    std::vector<double> light_sum(n, 0.0);
    std::vector<std::int64_t> count(n, 0);
    for (std::size_t m = n; m-- > 0;) {
        const Metamer& mm = tree.metamers[m];
        if (!mm.alive) continue;
        light_sum[m] += light[m];
        count[m] += 1;
        if (mm.parent >= 0) {
            light_sum[static_cast<std::size_t>(mm.parent)] += light_sum[m];
            count[static_cast<std::size_t>(mm.parent)] += count[m];
        }
    }
    std::vector<int> shed_roots;
    std::vector<std::uint8_t> is_lateral(n, 0);
    for (std::size_t m = 0; m < n; ++m)
        for (int l = tree.metamers[m].first_lateral; l >= 0; l = tree.metamers[static_cast<std::size_t>(l)].next_lateral)
            is_lateral[static_cast<std::size_t>(l)] = 1;
    for (std::size_t m = 0; m < n; ++m) {
        Metamer& mm = tree.metamers[m];
        if (!mm.alive) continue;
        if (mm.parent >= 0 && !tree.metamers[static_cast<std::size_t>(mm.parent)].alive) {
            mm.alive = false; // carried by a shed branch
            continue;
        }
        if (!is_lateral[m] || mm.fixed || count[m] < min_internodes) continue;
        if (light_sum[m] / static_cast<double>(count[m]) < threshold) {
            mm.alive = false;
            shed_roots.push_back(static_cast<int>(m));
        }
    }
    return shed_roots;
}

} // namespace lobe
