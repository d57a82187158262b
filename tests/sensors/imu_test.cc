// the IMU, checked against independent references: sample statistics of the
// configured noise, the Wiener-process law var(b(T)) = walk^2 T over many
// seeds, and the lever arm against a finite-difference of a point on a
// rotating rigid body.
#include "sim/sensors/imu.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "autonomy/common/time.h"
#include "tests/sensors/sample_stats.h"

namespace paddock::sensors {
namespace {

// an IMU with every random effect off and the sensor at the base origin
ImuParams perfect() {
  ImuParams p;
  p.accel_noise = 0.0;
  p.gyro_noise = 0.0;
  p.accel_bias_walk = 0.0;
  p.gyro_bias_walk = 0.0;
  p.accel_bias_initial_std = 0.0;
  p.gyro_bias_initial_std = 0.0;
  p.mount_x = 0.0;
  p.mount_y = 0.0;
  return p;
}

using testing::Stats;
using testing::stats;

TEST(ImuParams, DefaultsAreValid) { EXPECT_EQ(params::validate(ImuParams{}), ""); }

TEST(ImuParams, ValidateNamesTheField) {
  auto first_word = [](const ImuParams& p) {
    const std::string msg = params::validate(p);
    return msg.substr(0, msg.find(' '));
  };
  ImuParams p;
  p.rate = 0.0;
  EXPECT_EQ(params::validate(p), "rate must be in [1, 10000] Hz (got 0)");
  p = {};
  p.gyro_noise = -1.0;
  EXPECT_EQ(params::validate(p), "gyro_noise must be in [0, 10] rad/s (got -1)");
  p = {};
  p.accel_noise = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(first_word(p), "accel_noise");
  p = {};
  p.accel_bias_walk = -1e-3;
  EXPECT_EQ(first_word(p), "accel_bias_walk");
  p = {};
  p.gyro_bias_walk = std::numeric_limits<double>::infinity();
  EXPECT_EQ(first_word(p), "gyro_bias_walk");
  p = {};
  p.accel_bias_initial_std = -0.1;
  EXPECT_EQ(first_word(p), "accel_bias_initial_std");
  p = {};
  p.gyro_bias_initial_std = -0.1;
  EXPECT_EQ(first_word(p), "gyro_bias_initial_std");
  p = {};
  p.mount_x = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(first_word(p), "mount_x");
  EXPECT_THROW(Imu(p, 1), std::invalid_argument);
  EXPECT_NO_THROW(Imu(ImuParams{}, 1));
}

TEST(Imu, PeriodIsTheRate) { EXPECT_EQ(Imu(ImuParams{}, 1).period_ns(), 5'000'000); }

TEST(Imu, NoiseStdMatchesOver20000Samples) {
  ImuParams p = perfect();
  p.accel_noise = 0.03;
  p.gyro_noise = 0.004;
  Imu imu(p, 42);
  std::vector<double> ax, ay, gz;
  const TimeNs dt = imu.period_ns();
  for (int k = 0; k < 20000; ++k) {
    // a constant true motion at the base origin: the noise rides on it
    const ImuSample s = imu.measure(1.5, -0.5, 0.3, 0.0, k * dt);
    ax.push_back(s.ax);
    ay.push_back(s.ay);
    gz.push_back(s.gz);
  }
  const Stats sx = stats(ax), sy = stats(ay), sg = stats(gz);
  EXPECT_NEAR(sx.stddev, p.accel_noise, 0.05 * p.accel_noise);
  EXPECT_NEAR(sy.stddev, p.accel_noise, 0.05 * p.accel_noise);
  EXPECT_NEAR(sg.stddev, p.gyro_noise, 0.05 * p.gyro_noise);
  // unbiased: the mean within 5 standard errors
  EXPECT_NEAR(sx.mean, 1.5, 5.0 * p.accel_noise / std::sqrt(20000.0));
  EXPECT_NEAR(sy.mean, -0.5, 5.0 * p.accel_noise / std::sqrt(20000.0));
  EXPECT_NEAR(sg.mean, 0.3, 5.0 * p.gyro_noise / std::sqrt(20000.0));
}

TEST(Imu, TheOutOfPlaneAxesReadGravityPlusTheClimbWithTheirOwnNoiseAndBias) {
  ImuParams p = perfect();
  p.accel_noise = 0.03;
  p.gyro_noise = 0.004;
  Imu imu(p, 42);
  std::vector<double> az, gx, gy;
  const TimeNs dt = imu.period_ns();
  for (int k = 0; k < 20000; ++k) {
    const ImuSample s = imu.measure(1.5, -0.5, 0.3, 0.0, k * dt, -0.7);  // climbing less and less
    az.push_back(s.az);
    gx.push_back(s.gx);
    gy.push_back(s.gy);
  }
  const Stats sz = stats(az), sx = stats(gx), sy = stats(gy);
  EXPECT_NEAR(sz.stddev, p.accel_noise, 0.05 * p.accel_noise);
  EXPECT_NEAR(sx.stddev, p.gyro_noise, 0.05 * p.gyro_noise);
  EXPECT_NEAR(sy.stddev, p.gyro_noise, 0.05 * p.gyro_noise);
  // specific force: +g at rest, less when the point accelerates downwards
  EXPECT_NEAR(sz.mean, 9.81 - 0.7, 5.0 * p.accel_noise / std::sqrt(20000.0));
  // the car stays level: no roll or pitch rate
  EXPECT_NEAR(sx.mean, 0.0, 5.0 * p.gyro_noise / std::sqrt(20000.0));
  EXPECT_NEAR(sy.mean, 0.0, 5.0 * p.gyro_noise / std::sqrt(20000.0));
  // the out-of-plane noise is its own: not correlated with the planar axes'
  double c = 0.0;
  Imu again(p, 42);
  for (int k = 0; k < 20000; ++k) {
    const ImuSample s = again.measure(0.0, 0.0, 0.0, 0.0, k * dt);
    c += s.ax * (s.az - 9.81);
  }
  EXPECT_LT(std::abs(c / 20000.0) / (p.accel_noise * p.accel_noise), 0.05);
}

TEST(Imu, TheVerticalInputMovesTheVerticalAxisOnly) {
  // the planar axes draw from their own stream: a different vertical input
  // changes nothing in ax, ay, gz
  const ImuParams p;  // noise, walks, turn-on biases on
  Imu a(p, 7), b(p, 7);
  for (int k = 0; k < 1000; ++k) {
    const ImuSample sa = a.measure(0.4, 1.1, 0.2, 0.05, k * a.period_ns(), 0.0);
    const ImuSample sb = b.measure(0.4, 1.1, 0.2, 0.05, k * b.period_ns(), 3.0);
    ASSERT_EQ(sa.ax, sb.ax);
    ASSERT_EQ(sa.ay, sb.ay);
    ASSERT_EQ(sa.gz, sb.gz);
    ASSERT_NE(sa.az, sb.az);
  }
  EXPECT_NE(a.bias().az, 0.0);
  EXPECT_NE(a.bias().gx, a.bias().gy);
}

TEST(Imu, OutOfPlaneBiasRandomWalkVarianceGrowsAsWalkSquaredTimesT) {
  ImuParams p = perfect();
  p.accel_bias_walk = 0.05;
  p.gyro_bias_walk = 0.01;
  std::vector<double> az, gx;
  const TimeNs dt = from_seconds(0.005);
  for (int seed = 0; seed < 4000; ++seed) {
    Imu imu(p, static_cast<std::uint64_t>(seed) * 7919u + 1u);
    ImuSample s;
    for (TimeNs t = 0; t <= from_seconds(4.0); t += dt) s = imu.measure(0.0, 0.0, 0.0, 0.0, t);
    az.push_back(s.az - 9.81);
    gx.push_back(s.gx);
  }
  EXPECT_NEAR(stats(az).stddev * stats(az).stddev, 0.05 * 0.05 * 4.0, 0.10 * 0.05 * 0.05 * 4.0);
  EXPECT_NEAR(stats(gx).stddev * stats(gx).stddev, 0.01 * 0.01 * 4.0, 0.10 * 0.01 * 0.01 * 4.0);
}

// the variance over seeds of the bias (read through the noise-free output)
// at the times in `at`, for samples every `period` seconds
std::vector<double> bias_variance(const ImuParams& p, double period, const std::vector<double>& at, int seeds,
                                  bool gyro) {
  std::vector<std::vector<double>> values(at.size());
  const TimeNs dt = from_seconds(period);
  for (int seed = 0; seed < seeds; ++seed) {
    Imu imu(p, static_cast<std::uint64_t>(seed) * 7919u + 1u);
    std::size_t next = 0;
    for (TimeNs t = 0; next < at.size(); t += dt) {
      const ImuSample s = imu.measure(0.0, 0.0, 0.0, 0.0, t);
      if (t == from_seconds(at[next])) values[next++].push_back(gyro ? s.gz : s.ax);
    }
  }
  std::vector<double> var;
  for (const auto& v : values) var.push_back(stats(v).stddev * stats(v).stddev);
  return var;
}

TEST(Imu, GyroBiasRandomWalkVarianceGrowsAsWalkSquaredTimesT) {
  ImuParams p = perfect();
  p.gyro_bias_walk = 0.01;  // rad/s per sqrt(s)
  // 4000 seeds: the sample variance has a relative std of sqrt(2 / 4000) = 2.2 %
  const std::vector<double> at = {2.5, 10.0};
  const std::vector<double> var = bias_variance(p, 0.005, at, 4000, true);
  for (std::size_t i = 0; i < at.size(); ++i) {
    const double expected = p.gyro_bias_walk * p.gyro_bias_walk * at[i];
    EXPECT_NEAR(var[i], expected, 0.10 * expected) << "T = " << at[i];
  }
  // the law does not depend on the sample rate: 50 Hz gives the same growth
  const std::vector<double> var50 = bias_variance(p, 0.02, {10.0}, 4000, true);
  EXPECT_NEAR(var50[0], 0.01 * 0.01 * 10.0, 0.10 * 0.01 * 0.01 * 10.0);
}

TEST(Imu, AccelBiasRandomWalkVarianceGrowsAsWalkSquaredTimesT) {
  ImuParams p = perfect();
  p.accel_bias_walk = 0.05;  // m/s^2 per sqrt(s)
  const std::vector<double> var = bias_variance(p, 0.005, {4.0}, 4000, false);
  EXPECT_NEAR(var[0], 0.05 * 0.05 * 4.0, 0.10 * 0.05 * 0.05 * 4.0);
}

TEST(Imu, InitialBiasStdOverSeedsAndNoStepOnTheFirstSample) {
  ImuParams p = perfect();
  p.gyro_bias_initial_std = 0.01;
  p.gyro_bias_walk = 1.0;  // huge: any step on the first sample would show
  std::vector<double> first;
  for (int seed = 0; seed < 4000; ++seed) {
    Imu imu(p, static_cast<std::uint64_t>(seed) + 100u);
    const double b0 = imu.bias().gz;
    const ImuSample s = imu.measure(0.0, 0.0, 0.0, 0.0, 123'456'789);
    EXPECT_EQ(s.gz, b0);
    first.push_back(s.gz);
  }
  EXPECT_NEAR(stats(first).stddev, 0.01, 0.05 * 0.01);
}

TEST(Imu, LeverArmOneMetreAheadTurningAtOneRadPerSecond) {
  ImuParams p = perfect();
  p.mount_x = 1.0;
  Imu imu(p, 1);
  // zero base acceleration, constant 1 rad/s: the centripetal -omega^2 r
  const ImuSample s = imu.measure(0.0, 0.0, 1.0, 0.0, 0);
  EXPECT_DOUBLE_EQ(s.ax, -1.0);
  EXPECT_DOUBLE_EQ(s.ay, 0.0);
  EXPECT_DOUBLE_EQ(s.gz, 1.0);
}

// a point r on a body spinning about the base origin (which itself
// accelerates at a constant a0 in the map, with the body at yaw theta(t) =
// th0 + w0 t + alpha t^2 / 2): its map acceleration by a central second
// difference of its map position, rotated into the body frame. Nothing here
// uses the lever-arm formula.
TEST(Imu, LeverArmMatchesFiniteDifferenceOfARotatingBody) {
  const double rx = 1.3, ry = -0.4;             // m
  const double a0x = 0.7, a0y = -1.1;           // m/s^2, base origin, map frame
  const double th0 = 0.3, w0 = 0.8, alpha = -1.7;  // rad, rad/s, rad/s^2
  auto theta = [&](double t) { return th0 + w0 * t + 0.5 * alpha * t * t; };
  auto point = [&](double t, double& x, double& y) {
    const double th = theta(t), c = std::cos(th), s = std::sin(th);
    x = 0.5 * a0x * t * t + c * rx - s * ry;
    y = 0.5 * a0y * t * t + s * rx + c * ry;
  };
  const double t = 0.0, h = 1e-4;
  double xm, ym, x0, y0, xp, yp;
  point(t - h, xm, ym);
  point(t, x0, y0);
  point(t + h, xp, yp);
  const double amx = (xp - 2.0 * x0 + xm) / (h * h), amy = (yp - 2.0 * y0 + ym) / (h * h);
  const double c = std::cos(theta(t)), s = std::sin(theta(t));
  const double expect_x = c * amx + s * amy, expect_y = -s * amx + c * amy;

  ImuParams p = perfect();
  p.mount_x = rx;
  p.mount_y = ry;
  Imu imu(p, 1);
  // the base origin's acceleration in the body frame
  const double abx = c * a0x + s * a0y, aby = -s * a0x + c * a0y;
  const ImuSample m = imu.measure(abx, aby, w0, alpha, 0);
  EXPECT_NEAR(m.ax, expect_x, 1e-5);
  EXPECT_NEAR(m.ay, expect_y, 1e-5);
}

TEST(Imu, SameSeedSameSamplesOtherSeedOtherSamples) {
  const ImuParams p;  // defaults: every effect on
  Imu a(p, 7), b(p, 7), c(p, 8);
  bool differs = false;
  for (int k = 0; k < 1000; ++k) {
    const double w = 0.5 * std::sin(0.01 * k);
    const TimeNs t = k * a.period_ns();
    const ImuSample sa = a.measure(1.0, 0.2, w, 0.1, t);
    const ImuSample sb = b.measure(1.0, 0.2, w, 0.1, t);
    const ImuSample sc = c.measure(1.0, 0.2, w, 0.1, t);
    ASSERT_EQ(sa.stamp, t);
    ASSERT_EQ(sa.ax, sb.ax);
    ASSERT_EQ(sa.ay, sb.ay);
    ASSERT_EQ(sa.gz, sb.gz);
    differs = differs || sa.ax != sc.ax || sa.gz != sc.gz;
  }
  EXPECT_TRUE(differs);
}

TEST(Imu, NanInputGivesNanOutputAndLeavesTheBiasesAlone) {
  Imu imu(ImuParams{}, 3);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  imu.measure(0.0, 0.0, 0.0, 0.0, 0);
  const ImuSample s = imu.measure(nan, 0.0, nan, 0.0, 5'000'000);
  EXPECT_TRUE(std::isnan(s.ax));
  EXPECT_TRUE(std::isnan(s.gz));
  EXPECT_TRUE(std::isfinite(imu.bias().ax) && std::isfinite(imu.bias().ay) && std::isfinite(imu.bias().gz));
  const ImuSample next = imu.measure(0.0, 0.0, 0.0, 0.0, 10'000'000);
  EXPECT_TRUE(std::isfinite(next.ax) && std::isfinite(next.ay) && std::isfinite(next.gz));
}

TEST(Imu, AStampGoingBackwardsTakesNoStep) {
  ImuParams p = perfect();
  p.gyro_bias_walk = 1.0;
  Imu imu(p, 5);
  imu.measure(0.0, 0.0, 0.0, 0.0, 1'000'000'000);
  const double b = imu.bias().gz;
  imu.measure(0.0, 0.0, 0.0, 0.0, 500'000'000);
  EXPECT_EQ(imu.bias().gz, b);
}

}  // namespace
}  // namespace paddock::sensors
