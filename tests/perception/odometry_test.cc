// the dead-reckoning odometry against the analytic motion: a constant speed
// and yaw rate make a circular arc, x = v/w sin(w t), y = v/w (1 - cos(w t)).
#include "autonomy/perception/odometry.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace paddock::perception {
namespace {

constexpr double kTrackRear = 1.2;  // m, the default vehicle's rear track

// exact messages of a constant motion: IMU at 200 Hz, wheel speeds at 100 Hz
void feed(Odometry& odo, double v, double w, TimeNs from, TimeNs to) {
  const double r = odo.params().wheel_radius;
  for (TimeNs t = from; t <= to; t += 5'000'000) {
    odo.add(hal::Imu{t, 0.0, v * w, w});
    if ((t - from) % 10'000'000 == 0) {
      // rear wheels at -+ track/2: v -+ w track/2; the front ones are ignored
      hal::WheelSpeeds ws{t, {123.0, -7.0, (v - w * 0.5 * kTrackRear) / r, (v + w * 0.5 * kTrackRear) / r}};
      odo.add(ws);
    }
  }
}

TEST(OdometryTest, ConstantTurnGivesTheAnalyticArc) {
  Odometry odo;
  const double v = 10.0, w = 1.0;
  feed(odo, v, w, 0, from_seconds(1.0));
  for (const auto& [a, b] : {std::pair{0.2, 0.5}, std::pair{0.5, 0.2}, std::pair{0.31, 0.3125}, std::pair{0.0, 1.0}}) {
    const std::optional<Pose2> rel = odo.relative(from_seconds(a), from_seconds(b));
    ASSERT_TRUE(rel.has_value()) << a << " -> " << b;
    const double th = w * (b - a);
    EXPECT_NEAR(rel->x, v / w * std::sin(th), 1e-3);
    EXPECT_NEAR(rel->y, v / w * (1.0 - std::cos(th)), 1e-3);
    EXPECT_NEAR(rel->yaw, th, 1e-6);
  }
}

// a sliding car: the rear axle also moves sideways at u (the estimator's vy,
// handed in with each IMU sample as the stack does). The body-frame velocity
// (v, u) turns with the base, so from a pose the displacement after t is
//   x = (v sin(w t) - u (1 - cos(w t))) / w,  y = (v (1 - cos(w t)) + u sin(w t)) / w
// (the integral of R(w s) (v, u) ds), and without u the arc is off by u t
TEST(OdometryTest, LateralVelocityFromTheEstimateBendsTheArc) {
  const double v = 20.0, w = 0.6, u = -1.5;
  OdometryParams p;
  p.lateral_velocity = true;
  Odometry odo(p);
  const double r = odo.params().wheel_radius;
  for (TimeNs t = 0; t <= from_seconds(1.0); t += 5'000'000) {
    odo.add(hal::StateEstimate{t, Pose2{}, v, u, w});
    odo.add(hal::Imu{t, 0.0, v * w, w});
    if (t % 10'000'000 == 0) odo.add(hal::WheelSpeeds{t, {0.0, 0.0, (v - w * 0.6) / r, (v + w * 0.6) / r}});
  }
  for (const auto& [a, b] : {std::pair{0.2, 0.3}, std::pair{0.5, 0.2}, std::pair{0.31, 0.3125}, std::pair{0.0, 1.0}}) {
    const std::optional<Pose2> rel = odo.relative(from_seconds(a), from_seconds(b));
    ASSERT_TRUE(rel.has_value()) << a << " -> " << b;
    const double th = w * (b - a);
    EXPECT_NEAR(rel->x, (v * std::sin(th) - u * (1.0 - std::cos(th))) / w, 1e-3) << a << " -> " << b;
    EXPECT_NEAR(rel->y, (v * (1.0 - std::cos(th)) + u * std::sin(th)) / w, 1e-3) << a << " -> " << b;
    EXPECT_NEAR(rel->yaw, th, 1e-6);
  }
  // one rotation's (0.1 s) lateral displacement is the 15 cm the correction needs
  const std::optional<Pose2> scan = odo.relative(from_seconds(0.4), from_seconds(0.5));
  ASSERT_TRUE(scan.has_value());
  EXPECT_NEAR(scan->y - v / w * (1.0 - std::cos(w * 0.1)), u * 0.1, 2e-3);
  // a non-finite estimate is refused, and counted
  const std::size_t before = odo.rejected();
  odo.add(hal::StateEstimate{from_seconds(1.0), Pose2{}, v, std::numeric_limits<double>::quiet_NaN(), w});
  EXPECT_EQ(odo.rejected(), before + 1);
  // off (the default): the estimate is not taken, the arc is the kinematic one
  Odometry kinematic;
  for (TimeNs t = 0; t <= from_seconds(0.5); t += 5'000'000) {
    kinematic.add(hal::StateEstimate{t, Pose2{}, v, u, w});
    kinematic.add(hal::Imu{t, 0.0, v * w, w});
    if (t % 10'000'000 == 0) kinematic.add(hal::WheelSpeeds{t, {0.0, 0.0, (v - w * 0.6) / r, (v + w * 0.6) / r}});
  }
  const std::optional<Pose2> k = kinematic.relative(from_seconds(0.4), from_seconds(0.5));
  ASSERT_TRUE(k.has_value());
  EXPECT_NEAR(k->y, v / w * (1.0 - std::cos(w * 0.1)), 1e-6);
}

TEST(OdometryTest, StraightLineAndExtrapolationLimits) {
  OdometryParams p;
  p.extrapolation = 0.02;
  Odometry odo(p);
  feed(odo, 5.0, 0.0, from_seconds(1.0), from_seconds(2.0));
  const std::optional<Pose2> rel = odo.relative(from_seconds(1.5), from_seconds(2.01));
  ASSERT_TRUE(rel.has_value());
  EXPECT_NEAR(rel->x, 5.0 * 0.51, 1e-9);
  EXPECT_NEAR(rel->y, 0.0, 1e-12);
  EXPECT_FALSE(odo.relative(from_seconds(1.5), from_seconds(2.05)).has_value());
  EXPECT_FALSE(odo.relative(from_seconds(0.9), from_seconds(1.5)).has_value());
  EXPECT_TRUE(odo.relative(from_seconds(0.99), from_seconds(1.5)).has_value());
}

TEST(OdometryTest, HistoryIsBoundedAndBadMessagesAreIgnored) {
  OdometryParams p;
  p.history = 0.5;
  Odometry odo(p);
  EXPECT_FALSE(odo.relative(0, 0).has_value());  // nothing yet
  feed(odo, 3.0, 0.2, 0, from_seconds(2.0));
  EXPECT_FALSE(odo.relative(from_seconds(1.0), from_seconds(2.0)).has_value());
  EXPECT_TRUE(odo.relative(from_seconds(1.6), from_seconds(2.0)).has_value());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  odo.add(hal::Imu{from_seconds(2.001), 0.0, 0.0, nan});
  odo.add(hal::WheelSpeeds{from_seconds(2.002), {0.0, 0.0, nan, 1.0}});
  odo.add(hal::Imu{from_seconds(1.0), 0.0, 0.0, 0.0});  // backwards in time
  EXPECT_EQ(odo.rejected(), 3u);
  const std::optional<Pose2> rel = odo.relative(from_seconds(1.8), from_seconds(2.0));
  ASSERT_TRUE(rel.has_value());
  EXPECT_NEAR(rel->yaw, 0.2 * 0.2, 1e-9);
}

TEST(OdometryTest, ValidateNamesTheField) {
  OdometryParams p;
  EXPECT_EQ(params::validate(p), "");
  p.wheel_radius = -1.0;
  EXPECT_EQ(params::validate(p), "wheel_radius must be > 0 m (got -1)");
  p = OdometryParams{};
  p.history = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(params::validate(p), "history must be > 0 s (got nan)");
}

// same_state: two odometries fed the same messages answer alike, and are
// the same; one more message, another value's sign, or other params: not
TEST(OdometryTest, SameStateIsTheSameMessagesAndParams) {
  Odometry a, b;
  feed(a, 10.0, 0.5, 0, 1'000'000'000);
  feed(b, 10.0, 0.5, 0, 1'000'000'000);
  EXPECT_TRUE(a.same_state(b));
  Odometry c = a;
  EXPECT_TRUE(c.same_state(a));
  c.add(hal::Imu{1'002'000'000, 0.0, 0.0, 0.5});
  EXPECT_FALSE(c.same_state(a));
  EXPECT_FALSE(a.same_state(c));
  // a yaw rate of -0.0 against 0.0: equal as numbers, not as bits
  Odometry z0, z1;
  z0.add(hal::Imu{0, 0.0, 0.0, 0.0});
  z1.add(hal::Imu{0, 0.0, 0.0, -0.0});
  EXPECT_FALSE(z0.same_state(z1));
  OdometryParams longer;
  longer.history = 3.0;
  Odometry d(longer);
  feed(d, 10.0, 0.5, 0, 1'000'000'000);
  EXPECT_FALSE(d.same_state(a));
  // a rejected message leaves the state alone
  Odometry e = a;
  e.add(hal::Imu{500'000'000, 0.0, 0.0, std::numeric_limits<double>::quiet_NaN()});
  EXPECT_EQ(e.rejected(), a.rejected() + 1);
  EXPECT_TRUE(e.same_state(a));
}

}  // namespace
}  // namespace paddock::perception
