#pragma once
// the velocity and odometry estimator: an extended Kalman filter of the base
// frame's planar motion, the IMU as its process input, the four wheel speeds
// (and the steering angle that turns the front ones) as its measurements.
//
// State (index: quantity, unit), of the base origin (rear axle centre):
//   0 x, 1 y (m), 2 yaw (rad): the base pose in the odometry frame
//   3 vx, 4 vy (m/s): the base origin's velocity in the base frame
//   5 r (rad/s): the yaw rate
//   6 b_ax, 7 b_ay (m/s^2), 8 b_r (rad/s): the IMU's accelerometer and gyro biases
//
// Predict, at each IMU message (ax_m, ay_m, g_m at the IMU's mounting point
// m = (mx, my) in the base frame, axes the base frame's), over dt since the
// previous message. The IMU sits off the base origin, so it measures
//   a_m = a_base + alpha x m - r^2 m  (+ bias + noise)
// (alpha the yaw acceleration, unknown). We never need alpha: the velocity of
// the IMU point, v_m = v + r x m, obeys v_m' = a_m - r x v_m with no alpha in
// it, and v = v_m - r x m. Written on the base velocity over one step this is
//   r+  = g_m - b_r                                   (the gyro sets the yaw rate)
//   vx+ = vx + dt (ax + rb vy + rb^2 mx) + (r+ - r) my
//   vy+ = vy + dt (ay - rb vx + rb^2 my) - (r+ - r) mx
// with ax = mean of the last two samples' ax_m - b_ax (trapezoid), likewise ay,
// and rb = (r + r+) / 2: the alpha dt of the lever-arm term is exactly the
// change of the yaw rate over the step, (r+ - r). r is a state set from the
// gyro at each predict rather than an input: the wheel updates then see it
// (and, through its covariance with b_r, correct the gyro bias), and the
// lever arm is carried without a yaw acceleration.
//   yaw+ = yaw + dt rb,  (x, y)+ = (x, y) + dt R(yaw + dt rb / 2) (v + v+) / 2
//   biases+ = biases (random walks)
// Process noise: the IMU's white noise enters as the inputs' (accel_noise per
// sample on ax, ay: velocity variance (accel_noise dt)^2 per step; gyro_noise
// on r+), plus velocity_walk (unmodelled accelerations: the zero-order hold
// between samples, vibration, a road not quite flat) and the bias walks.
//
// Update, at each wheel-speed message: wheel i at (px_i, py_i) in the base
// frame (front: px = lf + lr, py = +-track_front / 2; rear: px = 0, py =
// +-track_rear / 2), the front ones turned by the last steering angle d_i
// (rear: 0). Its contact point moves at (vx - r py, vy + r px); along the wheel
//   u_i = (vx - r py) cos d_i + (vy + r px) sin d_i
// and the wheel turns at
//   omega_i = (u_i + k max(|u_i|, 1 m/s)) / R
// (its Jacobian has vx and the r of -r py cos d only: the steered wheels'
// lateral term is predicted but not observed, see velocity_ekf.cc) with k the
// slip ratio the tyres need for the force that accelerates the car
// (the vehicle model's slip definition): k = slip_per_accel (ax + drag_per_mass vx^2),
// ax the IMU's bias-corrected longitudinal acceleration. Its error (load
// transfer, brake balance, a wheel's own torque) is the measurement's:
// with the covariance, s_i = max(|u_i|, 1) / R the reading's change per unit slip,
//   C_ij = (slip_std + slip_model_error |k|)^2 s_i s_j            (one slip error common to all)
//        + [i = j] (wheel_noise^2 + ((wheel_slip_std + wheel_slip_model_error |k|
//                                      + wheel_slip_lateral |r vx|) s_i)^2)
// (the common part is a relative error of all readings: it scales the
// left-right difference by the same factor, so the yaw rate, and through it
// the gyro bias, is not pulled by what the model gets wrong of the slip)
// Wheels that spin or lock are not used:
//   1. consistency across the four: each wheel's reading gives the vx it
//      implies (the other states held); a wheel whose vx lies off the
//      reference by more than consistency_tolerance (+ consistency_relative |vx|)
//      is rejected. The reference is the median of the four, but the slowest
//      wheel under a driving force (k above drive_threshold: only spinning
//      makes a wheel fast) and the fastest under a braking force (only
//      locking makes one slow);
//   2. a chi-square gate on each remaining wheel's innovation (1 dof):
//      nu^2 / S > wheel_gate is rejected. The prediction from the IMU is
//      tight, so a wheel that all four share a spin with is still caught.
//      Until the velocity is acquired (after reset(), the first update that
//      uses two wheels, or a standstill) only the consistency check applies.
// The wheels left are applied together (one update with their correlated
// covariance: at most 4 x 4).
//
// A weak pseudo-measurement then keeps vy bounded (the IMU alone lets it
// random-walk and the wheels see it only through the steered front ones):
// the base origin is the rear axle's centre, so vy / vx is the rear tyres'
// slip angle, which in steady cornering is what their lateral force needs,
// a_y / (g C) with a_y = r vx and C the rear tyres' cornering stiffness per
// unit load:
//   vy = -r vx^2 / (g C)   with std  vy_std + vy_relative |r vx^2 / (g C)|
// (large against its error in a transient; the relative term covers the
// tyre's saturation near the limit), skipped when its innovation fails the
// chi-square gate vy_gate (a slide, past saturation: the IMU carries vy,
// and the skips are counted). It measures vy alone: the right side is
// evaluated at the estimate and its dependence on r and vx left out of the
// Jacobian, so that the model's error cannot leak into them and, through r,
// into the gyro bias.
//
// No update moves the position: the velocity, yaw rate, yaw and biases are
// corrected, and x, y only integrate them (the updates' gain rows of x and
// y are zero, a Schmidt-Kalman update, its covariance in the Joseph form).
// The odometry's position is continuous (REP 105's odom frame). With the
// full gain, x and y took the filter's hindsight through their covariance
// with the gyro bias, which after minutes of dead reckoning is thousands of
// metres per rad/s: at the final stop, under hard braking at low speed,
// where the wheels' slip model is worst, 5e-5 rad/s of bias correction
// moved the position by 0.18 m, back and forth every sample (the default
// run: the stack's pose 1.04 m off as the car came to rest). The yaw keeps
// its hindsight: a gyro bias learnt in the first seconds turns the heading
// it had integrated, which the first lap's map is built on. Measured
// (2026-11-29, seven shipped trackdrives x 2 seeds and the noisy CI
// scenario x 24 seeds, against the full gain): mean ATE RMS 0.053 / 0.196 m
// against 0.058 / 0.228 (clean / noisy), map RMSE 0.029 / 0.174 against
// 0.028 / 0.193, ATE max on the clean tracks 0.11-0.20 m against
// 0.11-1.06. Holding the yaw as well (x, y and yaw all integrated) left the
// first lap's heading drift in the map: noisy map RMSE 0.213 m, one seed's
// map turned by 9 mrad.
//
// Standstill: when every wheel reads at most standstill_wheel_speed and the
// IMU's bias-corrected acceleration and yaw rate are below their thresholds
// (for standstill_time),
// vx = vy = r = 0 is measured instead (a zero-velocity update, with the gyro's
// bias learnt through r = g_m - b_r).
//
// Bad input: a message with a value that is not finite, or stamped before
// the filter's time (IMU) or before the previous message of its own stream
// (wheels, steering; a wheel message up to max_wheel_lag behind the filter's
// time is applied at the filter's time), is ignored: EkfStatus::Rejected, and
// counted. A step that would make the state or covariance non-finite is
// undone and rejected the same way.
//
// No I/O, no clock, no global state.
#include <array>
#include <cstddef>
#include <optional>
#include <string>

#include <Eigen/Core>

#include "autonomy/common/geometry.h"
#include "autonomy/common/params.h"
#include "autonomy/common/time.h"
#include "autonomy/hal/messages.h"

namespace paddock::estimation {

struct VelocityEkfParams {
  // the IMU's white noise per sample, at its rate: the sensor's data sheet
  // (the simulated IMU's defaults, sim/sensors/imu.h)
  double accel_noise = 0.02;
  double gyro_noise = 0.002;
  // bias random walks: 3x the sensor's (3e-4, 2e-5), for the thermal drift a
  // data sheet's Allan curve leaves out
  double accel_bias_walk = 1e-3;
  double gyro_bias_walk = 6e-5;
  // unmodelled accelerations (the zero-order hold between 5 ms samples at a
  // jerk of ~100 m/s^3, vibration): 0.05 m/s per sqrt(s)
  double velocity_walk = 0.05;

  // the initial covariance at reset(): the pose is exact (it defines the
  // odometry frame); the car may be rolling (0.5 m/s); the biases' turn-on
  // residuals after the standstill calibration (the simulated IMU's 0.02
  // m/s^2 and 1e-3 rad/s), doubled
  double velocity_std_initial = 0.5;
  double yaw_rate_std_initial = 0.05;
  double accel_bias_std_initial = 0.04;
  double gyro_bias_std_initial = 2e-3;

  // wheel-speed measurement: the encoder's white noise (0.05 rad/s) with its
  // quantisation (0.0767 / sqrt(12) = 0.022 rad/s)
  double wheel_noise = 0.055;
  // the slip the model does not explain (rolling resistance, road): 0.3 %
  double slip_std = 0.003;
  // and the share of the modelled slip it gets wrong; both common to the four
  // wheels (one force on four like tyres: an error of the model is theirs all)
  double slip_model_error = 0.3;
  // each wheel's own slip error (load transfer, brake balance, its own
  // torque: the front wheels slip more than the rear ones when driving): 0.1 %
  // and 30 % of the modelled slip
  double wheel_slip_std = 0.001;
  double wheel_slip_model_error = 0.3;
  // and per m/s^2 of lateral acceleration (r vx): the inner and outer tyres'
  // combined slips differ by ~0.1 % at 1.5 g, an error that lasts the whole
  // corner and would pull the yaw rate and the gyro bias; 1e-3 per m/s^2
  // drowns it (the wheels then give the speed in a corner, the gyro the yaw rate)
  double wheel_slip_lateral = 1e-3;
  // rejection of spinning and locked wheels
  double wheel_gate = 16.0;  // chi-square, 1 dof: 4 sigma
  double consistency_tolerance = 0.3;
  double consistency_relative = 0.03;
  double drive_threshold = 0.005;  // slip ratio: 1.6 m/s^2 of driving or braking force

  // the rear axle's lateral slip pseudo-measurement (its stiffness: CarGeometry)
  // its error is not white: it lasts as long as a transient or a corner near
  // the limit (the tyre's saturation), so at 100 Hz it must be weak. 0.3 m/s
  // and half the modelled value: on the simulated car the NEES of vy is then
  // ~0.9 (consistent); 0.1 m/s made the filter 2.6x overconfident in vy. It
  // only has to bound the IMU's drift of vy (a real car's roll puts
  // g sin(roll) into ay: 0.17 m/s^2 per degree)
  double vy_std = 0.3;
  double vy_relative = 0.5;
  // a chi-square gate (1 dof) on its innovation nu^2 / (P_vy + std^2): past
  // it the tyres are out of the linear range the model describes (a slide:
  // vy of 2-5 m/s where the model says 1), and the IMU alone carries vy until
  // the car is back in it. 6.63: the 99 % point. 0: no gate. Without it, on
  // the noisy CI scenario (0.1 m range noise, 10 % misses) the model pulled
  // vy back during slides and the estimate left the car: 2 of 12 seeds did
  // not finish; with it 12 of 12
  double vy_gate = 6.63;

  // standstill detection: one encoder count is 0.077 rad/s
  double standstill_wheel_speed = 0.04;
  double standstill_accel = 0.5;
  double standstill_yaw_rate = 0.02;
  // how long the car must look at rest before the zero-velocity update: a car
  // whose wheels have just stopped creeps on its tyres' deflections (the
  // relaxation lengths, ~0.1 s)
  double standstill_time = 0.2;
  // the zero-velocity update's std (vibration of a parked car)
  double standstill_std = 0.002;

  // a wheel message this much behind the filter's time is applied at it
  double max_wheel_lag = 0.02;

  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(accel_noise), {"m/s^2", params::above_up_to(0.0, 100.0), "accelerometer white noise std per sample"});
    v(PADDOCK_PARAM(gyro_noise), {"rad/s", params::above_up_to(0.0, 10.0), "gyro white noise std per sample"});
    v(PADDOCK_PARAM(accel_bias_walk), {"m/s^2/sqrt(s)", params::in(0.0, 10.0), "accelerometer bias random walk"});
    v(PADDOCK_PARAM(gyro_bias_walk), {"rad/s/sqrt(s)", params::in(0.0, 10.0), "gyro bias random walk"});
    v(PADDOCK_PARAM(velocity_walk), {"m/s/sqrt(s)", params::in(0.0, 100.0), "velocity random walk of the unmodelled accelerations"});
    v(PADDOCK_PARAM(velocity_std_initial), {"m/s", params::above_up_to(0.0, 100.0), "velocity std at reset"});
    v(PADDOCK_PARAM(yaw_rate_std_initial), {"rad/s", params::above_up_to(0.0, 10.0), "yaw-rate std at reset"});
    v(PADDOCK_PARAM(accel_bias_std_initial), {"m/s^2", params::above_up_to(0.0, 10.0), "accelerometer bias std at reset"});
    v(PADDOCK_PARAM(gyro_bias_std_initial), {"rad/s", params::above_up_to(0.0, 1.0), "gyro bias std at reset"});
    v(PADDOCK_PARAM(wheel_noise), {"rad/s", params::above_up_to(0.0, 100.0), "wheel-speed white noise std (quantisation included)"});
    v(PADDOCK_PARAM(slip_std), {"", params::in(0.0, 1.0), "slip ratio std the model does not explain"});
    v(PADDOCK_PARAM(slip_model_error), {"", params::in(0.0, 10.0), "relative error of the modelled slip, common to the wheels"});
    v(PADDOCK_PARAM(wheel_slip_std), {"", params::in(0.0, 1.0), "slip ratio std of each wheel on its own"});
    v(PADDOCK_PARAM(wheel_slip_model_error), {"", params::in(0.0, 10.0), "relative error of the modelled slip, each wheel's own"});
    v(PADDOCK_PARAM(wheel_slip_lateral), {"s^2/m", params::in(0.0, 1.0), "each wheel's own slip ratio std per m/s^2 of lateral acceleration"});
    v(PADDOCK_PARAM(wheel_gate), {"", params::above(0.0), "chi-square (1 dof) above which a wheel is rejected"});
    v(PADDOCK_PARAM(consistency_tolerance), {"m/s", params::above(0.0), "a wheel's implied vx further than this (+ relative) from the reference is rejected"});
    v(PADDOCK_PARAM(consistency_relative), {"", params::in(0.0, 1.0), "the consistency tolerance's share of |vx|"});
    v(PADDOCK_PARAM(drive_threshold), {"", params::above(0.0), "modelled slip ratio above which the slowest wheel (below: minus it, the fastest) is the reference"});
    v(PADDOCK_PARAM(vy_std), {"m/s", params::above_up_to(0.0, 100.0), "std of the rear axle's lateral slip pseudo-measurement"});
    v(PADDOCK_PARAM(vy_relative), {"", params::in(0.0, 10.0), "its relative std, of the modelled lateral velocity"});
    v(PADDOCK_PARAM(vy_gate), {"", params::at_least(0.0), "chi-square (1 dof) above which the lateral slip pseudo-measurement is skipped (0: never)"});
    v(PADDOCK_PARAM(standstill_wheel_speed), {"rad/s", params::at_least(0.0), "every wheel slower than this (with the IMU quiet): at rest"});
    v(PADDOCK_PARAM(standstill_accel), {"m/s^2", params::at_least(0.0), "largest bias-corrected acceleration at rest"});
    v(PADDOCK_PARAM(standstill_yaw_rate), {"rad/s", params::at_least(0.0), "largest bias-corrected yaw rate at rest"});
    v(PADDOCK_PARAM(standstill_time), {"s", params::in(0.0, 10.0), "how long the car must look at rest before the zero-velocity update"});
    v(PADDOCK_PARAM(standstill_std), {"m/s", params::above_up_to(0.0, 10.0), "std of the zero-velocity update (rad/s for the yaw rate)"});
    v(PADDOCK_PARAM(max_wheel_lag), {"s", params::in(0.0, 1.0), "a wheel message up to this much older than the newest IMU message is applied at its time"});
  }
};

// what the estimator knows of the car and where its IMU sits: not
// parameters of its own, the runner fills them from [vehicle] and [imu]
// (the defaults are the default car's)
struct CarGeometry {
  double lf = 0.81, lr = 0.72, track_front = 1.22, track_rear = 1.18, wheel_radius = 0.2;
  // the IMU's mounting point in the base frame (m): [imu] mount_x, mount_y
  double imu_x = 0.765;
  double imu_y = 0.0;
  // the tyres' slip per m/s^2 of the car's acceleration, 1 / (g B_x C D_x)
  // (14 * 1.45 * 1.6 = 32.5 per unit slip)
  double slip_per_accel = 3.1e-3;
  // drag over mass (0.7 / 210): the tyres also push against it
  double drag_per_mass = 3.3e-3;
  // the rear tyres' lateral force per load per rad of slip, B C D (11 * 1.45 * 1.7 = 27)
  double cornering_stiffness = 27.0;
};

// the state order of VelocityEstimate::variance and of the filter
enum StateIndex : std::size_t { kX = 0, kY, kYaw, kVx, kVy, kR, kBax, kBay, kBr, kStateSize };

struct VelocityEstimate {
  TimeNs stamp = 0;
  Pose2 pose;  // base frame (rear axle centre) in the odometry frame (origin: the pose given to reset)
  double vx = 0.0, vy = 0.0, yaw_rate = 0.0;  // of the base origin (rear axle centre), base frame, m/s and rad/s
  double accel_bias_x = 0.0, accel_bias_y = 0.0, gyro_bias = 0.0;
  std::array<double, 9> variance{};  // diagonal of the covariance, in StateIndex order
  int wheels_used = 0;               // wheels accepted at the last wheel update (0-4)
};

enum class EkfStatus {
  Ok,
  Rejected,  // a message not finite or out of order: ignored
};

class VelocityEkf {
 public:
  using Vector = Eigen::Matrix<double, 9, 1>;
  using Matrix = Eigen::Matrix<double, 9, 9>;

  // throws std::invalid_argument on invalid params or geometry
  VelocityEkf(const VelocityEkfParams& p, const CarGeometry& g);

  // at rest-or-rolling at `pose`, biases 0, the initial covariance; forgets
  // the messages seen. Before the first reset() the filter starts at the
  // identity pose at its first message's stamp.
  void reset(const Pose2& pose, TimeNs stamp);
  // predict to m.stamp with the IMU as the process input
  EkfStatus on_imu(const hal::Imu& m);
  // update with the wheels that are neither spinning nor locked
  EkfStatus on_wheel_speeds(const hal::WheelSpeeds& m);
  // store the steering angle for the wheel model
  EkfStatus on_steering(const hal::SteeringAngle& m);

  VelocityEstimate estimate() const;
  std::size_t rejected() const { return rejected_; }
  // lateral slip pseudo-measurements skipped at the gate (slides)
  std::size_t vy_gated() const { return vy_gated_; }

  // the full covariance (StateIndex order), for consistency checks
  const Matrix& covariance() const { return P_; }
  const VelocityEkfParams& params() const { return params_; }

 private:
  // the process model over dt with the IMU inputs (bias-uncorrected means)
  void predict(double dt, double ax_m, double ay_m, double g_m);
  // one scalar update: z measured, h predicted, H its Jacobian, var its noise
  void update(double innovation, const Vector& H, double var);
  // the slip ratio the tyres need now, from the held IMU sample
  double modelled_slip() const;
  bool state_finite() const;
  void start_if_needed(TimeNs stamp);

  // the wheel update's parts: each wheel's predicted reading (innovation nu,
  // Jacobian H, the vx its reading implies) and the readings' covariance C
  struct WheelModel {
    std::array<Vector, 4> H;
    std::array<double, 4> nu{}, implied{};
    Eigen::Matrix4d C;
  };
  // the car at rest for standstill_time (updates the timer)
  bool at_rest(const hal::WheelSpeeds& m, double ax, double ay);
  void zero_velocity_update();
  WheelModel wheel_model(const hal::WheelSpeeds& m, double kappa) const;
  // the wheels that neither spin nor lock: consistent with the others, inside the gate
  std::array<bool, 4> consistent_wheels(const WheelModel& w, double kappa) const;
  // the accepted wheels in one joint update; returns how many
  int wheel_update(WheelModel w, const std::array<bool, 4>& use);
  void rear_slip_update();

  VelocityEkfParams params_;
  CarGeometry geometry_;
  std::array<double, 4> wheel_x_{}, wheel_y_{};  // wheel positions in the base frame

  Vector x_ = Vector::Zero();
  Matrix P_ = Matrix::Zero();
  TimeNs stamp_ = 0;
  bool started_ = false;

  // the newest IMU sample (held between samples) and whether there is one
  bool has_imu_ = false;
  double ax_m_ = 0.0, ay_m_ = 0.0, g_m_ = 0.0;
  // the newest steering angle and wheel stamp
  double steering_ = 0.0;
  bool has_steering_ = false;
  TimeNs steering_stamp_ = 0;
  bool has_wheels_ = false;
  TimeNs wheel_stamp_ = 0;
  int wheels_used_ = 0;
  // the velocity is known: a wheel update has used two wheels or found the car
  // at rest since reset() (until then the wheels are not gated against it)
  bool acquired_ = false;
  // since when the car looks at rest
  std::optional<TimeNs> still_since_;
  std::size_t rejected_ = 0;
  std::size_t vy_gated_ = 0;
};

}  // namespace paddock::estimation
