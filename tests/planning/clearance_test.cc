// a path pushed clear of the cones: brute-force distances before and after
#include "autonomy/planning/clearance.h"

#include <gtest/gtest.h>

#include <limits>

namespace paddock::planning {
namespace {

double min_distance(const std::vector<Vec2>& path, const std::vector<Cone>& cones) {
  double m = std::numeric_limits<double>::infinity();
  for (const Vec2& p : path)
    for (const Cone& c : cones) m = std::min(m, distance(p, c.position));
  return m;
}

TEST(Clearance, PushesPointsOffTheInnerConesOfACutCorner) {
  // a lane 3.3 m wide, and a path that hugs the right-hand cones at 0.5 m
  std::vector<Cone> cones;
  for (int i = 0; i <= 10; ++i) {
    cones.push_back({{2.0 * i, 1.65}, ConeColor::Blue});
    cones.push_back({{2.0 * i, -1.65}, ConeColor::Yellow});
  }
  std::vector<Vec2> path;
  for (int i = 0; i <= 40; ++i) path.push_back({0.5 * i, -1.15});
  EXPECT_LT(min_distance(path, cones), 0.51);
  const int moves = enforce_clearance(path, cones, ClearanceParams{});
  EXPECT_GT(moves, 0);
  EXPECT_GE(min_distance(path, cones), 1.1 - 1e-9);
  // it moved towards the middle of the lane and stayed inside it
  for (const Vec2& p : path) {
    EXPECT_GE(p.y, -1.15);
    EXPECT_LT(p.y, 1.65 - 1.1 + 1e-9);
  }
}

TEST(Clearance, LeavesAClearPathAloneAndIgnoresDegenerateCases) {
  const std::vector<Cone> cones = {{{0.0, 1.65}, ConeColor::Blue}, {{0.0, -1.65}, ConeColor::Yellow}};
  std::vector<Vec2> path = {{-1.0, 0.0}, {0.0, 0.0}, {1.0, 0.0}};
  const auto before = path;
  EXPECT_EQ(enforce_clearance(path, cones, ClearanceParams{}), 0);
  EXPECT_EQ(path, before);
  ClearanceParams off;
  off.clearance = 0.0;
  std::vector<Vec2> on_cone = {{0.0, 1.65}};
  EXPECT_EQ(enforce_clearance(on_cone, cones, off), 0);
  // a point exactly on a cone has no direction: left where it is
  EXPECT_EQ(enforce_clearance(on_cone, {{{0.0, 1.65}, ConeColor::Blue}}, ClearanceParams{}), 0);
  std::vector<Vec2> empty;
  EXPECT_EQ(enforce_clearance(empty, cones, ClearanceParams{}), 0);
}

}  // namespace
}  // namespace paddock::planning
