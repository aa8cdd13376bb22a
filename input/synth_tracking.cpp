#include "input/synth_tracking.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>

namespace lobe::synth {

namespace {

/// Three clamped normal draws as (x, y, z), z drawn first. Function arguments are evaluated
/// in an unspecified order (gcc right to left, clang left to right), so draws are never made
/// inside one call's arguments; z, y, x is the order the shipped recordings were made in.
dvec3 normal3(Rng& rng, double k)
{
    const double z = rng.normal_clamped(k);
    const double y = rng.normal_clamped(k);
    const double x = rng.normal_clamped(k);
    return dvec3(x, y, z);
}

/// True when every segment overlapping [a, b] allows a long drop-out; `from` is a segment
/// at or before `a`.
bool all_long(const Track& tr, std::size_t from, double a, double b)
{
    for (std::size_t i = from > 0 ? from - 1 : 0; i < tr.segs.size() && tr.segs[i].t0 < b; ++i) {
        const Segment& s = tr.segs[i];
        if (s.t1 <= a) continue;
        if (s.drop != DropZone::Long) return false;
    }
    return true;
}

int finger_of(int joint)
{
    if (joint < idx(Joint::ThumbMetacarpal)) return -1;
    if (joint <= idx(Joint::ThumbTip)) return 0;
    return 1 + (joint - idx(Joint::IndexMetacarpal)) / 5;
}

} // namespace

std::array<std::vector<Dropout>, kHandCount> schedule_dropouts(const Synth& sy, std::uint64_t seed)
{
    std::array<std::vector<Dropout>, kHandCount> out;
    Rng rng(stream_seed(seed, kTagDropouts));
    bool any_short = false;
    for (int h = 0; h < kHandCount; ++h) {
        const Track& tr = sy.tracks[static_cast<std::size_t>(h)];
        auto& list = out[static_cast<std::size_t>(h)];
        const double end = tr.segs.empty() ? 0.0 : tr.segs.back().t1;
        double t = 0.5 + rng.exponential(7.0);
        std::size_t si = 0;
        while (t < end - 0.5) {
            while (si + 1 < tr.segs.size() && tr.segs[si].t1 <= t) ++si;
            const Segment& s = tr.segs[si];
            const bool quirk = rng.uniform() < 0.5;
            if (s.drop == DropZone::Short) {
                double d = rng.uniform(0.055, 0.100);
                if (t >= s.t0 + 0.25 && t + d <= s.t1 - 0.25) {
                    list.push_back({t, t + d, quirk});
                    any_short = true;
                    t += d;
                }
            } else if (s.drop == DropZone::Long) {
                double d = rng.uniform(0.05, 0.29);
                if (all_long(tr, si, t - 0.05, t + d + 0.05)) {
                    list.push_back({t, t + d, quirk});
                    t += d;
                }
            }
            t += 0.4 + rng.exponential(7.0);
        }
    }
    // Make sure both kinds show up: the middle of the longest stroke of the drawing hands,
    // and the middle of the longest free stretch of the right hand.
    if (!any_short) {
        const Segment* best = nullptr;
        int best_hand = 0;
        for (int h = 0; h < kHandCount; ++h)
            for (const Segment& s : sy.tracks[static_cast<std::size_t>(h)].segs)
                if (s.drop == DropZone::Short && (!best || s.t1 - s.t0 > best->t1 - best->t0)) {
                    best = &s;
                    best_hand = h;
                }
        if (best && best->t1 - best->t0 > 0.8) {
            double mid = 0.5 * (best->t0 + best->t1);
            auto& list = out[static_cast<std::size_t>(best_hand)];
            list.push_back({mid - 0.04, mid + 0.04, false});
            std::sort(list.begin(), list.end(), [](const Dropout& a, const Dropout& b) { return a.t0 < b.t0; });
        }
    }
    for (int h = 0; h < kHandCount; ++h) {
        auto& list = out[static_cast<std::size_t>(h)];
        bool has_long = std::any_of(list.begin(), list.end(), [](const Dropout& d) { return d.t1 - d.t0 > 0.12; });
        if (has_long || h != static_cast<int>(Hand::Right)) continue;
        const Track& tr = sy.tracks[static_cast<std::size_t>(h)];
        double best_a = 0.0, best_b = 0.0;
        for (std::size_t i = 0; i < tr.segs.size();) {
            if (tr.segs[i].drop != DropZone::Long) {
                ++i;
                continue;
            }
            std::size_t j = i;
            while (j < tr.segs.size() && tr.segs[j].drop == DropZone::Long) ++j;
            if (tr.segs[j - 1].t1 - tr.segs[i].t0 > best_b - best_a) {
                best_a = tr.segs[i].t0;
                best_b = tr.segs[j - 1].t1;
            }
            i = j;
        }
        if (best_b - best_a > 0.8) {
            double mid = 0.5 * (best_a + best_b);
            bool clash = std::any_of(list.begin(), list.end(),
                                     [&](const Dropout& d) { return d.t1 > mid - 0.2 && d.t0 < mid + 0.2; });
            if (!clash) {
                list.push_back({mid - 0.09, mid + 0.09, true});
                std::sort(list.begin(), list.end(), [](const Dropout& a, const Dropout& b) { return a.t0 < b.t0; });
            }
        }
    }
    return out;
}

dvec3 tremor_offset(TremorState& state, const HandPersona& hp, const dquat& rot, double t, double dt, Rng& noise)
{
    const double freq = hp.tremor_f0 + 0.8 * std::sin(kTwoPi * t / 6.1 + hp.tremor_p1) +
                        0.4 * std::sin(kTwoPi * t / 2.3 + hp.tremor_p2);
    state.phase += kTwoPi * freq * dt + 0.04 * noise.normal_clamped(3.0);
    const double env = 1.0 + 0.2 * std::sin(kTwoPi * 0.13 * t + hp.tremor_p3);
    return rot * dvec3(0.5 * std::sin(state.phase + 1.3), std::sin(state.phase), 0.0) * (hp.tremor_amp * env);
}

void add_noise(HandState& hs, Rng& rng, const dvec3& tremor)
{
    const double k = 2.5;
    dvec3 common = normal3(rng, k);
    common *= 0.0005;
    std::array<dvec3, 5> finger{};
    for (auto& f : finger) f = 0.00035 * normal3(rng, k);
    for (int j = 0; j < kJointCount; ++j) {
        dvec3 own = 0.0003 * normal3(rng, k);
        int f = finger_of(j);
        dvec3 off = common + own + tremor + (f >= 0 ? finger[static_cast<std::size_t>(f)] : dvec3(0.0));
        JointState& js = hs.joints[static_cast<std::size_t>(j)];
        js.pose.position += glm::vec3(off);
        dvec3 r = 0.005 * normal3(rng, k);
        double angle = glm::length(r);
        if (angle > 1e-12)
            js.pose.orientation = glm::normalize(js.pose.orientation * glm::quat(glm::angleAxis(angle, r / angle)));
    }
}

HandState lost_hand(bool quirk)
{
    HandState hs; // inactive, joints zeroed, no flags
    if (quirk) {
        // Seen on real devices: "active" with every flag cleared and the joints at the origin.
        hs.active = true;
        for (JointState& js : hs.joints) {
            js.pose = Pose{};
            js.radius = 0.0f;
            js.flags = 0;
        }
    }
    return hs;
}

} // namespace lobe::synth
