#pragma once
// a C2 cubic spline through 2D points, parametrised by cumulative chord
// length u: closed (periodic) or open (natural ends, or clamped end tangents).
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "autonomy/common/geometry.h"

namespace paddock::planning {

// end conditions of an open spline: a tangent direction (any non-zero
// length; it is scaled to unit length, the speed |r'| of a chord-length
// parametrisation) clamps that end; nothing leaves it natural (r'' = 0)
struct SplineEnds {
  std::optional<Vec2> start_tangent;
  std::optional<Vec2> end_tangent;
};

// one coordinate of one segment: a + b t + c t^2 + d t^3, t = u - u_i in [0, h_i]
struct CubicPoly {
  double a = 0.0, b = 0.0, c = 0.0, d = 0.0;
};

class CubicSpline2D {
 public:
  bool empty() const { return u_.size() < 2; }
  bool closed() const { return closed_; }
  std::size_t segments() const { return u_.empty() ? 0 : u_.size() - 1; }
  // the knots' parameters u_0 = 0 < ... < u_n (m of chord); a closed spline's
  // last knot is the first one again
  const std::vector<double>& knot_params() const { return u_; }
  double param_end() const { return u_.empty() ? 0.0 : u_.back(); }

  // value (order 0), first (1) or second (2) derivative with respect to u at
  // parameter u: wrapped into [0, param_end) when closed, clamped to the ends
  // when open
  Vec2 eval(double u, int order) const;
  Vec2 position(double u) const { return eval(u, 0); }
  Vec2 first_derivative(double u) const { return eval(u, 1); }
  Vec2 second_derivative(double u) const { return eval(u, 2); }
  // tangent direction atan2(y', x') (rad)
  double heading(double u) const;
  // signed curvature (x'y'' - y'x'') / (x'^2 + y'^2)^1.5 (1/m), > 0 turning left
  double curvature(double u) const;
  // |r'(u)| (m of arc per m of parameter)
  double speed(double u) const { return norm(eval(u, 1)); }

  // one segment's polynomial evaluated at local t in [0, h_i] (no wrapping):
  // evaluates either side of a knot, for continuity checks
  Vec2 eval_segment(std::size_t seg, double t, int order) const;

  // arc length of the whole curve (m), by 8-point Gauss-Legendre quadrature
  // on each segment (computed once, at the fit)
  double length() const { return s_.empty() ? 0.0 : s_.back(); }
  // arc length from u = 0 to u (m), u clamped into [0, param_end]
  double arc_length_at(double u) const;
  // arc length between two parameters (m), negative when u1 < u0
  double arc_length(double u0, double u1) const;
  // the parameter at arc length s in [0, length()], or nothing outside it
  // (Newton's method on the quadrature, safeguarded by bisection)
  std::optional<double> param_at_arc_length(double s) const;

 private:
  friend struct SplineBuilder;
  std::size_t segment_of(double u) const;
  double wrap(double u) const;

  std::vector<double> u_;
  std::vector<double> s_;           // arc length at each knot (m)
  std::vector<CubicPoly> px_, py_;  // one per segment
  bool closed_ = false;
};

// a fitted spline, or the reason why there is none
struct SplineFit {
  CubicSpline2D spline;
  std::string reason;  // empty when ok

  bool ok() const { return reason.empty(); }
};

// the interpolating C2 cubic spline through the points. Closed: periodic
// (the curve returns to points[0] with equal first and second derivatives;
// do not repeat the first point at the end), at least 3 points. Open: at
// least 2 points, natural ends unless `ends` clamps them. Consecutive points
// must differ (and, closed, the last from the first); NaN fails cleanly.
SplineFit fit_spline(const std::vector<Vec2>& points, bool closed, const SplineEnds& ends = {});

// a point of the curve at a given arc length
struct SplineSample {
  double s = 0.0;          // arc length from the start (m)
  double u = 0.0;          // spline parameter
  Vec2 position;
  double heading = 0.0;    // rad
  double curvature = 0.0;  // 1/m
};

// samples at equal arc-length spacing as close to `ds` as divides the
// curve's length into whole steps: open, from the first to the last point
// (both included); closed, from u = 0 round the loop without repeating it.
// `length` receives the total arc length. ds must be > 0.
std::vector<SplineSample> sample_by_arc_length(const CubicSpline2D& spline, double ds,
                                               double* length = nullptr);

}  // namespace paddock::planning
