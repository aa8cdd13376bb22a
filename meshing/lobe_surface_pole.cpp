// Stage 2 of a lobe surface build (lobe_surface_builder.h): the pole of the stereographic
// projection, the direction farthest from every sample. No CGAL.
#include "meshing/lobe_surface_builder.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include <glm/geometric.hpp>

#include "core/errors.h"

namespace lobe {

namespace lobe_surface_detail {

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
    constexpr int kCandidates = 512;
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
    double best_dot = 2.0;
    glm::dvec3 best(0, 0, 1);
    std::vector<glm::dvec3> all;
    for (const auto& stroke : dirs_) all.insert(all.end(), stroke.begin(), stroke.end());
    const LobeBuildMemo* memo = old_memo_;
    Index old_count = 0;
    if (memo)
        for (Index s = 0; s < old_strokes_; ++s) old_count += dirs_[s].size();
    // Scans over the samples listed in [first, last) (indices into `all`, in order).
    std::vector<Index> every(all.size());
    std::iota(every.begin(), every.end(), Index{0});
    // The largest dot product with `d`, and the first sample giving it.
    auto max_over = [&](const glm::dvec3& d, const Index* first, const Index* last, int* nearest) {
        double m = -2.0;
        for (const Index* k = first; k != last; ++k) {
            const double c = glm::dot(all[*k], d);
            if (c > m) {
                m = c;
                if (nearest) *nearest = static_cast<int>(*k);
            }
        }
        return m;
    };
    // The first sample at least as near as the best (`bound`, its dot product ≥ best_dot), or −1.
    auto beaten_over = [&](const glm::dvec3& d, const Index* first, const Index* last, double& bound) {
        for (const Index* k = first; k != last; ++k) {
            const double c = glm::dot(all[*k], d);
            if (c >= best_dot) {
                bound = c;
                return static_cast<int>(*k);
            }
        }
        return -1;
    };
    const Index* every_end = every.data() + every.size();
    // Over the samples from `from` on (the new strokes' from old_count).
    auto max_dot = [&](const glm::dvec3& d, Index from, int* nearest) {
        return max_over(d, every.data() + from, every_end, nearest);
    };
    auto beaten = [&](const glm::dvec3& d, double& bound) { return beaten_over(d, every.data(), every_end, bound); };
    // Runs of up to 8 consecutive samples (along a stroke: close together), each with a cap
    // of directions holding it, so that a scan for a largest dot product can pass over a run
    // whose cap cannot beat the value it has: the same answer (and the same first sample
    // giving it), with fewer products. The old samples' runs end at old_count.
    struct Run {
        Index first, last;
        glm::dvec3 axis;
        double cos_r, sin_r; ///< of the cap's angular radius
    };
    std::vector<Run> runs;
    auto add_runs = [&](Index from, Index to) {
        for (Index f = from; f < to; f += 8) {
            Run run{f, std::min(to, f + 8), glm::dvec3(0.0), 1.0, 0.0};
            for (Index k = run.first; k < run.last; ++k) run.axis += all[k];
            const double len = glm::length(run.axis);
            if (!(len > 1e-6)) {
                run.cos_r = -1.0; // no useful cap: always scanned
            } else {
                run.axis /= len;
                for (Index k = run.first; k < run.last; ++k) run.cos_r = std::min(run.cos_r, glm::dot(all[k], run.axis));
                run.cos_r = std::clamp(run.cos_r, -1.0, 1.0);
                run.sin_r = std::sqrt(1.0 - run.cos_r * run.cos_r);
            }
            runs.push_back(run);
        }
    };
    // Only the search after one more stroke (memo) scans by runs.
    Index first_new_run = 0;
    if (memo) {
        add_runs(0, old_count);
        first_new_run = runs.size();
        add_runs(old_count, all.size());
    }
    // An upper bound of dot(d, x) over a run's samples x: cos(θ − r) for the angle θ between d
    // and the axis beyond the radius r (the products are of unit vectors, rounded far below
    // the margin).
    auto run_bound = [](const Run& run, const glm::dvec3& d) {
        if (run.cos_r <= -1.0) return 2.0;
        const double c = glm::dot(d, run.axis);
        if (c >= run.cos_r) return 2.0;
        return c * run.cos_r + std::sqrt(std::max(0.0, 1.0 - c * c)) * run.sin_r + 1e-9;
    };
    // max(floor, the largest dot product of `d` with a new sample): the runs that cannot
    // exceed what is found so far are passed over.
    auto new_max_above = [&](const glm::dvec3& d, double floor) {
        double m = floor;
        for (Index r = first_new_run; r < runs.size(); ++r) {
            const Run& run = runs[r];
            if (run_bound(run, d) <= m) continue;
            for (Index k = run.first; k < run.last; ++k) m = std::max(m, glm::dot(all[k], d));
        }
        return m;
    };
    LobeBuildMemo& out = *memo_;
    out.candidate_bound.assign(kCandidates, 0.0);
    out.candidate_exact.assign(kCandidates, 0);
    if (memo) {
        // New samples only raise a candidate's largest dot product, so the previous bounds stay
        // lower bounds. The previous winner's new value `ceiling` is one the answer cannot
        // exceed: a candidate whose bound is above it cannot be the answer and is passed over.
        // The others are scanned in order as the whole search does, so ties go the same way.
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
            if (bound >= best_dot || bound > ceiling) {
                exact = false; // the new samples may raise it: a lower bound now
            } else {
                // max(bound, the new samples' largest): bound is the old samples' largest
                // (exact) or a lower bound of it (< best_dot here), so `added` reaches
                // best_dot exactly when the new samples' largest does.
                const double added = new_max_above(d, bound);
                if (exact) {
                    bound = added;
                } else if (added >= best_dot) {
                    bound = added; // cannot win: a lower bound
                } else {
                    // The old samples until one is at least as near as the best (then it
                    // cannot win either), else all of them: the exact value. The samples that
                    // ended the scans of the lattice neighbours (Fibonacci index steps) are
                    // tried first, as in the whole search.
                    double old_max = -2.0;
                    for (int step : {1, 2, 3, 5, 8, 13, 21, 34, 55, 89}) {
                        if (i < static_cast<Index>(step)) break;
                        const int w = stopped_at[i - static_cast<Index>(step)];
                        if (w < 0) continue;
                        const double c = glm::dot(all[static_cast<Index>(w)], d);
                        if (c >= best_dot) {
                            old_max = c;
                            stopped_at[i] = w;
                            break;
                        }
                    }
                    // In sample order; a run that cannot beat old_max changes nothing.
                    for (Index r = 0; r < first_new_run && old_max < best_dot; ++r) {
                        const Run& run = runs[r];
                        if (run_bound(run, d) <= old_max) continue;
                        for (Index k = run.first; k < run.last && old_max < best_dot; ++k) {
                            const double c = glm::dot(all[k], d);
                            if (c > old_max) {
                                old_max = c;
                                stopped_at[i] = static_cast<int>(k);
                            }
                        }
                    }
                    // old_max is the old samples' largest when the scan ran through (so at
                    // least the lower bound folded into `added`), else a value ≥ best_dot:
                    // either way this is max(old_max, the new samples' largest).
                    bound = std::max(old_max, added);
                    exact = old_max < best_dot;
                }
                if (exact && bound < best_dot) {
                    best_dot = bound;
                    best = d;
                }
            }
            out.candidate_bound[i] = bound;
            out.candidate_exact[i] = exact ? 1 : 0;
        }
    } else {
        // A candidate is only of interest when its nearest sample is farther than the best
        // one's: the scan stops at the first sample at least as near (`witness`), and the
        // witnesses of the candidate's lattice neighbours (Fibonacci index steps) are tried first.
        std::vector<int> witness(kCandidates, 0);
        for (int i = 0; i < kCandidates; ++i) {
            const Index ii = static_cast<Index>(i);
            const glm::dvec3& d = lattice[ii];
            bool out_of_it = false;
            for (int step : {1, 2, 3, 5, 8, 13, 21, 34, 55, 89}) {
                if (i < step) break;
                const int w = witness[static_cast<Index>(i - step)];
                const double c = glm::dot(all[static_cast<Index>(w)], d);
                if (c >= best_dot) {
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
            if (m < best_dot) {
                best_dot = m;
                best = d;
            }
        }
    }
    out.start = best;
    out.start_dot = best_dot;
    out.steps.clear();
    // Following the previous search while every step is the same.
    bool follow = memo && memo->start == best && memo->start_dot == best_dot && memo->steps.size() == 40;
    // Otherwise the rounds look only at the samples near a centre (first the start): the
    // nearest sample to a point within `reach` of the centre lies within θ0 + 2·reach of it
    // (θ0: the centre's distance to its nearest sample), and so does every sample at least as
    // near to a trial within reach as the nearest one is to the pole, while the pole is within
    // reach too. When the search walks out of reach, the current pole becomes the centre (a
    // step moves less than reach). Either way the answers are the full scan's, bit for bit:
    // the samples left out cannot be the first nearest or the first at least as near.
    constexpr double reach = 0.15;
    const double cos_reach = std::cos(reach);
    glm::dvec3 centre = best;
    std::vector<Index> near;
    auto recentre = [&] {
        centre = best;
        const double near_cos = std::cos(std::min(M_PI, std::acos(std::clamp(best_dot, -1.0, 1.0)) + 2.0 * reach + 1e-6));
        near.clear();
        for (Index k = 0; k < all.size(); ++k)
            if (glm::dot(all[k], centre) >= near_cos) near.push_back(k);
    };
    bool near_ready = false;
    // Whether the near samples serve `d` (and the pole), moving the centre if they did not.
    auto near_serves = [&](const glm::dvec3& d) {
        auto covers = [&](const glm::dvec3& x) { return glm::dot(x, centre) >= cos_reach; };
        if (near_ready && covers(d) && covers(best)) return true;
        recentre();
        near_ready = true;
        return covers(d);
    };
    auto max_dot_near = [&](const glm::dvec3& d, int* nearest) {
        if (!near_serves(d)) return max_dot(d, 0, nearest);
        return max_over(d, near.data(), near.data() + near.size(), nearest);
    };
    auto beaten_near = [&](const glm::dvec3& d, double& bound) {
        if (!near_serves(d)) return beaten(d, bound);
        return beaten_over(d, near.data(), near.data() + near.size(), bound);
    };
    double step = 0.1;
    for (int it = 0; it < 40; ++it) {
        LobeBuildMemo::Step rec;
        if (follow) {
            int added_nearest = -1;
            if (max_dot(best, old_count, &added_nearest) > best_dot) {
                follow = false;
                rec.nearest = added_nearest; // a new sample is nearer than every old one
            } else {
                rec.nearest = memo->steps[static_cast<Index>(it)].nearest;
            }
        } else {
            max_dot_near(best, &rec.nearest);
        }
        const glm::dvec3& nearest = all[static_cast<Index>(rec.nearest)];
        const glm::dvec3 trial = glm::normalize(best - step * (nearest - glm::dot(nearest, best) * best));
        // m: the trial's largest dot product, or a lower bound of it when that is ≥ best_dot.
        double m = 0;
        if (follow) {
            const LobeBuildMemo::Step& was = memo->steps[static_cast<Index>(it)];
            if (!was.accepted) {
                m = was.value; // ≥ best_dot: still refused, and still a lower bound
            } else {
                m = std::max(was.value, max_dot(trial, old_count, nullptr));
                if (m != was.value) follow = false; // from here on the pole differs
            }
        } else {
            double bound = 0;
            m = beaten_near(trial, bound) >= 0 ? bound : max_dot_near(trial, nullptr);
        }
        rec.accepted = m < best_dot;
        rec.value = m;
        if (rec.accepted) {
            best_dot = m;
            best = trial;
        } else {
            step *= 0.5;
        }
        out.steps.push_back(rec);
    }
    empty_angle_ = std::acos(std::clamp(best_dot, -1.0, 1.0));
    if (empty_angle_ < 3.0 * M_PI / 180.0)
        throw InvalidInput("the lobe's strokes leave no open direction around its centre (they cover it densely)");
    stereo_ = Stereo(best);
}

} // namespace lobe_surface_detail

} // namespace lobe
