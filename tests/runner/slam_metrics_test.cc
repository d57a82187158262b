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

}  // namespace
}  // namespace paddock::runner
