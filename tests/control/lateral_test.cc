// the lateral laws against the ORACLES figures, and the look-ahead search.
#include "autonomy/control/lateral.h"

#include <gtest/gtest.h>

#include <cmath>

namespace paddock::control {
namespace {

constexpr double kTol = 1e-6;

// ORACLES "Controllers": k = 2.5, k_soft = 1
TEST(Stanley, MatchesOracles) {
  EXPECT_NEAR(stanley_steer(0.0, 0.5, 10.0, 2.5, 1.0), 0.113151, kTol);
  EXPECT_NEAR(stanley_steer(0.1, -0.3, 5.0, 2.5, 1.0), -0.024355, kTol);
  EXPECT_NEAR(stanley_steer(0.0, 1.0, 0.0, 2.5, 1.0), 1.190290, kTol);
}

TEST(Stanley, SignsFollowIso) {
  // path to the left -> steer left; path heading left of the car -> steer left
  EXPECT_GT(stanley_steer(0.0, 0.3, 5.0, 2.5, 1.0), 0.0);
  EXPECT_GT(stanley_steer(0.1, 0.0, 5.0, 2.5, 1.0), 0.0);
  EXPECT_LT(stanley_steer(-0.1, -0.3, 5.0, 2.5, 1.0), 0.0);
}

// ORACLES: L = 1.53, k_v = 0.1, L_min = 2.0
TEST(PurePursuit, MatchesOracles) {
  const double ld1 = lookahead_distance(10.0, 2.0, 0.1);
  EXPECT_NEAR(ld1, 3.00, kTol);
  EXPECT_NEAR(pure_pursuit_steer(0.1, ld1, 1.53), 0.101480, kTol);
  const double ld2 = lookahead_distance(5.0, 2.0, 0.1);
  EXPECT_NEAR(ld2, 2.50, kTol);
  EXPECT_NEAR(pure_pursuit_steer(0.3, ld2, 1.53), 0.347075, kTol);
}

TEST(PurePursuit, LookaheadIgnoresReverseSpeed) {
  EXPECT_DOUBLE_EQ(lookahead_distance(-3.0, 2.0, 0.1), 2.0);
}

TEST(PurePursuit, FollowsTheCircleThroughTheLookaheadPoint) {
  // a rear axle on a circle of radius R, heading along it: the point L_d ahead
  // on the circle lies at alpha = asin(L_d / 2R), and the law returns atan(L / R)
  const double R = 15.0, L = 1.53, L_d = 3.7;
  const double alpha = std::asin(L_d / (2.0 * R));
  EXPECT_NEAR(pure_pursuit_steer(alpha, L_d, L), std::atan(L / R), 1e-12);
}

TEST(CombinedWeight, LinearBetweenTheLimits) {
  // k_min 0.2, k_max 0.8, kappa_ref 0.1, k_curve 0.6
  EXPECT_DOUBLE_EQ(combined_weight(0.0, 0.2, 0.8, 0.1, 0.6), 0.2);
  EXPECT_NEAR(combined_weight(0.05, 0.2, 0.8, 0.1, 0.6), 0.5, 1e-12);
  EXPECT_NEAR(combined_weight(-0.05, 0.2, 0.8, 0.1, 0.6), 0.5, 1e-12);  // |kappa|
  EXPECT_DOUBLE_EQ(combined_weight(0.1, 0.2, 0.8, 0.1, 0.6), 0.8);
}

TEST(CombinedWeight, ClampsBetweenKminAndKmax) {
  for (double kappa = -1.0; kappa <= 1.0; kappa += 0.01) {
    const double k = combined_weight(kappa, 0.2, 0.8, 0.1, 0.6);
    EXPECT_GE(k, 0.2);
    EXPECT_LE(k, 0.8);
  }
  EXPECT_DOUBLE_EQ(combined_weight(10.0, 0.2, 0.8, 0.1, 0.6), 0.8);
  // and into [0, 1] whatever the parameters
  EXPECT_DOUBLE_EQ(combined_weight(0.0, -0.5, 0.8, 0.1, 0.6), 0.0);
  EXPECT_DOUBLE_EQ(combined_weight(10.0, 0.2, 1.5, 0.1, 0.6), 1.0);
}

TEST(SteadyStateYaw, MatchesHoffmannFormula) {
  // m r v / (C_y (1 + lf/lr)); gotthard in a 15 m circle at 8 m/s
  const double C_y = front_axle_cornering_stiffness(12.56, 1.38, 1.60, 190.0, 0.765, 0.765);
  EXPECT_NEAR(C_y, 25845.284736, 1e-3);
  const double r = 8.0 / 15.0;
  EXPECT_NEAR(steady_state_yaw(190.0, r, 8.0, C_y, 0.765, 0.765), 190.0 * r * 8.0 / (C_y * 2.0), 1e-15);
  // signed like the yaw rate of the trajectory
  EXPECT_GT(steady_state_yaw(190.0, r, 8.0, C_y, 0.765, 0.765), 0.0);
  EXPECT_LT(steady_state_yaw(190.0, -r, 8.0, C_y, 0.765, 0.765), 0.0);
  // a rear-heavy car (lf > lr) loads the front axle less: a smaller angle
  EXPECT_LT(steady_state_yaw(190.0, r, 8.0, C_y, 0.9, 0.63),
            steady_state_yaw(190.0, r, 8.0, C_y, 0.63, 0.9));
}

// an open straight along +x from x0, ds 0.5
Trajectory straight(double x0, double length) {
  Trajectory t;
  const int n = static_cast<int>(std::lround(length / 0.5)) + 1;
  for (int i = 0; i < n; ++i) {
    TrajectoryPoint p;
    p.s = 0.5 * i;
    p.x = x0 + p.s;
    t.points.push_back(p);
  }
  t.length = 0.5 * (n - 1);
  return t;
}

TEST(Lookahead, IntersectsTheCircleOnAStraight) {
  const Trajectory t = straight(-10.0, 100.0);
  const Vec2 rear{3.2, -0.6};
  const LookAhead la = find_lookahead(t, rear, 13.2, 3.0);
  ASSERT_TRUE(la.found);
  EXPECT_NEAR(la.distance, 3.0, 1e-9);
  EXPECT_NEAR(la.point.y, 0.0, 1e-12);
  EXPECT_NEAR(la.point.x, 3.2 + std::sqrt(9.0 - 0.36), 1e-9);
  EXPECT_NEAR(la.s, la.point.x + 10.0, 1e-9);
}

TEST(Lookahead, FallsBackWhenFarFromThePath) {
  const Trajectory t = straight(0.0, 100.0);
  const LookAhead la = find_lookahead(t, {20.0, -5.0}, 20.0, 3.0);
  EXPECT_FALSE(la.found);
  EXPECT_NEAR(la.s, 23.0, 1e-9);
  EXPECT_NEAR(la.point.x, 23.0, 1e-9);
}

TEST(Lookahead, StopsAtTheEndOfAnOpenPath) {
  const Trajectory t = straight(0.0, 10.0);
  const LookAhead la = find_lookahead(t, {9.0, 0.0}, 9.0, 3.0);
  EXPECT_FALSE(la.found);
  EXPECT_NEAR(la.s, 10.0, 1e-9);
  EXPECT_NEAR(la.distance, 1.0, 1e-9);
}

TEST(Lookahead, WrapsAroundAClosedPath) {
  // a closed circle of radius 10, counter-clockwise from (10, 0)
  Trajectory t;
  const int n = 126;
  const double R = 10.0;
  const double chord = 2.0 * R * std::sin(kPi / n);
  for (int i = 0; i < n; ++i) {
    const double a = 2.0 * kPi * i / n;
    TrajectoryPoint p;
    p.s = chord * i;
    p.x = R * std::cos(a);
    p.y = R * std::sin(a);
    p.heading = wrap_angle(a + 0.5 * kPi);
    p.curvature = 1.0 / R;
    t.points.push_back(p);
  }
  t.closed = true;
  t.length = chord * n;
  // just before the seam
  const double s = t.length - 1.0;
  const Vec2 rear = t.at(s).position();
  const LookAhead la = find_lookahead(t, rear, s, 4.0);
  ASSERT_TRUE(la.found);
  EXPECT_NEAR(la.distance, 4.0, 1e-9);
  EXPECT_LT(la.s, 4.0);  // wrapped past s = 0
  EXPECT_NEAR(la.curvature, 0.1, 1e-12);
}

}  // namespace
}  // namespace paddock::control
