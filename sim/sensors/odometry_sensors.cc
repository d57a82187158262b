#include "sim/sensors/odometry_sensors.h"

#include <cmath>
#include <cstddef>
#include <sstream>
#include <stdexcept>

#include "autonomy/common/geometry.h"

#include "sim/sensors/param_check.h"

namespace paddock::sensors {

namespace {

// rate: positive; 100 kHz bounds the sample count of a run
std::string check_rate(double rate) {
  if (std::isfinite(rate) && rate > 0.0 && rate <= 1e5) return {};
  std::ostringstream s;
  s << "rate must be a finite number in (0, 100000] Hz (got " << rate << ")";
  return s.str();
}

// the nearest multiple of step (ties away from zero); step 0: unchanged
double quantise(double v, double step) { return step > 0.0 ? step * std::round(v / step) : v; }

}  // namespace

std::string validate(const WheelSpeedParams& p) {
  std::string msg = check_rate(p.rate);
  if (msg.empty()) msg = check_range("noise", p.noise, 0.0, kNoUpperBound, "rad/s");
  if (msg.empty()) msg = check_range("resolution", p.resolution, 0.0, kNoUpperBound, "rad/s");
  return msg;
}

std::string validate(const SteeringSensorParams& p) {
  std::string msg = check_rate(p.rate);
  if (msg.empty()) msg = check_range("noise", p.noise, 0.0, kNoUpperBound, "rad");
  if (msg.empty()) msg = check_range("resolution", p.resolution, 0.0, kNoUpperBound, "rad");
  // a zero more than a quarter turn of road wheel off is not a calibration
  if (msg.empty()) msg = check_range("offset", p.offset, -0.5 * kPi, 0.5 * kPi, "rad");
  return msg;
}

WheelSpeedSensor::WheelSpeedSensor(const WheelSpeedParams& params, std::uint64_t seed) : params_(params), rng_(seed) {
  const std::string msg = validate(params);
  if (!msg.empty()) throw std::invalid_argument("wheel speed sensor: " + msg);
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
  const std::string msg = validate(params);
  if (!msg.empty()) throw std::invalid_argument("steering sensor: " + msg);
}

SteeringSample SteeringSensor::measure(double true_angle, TimeNs stamp) {
  const double g = normal_(rng_);
  SteeringSample out;
  out.stamp = stamp;
  out.angle = quantise(true_angle + params_.offset + params_.noise * g, params_.resolution);
  return out;
}

}  // namespace paddock::sensors
