#pragma once
/// \file random.h
/// The project's one seeded random stream: SplitMix64 (Steele, Lea and Flood, "Fast
/// splittable pseudorandom number generators", OOPSLA 2014).
///
/// Written here rather than taken from <random>: the standard distributions differ between
/// standard libraries, and a recording must replay to the same bits with every compiler
/// (DESIGN.md: randomness only through a seed that is part of the settings). One add, two
/// multiplies and three shifts per number; streams are keyed by hashing (splitmix64), so a
/// node's or a leaf's numbers depend only on its key, never on how many others were drawn.

#include <cmath>
#include <cstdint>

namespace lobe {

/// SplitMix64's increment, ⌊2⁶⁴/φ⌋ (odd).
inline constexpr std::uint64_t kSplitMix64Gamma = 0x9E3779B97F4A7C15ull;

/// SplitMix64's output function: a bijective mix of all 64 bits of `z`.
constexpr std::uint64_t splitmix64_finalize(std::uint64_t z)
{
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/// One SplitMix64 step from state `x`: the finaliser of x + γ. Also the hash that keys streams.
constexpr std::uint64_t splitmix64(std::uint64_t x) { return splitmix64_finalize(x + kSplitMix64Gamma); }

/// A uniform double in [0, 1) from the top 53 bits of `bits`.
constexpr double unit_interval(std::uint64_t bits) { return static_cast<double>(bits >> 11) * 0x1.0p-53; }

/// A SplitMix64 stream: state += γ, then the finaliser.
class SplitMix64 {
public:
    explicit constexpr SplitMix64(std::uint64_t seed = 0) : state_(seed) {}

    constexpr std::uint64_t next() { return splitmix64_finalize(state_ += kSplitMix64Gamma); }
    /// Uniform in [0, 1), 53 random bits.
    constexpr double uniform() { return unit_interval(next()); }
    /// Uniform in [a, b).
    constexpr double uniform(double a, double b) { return a + (b - a) * uniform(); }
    /// Standard normal: one Box–Muller value per call (two uniforms drawn).
    double normal()
    {
        const double u1 = 1.0 - uniform(); // (0, 1]
        const double u2 = uniform();
        return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * 3.14159265358979323846 * u2);
    }

    constexpr std::uint64_t state() const { return state_; }

private:
    std::uint64_t state_;
};

} // namespace lobe
