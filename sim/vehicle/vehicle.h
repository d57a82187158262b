#pragma once
// the vehicle model: a dynamic single-track (bicycle) model with Pacejka lateral
// tyres, a friction ellipse per axle, aero, a low-speed blend to the kinematic
// model (as in AMZ FSSIM), and lagged, rate-limited actuators with an optional
// steering dead time.
//
// MuJoCo style: a constant model (VehicleParams) + mutable state (VehicleState)
// + a free function step(). Many vehicles can be simulated side by side; nothing
// here allocates, reads files or keeps global mutable state.
#include <array>
#include <cstddef>
#include <limits>

#include "autonomy/common/geometry.h"
#include "autonomy/common/params.h"

namespace paddock::vehicle {

inline constexpr double kUnset = std::numeric_limits<double>::quiet_NaN();

// the longest steering dead time the state's delay line can hold, in steps
inline constexpr std::size_t kMaxDelaySteps = 255;
// the longest steering dead time VehicleParams accepts, s (kMaxDelaySteps at 1 kHz, with margin)
inline constexpr double kMaxSteeringDeadTime = 0.25;

// every physical parameter of the car. No defaults in code: each field starts as
// NaN and gets its value from scenarios/vehicles/default.ini (keys = field names);
// params::validate() rejects a field left unset (NaN is outside every bound).
struct VehicleParams {
  // mass and geometry
  double mass = kUnset;
  double inertia_z = kUnset;
  double lf = kUnset;
  double lr = kUnset;
  double h_cg = kUnset;
  double track_front = kUnset;
  double track_rear = kUnset;
  double wheel_radius = kUnset;
  // tyre: Pacejka magic formula, lateral, mu_y(a) = D sin(C atan(B a - E (B a - atan(B a))))
  double tyre_b = kUnset;
  double tyre_c = kUnset;
  double tyre_d = kUnset;
  double tyre_e = kUnset;
  // aero
  double c_down = kUnset;
  double aero_balance_front = kUnset;
  double c_drag = kUnset;
  // drivetrain and brakes
  double cm1 = kUnset;
  double cr0 = kUnset;
  double drive_split_front = kUnset;
  double brake_force_max = kUnset;
  double brake_split_front = kUnset;
  // load transfer
  double pitch_time_constant = kUnset;
  // actuators
  double steering_max = kUnset;
  double steering_rate_max = kUnset;
  double steering_time_constant = kUnset;
  double steering_dead_time = kUnset;
  double throttle_time_constant = kUnset;
  double brake_time_constant = kUnset;
  // footprint for collisions (a rectangle in the base frame)
  double front_overhang = kUnset;
  double rear_overhang = kUnset;
  double body_width = kUnset;

  template <class V>
  void visit(V& v) {
    // the ranges keep the model physical for the cars paddock is for (FS cars
    // weigh 150-300 kg and corner at 1.5-2.5 g): wide enough for karts and
    // small road cars, narrow enough that no value drives the state to NaN
    v(PADDOCK_PARAM(mass), {"kg", params::in(50.0, 2000.0), "total mass of the car"});
    v(PADDOCK_PARAM(inertia_z), {"kg m^2", params::in(5.0, 5000.0), "yaw moment of inertia about the CG"});
    v(PADDOCK_PARAM(lf), {"m", params::in(0.2, 3.0), "CG to front axle (along x)"});
    v(PADDOCK_PARAM(lr), {"m", params::in(0.2, 3.0), "CG to rear axle (along x)"});
    v(PADDOCK_PARAM(h_cg), {"m", params::in(0.0, 1.5), "CG height above ground (longitudinal load transfer)"});
    v(PADDOCK_PARAM(track_front), {"m", params::in(0.5, 3.0), "distance between the front contact patches"});
    v(PADDOCK_PARAM(track_rear), {"m", params::in(0.5, 3.0), "distance between the rear contact patches"});
    v(PADDOCK_PARAM(wheel_radius), {"m", params::in(0.1, 0.6), "dynamic rolling radius"});
    v(PADDOCK_PARAM(tyre_b), {"1/rad", params::above_up_to(0.0, 50.0), "Pacejka stiffness factor B"});
    // C >= 2 would make the force change sign at large slip
    v(PADDOCK_PARAM(tyre_c), {"", params::Bounds{0.0, 2.0, true, true}, "Pacejka shape factor C"});
    // slicks on dry asphalt reach 1.5-1.8; no tyre reaches 3
    v(PADDOCK_PARAM(tyre_d), {"", params::above_up_to(0.0, 3.0), "Pacejka peak friction coefficient D (also the friction ellipse radius)"});
    // E <= 1 keeps B a - E (B a - atan(B a)) increasing in a
    v(PADDOCK_PARAM(tyre_e), {"", params::at_most(1.0), "Pacejka curvature factor E"});
    v(PADDOCK_PARAM(c_down), {"N s^2/m^2", params::in(0.0, 20.0), "downforce F = c_down vx^2"});
    v(PADDOCK_PARAM(aero_balance_front), {"", params::fraction(), "share of the downforce on the front axle"});
    v(PADDOCK_PARAM(c_drag), {"N s^2/m^2", params::in(0.0, 20.0), "drag F = c_drag vx^2"});
    v(PADDOCK_PARAM(cm1), {"N", params::in(0.0, 20000.0), "motor force at full throttle (all driven wheels)"});
    v(PADDOCK_PARAM(cr0), {"N", params::in(0.0, 2000.0), "rolling resistance"});
    v(PADDOCK_PARAM(drive_split_front), {"", params::fraction(), "share of the motor force on the front axle"});
    v(PADDOCK_PARAM(brake_force_max), {"N", params::in(0.0, 20000.0), "total brake force at full brake"});
    v(PADDOCK_PARAM(brake_split_front), {"", params::fraction(), "share of the brake force on the front axle (brake balance)"});
    v(PADDOCK_PARAM(pitch_time_constant), {"s", params::above_up_to(0.0, 5.0), "lag of the longitudinal load transfer behind the acceleration (pitch dynamics)"});
    // below pi/2 so that tan(steering) of the kinematic model stays finite
    v(PADDOCK_PARAM(steering_max), {"rad", params::above_up_to(0.0, 1.5), "road-wheel angle limit (symmetric)"});
    v(PADDOCK_PARAM(steering_rate_max), {"rad/s", params::above_up_to(0.0, 20.0), "road-wheel angle rate limit"});
    v(PADDOCK_PARAM(steering_time_constant), {"s", params::in(0.0, 5.0), "first-order lag of the steering actuator (< dt/2: instantaneous)"});
    v(PADDOCK_PARAM(steering_dead_time), {"s", params::in(0.0, kMaxSteeringDeadTime), "pure delay on the steering command (rounded to whole steps)"});
    v(PADDOCK_PARAM(throttle_time_constant), {"s", params::in(0.0, 5.0), "first-order lag of the motor force (< dt/2: instantaneous)"});
    v(PADDOCK_PARAM(brake_time_constant), {"s", params::in(0.0, 5.0), "first-order lag of the brake force (< dt/2: instantaneous)"});
    v(PADDOCK_PARAM(front_overhang), {"m", params::in(0.0, 3.0), "front axle to the front of the car (nose, front wing)"});
    v(PADDOCK_PARAM(rear_overhang), {"m", params::in(0.0, 3.0), "rear axle to the back of the car"});
    v(PADDOCK_PARAM(body_width), {"m", params::above_up_to(0.0, 3.0), "overall width (tyres included)"});
  }
};

// what the driver (the autonomy stack) asks for. Out-of-range values are limited;
// non-finite ones are replaced by safe values (steering: hold, throttle 0, brake 1).
struct DriverInput {
  double steering_angle = 0.0;  // rad, road-wheel angle request, > 0 turns left
  double throttle = 0.0;        // [0, 1], fraction of the maximum motor force cm1
  double brake = 0.0;           // [0, 1], fraction of the maximum brake force
};

// the mutable state. A plain value type: copy it to fork a simulation.
struct VehicleState {
  // pose of the centre of gravity in the map frame
  double x = 0.0;    // m
  double y = 0.0;    // m
  double yaw = 0.0;  // rad, wrapped to [-pi, pi)
  // velocity of the CG in the body frame, and yaw rate
  double vx = 0.0;   // m/s, forward
  double vy = 0.0;   // m/s, left
  double r = 0.0;    // rad/s, counter-clockwise
  // actual actuator states, after dead time, limits and lags
  double steering = 0.0;  // rad, road-wheel angle
  double throttle = 0.0;  // [0, 1]
  double brake = 0.0;     // [0, 1]
  // longitudinal acceleration felt by the suspension (lagged ax) for the load transfer
  double ax_load = 0.0;   // m/s^2
  // mean over the last step (RK4-weighted): acceleration of the CG in the body
  // frame (what an accelerometer at the CG measures on flat ground) and yaw acceleration
  double ax = 0.0;        // m/s^2
  double ay = 0.0;        // m/s^2
  double yaw_accel = 0.0; // rad/s^2
  // steering dead time: a ring buffer of past steering commands
  std::array<double, kMaxDelaySteps + 1> steering_delay{};  // rad
  std::size_t delay_head = 0;  // index of the slot the next command is written to
};

// every quantity of the state is a finite number (a state that is not has
// diverged: too large a step for the parameters)
bool is_finite(const VehicleState& s);

// the state at rest with the base frame (rear axle centre on the ground) at base_pose
VehicleState initial_state(const VehicleParams& p, Pose2 base_pose);

// the state driving straight ahead at `speed` (m/s, CG) with the base frame at
// base_pose: every wheel rolling at that speed, actuators at rest
VehicleState rolling_state(const VehicleParams& p, Pose2 base_pose, double speed);

// one fixed step of length dt (s): RK4 over the whole state (rigid body and actuators)
void step(const VehicleParams& p, VehicleState& s, const DriverInput& in, double dt);

// lateral tyre force (N) at slip angle alpha (rad) and normal load fz (N); opposes the slip.
// Linear in fz, so it serves one wheel or a whole axle.
double tyre_lateral_force(const VehicleParams& p, double alpha, double fz);

// weight of the dynamic model in the low-speed blend: clamp(0.5 (|v| - 1.5), 0, 1)
double dynamic_weight(double speed);

// the slip angle (rad) of a wheel rolling at `steer` (rad, body frame) whose
// contact point moves at (vx, vy) (body frame): atan2(vy, vx) - steer rolling
// forwards, the angle from the backward direction rolling backwards; always
// in (-pi/2, pi/2] when |steer| < pi/2
double slip_angle(double vx, double vy, double steer);

// the longest physics step (s) the explicit RK4 integration stays stable at
// for this car: 2.5 / lambda, lambda the faster of the linear single-track
// model's lateral and yaw modes at the speed where the dynamic model starts
// to count (1.5 m/s, dynamic_weight), where they are fastest (both grow as
// 1 / v; downforce only adds a v^2 load that the 1 / v outweighs below
// ~10 m/s). With C_f = B C D Fz_f, C_r likewise at the static axle loads:
//   lateral  lambda_y = (C_f + C_r) / (m v)
//   yaw      lambda_r = (C_f lf^2 + C_r lr^2) / (Iz v)
// RK4's stability interval on the real axis is 2.785 / lambda; 2.5 keeps a
// margin. The default car: lambda ~ 183 1/s, 13.6 ms (74 Hz).
double stable_step_limit(const VehicleParams& p);

// below this |vx| (m/s) rolling resistance and brakes fade linearly to zero, so that a
// car at rest stays exactly at rest; chosen from dt for RK4 stability (see vehicle.cc)
double standstill_speed(const VehicleParams& p, double dt);

// pose of the base frame (rear axle centre) in the map
Pose2 base_pose(const VehicleParams& p, const VehicleState& s);
// velocity of the base origin (rear axle centre), in the base (body) frame, m/s
Vec2 base_velocity(const VehicleParams& p, const VehicleState& s);
// acceleration of the CG in the body frame over the last step (x forward, y left), m/s^2
Vec2 body_acceleration(const VehicleState& s);
// speed of the CG, m/s
double speed(const VehicleState& s);

enum Wheel : std::size_t { kFrontLeft = 0, kFrontRight = 1, kRearLeft = 2, kRearRight = 3 };
// contact patches in the map frame: FL, FR, RL, RR
std::array<Vec2, 4> wheel_positions(const VehicleParams& p, const VehicleState& s);
// wheel angular speeds, rad/s (> 0 rolling forward): the contact patch velocity along the
// wheel heading over the rolling radius (no longitudinal slip model): FL, FR, RL, RR
std::array<double, 4> wheel_speeds(const VehicleParams& p, const VehicleState& s);

// the collision footprint: an axis-aligned rectangle in the base frame
struct Footprint {
  double x_min = 0.0;  // m, back (-rear_overhang)
  double x_max = 0.0;  // m, front (lf + lr + front_overhang)
  double y_min = 0.0;  // m, right (-body_width / 2)
  double y_max = 0.0;  // m, left (body_width / 2)
  // corners counter-clockwise from the back right: (x_min, y_min), (x_max, y_min), (x_max, y_max), (x_min, y_max)
  std::array<Vec2, 4> corners() const {
    return {Vec2{x_min, y_min}, Vec2{x_max, y_min}, Vec2{x_max, y_max}, Vec2{x_min, y_max}};
  }
};
Footprint footprint(const VehicleParams& p);

}  // namespace paddock::vehicle
