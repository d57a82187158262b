// a path pushed clear of the cones: brute-force distances before and after
#include "autonomy/planning/clearance.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

namespace paddock::planning {
namespace {

double min_distance(const std::vector<Vec2>& path, const std::vector<Cone>& cones) {
  double m = std::numeric_limits<double>::infinity();
  for (const Vec2& p : path)
    for (const Cone& c : cones) m = std::min(m, distance(p, c.position));
  return m;
}

// clear_trajectory's rule as written, over every cone for every sample
std::vector<Vec2> cleared_brute_force(std::vector<Vec2> points, const Trajectory& traj, const std::vector<Cone>& cones,
                                      const ClearanceParams& params, double reach, double tolerance) {
  std::vector<double> shortfall(points.size(), 0.0);
  std::vector<Vec2> away(points.size());
  for (const TrajectoryPoint& s : traj.points) {
    const Cone* nearest = nullptr;
    double best2 = (params.clearance - tolerance) * (params.clearance - tolerance);
    for (const Cone& c : cones) {
      const double d2 = squared_norm(s.position() - c.position);
      if (d2 < best2) {
        best2 = d2;
        nearest = &c;
      }
    }
    if (!nearest) continue;
    const double missing = params.clearance - std::sqrt(best2);
    for (std::size_t i = 0; i < points.size(); ++i) {
      if (squared_norm(points[i] - s.position()) > reach * reach || missing <= shortfall[i]) continue;
      const Vec2 d = points[i] - nearest->position;
      if (norm(d) < 1e-9) continue;
      shortfall[i] = missing;
      away[i] = d / norm(d);
    }
  }
  for (std::size_t i = 0; i < points.size(); ++i)
    if (shortfall[i] > 0.0) points[i] += away[i] * shortfall[i];
  return points;
}

TEST(Clearance, TheTrajectorysPushesAreThoseOfEveryConeAgainstEverySample) {
  // a wavy 400 m path through a field of 600 random cones, some on it, two
  // at one place: the pushes equal the brute force's, bit for bit
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Trajectory traj;
  std::vector<Vec2> points;
  for (int k = 0; k < 1600; ++k) {
    const double x = 0.25 * k;
    TrajectoryPoint p;
    p.x = x;
    p.y = 6.0 * std::sin(0.05 * x);
    traj.points.push_back(p);
    if (k % 8 == 0) points.push_back({p.x + 0.1 * u(rng), p.y + 0.1 * u(rng)});
  }
  std::vector<Cone> cones;
  for (int i = 0; i < 600; ++i) cones.push_back({{200.0 + 200.0 * u(rng), 10.0 * u(rng)}, ConeColor::Blue});
  cones.push_back(cones[17]);
  ClearanceParams params;
  params.clearance = 1.2;
  std::vector<Vec2> fast = points;
  const int moved = clear_trajectory(fast, traj, cones, params, 2.0, 0.02);
  const std::vector<Vec2> slow = cleared_brute_force(points, traj, cones, params, 2.0, 0.02);
  EXPECT_GT(moved, 20);
  ASSERT_EQ(fast.size(), slow.size());
  for (std::size_t i = 0; i < fast.size(); ++i) {
    EXPECT_EQ(fast[i].x, slow[i].x) << i;
    EXPECT_EQ(fast[i].y, slow[i].y) << i;
  }
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
