// relocalisation against a map: a frame of cones seen from a known pose,
// the search started from a guess 2 m and 0.2 rad off
#include "autonomy/slam/relocalise.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace paddock::slam {
namespace {

// two rows of cones along a gently curving road, 5 m apart along, 3.5 m across
std::vector<Vec2> road() {
  std::vector<Vec2> m;
  for (int i = 0; i < 30; ++i) {
    const double s = 5.0 * i, bend = 0.002 * s * s;
    m.push_back({s, 1.75 + bend});
    m.push_back({s, -1.75 + bend});
  }
  return m;
}

// the cones within 20 m of the pose (a LiDAR sees all round), in its frame, with noise
std::vector<Vec2> seen_from(const std::vector<Vec2>& map, const Pose2& pose, double noise, std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, noise);
  std::vector<Vec2> out;
  for (const Vec2& m : map) {
    const Vec2 b = pose.inverse_transform(m);
    if (norm(b) > 0.5 && norm(b) < 20.0) out.push_back({b.x + n(rng), b.y + n(rng)});
  }
  return out;
}

TEST(Relocalise, FindsTheTruePoseFromAGuessTwoMetresOff) {
  const std::vector<Vec2> map = road();
  std::mt19937_64 rng(7);
  for (double s : {20.0, 47.0, 80.0}) {
    const Pose2 truth{s, 0.002 * s * s, std::atan(0.004 * s)};
    const std::vector<Vec2> obs = seen_from(map, truth, 0.03, rng);
    ASSERT_GE(obs.size(), 10u);
    for (const Pose2 off : {Pose2{2.0, 0.0, 0.0}, Pose2{-1.2, 1.5, 0.2}, Pose2{0.5, -1.9, -0.15}}) {
      const Pose2 guess{truth.x + off.x, truth.y + off.y, truth.yaw + off.yaw};
      const std::optional<Relocalisation> r = relocalise(map, obs, guess, RelocaliseParams{});
      ASSERT_TRUE(r) << "s = " << s;
      EXPECT_LT(distance(r->pose.position(), truth.position()), 0.05) << "s = " << s << " off " << off.x << ", " << off.y;
      EXPECT_LT(std::abs(wrap_angle(r->pose.yaw - truth.yaw)), 0.005);
      EXPECT_EQ(r->inliers, static_cast<int>(obs.size()));
    }
  }
}

TEST(Relocalise, RefusesWhatFitsNowhere) {
  const std::vector<Vec2> map = road();
  // cones in a pattern the road does not have (a 1 m square grid, beside it)
  std::vector<Vec2> obs;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 3; ++j) obs.push_back({3.0 + i, 10.0 + j});
  EXPECT_FALSE(relocalise(map, obs, Pose2{20.0, 0.8, 0.0}, RelocaliseParams{}));
  // nothing to fit, or nothing to fit on
  EXPECT_FALSE(relocalise(map, {}, Pose2{20.0, 0.8, 0.0}, RelocaliseParams{}));
  EXPECT_FALSE(relocalise({}, obs, Pose2{20.0, 0.8, 0.0}, RelocaliseParams{}));
}

}  // namespace
}  // namespace paddock::slam
