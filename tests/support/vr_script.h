#pragma once
// Scripted hands for the VR session's tests: both hands posed with the articulated hand model
// (input/hand_model.h) so that the gesture recogniser sees real pinches, points and fists, and
// moved along smooth (minimum-jerk) paths at 90 Hz. Clean tracking: the synthesizer's noise
// and drop-outs are what the recording tests cover; here every frame is what the script says.
#include <algorithm>
#include <cmath>
#include <functional>
#include <vector>

#include <glm/geometric.hpp>

#include "core/hand_frame.h"
#include "input/hand_model.h"

namespace lobe::test {

enum class HandPose { Open, Point, Fist };

struct ScriptHand {
    bool active = false;
    HandPose pose = HandPose::Open;
    glm::vec3 tip{0.0f}; ///< index tip (Open, Point) or palm (Fist), stage space
    float gap = 0.05f;   ///< Open: thumb-to-index gap between the tip surfaces (≤ 0: touching)
};

/// A hand in `pose` with its index tip (fist: palm) at `h.tip`, fingers along −Z, back up.
inline HandState pose_script_hand(Hand hand, const ScriptHand& h)
{
    namespace hm = hand_model;
    static const hm::HandShape shape = hm::make_hand_shape(1.0f);
    HandState out;
    if (!h.active) return out;
    hm::Articulation a;
    // The synthesizer's pinch-ready hand (input/synth_motion.cpp, approach_pose): index bent
    // about halfway, the other fingers relaxed, so that the thumb can reach the index tip.
    const float index_curl = h.pose == HandPose::Fist ? 1.0f : h.pose == HandPose::Point ? 0.0f : 0.55f;
    const float other_curl = h.pose == HandPose::Open ? 0.23f : 1.0f;
    for (int f = hm::kIndex; f <= hm::kLittle; ++f) a.curl[std::size_t(f)] = f == hm::kIndex ? index_curl : other_curl;
    hm::LocalHand local;
    hm::pose_fingers(shape, a, local);
    const glm::vec3 index_tip = local[idx(Joint::IndexTip)].position;
    glm::vec3 thumb_target;
    if (h.pose == HandPose::Open) {
        // The synthesizer's thumb directions: open, turning to the contact side as it closes.
        const float s_close = std::clamp(1.0f - h.gap / 0.065f, 0.0f, 1.0f);
        const glm::vec3 dir = glm::normalize(glm::mix(glm::normalize(glm::vec3(-0.85f, 0.35f, 0.4f)),
                                                      glm::normalize(glm::vec3(-0.6f, -0.2f, 0.75f)), s_close));
        const float radii = shape.radius[idx(Joint::ThumbTip)] + shape.radius[idx(Joint::IndexTip)];
        thumb_target = index_tip + dir * (radii + std::max(h.gap, -0.004f));
    } else {
        // Tucked over the middle finger's middle phalanx.
        thumb_target = local[idx(Joint::MiddleIntermediate)].position + glm::vec3(-0.02f, -0.012f, 0.0f);
    }
    hm::pose_thumb(shape, thumb_target, local);
    const Joint anchor = h.pose == HandPose::Fist ? Joint::Palm : Joint::IndexTip;
    const glm::vec3 anchor_local = hm::mirror(local[idx(anchor)].position, hand);
    return hm::place_hand(shape, local, hand, glm::quat(1, 0, 0, 0), h.tip - anchor_local);
}

/// Emits frames to `sink` at 90 Hz while hands move.
class VrScript {
public:
    explicit VrScript(std::function<void(const HandFrame&)> sink) : sink_(std::move(sink))
    {
        head_.position = {0.0f, 1.6f, 0.0f};
    }

    ScriptHand& hand(Hand h) { return hands_[static_cast<int>(h)]; }
    double time() const { return t_; }
    const Pose& head() const { return head_; }

    /// Holds everything still for `seconds`.
    void wait(double seconds) { run(seconds, [](double) {}); }

    /// Moves `h`'s tip along the straight line to `to` in `seconds` (minimum jerk).
    void move(Hand h, glm::vec3 to, double seconds)
    {
        const glm::vec3 from = hand(h).tip;
        run(seconds, [&, from, to](double u) { hand(h).tip = glm::mix(from, to, float(smooth(u))); });
    }

    /// Moves both hands at once.
    void move_both(glm::vec3 left_to, glm::vec3 right_to, double seconds)
    {
        const glm::vec3 l0 = hand(Hand::Left).tip, r0 = hand(Hand::Right).tip;
        run(seconds, [&, l0, r0, left_to, right_to](double u) {
            hand(Hand::Left).tip = glm::mix(l0, left_to, float(smooth(u)));
            hand(Hand::Right).tip = glm::mix(r0, right_to, float(smooth(u)));
        });
    }

    /// Closes (true) or opens the pinch of `h` where it is.
    void pinch(Hand h, bool close)
    {
        const float g0 = hand(h).gap, g1 = close ? -0.002f : 0.05f;
        run(0.2, [&, g0, g1](double u) { hand(h).gap = g0 + (g1 - g0) * float(smooth(u)); });
        wait(0.1);
    }

    /// Pinches at the first point of `path`, follows it at about `speed` m/s, releases.
    void pinch_along(Hand h, const std::vector<glm::vec3>& path, double speed = 0.3)
    {
        hand(h).pose = HandPose::Open;
        move(h, path.front(), 0.5);
        pinch(h, true);
        for (std::size_t i = 1; i < path.size(); ++i) {
            const double d = glm::distance(path[i - 1], path[i]);
            const glm::vec3 a = path[i - 1], b = path[i];
            run(std::max(d / speed, 1.0 / 90.0), [&, a, b](double u) { hand(h).tip = glm::mix(a, b, float(u)); });
        }
        pinch(h, false);
    }

    /// Closes `h` into a fist where it is (the palm stays put), or opens it.
    void fist(Hand h, bool close)
    {
        ScriptHand& sh = hand(h);
        if (close == (sh.pose == HandPose::Fist)) return;
        const HandState now = pose_script_hand(h, sh);
        if (close) {
            sh.tip = now[Joint::Palm].pose.position;
            sh.pose = HandPose::Fist;
        } else {
            sh.pose = HandPose::Open;
            ScriptHand open = sh;
            open.tip = glm::vec3(0.0f);
            sh.tip = now[Joint::Palm].pose.position - pose_script_hand(h, open)[Joint::Palm].pose.position;
        }
        wait(0.2);
    }

    /// Points with `h`, touches `point` coming along `normal` (the board's front), backs off.
    void poke(Hand h, glm::vec3 point, glm::vec3 normal)
    {
        hand(h).pose = HandPose::Point;
        move(h, point + 0.06f * normal, 0.5);
        move(h, point - 0.006f * normal, 0.25);
        move(h, point + 0.06f * normal, 0.25);
        hand(h).pose = HandPose::Open;
        wait(0.1);
    }

private:
    static double smooth(double u) { return u * u * u * (10.0 - 15.0 * u + 6.0 * u * u); }

    void run(double seconds, const std::function<void(double)>& at)
    {
        const int n = std::max(1, int(std::lround(seconds * 90.0)));
        for (int i = 1; i <= n; ++i) {
            at(double(i) / double(n));
            t_ += 1.0 / 90.0;
            HandFrame f;
            f.time = t_;
            f.head = head_;
            f.head_valid = true;
            for (int k = 0; k < kHandCount; ++k)
                f.hands[std::size_t(k)] = pose_script_hand(static_cast<Hand>(k), hands_[std::size_t(k)]);
            sink_(f);
        }
    }

    std::function<void(const HandFrame&)> sink_;
    std::array<ScriptHand, kHandCount> hands_{};
    Pose head_;
    double t_ = 0.0;
};

} // namespace lobe::test
