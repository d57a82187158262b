#pragma once
// the controller of the car: the lateral law (combined Stanley / pure pursuit,
// lateral.h) and the speed loop (longitudinal.h) on one reference trajectory,
// run once per control cycle (100 Hz by default).
#include <cmath>
#include <cstddef>
#include <limits>
#include <string>

#include "autonomy/common/geometry.h"
#include "autonomy/common/params.h"
#include "autonomy/common/trajectory.h"
#include "autonomy/control/lateral.h"
#include "autonomy/control/longitudinal.h"

namespace paddock::control {

// what the stack knows of its car. Defaults: the AMZ FSSIM "gotthard" car
// (m 190 kg, lf = lr = 0.765 m, Pacejka B 12.56 C 1.38 D 1.60, motor 5000 N,
// drag 0.7 v^2, rolling resistance 180 N). Not a parameter set a user
// writes: the runner fills it from the vehicle ([vehicle], see
// stack_params), so StackParams does not visit it (its check() checks it);
// the visit below gives the units and bounds params::validate checks.
struct VehicleKnowledge {
  double mass = 190.0;
  // the mass the drive accelerates: the car's plus its wheels' and motors'
  // rotating inertia seen at the road, sum I / r^2
  double equivalent_mass = 190.0;
  double lf = 0.765;
  double lr = 0.765;
  double wheelbase = 1.53;
  // B C D Fz_front at the static load Fz_front = m g lr / L = 931.95 N ->
  // 27.73 * 931.95 = 25,845 N/rad
  double front_cornering_stiffness = front_axle_cornering_stiffness(12.56, 1.38, 1.60, 190.0, 0.765, 0.765);
  // a 9 m hairpin (centreline radius ~3 m) needs atan(1.53 / 3) = 0.47 rad
  // kinematically; EUFS has +-0.52
  double max_steering_angle = 0.5;
  double max_drive_force = 5000.0;
  // what the motors deliver to the wheels above the base speed: the drive
  // force at throttle 1 is min(max_drive_force, max_drive_power / v)
  double max_drive_power = 1e12;
  // about what the tyres carry without downforce, D m g = 1.6 * 190 * 9.81
  double max_brake_force = 3000.0;
  double drag_coefficient = 0.7;
  double rolling_resistance = 180.0;

  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(mass), {"kg", params::above(0.0), "the car's mass"});
    v(PADDOCK_PARAM(equivalent_mass), {"kg", params::above(0.0), "mass plus the rotating parts seen at the road (what the drive accelerates)"});
    v(PADDOCK_PARAM(lf), {"m", params::above(0.0), "CG to front axle"});
    v(PADDOCK_PARAM(lr), {"m", params::above(0.0), "CG to rear axle"});
    v(PADDOCK_PARAM(wheelbase), {"m", params::above(0.0), "rear axle to front axle (lf + lr)"});
    v(PADDOCK_PARAM(front_cornering_stiffness), {"N/rad", params::above(0.0), "front axle cornering stiffness"});
    v(PADDOCK_PARAM(max_steering_angle), {"rad", params::Bounds{0.0, 0.5 * kPi, true, true}, "largest steering angle at the wheels"});
    v(PADDOCK_PARAM(max_drive_force), {"N", params::above(0.0), "drive force at throttle 1 below the base speed"});
    v(PADDOCK_PARAM(max_drive_power), {"W", params::above(0.0), "drive power at the wheels at throttle 1 above the base speed"});
    v(PADDOCK_PARAM(max_brake_force), {"N", params::above(0.0), "brake force at brake 1"});
    v(PADDOCK_PARAM(drag_coefficient), {"N s^2/m^2", params::at_least(0.0), "aerodynamic drag F = c v^2"});
    v(PADDOCK_PARAM(rolling_resistance), {"N", params::at_least(0.0), "constant resistance while moving"});
  }
  std::string check() const {
    if (std::abs(wheelbase - (lf + lr)) <= 1e-3) return "";
    return "wheelbase must equal lf + lr (got " + params::number(wheelbase) + ", lf + lr = " + params::number(lf + lr) + ")";
  }
};

struct ControlParams {
  static constexpr params::Choice<LateralMode> kLateralNames[] = {
      {"combined", LateralMode::Combined}, {"stanley", LateralMode::Stanley}, {"pure_pursuit", LateralMode::PurePursuit}};
  LateralMode lateral = LateralMode::Combined;
  // Stanley: k 2.5 1/s, k_soft 1 m/s (the pair of the ORACLES figures);
  // at 15 m/s a 0.5 m error asks 0.08 rad, gentle enough for a 190 kg car
  StanleyParams stanley;
  // pure pursuit: L_d = 2.5 m + 0.15 s * v -> 3.7 m at 8 m/s, 4.75 m at 15 m/s,
  // 5.5 m at 20 m/s: long enough not to weave at speed, short enough to cut a
  // 10 m radius corner by only a few cm once the car is on it
  PurePursuitParams pure_pursuit;
  // combined: 0.2 pure pursuit on straights (Stanley tracks them tightly and
  // recovers fast), rising by 0.6 per 0.1 1/m of look-ahead curvature to 0.8
  // in corners of radius 10 m and below (pure pursuit turns in early and does
  // not overshoot the apex)
  CombinedParams combined;
  // delta -= k_d_yaw (r_meas - r_traj). At 15 m/s the kinematic yaw-rate
  // gain is v / L = 9.8 1/s, so 0.05 s closes a damping loop of ~0.5: damps
  // the yaw transient without fighting the steering
  double k_d_yaw = 0.05;
  // the same damping by torque vectoring (a car with a motor per driven
  // wheel): yaw moment M = -k_tv_yaw (r_meas - r_traj). 0 (off) by default:
  // the paper's car damps with the steering; 300 N m s asks 60 N m (a 100 N
  // left/right force difference on a 1.2 m track) for a 0.2 rad/s error
  double k_tv_yaw = 0.0;
  LongitudinalParams longitudinal;
  // the projection searches +-projection_window of arc length around the last
  // cycle's s (advanced by v dt), so a track that passes near itself cannot
  // make it jump; a full search runs on the first call, after reset(), when
  // the trajectory changes, and when the windowed result lies farther than
  // relocalize_distance from the car
  double projection_window = 3.0;
  double relocalize_distance = 3.0;

  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(lateral), kLateralNames, "lateral control law");
    v.section(PADDOCK_PARAM(stanley), "the Stanley law");
    v.section(PADDOCK_PARAM(pure_pursuit), "the pure pursuit law");
    v.section(PADDOCK_PARAM(combined), "the curvature-weighted combination of pure pursuit and Stanley");
    v(PADDOCK_PARAM(k_d_yaw), {"s", params::in(0.0, 10.0), "yaw-rate damping gain"});
    v(PADDOCK_PARAM(k_tv_yaw), {"N m s", params::in(0.0, 1e4), "yaw-rate damping by torque vectoring (0: off)"});
    v.section(PADDOCK_PARAM(longitudinal), "the speed loop");
    v(PADDOCK_PARAM(projection_window), {"m", params::in(0.1, 100.0), "arc-length window of the path projection"});
    v(PADDOCK_PARAM(relocalize_distance), {"m", params::above(0.0),
                                           "a windowed projection farther than this from the car runs a full search"});
  }
};

enum class Status { Ok, NoTrajectory, BadState };

const char* to_string(Status s);

struct ControlInput {
  double dt = 0.0;        // time since the last cycle (s); 0 on the first one
  Pose2 base_pose;        // rear axle centre and yaw in the map frame
  double vx = 0.0;        // longitudinal speed of the base (m/s)
  double vy = 0.0;        // lateral speed of the base (m/s)
  double yaw_rate = 0.0;  // measured yaw rate (rad/s, > 0 counter-clockwise)
  const Trajectory* trajectory = nullptr;  // the reference; not owned, must outlive the call
  // cap on the reference speed (m/s); the mission brakes to a stop with it
  double max_speed = std::numeric_limits<double>::infinity();
};

struct Diagnostics {
  double s = 0.0;              // arc length of the base (rear axle) projection (m)
  double lateral_error = 0.0;  // signed offset of the FRONT axle centre from the path, > 0 left (m)
  double heading_error = 0.0;  // psi_e = wrap(path heading at the front axle - yaw) (rad)
  double v_ref = 0.0;          // reference speed after preview and cap (m/s)
  double a_ref = 0.0;          // reference acceleration fed forward (m/s^2)
  double k_pp = 0.0;           // pure pursuit weight used this cycle (-)
  double delta_st = 0.0;       // Stanley steering, theta_ss included (rad)
  double delta_pp = 0.0;       // pure pursuit steering (rad)
  double theta_ss = 0.0;       // steady-state yaw term (rad)
  double lookahead_distance = 0.0;  // distance used in the pure pursuit law (m)
};

struct ControlOutput {
  double steering_angle = 0.0;  // front wheel angle (rad, > 0 left), within the limit
  double throttle = 0.0;        // [0, 1]
  double brake = 1.0;           // [0, 1]
  double yaw_moment = 0.0;      // torque vectoring request (N m, > 0 counter-clockwise)
  Status status = Status::Ok;
  const char* reason = "";      // what went wrong when status != Ok (a static string)
  Diagnostics diagnostics;
};

class Controller {
 public:
  explicit Controller(const ControlParams& params = ControlParams{},
                      const VehicleKnowledge& vehicle = VehicleKnowledge{});

  // one control cycle; never throws. Bad input gives a status and the safe
  // output (wheels straight, full brake) and resets the state.
  ControlOutput update(const ControlInput& in);
  // forget the integrator and the projection hint (the next call searches everything)
  void reset();

  const ControlParams& params() const { return params_; }
  const VehicleKnowledge& vehicle() const { return vehicle_; }
  const ControlOutput& last_output() const { return last_; }

 private:
  ControlOutput fault(Status status, const char* reason);
  bool same_trajectory(const Trajectory& t) const;

  ControlParams params_;
  VehicleKnowledge vehicle_;
  SpeedModel speed_model_;

  // state
  SpeedController speed_;
  bool have_hint_ = false;
  double s_hint_ = 0.0;               // last cycle's base projection (m)
  double last_cap_ = 0.0;             // last cycle's speed cap, for the slope of a falling one (m/s)
  bool last_cap_finite_ = false;
  // a fingerprint of the last trajectory, to notice a new one
  const Trajectory* traj_ptr_ = nullptr;
  std::size_t traj_size_ = 0;
  double traj_length_ = 0.0;
  Vec2 traj_first_;
  ControlOutput last_;
};

}  // namespace paddock::control
