#pragma once
/// \file one_euro.h
/// One Euro filter (Casiez, Roussel, Vogel, CHI 2012): an adaptive low-pass whose cutoff
/// rises with speed, so jitter at rest is removed and fast motion is not lagged.

#include <glm/vec3.hpp>

#include "core/settings.h"

namespace lobe {

class OneEuroFilter3 {
public:
    OneEuroFilter3() = default;
    explicit OneEuroFilter3(const OneEuroOptions& options) : options_(options) {}

    /// Filters one sample at time t (seconds, strictly increasing since the last reset).
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
