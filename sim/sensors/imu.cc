#include "sim/sensors/imu.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "sim/sensors/param_check.h"

namespace paddock::sensors {

std::string validate(const ImuParams& p) {
  // rate: positive; 100 kHz bounds the sample count of a run
  if (!(std::isfinite(p.rate) && p.rate > 0.0 && p.rate <= 1e5)) {
    std::ostringstream s;
    s << "rate must be a finite number in (0, 100000] Hz (got " << p.rate << ")";
    return s.str();
  }
  struct Field {
    const char* name;
    double value;
    double lo;
    double hi;
    const char* unit;
  };
  const Field fields[] = {
      {"accel_noise", p.accel_noise, 0.0, kNoUpperBound, "m/s^2"},
      {"gyro_noise", p.gyro_noise, 0.0, kNoUpperBound, "rad/s"},
      {"accel_bias_walk", p.accel_bias_walk, 0.0, kNoUpperBound, "m/s^2/sqrt(s)"},
      {"gyro_bias_walk", p.gyro_bias_walk, 0.0, kNoUpperBound, "rad/s/sqrt(s)"},
      {"accel_bias_initial_std", p.accel_bias_initial_std, 0.0, kNoUpperBound, "m/s^2"},
      {"gyro_bias_initial_std", p.gyro_bias_initial_std, 0.0, kNoUpperBound, "rad/s"},
      {"mount_x", p.mount_x, -kNoUpperBound, kNoUpperBound, "m"},
      {"mount_y", p.mount_y, -kNoUpperBound, kNoUpperBound, "m"},
  };
  for (const Field& f : fields) {
    std::string msg = check_range(f.name, f.value, f.lo, f.hi, f.unit);
    if (!msg.empty()) return msg;
  }
  return {};
}

Imu::Imu(const ImuParams& params, std::uint64_t seed) : params_(params), rng_(seed) {
  const std::string msg = validate(params);
  if (!msg.empty()) throw std::invalid_argument("imu: " + msg);
  // the turn-on biases, three draws in a fixed order
  const double g_ax = gaussian(), g_ay = gaussian(), g_gz = gaussian();
  bias_.ax = params_.accel_bias_initial_std * g_ax;
  bias_.ay = params_.accel_bias_initial_std * g_ay;
  bias_.gz = params_.gyro_bias_initial_std * g_gz;
}

double Imu::gaussian() { return normal_(rng_); }

ImuSample Imu::measure(double true_ax, double true_ay, double true_yaw_rate, double true_yaw_accel, TimeNs stamp) {
  const ImuParams& p = params_;

  // six draws per call in a fixed order (walk ax, ay, gz; noise ax, ay, gz), so
  // that switching one effect off does not reshuffle the others
  const double w_ax = gaussian(), w_ay = gaussian(), w_gz = gaussian();
  const double n_ax = gaussian(), n_ay = gaussian(), n_gz = gaussian();

  // bias random walk over the time since the previous sample: a Wiener process
  // sampled at the stamps has independent increments of variance walk^2 * dt
  const double dt = has_previous_ && stamp > previous_stamp_ ? to_seconds(stamp - previous_stamp_) : 0.0;
  const double sqrt_dt = std::sqrt(dt);
  bias_.ax += p.accel_bias_walk * sqrt_dt * w_ax;
  bias_.ay += p.accel_bias_walk * sqrt_dt * w_ay;
  bias_.gz += p.gyro_bias_walk * sqrt_dt * w_gz;
  has_previous_ = true;
  previous_stamp_ = stamp;

  // lever arm: for a rigid body a_P = a_O + alpha x r + omega x (omega x r);
  // in the plane alpha x r = alpha (-r_y, r_x) and omega x (omega x r) =
  // -omega^2 (r_x, r_y) (the centripetal term, toward the centre of rotation)
  const double rx = p.mount_x, ry = p.mount_y;
  const double w2 = true_yaw_rate * true_yaw_rate;
  const double ax_mount = true_ax - true_yaw_accel * ry - w2 * rx;
  const double ay_mount = true_ay + true_yaw_accel * rx - w2 * ry;

  // the yaw rate is the same everywhere on a rigid body
  ImuSample out;
  out.stamp = stamp;
  out.ax = ax_mount + bias_.ax + p.accel_noise * n_ax;
  out.ay = ay_mount + bias_.ay + p.accel_noise * n_ay;
  out.gz = true_yaw_rate + bias_.gz + p.gyro_noise * n_gz;
  return out;
}

}  // namespace paddock::sensors
