// the cone map from detections at known poses: association, averaging,
// colour votes, and what it does with ghosts and bad values
#include "autonomy/slam/cone_map.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

namespace paddock::slam {
namespace {

TEST(ConeMap, RepeatedNoisyDetectionsAverageToTheTruth) {
  // two rows of cones 5 m apart; 200 frames with 5 cm noise
  std::vector<Cone> truth;
  for (int i = 0; i < 10; ++i) {
    truth.push_back({{5.0 * i, 1.5}, ConeColor::Blue});
    truth.push_back({{5.0 * i, -1.5}, ConeColor::Yellow});
  }
  ConeMap map;
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, 0.05);
  for (int f = 0; f < 200; ++f) {
    std::vector<Cone> frame;
    for (const Cone& c : truth) frame.push_back({c.position + Vec2{noise(rng), noise(rng)}, c.color});
    map.add(frame);
  }
  const auto cones = map.cones();
  ASSERT_EQ(cones.size(), truth.size());
  for (std::size_t i = 0; i < truth.size(); ++i) {
    // the mean of 200 samples of sigma 5 cm: its std is 3.5 mm; 2 cm is > 5 sigma
    EXPECT_LT(distance(cones[i].position, truth[i].position), 0.02);
    EXPECT_EQ(cones[i].color, truth[i].color);
  }
}

TEST(ConeMap, ColourIsTheMajorityOfTheColouredVotes) {
  ConeMap map;
  for (int f = 0; f < 10; ++f) {
    const ConeColor c = f < 3 ? ConeColor::Yellow : f < 8 ? ConeColor::Unknown : ConeColor::Blue;
    map.add({{{0.0, 0.0}, c}});
  }
  // 3 yellow, 5 unknown, 2 blue: yellow
  ASSERT_EQ(map.cones().size(), 1u);
  EXPECT_EQ(map.cones()[0].color, ConeColor::Yellow);
  ConeMap lidar_only;
  for (int f = 0; f < 5; ++f) lidar_only.add({{{0.0, 0.0}, ConeColor::Unknown}});
  EXPECT_EQ(lidar_only.cones()[0].color, ConeColor::Unknown);
}

TEST(ConeMap, OneFrameGhostsStayOutAndNeighboursStayApart) {
  ConeMapParams p;
  p.min_observations = 2;
  ConeMap map(p);
  map.add({{{0.0, 0.0}, ConeColor::Blue}, {{7.0, 3.0}, ConeColor::Unknown}});  // the second is a ghost
  map.add({{{0.02, 0.0}, ConeColor::Blue}});
  const auto cones = map.cones();
  ASSERT_EQ(cones.size(), 1u);
  EXPECT_NEAR(cones[0].position.x, 0.01, 1e-12);
  EXPECT_EQ(map.size(), 2u);
  // two detections of one frame 1.2 m apart are two cones, never one
  ConeMap pair;
  pair.add({{{0.0, 0.0}, ConeColor::Blue}, {{0.5, 0.0}, ConeColor::Blue}});
  EXPECT_EQ(pair.size(), 2u);
}

TEST(ConeMap, NonFiniteDetectionsAreSkipped) {
  ConeMap map;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  map.add({{{nan, 0.0}, ConeColor::Blue}, {{1.0, INFINITY}, ConeColor::Blue}});
  EXPECT_EQ(map.size(), 0u);
  map.add({});
  EXPECT_TRUE(map.cones().empty());
}

}  // namespace
}  // namespace paddock::slam
