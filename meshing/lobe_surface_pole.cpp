// Stage 2 of a lobe surface build (lobe_surface_builder.h): the pole of the stereographic
// projection, the direction farthest from every sample. No CGAL.
#include "meshing/lobe_surface_builder.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

#include <glm/geometric.hpp>

#include "core/errors.h"

namespace lobe {

namespace lobe_surface_detail {

namespace {

constexpr int kCandidates = 512;
/// Lattice neighbours of a candidate, by Fibonacci index steps: near on the sphere.
constexpr std::array<int, 10> kNeighbourSteps{1, 2, 3, 5, 8, 13, 21, 34, 55, 89};
/// Rounds of pushing the pole away from its nearest sample.
constexpr int kRounds = 40;

/// The candidates for the pole: a Fibonacci lattice of directions.
const std::vector<glm::dvec3>& candidate_lattice()
{
    static const std::vector<glm::dvec3> lattice = [] {
        std::vector<glm::dvec3> out;
        const double golden = M_PI * (3.0 - std::sqrt(5.0));
        for (int i = 0; i < kCandidates; ++i) {
            const double z = 1.0 - (2.0 * i + 1.0) / kCandidates;
            const double rr = std::sqrt(std::max(0.0, 1.0 - z * z));
            out.emplace_back(rr * std::cos(golden * i), rr * std::sin(golden * i), z);
        }
        return out;
    }();
    return lattice;
}

/// A run of up to 8 consecutive samples (along a stroke: close together) with a cap of
/// directions holding it, so that a scan for a largest dot product can pass over a run whose
/// cap cannot beat the value it has: the same answer (and the same first sample giving it),
/// with fewer products.
struct SampleRun {
    Index first, last;
    glm::dvec3 axis;
    double cos_r, sin_r; ///< of the cap's angular radius
};

/// An upper bound of dot(d, x) over a run's samples x: cos(θ − r) for the angle θ between d
/// and the axis beyond the radius r (the products are of unit vectors, rounded far below
/// the margin).
double run_bound(const SampleRun& run, const glm::dvec3& d)
{
    if (run.cos_r <= -1.0) return 2.0;
    const double c = glm::dot(d, run.axis);
    if (c >= run.cos_r) return 2.0;
    return c * run.cos_r + std::sqrt(std::max(0.0, 1.0 - c * c)) * run.sin_r + 1e-9;
}

/// The search for the direction farthest from every sample (the smallest largest dot
/// product with a sample): the lattice candidates rated, the best one kept, then rounds of
/// pushing it away from its nearest sample. After one more stroke (a usable memo), the
/// previous build's search is followed where the new samples cannot change a step.
class PoleSearch {
public:
    /// `dirs`: per stroke, its samples' directions; `memo`: the previous build's, when usable,
    /// made from the first `old_strokes` strokes.
    PoleSearch(const std::vector<std::vector<glm::dvec3>>& dirs, const LobeBuildMemo* memo, Index old_strokes)
        : memo_(memo)
    {
        for (const auto& stroke : dirs) all_.insert(all_.end(), stroke.begin(), stroke.end());
        if (memo_)
            for (Index s = 0; s < old_strokes; ++s) old_count_ += dirs[s].size();
        every_.resize(all_.size());
        std::iota(every_.begin(), every_.end(), Index{0});
        // Only the search after one more stroke scans by runs; the old samples' runs end at
        // old_count_.
        if (memo_) {
            add_runs(0, old_count_);
            first_new_run_ = runs_.size();
            add_runs(old_count_, all_.size());
        }
    }

    /// Rates every candidate into `out` (candidate_bound, candidate_exact) as the whole
    /// search does, keeping the best.
    void rate_candidates(LobeBuildMemo& out);
    /// The same, bit for bit, following the previous search (the memo's).
    void rate_candidates_following(LobeBuildMemo& out);
    /// The rounds of pushing the best candidate away from its nearest sample, each recorded
    /// in out.steps.
    void push_away(LobeBuildMemo& out);

    const glm::dvec3& best() const { return best_; }
    double best_dot() const { return best_dot_; }

private:
    void add_runs(Index from, Index to);
    // Scans over the samples listed in [first, last) (indices into all_, in order).
    double max_over(const glm::dvec3& d, const Index* first, const Index* last, int* nearest) const;
    int beaten_over(const glm::dvec3& d, const Index* first, const Index* last, double& bound) const;
    /// Over the samples from `from` on (the new strokes' from old_count_).
    double max_dot(const glm::dvec3& d, Index from, int* nearest) const
    {
        return max_over(d, every_.data() + from, every_.data() + every_.size(), nearest);
    }
    int beaten(const glm::dvec3& d, double& bound) const
    {
        return beaten_over(d, every_.data(), every_.data() + every_.size(), bound);
    }
    double new_max_above(const glm::dvec3& d, double floor) const;
    /// The old samples' largest dot product with candidate `i`, or a value ≥ best_dot_ where
    /// one is at least as near as the best (`stopped_at` as in rate_candidates_following).
    double old_max_below_best(Index i, const glm::dvec3& d, std::vector<int>& stopped_at) const;
    // The rounds' scans over the samples near the current centre (push_away).
    void recentre();
    bool near_serves(const glm::dvec3& d);
    double max_dot_near(const glm::dvec3& d, int* nearest);
    int beaten_near(const glm::dvec3& d, double& bound);

    const LobeBuildMemo* memo_;
    std::vector<glm::dvec3> all_; ///< every sample's direction, stroke by stroke
    Index old_count_ = 0;         ///< the old strokes' samples (with a memo)
    std::vector<Index> every_;    ///< 0, 1, …: every sample, for the scans over a list
    std::vector<SampleRun> runs_;
    Index first_new_run_ = 0;
    double best_dot_ = 2.0;
    glm::dvec3 best_{0, 0, 1};
    // push_away: the samples near `centre_`.
    static constexpr double kReach = 0.15;
    const double cos_reach_ = std::cos(kReach);
    glm::dvec3 centre_{0.0};
    std::vector<Index> near_;
    bool near_ready_ = false;
};

void PoleSearch::add_runs(Index from, Index to)
{
    for (Index f = from; f < to; f += 8) {
        SampleRun run{f, std::min(to, f + 8), glm::dvec3(0.0), 1.0, 0.0};
        for (Index k = run.first; k < run.last; ++k) run.axis += all_[k];
        const double len = glm::length(run.axis);
        if (!(len > 1e-6)) {
            run.cos_r = -1.0; // no useful cap: always scanned
        } else {
            run.axis /= len;
            for (Index k = run.first; k < run.last; ++k) run.cos_r = std::min(run.cos_r, glm::dot(all_[k], run.axis));
            run.cos_r = std::clamp(run.cos_r, -1.0, 1.0);
            run.sin_r = std::sqrt(1.0 - run.cos_r * run.cos_r);
        }
        runs_.push_back(run);
    }
}

/// The largest dot product with `d`, and the first sample giving it.
double PoleSearch::max_over(const glm::dvec3& d, const Index* first, const Index* last, int* nearest) const
{
    double m = -2.0;
    for (const Index* k = first; k != last; ++k) {
        const double c = glm::dot(all_[*k], d);
        if (c > m) {
            m = c;
            if (nearest) *nearest = static_cast<int>(*k);
        }
    }
    return m;
}

/// The first sample at least as near as the best (`bound`, its dot product ≥ best_dot_), or −1.
int PoleSearch::beaten_over(const glm::dvec3& d, const Index* first, const Index* last, double& bound) const
{
    for (const Index* k = first; k != last; ++k) {
        const double c = glm::dot(all_[*k], d);
        if (c >= best_dot_) {
            bound = c;
            return static_cast<int>(*k);
        }
    }
    return -1;
}

/// max(floor, the largest dot product of `d` with a new sample): the runs that cannot
/// exceed what is found so far are passed over.
double PoleSearch::new_max_above(const glm::dvec3& d, double floor) const
{
    double m = floor;
    for (Index r = first_new_run_; r < runs_.size(); ++r) {
        const SampleRun& run = runs_[r];
        if (run_bound(run, d) <= m) continue;
        for (Index k = run.first; k < run.last; ++k) m = std::max(m, glm::dot(all_[k], d));
    }
    return m;
}

void PoleSearch::rate_candidates(LobeBuildMemo& out)
{
    // A candidate is only of interest when its nearest sample is farther than the best
    // one's: the scan stops at the first sample at least as near (`witness`), and the
    // witnesses of the candidate's lattice neighbours (Fibonacci index steps) are tried first.
    const std::vector<glm::dvec3>& lattice = candidate_lattice();
    std::vector<int> witness(kCandidates, 0);
    for (int i = 0; i < kCandidates; ++i) {
        const Index ii = static_cast<Index>(i);
        const glm::dvec3& d = lattice[ii];
        bool out_of_it = false;
        for (int step : kNeighbourSteps) {
            if (i < step) break;
            const int w = witness[static_cast<Index>(i - step)];
            const double c = glm::dot(all_[static_cast<Index>(w)], d);
            if (c >= best_dot_) {
                witness[ii] = w;
                out.candidate_bound[ii] = c;
                out_of_it = true;
                break;
            }
        }
        if (out_of_it) continue;
        double bound = 0;
        const int w = beaten(d, bound);
        if (w >= 0) {
            witness[ii] = w;
            out.candidate_bound[ii] = bound;
            continue;
        }
        const double m = max_dot(d, 0, nullptr);
        out.candidate_bound[ii] = m;
        out.candidate_exact[ii] = 1;
        if (m < best_dot_) {
            best_dot_ = m;
            best_ = d;
        }
    }
}

void PoleSearch::rate_candidates_following(LobeBuildMemo& out)
{
    // New samples only raise a candidate's largest dot product, so the previous bounds stay
    // lower bounds. The previous winner's new value `ceiling` is one the answer cannot
    // exceed: a candidate whose bound is above it cannot be the answer and is passed over.
    // The others are scanned in order as the whole search does, so ties go the same way.
    const std::vector<glm::dvec3>& lattice = candidate_lattice();
    const LobeBuildMemo* memo = memo_;
    Index leader = 0;
    for (Index i = 1; i < static_cast<Index>(kCandidates); ++i)
        if (memo->candidate_exact[i] &&
            (!memo->candidate_exact[leader] || memo->candidate_bound[i] < memo->candidate_bound[leader]))
            leader = i;
    std::vector<int> stopped_at(kCandidates, -1); // per candidate scanned: its nearest old sample so far
    double ceiling = 2.0;
    if (memo->candidate_exact[leader])
        ceiling = new_max_above(lattice[leader], memo->candidate_bound[leader]);
    for (Index i = 0; i < static_cast<Index>(kCandidates); ++i) {
        const glm::dvec3& d = lattice[i];
        double bound = memo->candidate_bound[i];
        bool exact = memo->candidate_exact[i] != 0;
        if (bound >= best_dot_ || bound > ceiling) {
            exact = false; // the new samples may raise it: a lower bound now
        } else {
            // max(bound, the new samples' largest): bound is the old samples' largest
            // (exact) or a lower bound of it (< best_dot_ here), so `added` reaches
            // best_dot_ exactly when the new samples' largest does.
            const double added = new_max_above(d, bound);
            if (exact) {
                bound = added;
            } else if (added >= best_dot_) {
                bound = added; // cannot win: a lower bound
            } else {
                const double old_max = old_max_below_best(i, d, stopped_at);
                // old_max is the old samples' largest when the scan ran through (so at
                // least the lower bound folded into `added`), else a value ≥ best_dot_:
                // either way this is max(old_max, the new samples' largest).
                bound = std::max(old_max, added);
                exact = old_max < best_dot_;
            }
            if (exact && bound < best_dot_) {
                best_dot_ = bound;
                best_ = d;
            }
        }
        out.candidate_bound[i] = bound;
        out.candidate_exact[i] = exact ? 1 : 0;
    }
}

double PoleSearch::old_max_below_best(Index i, const glm::dvec3& d, std::vector<int>& stopped_at) const
{
    // The old samples until one is at least as near as the best (then it cannot win
    // either), else all of them: the exact value. The samples that ended the scans of the
    // lattice neighbours (Fibonacci index steps) are tried first, as in the whole search.
    double old_max = -2.0;
    for (int step : kNeighbourSteps) {
        if (i < static_cast<Index>(step)) break;
        const int w = stopped_at[i - static_cast<Index>(step)];
        if (w < 0) continue;
        const double c = glm::dot(all_[static_cast<Index>(w)], d);
        if (c >= best_dot_) {
            old_max = c;
            stopped_at[i] = w;
            break;
        }
    }
    // In sample order; a run that cannot beat old_max changes nothing.
    for (Index r = 0; r < first_new_run_ && old_max < best_dot_; ++r) {
        const SampleRun& run = runs_[r];
        if (run_bound(run, d) <= old_max) continue;
        for (Index k = run.first; k < run.last && old_max < best_dot_; ++k) {
            const double c = glm::dot(all_[k], d);
            if (c > old_max) {
                old_max = c;
                stopped_at[i] = static_cast<int>(k);
            }
        }
    }
    return old_max;
}

// Unless the rounds follow the previous search, they look only at the samples near a centre
// (first the start): the nearest sample to a point within kReach of the centre lies within
// θ0 + 2·kReach of it (θ0: the centre's distance to its nearest sample), and so does every
// sample at least as near to a trial within reach as the nearest one is to the pole, while
// the pole is within reach too. When the search walks out of reach, the current pole becomes
// the centre (a step moves less than kReach). Either way the answers are the full scan's, bit
// for bit: the samples left out cannot be the first nearest or the first at least as near.
void PoleSearch::recentre()
{
    centre_ = best_;
    const double near_cos = std::cos(std::min(M_PI, std::acos(std::clamp(best_dot_, -1.0, 1.0)) + 2.0 * kReach + 1e-6));
    near_.clear();
    for (Index k = 0; k < all_.size(); ++k)
        if (glm::dot(all_[k], centre_) >= near_cos) near_.push_back(k);
}

/// Whether the near samples serve `d` (and the pole), moving the centre if they did not.
bool PoleSearch::near_serves(const glm::dvec3& d)
{
    auto covers = [&](const glm::dvec3& x) { return glm::dot(x, centre_) >= cos_reach_; };
    if (near_ready_ && covers(d) && covers(best_)) return true;
    recentre();
    near_ready_ = true;
    return covers(d);
}

double PoleSearch::max_dot_near(const glm::dvec3& d, int* nearest)
{
    if (!near_serves(d)) return max_dot(d, 0, nearest);
    return max_over(d, near_.data(), near_.data() + near_.size(), nearest);
}

int PoleSearch::beaten_near(const glm::dvec3& d, double& bound)
{
    if (!near_serves(d)) return beaten(d, bound);
    return beaten_over(d, near_.data(), near_.data() + near_.size(), bound);
}

void PoleSearch::push_away(LobeBuildMemo& out)
{
    const LobeBuildMemo* memo = memo_;
    // Following the previous search while every step is the same.
    bool follow = memo && memo->start == best_ && memo->start_dot == best_dot_ && memo->steps.size() == kRounds;
    centre_ = best_;
    double step = 0.1;
    for (int it = 0; it < kRounds; ++it) {
        LobeBuildMemo::Step rec;
        if (follow) {
            int added_nearest = -1;
            if (max_dot(best_, old_count_, &added_nearest) > best_dot_) {
                follow = false;
                rec.nearest = added_nearest; // a new sample is nearer than every old one
            } else {
                rec.nearest = memo->steps[static_cast<Index>(it)].nearest;
            }
        } else {
            max_dot_near(best_, &rec.nearest);
        }
        const glm::dvec3& nearest = all_[static_cast<Index>(rec.nearest)];
        const glm::dvec3 trial = glm::normalize(best_ - step * (nearest - glm::dot(nearest, best_) * best_));
        // m: the trial's largest dot product, or a lower bound of it when that is ≥ best_dot_.
        double m = 0;
        if (follow) {
            const LobeBuildMemo::Step& was = memo->steps[static_cast<Index>(it)];
            if (!was.accepted) {
                m = was.value; // ≥ best_dot_: still refused, and still a lower bound
            } else {
                m = std::max(was.value, max_dot(trial, old_count_, nullptr));
                if (m != was.value) follow = false; // from here on the pole differs
            }
        } else {
            double bound = 0;
            m = beaten_near(trial, bound) >= 0 ? bound : max_dot_near(trial, nullptr);
        }
        rec.accepted = m < best_dot_;
        rec.value = m;
        if (rec.accepted) {
            best_dot_ = m;
            best_ = trial;
        } else {
            step *= 0.5;
        }
        out.steps.push_back(rec);
    }
}

} // namespace

void LobeSurfaceBuilder::choose_pole()
{
    // The direction farthest from every sample: a Fibonacci lattice of candidates, then a
    // few rounds of pushing the best one away from its nearest sample.
    //
    // After one more stroke (old_memo_), the previous build's search is followed wherever the
    // new samples cannot change a step: a candidate whose bound was already no better than the
    // best is passed over again; an exact one needs only the new samples; a round whose nearest
    // sample and outcome stay keeps them. The result is the whole search's, bit for bit: the
    // first candidate with the smallest largest dot product, then the same rounds.
    PoleSearch search(dirs_, old_memo_, old_strokes_);
    LobeBuildMemo& out = *memo_;
    out.candidate_bound.assign(kCandidates, 0.0);
    out.candidate_exact.assign(kCandidates, 0);
    if (old_memo_) search.rate_candidates_following(out);
    else search.rate_candidates(out);
    out.start = search.best();
    out.start_dot = search.best_dot();
    out.steps.clear();
    search.push_away(out);
    empty_angle_ = std::acos(std::clamp(search.best_dot(), -1.0, 1.0));
    if (empty_angle_ < 3.0 * M_PI / 180.0)
        throw InvalidInput("the lobe's strokes leave no open direction around its centre (they cover it densely)");
    stereo_ = Stereo(search.best());
}

} // namespace lobe_surface_detail

} // namespace lobe
