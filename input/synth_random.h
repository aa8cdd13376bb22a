#pragma once
/// \file synth_random.h
/// The synthesizer's random numbers (input/synth.h; not included outside input/): the
/// project's SplitMix64 stream (core/random.h), the same numbers on every platform and
/// standard library, split into independent streams per purpose so that changing one step of
/// a scenario leaves the others' numbers alone.

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "core/random.h"

namespace lobe::synth {

/// The scenario's random numbers (core/random.h), with the two distributions only the
/// synthesizer uses.
class Rng : public SplitMix64 {
public:
    using SplitMix64::SplitMix64;
    /// Normal truncated at ±k (tracking noise has no far outliers once fitted to a hand model).
    double normal_clamped(double k) { return std::clamp(normal(), -k, k); }
    double exponential(double mean) { return -mean * std::log(1.0 - uniform()); }
};

/// An independent stream for one purpose, derived from the scenario seed.
inline std::uint64_t stream_seed(std::uint64_t seed, std::uint64_t tag)
{
    Rng r(seed ^ (tag * 0xD1B54A32D192ED03ull + 0x2545F4914F6CDD1Dull));
    r.next();
    return r.next();
}

/// What a stream is for: the `tag` of stream_seed.
enum StreamTag : std::uint64_t {
    kTagPerson = 1,
    kTagDropouts = 2,
    kTagNoise = 3,
    kTagClock = 4,
    kTagStep = 0x10000,      // + step index: timing choices of one step
    kTagGenerator = 0x40000, // + step index: wobble of a generated curve
};

} // namespace lobe::synth
