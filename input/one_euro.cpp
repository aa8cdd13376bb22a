#include "input/one_euro.h"

#include <cmath>
#include <numbers>

#include <glm/geometric.hpp>

namespace lobe {

namespace {
double smoothing_factor(double dt, double cutoff_hz)
{
    const double tau = 1.0 / (2.0 * std::numbers::pi * cutoff_hz);
    return 1.0 / (1.0 + tau / dt);
}
} // namespace

glm::vec3 OneEuroFilter3::filter(const glm::vec3& xf, double t)
{
    const glm::dvec3 x(xf);
    if (!initialised_ || t <= last_t_) {
        // First sample, or a time that did not advance (duplicated frame): pass through.
        if (!initialised_) {
            x_prev_ = x;
            dx_prev_ = glm::dvec3(0.0);
        }
        initialised_ = true;
        last_t_ = t;
        return glm::vec3(x_prev_);
    }
    const double dt = t - last_t_;
    last_t_ = t;
    const glm::dvec3 dx = (x - x_prev_) / dt;
    const double ad = smoothing_factor(dt, options_.d_cutoff_hz);
    dx_prev_ = dx_prev_ + ad * (dx - dx_prev_);
    const double cutoff = options_.min_cutoff_hz + options_.beta * glm::length(dx_prev_);
    const double a = smoothing_factor(dt, cutoff);
    x_prev_ = x_prev_ + a * (x - x_prev_);
    return glm::vec3(x_prev_);
}

} // namespace lobe
