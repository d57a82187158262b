#include "sim/runner/perception_metrics.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

namespace paddock::runner {
namespace {

hal::DetectedCone det(double x, double y, ConeColor c) { return {{x, y}, c}; }

TEST(PerceptionMetrics, HandCountedFrame) {
  // car at (10, 0) facing +y: base x = map +y, base y = map -x
  const Pose2 pose{10.0, 0.0, kPi / 2};
  const std::vector<Cone> truth = {
      {{10.0, 3.0}, ConeColor::Blue},    // 3 m ahead: bin [0, 5)
      {{10.0, 7.0}, ConeColor::Yellow},  // 7 m: [5, 10)
      {{10.0, 12.0}, ConeColor::Blue},   // 12 m: [10, 15), not visible
      {{10.0, 40.0}, ConeColor::Blue},   // 40 m: [30, inf), visible, missed
  };
  const std::vector<bool> visible = {true, true, false, true};
  hal::ConeDetections d;
  d.cones = {det(3.1, 0.0, ConeColor::Blue),      // matches cone 0, error 0.1, right colour
             det(7.0, -0.2, ConeColor::Unknown),  // matches cone 1 (map (10.2, 7)), error 0.2, no colour
             det(12.0, 0.0, ConeColor::Yellow),   // matches cone 2 (not visible), wrong colour
             det(20.0, 0.0, ConeColor::Blue)};    // a ghost at 20 m: [20, 30)
  PerceptionMetrics m;
  m.add(d, pose, {0.0, 0.0}, truth, visible);
  const auto& b = m.bins();
  ASSERT_EQ(b.size(), 6u);
  EXPECT_EQ(b[0].detections, 1);
  EXPECT_DOUBLE_EQ(b[0].precision(), 1.0);
  EXPECT_DOUBLE_EQ(b[0].recall(), 1.0);
  EXPECT_DOUBLE_EQ(b[0].colour_accuracy(), 1.0);
  EXPECT_NEAR(b[0].error_mean(), 0.1, 1e-9);
  EXPECT_EQ(b[1].colour_unknown, 1);
  EXPECT_DOUBLE_EQ(b[1].colour_accuracy(), 0.0);
  EXPECT_NEAR(b[1].error_max, 0.2, 1e-9);
  EXPECT_EQ(b[2].visible, 0);        // cone 2 was not visible
  EXPECT_TRUE(std::isnan(b[2].recall()));
  EXPECT_DOUBLE_EQ(b[2].precision(), 1.0);  // but a detection of it is right
  EXPECT_EQ(b[4].detections, 1);
  EXPECT_DOUBLE_EQ(b[4].precision(), 0.0);
  EXPECT_EQ(b[5].visible, 1);
  EXPECT_DOUBLE_EQ(b[5].recall(), 0.0);
  const RangeBinStats t = m.total();
  EXPECT_DOUBLE_EQ(t.precision(), 3.0 / 4.0);
  EXPECT_DOUBLE_EQ(t.recall(), 2.0 / 3.0);
  EXPECT_DOUBLE_EQ(t.colour_accuracy(), 1.0 / 3.0);
}

TEST(PerceptionMetrics, GreedyMatchingAgreesWithBruteForceOnRandomFrames) {
  // with cones >= 2 m apart and noise < 0.25 m the nearest-first matching is the
  // only sensible one: every noisy detection pairs with the cone it came from
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-0.2, 0.2);
  std::vector<Cone> truth;
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j) truth.push_back({{2.0 * i, 2.0 * j}, ConeColor::Blue});
  hal::ConeDetections d;
  long expected = 0;
  for (std::size_t k = 0; k < truth.size(); k += 3) {
    d.cones.push_back(det(truth[k].position.x + u(rng), truth[k].position.y + u(rng), ConeColor::Blue));
    ++expected;
  }
  PerceptionMetrics m;
  m.add(d, Pose2{}, {0.0, 0.0}, truth, {});
  const RangeBinStats t = m.total();
  EXPECT_EQ(t.detections_matched, expected);
  EXPECT_EQ(t.visible, static_cast<long>(truth.size()));
  EXPECT_EQ(t.visible_matched, expected);
  EXPECT_LT(t.error_max, 0.2 * std::sqrt(2.0) + 1e-12);
}

TEST(PerceptionMetrics, RejectsBadEdges) {
  EXPECT_THROW(PerceptionMetrics({5.0, 1.0}), std::invalid_argument);
  EXPECT_THROW(PerceptionMetrics(std::vector<double>{}), std::invalid_argument);
}

}  // namespace
}  // namespace paddock::runner
