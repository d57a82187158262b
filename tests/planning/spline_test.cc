// the C2 cubic spline: interpolation, continuity, curvature, arc length.
#include "autonomy/planning/spline.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "autonomy/common/geometry.h"

namespace paddock::planning {
namespace {

std::vector<Vec2> arc_points(double r, double a0, double a1, std::size_t n, bool endpoint) {
  std::vector<Vec2> p;
  const double den = static_cast<double>(endpoint ? n - 1 : n);
  for (std::size_t i = 0; i < n; ++i) {
    const double a = a0 + (a1 - a0) * static_cast<double>(i) / den;
    p.push_back({r * std::cos(a), r * std::sin(a)});
  }
  return p;
}

// an irregular closed loop with uneven knot spacing
std::vector<Vec2> blob() {
  std::vector<Vec2> p;
  for (int i = 0; i < 23; ++i) {
    const double t = 2.0 * kPi * (i + 0.3 * std::sin(i)) / 23.0;
    const double r = 20.0 + 4.0 * std::sin(3.0 * t) + 2.0 * std::cos(5.0 * t);
    p.push_back({r * std::cos(t) + 3.0, 0.7 * r * std::sin(t) - 1.0});
  }
  return p;
}

// Simpson's rule on |r'(u)| with many panels: an independent arc length
double simpson_length(const CubicSpline2D& s, double u0, double u1) {
  const int n = 20000;
  const double h = (u1 - u0) / n;
  double sum = s.speed(u0) + s.speed(u1);
  for (int i = 1; i < n; ++i) sum += (i % 2 ? 4.0 : 2.0) * s.speed(u0 + i * h);
  return sum * h / 3.0;
}

TEST(Spline, InterpolatesKnots) {
  for (bool closed : {false, true}) {
    const auto pts = blob();
    const auto fit = fit_spline(pts, closed);
    ASSERT_TRUE(fit.ok()) << fit.reason;
    const auto& u = fit.spline.knot_params();
    ASSERT_EQ(u.size(), closed ? pts.size() + 1 : pts.size());
    EXPECT_DOUBLE_EQ(u.front(), 0.0);
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const Vec2 p = fit.spline.position(u[i]);
      EXPECT_NEAR(p.x, pts[i].x, 1e-10) << i;
      EXPECT_NEAR(p.y, pts[i].y, 1e-10) << i;
      // the chord-length parameter
      if (i > 0) {
        EXPECT_NEAR(u[i] - u[i - 1], distance(pts[i], pts[i - 1]), 1e-12);
      }
    }
    if (closed) {
      const Vec2 p = fit.spline.position(u.back());
      EXPECT_NEAR(p.x, pts[0].x, 1e-10);
      EXPECT_NEAR(p.y, pts[0].y, 1e-10);
    }
  }
}

TEST(Spline, C2AtEveryKnotIncludingTheClosingOne) {
  for (bool closed : {false, true}) {
    const auto fit = fit_spline(blob(), closed);
    ASSERT_TRUE(fit.ok());
    const auto& s = fit.spline;
    const auto& u = s.knot_params();
    const std::size_t m = s.segments();
    // interior knots, and for a closed spline the knot where it closes
    const std::size_t last = closed ? m : m - 1;
    for (std::size_t i = 0; i < last; ++i) {
      const std::size_t next = (i + 1) % m;
      for (int order = 0; order <= 2; ++order) {
        const Vec2 left = s.eval_segment(i, u[i + 1] - u[i], order);
        const Vec2 right = s.eval_segment(next, 0.0, order);
        EXPECT_NEAR(left.x, right.x, 1e-9) << "knot " << i + 1 << " order " << order;
        EXPECT_NEAR(left.y, right.y, 1e-9) << "knot " << i + 1 << " order " << order;
      }
    }
    if (!closed) {
      // natural ends
      const Vec2 a = s.eval_segment(0, 0.0, 2);
      const Vec2 b = s.eval_segment(m - 1, u[m] - u[m - 1], 2);
      EXPECT_NEAR(norm(a), 0.0, 1e-12);
      EXPECT_NEAR(norm(b), 0.0, 1e-12);
    }
  }
}

TEST(Spline, ClosedCircleCurvatureEverywhere) {
  const double r = 10.0;
  const auto fit = fit_spline(arc_points(r, 0.0, 2.0 * kPi, 36, false), true);
  ASSERT_TRUE(fit.ok());
  const auto& s = fit.spline;
  for (int k = 0; k <= 2000; ++k) {
    const double u = s.param_end() * k / 2000.0;
    EXPECT_NEAR(s.curvature(u), 1.0 / r, 1e-3) << u;
    EXPECT_NEAR(norm(s.position(u)), r, 2e-3) << u;
    // counter-clockwise: the heading leads the polar angle by 90 degrees
    const Vec2 p = s.position(u);
    EXPECT_NEAR(wrap_angle(s.heading(u) - angle_of(p) - kPi / 2), 0.0, 1e-3) << u;
  }
  // clockwise: negative curvature
  auto cw = arc_points(r, 0.0, -2.0 * kPi, 36, false);
  const auto fit_cw = fit_spline(cw, true);
  ASSERT_TRUE(fit_cw.ok());
  EXPECT_NEAR(fit_cw.spline.curvature(3.3), -1.0 / r, 1e-3);
  // its length: 36 chords of a circle give the circle's length within 0.01 %
  EXPECT_NEAR(s.length(), 2.0 * kPi * r, 2.0 * kPi * r * 1e-4);
}

TEST(Spline, OpenArcCurvatureAwayFromTheEnds) {
  const double r = 10.0;
  const auto fit = fit_spline(arc_points(r, 0.0, 1.5 * kPi, 40, true), false);
  ASSERT_TRUE(fit.ok());
  const auto& s = fit.spline;
  // natural ends force zero curvature at the ends; a few knots in, the arc
  const double u0 = s.param_end() * 0.2, u1 = s.param_end() * 0.8;
  for (int k = 0; k <= 500; ++k) {
    const double u = u0 + (u1 - u0) * k / 500.0;
    EXPECT_NEAR(s.curvature(u), 1.0 / r, 1e-3) << u;
  }
  EXPECT_NEAR(s.curvature(0.0), 0.0, 1e-12);
}

TEST(Spline, ClampedEndsTakeTheGivenTangents) {
  const double r = 10.0;
  const auto pts = arc_points(r, 0.0, 1.5 * kPi, 40, true);
  SplineEnds ends;
  ends.start_tangent = Vec2{0.0, 3.0};   // any length: only the direction counts
  ends.end_tangent = Vec2{1.0, 0.0};     // at angle 1.5 pi, counter-clockwise: +x
  const auto fit = fit_spline(pts, false, ends);
  ASSERT_TRUE(fit.ok());
  const auto& s = fit.spline;
  const Vec2 d0 = s.first_derivative(0.0);
  const Vec2 d1 = s.first_derivative(s.param_end());
  EXPECT_NEAR(d0.x, 0.0, 1e-12);
  EXPECT_NEAR(d0.y, 1.0, 1e-12);
  EXPECT_NEAR(d1.x, 1.0, 1e-12);
  EXPECT_NEAR(d1.y, 0.0, 1e-12);
  // clamped to the circle's own tangents, the curvature is right to the ends
  for (int k = 0; k <= 500; ++k) {
    const double u = s.param_end() * k / 500.0;
    EXPECT_NEAR(s.curvature(u), 1.0 / r, 1e-3) << u;
  }
  // one end clamped, the other natural
  SplineEnds one;
  one.start_tangent = Vec2{0.0, 1.0};
  const auto half = fit_spline(pts, false, one);
  ASSERT_TRUE(half.ok());
  EXPECT_NEAR(half.spline.first_derivative(0.0).y, 1.0, 1e-12);
  EXPECT_NEAR(norm(half.spline.second_derivative(half.spline.param_end())), 0.0, 1e-12);
}

TEST(Spline, StraightLineHasZeroCurvature) {
  // uneven spacing along a line
  std::vector<Vec2> pts;
  double t = 0.0;
  for (int i = 0; i < 12; ++i) {
    pts.push_back(Vec2{1.0, 2.0} + Vec2{3.0, -4.0} * (t / 5.0));
    t += 0.5 + 0.37 * (i % 3);
  }
  for (bool clamped : {false, true}) {
    SplineEnds ends;
    if (clamped) ends.start_tangent = ends.end_tangent = Vec2{3.0, -4.0};
    const auto fit = fit_spline(pts, false, ends);
    ASSERT_TRUE(fit.ok());
    const auto& s = fit.spline;
    for (int k = 0; k <= 300; ++k) {
      const double u = s.param_end() * k / 300.0;
      EXPECT_NEAR(s.curvature(u), 0.0, 1e-12);
      EXPECT_NEAR(s.heading(u), std::atan2(-4.0, 3.0), 1e-12);
      EXPECT_NEAR(s.speed(u), 1.0, 1e-12);
    }
    EXPECT_NEAR(s.length(), distance(pts.front(), pts.back()), 1e-9);
  }
  // two points: the segment itself
  const auto two = fit_spline({{0.0, 0.0}, {4.0, 3.0}}, false);
  ASSERT_TRUE(two.ok());
  EXPECT_NEAR(two.spline.length(), 5.0, 1e-12);
  EXPECT_NEAR(two.spline.position(2.5).x, 2.0, 1e-12);
  EXPECT_NEAR(two.spline.curvature(1.0), 0.0, 1e-15);
}

TEST(Spline, ArcLengthAgainstSimpson) {
  for (bool closed : {false, true}) {
    const auto fit = fit_spline(blob(), closed);
    ASSERT_TRUE(fit.ok());
    const auto& s = fit.spline;
    EXPECT_NEAR(s.length(), simpson_length(s, 0.0, s.param_end()), 1e-7);
    const double u0 = 0.13 * s.param_end(), u1 = 0.71 * s.param_end();
    EXPECT_NEAR(s.arc_length(u0, u1), simpson_length(s, u0, u1), 1e-7);
    // the inverse
    for (double frac : {0.0, 0.01, 0.25, 0.5, 0.999, 1.0}) {
      const double target = frac * s.length();
      const auto u = s.param_at_arc_length(target);
      ASSERT_TRUE(u.has_value());
      EXPECT_NEAR(s.arc_length_at(*u), target, 1e-9) << frac;
    }
    EXPECT_FALSE(s.param_at_arc_length(-1.0).has_value());
    EXPECT_FALSE(s.param_at_arc_length(s.length() + 1.0).has_value());
  }
}

TEST(Spline, SamplesAreEquallySpacedInRealMetres) {
  for (bool closed : {false, true}) {
    const auto fit = fit_spline(blob(), closed);
    ASSERT_TRUE(fit.ok());
    const auto& s = fit.spline;
    double length = 0.0;
    const auto samples = sample_by_arc_length(s, 0.5, &length);
    EXPECT_DOUBLE_EQ(length, s.length());
    const std::size_t nseg = closed ? samples.size() : samples.size() - 1;
    const double step = length / static_cast<double>(nseg);
    EXPECT_NEAR(step, 0.5, 0.5 / static_cast<double>(nseg) + 1e-12);
    for (std::size_t i = 0; i + 1 < samples.size(); i += 7) {
      // the true arc length between consecutive samples, independently integrated
      EXPECT_NEAR(simpson_length(s, samples[i].u, samples[i + 1].u), step, 1e-6) << i;
      EXPECT_NEAR(samples[i].s, step * static_cast<double>(i), 1e-9);
    }
    if (closed) {
      EXPECT_NEAR(simpson_length(s, samples.back().u, s.param_end()), step, 1e-6);
    } else {
      EXPECT_DOUBLE_EQ(samples.back().u, s.param_end());
      EXPECT_DOUBLE_EQ(samples.back().s, length);
    }
    for (const auto& p : samples) {
      const Vec2 q = s.position(p.u);
      EXPECT_EQ(q.x, p.position.x);
      EXPECT_EQ(q.y, p.position.y);
      EXPECT_DOUBLE_EQ(p.curvature, s.curvature(p.u));
    }
  }
}

TEST(Spline, AbnormalInputsGiveAReason) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  auto fails = [](const std::vector<Vec2>& pts, bool closed, const SplineEnds& ends = {}) {
    const auto fit = fit_spline(pts, closed, ends);
    EXPECT_FALSE(fit.ok());
    EXPECT_FALSE(fit.reason.empty());
    EXPECT_TRUE(fit.spline.empty());
  };
  fails({}, false);
  fails({{1.0, 1.0}}, false);
  fails({{0.0, 0.0}, {1.0, 0.0}}, true);
  fails({{0.0, 0.0}, {1.0, 0.0}, {1.0, 0.0}, {2.0, 0.0}}, false);  // duplicate
  fails({{0.0, 0.0}, {1.0, 0.0}, {1.0, 1.0}, {0.0, 0.0}}, true);   // closing duplicate
  fails({{0.0, 0.0}, {nan, 0.0}, {2.0, 0.0}}, false);
  SplineEnds zero;
  zero.start_tangent = Vec2{0.0, 0.0};
  fails({{0.0, 0.0}, {1.0, 0.0}}, false, zero);
  // an empty spline samples to nothing
  EXPECT_TRUE(sample_by_arc_length(CubicSpline2D{}, 0.5).empty());
}

}  // namespace
}  // namespace paddock::planning
