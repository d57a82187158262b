#include "autonomy/planning/racing_line.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <utility>

#include <ceres/ceres.h>
#include <IpIpoptApplication.hpp>
#include <IpSolveStatistics.hpp>
#include <IpTNLP.hpp>

#include "autonomy/common/polyline.h"

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

// the problem for IPOPT: minimise f(a) = sum_k r_k(a)^2 within the bounds,
// no other constraints. Each residual r_k touches three neighbouring offsets;
// its gradient comes from Ceres' automatic differentiation. The Hessian
// given is the Gauss-Newton one, 2 sum_k J_k^T J_k (positive semi-definite,
// the curvature residuals' own second derivatives left out), a band of
// width 2 round the loop.
class MinCurvatureNlp : public Ipopt::TNLP {
 public:
  using Index = Ipopt::Index;
  using Number = Ipopt::Number;

  MinCurvatureNlp(const std::vector<Vec2>& r, const std::vector<Vec2>& normal, bool closed,
                  const std::vector<double>& lower, const std::vector<double>& upper, std::vector<double>& offset)
      : lower_(lower), upper_(upper), offset_(offset) {
    const std::size_t n = r.size();
    for (std::size_t i = closed ? 0 : 1; i < (closed ? n : n - 1); ++i) {
      const std::size_t a = (i + n - 1) % n, c = (i + 1) % n;
      residuals_.push_back({{a, i, c},
                            std::make_unique<ceres::AutoDiffCostFunction<MengerResidual, 1, 1, 1, 1>>(
                                new MengerResidual{r[a], r[i], r[c], normal[a], normal[i], normal[c]})});
    }
    // the Hessian's lower triangle: every pair of offsets one residual joins
    for (Residual& res : residuals_) {
      for (int p = 0; p < 3; ++p) {
        for (int q = 0; q < 3; ++q) {
          const std::size_t i = res.index[p], j = res.index[q];
          if (i < j) continue;
          const auto [it, added] = hessian_slot_.try_emplace({i, j}, hessian_slot_.size());
          res.slot[p][q] = it->second;
        }
      }
    }
  }

  bool get_nlp_info(Index& n, Index& m, Index& nnz_jac_g, Index& nnz_h_lag, IndexStyleEnum& style) override {
    n = static_cast<Index>(offset_.size());
    m = 0;
    nnz_jac_g = 0;
    nnz_h_lag = static_cast<Index>(hessian_slot_.size());
    style = C_STYLE;
    return true;
  }
  bool get_bounds_info(Index n, Number* x_l, Number* x_u, Index, Number*, Number*) override {
    for (Index i = 0; i < n; ++i) x_l[i] = lower_[static_cast<std::size_t>(i)], x_u[i] = upper_[static_cast<std::size_t>(i)];
    return true;
  }
  bool get_starting_point(Index n, bool, Number* x, bool, Number*, Number*, Index, bool, Number*) override {
    std::copy(offset_.begin(), offset_.begin() + n, x);
    return true;
  }
  bool eval_f(Index, const Number* x, bool, Number& f) override {
    f = 0.0;
    for (const Residual& res : residuals_) {
      const double r = evaluate(res, x, nullptr);
      f += r * r;
    }
    return std::isfinite(f);
  }
  bool eval_grad_f(Index n, const Number* x, bool, Number* grad) override {
    std::fill(grad, grad + n, 0.0);
    double j[3];
    for (const Residual& res : residuals_) {
      const double r = evaluate(res, x, j);
      for (int p = 0; p < 3; ++p) grad[res.index[p]] += 2.0 * r * j[p];
    }
    return true;
  }
  bool eval_g(Index, const Number*, bool, Index, Number*) override { return true; }
  bool eval_jac_g(Index, const Number*, bool, Index, Index, Index*, Index*, Number*) override { return true; }
  bool eval_h(Index, const Number* x, bool, Number obj_factor, Index, const Number*, bool, Index nele, Index* row,
              Index* col, Number* values) override {
    if (values == nullptr) {
      for (const auto& [pair, slot] : hessian_slot_) {
        row[slot] = static_cast<Index>(pair.first);
        col[slot] = static_cast<Index>(pair.second);
      }
      return true;
    }
    std::fill(values, values + nele, 0.0);
    double j[3];
    for (const Residual& res : residuals_) {
      evaluate(res, x, j);
      for (int p = 0; p < 3; ++p)
        for (int q = 0; q < 3; ++q)
          if (res.index[p] >= res.index[q]) values[res.slot[p][q]] += obj_factor * 2.0 * j[p] * j[q];
    }
    return true;
  }
  void finalize_solution(Ipopt::SolverReturn, Index n, const Number* x, const Number*, const Number*, Index,
                         const Number*, const Number*, Number, const Ipopt::IpoptData*,
                         Ipopt::IpoptCalculatedQuantities*) override {
    std::copy(x, x + n, offset_.begin());
  }

 private:
  struct Residual {
    std::size_t index[3];
    std::unique_ptr<ceres::CostFunction> cost;
    std::size_t slot[3][3] = {};
  };

  // r_k, and its gradient with respect to its three offsets when j is given
  static double evaluate(const Residual& res, const Number* x, double* j) {
    const double* params[3] = {&x[res.index[0]], &x[res.index[1]], &x[res.index[2]]};
    double r = 0.0;
    double* jac[3] = {j, j ? j + 1 : nullptr, j ? j + 2 : nullptr};
    res.cost->Evaluate(params, &r, j ? jac : nullptr);
    return r;
  }

  const std::vector<double>& lower_;
  const std::vector<double>& upper_;
  std::vector<double>& offset_;
  std::vector<Residual> residuals_;
  std::map<std::pair<std::size_t, std::size_t>, std::size_t> hessian_slot_;
};

// one solve from `offset` (within the bounds); returns IPOPT's iterations,
// -1 when it failed (the offsets are then left as they were)
int solve(const std::vector<Vec2>& r, const std::vector<Vec2>& normal, bool closed, int max_iterations,
          const std::vector<double>& lower, const std::vector<double>& upper, std::vector<double>& offset) {
  // IPOPT's linear solver (Debian's sequential MUMPS) keeps global state: one
  // solve at a time in a process, whose sweep and tune runs are threads and
  // whose runs solve their limit lap on a thread of its own
  static std::mutex one_at_a_time;
  const std::lock_guard<std::mutex> lock(one_at_a_time);
  std::vector<double> x = offset;
  Ipopt::SmartPtr<MinCurvatureNlp> nlp = new MinCurvatureNlp(r, normal, closed, lower, upper, x);
  Ipopt::SmartPtr<Ipopt::IpoptApplication> app = IpoptApplicationFactory();
  app->Options()->SetIntegerValue("print_level", 0);
  app->Options()->SetStringValue("sb", "yes");  // no banner
  app->Options()->SetIntegerValue("max_iter", max_iterations);
  app->Options()->SetNumericValue("tol", 1e-10);
  app->Options()->SetStringValue("mu_strategy", "adaptive");
  app->Options()->SetStringValue("honor_original_bounds", "yes");
  if (app->Initialize() != Ipopt::Solve_Succeeded) return -1;
  const Ipopt::ApplicationReturnStatus status = app->OptimizeTNLP(Ipopt::SmartPtr<Ipopt::TNLP>(GetRawPtr(nlp)));
  const bool usable = status == Ipopt::Solve_Succeeded || status == Ipopt::Solved_To_Acceptable_Level ||
                      status == Ipopt::Maximum_Iterations_Exceeded;
  if (!usable || !std::all_of(x.begin(), x.end(), [](double v) { return std::isfinite(v); })) return -1;
  for (std::size_t i = 0; i < x.size(); ++i) offset[i] = std::clamp(x[i], lower[i], upper[i]);
  Ipopt::SmartPtr<Ipopt::SolveStatistics> stats = app->Statistics();
  return IsValid(stats) ? stats->IterationCount() : 0;
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
  for (int round = 0; round < kClearanceRounds; ++round) {
    const int iterations = solve(r, normal, closed, params.max_iterations, out.lower, out.upper, out.offset);
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
