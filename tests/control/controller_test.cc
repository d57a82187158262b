// the Controller: signs, mode blending, limits, bad input, the projection
// hint, the speed reference, and a kinematic closed loop on a circle.
#include "autonomy/control/controller.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <tuple>

namespace paddock::control {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// an open straight along +x from x0, ds 0.5, at a constant reference speed
Trajectory straight(double x0, double length, double speed) {
  Trajectory t;
  const int n = static_cast<int>(std::lround(length / 0.5)) + 1;
  for (int i = 0; i < n; ++i) {
    TrajectoryPoint p;
    p.s = 0.5 * i;
    p.x = x0 + p.s;
    p.speed = speed;
    t.points.push_back(p);
  }
  t.length = 0.5 * (n - 1);
  return t;
}

// a closed circle of radius R about the origin, counter-clockwise from (R, 0)
// (a left turn), about 0.5 m between samples
Trajectory circle(double R, double speed) {
  Trajectory t;
  const int n = static_cast<int>(std::lround(2.0 * kPi * R / 0.5));
  const double chord = 2.0 * R * std::sin(kPi / n);
  for (int i = 0; i < n; ++i) {
    const double a = 2.0 * kPi * i / n;
    TrajectoryPoint p;
    p.s = chord * i;
    p.x = R * std::cos(a);
    p.y = R * std::sin(a);
    p.heading = wrap_angle(a + 0.5 * kPi);
    p.curvature = 1.0 / R;
    p.speed = speed;
    t.points.push_back(p);
  }
  t.closed = true;
  t.length = chord * n;
  return t;
}

ControlInput input_at(const Trajectory& t, double x, double y, double yaw, double v) {
  ControlInput in;
  in.dt = 0.01;
  in.base_pose = {x, y, yaw};
  in.vx = v;
  in.trajectory = &t;
  return in;
}

ControlParams mode(LateralMode m) {
  ControlParams p;
  p.lateral = m;
  return p;
}

const LateralMode kModes[] = {LateralMode::Combined, LateralMode::Stanley, LateralMode::PurePursuit};

TEST(Controller, DefaultsAreValid) {
  EXPECT_EQ(params::validate(ControlParams{}), "");
  EXPECT_EQ(params::validate(VehicleKnowledge{}), "");
  ControlParams p;
  p.combined.k_max = 0.1;  // below k_min
  EXPECT_EQ(params::validate(p), "combined.k_max must be >= k_min");
  p = ControlParams{};
  p.stanley.k_soft = 0.0;
  EXPECT_EQ(params::validate(p), "stanley.k_soft must be in (0, 100] m/s (got 0)");
  p = ControlParams{};
  p.lateral = static_cast<LateralMode>(5);
  EXPECT_EQ(params::validate(p), "lateral has a value that is not one of its names");
  VehicleKnowledge v;
  v.wheelbase = 2.0;  // not lf + lr
  EXPECT_EQ(params::validate(v), "wheelbase must equal lf + lr (got 2, lf + lr = 1.53)");
  v = VehicleKnowledge{};
  v.max_steering_angle = 2.0;
  EXPECT_EQ(params::validate(v), "max_steering_angle must be in (0, 1.5707963267948966) rad (got 2)");
}

TEST(Controller, RightOfThePathSteersLeft) {
  const Trajectory t = straight(-10.0, 100.0, 10.0);
  for (LateralMode m : kModes) {
    Controller c(mode(m));
    const ControlOutput out = c.update(input_at(t, 0.0, -0.5, 0.0, 10.0));
    ASSERT_EQ(out.status, Status::Ok);
    EXPECT_GT(out.steering_angle, 0.0) << to_string(m);
    EXPECT_NEAR(out.diagnostics.lateral_error, -0.5, 1e-9);  // the front axle is right of the path
  }
}

TEST(Controller, LeftOfThePathSteersRight) {
  const Trajectory t = straight(-10.0, 100.0, 10.0);
  for (LateralMode m : kModes) {
    Controller c(mode(m));
    EXPECT_LT(c.update(input_at(t, 0.0, 0.5, 0.0, 10.0)).steering_angle, 0.0) << to_string(m);
  }
}

TEST(Controller, HeadingRotatedLeftSteersRight) {
  const Trajectory t = straight(-10.0, 100.0, 10.0);
  for (LateralMode m : kModes) {
    Controller c(mode(m));
    const ControlOutput out = c.update(input_at(t, 0.0, 0.0, 0.2, 10.0));
    EXPECT_LT(out.steering_angle, 0.0) << to_string(m);
    EXPECT_NEAR(out.diagnostics.heading_error, -0.2, 1e-12);
  }
}

// the car at (0, -0.5) with yaw 0.1 on the straight y = 0, no yaw rate: the
// expected laws computed here from the geometry, not from the controller
struct Expected {
  double delta_st;
  double delta_pp;
};

Expected expected_on_straight(const ControlParams& p, const VehicleKnowledge& car, double v) {
  const double y0 = -0.5, yaw = 0.1;
  const Vec2 front{car.wheelbase * std::cos(yaw), y0 + car.wheelbase * std::sin(yaw)};
  const double e = -front.y;  // the path is left of the front axle
  const double L_d = lookahead_distance(v, p.pure_pursuit.L_min, p.pure_pursuit.k_v);
  const double ahead = std::sqrt(L_d * L_d - y0 * y0);  // the circle meets y = 0 here
  const double alpha = std::atan2(-y0, ahead) - yaw;
  return {stanley_steer(-yaw, e, v, p.stanley.k, p.stanley.k_soft),
          pure_pursuit_steer(alpha, L_d, car.wheelbase)};
}

TEST(Controller, WeightOneIsPurePursuitAndZeroIsStanley) {
  const Trajectory t = straight(-10.0, 100.0, 10.0);
  const double v = 10.0;
  ControlParams p;
  const Expected want = expected_on_straight(p, VehicleKnowledge{}, v);
  ASSERT_NE(want.delta_st, want.delta_pp);

  // combined with k_min = k_max = 1: pure pursuit
  p.combined.k_min = p.combined.k_max = 1.0;
  const ControlOutput pp = Controller(p).update(input_at(t, 0.0, -0.5, 0.1, v));
  EXPECT_DOUBLE_EQ(pp.diagnostics.k_pp, 1.0);
  EXPECT_NEAR(pp.steering_angle, want.delta_pp, 1e-9);
  // and the same as the pure pursuit mode
  EXPECT_NEAR(Controller(mode(LateralMode::PurePursuit)).update(input_at(t, 0.0, -0.5, 0.1, v)).steering_angle,
              want.delta_pp, 1e-9);

  // combined with k_min = k_max = 0: Stanley
  p.combined.k_min = p.combined.k_max = 0.0;
  const ControlOutput st = Controller(p).update(input_at(t, 0.0, -0.5, 0.1, v));
  EXPECT_DOUBLE_EQ(st.diagnostics.k_pp, 0.0);
  EXPECT_NEAR(st.steering_angle, want.delta_st, 1e-9);
  EXPECT_NEAR(Controller(mode(LateralMode::Stanley)).update(input_at(t, 0.0, -0.5, 0.1, v)).steering_angle,
              want.delta_st, 1e-9);

  // the defaults blend them with k_min on a straight
  const ControlOutput mix = Controller().update(input_at(t, 0.0, -0.5, 0.1, v));
  EXPECT_DOUBLE_EQ(mix.diagnostics.k_pp, 0.2);
  EXPECT_NEAR(mix.steering_angle, 0.8 * want.delta_st + 0.2 * want.delta_pp, 1e-9);
}

TEST(Controller, SteeringLimitHolds) {
  const Trajectory t = straight(-10.0, 100.0, 10.0);
  const VehicleKnowledge car;
  for (LateralMode m : kModes) {
    // far right of the path, and turned hard right: asks for more than the limit
    Controller c(mode(m));
    const ControlOutput out = c.update(input_at(t, 0.0, -2.5, -1.2, 1.0));
    EXPECT_DOUBLE_EQ(out.steering_angle, car.max_steering_angle) << to_string(m);
    Controller c2(mode(m));
    const ControlOutput out2 = c2.update(input_at(t, 0.0, 2.5, 1.2, 1.0));
    EXPECT_DOUBLE_EQ(out2.steering_angle, -car.max_steering_angle) << to_string(m);
  }
  // a tighter limit holds too
  VehicleKnowledge tight;
  tight.max_steering_angle = 0.1;
  Controller c(ControlParams{}, tight);
  EXPECT_DOUBLE_EQ(c.update(input_at(t, 0.0, -1.0, 0.0, 5.0)).steering_angle, 0.1);
}

TEST(Controller, SteadyStateYawPointsIntoTheTurn) {
  // on a left circle, on the path: theta_ss > 0 (left), Stanley steers more
  const Trajectory t = circle(15.0, 8.0);
  ControlParams with = mode(LateralMode::Stanley);
  ControlParams without = with;
  without.stanley.use_steady_state_yaw = false;
  const ControlInput in = input_at(t, 15.0, 0.0, 0.5 * kPi, 8.0);
  const ControlOutput a = Controller(with).update(in);
  const ControlOutput b = Controller(without).update(in);
  EXPECT_GT(a.diagnostics.theta_ss, 0.0);
  EXPECT_EQ(b.diagnostics.theta_ss, 0.0);
  EXPECT_NEAR(a.diagnostics.delta_st - b.diagnostics.delta_st, a.diagnostics.theta_ss, 1e-12);
}

TEST(Controller, HeadingPreviewReadsThePathAhead) {
  // on a left circle of radius 15 m at 10 m/s, a preview of 0.2 s reads the
  // path heading 2 m further round: 2 / 15 rad more to the left
  const Trajectory t = circle(15.0, 10.0);
  ControlParams now = mode(LateralMode::Stanley);
  ControlParams ahead = now;
  ahead.stanley.preview_time = 0.2;
  const ControlInput in = input_at(t, 15.0, 0.0, 0.5 * kPi, 10.0);
  const ControlOutput a = Controller(ahead).update(in);
  const ControlOutput b = Controller(now).update(in);
  EXPECT_NEAR(a.diagnostics.heading_error - b.diagnostics.heading_error, 2.0 / 15.0, 1e-3);
  EXPECT_NEAR(a.steering_angle - b.steering_angle, 2.0 / 15.0, 1e-3);
  // on a straight the path ahead heads the same way: no change
  const Trajectory line = straight(-10.0, 100.0, 10.0);
  const ControlInput off = input_at(line, 0.0, -0.5, 0.1, 10.0);
  EXPECT_DOUBLE_EQ(Controller(ahead).update(off).steering_angle, Controller(now).update(off).steering_angle);
}

TEST(Controller, YawRateDampingOpposesExcessYaw) {
  // yawing left faster than the path asks -> less left steering
  const Trajectory t = circle(15.0, 8.0);
  ControlInput in = input_at(t, 15.0, 0.0, 0.5 * kPi, 8.0);
  in.yaw_rate = 8.0 / 15.0;
  const double matched = Controller().update(in).steering_angle;
  in.yaw_rate += 0.5;
  const double excess = Controller().update(in).steering_angle;
  EXPECT_NEAR(excess - matched, -ControlParams{}.k_d_yaw * 0.5, 1e-12);
  // torque vectoring is off by default; on, it asks a yaw moment against the excess
  EXPECT_EQ(Controller().update(in).yaw_moment, 0.0);
  ControlParams tv;
  tv.k_tv_yaw = 300.0;
  EXPECT_NEAR(Controller(tv).update(in).yaw_moment, -300.0 * 0.5, 1e-9);
  in.yaw_rate = 8.0 / 15.0;
  EXPECT_NEAR(Controller(tv).update(in).yaw_moment, 0.0, 1e-9);
}

TEST(Controller, EmptyOrMissingTrajectoryIsASafeStop) {
  Controller c;
  Trajectory empty;
  const Trajectory* missing = nullptr;
  const Trajectory* empty_ptr = &empty;
  for (const Trajectory* t : {missing, empty_ptr}) {
    ControlInput in;
    in.dt = 0.01;
    in.vx = 5.0;
    in.trajectory = t;
    const ControlOutput out = c.update(in);
    EXPECT_EQ(out.status, Status::NoTrajectory);
    EXPECT_STRNE(out.reason, "");
    EXPECT_EQ(out.steering_angle, 0.0);
    EXPECT_EQ(out.throttle, 0.0);
    EXPECT_EQ(out.brake, 1.0);
  }
  // one point is not a trajectory either
  Trajectory one;
  one.points.resize(1);
  ControlInput in;
  in.trajectory = &one;
  EXPECT_EQ(c.update(in).status, Status::NoTrajectory);
  EXPECT_EQ(std::string(to_string(Status::NoTrajectory)), "no_trajectory");
}

TEST(Controller, NonFiniteStateIsASafeStop) {
  const Trajectory t = straight(-10.0, 100.0, 10.0);
  Controller c;
  ControlInput ok = input_at(t, 0.0, -0.5, 0.0, 5.0);
  ASSERT_EQ(c.update(ok).status, Status::Ok);
  auto check = [&](ControlInput in) {
    const ControlOutput out = c.update(in);
    EXPECT_EQ(out.status, Status::BadState);
    EXPECT_STRNE(out.reason, "");
    EXPECT_EQ(out.steering_angle, 0.0);
    EXPECT_EQ(out.throttle, 0.0);
    EXPECT_EQ(out.brake, 1.0);
  };
  ControlInput in = ok;
  in.base_pose.x = kNaN;
  check(in);
  in = ok;
  in.base_pose.yaw = kNaN;
  check(in);
  in = ok;
  in.vx = kNaN;
  check(in);
  in = ok;
  in.yaw_rate = std::numeric_limits<double>::infinity();
  check(in);
  in = ok;
  in.dt = -0.01;
  check(in);
  in = ok;
  in.max_speed = kNaN;
  check(in);
  // and it recovers on good data
  EXPECT_EQ(c.update(ok).status, Status::Ok);
}

TEST(Controller, NonFiniteTrajectoryIsASafeStop) {
  Trajectory t = straight(-10.0, 100.0, 10.0);
  t.points[20].y = kNaN;  // at x = 0
  const ControlOutput out = Controller().update(input_at(t, 0.0, 0.0, 0.0, 5.0));
  EXPECT_EQ(out.status, Status::NoTrajectory);
  EXPECT_EQ(out.brake, 1.0);
  EXPECT_EQ(out.steering_angle, 0.0);
}

TEST(Controller, HintKeepsTheProjectionOnItsOwnLeg) {
  // a hairpin: out along y = 0, a half circle of radius 1.5, back along y = 3
  Trajectory t;
  auto add = [&t](double x, double y, double heading, double curvature) {
    TrajectoryPoint p;
    p.x = x;
    p.y = y;
    p.heading = heading;
    p.curvature = curvature;
    p.speed = 5.0;
    t.points.push_back(p);
  };
  for (int i = 0; i < 100; ++i) add(0.5 * i, 0.0, 0.0, 0.0);         // x 0 .. 49.5
  for (int i = 0; i < 9; ++i) {                                       // the turn, 0.52 m steps
    const double a = -0.5 * kPi + kPi * i / 9.0;
    add(50.0 + 1.5 * std::cos(a), 1.5 + 1.5 * std::sin(a), a + 0.5 * kPi, 1.0 / 1.5);
  }
  for (int i = 0; i < 100; ++i) add(50.0 - 0.5 * i, 3.0, kPi, 0.0);  // back to x 0.5
  // equal spacing is what Trajectory promises; these are close enough for the projection
  for (std::size_t i = 0; i < t.points.size(); ++i) t.points[i].s = 0.5 * static_cast<double>(i);
  t.length = 0.5 * static_cast<double>(t.points.size() - 1);

  Controller c;
  ASSERT_EQ(c.update(input_at(t, 20.0, 0.0, 0.0, 5.0)).status, Status::Ok);
  // 1.6 m left of the outward leg, 1.4 m from the return leg: stays on its leg
  const ControlOutput out = c.update(input_at(t, 20.05, 1.6, 0.0, 5.0));
  EXPECT_NEAR(out.diagnostics.s, 20.05, 0.1);
  EXPECT_NEAR(out.diagnostics.lateral_error, 1.6, 1e-9);
  // a fresh controller, searching everything, takes the nearer return leg
  Controller fresh;
  EXPECT_GT(fresh.update(input_at(t, 20.05, 1.6, 0.0, 5.0)).diagnostics.s, 60.0);
}

TEST(Controller, SpeedReferenceIsPreviewedAndCapped) {
  // the reference speed grows with s: speed = 5 + 0.1 s
  Trajectory t = straight(0.0, 100.0, 0.0);
  for (auto& p : t.points) p.speed = 5.0 + 0.1 * p.s;
  ControlParams p;
  Controller c(p);
  const ControlOutput out = c.update(input_at(t, 30.0, 0.0, 0.0, 10.0));
  const double s_preview = 30.0 + 10.0 * p.longitudinal.speed_preview_time;
  EXPECT_NEAR(out.diagnostics.s, 30.0, 1e-9);
  EXPECT_NEAR(out.diagnostics.v_ref, 5.0 + 0.1 * s_preview, 1e-9);
  EXPECT_NEAR(out.diagnostics.a_ref, (5.0 + 0.1 * s_preview) * 0.1, 1e-9);  // v dv/ds
  // a cap below the reference rules, with no acceleration fed forward
  ControlInput capped = input_at(t, 30.0, 0.0, 0.0, 10.0);
  capped.max_speed = 4.0;
  const ControlOutput co = Controller(p).update(capped);
  EXPECT_DOUBLE_EQ(co.diagnostics.v_ref, 4.0);
  EXPECT_EQ(co.diagnostics.a_ref, 0.0);
  EXPECT_GT(co.brake, 0.0);
  EXPECT_EQ(co.throttle, 0.0);
}

TEST(Controller, ZeroCapAtStandstillHoldsFullBrake) {
  const Trajectory t = straight(-10.0, 100.0, 10.0);
  ControlInput in = input_at(t, 0.0, 0.0, 0.0, 0.05);
  in.max_speed = 0.0;
  const ControlOutput out = Controller().update(in);
  EXPECT_EQ(out.status, Status::Ok);
  EXPECT_EQ(out.brake, 1.0);
  EXPECT_EQ(out.throttle, 0.0);
}

// the kinematic closed loop: a bicycle at its rear axle, x' = v cos(psi),
// y' = v sin(psi), psi' = v tan(delta) / L, integrated at 1 kHz with the
// controller at 100 Hz, at a constant 8 m/s on a circle of R = 15 m, from
// 1 m off the path (outside or inside) and tangent to it
class CircleLoop : public ::testing::TestWithParam<std::tuple<LateralMode, double>> {};

TEST_P(CircleLoop, ConvergesWithinTenSeconds) {
  const LateralMode m = std::get<0>(GetParam());
  const double offset = std::get<1>(GetParam());  // > 0 outside (right of a left circle)
  const double R = 15.0, v = 8.0;
  const Trajectory t = circle(R, v);
  Controller c(mode(m));
  const double L = c.vehicle().wheelbase;

  double x = R + offset, y = 0.0, psi = 0.5 * kPi;
  double delta = 0.0;
  double worst_last_second = 0.0;
  double first_within = -1.0;
  for (int k = 0; k < 1000; ++k) {  // 10 s of control cycles
    ControlInput in;
    in.dt = 0.01;
    in.base_pose = {x, y, psi};
    in.vx = v;
    in.yaw_rate = v * std::tan(delta) / L;
    in.trajectory = &t;
    const ControlOutput out = c.update(in);
    ASSERT_EQ(out.status, Status::Ok);
    const double err = std::abs(out.diagnostics.lateral_error);
    if (err < 0.15 && first_within < 0.0) first_within = 0.01 * k;
    if (err >= 0.15) first_within = -1.0;
    if (k >= 900) worst_last_second = std::max(worst_last_second, err);
    delta = out.steering_angle;
    for (int j = 0; j < 10; ++j) {
      x += 0.001 * v * std::cos(psi);
      y += 0.001 * v * std::sin(psi);
      psi += 0.001 * v * std::tan(delta) / L;
    }
  }
  EXPECT_LT(worst_last_second, 0.15) << to_string(m) << " offset " << offset;
  EXPECT_GE(first_within, 0.0);
  EXPECT_LT(first_within, 10.0);
  RecordProperty("settled_at_s", std::to_string(first_within));
  RecordProperty("final_error_m", std::to_string(worst_last_second));
}

INSTANTIATE_TEST_SUITE_P(AllModes, CircleLoop,
                         ::testing::Combine(::testing::ValuesIn(kModes), ::testing::Values(1.0, -1.0)),
                         [](const ::testing::TestParamInfo<CircleLoop::ParamType>& param_info) {
                           return std::string(to_string(std::get<0>(param_info.param))) +
                                  (std::get<1>(param_info.param) > 0.0 ? "_outside" : "_inside");
                         });

}  // namespace
}  // namespace paddock::control
