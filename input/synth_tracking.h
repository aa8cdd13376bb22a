#pragma once
/// \file synth_tracking.h
/// What a real tracker adds to the synthesizer's clean hands (input/synth.h; not included
/// outside input/): jitter, physiological tremor and tracking drop-outs, from their own
/// random streams. Amounts and where drop-outs fall: docs/scenario-format.md, "What the
/// synthesizer adds". Metres, seconds.

#include <array>
#include <cstdint>
#include <vector>

#include "core/hand_frame.h"
#include "input/synth_geometry.h"
#include "input/synth_motion.h"
#include "input/synth_random.h"

namespace lobe::synth {

/// One tracking loss of a hand over [t0, t1).
struct Dropout {
    double t0 = 0.0, t1 = 0.0;
    bool quirk = false; ///< active, flags cleared, joints at the origin (instead of inactive)
};

/// Tracking drop-outs (the kTagDropouts stream of `seed`), sorted by t0 per hand: about one
/// every 7 s per hand, 50–290 ms where the hand is between gestures, 55–100 ms inside a
/// stroke (the pipeline bridges losses up to 150 ms), none while the thumb closes or opens or
/// during distractors. At least one of each kind when possible.
std::array<std::vector<Dropout>, kHandCount> schedule_dropouts(const Synth& sy, std::uint64_t seed);

/// The drifting phase of one hand's tremor.
struct TremorState {
    double phase = 0.0;
};

/// Advances a hand's physiological tremor to time `t`, `dt` after the previous frame (one
/// draw from `noise`), and returns the hand's offset: 8–12 Hz, frequency and phase drifting,
/// mostly along the back of the hand (`rot` is the hand's orientation).
dvec3 tremor_offset(TremorState& state, const HandPersona& hp, const dquat& rot, double t, double dt, Rng& noise);

/// Jitter (white: hand 0.5 mm, finger 0.35 mm, joint 0.3 mm per axis, truncated at 2.5 σ,
/// about 1.2 mm per joint in all; orientations 0.3°) plus the `tremor` offset, added to every
/// joint.
void add_noise(HandState& hs, Rng& rng, const dvec3& tremor);

/// The hand during a drop-out: inactive, or with `quirk` the real-device quirk of an active
/// hand with every flag cleared and every joint at the origin.
HandState lost_hand(bool quirk);

} // namespace lobe::synth
