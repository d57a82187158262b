#include "autonomy/planning/gicp.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <nanoflann.hpp>

namespace paddock::planning {

namespace {

// a cloud's spread below this is no spread at all (m^2)
constexpr double kNoSpread = 1e-12;
// a cloud whose smaller principal variance is below this fraction of its
// larger one is collinear: its normal std is < 1/1000 of its extent
constexpr double kCollinearRatio = 1e-6;
// the scaled Gauss-Newton matrix is singular below this condition ratio
constexpr double kDegenerateRatio = 1e-10;
// Levenberg-Marquardt damping: H + lambda diag(H), lambda from kLambdaInit,
// times kLambdaFactor on a rejected step and divided by it on an accepted one
constexpr double kLambdaInit = 1e-6;
constexpr double kLambdaMin = 1e-12;
constexpr double kLambdaFactor = 10.0;
constexpr int kMaxLambdaTries = 12;

// nanoflann's view of a point list
struct CloudAdaptor {
  const std::vector<Vec2>* pts = nullptr;
  std::size_t kdtree_get_point_count() const { return pts->size(); }
  double kdtree_get_pt(std::size_t i, std::size_t dim) const {
    return dim == 0 ? (*pts)[i].x : (*pts)[i].y;
  }
  template <class Bbox>
  bool kdtree_get_bbox(Bbox&) const {
    return false;
  }
};
using KdTree =
    nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, CloudAdaptor>,
                                        CloudAdaptor, 2, std::uint32_t>;

// a KD-tree over a point list that outlives it
class Index {
 public:
  explicit Index(const std::vector<Vec2>& pts)
      : adaptor_{&pts}, tree_(2, adaptor_, nanoflann::KDTreeSingleIndexAdaptorParams(8)) {}
  // up to k nearest points: indices and squared distances, nearest first
  std::size_t knn(Vec2 q, std::size_t k, std::uint32_t* idx, double* d2) const {
    const double query[2] = {q.x, q.y};
    return tree_.knnSearch(query, k, idx, d2);
  }

 private:
  CloudAdaptor adaptor_;
  KdTree tree_;
};

Eigen::Matrix2d to_eigen(const Covariance2& c) {
  Eigen::Matrix2d m;
  m << c.xx, c.xy, c.xy, c.yy;
  return m;
}

Eigen::Matrix2d rotation(double yaw) {
  const double c = std::cos(yaw), s = std::sin(yaw);
  Eigen::Matrix2d r;
  r << c, -s, s, c;
  return r;
}

// mean and covariance of some points of a cloud
Eigen::Matrix2d spread(const std::vector<Vec2>& pts, const std::uint32_t* idx, std::size_t n) {
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (std::size_t i = 0; i < n; ++i) mean += Eigen::Vector2d(pts[idx[i]].x, pts[idx[i]].y);
  mean /= static_cast<double>(n);
  Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d d = Eigen::Vector2d(pts[idx[i]].x, pts[idx[i]].y) - mean;
    cov += d * d.transpose();
  }
  return cov / static_cast<double>(n);
}

// why a cloud cannot be aligned, or nothing
std::optional<std::string> check_cloud(const std::vector<Vec2>& pts, const char* name) {
  if (pts.size() < 3)
    return std::string(name) + " has " + std::to_string(pts.size()) +
           " points; at least 3 are needed";
  for (const Vec2& p : pts)
    if (!finite(p)) return std::string(name) + " has a non-finite point";
  std::vector<std::uint32_t> all(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) all[i] = static_cast<std::uint32_t>(i);
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig;
  eig.computeDirect(spread(pts, all.data(), all.size()));
  const Eigen::Vector2d ev = eig.eigenvalues();  // ascending
  if (!(ev(1) > kNoSpread)) return std::string(name) + ": all points coincide";
  if (ev(0) < kCollinearRatio * ev(1))
    return std::string(name) +
           ": all points are collinear (the shift along the line is unobservable)";
  return std::nullopt;
}

// a source-target pair with its fused information matrix
struct Pair {
  std::size_t src = 0;
  std::size_t tgt = 0;
  Eigen::Matrix2d info;  // (C_b + R C_a R^T)^-1 (1/m^2)
};

// nearest-neighbour correspondences of the source moved by T, with their
// information matrices at T's rotation
std::vector<Pair> correspond(const std::vector<Vec2>& source,
                             const std::vector<Covariance2>& source_cov,
                             const std::vector<Covariance2>& target_cov, const Index& target_index,
                             const Pose2& T, double max_distance) {
  std::vector<Pair> pairs;
  pairs.reserve(source.size());
  const Eigen::Matrix2d R = rotation(T.yaw);
  const double max_d2 = max_distance * max_distance;
  for (std::size_t i = 0; i < source.size(); ++i) {
    std::uint32_t j = 0;
    double d2 = 0.0;
    if (target_index.knn(T.transform(source[i]), 1, &j, &d2) != 1 || d2 > max_d2) continue;
    const Eigen::Matrix2d fused =
        to_eigen(target_cov[j]) + R * to_eigen(source_cov[i]) * R.transpose();
    pairs.push_back({i, j, fused.inverse()});
  }
  return pairs;
}

// sum of d^T M d over the pairs at T, d = T a - b (M held fixed)
double cost(const std::vector<Vec2>& source, const std::vector<Vec2>& target,
            const std::vector<Pair>& pairs, const Pose2& T) {
  double e = 0.0;
  for (const Pair& p : pairs) {
    const Vec2 d = T.transform(source[p.src]) - target[p.tgt];
    const Eigen::Vector2d r(d.x, d.y);
    e += r.dot(p.info * r);
  }
  return e;
}

// exp(delta) * T on SE(2), delta = (rho_x, rho_y, phi) a left perturbation:
// exp(delta) p = R(phi) p + V(phi) rho with
// V = [sin phi, -(1 - cos phi); 1 - cos phi, sin phi] / phi (-> I as phi -> 0)
Pose2 retract(const Eigen::Vector3d& delta, const Pose2& T) {
  const double phi = delta(2);
  double a = 1.0, b = 0.0;  // sin(phi)/phi, (1 - cos(phi))/phi
  if (std::abs(phi) > 1e-9) {
    a = std::sin(phi) / phi;
    b = (1.0 - std::cos(phi)) / phi;
  } else {
    b = 0.5 * phi;
  }
  const Vec2 v{a * delta(0) - b * delta(1), b * delta(0) + a * delta(1)};
  const Vec2 t = rotate(T.position(), phi) + v;
  return {t.x, t.y, wrap_angle(T.yaw + phi)};
}

// a length for a message: "5 m", "0.25 m"
std::string metres(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g m", v);
  return buf;
}

GicpResult fail(GicpResult r, std::string why) {
  r.converged = false;
  r.reason = std::move(why);
  return r;
}

}  // namespace

std::vector<Covariance2> estimate_covariances(const std::vector<Vec2>& points,
                                              const GicpParams& params) {
  if (!params::validate(params).empty() || points.empty()) return {};
  for (const Vec2& p : points)
    if (!finite(p)) return {};
  const Index index(points);
  const std::size_t k = std::min(points.size(), static_cast<std::size_t>(params.k_neighbours));
  std::vector<std::uint32_t> idx(k);
  std::vector<double> d2(k);
  std::vector<Covariance2> out(points.size());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const std::size_t n = index.knn(points[i], k, idx.data(), d2.data());
    const Eigen::Matrix2d cov = spread(points, idx.data(), n);
    if (!(cov.trace() > kNoSpread)) continue;  // coincident neighbours: the identity
    // plane-to-plane in 2D: the eigenvalues (ascending) become (eps, 1), the
    // smallest spread being the normal of the curve the points lie on
    eig.computeDirect(cov);
    const Eigen::Matrix2d V = eig.eigenvectors();
    const Eigen::Matrix2d C =
        V * Eigen::Vector2d(params.covariance_epsilon, 1.0).asDiagonal() * V.transpose();
    out[i] = {C(0, 0), 0.5 * (C(0, 1) + C(1, 0)), C(1, 1)};
  }
  return out;
}

GicpResult align(const std::vector<Vec2>& source, const std::vector<Vec2>& target,
                 const Pose2& initial, const GicpParams& params) {
  GicpResult r;
  r.transform = initial;
  if (const std::string bad = params::validate(params); !bad.empty()) return fail(r, "gicp: " + bad);
  if (auto bad = check_cloud(source, "source")) return fail(r, "gicp: " + *bad);
  if (auto bad = check_cloud(target, "target")) return fail(r, "gicp: " + *bad);
  return align(source, estimate_covariances(source, params), target,
               estimate_covariances(target, params), initial, params);
}

GicpResult align(const std::vector<Vec2>& source, const std::vector<Covariance2>& source_cov,
                 const std::vector<Vec2>& target, const std::vector<Covariance2>& target_cov,
                 const Pose2& initial, const GicpParams& params) {
  GicpResult r;
  r.transform = initial;
  // inputs
  if (const std::string bad = params::validate(params); !bad.empty()) return fail(r, "gicp: " + bad);
  if (!(std::isfinite(initial.x) && std::isfinite(initial.y) && std::isfinite(initial.yaw)))
    return fail(r, "gicp: the initial transform is not finite");
  if (auto bad = check_cloud(source, "source")) return fail(r, "gicp: " + *bad);
  if (auto bad = check_cloud(target, "target")) return fail(r, "gicp: " + *bad);
  if (source_cov.size() != source.size() || target_cov.size() != target.size())
    return fail(r, "gicp: one covariance per point is needed");
  for (const auto* covs : {&source_cov, &target_cov})
    for (const Covariance2& c : *covs) {
      // finite, symmetric positive definite
      if (!(finite(c.xx) && finite(c.xy) && finite(c.yy)) || !(c.xx > 0.0) || !(c.xx * c.yy - c.xy * c.xy > 0.0))
        return fail(r, "gicp: a covariance is not finite and positive definite");
    }

  // the scale that makes a rotation comparable with a translation: the
  // source's RMS radius about its centroid (m)
  Vec2 centroid;
  for (const Vec2& p : source) centroid += p;
  centroid = centroid / static_cast<double>(source.size());
  double radius2 = 0.0;
  for (const Vec2& p : source) radius2 += squared_norm(p - centroid);
  const double scale = std::sqrt(radius2 / static_cast<double>(source.size()));

  const Index target_index(target);
  Pose2 T = initial;
  double lambda = kLambdaInit;
  // one stage: iterate with correspondences gated at `gate` until a step
  // falls below the tolerances; a reason when it cannot go on
  auto run_stage = [&](double gate, bool* converged) -> std::optional<std::string> {
    *converged = false;
    for (int iter = 1; iter <= params.max_iterations; ++iter) {
      ++r.iterations;
      // correspondences at the current transform
      const std::vector<Pair> pairs =
          correspond(source, source_cov, target_cov, target_index, T, gate);
      if (pairs.size() < 3)
        return "only " + std::to_string(pairs.size()) + " correspondences within " + metres(gate);
      // linearise: d = T a - b, d(exp(delta) T a)/d delta = [I, perp(T a)]
      Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
      Eigen::Vector3d g = Eigen::Vector3d::Zero();
      double e = 0.0;
      for (const Pair& p : pairs) {
        const Vec2 q = T.transform(source[p.src]);
        const Vec2 d = q - target[p.tgt];
        const Eigen::Vector2d res(d.x, d.y);
        Eigen::Matrix<double, 2, 3> J;
        J << 1.0, 0.0, -q.y, 0.0, 1.0, q.x;
        const Eigen::Matrix<double, 3, 2> JtM = J.transpose() * p.info;
        H.noalias() += JtM * J;
        g.noalias() += JtM * res;
        e += res.dot(p.info * res);
      }
      // a well-posed system: the scaled matrix (rotation in m at `scale`)
      // is not singular
      const Eigen::Vector3d s(1.0, 1.0, 1.0 / std::max(scale, 1e-9));
      const Eigen::Matrix3d Hs = s.asDiagonal() * H * s.asDiagonal();
      const Eigen::Vector3d hev = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(Hs).eigenvalues();
      if (!(hev(0) > kDegenerateRatio * hev(2)))
        return std::string("degenerate geometry (the correspondences do not pin x, y and yaw)");
      // damped Gauss-Newton (Levenberg-Marquardt) on the fixed correspondences
      bool accepted = false;
      Eigen::Vector3d delta = Eigen::Vector3d::Zero();
      for (int tries = 0; tries < kMaxLambdaTries; ++tries) {
        Eigen::Matrix3d A = H;
        A.diagonal() += lambda * H.diagonal();
        delta = A.ldlt().solve(-g);
        const Pose2 T_new = retract(delta, T);
        if (delta.allFinite() && cost(source, target, pairs, T_new) < e) {
          T = T_new;
          lambda = std::max(lambda / kLambdaFactor, kLambdaMin);
          accepted = true;
          break;
        }
        lambda *= kLambdaFactor;
      }
      // no step lowers the cost: T is a minimum for these correspondences,
      // which are those of T itself
      const bool small = std::hypot(delta(0), delta(1)) < params.translation_tolerance &&
                         std::abs(delta(2)) < params.rotation_tolerance;
      if (!accepted || small) {
        *converged = true;
        return std::nullopt;
      }
    }
    return std::nullopt;
  };

  // coarse: the wide gate pulls the template in from a rough guess; fine:
  // the narrow gate drops the pairs of cones that have no counterpart
  // (missed or extra cones matched to a neighbour metres away), which would
  // otherwise drag the fit along the rings
  std::vector<double> gates = {params.max_correspondence_distance};
  if (params.refine_correspondence_distance > 0.0 &&
      params.refine_correspondence_distance < params.max_correspondence_distance)
    gates.push_back(params.refine_correspondence_distance);
  // (the coarse stage need not converge: with cones missing, a pair may
  // flip between two neighbours from one iteration to the next, a cycle
  // the fine stage's gate breaks; only the last stage must converge)
  for (double gate : gates) {
    if (auto why = run_stage(gate, &r.converged)) {
      r.transform = T;
      return fail(r, "gicp: " + *why);
    }
  }
  const double final_gate = gates.back();
  r.transform = T;

  // the final correspondences: how many, and how close
  const std::vector<Pair> pairs =
      correspond(source, source_cov, target_cov, target_index, T, final_gate);
  r.inliers = static_cast<int>(pairs.size());
  double sum2 = 0.0;
  for (const Pair& p : pairs) sum2 += squared_norm(T.transform(source[p.src]) - target[p.tgt]);
  r.rmse = pairs.empty() ? 0.0 : std::sqrt(sum2 / static_cast<double>(pairs.size()));
  if (!r.converged)
    return fail(r, "gicp: did not converge in " + std::to_string(params.max_iterations) +
                       " iterations with correspondences within " + metres(final_gate));
  if (pairs.size() < 3)
    return fail(r, "gicp: only " + std::to_string(pairs.size()) + " correspondences within " +
                       metres(final_gate) + " at the result");
  return r;
}

GicpObjective gicp_objective(const std::vector<Vec2>& source,
                             const std::vector<Covariance2>& source_cov,
                             const std::vector<Vec2>& target,
                             const std::vector<Covariance2>& target_cov, const Pose2& transform,
                             const GicpParams& params) {
  GicpObjective out;
  if (const std::string bad = params::validate(params); !bad.empty()) {
    out.reason = "gicp: " + bad;
    return out;
  }
  if (source.empty() || target.empty() || source_cov.size() != source.size() ||
      target_cov.size() != target.size()) {
    out.reason = "gicp: empty cloud or covariances that do not match the points";
    return out;
  }
  for (const Vec2& p : source)
    if (!finite(p)) out.reason = "gicp: source has a non-finite point";
  for (const Vec2& p : target)
    if (!finite(p)) out.reason = "gicp: target has a non-finite point";
  if (!out.reason.empty()) return out;
  const Index target_index(target);
  const std::vector<Pair> pairs = correspond(source, source_cov, target_cov, target_index,
                                             transform, params.max_correspondence_distance);
  out.inliers = static_cast<int>(pairs.size());
  out.value = cost(source, target, pairs, transform);
  return out;
}

}  // namespace paddock::planning
