#include "autonomy/planning/spline.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>

namespace paddock::planning {

namespace {

// 8-point Gauss-Legendre on [-1, 1]: exact for polynomials of degree 15,
// and |r'(u)| (the root of a quartic) is smooth on one segment
constexpr std::array<double, 4> kGaussX = {0.1834346424956498, 0.5255324099163290,
                                           0.7966664774136267, 0.9602898564975363};
constexpr std::array<double, 4> kGaussW = {0.3626837833783620, 0.3137066458778873,
                                           0.2223810344533745, 0.1012285362903763};

// a tridiagonal system: sub[i] x[i-1] + diag[i] x[i] + sup[i] x[i+1] = rhs[i]
// (sub[0] and sup[n-1] unused); the Thomas algorithm, for the diagonally
// dominant matrices of the spline equations (no pivoting needed)
std::vector<double> solve_tridiagonal(const std::vector<double>& sub, std::vector<double> diag,
                                      const std::vector<double>& sup, std::vector<double> rhs) {
  const std::size_t n = diag.size();
  for (std::size_t i = 1; i < n; ++i) {
    const double w = sub[i] / diag[i - 1];
    diag[i] -= w * sup[i - 1];
    rhs[i] -= w * rhs[i - 1];
  }
  std::vector<double> x(n);
  x[n - 1] = rhs[n - 1] / diag[n - 1];
  for (std::size_t i = n - 1; i-- > 0;) x[i] = (rhs[i] - sup[i] * x[i + 1]) / diag[i];
  return x;
}

// a cyclic tridiagonal system: as above plus the corners A[0][n-1] = top
// and A[n-1][0] = bottom (n >= 3). Sherman-Morrison: A = A' + w v^T with
// w = (g, 0.., bottom), v = (1, 0.., top / g), g = -diag[0]; solve A' y = r
// and A' z = w, then x = y - z (v.y) / (1 + v.z).
std::vector<double> solve_cyclic(const std::vector<double>& sub, std::vector<double> diag,
                                 const std::vector<double>& sup, double top, double bottom,
                                 const std::vector<double>& rhs) {
  const std::size_t n = diag.size();
  assert(n >= 3);
  const double g = -diag[0];
  diag[0] -= g;
  diag[n - 1] -= bottom * top / g;
  const std::vector<double> y = solve_tridiagonal(sub, diag, sup, rhs);
  std::vector<double> w(n, 0.0);
  w[0] = g;
  w[n - 1] = bottom;
  const std::vector<double> z = solve_tridiagonal(sub, diag, sup, w);
  const double f = (y[0] + top * y[n - 1] / g) / (1.0 + z[0] + top * z[n - 1] / g);
  std::vector<double> x(n);
  for (std::size_t i = 0; i < n; ++i) x[i] = y[i] - f * z[i];
  return x;
}

// the segment polynomials from knot values y and second derivatives m:
// S_i(t) = y_i + b t + m_i/2 t^2 + (m_i+1 - m_i)/(6 h) t^3,
// b = (y_i+1 - y_i)/h - h (2 m_i + m_i+1)/6
std::vector<CubicPoly> polys(const std::vector<double>& h, const std::vector<double>& y,
                             const std::vector<double>& m) {
  std::vector<CubicPoly> out(h.size());
  for (std::size_t i = 0; i < h.size(); ++i) {
    out[i].a = y[i];
    out[i].b = (y[i + 1] - y[i]) / h[i] - h[i] * (2.0 * m[i] + m[i + 1]) / 6.0;
    out[i].c = 0.5 * m[i];
    out[i].d = (m[i + 1] - m[i]) / (6.0 * h[i]);
  }
  return out;
}

// second derivatives at the knots of an open spline (n + 1 knots): the
// standard moment equations
//   h_i-1 M_i-1 + 2 (h_i-1 + h_i) M_i + h_i M_i+1 = 6 (slope_i - slope_i-1)
// closed at each end by M = 0 (natural) or by the clamped slope s:
//   2 h_0 M_0 + h_0 M_1 = 6 (slope_0 - s_0),  h M_n-1 + 2 h M_n = 6 (s_n - slope_n-1)
std::vector<double> open_moments(const std::vector<double>& h, const std::vector<double>& y,
                                 std::optional<double> s0, std::optional<double> sn) {
  const std::size_t n = h.size();
  std::vector<double> sub(n + 1, 0.0), diag(n + 1, 0.0), sup(n + 1, 0.0), rhs(n + 1, 0.0);
  auto slope = [&](std::size_t i) { return (y[i + 1] - y[i]) / h[i]; };
  for (std::size_t i = 1; i < n; ++i) {
    sub[i] = h[i - 1];
    diag[i] = 2.0 * (h[i - 1] + h[i]);
    sup[i] = h[i];
    rhs[i] = 6.0 * (slope(i) - slope(i - 1));
  }
  if (s0) {
    diag[0] = 2.0 * h[0];
    sup[0] = h[0];
    rhs[0] = 6.0 * (slope(0) - *s0);
  } else {
    diag[0] = 1.0;
  }
  if (sn) {
    sub[n] = h[n - 1];
    diag[n] = 2.0 * h[n - 1];
    rhs[n] = 6.0 * (*sn - slope(n - 1));
  } else {
    diag[n] = 1.0;
  }
  return solve_tridiagonal(sub, diag, sup, rhs);
}

// second derivatives of a periodic spline: m unknowns (M_m = M_0), the same
// moment equations with indices wrapping round the loop
std::vector<double> periodic_moments(const std::vector<double>& h, const std::vector<double>& y) {
  const std::size_t m = h.size();
  std::vector<double> sub(m), diag(m), sup(m), rhs(m);
  for (std::size_t i = 0; i < m; ++i) {
    const std::size_t prev = (i + m - 1) % m;
    sub[i] = h[prev];
    diag[i] = 2.0 * (h[prev] + h[i]);
    sup[i] = h[i];
    rhs[i] = 6.0 * ((y[i + 1] - y[i]) / h[i] - (y[prev + 1] - y[prev]) / h[prev]);
  }
  std::vector<double> mom = solve_cyclic(sub, diag, sup, h[m - 1], h[m - 1], rhs);
  mom.push_back(mom[0]);
  return mom;
}

Vec2 eval_poly(const CubicPoly& px, const CubicPoly& py, double t, int order) {
  auto e = [t, order](const CubicPoly& p) {
    switch (order) {
      case 0: return p.a + t * (p.b + t * (p.c + t * p.d));
      case 1: return p.b + t * (2.0 * p.c + t * 3.0 * p.d);
      case 2: return 2.0 * p.c + 6.0 * p.d * t;
      default: return 0.0;
    }
  };
  return {e(px), e(py)};
}

}  // namespace

// builds the spline; a friend of CubicSpline2D
struct SplineBuilder {
  static SplineFit fit(const std::vector<Vec2>& points, bool closed, const SplineEnds& ends);
  // arc length of segment i from t = 0 to t
  static double partial_length(const CubicSpline2D& s, std::size_t i, double t);
};

// (|r'(t)|, the speed of a segment's parameter, is a modest number: the fit
// parameterises by chord length, so plain_norm)
double SplineBuilder::partial_length(const CubicSpline2D& s, std::size_t i, double t) {
  const double half = 0.5 * t;
  double sum = 0.0;
  for (std::size_t k = 0; k < kGaussX.size(); ++k) {
    for (const double sign : {-1.0, 1.0}) {
      sum += kGaussW[k] * plain_norm(eval_poly(s.px_[i], s.py_[i], half * (1.0 + sign * kGaussX[k]), 1));
    }
  }
  return half * sum;
}

SplineFit SplineBuilder::fit(const std::vector<Vec2>& points, bool closed, const SplineEnds& ends) {
  SplineFit out;
  const std::size_t np = points.size();
  const std::size_t min_points = closed ? 3 : 2;
  if (np < min_points) {
    out.reason = std::string("spline: a ") + (closed ? "closed" : "open") + " spline needs at least " +
                 std::to_string(min_points) + " points, got " + std::to_string(np);
    return out;
  }
  for (const Vec2& p : points) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) {
      out.reason = "spline: a point has a NaN or infinite coordinate";
      return out;
    }
  }
  for (const auto* t : {&ends.start_tangent, &ends.end_tangent}) {
    if (*t && !(std::isfinite(norm(**t)) && norm(**t) > 0.0)) {
      out.reason = "spline: a clamped end tangent must be finite and non-zero";
      return out;
    }
  }
  // the knot values, the loop closed by repeating the first point
  std::vector<double> x(points.size()), y(points.size());
  for (std::size_t i = 0; i < np; ++i) {
    x[i] = points[i].x;
    y[i] = points[i].y;
  }
  if (closed) {
    x.push_back(points[0].x);
    y.push_back(points[0].y);
  }
  // the parameter: cumulative chord length
  const std::size_t n = x.size() - 1;  // segments
  std::vector<double> h(n);
  CubicSpline2D& sp = out.spline;
  sp.u_.assign(n + 1, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    h[i] = std::hypot(x[i + 1] - x[i], y[i + 1] - y[i]);
    if (!(h[i] > 0.0)) {
      out.reason = "spline: points " + std::to_string(i) + " and " + std::to_string((i + 1) % np) +
                   " coincide";
      out.spline = CubicSpline2D{};
      return out;
    }
    sp.u_[i + 1] = sp.u_[i] + h[i];
  }
  // the knots' second derivatives, then the segment polynomials
  std::vector<double> mx, my;
  if (closed) {
    mx = periodic_moments(h, x);
    my = periodic_moments(h, y);
  } else {
    std::optional<double> sx0, sy0, sxn, syn;
    if (ends.start_tangent) {
      const Vec2 t = *ends.start_tangent / norm(*ends.start_tangent);
      sx0 = t.x;
      sy0 = t.y;
    }
    if (ends.end_tangent) {
      const Vec2 t = *ends.end_tangent / norm(*ends.end_tangent);
      sxn = t.x;
      syn = t.y;
    }
    mx = open_moments(h, x, sx0, sxn);
    my = open_moments(h, y, sy0, syn);
  }
  sp.px_ = polys(h, x, mx);
  sp.py_ = polys(h, y, my);
  sp.closed_ = closed;
  // the arc length at each knot, for arc-length queries
  sp.s_.assign(n + 1, 0.0);
  for (std::size_t i = 0; i < n; ++i) sp.s_[i + 1] = sp.s_[i] + partial_length(sp, i, h[i]);
  return out;
}

SplineFit fit_spline(const std::vector<Vec2>& points, bool closed, const SplineEnds& ends) {
  return SplineBuilder::fit(points, closed, ends);
}

double CubicSpline2D::wrap(double u) const {
  const double end = param_end();
  if (closed_) {
    u = std::fmod(u, end);
    if (u < 0.0) u += end;
    return u;
  }
  return std::clamp(u, 0.0, end);
}

std::size_t CubicSpline2D::segment_of(double u) const {
  // the last knot whose parameter is <= u, at most the last segment
  const auto it = std::upper_bound(u_.begin(), u_.end(), u);
  const std::size_t k = it == u_.begin() ? 0 : static_cast<std::size_t>(it - u_.begin()) - 1;
  return std::min(k, segments() - 1);
}

Vec2 CubicSpline2D::eval(double u, int order) const {
  assert(!empty());
  const double w = wrap(u);
  const std::size_t i = segment_of(w);
  return eval_poly(px_[i], py_[i], w - u_[i], order);
}

Vec2 CubicSpline2D::eval_segment(std::size_t seg, double t, int order) const {
  assert(seg < segments());
  return eval_poly(px_[seg], py_[seg], t, order);
}

double CubicSpline2D::heading(double u) const {
  const Vec2 d = eval(u, 1);
  return std::atan2(d.y, d.x);
}

double CubicSpline2D::curvature(double u) const {
  const Vec2 d1 = eval(u, 1);
  const Vec2 d2 = eval(u, 2);
  const double sp2 = squared_norm(d1);
  if (!(sp2 > 0.0)) return 0.0;
  return cross(d1, d2) / (sp2 * std::sqrt(sp2));
}

double CubicSpline2D::arc_length_at(double u) const {
  assert(!empty());
  const double w = std::clamp(u, 0.0, param_end());
  const std::size_t i = segment_of(w);
  return s_[i] + SplineBuilder::partial_length(*this, i, w - u_[i]);
}

double CubicSpline2D::arc_length(double u0, double u1) const {
  return arc_length_at(u1) - arc_length_at(u0);
}

std::optional<double> CubicSpline2D::param_at_arc_length(double s) const {
  if (empty() || !(s >= 0.0) || s > length() * (1.0 + 1e-12) + 1e-12) return std::nullopt;
  s = std::min(s, length());
  // the segment holding s, then Newton on L_i(t) = s - s_i with dL/dt = |r'(t)|,
  // kept inside a shrinking bracket [lo, hi] so that it cannot wander off
  const auto it = std::upper_bound(s_.begin(), s_.end(), s);
  std::size_t i = it == s_.begin() ? 0 : static_cast<std::size_t>(it - s_.begin()) - 1;
  i = std::min(i, segments() - 1);
  const double h = u_[i + 1] - u_[i];
  const double target = s - s_[i];
  const double seg_len = s_[i + 1] - s_[i];
  double lo = 0.0, hi = h;
  double t = seg_len > 0.0 ? std::clamp(h * target / seg_len, 0.0, h) : 0.0;
  for (int iter = 0; iter < 50; ++iter) {
    const double f = SplineBuilder::partial_length(*this, i, t) - target;
    if (std::abs(f) < 1e-12) break;
    if (f > 0.0) hi = t; else lo = t;
    const double d = plain_norm(eval_poly(px_[i], py_[i], t, 1));
    double next = d > 0.0 ? t - f / d : 0.5 * (lo + hi);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (std::abs(next - t) < 1e-14 * (1.0 + h)) {
      t = next;
      break;
    }
    t = next;
  }
  return u_[i] + t;
}

std::vector<SplineSample> sample_by_arc_length(const CubicSpline2D& spline, double ds,
                                               double* length) {
  std::vector<SplineSample> out;
  if (length) *length = 0.0;
  if (spline.empty() || !(ds > 0.0)) return out;
  const double total = spline.length();
  if (length) *length = total;
  // whole steps of equal arc length, as near to ds as divide the length
  const double steps = std::round(total / ds);
  const auto n = static_cast<std::size_t>(std::max(spline.closed() ? 3.0 : 1.0, steps));
  const double step = total / static_cast<double>(n);
  const std::size_t count = spline.closed() ? n : n + 1;
  out.reserve(count);
  for (std::size_t k = 0; k < count; ++k) {
    SplineSample p;
    p.s = k + 1 == count && !spline.closed() ? total : static_cast<double>(k) * step;
    p.u = k + 1 == count && !spline.closed() ? spline.param_end()
                                             : spline.param_at_arc_length(p.s).value_or(0.0);
    p.position = spline.position(p.u);
    p.heading = spline.heading(p.u);
    p.curvature = spline.curvature(p.u);
    out.push_back(p);
  }
  return out;
}

}  // namespace paddock::planning
