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

// the map as the plain rule builds it: each detection to the nearest free
// mapped cone within the gate (the first of equals), scanning every cone
std::vector<MappedCone> brute_force_map(const std::vector<std::vector<Cone>>& frames, double gate) {
  std::vector<MappedCone> map;
  for (const std::vector<Cone>& frame : frames) {
    std::vector<char> taken(map.size(), 0);
    for (const Cone& d : frame) {
      if (!std::isfinite(d.position.x) || !std::isfinite(d.position.y)) continue;
      std::size_t best = map.size();
      double best_d2 = gate * gate;
      for (std::size_t i = 0; i < taken.size(); ++i) {
        const double d2 = squared_norm(map[i].position - d.position);
        if (!taken[i] && d2 < best_d2) {
          best_d2 = d2;
          best = i;
        }
      }
      if (best == map.size()) {
        map.push_back({d.position, 0, {}});
        taken.push_back(1);
      } else {
        taken[best] = 1;
        map[best].position += (d.position - map[best].position) / static_cast<double>(map[best].observations + 1);
      }
      ++map[best].observations;
      ++map[best].votes[static_cast<std::size_t>(d.color)];
    }
  }
  return map;
}

TEST(ConeMap, AssociatesAsTheNearestFreeConeOverTheWholeMap) {
  // a car's frames down a 400 m row of cone pairs: 20 m of view, noise, ghosts,
  // a cone seen twice in a frame, NaN; the map equals the brute force's, bit for bit
  std::mt19937_64 rng(11);
  std::normal_distribution<double> noise(0.0, 0.3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<std::vector<Cone>> frames;
  for (double x = 0.0; x < 400.0; x += 1.3) {
    std::vector<Cone> frame;
    for (double c = 0.0; c < 400.0; c += 4.0) {
      if (c < x || c > x + 20.0) continue;
      for (const double y : {-1.6, 1.6}) {
        if (u(rng) < 0.1) continue;  // missed
        frame.push_back({{c + noise(rng), y + noise(rng)}, u(rng) < 0.5 ? ConeColor::Blue : ConeColor::Unknown});
        if (u(rng) < 0.05) frame.push_back({{c + noise(rng), y + noise(rng)}, ConeColor::Yellow});  // twice
      }
    }
    if (u(rng) < 0.2) frame.push_back({{x + 30.0 * u(rng), 10.0 * u(rng) - 5.0}, ConeColor::Unknown});  // a ghost
    if (u(rng) < 0.05) frame.push_back({{std::nan(""), 0.0}, ConeColor::Blue});
    frames.push_back(frame);
  }
  for (const double gate : {0.5, 1.0, 2.5}) {
    ConeMapParams p;
    p.association_distance = gate;
    ConeMap map(p);
    for (const std::vector<Cone>& f : frames) map.add(f);
    const std::vector<MappedCone> expected = brute_force_map(frames, gate);
    ASSERT_EQ(map.all().size(), expected.size()) << "gate " << gate;
    for (std::size_t i = 0; i < expected.size(); ++i) {
      ASSERT_EQ(map.all()[i].position.x, expected[i].position.x) << i;
      ASSERT_EQ(map.all()[i].position.y, expected[i].position.y) << i;
      ASSERT_EQ(map.all()[i].observations, expected[i].observations) << i;
      ASSERT_EQ(map.all()[i].votes, expected[i].votes) << i;
    }
    EXPECT_GT(expected.size(), 200u);
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
