#include "autonomy/planning/racing_line.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <optional>

#include <ceres/jet.h>

#include "autonomy/common/polyline.h"
#include "autonomy/planning/interior_point.h"

namespace paddock::planning {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

bool all_finite(const std::vector<Vec2>& pts) {
  return std::all_of(pts.begin(), pts.end(), [](Vec2 p) { return finite(p); });
}

// the distance along the ray o + t d (t > 0, d a unit vector) to the first
// crossing of the polyline, infinite when it crosses none
double ray_distance(Vec2 o, Vec2 d, const std::vector<Vec2>& line, bool closed, double max_gap) {
  double best = kInf;
  const std::size_t n = line.size();
  const std::size_t segments = closed ? n : (n > 0 ? n - 1 : 0);
  for (std::size_t i = 0; i < segments; ++i) {
    const Vec2 a = line[i], b = line[(i + 1) % n];
    const Vec2 e = b - a;
    if (squared_norm(e) > max_gap * max_gap) continue;  // a gap, not a boundary
    const double den = cross(d, e);
    if (std::abs(den) < 1e-12) continue;  // parallel
    const Vec2 w = a - o;
    const double t = cross(w, e) / den;  // along the ray
    const double u = cross(w, d) / den;  // along the segment
    if (t > 0.0 && u >= 0.0 && u <= 1.0) best = std::min(best, t);
  }
  return best;
}

// the curvature of the circle through three points, 2 (a x b) / (|a| |b| |a + b|),
// times sqrt(ds) with ds half the two chords (the length the point stands
// for): its square summed is sum kappa^2 ds (curvature_cost). Templated for
// Ceres' automatic differentiation, which gives each residual's gradient.
struct MengerResidual {
  Vec2 r0, r1, r2;  // reference points
  Vec2 n0, n1, n2;  // their unit normals

  template <class T>
  bool operator()(const T* a0, const T* a1, const T* a2, T* residual) const {
    using std::sqrt;
    const T x0 = r0.x + a0[0] * n0.x, y0 = r0.y + a0[0] * n0.y;
    const T x1 = r1.x + a1[0] * n1.x, y1 = r1.y + a1[0] * n1.y;
    const T x2 = r2.x + a2[0] * n2.x, y2 = r2.y + a2[0] * n2.y;
    const T ax = x1 - x0, ay = y1 - y0, bx = x2 - x1, by = y2 - y1, cx = x2 - x0, cy = y2 - y0;
    const T la = sqrt(ax * ax + ay * ay), lb = sqrt(bx * bx + by * by), lc = sqrt(cx * cx + cy * cy);
    residual[0] = sqrt(0.5 * (la + lb)) * 2.0 * (ax * by - ay * bx) / (la * lb * lc);
    return true;
  }
};

double menger(Vec2 p0, Vec2 p1, Vec2 p2) {
  const Vec2 a = p1 - p0, b = p2 - p1, c = p2 - p0;
  const double den = norm(a) * norm(b) * norm(c);
  return den > 0.0 ? 2.0 * cross(a, b) / den : 0.0;
}

// rounds of tightening the bounds where the Euclidean clearance falls short
constexpr int kClearanceRounds = 4;
// m: a shortfall smaller than this is left alone
constexpr double kClearanceTolerance = 0.005;

// the cost as sum_k r_k(a)^2 for the interior-point solver: one Menger
// residual per inner point, a function of its offset and its neighbours',
// its gradient from Ceres' automatic differentiation (its Jet type: the
// functor is called here as ceres::AutoDiffCostFunction<MengerResidual, 1,
// 1, 1, 1>::Evaluate would call it, one Jet per offset with its own unit
// derivative, without the virtual call and the copying in and out; the
// same operations, so the same bits)
class MengerTerms : public SparseLeastSquares {
 public:
  MengerTerms(const std::vector<Vec2>& r, const std::vector<Vec2>& normal, bool closed) {
    const std::size_t n = r.size();
    for (std::size_t i = closed ? 0 : 1; i < (closed ? n : n - 1); ++i) {
      const std::size_t a = (i + n - 1) % n, c = (i + 1) % n;
      terms_.push_back({{static_cast<int>(a), static_cast<int>(i), static_cast<int>(c)},
                        MengerResidual{r[a], r[i], r[c], normal[a], normal[i], normal[c]}});
    }
  }

  std::size_t residuals() const override { return terms_.size(); }
  std::size_t arity(std::size_t) const override { return 3; }
  const int* variables(std::size_t k) const override { return terms_[k].index; }
  double residual(std::size_t k, const double* x, double* jacobian) const override {
    const Term& t = terms_[k];
    if (!jacobian) {
      double value = 0.0;
      t.cost(&x[t.index[0]], &x[t.index[1]], &x[t.index[2]], &value);
      return value;
    }
    using Jet = ceres::Jet<double, 3>;
    const Jet a0(x[t.index[0]], 0), a1(x[t.index[1]], 1), a2(x[t.index[2]], 2);
    Jet value;
    t.cost(&a0, &a1, &a2, &value);
    for (int p = 0; p < 3; ++p) jacobian[p] = value.v[p];
    return value.a;
  }

 private:
  struct Term {
    int index[3];
    MengerResidual cost;
  };
  std::vector<Term> terms_;
};

// one solve from `offset` (within the bounds); returns the Newton
// iterations, -1 when it failed (the offsets are then left as they were)
int solve(const MengerTerms& terms, int max_iterations, const std::vector<double>& lower,
          const std::vector<double>& upper, std::vector<double>& offset) {
  std::vector<double> x = offset;
  InteriorPointOptions options;
  options.max_iterations = max_iterations;
  const InteriorPointResult result = minimise_within_bounds(terms, lower, upper, x, options);
  if (!result.usable() || !std::all_of(x.begin(), x.end(), [](double v) { return std::isfinite(v); })) return -1;
  offset = x;
  return result.iterations;
}

}  // namespace

double curvature_cost(const std::vector<Vec2>& pts, bool closed) {
  const std::size_t n = pts.size();
  if (n < 3) return 0.0;
  double cost = 0.0;
  for (std::size_t i = closed ? 0 : 1; i < (closed ? n : n - 1); ++i) {
    const Vec2 p0 = pts[(i + n - 1) % n], p1 = pts[i], p2 = pts[(i + 1) % n];
    const double k = menger(p0, p1, p2);
    cost += k * k * 0.5 * (distance(p0, p1) + distance(p1, p2));
  }
  return cost;
}

RacingLine min_curvature_line(const std::vector<Vec2>& reference, const std::vector<Vec2>& left,
                              const std::vector<Vec2>& right, bool closed, const RacingLineParams& params,
                              bool pin_ends, std::optional<double> start_heading) {
  RacingLine out;
  if (const std::string bad = params::validate(params); !bad.empty()) {
    out.reason = "racing line: " + bad;
    return out;
  }
  if (!all_finite(reference) || !all_finite(left) || !all_finite(right)) {
    out.reason = "racing line: a point is NaN or infinite";
    return out;
  }
  if (left.size() < 2 || right.size() < 2) {
    out.reason = "racing line: each boundary needs at least 2 points";
    return out;
  }
  std::vector<Vec2> r = resample(reference, closed, params.step);
  // a closed resample may end on its start again
  if (closed && r.size() > 1 && distance(r.front(), r.back()) < 1e-6 * params.step) r.pop_back();
  const std::size_t n = r.size();
  if (n < (closed ? 3u : 4u)) {
    out.reason = "racing line: the reference is too short (" + std::to_string(n) + " points at " +
                 params::number(params.step) + " m)";
    return out;
  }

  // the normals (central differences) and the offsets' bounds
  std::vector<Vec2> normal(n);
  out.lower.resize(n);
  out.upper.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2 prev = closed ? r[(i + n - 1) % n] : r[i == 0 ? 0 : i - 1];
    const Vec2 next = closed ? r[(i + 1) % n] : r[std::min(i + 1, n - 1)];
    const Vec2 t = next - prev;
    const double len = norm(t);
    if (!(len > 0.0)) {
      out.reason = "racing line: the reference doubles back on itself";
      return out;
    }
    normal[i] = left_normal((1.0 / len) * t);
    double dl = ray_distance(r[i], normal[i], left, closed, params.max_gap);
    double dr = ray_distance(r[i], -1.0 * normal[i], right, closed, params.max_gap);
    // no boundary within reach: the point may not move to that side
    if (!(dl <= params.reach)) dl = params.clearance;
    if (!(dr <= params.reach)) dr = params.clearance;
    double lo = -(dr - params.clearance), hi = dl - params.clearance;
    if (lo > hi) lo = hi = 0.5 * (lo + hi);  // narrower than twice the clearance: midway
    out.lower[i] = lo;
    out.upper[i] = hi;
  }
  if (pin_ends && !closed) {
    out.lower.front() = out.upper.front() = out.lower.back() = out.upper.back() = 0.0;
    // r_1 + a n_1 - r_0 along h: cross(h, r_1 - r_0) + a cross(h, n_1) = 0
    const Vec2 h{std::cos(start_heading.value_or(0.0)), std::sin(start_heading.value_or(0.0))};
    const double c = cross(h, normal[1]);
    if (start_heading && std::isfinite(*start_heading) && n > 2 && std::abs(c) > 1e-6) {
      const double a = std::clamp(-cross(h, r[1] - r[0]) / c, out.lower[1], out.upper[1]);
      out.lower[1] = out.upper[1] = a;
    }
  }

  // the problem: one offset per point, one curvature residual per inner
  // point. The bounds come from distances along the normals; where a
  // boundary bends towards a point, the true (Euclidean) distance of the
  // solved point can be shorter, so that side's bound is tightened by the
  // shortfall and the problem solved again from there (a few rounds)
  out.offset.assign(n, 0.0);
  for (std::size_t i = 0; i < n; ++i) out.offset[i] = std::clamp(0.0, out.lower[i], out.upper[i]);
  const MengerTerms terms(r, normal, closed);
  for (int round = 0; round < kClearanceRounds; ++round) {
    const int iterations = solve(terms, params.max_iterations, out.lower, out.upper, out.offset);
    if (iterations < 0) {
      out.reason = "racing line: the optimiser failed";
      return out;
    }
    out.iterations += iterations;
    // each point and the point half-way to the next (a line wrapping round a
    // cone at exactly the clearance comes closer between its points); a
    // shortfall half-way tightens both ends
    bool tightened = false;
    const auto tighten = [&](std::size_t i, double short_left, double short_right) {
      if (short_left > kClearanceTolerance && out.upper[i] - short_left >= out.lower[i]) {
        out.upper[i] -= short_left;
        out.offset[i] = std::min(out.offset[i], out.upper[i]);
        tightened = true;
      }
      if (short_right > kClearanceTolerance && out.lower[i] + short_right <= out.upper[i]) {
        out.lower[i] += short_right;
        out.offset[i] = std::max(out.offset[i], out.lower[i]);
        tightened = true;
      }
    };
    std::vector<double> short_left(n), short_right(n), mid_left(n, 0.0), mid_right(n, 0.0);
    for (std::size_t i = 0; i < n; ++i) {
      const Vec2 q = r[i] + out.offset[i] * normal[i];
      short_left[i] = params.clearance - polyline_distance(left, closed, q);
      short_right[i] = params.clearance - polyline_distance(right, closed, q);
      if (!closed && i + 1 == n) continue;
      const std::size_t j = (i + 1) % n;
      const Vec2 m = 0.5 * (q + r[j] + out.offset[j] * normal[j]);
      mid_left[i] = params.clearance - polyline_distance(left, closed, m);
      mid_right[i] = params.clearance - polyline_distance(right, closed, m);
    }
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t h = closed ? (i + n - 1) % n : (i == 0 ? 0 : i - 1);  // the half-way point before
      tighten(i, std::max({short_left[i], mid_left[i], mid_left[h]}), std::max({short_right[i], mid_right[i], mid_right[h]}));
    }
    if (!tightened) break;
  }

  out.reference = r;
  out.points.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    out.points[i] = r[i] + out.offset[i] * normal[i];
  }
  out.cost_reference = curvature_cost(r, closed);
  out.cost = curvature_cost(out.points, closed);
  if (!std::isfinite(out.cost)) {
    out.reason = "racing line: the solver gave a non-finite line";
    out.points.clear();
  }
  return out;
}

}  // namespace paddock::planning
