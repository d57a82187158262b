#include "sim/sensors/imu.h"

#include <cmath>

#include "autonomy/common/geometry.h"

namespace paddock::sensors {

namespace {
// the out-of-plane axes' seed: one splitmix64 step away from the sensor's
std::uint64_t seed_3d(std::uint64_t seed) {
  std::uint64_t z = seed + 0x9e3779b97f4a7c15ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}
}  // namespace

Imu::Imu(const ImuParams& params, std::uint64_t seed) : params_(params), rng_(seed), rng_3d_(seed_3d(seed)) {
  params::require_valid(params_, "ImuParams");
  // the turn-on biases, three draws in a fixed order per stream
  const double g_ax = gaussian(), g_ay = gaussian(), g_gz = gaussian();
  bias_.ax = params_.accel_bias_initial_std * g_ax;
  bias_.ay = params_.accel_bias_initial_std * g_ay;
  bias_.gz = params_.gyro_bias_initial_std * g_gz;
  const double g_az = normal_3d_(rng_3d_), g_gx = normal_3d_(rng_3d_), g_gy = normal_3d_(rng_3d_);
  bias_.az = params_.accel_bias_initial_std * g_az;
  bias_.gx = params_.gyro_bias_initial_std * g_gx;
  bias_.gy = params_.gyro_bias_initial_std * g_gy;
}

double Imu::gaussian() { return normal_(rng_); }

ImuSample Imu::measure(double true_ax, double true_ay, double true_yaw_rate, double true_yaw_accel, TimeNs stamp,
                       double true_az) {
  const ImuParams& p = params_;

  // six draws per call and stream in a fixed order (walk ax, ay, gz; noise
  // ax, ay, gz; then walk az, gx, gy; noise az, gx, gy), so that switching
  // one effect off does not reshuffle the others
  const double w_ax = gaussian(), w_ay = gaussian(), w_gz = gaussian();
  const double n_ax = gaussian(), n_ay = gaussian(), n_gz = gaussian();
  double d3[6];
  for (double& d : d3) d = normal_3d_(rng_3d_);
  const double w_az = d3[0], w_gx = d3[1], w_gy = d3[2], n_az = d3[3], n_gx = d3[4], n_gy = d3[5];

  // bias random walk over the time since the previous sample: a Wiener process
  // sampled at the stamps has independent increments of variance walk^2 * dt
  const double dt = has_previous_ && stamp > previous_stamp_ ? to_seconds(stamp - previous_stamp_) : 0.0;
  const double sqrt_dt = std::sqrt(dt);
  bias_.ax += p.accel_bias_walk * sqrt_dt * w_ax;
  bias_.ay += p.accel_bias_walk * sqrt_dt * w_ay;
  bias_.gz += p.gyro_bias_walk * sqrt_dt * w_gz;
  bias_.az += p.accel_bias_walk * sqrt_dt * w_az;
  bias_.gx += p.gyro_bias_walk * sqrt_dt * w_gx;
  bias_.gy += p.gyro_bias_walk * sqrt_dt * w_gy;
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
  // level: gravity and the mounting point's climb on z, no roll or pitch rate
  out.az = kGravity + true_az + bias_.az + p.accel_noise * n_az;
  out.gx = bias_.gx + p.gyro_noise * n_gx;
  out.gy = bias_.gy + p.gyro_noise * n_gy;
  return out;
}

}  // namespace paddock::sensors
