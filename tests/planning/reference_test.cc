// the reference trajectory: spline, arc-length samples, velocity profile.
#include "autonomy/planning/reference.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "autonomy/common/geometry.h"

namespace paddock::planning {
namespace {

std::vector<Vec2> polygon(double r, std::size_t n, Vec2 centre = {}) {
  std::vector<Vec2> p;
  for (std::size_t i = 0; i < n; ++i) {
    const double a = 2.0 * kPi * static_cast<double>(i) / static_cast<double>(n);
    p.push_back(centre + Vec2{r * std::cos(a), r * std::sin(a)});
  }
  return p;
}

TEST(Reference, ClosedCircleFrom36Gon) {
  const double r = 10.0;
  const ReferenceParams params;  // the car's defaults
  const auto res = build_reference(polygon(r, 36, {5.0, -3.0}), true, params);
  ASSERT_TRUE(res.ok()) << res.reason;
  const Trajectory& t = res.trajectory;
  ASSERT_FALSE(t.empty());
  EXPECT_TRUE(t.closed);
  EXPECT_NEAR(t.length, 2.0 * kPi * r, 0.005 * 2.0 * kPi * r);
  const double v_corner = std::sqrt(params.profile.ay_max * r);
  for (const auto& p : t.points) {
    EXPECT_NEAR(p.curvature, 1.0 / r, 0.02 / r) << p.s;
    EXPECT_NEAR(p.speed, v_corner, 0.01 * v_corner) << p.s;
    EXPECT_LE(p.speed * p.speed * std::abs(p.curvature), params.profile.ay_max + 1e-9);
  }
  // equal steps, the last one closing the loop
  const double step = t.length / static_cast<double>(t.points.size());
  EXPECT_NEAR(step, params.ds, 0.01);
  for (std::size_t i = 0; i < t.points.size(); ++i)
    EXPECT_NEAR(t.points[i].s, step * static_cast<double>(i), 1e-9);
  // it starts at the centreline's first point, heading counter-clockwise
  EXPECT_NEAR(t.points[0].x, 15.0, 1e-9);
  EXPECT_NEAR(t.points[0].y, -3.0, 1e-9);
  EXPECT_NEAR(t.points[0].heading, kPi / 2, 0.02);
  // lap time: the length at about the corner speed
  EXPECT_NEAR(lap_time(t), t.length / v_corner, 0.01 * t.length / v_corner);
}

TEST(Reference, ClosedCentrelineMayRepeatItsFirstPoint) {
  auto pts = polygon(10.0, 36);
  const auto a = build_reference(pts, true, ReferenceParams{});
  pts.push_back(pts.front());
  const auto b = build_reference(pts, true, ReferenceParams{});
  ASSERT_TRUE(a.ok() && b.ok());
  ASSERT_EQ(a.trajectory.points.size(), b.trajectory.points.size());
  EXPECT_DOUBLE_EQ(a.trajectory.length, b.trajectory.length);
}

TEST(Reference, OpenStraight) {
  // a 60 m straight given as uneven points along a diagonal
  const Vec2 dir = Vec2{1.0, 2.0} / std::sqrt(5.0);
  std::vector<Vec2> pts;
  for (double s : {0.0, 3.0, 4.0, 11.5, 20.0, 33.3, 41.0, 52.0, 60.0}) pts.push_back(Vec2{-2.0, 7.0} + dir * s);
  ReferenceParams params;
  const auto res = build_reference(pts, false, params, 2.0, 1.0);
  ASSERT_TRUE(res.ok()) << res.reason;
  const Trajectory& t = res.trajectory;
  EXPECT_FALSE(t.closed);
  EXPECT_NEAR(t.length, 60.0, 1e-9);
  ASSERT_EQ(t.points.size(), 121u);
  const double heading = std::atan2(dir.y, dir.x);
  const double step = t.length / 120.0;
  for (std::size_t i = 0; i < t.points.size(); ++i) {
    const auto& p = t.points[i];
    EXPECT_NEAR(p.curvature, 0.0, 1e-9) << i;
    EXPECT_NEAR(p.heading, heading, 1e-9) << i;
    EXPECT_NEAR(p.s, step * static_cast<double>(i), 1e-9);
    if (i > 0) {
      // equal spacing in real metres
      EXPECT_NEAR(distance(p.position(), t.points[i - 1].position()), step, 1e-6) << i;
    }
  }
  EXPECT_DOUBLE_EQ(t.points.front().speed, 2.0);
  EXPECT_DOUBLE_EQ(t.points.back().speed, 1.0);
  EXPECT_NEAR(t.points.front().x, -2.0, 1e-9);
  EXPECT_NEAR(t.points.back().y, 7.0 + dir.y * 60.0, 1e-9);
  // somewhere in the middle it is much faster
  EXPECT_GT(t.at(30.0).speed, 15.0);
}

TEST(Reference, TrajectoryAgreesWithItsOwnSamples) {
  // a stadium: the trajectory's interpolation lands on its samples
  std::vector<Vec2> pts;
  for (int i = 0; i <= 20; ++i) pts.push_back({2.0 * i, -10.0});
  for (int i = 1; i < 18; ++i) {
    const double a = -kPi / 2 + kPi * i / 18.0;
    pts.push_back({40.0 + 10.0 * std::cos(a), 10.0 * std::sin(a)});
  }
  for (int i = 20; i >= 0; --i) pts.push_back({2.0 * i, 10.0});
  for (int i = 1; i < 18; ++i) {
    const double a = kPi / 2 + kPi * i / 18.0;
    pts.push_back({10.0 * std::cos(a), 10.0 * std::sin(a)});
  }
  ReferenceParams params;
  params.profile.ay_max = 12.0;
  params.profile.turn_accel_scale = 1.0;
  const auto res = build_reference(pts, true, params);
  ASSERT_TRUE(res.ok()) << res.reason;
  const Trajectory& t = res.trajectory;
  EXPECT_NEAR(t.length, 80.0 + 20.0 * kPi, 0.01 * (80.0 + 20.0 * kPi));
  for (std::size_t i = 0; i < t.points.size(); i += 13) {
    const auto q = t.at(t.points[i].s);
    EXPECT_NEAR(q.x, t.points[i].x, 1e-9);
    EXPECT_NEAR(q.speed, t.points[i].speed, 1e-9);
  }
  // the speeds vary between the corner speed and a faster straight
  double vmin = 1e9, vmax = 0.0;
  for (const auto& p : t.points) {
    vmin = std::min(vmin, p.speed);
    vmax = std::max(vmax, p.speed);
  }
  // the slowest point: the corner speed, a little under it where the
  // interpolating spline overshoots the curvature step from 0 to 0.1 1/m
  EXPECT_LT(vmin, std::sqrt(12.0 * 10.0) + 1e-9);
  EXPECT_GT(vmin, 0.9 * std::sqrt(12.0 * 10.0));
  EXPECT_GT(vmax, vmin + 3.0);
  // headings follow the positions: the chord direction between samples
  for (std::size_t i = 0; i + 1 < t.points.size(); ++i) {
    const Vec2 d = t.points[i + 1].position() - t.points[i].position();
    const double mid = t.points[i].heading + 0.5 * wrap_angle(t.points[i + 1].heading - t.points[i].heading);
    EXPECT_NEAR(wrap_angle(angle_of(d) - mid), 0.0, 1e-3) << i;
  }
  const double lt = lap_time(t);
  EXPECT_GT(lt, t.length / vmax);
  EXPECT_LT(lt, t.length / vmin);
}

TEST(Reference, AbnormalInputsGiveAReasonAndNoTrajectory) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  auto fails = [](const std::vector<Vec2>& pts, bool closed, const ReferenceParams& p = ReferenceParams{}) {
    ReferenceResult res;
    EXPECT_NO_THROW(res = build_reference(pts, closed, p));
    EXPECT_FALSE(res.ok());
    EXPECT_FALSE(res.reason.empty());
    EXPECT_TRUE(res.trajectory.points.empty());
    return res.reason;
  };
  fails({}, false);
  fails({}, true);
  fails({{1.0, 2.0}}, false);
  fails({{0.0, 0.0}, {5.0, 0.0}}, true);
  fails({{0.0, 0.0}, {5.0, 0.0}, {5.0, 0.0}}, true);
  EXPECT_NE(fails({{0.0, 0.0}, {5.0, 0.0}, {5.0, 0.0}, {9.0, 0.0}}, false).find("coincide"), std::string::npos);
  fails({{0.0, 0.0}, {nan, 0.0}, {9.0, 0.0}}, false);
  fails({{0.0, 0.0}, {1.0, std::numeric_limits<double>::infinity()}}, false);
  ReferenceParams bad;
  bad.ds = 0.0;
  fails({{0.0, 0.0}, {9.0, 0.0}}, false, bad);
  bad = ReferenceParams{};
  bad.knot_spacing = nan;
  fails({{0.0, 0.0}, {9.0, 0.0}}, false, bad);
  bad = ReferenceParams{};
  bad.profile.ax_max = -1.0;
  fails({{0.0, 0.0}, {9.0, 0.0}}, false, bad);
  // an empty trajectory has no lap time
  EXPECT_EQ(lap_time(Trajectory{}), 0.0);
}

TEST(Reference, ShortOpenPathStillWorks) {
  // shorter than one knot spacing and one ds
  const auto res = build_reference({{0.0, 0.0}, {0.3, 0.0}}, false, ReferenceParams{}, 0.0, 0.0);
  ASSERT_TRUE(res.ok()) << res.reason;
  EXPECT_EQ(res.trajectory.points.size(), 2u);
  EXPECT_NEAR(res.trajectory.length, 0.3, 1e-12);
}

TEST(Reference, FromSplineMatchesBuild) {
  const auto pts = polygon(10.0, 36);
  const auto direct = build_reference(pts, true, ReferenceParams{});
  const auto fit = fit_spline(pts, true);
  ASSERT_TRUE(fit.ok());
  const auto res = reference_from_spline(fit.spline, ReferenceParams{});
  ASSERT_TRUE(res.ok() && direct.ok());
  EXPECT_NEAR(res.trajectory.length, 2.0 * kPi * 10.0, 0.01);
  EXPECT_FALSE(reference_from_spline(CubicSpline2D{}, ReferenceParams{}).ok());
}

}  // namespace
}  // namespace paddock::planning
