#include "autonomy/slam/lio.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>

namespace paddock::slam {

using Eigen::Isometry3d;
using Eigen::Matrix3d;
using Eigen::Vector3d;

std::string LioParams::check() const {
  if (max_range <= min_range) return "max_range must be above min_range";
  return "";
}

const char* to_string(LioStatus s) {
  switch (s) {
    case LioStatus::Ok: return "ok";
    case LioStatus::Initialising: return "initialising";
    case LioStatus::Degenerate: return "degenerate";
    case LioStatus::TooFewPoints: return "too few points";
    case LioStatus::NoImu: return "no IMU";
  }
  return "?";
}

// ---------------------------------------------------------------- SO(3)

Matrix3d skew(const Vector3d& w) {
  Matrix3d S;
  S << 0.0, -w.z(), w.y(), w.z(), 0.0, -w.x(), -w.y(), w.x(), 0.0;
  return S;
}

Matrix3d so3_exp(const Vector3d& w) {
  const double th = w.norm();
  const Matrix3d W = skew(w);
  if (th < 1e-8) return Matrix3d::Identity() + W + 0.5 * W * W;
  return Matrix3d::Identity() + std::sin(th) / th * W + (1.0 - std::cos(th)) / (th * th) * W * W;
}

Vector3d so3_log(const Matrix3d& R) {
  const double c = std::clamp(0.5 * (R.trace() - 1.0), -1.0, 1.0);
  const double th = std::acos(c);
  const Vector3d v(R(2, 1) - R(1, 2), R(0, 2) - R(2, 0), R(1, 0) - R(0, 1));
  if (th < 1e-8) return 0.5 * v;
  if (kPi - th < 1e-6) {
    // near pi: from the symmetric part, R = I + 2 a a^T - ... : a from the largest diagonal
    const Matrix3d B = 0.5 * (R + Matrix3d::Identity());
    int i = 0;
    B.diagonal().maxCoeff(&i);
    Vector3d a = B.col(i) / std::sqrt(std::max(B(i, i), 1e-300));
    a.normalize();
    if (a.dot(v) < 0.0) a = -a;
    return th * a;
  }
  return th / (2.0 * std::sin(th)) * v;
}

Matrix3d so3_right_jacobian(const Vector3d& w) {
  const double th = w.norm();
  const Matrix3d W = skew(w);
  if (th < 1e-6) return Matrix3d::Identity() - 0.5 * W + W * W / 6.0;
  return Matrix3d::Identity() - (1.0 - std::cos(th)) / (th * th) * W + (th - std::sin(th)) / (th * th * th) * W * W;
}

LioState boxplus(const LioState& x, const LioVector& d) {
  LioState y = x;
  y.R = x.R * so3_exp(d.segment<3>(kLioTheta));
  y.p += d.segment<3>(kLioP);
  y.v += d.segment<3>(kLioV);
  y.bg += d.segment<3>(kLioBg);
  y.ba += d.segment<3>(kLioBa);
  y.g += d.segment<3>(kLioG);
  return y;
}

LioVector boxminus(const LioState& a, const LioState& b) {
  LioVector d;
  d.segment<3>(kLioTheta) = so3_log(b.R.transpose() * a.R);
  d.segment<3>(kLioP) = a.p - b.p;
  d.segment<3>(kLioV) = a.v - b.v;
  d.segment<3>(kLioBg) = a.bg - b.bg;
  d.segment<3>(kLioBa) = a.ba - b.ba;
  d.segment<3>(kLioG) = a.g - b.g;
  return d;
}

// ---------------------------------------------------------------- Lio

// x moved over tau with the body rate w and the specific force a (both
// after bias) held constant (Forster et al. 2017's integrals in closed form):
//   R' = R Exp(w tau)
//   v' = v + R Jl(w tau) a tau + g tau,  Jl(phi) = int_0^1 Exp(phi u) du
//   p' = p + v tau + R N(w tau) a tau^2 + g tau^2 / 2,
//        N(phi) = int_0^1 (1 - u) Exp(phi u) du
//      = I/2 + (th - sin th) / th^3 [phi]x + (th^2/2 + cos th - 1) / th^4 [phi]x^2
void moved(const LioState& x, const Vector3d& w, const Vector3d& a, double tau, Vector3d& p, Vector3d& v,
           Matrix3d& R) {
  const Vector3d phi = w * tau;
  const double th = phi.norm();
  const Matrix3d F = skew(phi);
  Matrix3d N;
  if (th < 1e-4) {
    N = 0.5 * Matrix3d::Identity() + F / 6.0 + F * F / 24.0;
  } else {
    const double th2 = th * th;
    N = 0.5 * Matrix3d::Identity() + (th - std::sin(th)) / (th2 * th) * F +
        (0.5 * th2 + std::cos(th) - 1.0) / (th2 * th2) * F * F;
  }
  const Matrix3d Jl = so3_right_jacobian(-phi);
  const Vector3d p0 = x.p, v0 = x.v;
  const Matrix3d R0 = x.R;
  p = p0 + v0 * tau + R0 * N * a * (tau * tau) + 0.5 * x.g * tau * tau;
  v = v0 + R0 * Jl * a * tau + x.g * tau;
  R = R0 * so3_exp(phi);
}

namespace {

bool finite(const hal::Imu& m) {
  return std::isfinite(m.ax) && std::isfinite(m.ay) && std::isfinite(m.az) && std::isfinite(m.roll_rate) &&
         std::isfinite(m.pitch_rate) && std::isfinite(m.yaw_rate);
}
Vector3d gyro_of(const hal::Imu& m) { return {m.roll_rate, m.pitch_rate, m.yaw_rate}; }
Vector3d accel_of(const hal::Imu& m) { return {m.ax, m.ay, m.az}; }

Isometry3d planar(const Pose2& p) {
  Isometry3d T = Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(p.yaw, Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Vector3d(p.x, p.y, 0.0);
  return T;
}

}  // namespace

Lio::Lio(const LioParams& params, const LioExtrinsics& extrinsics, const Pose2& start)
    : params_(params::require_valid(params, "LioParams")),
      imu_lidar_(extrinsics.base_imu.inverse() * extrinsics.base_lidar),
      imu_base_(extrinsics.base_imu.inverse()),
      map_(params.map) {
  const Isometry3d world_imu = planar(start) * extrinsics.base_imu;
  x_.R = world_imu.linear();
  x_.p = world_imu.translation();
  const LioParams& p = params_;
  P_.setZero();
  P_.block<2, 2>(kLioTheta, kLioTheta) = Eigen::Matrix2d::Identity() * p.initial_attitude_std * p.initial_attitude_std;
  P_(kLioTheta + 2, kLioTheta + 2) = p.initial_yaw_std * p.initial_yaw_std;
  P_.block<3, 3>(kLioP, kLioP) = Matrix3d::Identity() * p.initial_position_std * p.initial_position_std;
  P_.block<3, 3>(kLioV, kLioV) = Matrix3d::Identity() * 1e-4;
  P_.block<3, 3>(kLioBg, kLioBg) = Matrix3d::Identity() * p.initial_gyro_bias_std * p.initial_gyro_bias_std;
  P_.block<3, 3>(kLioBa, kLioBa) = Matrix3d::Identity() * p.initial_accel_bias_std * p.initial_accel_bias_std;
  P_.block<3, 3>(kLioG, kLioG) = Matrix3d::Identity() * p.initial_gravity_std * p.initial_gravity_std;
  nn_.reserve(static_cast<std::size_t>(p.neighbours));
}

void Lio::reset(const LioState& x, TimeNs t) {
  ++generation_;
  x_ = x;
  t_ = t;
  started_ = true;
}

void Lio::load_map(const std::vector<Vector3d>& points) {
  map_.insert(points);
  has_map_ = map_.size() > 0;
}

void Lio::on_imu(const hal::Imu& m) {
  if (!finite(m) || (!imu_.empty() && m.stamp <= imu_.back().stamp)) {
    ++stats_.rejected_imu;
    return;
  }
  imu_.push_back(m);
  // keep what the state's time still needs: the last sample at or before it
  while (started_ && imu_.size() > 2 && imu_[1].stamp <= t_) imu_.pop_front();
  // before the first rotation: a second of samples is plenty
  while (!started_ && imu_.size() > 2 && imu_.back().stamp - imu_[1].stamp > from_seconds(1.0)) imu_.pop_front();
}

void Lio::initialise_from_rest(TimeNs t) {
  // the mean gyro rate over init_time before t is its bias (the car is at
  // rest before it drives off); the attitude stays level: the world's z is
  // gravity's, and a tilt of the accelerometer's mean is its bias there
  Vector3d sum = Vector3d::Zero();
  int n = 0;
  for (const hal::Imu& m : imu_) {
    if (m.stamp > t || m.stamp < t - from_seconds(params_.init_time)) continue;
    sum += gyro_of(m);
    ++n;
  }
  if (n > 0 && params_.init_time > 0.0) x_.bg = sum / n;
  t_ = t;
  started_ = true;
}

void Lio::propagate_to(TimeNs t, std::vector<Knot>* knots) {
  propagate(x_, &P_, t_, t, knots);
  ++generation_;
}

void Lio::propagate(LioState& x, LioMatrix* P, TimeNs& now, TimeNs t, std::vector<Knot>* knots) const {
  const LioParams& pr = params_;
  auto push = [&](TimeNs at, const Vector3d& w, const Vector3d& a) {
    if (knots) knots->push_back({at, x, w, a});
  };
  if (imu_.empty()) {
    push(now, Vector3d::Zero(), Vector3d::Zero());
    return;
  }
  // the sample governing [now, next): the last at or before now, else the first
  std::size_t i = 0;
  while (i + 1 < imu_.size() && imu_[i + 1].stamp <= now) ++i;
  while (now < t) {
    const hal::Imu& m0 = imu_[i];
    const bool has_next = i + 1 < imu_.size();
    const TimeNs next = has_next ? std::min(imu_[i + 1].stamp, t) : t;
    // the interval's mean of its two samples (the last one alone when no next)
    Vector3d w_m = gyro_of(m0), a_m = accel_of(m0);
    if (has_next && imu_[i + 1].stamp > m0.stamp) {
      w_m = 0.5 * (w_m + gyro_of(imu_[i + 1]));
      a_m = 0.5 * (a_m + accel_of(imu_[i + 1]));
    }
    const double dt = to_seconds(next - now);
    const Vector3d w = w_m - x.bg;
    const Vector3d a = a_m - x.ba;
    push(now, w, a);
    if (dt > 0.0 && P) {
      // covariance first, about the state at the interval's start
      LioMatrix F = LioMatrix::Identity();
      F.block<3, 3>(kLioTheta, kLioTheta) = so3_exp(-w * dt);
      F.block<3, 3>(kLioTheta, kLioBg) = -so3_right_jacobian(w * dt) * dt;
      F.block<3, 3>(kLioP, kLioV) = Matrix3d::Identity() * dt;
      F.block<3, 3>(kLioV, kLioTheta) = -x.R * skew(a) * dt;
      F.block<3, 3>(kLioV, kLioBa) = -x.R * dt;
      F.block<3, 3>(kLioV, kLioG) = Matrix3d::Identity() * dt;
      LioMatrix Q = LioMatrix::Zero();
      const double sg = pr.gyro_noise * dt, sa = pr.accel_noise * dt;
      Q.block<3, 3>(kLioTheta, kLioTheta) = Matrix3d::Identity() * sg * sg;
      Q.block<3, 3>(kLioV, kLioV) = Matrix3d::Identity() * sa * sa;
      Q.block<3, 3>(kLioBg, kLioBg) = Matrix3d::Identity() * pr.gyro_bias_walk * pr.gyro_bias_walk * dt;
      Q.block<3, 3>(kLioBa, kLioBa) = Matrix3d::Identity() * pr.accel_bias_walk * pr.accel_bias_walk * dt;
      *P = F * *P * F.transpose() + Q;
    }
    if (dt > 0.0) {
      // the state: exact for a constant body rate and specific force over
      // the interval (the specific force turns with the body; held at the
      // interval's start attitude it would lag by half a step's turn: a
      // 0.3 m drift over 10 s on a 20 m circle at 10 m/s)
      moved(x, w, a, dt, x.p, x.v, x.R);
    }
    now = next;
    if (has_next && imu_[i + 1].stamp <= now) ++i;
  }
  push(now, Vector3d::Zero(), Vector3d::Zero());  // the end: only tau = 0 is read here
}

Pose2 Lio::predict_base_pose(TimeNs t) {
  // carried on from the last prediction while the state is unchanged (the
  // IMU rate calls this once per sample: one interval each, not all since
  // the last scan)
  if (front_of_ != generation_ || front_t_ > t) {
    front_x_ = x_;
    front_t_ = t_;
    front_of_ = generation_;
  }
  if (t > front_t_) propagate(front_x_, nullptr, front_t_, t, nullptr);
  return base_pose_of(front_x_);
}

std::vector<Vector3d> Lio::deskew(const std::vector<hal::LidarPoint>& points, const Isometry3d& imu_lidar,
                                  const std::vector<Knot>& knots) {
  std::vector<Vector3d> out;
  deskew(points.data(), points.data() + points.size(), imu_lidar, knots, out);
  return out;
}

void Lio::deskew(const hal::LidarPoint* begin, const hal::LidarPoint* end, const Isometry3d& imu_lidar,
                 const std::vector<Knot>& knots, std::vector<Vector3d>& out) {
  out.clear();
  if (knots.empty()) return;
  out.reserve(static_cast<std::size_t>(end - begin));
  const Knot& last = knots.back();
  const Matrix3d Re_t = last.x.R.transpose();
  std::size_t k = 0;
  TimeNs at = std::numeric_limits<TimeNs>::min();
  Matrix3d Rc;  // end <- IMU at the point's time, and the IMU's origin there
  Vector3d tc;
  for (const hal::LidarPoint* it = begin; it != end; ++it) {
    const hal::LidarPoint& q = *it;
    if (q.t != at) {
      // the interval [knots[k], knots[k+1]) holding the point's time (points
      // in time order; a column's points share theirs)
      while (k + 1 < knots.size() && knots[k + 1].t <= q.t) ++k;
      const Knot& a = knots[k];
      Vector3d pi, vi;
      Matrix3d Ri;
      moved(a.x, a.omega, a.accel, to_seconds(q.t - a.t), pi, vi, Ri);
      Rc = Re_t * Ri;
      tc = Re_t * (pi - last.x.p);
      at = q.t;
    }
    out.push_back(Rc * (imu_lidar * Vector3d(q.x, q.y, q.z)) + tc);
  }
}

double Lio::plane_residual(const LioState& x, const Vector3d& p_imu, const Vector3d& n, double d,
                           Eigen::Matrix<double, 1, 6>* H) {
  const Vector3d pw = x.R * p_imu + x.p;
  if (H) {
    // p_W(dtheta) = R Exp(dtheta) p_I + p ~ R (I + [dtheta]x) p_I + p
    //   d/d(dtheta) = -R [p_I]x ; d/dp = I
    H->block<1, 3>(0, 0) = -n.transpose() * x.R * skew(p_imu);
    H->block<1, 3>(0, 3) = n.transpose();
  }
  return n.dot(pw) + d;
}

bool Lio::fit_plane(const Vector3d& p_world, Vector3d& n, double& d) {
  const int k = map_.knn(p_world, params_.neighbours, params_.neighbour_max_distance, nn_);
  if (k < params_.neighbours) return false;
  // least squares: the normal is the eigenvector of the scatter's least
  // eigenvalue (exact for noise-free points on a plane)
  Vector3d c = Vector3d::Zero();
  for (int i = 0; i < k; ++i) c += nn_[static_cast<std::size_t>(i)].point;
  c /= k;
  Matrix3d S = Matrix3d::Zero();
  for (int i = 0; i < k; ++i) {
    const Vector3d e = nn_[static_cast<std::size_t>(i)].point - c;
    S += e * e.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Matrix3d> es;
  es.computeDirect(S);
  n = es.eigenvectors().col(0);
  if (!n.allFinite() || n.norm() < 0.5) return false;
  n.normalize();
  d = -n.dot(c);
  for (int i = 0; i < k; ++i) {
    if (std::abs(n.dot(nn_[static_cast<std::size_t>(i)].point) + d) > params_.plane_max_distance) return false;
  }
  return true;
}

LioStatus Lio::update(const std::vector<Vector3d>& points) {
  const LioParams& pr = params_;
  const LioState prior = x_;
  const double inv_s2 = 1.0 / (pr.point_std * pr.point_std);
  const double huber = pr.huber_k * pr.point_std;
  const Eigen::LLT<LioMatrix> P_llt(P_);
  if (P_llt.info() != Eigen::Success) return LioStatus::TooFewPoints;
  const LioMatrix P_inv = P_llt.solve(LioMatrix::Identity());
  Eigen::Matrix<double, 6, 6> info = Eigen::Matrix<double, 6, 6>::Zero();
  int matches = 0;
  bool converged = false;
  planes_.resize(points.size());
  bool search = true;
  for (int it = 0; it < pr.max_iterations && !converged; ++it) {
    // the planes (searched again unless the last step moved the points less
    // than a tenth of the map's leaf) and the residuals at this iterate
    Eigen::Matrix<double, 6, 6> HtH = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> Htz = Eigen::Matrix<double, 6, 1>::Zero();
    matches = 0;
    for (std::size_t i = 0; i < points.size(); ++i) {
      const Vector3d& q = points[i];
      Plane& pl = planes_[i];
      if (search) pl.valid = fit_plane(x_.R * q + x_.p, pl.n, pl.d);
      if (!pl.valid) continue;
      const Vector3d& n = pl.n;
      const double d = pl.d;
      Eigen::Matrix<double, 1, 6> H;
      const double z = plane_residual(x_, q, n, d, &H);
      // Huber's weight at this iterate (iteratively reweighted)
      const double w = huber > 0.0 && std::abs(z) > huber ? huber / std::abs(z) : 1.0;
      HtH += w * H.transpose() * H;
      Htz += w * H.transpose() * z;
      ++matches;
    }
    stats_.last_matches = matches;
    if (matches < pr.min_matches) {
      x_ = prior;
      ++generation_;
      return LioStatus::TooFewPoints;
    }
    info = HtH;
    // K = (H^T H / s^2 + P^-1)^-1 H^T / s^2 with H zero past the pose's 6 columns
    LioMatrix A = P_inv;
    A.block<6, 6>(0, 0) += HtH * inv_s2;
    const Eigen::LDLT<LioMatrix> A_ldlt(A);
    const LioVector dx_prior = boxminus(x_, prior);
    // -K z - (I - K H) dx = -A^-1 (H^T z / s^2) - dx + A^-1 H^T H dx / s^2
    LioVector rhs = LioVector::Zero();
    rhs.head<6>() = -Htz * inv_s2 + HtH * inv_s2 * dx_prior.head<6>();
    const LioVector step = A_ldlt.solve(rhs) - dx_prior;
    x_ = boxplus(x_, step);
    ++generation_;
    // a point at the slice's reach moves by |dp| + r |dtheta|
    search = step.segment<3>(kLioP).norm() + pr.max_range * step.segment<3>(kLioTheta).norm() >
             0.1 * pr.map.leaf_size;
    ++stats_.iterations;
    converged = step.norm() < pr.convergence;
  }
  // P = (I - K H) P = (H^T H / s^2 + P^-1)^-1
  LioMatrix A = P_inv;
  A.block<6, 6>(0, 0) += info * inv_s2;
  P_ = A.ldlt().solve(LioMatrix::Identity());
  P_ = 0.5 * (P_ + P_.transpose());
  // the pose's information per plane: its least eigenvalue (rotation in
  // rad against translation in m: points a few metres out weigh both alike)
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> es(info / std::max(matches, 1));
  stats_.last_min_eigenvalue = es.eigenvalues()(0);
  ++stats_.updates;
  if (stats_.last_min_eigenvalue < pr.degeneracy_threshold) {
    ++stats_.degenerate_slices;
    return LioStatus::Degenerate;
  }
  return LioStatus::Ok;
}

void Lio::down_sample(const hal::LidarPoint* slice, std::vector<Vector3d>& pts) {
  // one point a leaf: the first of it in counter-clockwise azimuth order
  // about the sensor's axis (ties, a column's rings within the float
  // points' rounding: the first in time), whichever way the head spins. Time
  // order is that order only for a counter-clockwise head; which edge of its
  // leaf the kept point lies on moves the estimate (FSG 2023 autocross with
  // barriers, LIO: a clockwise head kept the first in time order, the other
  // edge, at ATE rms 0.05 m against 0.02 m). Each leaf's points are taken
  // in time order: its first, replaced by a later one more than the tie
  // before it in azimuth. The leaves are kept in a flat hash table of
  // (leaf, point kept, its azimuth), reused slice after slice (an entry
  // stamped with another slice's number is empty): no allocation, and an
  // azimuth is computed only where a leaf meets its second point
  constexpr double kLeafAzimuthTie = 1e-5;  // rad
  const double leaf = params_.scan_leaf;
  const auto cell = [leaf](double c) {
    return static_cast<std::uint64_t>(static_cast<std::int64_t>(std::floor(c / leaf)) & 0x1fffff);
  };
  std::size_t size = 64;
  while (size < 2 * pts.size()) size *= 2;
  if (leaves_.size() < size) leaves_.assign(size, LeafEntry{});
  const std::size_t mask = leaves_.size() - 1;
  if (++leaf_stamp_ == 0) {  // wrapped: every stamp is stale again
    std::fill(leaves_.begin(), leaves_.end(), LeafEntry{});
    leaf_stamp_ = 1;
  }
  const std::uint32_t stamp = leaf_stamp_;
  const auto azimuth = [slice](std::size_t i) { return static_cast<double>(std::atan2(slice[i].y, slice[i].x)); };
  leaf_kept_.assign(pts.size(), 0);
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const Vector3d& q = pts[i];
    const std::uint64_t key = cell(q.x()) | (cell(q.y()) << 21) | (cell(q.z()) << 42);
    std::uint64_t h = key * 0x9E3779B97F4A7C15ull;
    h ^= h >> 29;
    std::size_t j = static_cast<std::size_t>(h) & mask;
    while (leaves_[j].stamp == stamp && leaves_[j].key != key) j = (j + 1) & mask;
    LeafEntry& e = leaves_[j];
    if (e.stamp != stamp) {
      e = {key, stamp, static_cast<std::uint32_t>(i), false, 0.0};
      leaf_kept_[i] = 1;
      continue;
    }
    if (!e.has_azimuth) {
      e.azimuth = azimuth(e.kept);
      e.has_azimuth = true;
    }
    const double a = azimuth(i);
    if (a < e.azimuth - kLeafAzimuthTie) {
      leaf_kept_[e.kept] = 0;
      leaf_kept_[i] = 1;
      e.kept = static_cast<std::uint32_t>(i);
      e.azimuth = a;
    }
  }
  // kept in time order, in place (each kept index is at least its position)
  std::size_t n = 0;
  for (std::size_t i = 0; i < pts.size(); ++i)
    if (leaf_kept_[i]) pts[n++] = pts[i];
  pts.resize(n);
}

LioStatus Lio::on_scan(const hal::LidarScan& scan) {
  const LioParams& pr = params_;
  ++stats_.scans;
  if (imu_.empty() || imu_.back().stamp < scan.stamp) return LioStatus::NoImu;
  if (!started_) initialise_from_rest(scan.stamp);
  // the usable points (finite, in range, not before the state's time)
  std::vector<hal::LidarPoint>& usable = usable_;
  usable.clear();
  usable.reserve(scan.points.size());
  for (const hal::LidarPoint& q : scan.points) {
    const double r2 = static_cast<double>(q.x) * q.x + static_cast<double>(q.y) * q.y + static_cast<double>(q.z) * q.z;
    if (!std::isfinite(r2) || q.t < t_) {
      if (!std::isfinite(r2)) ++stats_.rejected_points;
      continue;
    }
    if (r2 < pr.min_range * pr.min_range || r2 > pr.max_range * pr.max_range) continue;
    usable.push_back(q);
  }
  const auto earlier = [](const hal::LidarPoint& a, const hal::LidarPoint& b) { return a.t < b.t; };
  if (!std::is_sorted(usable.begin(), usable.end(), earlier)) std::stable_sort(usable.begin(), usable.end(), earlier);

  // slice by slice: propagate, deskew, down-sample, update (LIMO-Velo)
  std::vector<Vector3d>& to_map = to_map_;
  to_map.clear();
  LioStatus status = LioStatus::Ok;
  const TimeNs slice_ns = std::max<TimeNs>(1, from_seconds(pr.slice));
  std::size_t begin = 0;
  std::vector<Knot>& knots = knots_;
  std::vector<Vector3d>& pts = slice_points_;
  while (begin < usable.size()) {
    const TimeNs slice_end = usable[begin].t + slice_ns;
    std::size_t end = begin;
    while (end < usable.size() && usable[end].t < slice_end) ++end;
    const TimeNs t2 = usable[end - 1].t;
    knots.clear();
    propagate_to(std::max(t2, t_), &knots);
    const hal::LidarPoint* slice = usable.data() + begin;
    deskew(slice, usable.data() + end, imu_lidar_, knots, pts);
    if (pr.scan_leaf > 0.0) down_sample(slice, pts);
    ++stats_.slices;
    if (!has_map_) {
      status = LioStatus::Initialising;
    } else {
      status = update(pts);
      if (status == LioStatus::TooFewPoints) ++stats_.too_few_points;
    }
    for (const Vector3d& q : pts) to_map.push_back(x_.R * q + x_.p);
    begin = end;
  }
  // localise, then map: the rotation joins the map after all its slices
  map_.insert(to_map);
  map_.remove_outside(x_.p);
  has_map_ = has_map_ || !to_map.empty();
  return status;
}

Pose2 Lio::base_pose() const { return base_pose_of(x_); }

Pose2 Lio::base_pose_of(const LioState& x) const {
  Isometry3d world_imu = Isometry3d::Identity();
  world_imu.linear() = x.R;
  world_imu.translation() = x.p;
  const Isometry3d world_base = world_imu * imu_base_;
  const Vector3d fwd = world_base.linear().col(0);
  return {world_base.translation().x(), world_base.translation().y(), std::atan2(fwd.y(), fwd.x())};
}

Eigen::Matrix3d Lio::base_pose_covariance() const {
  // the base origin = p + R t (t: the base origin in the IMU frame); a right
  // perturbation dtheta moves it by -R [t]x dtheta, and the yaw by (R dtheta)_z
  const Vector3d t = imu_base_.translation();
  Eigen::Matrix<double, 3, 6> J = Eigen::Matrix<double, 3, 6>::Zero();
  const Matrix3d dpos = -x_.R * skew(t);
  J.block<2, 3>(0, 0) = dpos.topRows<2>();
  J.block<2, 2>(0, 3) = Eigen::Matrix2d::Identity();
  J.block<1, 3>(2, 0) = x_.R.row(2);
  const Eigen::Matrix<double, 6, 6> Pp = P_.block<6, 6>(0, 0);
  return J * Pp * J.transpose();
}

}  // namespace paddock::slam
