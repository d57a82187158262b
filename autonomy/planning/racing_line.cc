#include "autonomy/planning/racing_line.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <memory>
#include <optional>

#include <ceres/ceres.h>

#include "autonomy/common/polyline.h"

namespace paddock::planning {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

bool all_finite(const std::vector<Vec2>& pts) {
  return std::all_of(pts.begin(), pts.end(), [](Vec2 p) { return finite(p); });
}

// the distance along the ray o + t d (t > 0, d a unit vector) to the first
// crossing of the polyline, infinite when it crosses none
double ray_distance(Vec2 o, Vec2 d, const std::vector<Vec2>& line, bool closed) {
  double best = kInf;
  const std::size_t n = line.size();
  const std::size_t segments = closed ? n : (n > 0 ? n - 1 : 0);
  for (std::size_t i = 0; i < segments; ++i) {
    const Vec2 a = line[i], b = line[(i + 1) % n];
    const Vec2 e = b - a;
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
// times sqrt(ds): its square summed is sum kappa^2 ds (curvature_cost)
struct MengerResidual {
  Vec2 r0, r1, r2;  // reference points
  Vec2 n0, n1, n2;  // their unit normals

  template <class T>
  bool operator()(const T* a0, const T* a1, const T* a2, T* residual) const {
    const T x0 = r0.x + a0[0] * n0.x, y0 = r0.y + a0[0] * n0.y;
    const T x1 = r1.x + a1[0] * n1.x, y1 = r1.y + a1[0] * n1.y;
    const T x2 = r2.x + a2[0] * n2.x, y2 = r2.y + a2[0] * n2.y;
    const T ax = x1 - x0, ay = y1 - y0, bx = x2 - x1, by = y2 - y1, cx = x2 - x0, cy = y2 - y0;
    using std::sqrt;
    const T la = sqrt(ax * ax + ay * ay), lb = sqrt(bx * bx + by * by), lc = sqrt(cx * cx + cy * cy);
    // ds: half the two chords, the length this point stands for
    residual[0] = sqrt(0.5 * (la + lb)) * 2.0 * (ax * by - ay * bx) / (la * lb * lc);
    return true;
  }
};

double menger(Vec2 p0, Vec2 p1, Vec2 p2) {
  const Vec2 a = p1 - p0, b = p2 - p1, c = p2 - p0;
  const double den = norm(a) * norm(b) * norm(c);
  return den > 0.0 ? 2.0 * cross(a, b) / den : 0.0;
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
                              const std::vector<Vec2>& right, bool closed, const RacingLineParams& params) {
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
    double dl = ray_distance(r[i], normal[i], left, closed);
    double dr = ray_distance(r[i], -1.0 * normal[i], right, closed);
    // no boundary within reach: the point may not move to that side
    if (!(dl <= params.reach)) dl = params.clearance;
    if (!(dr <= params.reach)) dr = params.clearance;
    double lo = -(dr - params.clearance), hi = dl - params.clearance;
    if (lo > hi) lo = hi = 0.5 * (lo + hi);  // narrower than twice the clearance: midway
    out.lower[i] = lo;
    out.upper[i] = hi;
  }

  // the problem: one offset per point, one curvature residual per inner point
  out.offset.assign(n, 0.0);
  for (std::size_t i = 0; i < n; ++i) out.offset[i] = std::clamp(0.0, out.lower[i], out.upper[i]);
  ceres::Problem::Options problem_options;
  ceres::Problem problem(problem_options);
  for (std::size_t i = closed ? 0 : 1; i < (closed ? n : n - 1); ++i) {
    const std::size_t a = (i + n - 1) % n, c = (i + 1) % n;
    auto* cost = new ceres::AutoDiffCostFunction<MengerResidual, 1, 1, 1, 1>(
        new MengerResidual{r[a], r[i], r[c], normal[a], normal[i], normal[c]});
    problem.AddResidualBlock(cost, nullptr, &out.offset[a], &out.offset[i], &out.offset[c]);
  }
  for (std::size_t i = 0; i < n; ++i) {
    double* a = &out.offset[i];
    if (out.upper[i] - out.lower[i] < 1e-9) {
      problem.SetParameterBlockConstant(a);
    } else {
      problem.SetParameterLowerBound(a, 0, out.lower[i]);
      problem.SetParameterUpperBound(a, 0, out.upper[i]);
    }
  }
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  options.sparse_linear_algebra_library_type = ceres::EIGEN_SPARSE;
  options.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  options.max_num_iterations = params.max_iterations;
  options.function_tolerance = 1e-13;
  options.gradient_tolerance = 1e-12;
  options.parameter_tolerance = 1e-12;
  options.num_threads = 1;
  options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  out.iterations = static_cast<int>(summary.iterations.size());

  out.reference = r;
  out.points.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double a = std::clamp(out.offset[i], out.lower[i], out.upper[i]);
    out.offset[i] = a;
    out.points[i] = r[i] + a * normal[i];
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
