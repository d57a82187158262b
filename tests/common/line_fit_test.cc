// the total-least-squares line fit: exact lines, a noisy line against a
// brute-force scan of directions, and degenerate input.
#include "autonomy/common/line_fit.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "autonomy/common/geometry.h"

namespace paddock {
namespace {

// the sum of squared perpendicular distances of the points from the line
// through `through` with direction angle `angle`
double squared_distances(const std::vector<Vec2>& pts, Vec2 through, double angle) {
  const Vec2 u = unit_from_angle(angle);
  double sum = 0.0;
  for (const Vec2& p : pts) {
    const double d = cross(u, p - through);
    sum += d * d;
  }
  return sum;
}

// the difference of two line directions, as angles modulo pi (rad)
double direction_error(Vec2 a, Vec2 b) { return std::asin(std::min(1.0, std::abs(cross(a, b)))); }

TEST(LineFit, IsTotalLeastSquares) {
  // exact points on a slanted line
  std::vector<Vec2> pts;
  for (int i = 0; i < 10; ++i) pts.push_back({1.0 + 2.0 * i, -3.0 + 1.0 * i});
  LineFit f = fit_line(pts);
  ASSERT_TRUE(f.ok());
  EXPECT_NEAR(std::abs(cross(f.direction, Vec2{2.0, 1.0} / std::sqrt(5.0))), 0.0, 1e-12);
  EXPECT_NEAR(f.rms, 0.0, 1e-9);
  EXPECT_NEAR(f.point.x, 10.0, 1e-12);
  EXPECT_NEAR(f.point.y, 1.5, 1e-12);
  // points alternately 0.2 m either side of the x axis: rms 0.2, along x
  pts.clear();
  for (int i = 0; i < 20; ++i) pts.push_back({1.0 * i, i % 2 ? 0.2 : -0.2});
  f = fit_line(pts);
  ASSERT_TRUE(f.ok());
  EXPECT_NEAR(std::abs(f.direction.x), 1.0, 1e-3);
  EXPECT_NEAR(f.rms, 0.2, 1e-3);
  // a vertical line (ordinary least squares y(x) would fail here)
  pts = {{2.0, 0.0}, {2.0, 1.0}, {2.0, 5.0}};
  f = fit_line(pts);
  ASSERT_TRUE(f.ok());
  EXPECT_NEAR(std::abs(f.direction.y), 1.0, 1e-12);
}

TEST(LineFit, MatchesABruteForceScanOfDirections) {
  // points along a known line with noise across it (and a little along it)
  const double true_angle = 2.3;  // rad
  const Vec2 through{4.0, -7.0};
  const Vec2 u = unit_from_angle(true_angle), n = left_normal(u);
  std::mt19937 rng(17);
  std::normal_distribution<double> across(0.0, 0.3), along(0.0, 0.5);
  std::vector<Vec2> pts;
  for (int i = 0; i < 60; ++i) {
    const double t = -25.0 + 50.0 * i / 59.0 + along(rng);
    pts.push_back(through + u * t + n * across(rng));
  }
  const LineFit f = fit_line(pts);
  ASSERT_TRUE(f.ok());
  EXPECT_NEAR(norm(f.direction), 1.0, 1e-12);

  // brute force: for any direction the best line passes through the
  // centroid (the mean of the signed distances is their minimiser), so scan
  // the angle over [0, pi) in 1e-4 rad steps, then 1e-7 rad steps around the best
  Vec2 centroid;
  for (const Vec2& p : pts) centroid += p;
  centroid = centroid / static_cast<double>(pts.size());
  double best_angle = 0.0, best = squared_distances(pts, centroid, 0.0);
  for (int k = 1; k < 31416; ++k) {
    const double a = 1e-4 * k;
    const double s = squared_distances(pts, centroid, a);
    if (s < best) {
      best = s;
      best_angle = a;
    }
  }
  const double coarse = best_angle;
  for (int k = -2000; k <= 2000; ++k) {
    const double a = coarse + 1e-7 * k;
    const double s = squared_distances(pts, centroid, a);
    if (s < best) {
      best = s;
      best_angle = a;
    }
  }
  EXPECT_LT(direction_error(f.direction, unit_from_angle(best_angle)), 1e-6);
  EXPECT_NEAR(f.rms, std::sqrt(best / static_cast<double>(pts.size())), 1e-9);
  EXPECT_NEAR(f.point.x, centroid.x, 1e-12);
  EXPECT_NEAR(f.point.y, centroid.y, 1e-12);
  // no scanned direction fits better than the fitted one
  EXPECT_LE(squared_distances(pts, f.point, angle_of(f.direction)), best + 1e-9);
  // and the fit recovers the true line to within the noise
  EXPECT_LT(direction_error(f.direction, u), 0.01);
  EXPECT_LT(std::abs(cross(u, f.point - through)), 0.15);
  EXPECT_NEAR(f.rms, 0.3, 0.06);
}

TEST(LineFit, DegenerateInputGivesAReason) {
  EXPECT_FALSE(fit_line({}).ok());
  EXPECT_FALSE(fit_line({{1.0, 1.0}}).ok());
  EXPECT_FALSE(fit_line({{1.0, 1.0}, {1.0, 1.0}, {1.0, 1.0}}).ok());
  EXPECT_FALSE(fit_line({{1.0, 1.0}, {std::nan(""), 1.0}}).ok());
  EXPECT_FALSE(fit_line({{1.0, 1.0}, {2.0, std::numeric_limits<double>::infinity()}}).ok());
  // two distinct points are enough
  const LineFit f = fit_line({{0.0, 0.0}, {0.0, 3.0}});
  ASSERT_TRUE(f.ok());
  EXPECT_NEAR(std::abs(f.direction.y), 1.0, 1e-12);
  EXPECT_NEAR(f.rms, 0.0, 1e-12);
}

}  // namespace
}  // namespace paddock
