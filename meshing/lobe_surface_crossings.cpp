// Stage 3 of a lobe surface build (lobe_surface_builder.h): where the strokes cross, seen from
// the lobe's centre. No CGAL.
#include "meshing/lobe_surface_builder.h"

#include <algorithm>
#include <array>
#include <limits>
#include <map>
#include <string>
#include <tuple>
#include <utility>

#include <glm/geometric.hpp>

#include "core/errors.h"

namespace lobe {

namespace lobe_surface_detail {

namespace {

/// Proper crossing of the arcs a0a1 and b0b1 between unit directions, each shorter than 90°
/// (make_directions): each arc's ends lie strictly on opposite sides of the other's great
/// circle, and the two arcs lie on the same side of the sphere. `s` and `t` are where each
/// chord meets the other's plane. Ends touching or on the other arc count as none (adjacent
/// segments meet there by construction).
bool arc_crossing(const glm::dvec3& a0, const glm::dvec3& a1, const glm::dvec3& b0, const glm::dvec3& b1, double& s,
                  double& t)
{
    const double sa0 = orient3(a0, a1, b0), sa1 = orient3(a0, a1, b1);
    if (!((sa0 > 0.0 && sa1 < 0.0) || (sa0 < 0.0 && sa1 > 0.0))) return false;
    const double sb0 = orient3(b0, b1, a0), sb1 = orient3(b0, b1, a1);
    if (!((sb0 > 0.0 && sb1 < 0.0) || (sb0 < 0.0 && sb1 > 0.0))) return false;
    if (!(glm::dot(a0 + a1, b0 + b1) > 0.0)) return false;
    s = sb0 / (sb0 - sb1);
    t = sa0 / (sa0 - sa1);
    return true;
}

/// The segments of all strokes, as arcs between unit directions, binned in a uniform grid
/// over [-1, 1]³ by the box of each arc (its chord's box grown by the arc's sagitta), so
/// that every pair of arcs that cross shares a cell and crossings are found in time about
/// linear in the number of segments. On the sphere, not in the projection: which strokes
/// cross does not depend on the pole.
class SegmentGrid {
public:
    struct Seg {
        int stroke, index;
        glm::dvec3 p0, p1;
    };

    SegmentGrid(std::vector<Seg> segs) : segs_(std::move(segs))
    {
        lo_ = glm::dvec3(std::numeric_limits<double>::max());
        glm::dvec3 hi(-std::numeric_limits<double>::max());
        std::vector<double> lengths;
        lengths.reserve(segs_.size());
        pad_.reserve(segs_.size());
        for (const Seg& s : segs_) {
            // The arc leaves its chord by at most 1 − cos(θ/2) = 1 − √((1 + cos θ) / 2).
            const double c = std::clamp(glm::dot(s.p0, s.p1), -1.0, 1.0);
            pad_.push_back(1.0 - std::sqrt(0.5 * (1.0 + c)) + 1e-12);
            lo_ = glm::min(lo_, glm::min(s.p0, s.p1) - pad_.back());
            hi = glm::max(hi, glm::max(s.p0, s.p1) + pad_.back());
            lengths.push_back(glm::distance(s.p0, s.p1));
        }
        std::nth_element(lengths.begin(), lengths.begin() + static_cast<long>(lengths.size() / 2), lengths.end());
        const glm::dvec3 extent = hi - lo_;
        const double cap = std::max({extent.x, extent.y, extent.z}) / 64.0;
        cell_ = std::max({lengths[lengths.size() / 2] * 2.0, cap, 1e-12});
        n_[0] = static_cast<int>(extent.x / cell_) + 1;
        n_[1] = static_cast<int>(extent.y / cell_) + 1;
        n_[2] = static_cast<int>(extent.z / cell_) + 1;
        // Cells in one array: cell c holds cells_[start_[c] .. start_[c + 1]), segments in order.
        start_.assign(static_cast<Index>(n_[0]) * static_cast<Index>(n_[1]) * static_cast<Index>(n_[2]) + 1, 0);
        for (Index i = 0; i < segs_.size(); ++i) for_cells(i, [&](Index c) { ++start_[c + 1]; });
        for (Index c = 1; c < start_.size(); ++c) start_[c] += start_[c - 1];
        cells_.resize(static_cast<Index>(start_.back()));
        std::vector<int> next(start_.begin(), start_.end() - 1);
        for (Index i = 0; i < segs_.size(); ++i)
            for_cells(i, [&](Index c) { cells_[static_cast<Index>(next[c]++)] = static_cast<int>(i); });
    }

    /// Calls f(seg_i, seg_j), i < j, once for each pair of segments whose boxes share a cell
    /// and of which one is at or after `first` (0: every pair, in increasing (i, j) order).
    template <typename F>
    void for_each_candidate_from(int first, F&& f) const
    {
        check_density();
        std::vector<int> others;
        for (int i = first; i < static_cast<int>(segs_.size()); ++i) {
            others.clear();
            for_cells(static_cast<Index>(i), [&](Index c) {
                // Cells list their segments in increasing order: those after i from the end,
                // those before `first` from the start.
                for (int k = start_[c + 1] - 1; k >= start_[c] && cells_[static_cast<Index>(k)] > i; --k)
                    others.push_back(cells_[static_cast<Index>(k)]);
                for (int k = start_[c]; k < start_[c + 1] && cells_[static_cast<Index>(k)] < first; ++k)
                    others.push_back(cells_[static_cast<Index>(k)]);
            });
            std::sort(others.begin(), others.end());
            others.erase(std::unique(others.begin(), others.end()), others.end());
            for (int j : others) {
                if (j < i) f(segs_[static_cast<Index>(j)], segs_[static_cast<Index>(i)]);
                else f(segs_[static_cast<Index>(i)], segs_[static_cast<Index>(j)]);
            }
        }
    }

private:
    /// Bounded work and memory on any input (a dense scribble in one spot).
    void check_density() const
    {
        std::size_t total = 0;
        for (Index c = 0; c + 1 < start_.size(); ++c) {
            const std::size_t k = static_cast<std::size_t>(start_[c + 1] - start_[c]);
            total += k * (k - (k > 0 ? 1 : 0)) / 2;
        }
        if (total > 20000000) throw InvalidInput("the lobe's strokes are too densely tangled to mesh");
    }

    template <typename F>
    void for_cells(Index i, F&& f) const
    {
        const Seg& s = segs_[i];
        const auto c0 = cell_of(glm::min(s.p0, s.p1) - pad_[i]);
        const auto c1 = cell_of(glm::max(s.p0, s.p1) + pad_[i]);
        for (int z = c0[2]; z <= c1[2]; ++z)
            for (int y = c0[1]; y <= c1[1]; ++y)
                for (int x = c0[0]; x <= c1[0]; ++x)
                    f((static_cast<Index>(z) * static_cast<Index>(n_[1]) + static_cast<Index>(y)) * static_cast<Index>(n_[0]) +
                      static_cast<Index>(x));
    }
    std::array<int, 3> cell_of(const glm::dvec3& p) const
    {
        std::array<int, 3> c{};
        for (int k = 0; k < 3; ++k)
            c[static_cast<Index>(k)] = std::clamp(static_cast<int>((p[k] - lo_[k]) / cell_), 0, n_[static_cast<Index>(k)] - 1);
        return c;
    }
    std::vector<Seg> segs_;
    std::vector<double> pad_;
    glm::dvec3 lo_{0.0};
    double cell_ = 1;
    std::array<int, 3> n_{1, 1, 1};
    std::vector<int> start_, cells_;
};

} // namespace

void LobeSurfaceBuilder::find_crossings()
{
    // After one more stroke, the old strokes' crossings are the previous build's: only pairs
    // with a new segment are tested. Anything refused is refused by the whole search, so
    // that the message is the same.
    if (old_memo_) {
        if (find_crossings(true)) return;
        crossings_.clear();
    }
    find_crossings(false);
}

bool LobeSurfaceBuilder::find_crossings(bool only_new)
{
    std::vector<SegmentGrid::Seg> segs;
    int first_new = 0;
    for (Index s = 0; s < strokes_.size(); ++s) {
        if (s == old_strokes_) first_new = static_cast<int>(segs.size());
        const Index n = dirs_[s].size();
        const Index count = strokes_[s].closed ? n : n - 1;
        for (Index i = 0; i < count; ++i)
            segs.push_back({static_cast<int>(s), static_cast<int>(i), dirs_[s][i], dirs_[s][(i + 1) % n]});
    }
    if (only_new && old_strokes_ >= strokes_.size()) first_new = static_cast<int>(segs.size());
    SegmentGrid grid(std::move(segs));
    crossing_count_.assign(strokes_.size(), 0);
    std::map<std::pair<int, int>, std::size_t> pair_count; // (lower, higher stroke) → crossings
    if (only_new) {
        crossings_ = old_memo_->crossings;
        for (const Crossing& c : crossings_) {
            ++crossing_count_[static_cast<Index>(c.a)];
            ++crossing_count_[static_cast<Index>(c.b)];
        }
    }
    // Looking only at the new segments, a refusal hands over to the whole search (false).
    struct Refused {};
    auto refuse = [&](const std::string& why) {
        if (only_new) throw Refused{};
        throw InvalidInput(why);
    };
    auto test = [&](const SegmentGrid::Seg& a, const SegmentGrid::Seg& b) {
        double s = 0, t = 0;
        if (!arc_crossing(a.p0, a.p1, b.p0, b.p1, s, t)) return;
        if (a.stroke == b.stroke) refuse(stroke_name(a.stroke) + " folds back over itself as seen from the lobe's centre");
        if (crossings_.size() >= 100000) refuse("the lobe's strokes cross each other too often to mesh");
        crossings_.push_back({a.stroke, a.index, b.stroke, b.index, s, t});
        ++crossing_count_[static_cast<Index>(a.stroke)];
        ++crossing_count_[static_cast<Index>(b.stroke)];
        ++pair_count[{std::min(a.stroke, b.stroke), std::max(a.stroke, b.stroke)}];
    };
    try {
        grid.for_each_candidate_from(only_new ? first_new : 0, test);
        // Two strokes that run along each other (seen from the centre) cross again and again.
        for (const auto& [pair, c] : pair_count) {
            const Index a = static_cast<Index>(pair.first), b = static_cast<Index>(pair.second);
            if (c > std::max<std::size_t>(16, std::min(dirs_[a].size(), dirs_[b].size()) / 2))
                refuse(stroke_name(pair.second) + " runs along " + stroke_name(pair.first) +
                       " as seen from the lobe's centre (they cross " + std::to_string(c) + " times; is one inside the lobe?)");
        }
    } catch (const Refused&) {
        return false;
    }
    sort_crossings();
    return true;
}

void LobeSurfaceBuilder::sort_crossings()
{
    std::sort(crossings_.begin(), crossings_.end(), [](const Crossing& x, const Crossing& y) {
        return std::tie(x.a, x.seg, x.s, x.b, x.other_seg) < std::tie(y.a, y.seg, y.s, y.b, y.other_seg);
    });
    memo_->crossings = crossings_;
}

} // namespace lobe_surface_detail

} // namespace lobe
