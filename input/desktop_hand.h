#pragma once
/// \file desktop_hand.h
/// The desktop app's simulated hand: a right hand posed so that its index fingertip is
/// exactly at the point the mouse picks, pinching (thumb tip on the index tip) while the
/// button is held. Its frames go through the same input pipeline as tracked hands, and into
/// the session's recording, so a desktop session replays like a headset one.

#include <glm/vec3.hpp>

#include "core/hand_frame.h"

namespace lobe {

struct DesktopHandPose {
    glm::vec3 tip{0.0f};            ///< where the index fingertip is, stage space (metres)
    glm::vec3 forward{0.0f, 0.0f, -1.0f}; ///< the camera's viewing direction (the fingers point along it)
    bool pinched = false;           ///< thumb tip on the index tip (pinch gap about −1 mm) or open (about 5 cm)
};

/// A right hand (all joints valid and tracked, active) in the given pose: relaxed middle,
/// ring and little fingers (never a grab), the back of the hand up. Deterministic.
HandState desktop_hand(const DesktopHandPose& pose);

/// A frame at `time` with the right hand in `pose` and the left hand untracked; with
/// `tracked` false (the cursor left the window) neither hand is tracked.
HandFrame desktop_frame(double time, const DesktopHandPose& pose, bool tracked = true);

} // namespace lobe
