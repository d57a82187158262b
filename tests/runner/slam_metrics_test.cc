// the final map's metrics against hand-counted cases
#include "sim/runner/slam_metrics.h"

#include <gtest/gtest.h>

#include <cmath>

namespace paddock::runner {
namespace {

Cone cone(double x, double y, ConeColor c = ConeColor::Blue) { return {{x, y}, c}; }

// a straight path along y = 0 from x = 0 to x = 20
const std::vector<Vec2> kPath = {{0.0, 0.0}, {10.0, 0.0}, {20.0, 0.0}};

TEST(MapMetrics, APerfectMapScoresOne) {
  const std::vector<Cone> truth = {cone(5, 2), cone(5, -2, ConeColor::Yellow), cone(15, 2), cone(15, -2, ConeColor::Yellow)};
  const MapMetrics m = map_metrics(truth, truth, kPath);
  EXPECT_EQ(m.map_cones, 4);
  EXPECT_EQ(m.true_cones, 4);
  EXPECT_EQ(m.matched, 4);
  EXPECT_EQ(m.rmse, 0.0);
  EXPECT_EQ(m.precision, 1.0);
  EXPECT_EQ(m.recall, 1.0);
  EXPECT_EQ(m.colour_accuracy, 1.0);
}

TEST(MapMetrics, GhostsMissesOffsetsAndColoursCountAsCountedByHand) {
  const std::vector<Cone> truth = {cone(5, 2), cone(5, -2, ConeColor::Yellow), cone(15, 2), cone(15, -2, ConeColor::Yellow),
                                   cone(10, 30)};  // far from the path: not in the corridor
  const std::vector<Cone> map = {
      cone(5.3, 2),                            // 0.3 m off
      cone(5, -2.4, ConeColor::Blue),          // 0.4 m off, the wrong colour
      cone(15, 2),                             // exact
      cone(10, 0.5),                           // a ghost: 3.9 m from the nearest true cone
      cone(15.2, 2.0),                         // a duplicate of (15, 2): the exact one takes it first
  };                                           // (15, -2) is missed
  const MapMetrics m = map_metrics(map, truth, kPath);
  EXPECT_EQ(m.map_cones, 5);
  EXPECT_EQ(m.true_cones, 4);
  EXPECT_EQ(m.matched, 3);
  EXPECT_NEAR(m.rmse, std::sqrt((0.09 + 0.16 + 0.0) / 3.0), 1e-12);
  EXPECT_DOUBLE_EQ(m.precision, 3.0 / 5.0);
  EXPECT_DOUBLE_EQ(m.recall, 3.0 / 4.0);
  EXPECT_DOUBLE_EQ(m.colour_accuracy, 2.0 / 3.0);
}

TEST(MapMetrics, TheMatchRadiusAndTheCorridorAreBounds) {
  const std::vector<Cone> truth = {cone(5, 4.9), cone(5, 5.1)};
  // 1.01 m off: no match within 1 m; the cone at 5.1 m lies outside the 5 m corridor
  const MapMetrics m = map_metrics({cone(6.01, 4.9)}, truth, kPath);
  EXPECT_EQ(m.true_cones, 1);
  EXPECT_EQ(m.matched, 0);
  EXPECT_EQ(m.precision, 0.0);
  EXPECT_EQ(m.recall, 0.0);
  EXPECT_EQ(map_metrics({}, truth, kPath).precision, 0.0);
  EXPECT_EQ(map_metrics({}, {}, kPath).recall, 1.0);
}

// the drift over 100 m windows, against hand-computed cases: an estimate
// that reads every distance 1 % long drifts 1 m per 100 m whatever the
// offset and heading it starts with; one whose heading turns 0.01 rad per
// 100 m more than the truth on a straight drifts that much, and the chord's
// error 100 sin(0.01 / 2) ~ 0.5 m (the heading error grows linearly along
// the window: the mean direction is off by half the turn)
TEST(Drift, ScaleAndHeadingErrorsGiveTheirClosedForms) {
  // samples every 0.125 m (exact in binary: the windows close exactly at 100 m)
  std::vector<Pose2> truth, scaled, turning;
  for (int i = 0; i <= 2400; ++i) {
    const double s = 0.125 * i;  // 300 m along x
    truth.push_back({s, 0.0, 0.0});
    // offset by (5, -2) and turned by 1 rad: the relative motion is the same
    const Vec2 p = rotate(Vec2{1.01 * s, 0.0}, 1.0) + Vec2{5.0, -2.0};
    scaled.push_back({p.x, p.y, 1.0});
    // the heading turns 1e-4 rad per metre: an arc of radius 1e4 m
    const double k = 1e-4, a = k * s;
    turning.push_back({std::sin(a) / k, (1.0 - std::cos(a)) / k, a});
  }
  const Drift d = relative_drift(truth, scaled, 100.0, 10.0);
  EXPECT_EQ(d.windows, 21);  // windows starting at 0, 10, ..., 200 m
  EXPECT_NEAR(d.translation, 1.0, 1e-9);
  EXPECT_NEAR(d.rotation, 0.0, 1e-12);
  const Drift e = relative_drift(truth, turning, 100.0, 10.0);
  EXPECT_NEAR(e.rotation, 0.01, 1e-9);
  // chord of the arc of 100 m: 2 R sin(a / 2) long at a / 2 off the x axis,
  // against 100 m along x
  const double R = 1e4, a = 0.01, chord = 2.0 * R * std::sin(a / 2.0);
  EXPECT_NEAR(e.translation, std::hypot(chord * std::cos(a / 2.0) - 100.0, chord * std::sin(a / 2.0)), 1e-6);
  EXPECT_NEAR(e.translation, 0.5, 0.01);
  // shorter than a window: none
  EXPECT_EQ(relative_drift({truth.begin(), truth.begin() + 700}, scaled, 100.0, 10.0).windows, 0);
  EXPECT_EQ(relative_drift(truth, truth).translation, 0.0);
}

}  // namespace
}  // namespace paddock::runner
