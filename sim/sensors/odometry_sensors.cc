#include "sim/sensors/odometry_sensors.h"

#include <cmath>
#include <cstddef>

namespace paddock::sensors {

namespace {

// the nearest multiple of step (ties away from zero); step 0: unchanged
double quantise(double v, double step) { return step > 0.0 ? step * std::round(v / step) : v; }

}  // namespace

WheelSpeedSensor::WheelSpeedSensor(const WheelSpeedParams& params, std::uint64_t seed) : params_(params), rng_(seed) {
  params::require_valid(params_, "WheelSpeedParams");
}

WheelSpeedSample WheelSpeedSensor::measure(const std::array<double, 4>& true_omega, TimeNs stamp) {
  WheelSpeedSample out;
  out.stamp = stamp;
  for (std::size_t i = 0; i < 4; ++i) {
    // one draw per wheel, also at rest, so that one wheel stopping does not
    // reshuffle the others' noise
    const double g = normal_(rng_);
    const double w = true_omega[i];
    // at rest: no edges, no count, exactly 0 (a NaN fails the test and reads NaN)
    if (w == 0.0) {
      out.omega[i] = 0.0;
      continue;
    }
    // noise on the magnitude, clipped at 0: the noise never reverses the wheel
    const double magnitude = std::fmax(0.0, std::abs(w) + params_.noise * g);
    // std::fmax returns 0 for a NaN magnitude: keep the NaN
    const double m = std::isnan(w) ? w : magnitude;
    const double q = quantise(m, params_.resolution);
    // a zero count is +0 whatever the direction
    out.omega[i] = q == 0.0 ? 0.0 : std::copysign(q, w);
  }
  return out;
}

SteeringSensor::SteeringSensor(const SteeringSensorParams& params, std::uint64_t seed) : params_(params), rng_(seed) {
  params::require_valid(params_, "SteeringSensorParams");
}

SteeringSample SteeringSensor::measure(double true_angle, TimeNs stamp) {
  const double g = normal_(rng_);
  SteeringSample out;
  out.stamp = stamp;
  out.angle = quantise(true_angle + params_.offset + params_.noise * g, params_.resolution);
  return out;
}

}  // namespace paddock::sensors
