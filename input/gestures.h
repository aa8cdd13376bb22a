#pragma once
/// \file gestures.h
/// Gesture recognition, computed once per frame for both hands: pinch (thumb-tip/index-tip
/// gap with hysteresis, never while the other fingers are all curled), grab (middle, ring
/// and little curled), point (index straight, the others curled), with "just started / just
/// ended" edges. Handles real-device quirks: hands that snap to the origin or the head on
/// loss, joints flagged invalid, tracking drop-outs. What a pinch *does* is decided by the
/// active tool (input/pipeline.h), never here.

#include <array>

#include <glm/vec3.hpp>

#include "core/hand_frame.h"
#include "core/settings.h"
#include "input/one_euro.h"

namespace lobe {

/// Curl of one finger (0 thumb … 4 little): the sum of the bend angles at the knuckle, the
/// middle and the last joint (metacarpal → proximal → intermediate → distal → tip) over 270°,
/// clamped to [0, 1]: 0 straight, about 0.25 relaxed, 0.55–0.7 in a fist. The thumb's chain
/// runs wrist → metacarpal → proximal → distal → tip.
float finger_curl(const HandState& hand, int finger);

/// Why a hand does not count as tracked this frame (for messages and tests).
enum class HandLoss : std::uint8_t {
    None = 0,
    Inactive,        ///< the runtime says the hand is not tracked
    InvalidJoints,   ///< a joint that matters has no valid position
    AtOrigin,        ///< the hand snapped to the stage origin
    AtHead,          ///< the hand snapped to the head
    Jump,            ///< moved faster than a hand can (a tracking glitch)
};

struct HandGesture {
    bool tracked = false;
    HandLoss loss = HandLoss::Inactive;
    double lost_for_s = 0.0; ///< time since the hand was last tracked (0 while tracked)

    glm::vec3 index_tip{0.0f}; ///< filtered (One Euro), metres
    glm::vec3 thumb_tip{0.0f}; ///< filtered
    glm::vec3 palm{0.0f};      ///< raw
    float pinch_gap = 1.0f;    ///< tip distance minus both tip radii (lightly filtered), metres
    std::array<float, 5> curl{}; ///< thumb, index, middle, ring, little

    bool pinching = false;
    bool grabbing = false;
    bool pointing = false;
    bool pinch_started = false, pinch_ended = false;
    bool grab_started = false, grab_ended = false;
    bool point_started = false, point_ended = false;
};

/// Keeps the filters and hysteresis state of both hands.
class GestureRecognizer {
public:
    explicit GestureRecognizer(const InputOptions& options = {});

    /// Updates both hands from one frame (times strictly increasing) and returns their
    /// gestures with this frame's edges.
    const std::array<HandGesture, kHandCount>& update(const HandFrame& frame);
    const HandGesture& hand(Hand h) const { return state_[static_cast<int>(h)]; }
    /// Ends every gesture (end of input): emits the end edges of active gestures.
    const std::array<HandGesture, kHandCount>& finish();

private:
    struct PerHand {
        OneEuroFilter3 index_filter, index_gap_filter, thumb_gap_filter;
        bool ever_tracked = false;
        /// A pinch may start only after the gap was seen open: a hand re-acquired after a long
        /// loss (or first seen) already pinched does not draw until it opens.
        bool armed = false;
        double last_tracked_t = 0.0;
        glm::vec3 last_palm{0.0f};
        double below_since = -1.0; ///< time the gap first fell below the start threshold
    };
    void update_hand(int h, const HandFrame& frame);
    void end_all(HandGesture& g);

    InputOptions options_;
    std::array<HandGesture, kHandCount> state_{};
    std::array<PerHand, kHandCount> per_{};
};

} // namespace lobe
