// tests of the vehicle model, each against something independent of the code under
// test: the FSSIM tyre oracle, closed-form solutions, single-track theory, physical
// bounds, or a second run.
#include "sim/vehicle/vehicle.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace paddock::vehicle {
namespace {

constexpr double kDt = 1e-3;  // s, the simulator's physics step

// the tests step cars by their parameters and change them between
// manoeuvres: the Car is compiled afresh whenever the parameters differ from
// those compiled last (VehicleParams is doubles only: compared bytewise)
void step(const VehicleParams& p, VehicleState& s, const DriverInput& in, double dt) {
  static VehicleParams last;
  static std::optional<Car> car;
  if (!car || std::memcmp(&last, &p, sizeof p) != 0) {
    last = p;
    car.emplace(p);
  }
  vehicle::step(*car, s, in, dt);
}

// the fields of p in the order its visit() lists them, by name
std::vector<std::pair<std::string, double*>> fields_of(VehicleParams& p) {
  struct Lister {
    std::vector<std::pair<std::string, double*>> fields;
    void operator()(const char* key, double& field, const params::Spec&) { fields.emplace_back(key, &field); }
  } lister;
  p.visit(lister);
  return lister.fields;
}

// a minimal reader of scenarios/vehicles/default.ini (the real scenario parser lives in
// sim/runner): one [vehicle] section, `key = value ; comment` lines; every key must be a
// field of VehicleParams, every field must appear exactly once
VehicleParams load_car(const std::string& car) {
  const std::string path = std::string(PADDOCK_SOURCE_DIR) + "/scenarios/vehicles/" + car + ".ini";
  std::ifstream f(path);
  EXPECT_TRUE(f.good()) << "cannot open " << path;
  VehicleParams p;
  const auto fields = fields_of(p);
  std::set<std::string> seen;
  std::string line, section;
  int lineno = 0;
  while (std::getline(f, line)) {
    ++lineno;
    const auto semi = line.find(';');
    if (semi != std::string::npos) line.resize(semi);
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos) continue;
    line = line.substr(first, line.find_last_not_of(" \t\r") - first + 1);
    if (line.front() == '[') {
      section = line;
      continue;
    }
    EXPECT_EQ(section, "[vehicle]") << path << ":" << lineno;
    const auto eq = line.find('=');
    EXPECT_NE(eq, std::string::npos) << path << ":" << lineno;
    std::string key = line.substr(0, eq);
    key.erase(key.find_last_not_of(" \t") + 1);
    const std::string value = line.substr(eq + 1);
    bool known = false;
    for (const auto& [name, field] : fields) {
      if (key == name) {
        known = true;
        std::size_t used = 0;
        *field = std::stod(value, &used);
        EXPECT_EQ(value.find_first_not_of(" \t", used), std::string::npos) << path << ":" << lineno;
      }
    }
    EXPECT_TRUE(known) << path << ":" << lineno << ": unknown key " << key;
    EXPECT_TRUE(seen.insert(key).second) << path << ":" << lineno << ": duplicate key " << key;
  }
  EXPECT_EQ(seen.size(), fields.size()) << path << " must set every field";
  return p;
}

const VehicleParams& defaults() {
  static const VehicleParams p = load_car("default");
  return p;
}

// the AMZ FSSIM car
const VehicleParams& gotthard() {
  static const VehicleParams p = load_car("gotthard");
  return p;
}

// the default car with instantaneous actuators (time constants 0)
VehicleParams instant_actuators() {
  VehicleParams p = defaults();
  p.steering_time_constant = 0.0;
  p.throttle_time_constant = 0.0;
  p.brake_time_constant = 0.0;
  return p;
}

VehicleState moving_state(const VehicleParams& p, double vx) { return rolling_state(p, Pose2{}, vx); }

// run at a constant steering angle with a speed controller (feedforward against drag
// and rolling resistance + proportional), return the final state
VehicleState steady_corner(const VehicleParams& p, double v_target, double steering, double seconds,
                           VehicleState s) {
  const int n = static_cast<int>(std::lround(seconds / kDt));
  for (int k = 0; k < n; ++k) {
    const double ff = (p.cr0 + p.c_drag * v_target * v_target) * p.wheel_radius / drive_torque_limit(p, 0.0);
    const double thr = std::clamp(ff + 0.5 * (v_target - s.vx), 0.0, 1.0);
    step(p, s, DriverInput{steering, thr, 0.0}, kDt);
  }
  return s;
}

void expect_states_equal(const VehicleState& a, const VehicleState& b) {
  EXPECT_EQ(a.x, b.x);
  EXPECT_EQ(a.y, b.y);
  EXPECT_EQ(a.yaw, b.yaw);
  EXPECT_EQ(a.vx, b.vx);
  EXPECT_EQ(a.vy, b.vy);
  EXPECT_EQ(a.r, b.r);
  EXPECT_EQ(a.steering, b.steering);
  EXPECT_EQ(a.throttle, b.throttle);
  EXPECT_EQ(a.brake, b.brake);
  EXPECT_EQ(a.ax_load, b.ax_load);
  EXPECT_EQ(a.ax, b.ax);
  EXPECT_EQ(a.ay, b.ay);
  EXPECT_EQ(a.yaw_accel, b.yaw_accel);
  EXPECT_EQ(a.omega, b.omega);
  EXPECT_EQ(a.u_x, b.u_x);
  EXPECT_EQ(a.u_y, b.u_y);
  EXPECT_EQ(a.energy, b.energy);
  EXPECT_EQ(a.power, b.power);
  EXPECT_EQ(a.torque_cut, b.torque_cut);
  EXPECT_EQ(a.steering_delay, b.steering_delay);
  EXPECT_EQ(a.delay_head, b.delay_head);
}

// ---------------------------------------------------------------------------
// parameters
// ---------------------------------------------------------------------------

TEST(VehicleParams, TheVisitListsEveryFieldOnce) {
  // every member is a double: the visit must list as many distinct fields
  VehicleParams p;
  const auto fields = fields_of(p);
  EXPECT_EQ(fields.size(), sizeof(VehicleParams) / sizeof(double));
  std::set<std::string> names;
  std::set<const double*> members;
  for (const auto& [name, field] : fields) {
    EXPECT_TRUE(names.insert(name).second) << name << " listed twice";
    EXPECT_TRUE(members.insert(field).second) << name << " is another field's member";
  }
}

TEST(VehicleParams, TheCarFilesSetEveryFieldAndValidate) {
  EXPECT_EQ(params::validate(defaults()), "");
  EXPECT_EQ(defaults().accumulator_power_max, 80000.0);  // the FS rules' limit
  const VehicleParams& p = gotthard();
  EXPECT_EQ(params::validate(p), "");
  // the ORACLES.md gotthard figures
  EXPECT_EQ(p.mass, 190.0);
  EXPECT_EQ(p.inertia_z, 110.0);
  EXPECT_EQ(p.lf + p.lr, 1.53);
  EXPECT_EQ(p.c_down, 1.9032);
  EXPECT_EQ(p.steering_dead_time, 0.0);
}

TEST(VehicleParams, ValidateNamesTheFieldAndWhatWasExpected) {
  VehicleParams p = defaults();
  p.mass = -1.0;
  EXPECT_EQ(params::validate(p), "mass must be in [50, 2000] kg (got -1)");

  p = defaults();
  p.aero_balance_front = 1.5;
  EXPECT_EQ(params::validate(p), "aero_balance_front must be in [0, 1] (got 1.5)");

  p = defaults();
  p.steering_dead_time = 2.0;
  EXPECT_EQ(params::validate(p), "steering_dead_time must be in [0, 0.25] s (got 2)");

  p = defaults();
  p.tyre_c = 2.0;  // open upper end
  EXPECT_EQ(params::validate(p), "tyre_c must be in (0, 2) (got 2)");

  // a field left unset (NaN) is named
  p = defaults();
  p.brake_force_max = kUnset;
  EXPECT_EQ(params::validate(p), "brake_force_max must be in [0, 30000] N (got nan)");

  // a default-constructed set is rejected at its first field
  EXPECT_EQ(params::validate(VehicleParams{}), "mass must be in [50, 2000] kg (got nan)");
}

// ---------------------------------------------------------------------------
// tyre
// ---------------------------------------------------------------------------

TEST(Tyre, MatchesFssimOracle) {
  // ORACLES.md: per wheel at Fz = 465.975 N (= 190 kg g / 4), gotthard's tyre
  const VehicleParams& p = gotthard();
  const double fz = 465.975;
  EXPECT_NEAR(std::abs(tyre_lateral_force(p, 0.05, fz)), 540.906, 1e-3);
  EXPECT_NEAR(std::abs(tyre_lateral_force(p, 0.10, fz)), 725.869, 1e-3);
  EXPECT_NEAR(std::abs(tyre_lateral_force(p, 0.20, fz)), 732.389, 1e-3);
  // the force opposes the slip, is odd in the slip, zero at zero slip
  EXPECT_LT(tyre_lateral_force(p, 0.05, fz), 0.0);
  EXPECT_EQ(tyre_lateral_force(p, -0.05, fz), -tyre_lateral_force(p, 0.05, fz));
  EXPECT_EQ(tyre_lateral_force(p, 0.0, fz), 0.0);
}

// the magic formula written out, for one direction
double magic(double b, double c, double d, double e, double x) {
  return d * std::sin(c * std::atan(b * x - e * (b * x - std::atan(b * x))));
}

TEST(Tyre, PureSlipIsEachMagicFormulaAndCombinedSlipStaysOnTheEllipse) {
  const VehicleParams& p = defaults();
  for (const double fz : {200.0, 500.0, 900.0}) {
    const double mu = 1.0 + p.tyre_load_sensitivity * (fz / p.tyre_load_nominal - 1.0);
    for (const double s : {-0.5, -0.1, -0.02, 0.01, 0.08, 0.3, 1.0}) {
      EXPECT_NEAR(tyre_force(p, s, 0.0, fz).fx, mu * fz * magic(p.tyre_bx, p.tyre_c, p.tyre_dx, p.tyre_e, s), 1e-9);
      EXPECT_NEAR(tyre_force(p, 0.0, s, fz).fy, -mu * fz * magic(p.tyre_b, p.tyre_c, p.tyre_d, p.tyre_e, s), 1e-9);
      EXPECT_EQ(tyre_force(p, s, 0.0, fz).fy, 0.0);
    }
    // combined: inside the friction ellipse of radii D_x mu fz, D mu fz, and
    // each force smaller than its pure-slip value
    for (const double kappa : {-0.3, -0.05, 0.02, 0.1, 0.6}) {
      for (const double alpha : {-0.4, -0.03, 0.05, 0.2}) {
        const TyreForce f = tyre_force(p, kappa, alpha, fz);
        const double ex = f.fx / (p.tyre_dx * mu * fz), ey = f.fy / (p.tyre_d * mu * fz);
        EXPECT_LE(ex * ex + ey * ey, 1.0 + 1e-12);
        EXPECT_LE(std::abs(f.fx), std::abs(tyre_force(p, kappa, 0.0, fz).fx) + 1e-9);
        EXPECT_LE(std::abs(f.fy), std::abs(tyre_force(p, 0.0, alpha, fz).fy) + 1e-9);
        EXPECT_GT(f.fx * kappa, 0.0);   // drives when the wheel is faster than the road
        EXPECT_LT(f.fy * alpha, 0.0);   // opposes the sliding
      }
    }
  }
  // load sensitivity: the peak (brute force over the slip) of twice the nominal
  // load is (1 + s) D 2 Fz0
  double peak = 0.0;
  for (int k = 1; k < 4000; ++k) peak = std::max(peak, -tyre_lateral_force(p, k * 1e-4, 2.0 * p.tyre_load_nominal));
  EXPECT_NEAR(peak, (1.0 + p.tyre_load_sensitivity) * p.tyre_d * 2.0 * p.tyre_load_nominal, 1e-3 * peak);
}

// ---------------------------------------------------------------------------
// standstill (fault 4: static friction)
// ---------------------------------------------------------------------------

TEST(Standstill, AtRestWithZeroInputStaysExactlyAtRest) {
  for (const VehicleParams* p : {&defaults(), &gotthard()}) {
    const VehicleState s0 = initial_state(*p, Pose2{3.0, -2.0, 0.7});
    VehicleState s = s0;
    for (int i = 0; i < 10000; ++i) step(*p, s, DriverInput{}, kDt);  // 10 s
    expect_states_equal(s, s0);
  }
}

TEST(Standstill, AtRestWithBrakesAndSteeringDoesNotCreep) {
  const VehicleParams& p = defaults();
  const VehicleState s0 = initial_state(p, Pose2{});
  VehicleState s = s0;
  for (int i = 0; i < 10000; ++i) step(p, s, DriverInput{0.3, 0.0, 1.0}, kDt);
  EXPECT_EQ(s.x, s0.x);
  EXPECT_EQ(s.y, s0.y);
  EXPECT_EQ(s.yaw, s0.yaw);
  EXPECT_EQ(s.vx, 0.0);
  EXPECT_EQ(s.vy, 0.0);
  EXPECT_EQ(s.r, 0.0);
  EXPECT_NEAR(s.steering, 0.3, 1e-12);
}

// the throttle whose drive force (at the torque limit) is `force` N
double throttle_for(const VehicleParams& p, double force) {
  return force * p.wheel_radius / (p.motor_torque_max * p.gear_ratio);
}

TEST(Standstill, ADriveForceBelowTheBreakawayForceMovesNothing) {
  // rolling resistance is a friction torque cr0 r / 4 per wheel: a drive force
  // below cr0 must not move the car at all (it crept 1.3 m a minute at 2 %
  // throttle), one above it must
  for (const VehicleParams* p : {&defaults(), &gotthard()}) {
    VehicleState s = initial_state(*p, Pose2{});
    const VehicleState s0 = s;
    for (int i = 0; i < 60000; ++i) step(*p, s, DriverInput{0.0, throttle_for(*p, 0.9 * p->cr0), 0.0}, kDt);
    EXPECT_EQ(s.x, s0.x);
    EXPECT_EQ(s.vx, 0.0);
    for (const double w : s.omega) EXPECT_EQ(w, 0.0);
    for (int i = 0; i < 5000; ++i) step(*p, s, DriverInput{0.0, throttle_for(*p, 1.3 * p->cr0), 0.0}, kDt);
    EXPECT_GT(s.x - s0.x, 0.01);
  }
}

TEST(Standstill, BrakesHoldTheMotor) {
  const VehicleParams& p = defaults();
  // a drive torque below the brakes' on every wheel: held, exactly
  double t_brake_min = std::min(p.brake_split_front, 1.0 - p.brake_split_front) * 0.5 * p.brake_force_max;
  const double throttle = std::min(0.24, 0.9 * t_brake_min / (0.5 * std::max(p.drive_split_front, 1.0 - p.drive_split_front) *
                                               p.motor_torque_max * p.gear_ratio / p.wheel_radius));
  VehicleState s = initial_state(p, Pose2{});
  const VehicleState s0 = s;
  for (int i = 0; i < 60000; ++i) step(p, s, DriverInput{0.0, throttle, 1.0}, kDt);
  EXPECT_EQ(s.x, s0.x);
  EXPECT_FALSE(s.torque_cut);
  // full throttle with the brake on: the brake plausibility check (FS rules
  // EV 2.3) cuts the motors (it accelerated against the brakes before), and
  // keeps them cut after the brake is released until the throttle drops
  // below 5 %
  for (const VehicleParams* car : {&defaults(), &gotthard()}) {
    s = initial_state(*car, Pose2{});
    const double x0 = s.x;
    for (int i = 0; i < 60000; ++i) step(*car, s, DriverInput{0.0, 1.0, 1.0}, kDt);
    EXPECT_EQ(s.x, x0);
    EXPECT_TRUE(s.torque_cut);
    for (int i = 0; i < 1000; ++i) step(*car, s, DriverInput{0.0, 1.0, 0.0}, kDt);
    EXPECT_EQ(s.x, x0);
    step(*car, s, DriverInput{0.0, 0.0, 0.0}, kDt);
    for (int i = 0; i < 1000; ++i) step(*car, s, DriverInput{0.0, 1.0, 0.0}, kDt);
    EXPECT_GT(s.x - x0, 1.0);
  }
}

// ---------------------------------------------------------------------------
// longitudinal
// ---------------------------------------------------------------------------

// the car's mass plus its rotating parts seen at the road: m + sum I / r^2
double effective_mass(const VehicleParams& p) {
  double m = p.mass;
  for (int i = 0; i < 4; ++i) {
    const bool driven = i < 2 ? p.drive_split_front > 0.0 : p.drive_split_front < 1.0;
    m += (p.wheel_inertia + (driven ? p.driveline_inertia : 0.0)) / (p.wheel_radius * p.wheel_radius);
  }
  return m;
}

TEST(Longitudinal, CoastDownMatchesItsClosedFormWithTheRotatingInertia) {
  // m_eff v' = -(c v^2 + Cr):  v(t) = sqrt(Cr / c) tan(atan(v0 sqrt(c / Cr)) - sqrt(c Cr) t / m_eff)
  for (const VehicleParams* p : {&defaults(), &gotthard()}) {
    const double m_eff = effective_mass(*p);
    const double c = p->c_drag, cr = p->cr0, v0 = 25.0;
    auto closed = [&](double t) {
      return std::sqrt(cr / c) * std::tan(std::atan(v0 * std::sqrt(c / cr)) - std::sqrt(c * cr) * t / m_eff);
    };
    // without the rotating inertia the car would be this much slower at 10 s
    ASSERT_GT(closed(10.0) - std::sqrt(cr / c) * std::tan(std::atan(v0 * std::sqrt(c / cr)) - std::sqrt(c * cr) * 10.0 / p->mass), 0.05 * closed(10.0) * (m_eff - p->mass) / m_eff);
    VehicleState s = rolling_state(*p, Pose2{}, v0);
    int k = 0;
    for (const double t_check : {1.0, 3.0, 6.0, 10.0}) {
      for (; k < static_cast<int>(std::lround(t_check / kDt)); ++k) step(*p, s, DriverInput{}, kDt);
      ASSERT_GT(closed(t_check), 1.0);
      EXPECT_NEAR(s.vx, closed(t_check), 0.01 * closed(t_check)) << "t = " << t_check;
    }
  }
}

TEST(Longitudinal, APowerLimitedLaunchMatchesTheOde) {
  // grip to spare (D = 3, a stiff tyre: the slip stays below 1 %, no load
  // transfer to unload the front), instant actuators: the car follows m_eff v' = min(T g, P r / v) / r - c v^2 - Cr
  // with T the motor torque limit, g the gear ratio, P the smaller of the
  // motor power and eta x the accumulator's; the ODE integrated here with
  // RK4 at 0.1 ms, the comparison below the motor speed fade
  for (VehicleParams p : {instant_actuators(), gotthard()}) {
    p.throttle_time_constant = 0.0;
    p.tyre_d = p.tyre_dx = 3.0;
    p.tyre_bx = 50.0;
    p.tyre_load_sensitivity = 0.0;
    p.h_cg = 0.0;
    const double m_eff = effective_mass(p);
    const double power = std::min(p.motor_power_max, p.drivetrain_efficiency * p.accumulator_power_max);
    auto accel = [&](double v) {
      const double force = std::min(p.motor_torque_max * p.gear_ratio, v > 0.0 ? power * p.wheel_radius / v : 1e300) / p.wheel_radius;
      return (force - p.c_drag * v * v - p.cr0) / m_eff;
    };
    const double v_fade = 0.95 * p.motor_speed_max / p.gear_ratio * p.wheel_radius;
    double v_ode = 0.0, t_ode = 0.0;
    VehicleState s = initial_state(p, Pose2{});
    int k = 0, checks = 0;
    for (const double t_check : {0.25, 0.5, 1.0, 1.5, 2.0, 3.0, 5.0, 8.0}) {
      for (; k < static_cast<int>(std::lround(t_check / kDt)); ++k) step(p, s, DriverInput{0.0, 1.0, 0.0}, kDt);
      for (const double h = 1e-4; t_ode < t_check - 0.5 * h; t_ode += h) {
        const double a1 = accel(v_ode), a2 = accel(v_ode + 0.5 * h * a1), a3 = accel(v_ode + 0.5 * h * a2), a4 = accel(v_ode + h * a3);
        v_ode += h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4);
      }
      if (v_ode > v_fade) break;
      EXPECT_NEAR(s.vx, v_ode, 0.01 * v_ode) << "t = " << t_check;
      ++checks;
    }
    EXPECT_GE(checks, 4);
    EXPECT_GT(v_ode * accel(v_ode) * m_eff, 0.0);
  }
}

TEST(Longitudinal, TheDefaultCarIsAnFsCar) {
  // issue 17's acceptance: 75 m from rest in 3.3-4.5 s; top speed set by the
  // motor or the power (not the old 299 km/h); braking from 100 km/h at 1.5-2 g
  const VehicleParams& p = defaults();
  VehicleState s = initial_state(p, Pose2{});
  double t = 0.0;
  while (s.x - p.lr < 75.0 && t < 10.0) {
    step(p, s, DriverInput{0.0, 1.0, 0.0}, kDt);
    t += kDt;
  }
  EXPECT_GE(t, 3.3);
  EXPECT_LE(t, 4.5);
  for (int k = 0; k < 60000; ++k) step(p, s, DriverInput{0.0, 1.0, 0.0}, kDt);
  const double v_motor = p.motor_speed_max / p.gear_ratio * p.wheel_radius;
  const double power = std::min(p.motor_power_max, p.drivetrain_efficiency * p.accumulator_power_max);
  EXPECT_LE(s.vx, v_motor);
  EXPECT_LE(s.vx * (p.c_drag * s.vx * s.vx + p.cr0), power * 1.001);
  EXPECT_NEAR(s.vx, top_speed(p), 0.01 * top_speed(p));
  const double v0 = 100.0 / 3.6;
  double best = 1e9;
  for (double pedal = 0.3; pedal <= 1.0 + 1e-9; pedal += 0.05) {
    s = rolling_state(p, Pose2{}, v0);
    for (int k = 0; k < 10000 && s.vx > 0.0; ++k) step(p, s, DriverInput{0.0, 0.0, pedal}, kDt);
    best = std::min(best, s.x - p.lr);
  }
  const double g_braking = v0 * v0 / (2.0 * best) / kGravity;
  EXPECT_GE(g_braking, 1.5);
  EXPECT_LE(g_braking, 2.0);
  std::printf("default car: 75 m in %.3f s, top speed %.1f km/h, braking from 100 km/h in %.2f m (%.2f g)\n", t,
              top_speed(p) * 3.6, best, g_braking);
}

TEST(Longitudinal, WheelsSpinOnLowGripAndLockUnderFullBrakingWithoutAbs) {
  // mu 0.6, full throttle from rest, no traction control: the wheel speeds
  // show more than 10 % slip
  VehicleParams p = defaults();
  p.tyre_d = p.tyre_dx = 0.6;
  p.traction_control_slip = 0.0;
  VehicleState s = initial_state(p, Pose2{});
  for (int k = 0; k < 2000; ++k) step(p, s, DriverInput{0.0, 1.0, 0.0}, kDt);
  for (const int i : {kRearLeft, kFrontLeft}) {
    const double v_wheel = s.omega[i] * p.wheel_radius;
    EXPECT_GT((v_wheel - s.vx) / s.vx, 0.1) << "wheel " << i;
  }
  // with traction control the slip settles near its threshold
  p.traction_control_slip = 0.1;
  s = initial_state(p, Pose2{});
  for (int k = 0; k < 3000; ++k) step(p, s, DriverInput{0.0, 1.0, 0.0}, kDt);
  for (const double kappa : slip_ratios(p, s)) EXPECT_LT(kappa, 0.3);
  // full brake from 20 m/s on the default car: the front wheels lock while it still moves
  const VehicleParams& d = defaults();
  s = rolling_state(d, Pose2{}, 20.0);
  bool locked = false;
  while (s.vx > 5.0) {
    step(d, s, DriverInput{0.0, 0.0, 1.0}, kDt);
    locked = locked || (s.omega[kFrontLeft] == 0.0 && s.omega[kFrontRight] == 0.0);
  }
  EXPECT_TRUE(locked);
}

TEST(Longitudinal, BrakingStopsAndTheCarStaysAtRest) {
  for (const VehicleParams* p : {&defaults(), &gotthard()}) {
    VehicleState s = rolling_state(*p, Pose2{}, 15.0);
    const double v0 = 15.0;
    int stop_step = -1;
    for (int k = 0; k < 10000 && stop_step < 0; ++k) {
      step(*p, s, DriverInput{0.0, 0.0, 1.0}, kDt);
      // the deceleration never beats the friction limit plus drag and rolling resistance
      if (s.vx < 1e-3) stop_step = k;
    }
    ASSERT_GE(stop_step, 0) << "did not stop";
    const double a_bound = std::max(p->tyre_d, p->tyre_dx) * (kGravity + p->c_down * v0 * v0 / p->mass) +
                           (p->c_drag * v0 * v0 + p->cr0) / p->mass;
    EXPECT_GT(stop_step * kDt, v0 / a_bound);
    EXPECT_LT(stop_step * kDt, 2.0);
    // then at rest: the tyres' deflection settles in a few cm, nothing creeps
    const VehicleState stopped = s;
    for (int k = 0; k < 5000; ++k) step(*p, s, DriverInput{0.0, 0.0, 1.0}, kDt);
    EXPECT_LT(std::abs(s.x - stopped.x), 0.05);
    const VehicleState settled = s;
    for (int k = 0; k < 5000; ++k) step(*p, s, DriverInput{0.0, 0.0, 1.0}, kDt);
    EXPECT_LT(std::abs(s.x - settled.x), 1e-6);
    EXPECT_LT(std::abs(s.vx), 1e-6);
  }
}

TEST(Longitudinal, TheAccumulatorEnergyCoversTheWorkAndRegenerationReturnsSome) {
  // a launch to 20 m/s at 30 % throttle without drag or rolling resistance:
  // eta x the energy drawn is the kinetic energy gained (car and rotating
  // parts) plus the tyres' slip losses, a few %
  VehicleParams p = defaults();
  p.c_drag = 0.0;
  p.cr0 = 0.0;
  VehicleState s = initial_state(p, Pose2{});
  while (s.vx < 20.0) step(p, s, DriverInput{0.0, 0.3, 0.0}, kDt);
  double kinetic = 0.5 * p.mass * s.vx * s.vx;
  for (int i = 0; i < 4; ++i) kinetic += 0.5 * (p.wheel_inertia + p.driveline_inertia) * s.omega[i] * s.omega[i];
  const double work = p.drivetrain_efficiency * s.energy;
  EXPECT_GE(work, kinetic);
  EXPECT_LE(work, 1.05 * kinetic);
  // braking back: regeneration returns energy, at most eta x the kinetic energy
  const double e_before = s.energy;
  while (s.vx > 0.5) step(p, s, DriverInput{0.0, 0.0, 0.4}, kDt);
  EXPECT_LT(s.energy, e_before - 0.2 * kinetic);
  EXPECT_GT(s.energy, e_before - p.drivetrain_efficiency * kinetic);
  // without regeneration nothing comes back
  p.regen_torque_max = 0.0;
  s = rolling_state(p, Pose2{}, 20.0);
  while (s.vx > 0.5) step(p, s, DriverInput{0.0, 0.0, 0.4}, kDt);
  EXPECT_EQ(s.energy, 0.0);
}

// ---------------------------------------------------------------------------
// energy (fault 2), bounded accelerations (fault 3), spinning (fault 1)
// ---------------------------------------------------------------------------

// kinetic energy of the car and its rotating parts, J
double kinetic_energy(const VehicleParams& p, const VehicleState& s) {
  double e = 0.5 * p.mass * (s.vx * s.vx + s.vy * s.vy) + 0.5 * p.inertia_z * s.r * s.r;
  for (int i = 0; i < 4; ++i) {
    const bool driven = i < 2 ? p.drive_split_front > 0.0 : p.drive_split_front < 1.0;
    e += 0.5 * (p.wheel_inertia + (driven ? p.driveline_inertia : 0.0)) * s.omega[i] * s.omega[i];
  }
  return e;
}

TEST(Energy, KineticEnergyNeverGrowsWithoutDriveInAnyRegime) {
  // no drive, drag or rolling resistance; the tyres start undeflected, so the
  // kinetic energy is bounded by its start (the deflections' energy is >= 0):
  // at 2 m/s on full lock (it grew by 168 % in the old blend), steering to and
  // fro at walking pace (+16 %), a slalom at 15 m/s, a slide into the low
  // speeds (the old blend's band)
  for (const VehicleParams* car : {&defaults(), &gotthard()}) {
    VehicleParams p = *car;
    p.c_drag = 0.0;
    p.cr0 = 0.0;
    struct Case {
      double v0, vy0, r0;
      double (*steer)(double t);
    };
    const Case cases[] = {
        {2.0, 0.0, 0.0, [](double) { return 0.52; }},
        {1.0, 0.0, 0.0, [](double t) { return 0.5 * std::sin(3.0 * t); }},
        {15.0, 0.0, 0.0, [](double t) { return 0.15 * std::sin(kPi * t); }},
        {4.0, 2.5, 1.5, [](double) { return -0.3; }},
    };
    for (const Case& c : cases) {
      VehicleState s = rolling_state(p, Pose2{}, c.v0);
      s.vy = c.vy0;
      s.r = c.r0;
      const double e0 = kinetic_energy(p, s);
      double e_max = e0;
      for (int k = 0; k < 10000; ++k) {
        step(p, s, DriverInput{c.steer(k * kDt), 0.0, 0.0}, kDt);
        e_max = std::max(e_max, kinetic_energy(p, s));
      }
      EXPECT_LE(e_max, e0 * (1.0 + 1e-9)) << "v0 " << c.v0;
      EXPECT_LT(kinetic_energy(p, s), e0);
    }
  }
}

TEST(Energy, AccelerationsStayBoundedFromASlideToRest) {
  // a car sliding sideways into the low speeds: its acceleration never beats
  // what the tyres can carry (it was pulled to the kinematic values in 10 ms:
  // 16 g), here D g (1 + downforce) with 10 % for the load transfer
  for (const VehicleParams* p : {&defaults(), &gotthard()}) {
    VehicleState s = rolling_state(*p, Pose2{}, 6.0);
    s.vy = 3.0;
    s.r = -1.0;
    const double bound = 1.1 * std::max(p->tyre_d, p->tyre_dx) * (kGravity + p->c_down * 36.0 / p->mass);
    double worst = 0.0;
    for (int k = 0; k < 8000; ++k) {
      step(*p, s, DriverInput{0.2, 0.0, k < 4000 ? 0.0 : 0.5}, kDt);
      worst = std::max(worst, std::hypot(s.ax, s.ay));
    }
    EXPECT_LE(worst, bound);
    EXPECT_LT(speed(s), 0.05);
  }
}

TEST(Lateral, ASpunCarComesToRest) {
  // straight at 20 m/s, full lock held, no throttle, no brake: the car spins
  // and must then stop under drag and rolling resistance (it used to travel
  // backwards at 3.46 m/s for as long as the run lasted)
  for (const VehicleParams* p : {&defaults(), &gotthard()}) {
    VehicleState s = rolling_state(*p, Pose2{}, 20.0);
    const DriverInput in{p->steering_max, 0.0, 0.0};
    double min_vx = 0.0, max_yaw_turn = 0.0;
    for (int k = 0; k < 60000; ++k) {
      step(*p, s, in, kDt);
      min_vx = std::min(min_vx, s.vx);
      max_yaw_turn = std::max(max_yaw_turn, std::abs(s.r));
    }
    EXPECT_GT(max_yaw_turn, 1.0) << "the car did not turn hard: the test tests nothing";
    EXPECT_LT(std::hypot(s.vx, s.vy), 0.05) << "vx " << s.vx << " vy " << s.vy;
    EXPECT_LT(std::abs(s.r), 0.05);
  }
}

// ---------------------------------------------------------------------------
// lateral
// ---------------------------------------------------------------------------

TEST(Lateral, LowSpeedCorneringMatchesKinematicYawRate) {
  const VehicleParams& p = defaults();
  const double delta = 0.3;
  const VehicleState s = steady_corner(p, 1.0, delta, 20.0, initial_state(p, Pose2{}));
  ASSERT_NEAR(s.vx, 1.0, 2e-2);
  ASSERT_NEAR(s.steering, delta, 1e-9);
  const double r_kin = s.vx * std::tan(delta) / (p.lf + p.lr);
  EXPECT_NEAR(s.r, r_kin, 0.01 * r_kin);
}

TEST(Lateral, SteadyStateCorneringIsTheLinearSingleTrackModel) {
  // single-track theory: r = v delta / (L + K v^2), K = m (lr C_r - lf C_f) / (L C_f C_r)
  // with the axle cornering stiffnesses C = 2 B C D L(Fz) Fz at the wheel
  // loads there (static + downforce); within 1 % at 10-20 m/s, 0.5-2 deg, on
  // gotthard (whose tyres stay linear enough there) and on the default car
  // where its lateral acceleration stays below 0.4 g (its tyres are softer)
  for (const VehicleParams* car : {&gotthard(), &defaults()}) {
    const VehicleParams& p = *car;
    const double L = p.lf + p.lr;
    int checked = 0;
    for (const double v : {10.0, 15.0, 20.0}) {
      for (const double deg : {0.5, 1.0, 2.0}) {
        const double delta = deg * kPi / 180.0;
        const VehicleState s = steady_corner(p, v, delta, 15.0, rolling_state(p, Pose2{}, v));
        if (car == &defaults() && std::abs(s.ay) > 0.4 * kGravity) continue;
        const double down = p.c_down * s.vx * s.vx;
        auto axle = [&](double static_share, double aero_share) {
          const double fz = 0.5 * (p.mass * kGravity * static_share + aero_share * down);
          return 2.0 * p.tyre_b * p.tyre_c * p.tyre_d * load_factor(p, fz) * fz;
        };
        const double cf = axle(p.lr / L, p.aero_balance_front), cr = axle(p.lf / L, 1.0 - p.aero_balance_front);
        const double k_us = p.mass * (p.lr * cr - p.lf * cf) / (L * cf * cr);
        const double r_theory = s.vx * delta / (L + k_us * s.vx * s.vx);
        EXPECT_NEAR(s.r, r_theory, 0.01 * r_theory) << "v " << v << " deg " << deg;
        ++checked;
      }
    }
    EXPECT_GE(checked, 5);
  }
}

TEST(Lateral, LeftAndRightAreMirrorImages) {
  const VehicleParams& p = defaults();
  auto run = [&](double sign) {
    VehicleState s = initial_state(p, Pose2{});
    for (int k = 0; k < 8000; ++k) {
      const double t = k * kDt;
      step(p, s, DriverInput{sign * 0.2 * std::sin(1.5 * t), t < 5.0 ? 0.8 : 0.0, t < 5.0 ? 0.0 : 0.6, sign * 100.0}, kDt);
    }
    return s;
  };
  const VehicleState a = run(1.0), b = run(-1.0);
  EXPECT_GT(std::abs(a.y), 0.5);
  EXPECT_NEAR(a.x, b.x, 1e-6);
  EXPECT_NEAR(a.y, -b.y, 1e-6);
  EXPECT_NEAR(a.yaw, -b.yaw, 1e-9);
  EXPECT_NEAR(a.vy, -b.vy, 1e-9);
  EXPECT_NEAR(a.r, -b.r, 1e-9);
  EXPECT_NEAR(a.omega[kFrontLeft], b.omega[kFrontRight], 1e-9);
  EXPECT_NEAR(a.omega[kRearRight], b.omega[kRearLeft], 1e-9);
}

TEST(Lateral, TorqueVectoringTurnsTheCar) {
  // a yaw moment request on a straight: the right wheels drive harder, the car
  // turns left (and right for a negative one), the drive split unchanged on average
  const VehicleParams& p = defaults();
  VehicleState s = rolling_state(p, Pose2{}, 10.0);
  for (int k = 0; k < 2000; ++k) step(p, s, DriverInput{0.0, 0.2, 0.0, 300.0}, kDt);
  EXPECT_GT(s.r, 0.05);
  EXPECT_GT(s.y, 0.1);
  VehicleState n = rolling_state(p, Pose2{}, 10.0);
  for (int k = 0; k < 2000; ++k) step(p, n, DriverInput{0.0, 0.2, 0.0, 0.0}, kDt);
  EXPECT_NEAR(n.r, 0.0, 1e-12);
  EXPECT_NEAR(s.vx, n.vx, 0.05 * n.vx);
}

TEST(Lateral, ResultsConvergeAsTheStepShrinks) {
  // a launch into a slalom and a braking zone at 4, 2, 1, 0.5 and 0.25 ms:
  // the difference to the finest halves at least with each halving of the step
  const VehicleParams& p = defaults();
  auto run = [&](double dt) {
    VehicleState s = rolling_state(p, Pose2{}, 5.0);
    const int n = static_cast<int>(std::lround(6.0 / dt));
    for (int k = 0; k < n; ++k) {
      const double t = k * dt;
      step(p, s, DriverInput{0.15 * std::sin(2.0 * t), t < 4.0 ? 0.7 : 0.0, t < 4.0 ? 0.0 : 0.5}, dt);
    }
    return s;
  };
  const VehicleState fine = run(0.125e-3);
  double prev = 1e9;
  for (const double dt : {4e-3, 2e-3, 1e-3, 0.5e-3, 0.25e-3}) {
    const VehicleState s = run(dt);
    const double err = std::hypot(s.x - fine.x, s.y - fine.y);
    EXPECT_LT(err, 0.75 * prev + 1e-6) << "dt " << dt;
    prev = err;
  }
  EXPECT_LT(prev, 0.01);
}

TEST(Lateral, SkidpadMaximumLateralAccelerationIsPlausible) {
  // hold a skidpad circle (R = 9.125 m, FS skidpad centreline) with pure pursuit while
  // the target speed ramps up; the largest lateral acceleration held on the circle
  // (0.5 s average) must be that of an FS car, 1.5 g .. 2.2 g for the default car,
  // and not above the friction bound D (g + c_down v^2 / m) of the whole car at that speed
  for (const VehicleParams* car : {&defaults(), &gotthard()}) {
    const VehicleParams& p = *car;
    const double R = 9.125;
    const Vec2 centre{0.0, R};
    const double L = p.lf + p.lr;
    VehicleState s = initial_state(p, Pose2{-p.lr, 0.0, 0.0});  // CG on the circle, heading +x, turning left
    const int window = 500;
    std::vector<double> ay_hist;
    double best_ay = 0.0, best_v = 0.0;
    for (int k = 0; k < 60000; ++k) {
      const double t = k * kDt;
      const double v_target = std::min(2.0 + 0.25 * t, 20.0);
      // pure pursuit from the rear axle to a point on the circle 4 m ahead
      const Pose2 base = base_pose(p, s);
      const Vec2 rel = base.position() - centre;
      const double theta = std::atan2(rel.y, rel.x) + 4.0 / R;
      const Vec2 target = centre + R * unit_from_angle(theta);
      const Vec2 local = base.inverse_transform(target);
      const double steer = std::atan(2.0 * L * local.y / squared_norm(local));
      const double thr = std::clamp(0.1 + 0.5 * (v_target - s.vx), 0.0, 1.0);
      step(p, s, DriverInput{steer, thr, 0.0}, kDt);
      ay_hist.push_back(body_acceleration(s).y);
      const double err = distance(Vec2{s.x, s.y}, centre) - R;
      if (static_cast<int>(ay_hist.size()) >= window && t > 3.0 && std::abs(err) < 0.3) {
        double mean = 0.0;
        for (std::size_t i = ay_hist.size() - window; i < ay_hist.size(); ++i) mean += ay_hist[i];
        mean /= window;
        if (mean > best_ay) {
          best_ay = mean;
          best_v = speed(s);
        }
      }
    }
    const double g = kGravity;
    EXPECT_GT(best_ay, (car == &defaults() ? 1.5 : 1.2) * g);
    EXPECT_LT(best_ay, (car == &defaults() ? 2.2 : 2.5) * g);
    EXPECT_LE(best_ay, p.tyre_d * (g + p.c_down * best_v * best_v / p.mass) * 1.01);
    std::printf("skidpad: max steady lateral acceleration %.2f m/s^2 = %.2f g at %.2f m/s\n", best_ay, best_ay / g,
                best_v);
  }
}

TEST(Stability, AtTheStepLimitAHardManoeuvreStaysSane) {
  // stable_step_limit: at the limit a hard manoeuvre (full throttle and full
  // brake through a slalom at full lock amplitude) stays finite and close to
  // the same manoeuvre at a fine step
  for (const VehicleParams* p : {&defaults(), &gotthard()}) {
    auto run = [&](double dt) {
      VehicleState s = rolling_state(*p, Pose2{}, 2.0);
      const int n = static_cast<int>(std::lround(8.0 / dt));
      for (int k = 0; k < n && is_finite(s); ++k) {
        const double t = k * dt;
        step(*p, s, DriverInput{0.4 * std::sin(2.0 * t), t < 5.0 ? 1.0 : 0.0, t < 5.0 ? 0.0 : 1.0}, dt);
      }
      return s;
    };
    const double limit = stable_step_limit(*p);
    ASSERT_GT(limit, 1e-3);
    const VehicleState ok = run(limit);
    ASSERT_TRUE(is_finite(ok));
    const VehicleState fine = run(0.25e-3);
    EXPECT_LT(std::hypot(ok.x - fine.x, ok.y - fine.y), 0.05 * std::hypot(fine.x, fine.y));
  }
}

// ---------------------------------------------------------------------------
// actuators
// ---------------------------------------------------------------------------

TEST(Actuators, SteeringRateAndAngleLimitsHold) {
  const VehicleParams& p = defaults();
  VehicleState s = initial_state(p, Pose2{});
  // ask for far beyond the angle limit: the first-order lag alone would move at
  // (1 - 0) / 0.05 = 20 rad/s, so the rate limit (1.5 rad/s) governs at first
  const DriverInput in{1.0, 0.0, 0.0};
  double prev = s.steering;
  for (int k = 0; k < 2000; ++k) {
    step(p, s, in, kDt);
    EXPECT_LE(s.steering - prev, p.steering_rate_max * kDt * (1.0 + 1e-12)) << "k = " << k;
    EXPECT_LE(s.steering, p.steering_max);
    prev = s.steering;
    if (k == 99) {
      EXPECT_NEAR(s.steering, 0.1 * p.steering_rate_max, 1e-12);  // rate-limited ramp
    }
  }
  EXPECT_NEAR(s.steering, p.steering_max, 1e-9);
  // and back to the other side
  for (int k = 0; k < 2000; ++k) {
    step(p, s, DriverInput{-1.0, 0.0, 0.0}, kDt);
    EXPECT_GE(s.steering - prev, -p.steering_rate_max * kDt * (1.0 + 1e-12));
    EXPECT_GE(s.steering, -p.steering_max);
    prev = s.steering;
  }
  EXPECT_NEAR(s.steering, -p.steering_max, 1e-9);
}

TEST(Actuators, FirstOrderLagsFollowTheExponential) {
  // a first-order lag y' = (u - y) / tau from 0 is u (1 - exp(-t / tau)). RK4 multiplies
  // the error by R(-z) = exp(-z) + z^5 / 120 + O(z^6) per step (z = dt / tau), so after
  // k steps it is off by k z^5 / 120 exp(-(k-1) z), whose maximum over k is
  // z^4 exp(z) / (120 e): the tolerance, times the amplitude u
  auto tol = [](double u, double tau) {
    const double z = kDt / tau;
    return 1.01 * u * std::pow(z, 4) * std::exp(z) / (120.0 * std::exp(1.0));
  };
  const VehicleParams& p = defaults();
  VehicleState s = initial_state(p, Pose2{});
  for (int k = 1; k <= 200; ++k) {
    step(p, s, DriverInput{0.0, 0.0, 1.0}, kDt);
    EXPECT_NEAR(s.brake, 1.0 - std::exp(-k * kDt / p.brake_time_constant), tol(1.0, p.brake_time_constant));
  }
  s = initial_state(p, Pose2{});
  for (int k = 1; k <= 200; ++k) {
    step(p, s, DriverInput{0.0, 0.4, 0.0}, kDt);
    EXPECT_NEAR(s.throttle, 0.4 * (1.0 - std::exp(-k * kDt / p.throttle_time_constant)),
                tol(0.4, p.throttle_time_constant));
  }
  // small steering steps stay below the rate limit: a pure exponential too
  s = initial_state(p, Pose2{});
  for (int k = 1; k <= 200; ++k) {
    step(p, s, DriverInput{0.05, 0.0, 0.0}, kDt);
    EXPECT_NEAR(s.steering, 0.05 * (1.0 - std::exp(-k * kDt / p.steering_time_constant)),
                tol(0.05, p.steering_time_constant));
  }
}

TEST(Actuators, DeadTimeDelaysTheSteeringByTheConfiguredTime) {
  VehicleParams delayed = defaults();
  delayed.steering_dead_time = 0.05;
  const int n = 50;  // 0.05 s at 1 kHz
  const VehicleParams& plain = defaults();
  VehicleState a = moving_state(plain, 10.0);
  VehicleState b = moving_state(delayed, 10.0);
  auto command = [](int k) { return 0.2 * std::sin(0.01 * k) + (k > 300 ? 0.1 : 0.0); };
  std::vector<double> steer_plain, steer_delayed;
  const Car plain_car(plain), delayed_car(delayed);
  for (int k = 0; k < 1000; ++k) {
    step(plain_car, a, DriverInput{command(k), 0.1, 0.0}, kDt);
    step(delayed_car, b, DriverInput{command(k), 0.1, 0.0}, kDt);
    steer_plain.push_back(a.steering);
    steer_delayed.push_back(b.steering);
  }
  for (int k = 0; k < n; ++k) EXPECT_EQ(steer_delayed[k], 0.0) << "k = " << k;
  for (int k = n; k < 1000; ++k) EXPECT_EQ(steer_delayed[k], steer_plain[k - n]) << "k = " << k;
}

TEST(Actuators, NonFiniteCommandsDoNotPoisonTheState) {
  const VehicleParams& p = defaults();
  VehicleState s = moving_state(p, 10.0);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (int k = 0; k < 3000; ++k) step(p, s, DriverInput{nan, nan, nan}, kDt);
  EXPECT_TRUE(std::isfinite(s.x) && std::isfinite(s.vx) && std::isfinite(s.steering));
  EXPECT_LT(s.vx, 1e-6);  // a non-finite brake command brakes
}

// ---------------------------------------------------------------------------
// determinism
// ---------------------------------------------------------------------------

TEST(Determinism, TwoIdenticalRunsAreBitIdentical) {
  VehicleParams p = defaults();
  p.steering_dead_time = 0.02;
  auto run = [&]() {
    VehicleState s = initial_state(p, Pose2{1.0, 2.0, 0.3});
    for (int k = 0; k < 20000; ++k) {
      const double t = k * kDt;
      DriverInput in;
      in.steering_angle = 0.3 * std::sin(1.3 * t);
      in.throttle = t < 12.0 ? 0.6 : 0.0;
      in.brake = t < 12.0 ? 0.0 : 0.8;
      step(p, s, in, kDt);
    }
    return s;
  };
  const VehicleState a = run();
  const VehicleState b = run();
  expect_states_equal(a, b);
  EXPECT_NE(a.x, 1.0);  // it did drive
}

// the step as built for AVX2 (where this CPU has it) and as built for
// baseline x86-64: the same bits through launch, traction control, a slide,
// lock-up under braking and rest (simd_math.h: elementwise, no FMA)
TEST(Determinism, TheAvx2AndBaselineStepsAgreeBitForBit) {
#if defined(__x86_64__)
  __builtin_cpu_init();
  if (!__builtin_cpu_supports("avx2")) GTEST_SKIP() << "no AVX2 on this CPU: step() is step_baseline()";
#endif
  VehicleParams p = defaults();
  p.steering_dead_time = 0.02;
  const Car car(p);
  VehicleState a = initial_state(p, Pose2{1.0, 2.0, 0.3});
  VehicleState b = a;
  for (int k = 0; k < 20000; ++k) {
    const double t = k * kDt;
    DriverInput in;
    in.steering_angle = 0.35 * std::sin(1.7 * t);
    in.throttle = t < 10.0 ? 1.0 : 0.0;
    in.brake = t < 10.0 ? 0.0 : 1.0;
    step(car, a, in, kDt);
    step_baseline(car, b, in, kDt);
  }
  expect_states_equal(a, b);
  EXPECT_GT(std::hypot(a.x - 1.0, a.y - 2.0), 50.0);  // it did drive
  EXPECT_LT(speed(a), 0.01);                        // and stopped
}

// ---------------------------------------------------------------------------
// accessors
// ---------------------------------------------------------------------------

TEST(Accessors, BasePoseWheelsFootprintAndWheelSpeeds) {
  const VehicleParams& p = defaults();
  const Pose2 pose{5.0, -3.0, 2.0};
  VehicleState s = initial_state(p, pose);
  const Pose2 back = base_pose(p, s);
  EXPECT_NEAR(back.x, pose.x, 1e-12);
  EXPECT_NEAR(back.y, pose.y, 1e-12);
  EXPECT_NEAR(back.yaw, pose.yaw, 1e-12);
  EXPECT_EQ(s.vx, 0.0);

  // contact patches: the rear pair straddles the base origin, the front pair is a
  // wheelbase ahead; tracks as configured
  const auto w = wheel_positions(p, s);
  const Vec2 rear_mid = 0.5 * (w[kRearLeft] + w[kRearRight]);
  const Vec2 front_mid = 0.5 * (w[kFrontLeft] + w[kFrontRight]);
  EXPECT_NEAR(distance(rear_mid, pose.position()), 0.0, 1e-12);
  EXPECT_NEAR(distance(front_mid, pose.transform({p.lf + p.lr, 0.0})), 0.0, 1e-12);
  EXPECT_NEAR(distance(w[kFrontLeft], w[kFrontRight]), p.track_front, 1e-12);
  EXPECT_NEAR(distance(w[kRearLeft], w[kRearRight]), p.track_rear, 1e-12);
  EXPECT_GT(pose.inverse_transform(w[kFrontLeft]).y, 0.0);  // left is left

  // the footprint contains every wheel
  const Footprint f = footprint(p);
  EXPECT_NEAR(f.x_max - f.x_min, 2.83, 1e-12);
  for (const Vec2& wp : w) {
    const Vec2 local = pose.inverse_transform(wp);
    EXPECT_GT(local.x, f.x_min);
    EXPECT_LT(local.x, f.x_max);
    EXPECT_GT(local.y, f.y_min);
    EXPECT_LT(local.y, f.y_max);
  }
  EXPECT_EQ(f.corners()[2].x, f.x_max);
  EXPECT_EQ(f.corners()[2].y, f.y_max);

  // wheel speeds: the wheels' spin, v / R rolling straight, 0 slip there
  s = rolling_state(p, pose, 10.0);
  for (double omega : wheel_speeds(p, s)) EXPECT_NEAR(omega, 10.0 / p.wheel_radius, 1e-12);
  for (double kappa : slip_ratios(p, s)) EXPECT_NEAR(kappa, 0.0, 1e-12);
  s.r = 0.5;
  EXPECT_NEAR(base_velocity(p, s).y, -p.lr * 0.5, 1e-12);
  // in a turn the outer wheels cover more ground: at the same spin the inner one slips forward
  const auto kappa = slip_ratios(p, s);
  const double v_left = 10.0 - 0.5 * 0.5 * p.track_rear, v_right = 10.0 + 0.5 * 0.5 * p.track_rear;
  EXPECT_NEAR(kappa[kRearLeft], (10.0 - v_left) / v_left, 1e-12);
  EXPECT_NEAR(kappa[kRearRight], (10.0 - v_right) / v_right, 1e-12);
}

TEST(Accessors, AccelerationMatchesTheVelocityChange) {
  // on a straight line the body acceleration is dv/dt
  const VehicleParams p = instant_actuators();
  VehicleState s = moving_state(p, 5.0);
  for (int k = 0; k < 100; ++k) {
    const double v_before = s.vx;
    step(p, s, DriverInput{0.0, 0.5, 0.0}, kDt);
    EXPECT_NEAR(body_acceleration(s).x, (s.vx - v_before) / kDt, 1e-9);
    EXPECT_EQ(body_acceleration(s).y, 0.0);
  }
  // in the steady low-speed corner the lateral acceleration is v r
  const VehicleState c = steady_corner(defaults(), 1.0, 0.3, 20.0, initial_state(defaults(), Pose2{}));
  EXPECT_NEAR(body_acceleration(c).y, c.vx * c.r, 1e-6);
}

}  // namespace
}  // namespace paddock::vehicle
