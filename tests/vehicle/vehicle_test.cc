// tests of the vehicle model, each against something independent of the code under
// test: the FSSIM tyre oracle, closed-form solutions, single-track theory, physical
// bounds, or a second run.
#include "sim/vehicle/vehicle.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace paddock::vehicle {
namespace {

constexpr double kDt = 1e-3;  // s, the simulator's physics step

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
VehicleParams load_default_params() {
  const std::string path = std::string(PADDOCK_SOURCE_DIR) + "/scenarios/vehicles/default.ini";
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
  EXPECT_EQ(seen.size(), fields.size()) << "default.ini must set every field";
  return p;
}

const VehicleParams& defaults() {
  static const VehicleParams p = load_default_params();
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
    const double ff = (p.cr0 + p.c_drag * v_target * v_target) / p.cm1;
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

TEST(VehicleParams, DefaultIniSetsEveryFieldAndValidates) {
  const VehicleParams& p = defaults();
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
  EXPECT_EQ(params::validate(p), "brake_force_max must be in [0, 20000] N (got nan)");

  // a default-constructed set is rejected at its first field
  EXPECT_EQ(params::validate(VehicleParams{}), "mass must be in [50, 2000] kg (got nan)");
}

// ---------------------------------------------------------------------------
// tyre
// ---------------------------------------------------------------------------

TEST(Tyre, MatchesFssimOracle) {
  // ORACLES.md: per wheel at Fz = 465.975 N (= 190 kg g / 4)
  const VehicleParams& p = defaults();
  const double fz = 465.975;
  EXPECT_NEAR(std::abs(tyre_lateral_force(p, 0.05, fz)), 540.906, 1e-3);
  EXPECT_NEAR(std::abs(tyre_lateral_force(p, 0.10, fz)), 725.869, 1e-3);
  EXPECT_NEAR(std::abs(tyre_lateral_force(p, 0.20, fz)), 732.389, 1e-3);
  // the force opposes the slip, is odd in the slip, zero at zero slip
  EXPECT_LT(tyre_lateral_force(p, 0.05, fz), 0.0);
  EXPECT_EQ(tyre_lateral_force(p, -0.05, fz), -tyre_lateral_force(p, 0.05, fz));
  EXPECT_EQ(tyre_lateral_force(p, 0.0, fz), 0.0);
}

TEST(Tyre, DynamicWeightIsTheFssimBlend) {
  EXPECT_EQ(dynamic_weight(0.0), 0.0);
  EXPECT_EQ(dynamic_weight(1.5), 0.0);
  EXPECT_EQ(dynamic_weight(2.5), 0.5);
  EXPECT_EQ(dynamic_weight(3.5), 1.0);
  EXPECT_EQ(dynamic_weight(30.0), 1.0);
}

// ---------------------------------------------------------------------------
// standstill
// ---------------------------------------------------------------------------

TEST(Standstill, AtRestWithZeroInputStaysExactlyAtRest) {
  const VehicleParams& p = defaults();
  const VehicleState s0 = initial_state(p, Pose2{3.0, -2.0, 0.7});
  VehicleState s = s0;
  for (int i = 0; i < 10000; ++i) step(p, s, DriverInput{}, kDt);  // 10 s
  expect_states_equal(s, s0);
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

// ---------------------------------------------------------------------------
// longitudinal
// ---------------------------------------------------------------------------

// m dv/dt = F - Cr0 - c v^2 with v_inf = sqrt((F - Cr0) / c) has the solution
//   v(t) = v_inf tanh(c v_inf t / m + atanh(v0 / v_inf)).
double analytic_speed(const VehicleParams& p, double force, double v0, double t) {
  const double v_inf = std::sqrt((force - p.cr0) / p.c_drag);
  return v_inf * std::tanh(p.c_drag * v_inf * t / p.mass + std::atanh(v0 / v_inf));
}

TEST(Longitudinal, StraightLineAccelerationMatchesTanhSolution) {
  // throttle 0.3: 1500 N, half per axle (750 N) against a friction limit of
  // D Fz > 1.6 (931.95 - 225) N = 1131 N per axle even with the full load transfer
  const VehicleParams p = instant_actuators();
  const double throttle = 0.3;
  const double force = throttle * p.cm1;
  const DriverInput in{0.0, throttle, 0.0};

  // from a rolling start (above the standstill band): the model is exactly the ODE
  // above (kinematic and dynamic rows agree on a straight line), so only RK4's
  // truncation error remains, O(dt^4) ~ 1e-12 here: tolerance 1e-9 m/s
  {
    const double v0 = 2.0;
    VehicleState s = moving_state(p, v0);
    int k = 0;
    for (double t_check : {0.5, 1.0, 2.0, 5.0, 10.0, 20.0}) {
      while (k < static_cast<int>(std::lround(t_check / kDt))) {
        step(p, s, in, kDt);
        ++k;
      }
      EXPECT_NEAR(s.vx, analytic_speed(p, force, v0, t_check), 1e-9) << "t = " << t_check;
      EXPECT_EQ(s.vy, 0.0);
      EXPECT_EQ(s.r, 0.0);
    }
  }

  // from rest: below v_reg the rolling resistance is regularised to Cr0 vx / v_reg, so
  // while crossing the band (at most v_reg / a_min seconds, a_min = (F - Cr0) / m) the
  // car gains less than the missing Cr0 / m: dv < Cr0 / m * v_reg / a_min = 5.3e-3 m/s
  // (v_reg = 3.9 cm/s; about half of that on average), and drag then shrinks the
  // excess. Tolerance: that bound.
  {
    const double v_reg = standstill_speed(p, kDt);
    const double a_min = (force - p.cr0) / p.mass;
    const double tol = p.cr0 / p.mass * v_reg / a_min;
    VehicleState s = initial_state(p, Pose2{});
    int k = 0;
    for (double t_check : {0.5, 1.0, 2.0, 5.0, 10.0, 20.0}) {
      while (k < static_cast<int>(std::lround(t_check / kDt))) {
        step(p, s, in, kDt);
        ++k;
      }
      const double expected = analytic_speed(p, force, 0.0, t_check);
      EXPECT_NEAR(s.vx, expected, tol) << "t = " << t_check;
      EXPECT_GE(s.vx, expected) << "the regularisation can only help";
    }
  }
}

TEST(Longitudinal, BrakingStopsNeverReversesAndStaysAtRest) {
  const VehicleParams& p = defaults();
  VehicleState s = moving_state(p, 15.0);
  const DriverInput in{0.0, 0.0, 1.0};
  double min_vx = s.vx;
  int stop_step = -1;
  double x_stop = 0.0;
  for (int k = 0; k < 10000; ++k) {
    const double vx_before = s.vx;
    step(p, s, in, kDt);
    min_vx = std::min(min_vx, s.vx);
    // the deceleration never beats the friction limit plus drag and rolling resistance
    const double decel = (vx_before - s.vx) / kDt;
    const double bound =
        p.tyre_d * (kGravity + p.c_down * vx_before * vx_before / p.mass) +
        (p.c_drag * vx_before * vx_before + p.cr0) / p.mass;
    EXPECT_LE(decel, bound * 1.001) << "k = " << k;
    if (stop_step < 0 && s.vx < 1e-6) stop_step = k;
    if (stop_step >= 0 && k == stop_step + 1000) x_stop = s.x;
  }
  ASSERT_GE(stop_step, 0) << "did not stop";
  EXPECT_GE(min_vx, 0.0) << "rolled backwards";
  // the stopping time is at least v0 / (the deceleration bound above, at its largest,
  // v = v0), and a car with brakes that reach the tyre limit stops within 2 s
  const double v0 = 15.0;
  const double a_bound = p.tyre_d * (kGravity + p.c_down * v0 * v0 / p.mass) + (p.c_drag * v0 * v0 + p.cr0) / p.mass;
  EXPECT_GT(stop_step * kDt, v0 / a_bound);
  EXPECT_LT(stop_step * kDt, 2.0);
  // then at rest: inside the standstill band vx decays like exp(-t / tau) with
  // tau = m v_reg / F ~ 2 ms, so one second after the stop the car does not move at all
  ASSERT_LT(stop_step + 1000, 10000);
  EXPECT_EQ(s.x, x_stop);
  EXPECT_LT(s.vx, 1e-200);
  EXPECT_EQ(s.y, 0.0);
  EXPECT_EQ(s.yaw, 0.0);
  std::printf("braking from %.0f m/s: stopped after %.3f s in %.2f m\n", v0, stop_step * kDt, s.x);
}

TEST(Longitudinal, BrakingInACornerStopsAndStopsTurning) {
  // through the blend into the kinematic model with a residual sideslip: vy and r must
  // settle on their kinematic values (zero at vx = 0), so the car does not spin in place
  const VehicleParams& p = defaults();
  VehicleState s = steady_corner(p, 10.0, 0.1, 3.0, moving_state(p, 10.0));
  ASSERT_GT(std::abs(s.vy), 1e-3);
  for (int k = 0; k < 5000; ++k) {
    step(p, s, DriverInput{0.1, 0.0, 1.0}, kDt);
    EXPECT_GE(s.vx, 0.0) << "k = " << k;
  }
  const VehicleState stopped = s;
  EXPECT_LT(std::abs(s.r), 1e-9);
  EXPECT_LT(std::abs(s.vy), 1e-9);
  for (int k = 0; k < 5000; ++k) step(p, s, DriverInput{0.1, 0.0, 1.0}, kDt);
  EXPECT_NEAR(s.yaw, stopped.yaw, 1e-9);
  EXPECT_NEAR(s.x, stopped.x, 1e-9);
  EXPECT_NEAR(s.y, stopped.y, 1e-9);
}

TEST(Lateral, SlipAngleOpposesTheLateralVelocityInEveryDirectionOfTravel) {
  // forwards it is the textbook atan2(vy, vx) - steer, to the bit
  EXPECT_EQ(slip_angle(10.0, 1.0, 0.1), std::atan2(1.0, 10.0) - 0.1);
  // backwards: the same magnitude as forwards, its sign that of the lateral velocity
  EXPECT_NEAR(slip_angle(-10.0, 1.0, 0.0), std::atan(1.0 / 10.0), 1e-12);
  EXPECT_NEAR(slip_angle(-10.0, -1.0, 0.0), -std::atan(1.0 / 10.0), 1e-12);
  // a steered wheel rolling backwards: the velocity in the wheel frame, by rotation
  for (const double steer : {-0.5, -0.1, 0.2, 0.5}) {
    for (const double vy : {-3.0, -0.2, 0.0, 0.7, 4.0}) {
      const double v_long = -6.0 * std::cos(steer) + vy * std::sin(steer);
      const double v_lat = 6.0 * std::sin(steer) + vy * std::cos(steer);
      EXPECT_NEAR(slip_angle(-6.0, vy, steer), std::atan(v_lat / std::abs(v_long)), 1e-12) << steer << " " << vy;
      EXPECT_LE(std::abs(slip_angle(-6.0, vy, steer)), kPi / 2);
    }
  }
}

TEST(Lateral, ASpunCarComesToRest) {
  // straight at 20 m/s, full lock held, no throttle, no brake: the car spins
  // and must then stop under drag and rolling resistance (it used to travel
  // backwards at 3.46 m/s for as long as the run lasted)
  const VehicleParams& p = defaults();
  VehicleState s = moving_state(p, 20.0);
  const DriverInput in{p.steering_max, 0.0, 0.0};
  double min_vx = 0.0;
  for (int k = 0; k < 60000; ++k) {
    step(p, s, in, kDt);
    min_vx = std::min(min_vx, s.vx);
  }
  EXPECT_LT(min_vx, -1.0) << "the car did not spin: the test tests nothing";
  EXPECT_LT(std::hypot(s.vx, s.vy), 0.05) << "vx " << s.vx << " vy " << s.vy;
  EXPECT_LT(std::abs(s.r), 0.05);
}

TEST(Longitudinal, SpeedIsConservedWithoutForces) {
  // no drive, brake, drag or rolling resistance: on a straight line nothing acts
  VehicleParams p = defaults();
  p.c_drag = 0.0;
  p.cr0 = 0.0;
  for (double v0 : {1.0, 2.5, 10.0}) {  // kinematic, blended, dynamic
    VehicleState s = moving_state(p, v0);
    for (int k = 0; k < 10000; ++k) step(p, s, DriverInput{}, kDt);
    EXPECT_NEAR(s.vx, v0, 1e-12);
    EXPECT_NEAR(s.x - moving_state(p, v0).x, v0 * 10.0, 1e-9);
    EXPECT_EQ(s.vy, 0.0);
  }
}

TEST(Longitudinal, KineticEnergyNeverGrowsInASlalomWithoutDrive) {
  // tyre forces oppose the slip, so in the dynamic model their power is <= 0:
  // E = m (vx^2 + vy^2) / 2 + Iz r^2 / 2 can only decrease (RK4 error aside)
  VehicleParams p = defaults();
  p.c_drag = 0.0;
  p.cr0 = 0.0;
  VehicleState s = moving_state(p, 15.0);
  auto energy = [&](const VehicleState& st) {
    return 0.5 * p.mass * (st.vx * st.vx + st.vy * st.vy) + 0.5 * p.inertia_z * st.r * st.r;
  };
  double e_prev = energy(s);
  const double e0 = e_prev;
  for (int k = 0; k < 5000; ++k) {
    const double t = k * kDt;
    step(p, s, DriverInput{0.15 * std::sin(2.0 * kPi * 0.5 * t), 0.0, 0.0}, kDt);
    const double e = energy(s);
    EXPECT_LE(e, e_prev + 1e-9 * e0) << "k = " << k;
    e_prev = e;
  }
  EXPECT_LT(e_prev, e0);           // the slalom scrubbed some speed
  EXPECT_GT(s.vx, 3.5);            // and stayed in the dynamic regime
}

// ---------------------------------------------------------------------------
// lateral
// ---------------------------------------------------------------------------


TEST(Lateral, LowSpeedCorneringMatchesKinematicYawRate) {
  const VehicleParams& p = defaults();
  const double delta = 0.3;
  const VehicleState s = steady_corner(p, 1.0, delta, 20.0, initial_state(p, Pose2{}));
  ASSERT_NEAR(s.vx, 1.0, 1e-3);
  ASSERT_NEAR(s.steering, delta, 1e-9);
  const double r_kin = s.vx * std::tan(delta) / (p.lf + p.lr);
  EXPECT_NEAR(s.r, r_kin, 0.01 * r_kin);
  // the rear axle does not slip in the kinematic model
  EXPECT_NEAR(base_velocity(p, s).y, 0.0, 1e-6);
}

TEST(Lateral, LinearRangeSteadyStateIsNeutralSteer) {
  // single-track theory: r / delta = v / (L + K v^2), understeer gradient
  // K = m (lr / Cf - lf / Cr) / L = 0 here (lf = lr, equal axle loads and tyres), so
  // r = v delta / L like the kinematic model, although this runs fully dynamic (8 m/s)
  const VehicleParams& p = defaults();
  const double delta = 0.03;
  const VehicleState s = steady_corner(p, 8.0, delta, 10.0, moving_state(p, 8.0));
  ASSERT_NEAR(s.vx, 8.0, 1e-2);
  const double r_theory = s.vx * delta / (p.lf + p.lr);
  EXPECT_NEAR(s.r, r_theory, 0.01 * r_theory);
  // and unlike the kinematic model, the rear axle now has a slip angle (it carries force)
  EXPECT_LT(base_velocity(p, s).y, -1e-4);
}

TEST(Lateral, SkidpadMaximumLateralAccelerationIsPlausible) {
  // hold a skidpad circle (R = 9.125 m, FS skidpad centreline) with pure pursuit while
  // the target speed ramps up; the largest lateral acceleration held on the circle
  // (0.5 s average) must be physically plausible: 1.2 g .. 2.5 g, and not above the
  // friction bound D (g + c_down v^2 / m) of the whole car at that speed
  const VehicleParams& p = defaults();
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
    const double ld2 = squared_norm(local);
    const double steer = std::atan(2.0 * L * local.y / ld2);
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
  EXPECT_GT(best_ay, 1.2 * g);
  EXPECT_LT(best_ay, 2.5 * g);
  EXPECT_LE(best_ay, p.tyre_d * (g + p.c_down * best_v * best_v / p.mass) * 1.01);
  std::printf("skidpad: max steady lateral acceleration %.2f m/s^2 = %.2f g at %.2f m/s\n", best_ay,
              best_ay / g, best_v);
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
  for (int k = 0; k < 1000; ++k) {
    step(plain, a, DriverInput{command(k), 0.1, 0.0}, kDt);
    step(delayed, b, DriverInput{command(k), 0.1, 0.0}, kDt);
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

  // wheel speeds: v / R on a straight; in a turn the outer wheels turn faster
  s.vx = 10.0;
  for (double omega : wheel_speeds(p, s)) EXPECT_NEAR(omega, 10.0 / p.wheel_radius, 1e-12);
  s.r = 0.5;
  const auto ws = wheel_speeds(p, s);
  EXPECT_NEAR(ws[kRearRight] - ws[kRearLeft], 0.5 * p.track_rear / p.wheel_radius, 1e-12);
  EXPECT_NEAR(base_velocity(p, s).y, -p.lr * 0.5, 1e-12);
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
