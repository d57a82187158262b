#include "autonomy/slam/pose_graph.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <utility>

#include <Eigen/Cholesky>
#include <ceres/ceres.h>

namespace paddock::slam {

namespace {

// the parameters' range beyond which an input is no pose or position of a
// car on a track (as FastSLAM's absurd delta)
constexpr double kMaxCoordinate = 1e6;  // m

bool sane(double v) { return std::isfinite(v) && std::abs(v) < kMaxCoordinate; }
bool sane(Vec2 p) { return sane(p.x) && sane(p.y); }
bool sane(const Pose2& p) { return sane(p.x) && sane(p.y) && sane(p.yaw); }

// The linear solver. The graph's unknowns are ~5000 poses (3 each) and a
// few hundred landmarks (2 each); a pose touches its two neighbours and the
// ~15 landmarks it sees. SPARSE_SCHUR, bundle adjustment's choice,
// eliminates the landmarks and factors the poses' Schur complement; but here
// the landmarks are the few and the poses the many, and a landmark seen
// from n poses fills an n x n block of that complement (a cone seen over 5
// laps ties ~75 poses together): it eliminates little and densifies the
// rest. Sparse normal Cholesky on the whole system lets the fill-reducing
// ordering (AMD) choose what to eliminate. The library: Eigen's sparse
// Cholesky (compiled into Ceres, no BLAS); SuiteSparse's supernodal CHOLMOD
// calls the system's BLAS, whose kernels are chosen per CPU at run time
// (results would depend on the machine) and is no faster at this size.
// Measured (bench/pose_graph_bench.cc, 250 landmarks, 15 observations per
// node, the same 11 iterations each), 5100 nodes: Eigen 1.03 s, SuiteSparse
// 1.13 s, SPARSE_SCHUR 1.64 s, CXSparse 0.96 s (deprecated, gone in Ceres
// 2.2); 1500 nodes: Eigen 264 ms, SuiteSparse 320 ms, SPARSE_SCHUR 341 ms.
// the step test of PoseGraphParams::step_tolerance: after a successful
// step shorter than it, the solve ends (Ceres reports USER_SUCCESS)
class StepTest : public ceres::IterationCallback {
 public:
  explicit StepTest(double tolerance) : tolerance_(tolerance) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& s) override {
    const bool short_step = s.iteration > 0 && s.step_is_successful && s.step_norm < tolerance_;
    return short_step ? ceres::SOLVER_TERMINATE_SUCCESSFULLY : ceres::SOLVER_CONTINUE;
  }

 private:
  double tolerance_;
};

ceres::Solver::Options solver_options(int max_iterations) {
  ceres::Solver::Options o;
  o.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  o.sparse_linear_algebra_library_type = ceres::EIGEN_SPARSE;
  o.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  o.max_num_iterations = max_iterations;
  // converged when an iteration changes the cost by < 1e-12 of it, the step
  // is < 1e-10 of the parameters or the gradient vanishes. Ceres' default
  // 1e-6 on the cost stops up to 5 mm short of the minimum on the lap graph
  // of bench/pose_graph_bench.cc (after 6 iterations instead of 8: this costs
  // ~30 % more time) and 2e-7 short on the test's small problem (1e-12: 2e-9)
  o.function_tolerance = 1e-12;
  o.parameter_tolerance = 1e-10;
  o.gradient_tolerance = 1e-14;
  // deterministic: one thread, nothing printed
  o.num_threads = 1;
  o.logging_type = ceres::SILENT;
  o.minimizer_progress_to_stdout = false;
  return o;
}

}  // namespace

LandmarkResidual::LandmarkResidual(double range, double bearing, const Eigen::Matrix2d& W)
    : mx(range * std::cos(bearing)),
      my(range * std::sin(bearing)),
      w00(W(0, 0)),
      w01(W(0, 1)),
      w10(W(1, 0)),
      w11(W(1, 1)) {}

MotionResidual::MotionResidual(double v_, double w_, const Eigen::Vector3d& sqrt_info)
    : v(v_), w(w_), ix(sqrt_info(0)), iy(sqrt_info(1)), iyaw(sqrt_info(2)) {}

MotionMeasurement motion_measurement(const Pose2& odom_prev, const Pose2& odom_curr) {
  const Pose2 d = between(odom_prev, odom_curr);
  const double v = std::hypot(d.x, d.y);
  const double w = 0.5 * d.yaw;
  // the chord's component across the midpoint direction (w)
  const double off = -std::sin(w) * d.x + std::cos(w) * d.y;
  return {v, w, off};
}

Eigen::Matrix2d observation_whitening(double range, double bearing, const PoseGraphParams& p) {
  // C = J diag(sr^2, sb^2) J^T, J = d(r cos b, r sin b)/d(r, b); W = L^-1
  const double sr = p.range_std + p.range_std_per_m * range;
  const double sb = p.bearing_std;
  const double c = std::cos(bearing), s = std::sin(bearing);
  Eigen::Matrix2d J;
  J << c, -range * s, s, range * c;
  const Eigen::Matrix2d C = J * Eigen::Vector2d(sr * sr, sb * sb).asDiagonal() * J.transpose();
  const Eigen::Matrix2d L = C.llt().matrixL();
  return L.triangularView<Eigen::Lower>().solve(Eigen::Matrix2d::Identity());
}

Eigen::Vector3d motion_whitening(const MotionMeasurement& m, const PoseGraphParams& p) {
  // the odometry's own noise, and the part of its motion the midpoint
  // model cannot express (off_chord), added in quadrature
  const double sxy = std::max(std::hypot(p.motion_std_xy_per_m * m.v, m.off_chord), p.motion_std_xy_min);
  const double syaw =
      std::max(p.motion_std_yaw_per_m * m.v + p.motion_std_yaw_per_rad * std::abs(2.0 * m.w), p.motion_std_yaw_min);
  return {1.0 / sxy, 1.0 / sxy, 1.0 / syaw};
}

PoseGraph::PoseGraph(const PoseGraphParams& p) : params_(params::require_valid(p, "PoseGraphParams")) {}

int PoseGraph::add_pose(const Pose2& estimate, const Pose2& odometry) {
  if (!sane(estimate) || !sane(odometry)) {
    ++rejected_;
    return -1;
  }
  Edge e;
  if (!odometry_.empty()) {
    e.m = motion_measurement(odometry_.back(), odometry);
    e.sqrt_info = motion_whitening(e.m, params_);
  }
  poses_.push_back({estimate.x, estimate.y, wrap_angle(estimate.yaw)});
  odometry_.push_back(odometry);
  edges_.push_back(e);
  return static_cast<int>(poses_.size()) - 1;
}

bool PoseGraph::add_landmark(std::int64_t id, Vec2 initial) {
  if (!sane(initial)) {
    ++rejected_;
    return false;
  }
  if (landmark_index_.count(id)) return true;  // idempotent: the first value stays
  landmark_index_.emplace(id, static_cast<int>(landmarks_.size()));
  landmarks_.push_back({initial.x, initial.y});
  landmark_ids_.push_back(id);
  return true;
}

bool PoseGraph::add_observation(int node, std::int64_t landmark_id, Vec2 measured_in_base) {
  const auto it = landmark_index_.find(landmark_id);
  const double range = norm(measured_in_base);
  if (node < 0 || node >= nodes() || it == landmark_index_.end() || !sane(measured_in_base) ||
      !(range >= params_.min_range)) {
    ++rejected_;
    return false;
  }
  const double bearing = angle_of(measured_in_base);
  observations_.push_back({node, it->second, range, bearing, observation_whitening(range, bearing, params_)});
  return true;
}

bool PoseGraph::wants_node(const Pose2& odom_now) const {
  if (odometry_.empty()) return true;
  const Pose2& last = odometry_.back();
  return distance(last.position(), odom_now.position()) >= params_.node_spacing ||
         std::abs(wrap_angle(odom_now.yaw - last.yaw)) >= params_.node_spacing_yaw;
}

PoseGraph::Result PoseGraph::optimise(int fixed_nodes) {
  Result res;
  if (poses_.empty()) {
    res.reason = "empty graph: no poses";
    return res;
  }
  if (poses_.size() == 1 && observations_.empty()) {
    res.ok = true;
    res.reason = "nothing to optimise: one fixed pose";
    return res;
  }
  // the loss is shared by every observation: the graph owns it
  std::unique_ptr<ceres::LossFunction> loss;
  if (params_.huber_scale > 0.0) loss = std::make_unique<ceres::HuberLoss>(params_.huber_scale);
  ceres::Problem::Options po;
  po.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(po);
  // poses, then edges in node order, then observations in order of addition
  for (std::array<double, 3>& p : poses_) problem.AddParameterBlock(p.data(), 3);
  const std::size_t fixed = std::clamp<std::size_t>(static_cast<std::size_t>(std::max(fixed_nodes, 1)), 1, poses_.size());
  for (std::size_t i = 0; i < fixed; ++i) problem.SetParameterBlockConstant(poses_[i].data());
  for (std::size_t i = 1; i < poses_.size(); ++i) {
    const Edge& e = edges_[i];
    auto* cost = new ceres::AutoDiffCostFunction<MotionResidual, 3, 3, 3>(new MotionResidual(e.m.v, e.m.w, e.sqrt_info));
    problem.AddResidualBlock(cost, nullptr, poses_[i - 1].data(), poses_[i].data());
  }
  for (const Obs& o : observations_) {
    auto* cost = new ceres::AutoDiffCostFunction<LandmarkResidual, 2, 3, 2>(new LandmarkResidual(o.range, o.bearing, o.W));
    problem.AddResidualBlock(cost, loss.get(), poses_[static_cast<std::size_t>(o.node)].data(),
                             landmarks_[static_cast<std::size_t>(o.landmark)].data());
  }

  // kept to restore a failed solve (Ceres may leave its last trial behind)
  const std::vector<std::array<double, 3>> poses_before = poses_;
  const std::vector<std::array<double, 2>> landmarks_before = landmarks_;
  ceres::Solver::Summary summary;
  ceres::Solver::Options options = solver_options(params_.max_iterations);
  StepTest step_test(params_.step_tolerance);
  if (params_.step_tolerance > 0.0) options.callbacks.push_back(&step_test);
  ceres::Solve(options, &problem, &summary);

  res.ok = summary.IsSolutionUsable();
  res.iterations = summary.num_successful_steps + summary.num_unsuccessful_steps;
  res.initial_cost = summary.initial_cost;
  res.final_cost = summary.final_cost;
  if (summary.termination_type != ceres::CONVERGENCE && summary.termination_type != ceres::USER_SUCCESS) {
    res.reason = summary.message;
  }
  if (!res.ok) {
    poses_ = poses_before;
    landmarks_ = landmarks_before;
    return res;
  }
  for (std::array<double, 3>& p : poses_) p[2] = wrap_angle(p[2]);
  return res;
}

Pose2 PoseGraph::pose(int node) const {
  const std::array<double, 3>& p = poses_.at(static_cast<std::size_t>(node));
  return {p[0], p[1], wrap_angle(p[2])};
}

std::optional<Vec2> PoseGraph::landmark(std::int64_t id) const {
  const auto it = landmark_index_.find(id);
  if (it == landmark_index_.end()) return std::nullopt;
  const std::array<double, 2>& l = landmarks_[static_cast<std::size_t>(it->second)];
  return Vec2{l[0], l[1]};
}

void PoseGraph::clear() {
  poses_.clear();
  odometry_.clear();
  edges_.clear();
  landmarks_.clear();
  landmark_ids_.clear();
  landmark_index_.clear();
  observations_.clear();
}

}  // namespace paddock::slam
