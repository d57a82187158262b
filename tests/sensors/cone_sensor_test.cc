// the object-level cone sensor, checked against independent references: a
// brute-force visible set, hand-placed boundary and occlusion cases, and the
// configured noise, miss, colour and false-positive rates over many frames.
#include "sim/sensors/cone_sensor.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

namespace paddock::sensors {
namespace {

// every random effect off, no occlusion: the sensor should be an exact window
ConeSensorParams perfect() {
  ConeSensorParams p;
  p.occlusion = false;
  p.range_noise = 0.0;
  p.range_noise_per_m = 0.0;
  p.bearing_noise = 0.0;
  p.miss_probability = 0.0;
  p.miss_probability_growth = 0.0;
  p.unknown_color_probability = 0.0;
  p.unknown_color_growth = 0.0;
  p.color_flip_probability = 0.0;
  p.color_flip_growth = 0.0;
  p.false_positives_per_frame = 0.0;
  return p;
}

// a point given in the sensor's polar frame, in the map
Vec2 map_point(const ConeSensorParams& p, const Pose2& pose, double r, double bearing) {
  return pose.transform(Vec2{p.mount_x, p.mount_y} + r * unit_from_angle(bearing));
}

bool less_xy(const hal::DetectedCone& a, const hal::DetectedCone& b) {
  return a.position.x < b.position.x || (a.position.x == b.position.x && a.position.y < b.position.y);
}

TEST(ConeSensorParams, DefaultsAreValid) { EXPECT_EQ(params::validate(ConeSensorParams{}), ""); }

TEST(ConeSensorParams, ValidateNamesTheField) {
  auto first_word = [](const ConeSensorParams& p) {
    const std::string msg = params::validate(p);
    return msg.substr(0, msg.find(' '));
  };
  ConeSensorParams p;
  p.range_max = p.range_min;
  EXPECT_EQ(first_word(p), "range_max");
  p = {};
  p.fov = 7.0;
  EXPECT_EQ(first_word(p), "fov");
  p = {};
  p.range_noise = -0.01;
  EXPECT_EQ(first_word(p), "range_noise");
  p = {};
  p.bearing_noise = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(first_word(p), "bearing_noise");
  p = {};
  p.miss_probability_growth = 0.99;
  EXPECT_EQ(first_word(p), "miss_probability_growth");
  p = {};
  p.occlusion_fraction = 0.0;
  EXPECT_EQ(first_word(p), "occlusion_fraction");
  p = {};
  p.rate = 0.0;
  EXPECT_EQ(first_word(p), "rate");
  p = {};
  p.false_positives_per_frame = -1.0;
  EXPECT_EQ(first_word(p), "false_positives_per_frame");
  p = {};
  p.small_cone_radius = 0.0;  // set by the runner, not visited: check() has it
  EXPECT_EQ(params::validate(p), "small_cone_radius must be > 0 m (got 0)");
  EXPECT_THROW(ConeSensor(p, 1), std::invalid_argument);
  p = {};
  p.false_positives_per_frame = -1.0;
  EXPECT_THROW(ConeSensor(p, 1), std::invalid_argument);
  EXPECT_NO_THROW(ConeSensor(ConeSensorParams{}, 1));
}

TEST(ConeSensor, LatencyAndPeriodInNanoseconds) {
  ConeSensor sensor(ConeSensorParams{}, 1);
  EXPECT_EQ(sensor.latency_ns(), 100'000'000);
  EXPECT_EQ(sensor.period_ns(), 100'000'000);
}

// noise-free, every cone visible: the frame is exactly the brute-force set of
// cones in range and field of view, transformed into the base frame
TEST(ConeSensor, NoiseFreeEqualsBruteForce) {
  std::mt19937_64 gen(42);
  std::uniform_real_distribution<double> coord(-30.0, 30.0);
  const ConeColor colors[] = {ConeColor::Blue, ConeColor::Yellow, ConeColor::SmallOrange, ConeColor::BigOrange,
                              ConeColor::Unknown};
  std::vector<Cone> cones;
  for (int i = 0; i < 400; ++i) cones.push_back({{coord(gen), coord(gen)}, colors[i % 5]});

  struct Case {
    double fov, mount_y, range_min, range_max;
    Pose2 pose;
  };
  const Case cases[] = {
      {kPi, 0.0, 0.5, 20.0, {0.0, 0.0, 0.0}},
      {2.0 * kPi / 3.0, 0.3, 1.0, 15.0, {3.0, -4.0, 2.5}},
      {2.0 * kPi, -0.2, 0.0, 25.0, {-5.0, 7.0, -1.2}},
  };
  int total = 0;
  for (const Case& cs : cases) {
    ConeSensorParams p = perfect();
    p.fov = cs.fov;
    p.mount_y = cs.mount_y;
    p.range_min = cs.range_min;
    p.range_max = cs.range_max;
    ConeSensor sensor(p, 7);
    const hal::ConeDetections frame = sensor.measure(cones, {}, cs.pose, 123);
    EXPECT_EQ(frame.stamp, 123);

    // brute force: every cone, by the pose's inverse transform
    std::vector<hal::DetectedCone> expected;
    for (const Cone& c : cones) {
      const Vec2 b = cs.pose.inverse_transform(c.position);
      const Vec2 v = b - Vec2{p.mount_x, p.mount_y};
      const double r = norm(v);
      if (r >= p.range_min && r <= p.range_max && std::abs(angle_of(v)) <= 0.5 * p.fov)
        expected.push_back({b, c.color});
    }
    ASSERT_EQ(frame.cones.size(), expected.size());
    ASSERT_GT(expected.size(), 10u);
    total += static_cast<int>(expected.size());

    // sorted by range from the sensor
    for (std::size_t i = 1; i < frame.cones.size(); ++i) {
      const Vec2 m{p.mount_x, p.mount_y};
      EXPECT_LE(norm(frame.cones[i - 1].position - m), norm(frame.cones[i].position - m));
    }
    std::vector<hal::DetectedCone> got = frame.cones;
    std::sort(got.begin(), got.end(), less_xy);
    std::sort(expected.begin(), expected.end(), less_xy);
    for (std::size_t i = 0; i < got.size(); ++i) {
      EXPECT_NEAR(got[i].position.x, expected[i].position.x, 1e-9);
      EXPECT_NEAR(got[i].position.y, expected[i].position.y, 1e-9);
      EXPECT_EQ(got[i].color, expected[i].color);
    }
    EXPECT_EQ(sensor.last_stats().in_view, static_cast<int>(expected.size()));
  }
  EXPECT_GT(total, 100);
}

// cones just inside and just outside each limit
TEST(ConeSensor, RangeAndFieldOfViewLimits) {
  ConeSensorParams p = perfect();
  p.fov = 2.0;  // rad: +-1 rad
  p.range_min = 1.0;
  p.range_max = 15.0;
  const Pose2 pose{3.0, -2.0, 0.7};
  const double e = 1e-6;
  struct Probe {
    double r, b;
    bool seen;
  };
  const Probe probes[] = {
      {15.0 - e, 0.0, true},  {15.0 + e, 0.0, false}, {1.0 + e, 0.3, true},  {1.0 - e, 0.3, false},
      {10.0, 1.0 - e, true},  {10.0, 1.0 + e, false}, {10.0, -1.0 + e, true}, {10.0, -1.0 - e, false},
      {14.0, 0.99, true},     {5.0, -2.5, false},     {5.0, kPi, false},
  };
  // one at a time, so that nothing depends on the others
  for (const Probe& pr : probes) {
    ConeSensor sensor(p, 3);
    const Vec2 m = map_point(p, pose, pr.r, pr.b);
    const hal::ConeDetections f = sensor.measure({{m, ConeColor::Blue}}, {}, pose, 0);
    EXPECT_EQ(f.cones.size(), pr.seen ? 1u : 0u) << "r " << pr.r << " bearing " << pr.b;
  }
}

TEST(ConeSensor, OcclusionBehindAnotherCone) {
  ConeSensorParams p = perfect();
  p.occlusion = true;
  const Pose2 pose{10.0, 5.0, -0.4};
  const double b = 0.1;
  const Vec2 near = map_point(p, pose, 5.0, b);
  const Vec2 far = map_point(p, pose, 8.0, b);
  // the far cone shifted sideways (perpendicular to the line of sight) by more
  // than the two base radii
  const Vec2 offset = pose.transform(Vec2{p.mount_x, p.mount_y} + 8.0 * unit_from_angle(b) +
                                     (2.0 * p.small_cone_radius + 0.01) * unit_from_angle(b + 0.5 * kPi));
  {
    ConeSensor sensor(p, 1);
    const auto f = sensor.measure({{far, ConeColor::Yellow}, {near, ConeColor::Blue}}, {}, pose, 0);
    ASSERT_EQ(f.cones.size(), 1u);
    EXPECT_EQ(f.cones[0].color, ConeColor::Blue);
    EXPECT_EQ(sensor.last_stats().occluded, 1);
    EXPECT_EQ(sensor.last_stats().in_view, 2);
  }
  {
    ConeSensor sensor(p, 1);
    const auto f = sensor.measure({{offset, ConeColor::Yellow}, {near, ConeColor::Blue}}, {}, pose, 0);
    EXPECT_EQ(f.cones.size(), 2u);
  }
  {
    // occlusion off: both seen
    ConeSensorParams q = p;
    q.occlusion = false;
    ConeSensor sensor(q, 1);
    EXPECT_EQ(sensor.measure({{far, ConeColor::Yellow}, {near, ConeColor::Blue}}, {}, pose, 0).cones.size(), 2u);
  }
  {
    // a big orange cone in front hides a small one; a small cone in front of a
    // big one leaves a rim of its interval free: hidden only when the covered
    // part reaches occlusion_fraction
    ConeSensor sensor(p, 1);
    EXPECT_EQ(sensor.measure({{near, ConeColor::BigOrange}, {far, ConeColor::Blue}}, {}, pose, 0).cones.size(), 1u);
    // small at 7.9 m (half-angle 0.01443) before big at 8 m (0.01781): covered 81 %
    const Vec2 small_front = map_point(p, pose, 7.9, b);
    EXPECT_EQ(sensor.measure({{small_front, ConeColor::Blue}, {far, ConeColor::BigOrange}}, {}, pose, 0).cones.size(),
              1u);
    ConeSensorParams q = p;
    q.occlusion_fraction = 0.9;
    ConeSensor lenient(q, 1);
    EXPECT_EQ(lenient.measure({{small_front, ConeColor::Blue}, {far, ConeColor::BigOrange}}, {}, pose, 0).cones.size(),
              2u);
  }
}

// two near cones that each cover 40 % of a far cone hide it together (80 %)
TEST(ConeSensor, OcclusionByTheUnionOfNearerCones) {
  ConeSensorParams p = perfect();
  p.occlusion = true;
  const Pose2 pose{0.0, 0.0, 0.0};
  const double rf = 10.0, rn = 4.0;
  const double af = std::asin(p.small_cone_radius / rf), an = std::asin(p.small_cone_radius / rn);
  const double bl = -af + 0.8 * af - an, br = af - 0.8 * af + an;
  const Cone far{map_point(p, pose, rf, 0.0), ConeColor::Yellow};
  const Cone left{map_point(p, pose, rn, bl), ConeColor::Blue};
  const Cone right{map_point(p, pose, rn, br), ConeColor::Blue};
  ConeSensor sensor(p, 1);
  EXPECT_EQ(sensor.measure({far, left}, {}, pose, 0).cones.size(), 2u);
  EXPECT_EQ(sensor.measure({far, right}, {}, pose, 0).cones.size(), 2u);
  EXPECT_EQ(sensor.measure({far, left, right}, {}, pose, 0).cones.size(), 2u);
  EXPECT_EQ(sensor.last_stats().occluded, 1);
}

// a line of sight across the sensor's +-pi bearing: the intervals wrap
TEST(ConeSensor, OcclusionAcrossTheRearBearing) {
  ConeSensorParams p = perfect();
  p.occlusion = true;
  p.fov = 2.0 * kPi;
  const Pose2 pose{1.0, 1.0, 0.3};
  const Cone near{map_point(p, pose, 3.0, kPi - 0.001), ConeColor::Blue};
  const Cone far{map_point(p, pose, 6.0, -kPi + 0.001), ConeColor::Yellow};
  ConeSensor sensor(p, 1);
  const auto f = sensor.measure({far, near}, {}, pose, 0);
  ASSERT_EQ(f.cones.size(), 1u);
  EXPECT_EQ(f.cones[0].color, ConeColor::Blue);
}

// a cone out of view (behind the sensor, or nearer than range_min) still hides
TEST(ConeSensor, UnreportedConesStillOcclude) {
  ConeSensorParams p = perfect();
  p.occlusion = true;
  p.range_min = 1.0;
  const Pose2 pose{};
  const Cone blind{map_point(p, pose, 0.8, 0.2), ConeColor::Blue};
  const Cone far{map_point(p, pose, 9.0, 0.2), ConeColor::Yellow};
  ConeSensor sensor(p, 1);
  EXPECT_TRUE(sensor.measure({blind, far}, {}, pose, 0).cones.empty());
}

TEST(ConeSensor, KnockedConesAreNotReportedNorOcclude) {
  ConeSensorParams p = perfect();
  p.occlusion = true;
  const Pose2 pose{2.0, 3.0, 1.0};
  const std::vector<Cone> cones = {{map_point(p, pose, 4.0, 0.0), ConeColor::Blue},
                                   {map_point(p, pose, 8.0, 0.0), ConeColor::Yellow},
                                   {map_point(p, pose, 6.0, 0.5), ConeColor::BigOrange}};
  ConeSensor sensor(p, 1);
  auto f = sensor.measure(cones, {false, false, false}, pose, 0);
  EXPECT_EQ(f.cones.size(), 2u);  // the yellow one hides behind the blue one
  f = sensor.measure(cones, {true, false, true}, pose, 0);
  ASSERT_EQ(f.cones.size(), 1u);
  EXPECT_EQ(f.cones[0].color, ConeColor::Yellow);
  EXPECT_EQ(sensor.last_stats().knocked, 2);
  f = sensor.measure(cones, {true, true, true}, pose, 0);
  EXPECT_TRUE(f.cones.empty());
}

// range and bearing noise: the sample std over 20 000 frames within 5 %
TEST(ConeSensor, RangeAndBearingNoiseStatistics) {
  ConeSensorParams p = perfect();
  p.range_noise = 0.03;
  p.range_noise_per_m = 0.002;
  p.bearing_noise = 0.004;
  const Pose2 pose{-3.0, 2.0, 0.4};
  const double r = 10.0, b = 0.3;
  const std::vector<Cone> cones = {{map_point(p, pose, r, b), ConeColor::Blue}};
  ConeSensor sensor(p, 11);
  const int n = 20000;
  double sr = 0, srr = 0, sb = 0, sbb = 0;
  for (int i = 0; i < n; ++i) {
    const auto f = sensor.measure(cones, {}, pose, i);
    ASSERT_EQ(f.cones.size(), 1u);
    const Vec2 v = f.cones[0].position - Vec2{p.mount_x, p.mount_y};
    const double dr = norm(v) - r, db = angle_of(v) - b;
    sr += dr, srr += dr * dr, sb += db, sbb += db * db;
  }
  const double sigma_r = 0.03 + 0.002 * r;
  const double mean_r = sr / n, std_r = std::sqrt(srr / n - mean_r * mean_r);
  const double mean_b = sb / n, std_b = std::sqrt(sbb / n - mean_b * mean_b);
  EXPECT_NEAR(std_r, sigma_r, 0.05 * sigma_r);
  EXPECT_NEAR(std_b, p.bearing_noise, 0.05 * p.bearing_noise);
  // unbiased: within 4 standard errors
  EXPECT_NEAR(mean_r, 0.0, 4.0 * sigma_r / std::sqrt(n));
  EXPECT_NEAR(mean_b, 0.0, 4.0 * p.bearing_noise / std::sqrt(n));
}

// a fan of cones at one range, far enough apart not to occlude each other
std::vector<Cone> fan(const ConeSensorParams& p, const Pose2& pose, double r, int n) {
  std::vector<Cone> cones;
  const ConeColor colors[] = {ConeColor::Blue, ConeColor::Yellow, ConeColor::SmallOrange, ConeColor::BigOrange};
  for (int i = 0; i < n; ++i) {
    const double b = -1.2 + 2.4 * i / (n - 1);
    cones.push_back({map_point(p, pose, r, b), colors[i % 4]});
  }
  return cones;
}

TEST(ConeSensor, MissRateGrowsWithRange) {
  ConeSensorParams p = perfect();
  p.occlusion = true;
  p.miss_probability = 0.05;
  p.miss_probability_growth = 0.2;
  const Pose2 pose{1.0, 2.0, 3.0};
  for (const double r : {3.0, 15.0}) {
    const std::vector<Cone> cones = fan(p, pose, r, 10);
    ConeSensor sensor(p, 5);
    const int frames = 2000;
    int seen = 0;
    for (int i = 0; i < frames; ++i) seen += static_cast<int>(sensor.measure(cones, {}, pose, i).cones.size());
    const double expected = 0.05 + 0.2 * (r / 20.0) * (r / 20.0);
    EXPECT_NEAR(1.0 - static_cast<double>(seen) / (frames * 10.0), expected, 0.01) << "r " << r;
  }
}

TEST(ConeSensor, ColourUnknownAndFlipRates) {
  ConeSensorParams p = perfect();
  p.unknown_color_probability = 0.05;
  p.unknown_color_growth = 0.15;
  p.color_flip_probability = 0.03;
  p.color_flip_growth = 0.08;
  const Pose2 pose{};
  const double r = 10.0, q = (r / 20.0) * (r / 20.0);
  const std::vector<Cone> cones = fan(p, pose, r, 8);  // B Y SO BO B Y SO BO
  ConeSensor sensor(p, 9);
  const int frames = 2500;  // 20 000 cone draws
  int unknown = 0, flipped = 0, total = 0, small_total = 0, big_unknown = 0;
  for (int i = 0; i < frames; ++i) {
    const auto f = sensor.measure(cones, {}, pose, i);
    ASSERT_EQ(f.cones.size(), cones.size());
    for (const auto& d : f.cones) {
      // find the true cone: the nearest one (they are ~2 m apart, noise is off)
      const Vec2 m = pose.transform(d.position);
      const Cone* truth = &cones[0];
      for (const Cone& c : cones)
        if (distance(c.position, m) < distance(truth->position, m)) truth = &c;
      ++total;
      // a big cone keeps its class by its size when its colour is lost
      if (truth->color == ConeColor::BigOrange) big_unknown += d.color == ConeColor::Unknown;
      else ++small_total;
      if (d.color == ConeColor::Unknown) {
        ++unknown;
      } else if (d.color != truth->color) {
        ++flipped;
        // only the look-alike
        const ConeColor t = truth->color;
        const ConeColor want = t == ConeColor::Blue     ? ConeColor::Yellow
                               : t == ConeColor::Yellow ? ConeColor::Blue
                               : t == ConeColor::SmallOrange ? ConeColor::BigOrange
                                                             : ConeColor::SmallOrange;
        EXPECT_EQ(d.color, want);
      }
    }
  }
  const double pu = 0.05 + 0.15 * q, pf = (1.0 - pu) * (0.03 + 0.08 * q);
  EXPECT_EQ(big_unknown, 0);
  EXPECT_NEAR(static_cast<double>(unknown) / small_total, pu, 0.01);
  EXPECT_NEAR(static_cast<double>(flipped) / total, pf, 0.01);
}

TEST(ConeSensor, UnknownTrueColourStaysUnknown) {
  ConeSensorParams p = perfect();
  p.color_flip_probability = 1.0;
  const Pose2 pose{};
  ConeSensor sensor(p, 9);
  const auto f = sensor.measure({{map_point(p, pose, 5.0, 0.0), ConeColor::Unknown},
                                 {map_point(p, pose, 5.0, 0.5), ConeColor::Blue}},
                                {}, pose, 0);
  ASSERT_EQ(f.cones.size(), 2u);
  int unknown = 0, yellow = 0;
  for (const auto& d : f.cones) unknown += d.color == ConeColor::Unknown, yellow += d.color == ConeColor::Yellow;
  EXPECT_EQ(unknown, 1);
  EXPECT_EQ(yellow, 1);
}

TEST(ConeSensor, FalsePositiveStatistics) {
  ConeSensorParams p = perfect();
  p.false_positives_per_frame = 2.5;
  p.false_positive_unknown_probability = 0.3;
  p.fov = 2.0;
  p.range_min = 1.0;
  p.range_max = 18.0;
  const Pose2 pose{4.0, 4.0, -2.0};
  ConeSensor sensor(p, 13);
  const int frames = 20000;
  int count = 0, unknown = 0, inner = 0, per_color[4] = {0, 0, 0, 0};
  const double r2_mid = 0.5 * (1.0 + 18.0 * 18.0);
  for (int i = 0; i < frames; ++i) {
    const auto f = sensor.measure({}, {}, pose, i);
    EXPECT_EQ(sensor.last_stats().false_positives, static_cast<int>(f.cones.size()));
    for (const auto& d : f.cones) {
      const Vec2 v = d.position - Vec2{p.mount_x, p.mount_y};
      const double r = norm(v);
      EXPECT_GE(r, p.range_min - 1e-9);
      EXPECT_LE(r, p.range_max + 1e-9);
      EXPECT_LE(std::abs(angle_of(v)), 0.5 * p.fov + 1e-9);
      ++count;
      inner += r * r < r2_mid;
      if (d.color == ConeColor::Unknown) ++unknown;
      else ++per_color[static_cast<int>(d.color)];
    }
  }
  const double mean = static_cast<double>(count) / frames;
  EXPECT_NEAR(mean, 2.5, 0.05 * 2.5);
  EXPECT_NEAR(static_cast<double>(unknown) / count, 0.3, 0.01);
  // uniform over the area: half the detections inside the middle r^2
  EXPECT_NEAR(static_cast<double>(inner) / count, 0.5, 0.01);
  for (int n : per_color) EXPECT_NEAR(static_cast<double>(n) / count, 0.7 / 4.0, 0.01);
}

// a track-like ring of cones for the frames below
std::vector<Cone> ring(int n) {
  std::vector<Cone> cones;
  for (int i = 0; i < n / 2; ++i) {
    const double a = 2.0 * kPi * i / (n / 2);
    cones.push_back({{40.0 * std::cos(a), 25.0 * std::sin(a)}, ConeColor::Blue});
    cones.push_back({{43.0 * std::cos(a), 28.0 * std::sin(a)}, ConeColor::Yellow});
  }
  return cones;
}

TEST(ConeSensor, Deterministic) {
  const std::vector<Cone> cones = ring(400);
  ConeSensorParams p;  // defaults: every effect on
  p.false_positives_per_frame = 1.0;
  ConeSensor a(p, 77), b(p, 77), c(p, 78);
  bool differs = false;
  int detections = 0;
  for (int i = 0; i < 30; ++i) {
    const Pose2 pose{41.5 * std::cos(0.05 * i), 26.5 * std::sin(0.05 * i), 0.05 * i + 0.5 * kPi};
    const auto fa = a.measure(cones, {}, pose, i * 100'000'000LL);
    const auto fb = b.measure(cones, {}, pose, i * 100'000'000LL);
    const auto fc = c.measure(cones, {}, pose, i * 100'000'000LL);
    ASSERT_EQ(fa.cones.size(), fb.cones.size());
    detections += static_cast<int>(fa.cones.size());
    for (std::size_t k = 0; k < fa.cones.size(); ++k) {
      // bit-identical
      EXPECT_EQ(fa.cones[k].position, fb.cones[k].position);
      EXPECT_EQ(fa.cones[k].color, fb.cones[k].color);
    }
    if (fa.cones.size() != fc.cones.size()) {
      differs = true;
    } else {
      for (std::size_t k = 0; k < fa.cones.size(); ++k) differs |= !(fa.cones[k].position == fc.cones[k].position);
    }
  }
  EXPECT_GT(detections, 30 * 8);
  EXPECT_TRUE(differs);
}

TEST(ConeSensor, EmptyConeListGivesEmptyFrame) {
  ConeSensor sensor(perfect(), 1);
  const auto f = sensor.measure({}, {}, Pose2{1.0, 2.0, 3.0}, 42);
  EXPECT_TRUE(f.cones.empty());
  EXPECT_EQ(f.stamp, 42);
}

TEST(ConeSensor, NonFiniteInputsGiveNoDetections) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<Cone> cones = ring(400);
  ConeSensor sensor(ConeSensorParams{}, 1);  // false positives on too
  for (const Pose2& pose : {Pose2{nan, 0.0, 0.0}, Pose2{0.0, inf, 0.0}, Pose2{41.5, 0.0, nan}}) {
    const auto f = sensor.measure(cones, {}, pose, 7);
    EXPECT_TRUE(f.cones.empty());
    EXPECT_EQ(f.stamp, 7);
  }
  // a NaN cone is skipped, the others are seen
  ConeSensor exact(perfect(), 1);
  const Pose2 pose{};
  const auto f = exact.measure({{{nan, 1.0}, ConeColor::Blue}, {{5.0, inf}, ConeColor::Blue},
                                {{8.0, 0.0}, ConeColor::Yellow}},
                               {}, pose, 0);
  ASSERT_EQ(f.cones.size(), 1u);
  EXPECT_EQ(f.cones[0].color, ConeColor::Yellow);
}

}  // namespace
}  // namespace paddock::sensors
