#pragma once
// the vehicle model: a dynamic single-track (bicycle) model of the chassis on
// four rotating wheels. Each wheel has its own spin, longitudinal slip and
// slip angle, carried as tyre deflections with relaxation lengths (so the model
// holds from standstill to top speed without a kinematic blend), and a
// combined-slip Pacejka tyre with load sensitivity. An electric powertrain per
// the FS rules (motor torque and power envelope, gear, efficiency, the
// accumulator's power limit, optional regeneration, a torque split and torque
// vectoring, traction control in the car's VCU) drives the wheels; brakes and
// rolling resistance act on them as friction torques that stick at rest. Aero
// load, lagged longitudinal load transfer, and lagged, rate-limited actuators
// with an optional steering dead time complete it.
//
// MuJoCo style: a constant model (VehicleParams, compiled once into a Car) +
// mutable state (VehicleState) + a free function step(). Many vehicles can be
// simulated side by side; step() never allocates, and nothing here reads
// files or keeps global mutable state.
#include <array>
#include <cstddef>
#include <limits>
#include <memory>

#include "autonomy/common/geometry.h"
#include "autonomy/common/params.h"

namespace paddock::vehicle {

inline constexpr double kUnset = std::numeric_limits<double>::quiet_NaN();

// the longest steering dead time the state's delay line can hold, in steps
inline constexpr std::size_t kMaxDelaySteps = 255;
// the longest steering dead time VehicleParams accepts, s (kMaxDelaySteps at 1 kHz, with margin)
inline constexpr double kMaxSteeringDeadTime = 0.25;

// every physical parameter of the car. No defaults in code: each field starts as
// NaN and gets its value from a car file (scenarios/vehicles/*.ini, keys = field
// names); params::validate() rejects a field left unset (NaN is outside every bound).
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
  // rotating parts
  double wheel_inertia = kUnset;
  double driveline_inertia = kUnset;
  // tyre: Pacejka magic formula on the combined slip (see tyre_force)
  double tyre_b = kUnset;
  double tyre_c = kUnset;
  double tyre_d = kUnset;
  double tyre_e = kUnset;
  double tyre_bx = kUnset;
  double tyre_dx = kUnset;
  double tyre_load_nominal = kUnset;
  double tyre_load_sensitivity = kUnset;
  double relaxation_length_x = kUnset;
  double relaxation_length_y = kUnset;
  // aero
  double c_down = kUnset;
  double aero_balance_front = kUnset;
  double c_drag = kUnset;
  // electric powertrain
  double motor_torque_max = kUnset;
  double motor_power_max = kUnset;
  double motor_speed_max = kUnset;
  double gear_ratio = kUnset;
  double drivetrain_efficiency = kUnset;
  double accumulator_power_max = kUnset;
  double regen_torque_max = kUnset;
  double drive_split_front = kUnset;
  double traction_control_slip = kUnset;
  // brakes and rolling resistance
  double brake_force_max = kUnset;
  double brake_split_front = kUnset;
  double cr0 = kUnset;
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
    v(PADDOCK_PARAM(wheel_inertia), {"kg m^2", params::in(0.02, 5.0), "spin inertia of one wheel (tyre, rim, hub, brake disc)"});
    v(PADDOCK_PARAM(driveline_inertia), {"kg m^2", params::in(0.0, 5.0), "motor rotor and gears of one driven wheel, reflected to the wheel (J_rotor gear_ratio^2)"});
    v(PADDOCK_PARAM(tyre_b), {"1/rad", params::in(2.0, 50.0), "Pacejka stiffness factor B, lateral (of the slip angle)"});
    // C >= 2 would make the force change sign at large slip
    v(PADDOCK_PARAM(tyre_c), {"", params::Bounds{0.0, 2.0, true, true}, "Pacejka shape factor C (lateral and longitudinal)"});
    // slicks on dry asphalt reach 1.5-1.8; no tyre reaches 3
    v(PADDOCK_PARAM(tyre_d), {"", params::above_up_to(0.0, 3.0), "Pacejka peak friction D, lateral, at the nominal load"});
    // E <= 1 keeps B a - E (B a - atan(B a)) increasing in a
    v(PADDOCK_PARAM(tyre_e), {"", params::in(-5.0, 1.0), "Pacejka curvature factor E (lateral and longitudinal)"});
    v(PADDOCK_PARAM(tyre_bx), {"", params::in(2.0, 50.0), "Pacejka stiffness factor B, longitudinal (of the slip ratio)"});
    v(PADDOCK_PARAM(tyre_dx), {"", params::above_up_to(0.0, 3.0), "Pacejka peak friction D, longitudinal, at the nominal load"});
    v(PADDOCK_PARAM(tyre_load_nominal), {"N", params::in(50.0, 20000.0), "wheel load at which the peak frictions are tyre_d and tyre_dx"});
    v(PADDOCK_PARAM(tyre_load_sensitivity), {"", params::in(-0.5, 0.0), "relative change of the peak friction per nominal load: D (1 + s (Fz / Fz0 - 1))"});
    v(PADDOCK_PARAM(relaxation_length_x), {"m", params::in(0.02, 1.0), "longitudinal relaxation length of the tyre"});
    v(PADDOCK_PARAM(relaxation_length_y), {"m", params::in(0.02, 1.0), "lateral relaxation length of the tyre"});
    v(PADDOCK_PARAM(c_down), {"N s^2/m^2", params::in(0.0, 20.0), "downforce F = c_down vx^2"});
    v(PADDOCK_PARAM(aero_balance_front), {"", params::fraction(), "share of the downforce on the front axle"});
    v(PADDOCK_PARAM(c_drag), {"N s^2/m^2", params::in(0.0, 20.0), "drag F = c_drag vx^2"});
    v(PADDOCK_PARAM(motor_torque_max), {"N m", params::above_up_to(0.0, 2000.0), "peak torque of all motors together, at the motor shafts"});
    v(PADDOCK_PARAM(motor_power_max), {"W", params::above_up_to(0.0, 1e6), "peak mechanical power of all motors together (constant power above the base speed)"});
    v(PADDOCK_PARAM(motor_speed_max), {"rad/s", params::above_up_to(0.0, 5000.0), "largest motor speed (the torque fades to 0 over its last 5 %)"});
    v(PADDOCK_PARAM(gear_ratio), {"", params::in(1.0, 30.0), "motor speed / wheel speed"});
    v(PADDOCK_PARAM(drivetrain_efficiency), {"", params::above_up_to(0.5, 1.0), "accumulator to wheels (inverter, motor, gears): P_wheels = eta P_accumulator"});
    v(PADDOCK_PARAM(accumulator_power_max), {"W", params::above_up_to(0.0, 1e6), "largest power drawn from the accumulator (FS rules: 80 kW)"});
    v(PADDOCK_PARAM(regen_torque_max), {"N m", params::in(0.0, 2000.0), "motor torque available for regenerative braking, at the motor shafts (0: no regeneration)"});
    v(PADDOCK_PARAM(drive_split_front), {"", params::fraction(), "share of the drive torque on the front axle (0: rear-wheel drive)"});
    v(PADDOCK_PARAM(traction_control_slip), {"", params::in(0.0, 1.0), "slip ratio above which the VCU cuts a wheel's drive torque (0: no traction control)"});
    v(PADDOCK_PARAM(brake_force_max), {"N", params::in(0.0, 30000.0), "total brake torque at full brake, over the wheel radius"});
    v(PADDOCK_PARAM(brake_split_front), {"", params::fraction(), "share of the brake torque on the front axle (brake balance)"});
    v(PADDOCK_PARAM(cr0), {"N", params::in(0.0, 2000.0), "rolling resistance (a friction torque cr0 r / 4 on each wheel)"});
    v(PADDOCK_PARAM(pitch_time_constant), {"s", params::above_up_to(0.0, 5.0), "lag of the longitudinal load transfer behind the acceleration (pitch dynamics)"});
    // below pi/2 so that tan(steering) stays finite
    v(PADDOCK_PARAM(steering_max), {"rad", params::above_up_to(0.0, 1.5), "road-wheel angle limit (symmetric)"});
    v(PADDOCK_PARAM(steering_rate_max), {"rad/s", params::above_up_to(0.0, 20.0), "road-wheel angle rate limit"});
    v(PADDOCK_PARAM(steering_time_constant), {"s", params::in(0.0, 5.0), "first-order lag of the steering actuator (< dt/2: instantaneous)"});
    v(PADDOCK_PARAM(steering_dead_time), {"s", params::in(0.0, kMaxSteeringDeadTime), "pure delay on the steering command (rounded to whole steps)"});
    v(PADDOCK_PARAM(throttle_time_constant), {"s", params::in(0.0, 5.0), "first-order lag of the motor torque (< dt/2: instantaneous)"});
    v(PADDOCK_PARAM(brake_time_constant), {"s", params::in(0.0, 5.0), "first-order lag of the brake torque (< dt/2: instantaneous)"});
    v(PADDOCK_PARAM(front_overhang), {"m", params::in(0.0, 3.0), "front axle to the front of the car (nose, front wing)"});
    v(PADDOCK_PARAM(rear_overhang), {"m", params::in(0.0, 3.0), "rear axle to the back of the car"});
    v(PADDOCK_PARAM(body_width), {"m", params::above_up_to(0.0, 3.0), "overall width (tyres included)"});
  }
};

// what the driver (the autonomy stack) asks for. Out-of-range values are limited;
// non-finite ones are replaced by safe values (steering: hold, throttle 0, brake 1).
struct DriverInput {
  double steering_angle = 0.0;  // rad, road-wheel angle request, > 0 turns left
  double throttle = 0.0;        // [0, 1], fraction of the motor torque limit (the power limit still applies)
  double brake = 0.0;           // [0, 1], fraction of the maximum brake torque
  double yaw_moment = 0.0;      // N m, torque vectoring: a left/right drive torque difference (> 0 counter-clockwise)
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
  // the wheels FL, FR, RL, RR: spin, and the tyre's deflections that carry the
  // slip (longitudinal slip ratio u_x / relaxation_length_x, slip angle
  // atan(u_y / relaxation_length_y))
  std::array<double, 4> omega{};  // rad/s, > 0 rolling forward
  std::array<double, 4> u_x{};    // m
  std::array<double, 4> u_y{};    // m, > 0 when the contact point moves left relative to the wheel
  // energy drawn from the accumulator since the start (regeneration counts negative), J
  double energy = 0.0;
  // electrical power over the last step (RK4-weighted mean), W
  double power = 0.0;
  // the VCU's brake plausibility check (FS rules EV 2.3) has cut the motor
  // torque: braking with more than 25 % throttle; cleared below 5 % throttle
  bool torque_cut = false;
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

// what a car's parameters imply for every step (vehicle.cc)
struct CarConstants;
// its tyre curve as tables (tyre_tables.h)
struct TyreTables;

// a car ready to be stepped: its parameters and what step() derives from them
// once (as MuJoCo compiles its mjModel). A value: copies share the constant part
class Car {
 public:
  explicit Car(const VehicleParams& p);
  const VehicleParams& params() const { return p_; }
  const CarConstants& constants() const { return *constants_; }
  // the tyre curve's tables, or null where they miss the curve (it is then
  // computed as written)
  const TyreTables* tyres() const { return tyres_.get(); }

 private:
  VehicleParams p_;
  std::shared_ptr<const CarConstants> constants_;
  std::shared_ptr<const TyreTables> tyres_;
};

// one fixed step of length dt (s): RK4 over the whole state (rigid body and actuators)
void step(const Car& car, VehicleState& s, const DriverInput& in, double dt);
// the same step as built for baseline x86-64 (step() takes the AVX2 build
// where the CPU has AVX2): the tests hold the two to the same bits
void step_baseline(const Car& car, VehicleState& s, const DriverInput& in, double dt);

// the peak-friction factor of a wheel load fz (N): 1 + s (fz / Fz0 - 1), at least 0
double load_factor(const VehicleParams& p, double fz);

// the tyre's force (N, wheel frame: fx forward, fy left) at slip ratio kappa,
// slip angle alpha (rad, > 0 when the contact point slides left) and load fz (N).
// Pacejka's curve g(X) = sin(C atan(X - E (X - atan X))) on the combined
// normalised slip X = |(B_x kappa, B alpha)|, shared out along its direction:
//   fx = D_x L(fz) fz g(X) B_x kappa / X,   fy = -D L(fz) fz g(X) B alpha / X
// (a friction ellipse on slip: each pure slip gives its own magic formula, the
// forces saturate together on the ellipse of radii D_x, D)
struct TyreForce {
  double fx = 0.0;
  double fy = 0.0;
};
TyreForce tyre_force(const VehicleParams& p, double kappa, double alpha, double fz);
// the same as step() computes it: the curve from the car's tables (within
// 1e-13 of the above, relative)
TyreForce tyre_force(const Car& car, double kappa, double alpha, double fz);
// the pure lateral force: tyre_force(p, 0, alpha, fz).fy
double tyre_lateral_force(const VehicleParams& p, double alpha, double fz);

// the power the motors may deliver to the wheels (W): their own limit, and
// the accumulator's times the drivetrain efficiency
double drive_power_limit(const VehicleParams& p);
// the wheel torque (N m, all driven wheels together) the motors deliver at
// full throttle when each driven wheel turns at wheel_speed (rad/s): the motor
// torque limit times the gear ratio, the motor power and the accumulator power
// (times the drivetrain efficiency) over the wheel speed above the base speed,
// fading to 0 over the last 5 % of the motor speed
double drive_torque_limit(const VehicleParams& p, double wheel_speed);
// the car's mass plus its wheels' and motors' rotating inertia seen at the
// road, m + sum I_wheel / r^2 (kg): what a drive or brake force accelerates
double equivalent_mass(const VehicleParams& p);
// the car's top speed on a flat road, m/s: where the drive force at full
// throttle meets drag and rolling resistance, or the motor speed limit
double top_speed(const VehicleParams& p);

// the longest physics step (s) the explicit RK4 integration stays stable at
// for this car: 2.5 / lambda, lambda the fastest of the model's modes (see
// vehicle.cc): the wheel's spin against the tyre's longitudinal stiffness,
// the relaxation of the deflections at top speed, the chassis on the tyres'
// lateral stiffness and the low-speed damping. RK4's stability interval is
// 2.785 / lambda on the real axis and 2.83 / lambda on the imaginary one;
// 2.5 keeps a margin.
double stable_step_limit(const VehicleParams& p);

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
// wheel angular speeds, rad/s (> 0 rolling forward): the wheels' spin, FL, FR, RL, RR
std::array<double, 4> wheel_speeds(const VehicleParams& p, const VehicleState& s);
// each wheel's longitudinal slip ratio (omega r - v) / max(|v|, 1 m/s), v the
// contact point's speed along the wheel: FL, FR, RL, RR
std::array<double, 4> slip_ratios(const VehicleParams& p, const VehicleState& s);

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
