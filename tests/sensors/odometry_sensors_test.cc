// the wheel-speed and steering-angle sensors, checked against independent
// references: sample statistics of the configured noise (with Sheppard's
// correction res^2 / 12 once quantised), brute-force nearest multiples, and
// the physics of an encoder at rest.
#include "sim/sensors/odometry_sensors.h"
#include "tests/sensors/sample_stats.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace paddock::sensors {
namespace {

using testing::Stats;
using testing::stats;

// v is step * k for an integer k, exactly as the sensor writes it
bool exact_multiple(double v, double step) { return v == step * std::round(v / step); }

TEST(WheelSpeedParams, DefaultsAreValidAndValidateNamesTheField) {
  EXPECT_EQ(params::validate(WheelSpeedParams{}), "");
  WheelSpeedParams p;
  p.rate = -1.0;
  EXPECT_EQ(params::validate(p), "rate must be in [1, 10000] Hz (got -1)");
  p = {};
  p.noise = -0.5;
  EXPECT_EQ(params::validate(p), "noise must be in [0, 100] rad/s (got -0.5)");
  p = {};
  p.resolution = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(params::validate(p).substr(0, 11), "resolution ");
  EXPECT_THROW(WheelSpeedSensor(p, 1), std::invalid_argument);
  EXPECT_NO_THROW(WheelSpeedSensor(WheelSpeedParams{}, 1));
  EXPECT_EQ(WheelSpeedSensor(WheelSpeedParams{}, 1).period_ns(), 10'000'000);
}

TEST(SteeringSensorParams, DefaultsAreValidAndValidateNamesTheField) {
  EXPECT_EQ(params::validate(SteeringSensorParams{}), "");
  SteeringSensorParams p;
  p.rate = std::numeric_limits<double>::infinity();
  EXPECT_EQ(params::validate(p).substr(0, 5), "rate ");
  p = {};
  p.noise = -1.0;
  EXPECT_EQ(params::validate(p), "noise must be in [0, 1] rad (got -1)");
  p = {};
  p.resolution = -1e-3;
  EXPECT_EQ(params::validate(p).substr(0, 11), "resolution ");
  p = {};
  p.offset = 2.0;
  EXPECT_EQ(params::validate(p), "offset must be in [-1.5, 1.5] rad (got 2)");
  EXPECT_THROW(SteeringSensor(p, 1), std::invalid_argument);
}

TEST(WheelSpeedSensor, NoiseStdMatchesOver20000Samples) {
  WheelSpeedParams p;
  p.noise = 0.2;
  p.resolution = 0.0;  // no quantisation: the raw noise
  WheelSpeedSensor sensor(p, 11);
  std::array<std::vector<double>, 4> v;
  const std::array<double, 4> truth = {50.0, 51.0, -20.0, 49.5};
  for (int k = 0; k < 20000; ++k) {
    const WheelSpeedSample s = sensor.measure(truth, k * sensor.period_ns());
    for (std::size_t i = 0; i < 4; ++i) v[i].push_back(s.omega[i]);
  }
  for (std::size_t i = 0; i < 4; ++i) {
    const Stats st = stats(v[i]);
    EXPECT_NEAR(st.stddev, p.noise, 0.05 * p.noise) << "wheel " << i;
    EXPECT_NEAR(st.mean, truth[i], 5.0 * p.noise / std::sqrt(20000.0)) << "wheel " << i;
  }
}

TEST(WheelSpeedSensor, QuantisedNoiseFollowsSheppardsCorrection) {
  // default noise 0.05 and resolution 0.0767 rad/s: var = noise^2 + res^2 / 12
  const WheelSpeedParams p;
  WheelSpeedSensor sensor(p, 12);
  std::vector<double> v;
  for (int k = 0; k < 20000; ++k) v.push_back(sensor.measure({40.0123, 1.0, 1.0, 1.0}, 0).omega[0]);
  const double expected = std::sqrt(p.noise * p.noise + p.resolution * p.resolution / 12.0);
  EXPECT_NEAR(stats(v).stddev, expected, 0.05 * expected);
}

TEST(WheelSpeedSensor, OutputsAreExactMultiplesOfTheResolutionAndTheNearest) {
  WheelSpeedParams p;
  p.noise = 0.0;
  p.resolution = 0.0767;
  WheelSpeedSensor sensor(p, 13);
  for (int k = -2000; k <= 2000; ++k) {
    const double w = 0.01237 * k;
    const WheelSpeedSample s = sensor.measure({w, w, w, w}, 0);
    for (double o : s.omega) {
      ASSERT_TRUE(exact_multiple(o, p.resolution)) << o;
      // brute force: no other multiple is nearer to the truth
      const double n = std::round(o / p.resolution);
      ASSERT_LE(std::abs(o - w), std::abs((n - 1.0) * p.resolution - w) + 1e-12);
      ASSERT_LE(std::abs(o - w), std::abs((n + 1.0) * p.resolution - w) + 1e-12);
    }
  }
  // with noise too
  WheelSpeedSensor noisy(WheelSpeedParams{}, 14);
  for (int k = 0; k < 2000; ++k) {
    for (double o : noisy.measure({10.0, 3.3, -7.1, 0.02}, 0).omega) {
      ASSERT_TRUE(exact_multiple(o, WheelSpeedParams{}.resolution)) << o;
    }
  }
}

TEST(WheelSpeedSensor, AWheelAtRestReadsExactlyZero) {
  // a real encoder that turns sees no edges and counts none: no noise at rest
  WheelSpeedParams p;
  p.noise = 1.0;  // large: any leak would show
  WheelSpeedSensor sensor(p, 15);
  for (int k = 0; k < 5000; ++k) {
    const WheelSpeedSample s = sensor.measure({0.0, -0.0, 0.0, 0.0}, 0);
    for (double o : s.omega) {
      ASSERT_EQ(o, 0.0);
      ASSERT_FALSE(std::signbit(o));
    }
  }
}

TEST(WheelSpeedSensor, NoiseNeverReversesAWheel) {
  WheelSpeedParams p;
  p.noise = 1.0;
  WheelSpeedSensor sensor(p, 16);
  for (int k = 0; k < 5000; ++k) {
    const WheelSpeedSample s = sensor.measure({0.1, -0.1, 0.01, -0.01}, 0);
    EXPECT_GE(s.omega[0], 0.0);
    EXPECT_LE(s.omega[1], 0.0);
    EXPECT_GE(s.omega[2], 0.0);
    EXPECT_LE(s.omega[3], 0.0);
    for (double o : s.omega) ASSERT_FALSE(o == 0.0 && std::signbit(o));
  }
}

TEST(WheelSpeedSensor, AStoppedWheelDoesNotReshuffleTheOthers) {
  WheelSpeedSensor a(WheelSpeedParams{}, 17), b(WheelSpeedParams{}, 17);
  for (int k = 0; k < 100; ++k) {
    const WheelSpeedSample sa = a.measure({10.0, 10.0, 10.0, 10.0}, 0);
    const WheelSpeedSample sb = b.measure({0.0, 10.0, 10.0, 10.0}, 0);
    EXPECT_EQ(sb.omega[0], 0.0);
    for (std::size_t i = 1; i < 4; ++i) ASSERT_EQ(sa.omega[i], sb.omega[i]);
  }
}

TEST(WheelSpeedSensor, SameSeedSameSamples) {
  WheelSpeedSensor a(WheelSpeedParams{}, 18), b(WheelSpeedParams{}, 18), c(WheelSpeedParams{}, 19);
  bool differs = false;
  for (int k = 0; k < 1000; ++k) {
    const std::array<double, 4> w = {20.0 + 0.01 * k, 20.0, 19.0, 21.0};
    const WheelSpeedSample sa = a.measure(w, k), sb = b.measure(w, k), sc = c.measure(w, k);
    ASSERT_EQ(sa.stamp, k);
    ASSERT_EQ(sa.omega, sb.omega);
    differs = differs || sa.omega != sc.omega;
  }
  EXPECT_TRUE(differs);
}

TEST(WheelSpeedSensor, NanInputReadsNanAndDoesNotCrash) {
  WheelSpeedSensor sensor(WheelSpeedParams{}, 20);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const WheelSpeedSample s = sensor.measure({nan, 10.0, nan, 10.0}, 0);
  EXPECT_TRUE(std::isnan(s.omega[0]));
  EXPECT_TRUE(std::isfinite(s.omega[1]));
  EXPECT_TRUE(std::isnan(s.omega[2]));
  const WheelSpeedSample next = sensor.measure({10.0, 10.0, 10.0, 10.0}, 1);
  for (double o : next.omega) EXPECT_TRUE(std::isfinite(o));
}

TEST(SteeringSensor, NoiseStdAndOffsetMatchOver20000Samples) {
  SteeringSensorParams p;
  p.noise = 2e-3;
  p.resolution = 0.0;
  p.offset = 0.01;
  SteeringSensor sensor(p, 21);
  std::vector<double> v;
  for (int k = 0; k < 20000; ++k) v.push_back(sensor.measure(0.2, k * sensor.period_ns()).angle);
  const Stats st = stats(v);
  EXPECT_NEAR(st.stddev, p.noise, 0.05 * p.noise);
  EXPECT_NEAR(st.mean, 0.21, 5.0 * p.noise / std::sqrt(20000.0));
}

TEST(SteeringSensor, OutputsAreExactMultiplesOfTheResolution) {
  const SteeringSensorParams p;  // defaults: noise and resolution on
  SteeringSensor sensor(p, 22);
  for (int k = -1000; k <= 1000; ++k) {
    const double a = 0.000413 * k;
    const double o = sensor.measure(a, 0).angle;
    ASSERT_TRUE(exact_multiple(o, p.resolution)) << o;
    // noise 0.5 mrad: within 6 sigma plus half a step of the truth
    ASSERT_NEAR(o, a, 6.0 * p.noise + 0.5 * p.resolution);
  }
  // noise off: the nearest multiple
  SteeringSensorParams q;
  q.noise = 0.0;
  SteeringSensor exact(q, 23);
  EXPECT_EQ(exact.measure(0.0, 0).angle, 0.0);
  EXPECT_LE(std::abs(exact.measure(0.1234567, 0).angle - 0.1234567), 0.5 * q.resolution);
}

TEST(SteeringSensor, SameSeedSameSamplesAndNanDoesNotCrash) {
  SteeringSensor a(SteeringSensorParams{}, 24), b(SteeringSensorParams{}, 24);
  for (int k = 0; k < 1000; ++k) {
    const double angle = 0.3 * std::sin(0.01 * k);
    const SteeringSample sa = a.measure(angle, k), sb = b.measure(angle, k);
    ASSERT_EQ(sa.stamp, k);
    ASSERT_EQ(sa.angle, sb.angle);
  }
  EXPECT_TRUE(std::isnan(a.measure(std::numeric_limits<double>::quiet_NaN(), 0).angle));
  EXPECT_TRUE(std::isfinite(a.measure(0.1, 1).angle));
}

}  // namespace
}  // namespace paddock::sensors
