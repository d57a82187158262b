#pragma once
// a six-axis strapdown IMU: a three-axis accelerometer (specific force: a
// level sensor at rest reads az = +g) and a three-axis gyro, with white noise
// per sample, a turn-on bias and a bias that performs a random walk (the two
// error terms of a MEMS data sheet and of a Kalibr-style IMU noise model). The
// sensor axes are the base frame's; the sensor sits at (mount_x, mount_y) in
// the base frame, and measure() adds the rigid-body lever-arm term from the
// base origin to that point. The car's body stays level (the vehicle model is
// planar; see lidar.h's ground): the roll and pitch rates are 0 and the
// vertical axis feels gravity plus the vertical acceleration of the mounting
// point as it keeps its height above the ground under it.
//
// The planar axes (ax, ay, gz) draw from the sensor's stream as they always
// did; the out-of-plane axes (az, gx, gy) from a second stream of their own,
// so a scenario's planar samples do not change with them.
//
// Model (ImuParams) + a small class holding its random stream, its current
// biases and the previous stamp (Imu). No I/O, no clock, no global state.
#include <cstdint>
#include <random>

#include "autonomy/common/params.h"
#include "autonomy/common/time.h"
#include "sim/sensors/gaussian.h"

namespace paddock::sensors {

// every field is the INI key `[imu] <field>`. The defaults describe a good
// automotive / industrial MEMS IMU (Bosch BMI088 class, Xsens MTi-630 or
// ADIS16448 class) after the standstill calibration an FS car does in the
// staging area; each says why.
struct ImuParams {
  // DESIGN.md default rates
  double rate = 200.0;

  // white noise std PER SAMPLE. A data sheet gives a noise density n (per
  // sqrt(Hz)); sampled at `rate` with the anti-alias filter at Nyquist the
  // per-sample std is n * sqrt(rate / 2).
  // accel: 150 ug/sqrt(Hz) (BMI088: 175, MTi-630: 60) = 1.5e-3 m/s^2/sqrt(Hz)
  // -> 0.015 m/s^2 at 200 Hz; rounded up to 0.02 for the residual vibration
  // a stiff mount on a monocoque still passes.
  double accel_noise = 0.02;
  // gyro: 0.01 deg/s/sqrt(Hz) (BMI088: 0.014, MTi-630: 0.007) = 1.75e-4
  // rad/s/sqrt(Hz) -> 1.75e-3 rad/s at 200 Hz; rounded to 0.002.
  double gyro_noise = 0.002;

  // bias random walk: b_{k+1} = b_k + walk * sqrt(dt) * N(0, 1), so the bias
  // variance grows by walk^2 per second. The Kalibr reference values of an
  // ADIS16448 (accelerometer_random_walk 3e-4 m/s^3/sqrt(Hz),
  // gyroscope_random_walk 1.9e-5 rad/s^2/sqrt(Hz)): over a 10-minute run the
  // accel bias drifts by ~7 mm/s^2 (1 sigma) and the gyro bias by ~5e-4 rad/s
  // (0.03 deg/s), small against the turn-on residuals below, as on a real car.
  double accel_bias_walk = 3e-4;
  double gyro_bias_walk = 2e-5;

  // turn-on bias std, drawn once per sensor (per run). What is left after a
  // standstill calibration: accel 0.02 m/s^2 (2 mg, the tilt of the ground
  // and the repeatability of a MEMS accelerometer's offset), gyro 1e-3 rad/s
  // (0.06 deg/s; BMI088's uncalibrated zero-rate offset is up to 1 deg/s, a
  // few seconds of standstill averaging remove all but a drift-limited rest).
  double accel_bias_initial_std = 0.02;
  double gyro_bias_initial_std = 1e-3;

  // mounting of the sensor origin in the base frame (rear axle centre, x
  // forward, y left); the axes are the base frame's. 0.765 m: at the CG of
  // the default vehicle (lr = 0.765 m), where FS teams put the IMU so that it
  // sees no lever-arm terms.
  double mount_x = 0.765;
  double mount_y = 0.0;

  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(rate), {"Hz", params::in(1.0, 10000.0), "samples per second"});
    v(PADDOCK_PARAM(accel_noise), {"m/s^2", params::in(0.0, 100.0), "accelerometer white noise std per sample"});
    v(PADDOCK_PARAM(gyro_noise), {"rad/s", params::in(0.0, 10.0), "gyro white noise std per sample"});
    v(PADDOCK_PARAM(accel_bias_walk), {"m/s^2/sqrt(s)", params::in(0.0, 10.0), "accelerometer bias random walk"});
    v(PADDOCK_PARAM(gyro_bias_walk), {"rad/s/sqrt(s)", params::in(0.0, 10.0), "gyro bias random walk"});
    v(PADDOCK_PARAM(accel_bias_initial_std), {"m/s^2", params::in(0.0, 10.0), "turn-on accelerometer bias std"});
    v(PADDOCK_PARAM(gyro_bias_initial_std), {"rad/s", params::in(0.0, 10.0), "turn-on gyro bias std"});
    v(PADDOCK_PARAM(mount_x), {"m", params::in(-10.0, 10.0), "IMU position ahead of the rear axle"});
    v(PADDOCK_PARAM(mount_y), {"m", params::in(-5.0, 5.0), "IMU position left of the centre"});
  }
};

// one IMU sample, in the sensor frame (= base frame orientation)
struct ImuSample {
  TimeNs stamp = 0;
  double ax = 0.0;  // m/s^2, specific force along x (forward)
  double ay = 0.0;  // m/s^2, specific force along y (left)
  double gz = 0.0;  // rad/s, yaw rate (> 0 turning left)
  double az = 0.0;  // m/s^2, specific force along z (up)
  double gx = 0.0;  // rad/s, roll rate
  double gy = 0.0;  // rad/s, pitch rate
};

// the current biases, for tests and for the run's ground-truth log
struct ImuBias {
  double ax = 0.0;  // m/s^2
  double ay = 0.0;  // m/s^2
  double gz = 0.0;  // rad/s
  double az = 0.0;  // m/s^2
  double gx = 0.0;  // rad/s
  double gy = 0.0;  // rad/s
};

class Imu {
 public:
  // throws std::invalid_argument when params::validate(params) fails. The seed starts
  // this sensor's own random stream (std::mt19937_64) and draws the turn-on
  // biases: the same seed and the same inputs give the same samples.
  Imu(const ImuParams& params, std::uint64_t seed);

  // one sample at `stamp`. true_ax, true_ay: the acceleration of the BASE
  // ORIGIN (rear axle centre), expressed in the base frame (m/s^2; planar, no
  // gravity); true_yaw_rate (rad/s) and true_yaw_accel (rad/s^2) of the body.
  // The sensor adds the lever arm to its mounting point r = (mount_x, mount_y):
  // a_mount = a_base + alpha x r - omega^2 r, then its biases and noise.
  // The biases first take one random-walk step over dt = stamp - previous
  // stamp (none on the first sample; a stamp going backwards counts as dt = 0).
  // true_az: the vertical acceleration of the MOUNTING POINT (m/s^2, up;
  // gravity is added here). Six normal draws per call from each stream
  // whatever the inputs. A NaN input gives a NaN in the outputs that depend
  // on it and leaves the biases untouched.
  ImuSample measure(double true_ax, double true_ay, double true_yaw_rate, double true_yaw_accel, TimeNs stamp,
                    double true_az = 0.0);

  const ImuParams& params() const { return params_; }
  const ImuBias& bias() const { return bias_; }
  // the sample period in integer nanoseconds
  TimeNs period_ns() const { return from_seconds(1.0 / params_.rate); }

 private:
  double gaussian();  // N(0, 1)

  ImuParams params_;
  std::mt19937_64 rng_;
  Gaussian normal_{0.0, 1.0};
  std::mt19937_64 rng_3d_;  // the out-of-plane axes'
  Gaussian normal_3d_{0.0, 1.0};
  ImuBias bias_;
  bool has_previous_ = false;
  TimeNs previous_stamp_ = 0;
};

}  // namespace paddock::sensors
