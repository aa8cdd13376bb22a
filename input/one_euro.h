#pragma once
/// \file one_euro.h
/// One Euro filter (Casiez, Roussel, Vogel, CHI 2012): an adaptive low-pass whose cutoff
/// rises with speed, so jitter at rest is removed and fast motion is not lagged. Per sample,
/// with Δt the time since the last one: α(f) = 1 / (1 + τ/Δt), τ = 1 / (2π f); the speed
/// ẋ is low-passed at d_cutoff_hz, then x at f = min_cutoff_hz + beta · |ẋ| (speed in m/s).

#include <glm/vec3.hpp>

#include "core/settings.h"

namespace lobe {

class OneEuroFilter3 {
public:
    OneEuroFilter3() = default;
    explicit OneEuroFilter3(const OneEuroOptions& options) : options_(options) {}

    /// Filters one sample (metres) at time t (seconds). The first sample (after construction
    /// or reset) passes through; a sample whose time does not advance (a duplicated frame)
    /// returns the last output.
    glm::vec3 filter(const glm::vec3& x, double t);
    /// Forgets the past (after tracking loss): the next sample passes through unchanged.
    void reset() { initialised_ = false; }
    bool initialised() const { return initialised_; }

private:
    OneEuroOptions options_;
    bool initialised_ = false;
    double last_t_ = 0.0;
    glm::dvec3 x_prev_{0.0};
    glm::dvec3 dx_prev_{0.0};
};

} // namespace lobe
