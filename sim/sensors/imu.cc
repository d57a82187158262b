#include "sim/sensors/imu.h"

#include <cmath>

namespace paddock::sensors {

Imu::Imu(const ImuParams& params, std::uint64_t seed) : params_(params), rng_(seed) {
  params::require_valid(params_, "ImuParams");
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
