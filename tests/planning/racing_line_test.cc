// the minimum-curvature line against closed forms (a ring), brute force (no
// nearby feasible line bends less) and its constraints.
#include "autonomy/planning/racing_line.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "autonomy/common/geometry.h"
#include "autonomy/common/polyline.h"

namespace paddock::planning {
namespace {

std::vector<Vec2> circle(double r, std::size_t n, bool clockwise = false) {
  std::vector<Vec2> pts;
  for (std::size_t i = 0; i < n; ++i) {
    const double a = 2.0 * kPi * static_cast<double>(i) / static_cast<double>(n);
    pts.push_back({r * std::cos(clockwise ? -a : a), r * std::sin(clockwise ? -a : a)});
  }
  return pts;
}

// a stadium of two straights of `length` joined by semicircles of radius r
// (its centreline), driven anticlockwise, offset by d to the left (d < 0:
// right)
std::vector<Vec2> stadium(double length, double r, double d, double step = 0.25) {
  std::vector<Vec2> pts;
  const double rr = r - d;  // anticlockwise: the left is the inside
  const auto add_straight = [&](Vec2 a, Vec2 b) {
    const int n = static_cast<int>(std::ceil(distance(a, b) / step));
    for (int i = 0; i < n; ++i) pts.push_back(a + (static_cast<double>(i) / n) * (b - a));
  };
  const auto add_arc = [&](Vec2 c, double a0) {
    const int n = static_cast<int>(std::ceil(kPi * rr / step));
    for (int i = 0; i < n; ++i) {
      const double a = a0 + kPi * static_cast<double>(i) / n;
      pts.push_back(c + rr * Vec2{std::cos(a), std::sin(a)});
    }
  };
  add_straight({0.0, -rr}, {length, -rr});
  add_arc({length, 0.0}, -kPi / 2.0);
  add_straight({length, rr}, {0.0, rr});
  add_arc({0.0, 0.0}, kPi / 2.0);
  return pts;
}

TEST(RacingLine, RingGivesTheOuterCircleLessTheClearance) {
  // an annulus 10..16 m driven anticlockwise (the inner ring on the left):
  // among closed curves in it, sum kappa^2 ds = 2 pi / R is least for the
  // largest circle, R = 16 - clearance
  const std::vector<Vec2> left = circle(10.0, 400), right = circle(16.0, 400), ref = circle(13.0, 400);
  RacingLineParams p;
  p.clearance = 1.0;
  const RacingLine line = min_curvature_line(ref, left, right, true, p);
  ASSERT_TRUE(line.ok()) << line.reason;
  for (const Vec2& q : line.points) EXPECT_NEAR(norm(q), 15.0, 1e-3);
  EXPECT_NEAR(line.cost, 2.0 * kPi / 15.0, 2e-3);
  EXPECT_NEAR(line.cost_reference, 2.0 * kPi / 13.0, 2e-3);
}

TEST(RacingLine, NoNearbyFeasibleLineBendsLess) {
  // a stadium 40 m x R 8 m, 5 m wide: the optimum is a local minimum of the
  // cost among lines within the bounds; 2000 random feasible perturbations of
  // one to five neighbouring points never lower it
  const std::vector<Vec2> ref = stadium(40.0, 8.0, 0.0), left = stadium(40.0, 8.0, 2.5),
                          right = stadium(40.0, 8.0, -2.5);
  RacingLineParams p;
  p.clearance = 1.0;
  const RacingLine line = min_curvature_line(ref, left, right, true, p);
  ASSERT_TRUE(line.ok()) << line.reason;
  EXPECT_LT(line.cost, 0.85 * line.cost_reference);
  const std::size_t n = line.points.size();
  std::mt19937 rng(7);
  std::uniform_int_distribution<std::size_t> pick(0, n - 1);
  std::uniform_int_distribution<int> width(1, 5);
  std::uniform_real_distribution<double> step(-0.05, 0.05);
  int tried = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    std::vector<Vec2> q = line.points;
    const std::size_t first = pick(rng);
    const int w = width(rng);
    bool feasible = true;
    for (int k = 0; k < w; ++k) {
      const std::size_t i = (first + static_cast<std::size_t>(k)) % n;
      const Vec2 nrm = left_normal(line.reference[(i + 1) % n] - line.reference[(i + n - 1) % n]);
      const Vec2 unit = (1.0 / norm(nrm)) * nrm;
      const double a = line.offset[i] + step(rng);
      if (a < line.lower[i] || a > line.upper[i]) feasible = false;
      q[i] = line.reference[i] + a * unit;
    }
    if (!feasible) continue;
    ++tried;
    EXPECT_GE(curvature_cost(q, true), line.cost - 1e-9) << "trial " << trial;
  }
  EXPECT_GT(tried, 500);
}

TEST(RacingLine, KeepsTheClearanceFromBothBoundaries) {
  const std::vector<Vec2> ref = stadium(40.0, 8.0, 0.0), left = stadium(40.0, 8.0, 2.5),
                          right = stadium(40.0, 8.0, -2.5);
  for (double c : {0.5, 1.0, 2.0}) {
    RacingLineParams p;
    p.clearance = c;
    const RacingLine line = min_curvature_line(ref, left, right, true, p);
    ASSERT_TRUE(line.ok()) << line.reason;
    for (const Vec2& q : line.points) {
      EXPECT_GE(polyline_distance(left, true, q), c - 1e-3);
      EXPECT_GE(polyline_distance(right, true, q), c - 1e-3);
    }
    // and uses the room: on a stadium the least-bending line runs round the
    // outside (it never reaches the inner bound), touching its bound there
    double closest_right = 1e9;
    for (const Vec2& q : line.points) closest_right = std::min(closest_right, polyline_distance(right, true, q));
    EXPECT_NEAR(closest_right, c, 0.02) << c;
  }
}

TEST(RacingLine, NarrowerThanTwiceTheClearanceStaysMidway) {
  // 1.5 m wide with a 1 m clearance: no room, the line is the middle
  const std::vector<Vec2> ref = stadium(40.0, 8.0, 0.0), left = stadium(40.0, 8.0, 0.75),
                          right = stadium(40.0, 8.0, -0.75);
  const RacingLine line = min_curvature_line(ref, left, right, true, {});
  ASSERT_TRUE(line.ok()) << line.reason;
  for (std::size_t i = 0; i < line.points.size(); ++i) EXPECT_NEAR(line.offset[i], 0.0, 2e-3);
}

TEST(RacingLine, PinnedEndsStayOnTheReference) {
  // an open half of a ring of radius 10 between boundaries at 8 and 12: the
  // free line moves its ends, the pinned one keeps them and still bends less
  std::vector<Vec2> ref, left, right;
  for (int i = 0; i <= 60; ++i) {
    const double a = kPi * i / 60.0;
    const Vec2 u{std::cos(a), std::sin(a)};
    ref.push_back(10.0 * u);
    left.push_back(8.0 * u);
    right.push_back(12.0 * u);
  }
  RacingLineParams p;
  p.clearance = 0.5;
  const RacingLine free_line = min_curvature_line(ref, left, right, false, p);
  const RacingLine pinned = min_curvature_line(ref, left, right, false, p, true);
  ASSERT_TRUE(free_line.ok() && pinned.ok()) << free_line.reason << pinned.reason;
  EXPECT_DOUBLE_EQ(pinned.offset.front(), 0.0);
  EXPECT_DOUBLE_EQ(pinned.offset.back(), 0.0);
  EXPECT_LT(distance(pinned.points.front(), ref.front()), 1e-9);
  EXPECT_GT(std::abs(free_line.offset.front()) + std::abs(free_line.offset.back()), 0.5);
  EXPECT_LE(pinned.cost, pinned.cost_reference + 1e-12);
  EXPECT_LE(free_line.cost, pinned.cost + 1e-9);
  for (std::size_t i = 0; i < pinned.offset.size(); ++i) {
    EXPECT_GE(pinned.offset[i], -1.5 - 1e-6);
    EXPECT_LE(pinned.offset[i], 1.5 + 1e-6);
  }
}

TEST(RacingLine, StartHeadingHoldsTheSecondPointOnTheCarsHeading) {
  // a straight 3 m corridor along x, the car at its start heading 0.2 rad
  // left: the line leaves along that heading (the second point on the ray),
  // a heading the bounds cannot follow is clamped to them
  std::vector<Vec2> ref, left, right;
  for (int i = 0; i <= 30; ++i) {
    ref.push_back({static_cast<double>(i), 0.0});
    left.push_back({static_cast<double>(i), 3.0});
    right.push_back({static_cast<double>(i), -3.0});
  }
  RacingLineParams p;
  p.clearance = 1.0;
  const RacingLine line = min_curvature_line(ref, left, right, false, p, true, 0.2);
  ASSERT_TRUE(line.ok()) << line.reason;
  const Vec2 d = line.points[1] - line.points[0];
  EXPECT_NEAR(std::atan2(d.y, d.x), 0.2, 1e-9);
  EXPECT_DOUBLE_EQ(line.offset.front(), 0.0);
  EXPECT_DOUBLE_EQ(line.offset.back(), 0.0);
  const RacingLine steep = min_curvature_line(ref, left, right, false, p, true, 1.5);
  ASSERT_TRUE(steep.ok()) << steep.reason;
  EXPECT_NEAR(steep.offset[1], steep.upper[1], 1e-12);
  EXPECT_NEAR(steep.upper[1], 2.0, 1e-9);
}

TEST(RacingLine, BadInputGivesAReason) {
  const std::vector<Vec2> ref = circle(13.0, 100), left = circle(10.0, 100), right = circle(16.0, 100);
  std::vector<Vec2> bad = ref;
  bad[3].x = std::nan("");
  EXPECT_FALSE(min_curvature_line(bad, left, right, true).ok());
  EXPECT_FALSE(min_curvature_line({{0, 0}, {1, 0}}, left, right, true).ok());
  EXPECT_FALSE(min_curvature_line(ref, {{0, 0}}, right, true).ok());
  RacingLineParams p;
  p.step = -1.0;
  const RacingLine r = min_curvature_line(ref, left, right, true, p);
  EXPECT_NE(r.reason.find("step"), std::string::npos) << r.reason;
}

}  // namespace
}  // namespace paddock::planning
