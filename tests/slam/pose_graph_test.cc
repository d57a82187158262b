// The pose graph against independent truth: both residuals worked out by
// hand, a noise-free graph that must stay put, a drifted synthetic loop
// pulled back to the truth it was drawn from, Ceres' solution against a
// dense Gauss-Newton written here, determinism and bad input.
#include "autonomy/slam/pose_graph.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Dense>

namespace paddock::slam {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// ---- 1. the residuals against values worked out by hand

TEST(PoseGraph, LandmarkResidualMatchesTheHandComputedValue) {
  // pose (1, 2, pi/6), landmark (4, 6): l - p = (3, 4); cos 30 = sqrt(3)/2 = 0.8660254038, sin 30 = 0.5
  //   R^T (l - p) = ( 0.8660254038 * 3 + 0.5 * 4,  -0.5 * 3 + 0.8660254038 * 4)
  //               = ( 2.5980762114 + 2,  -1.5 + 3.4641016151) = (4.5980762114, 1.9641016151)
  // measurement range 5, bearing 0.4: 5 (cos 0.4, sin 0.4) = 5 (0.9210609940, 0.3894183423)
  //   = (4.6053049700, 1.9470917115)
  // r = (4.5980762114 - 4.6053049700, 1.9641016151 - 1.9470917115) = (-0.0072287587, 0.0170099036)
  const double pose[3] = {1.0, 2.0, kPi / 6.0};
  const double lm[2] = {4.0, 6.0};
  double r[2];
  ASSERT_TRUE(LandmarkResidual(5.0, 0.4)(pose, lm, r));
  EXPECT_NEAR(r[0], -0.0072287587, 1e-10);
  EXPECT_NEAR(r[1], 0.0170099036, 1e-10);
  // whitened by W: W r, here W = [[2, 1], [0, 3]]: (2 r0 + r1, 3 r1)
  //   = (-0.0144575174 + 0.0170099036, 0.0510297108) = (0.0025523862, 0.0510297108)
  Eigen::Matrix2d W;
  W << 2.0, 1.0, 0.0, 3.0;
  ASSERT_TRUE(LandmarkResidual(5.0, 0.4, W)(pose, lm, r));
  EXPECT_NEAR(r[0], 0.0025523862, 1e-10);
  EXPECT_NEAR(r[1], 0.0510297108, 1e-10);
}

TEST(PoseGraph, MotionResidualMatchesTheHandComputedValue) {
  // prev (1, 1, 0.3), curr (2, 3, 0.5), v = 2, w = 0.1: heading 0.3 + 0.1 = 0.4
  //   r = (1 - 2 cos 0.4, 2 - 2 sin 0.4, 0.2 - 0.2)
  //     = (1 - 1.8421219880, 2 - 0.7788366846, 0) = (-0.8421219880, 1.2211633154, 0)
  {
    const double prev[3] = {1.0, 1.0, 0.3}, curr[3] = {2.0, 3.0, 0.5};
    double r[3];
    ASSERT_TRUE(MotionResidual(2.0, 0.1)(prev, curr, r));
    EXPECT_NEAR(r[0], -0.8421219880, 1e-10);
    EXPECT_NEAR(r[1], 1.2211633154, 1e-10);
    EXPECT_NEAR(r[2], 0.0, 1e-15);
    // whitened by (10, 20, 30): (-8.421219880, 24.423266308, 0)
    ASSERT_TRUE(MotionResidual(2.0, 0.1, Eigen::Vector3d(10.0, 20.0, 30.0))(prev, curr, r));
    EXPECT_NEAR(r[0], -8.421219880, 1e-9);
    EXPECT_NEAR(r[1], 24.423266308, 1e-9);
  }
  // across +-pi: prev yaw 3.1, curr yaw -3.1 (0.0831853 rad of left turn), w = 0.04:
  //   d = (-3.1 - 3.1) - 0.08 = -6.28, wrapped: -6.28 + 2 pi = 0.0031853072 (not -6.28)
  {
    const double prev[3] = {0.0, 0.0, 3.1}, curr[3] = {0.0, 0.0, -3.1};
    double r[3];
    ASSERT_TRUE(MotionResidual(0.0, 0.04)(prev, curr, r));
    EXPECT_NEAR(r[2], 0.0031853072, 1e-10);
  }
  // the odometry's edge across +-pi: from (0, 0, 3.1) to (-1, 0, -3.1):
  //   v = 1, w = wrap(-6.2) / 2 = (2 pi - 6.2) / 2 = 0.0415926536 (half a left turn of 0.083 rad)
  //   the chord then points along 3.1 + 0.0415926536 = pi: (cos pi, sin pi) = (-1, 0), so
  //   r = (-1 - (-1), 0 - 0, wrap(-6.2 - 0.0831853072)) = (0, 0, wrap(-2 pi)) = (0, 0, 0)
  {
    const MotionMeasurement m = motion_measurement({0.0, 0.0, 3.1}, {-1.0, 0.0, -3.1});
    EXPECT_NEAR(m.v, 1.0, 1e-15);
    EXPECT_NEAR(m.w, 0.0415926536, 1e-10);
    const double prev[3] = {0.0, 0.0, 3.1}, curr[3] = {-1.0, 0.0, -3.1};
    double r[3];
    ASSERT_TRUE(MotionResidual(m.v, m.w)(prev, curr, r));
    EXPECT_NEAR(r[0], 0.0, 1e-12);
    EXPECT_NEAR(r[1], 0.0, 1e-12);
    EXPECT_NEAR(r[2], 0.0, 1e-12);
  }
}

TEST(PoseGraph, ObservationWhiteningIsTheInverseCholeskyFactor) {
  // range 10, range std 0.1 (no per-m part), bearing std 0.001: radial 0.1 m, tangential 10 * 0.001 = 0.01 m
  PoseGraphParams p;
  p.range_std = 0.1;
  p.range_std_per_m = 0.0;
  p.bearing_std = 0.001;
  // bearing 0: C = diag(0.1^2, 0.01^2), L = diag(0.1, 0.01), W = diag(10, 100)
  const Eigen::Matrix2d W0 = observation_whitening(10.0, 0.0, p);
  EXPECT_NEAR(W0(0, 0), 10.0, 1e-9);
  EXPECT_NEAR(W0(1, 1), 100.0, 1e-9);
  EXPECT_NEAR(W0(0, 1), 0.0, 1e-9);
  EXPECT_NEAR(W0(1, 0), 0.0, 1e-9);
  // bearing pi/2: the radial axis is y: C = diag(0.01^2, 0.1^2), W = diag(100, 10)
  const Eigen::Matrix2d W1 = observation_whitening(10.0, kPi / 2.0, p);
  EXPECT_NEAR(W1(0, 0), 100.0, 1e-9);
  EXPECT_NEAR(W1(1, 1), 10.0, 1e-9);
  EXPECT_NEAR(W1(1, 0), 0.0, 1e-9);
  // bearing pi/4: C = 1/2 [[0.0101, 0.0099], [0.0099, 0.0101]];
  //   L00 = sqrt(0.00505) = 0.0710633520, L10 = 0.00495 / L00 = 0.0696558613,
  //   L11 = sqrt(0.00505 - L10^2) = sqrt(0.0000980198) = 0.0099005...; W = L^-1 lower triangular
  //   with W00 = 1/L00 = 14.0719509, W11 = 1/L11, and W C W^T = I
  const Eigen::Matrix2d W2 = observation_whitening(10.0, kPi / 4.0, p);
  EXPECT_NEAR(W2(0, 0), 14.0719509, 1e-6);
  EXPECT_NEAR(W2(0, 1), 0.0, 1e-12);
  EXPECT_NEAR(W2(1, 1), 1.0 / std::sqrt(0.00505 - 0.00495 * 0.00495 / 0.00505), 1e-6);
  Eigen::Matrix2d C;
  C << 0.00505, 0.00495, 0.00495, 0.00505;
  EXPECT_TRUE((W2 * C * W2.transpose()).isApprox(Eigen::Matrix2d::Identity(), 1e-9));
}

TEST(PoseGraph, MotionWhiteningFollowsTheOdometryModelWithItsFloors) {
  PoseGraphParams p;  // 0.01 / m; 1e-4 rad/m + 0.005 rad/rad; floors 0.002 m, 2e-5 rad
  // v = 1 m, w = 0.05 (0.1 rad turned): sxy = 0.01, syaw = 1e-4 + 0.005 * 0.1 = 6e-4
  const Eigen::Vector3d a = motion_whitening({1.0, 0.05}, p);
  EXPECT_NEAR(a(0), 100.0, 1e-9);
  EXPECT_NEAR(a(1), 100.0, 1e-9);
  EXPECT_NEAR(a(2), 1.0 / 6e-4, 1e-6);
  // no motion: the floors, not infinity
  const Eigen::Vector3d z = motion_whitening({0.0, 0.0}, p);
  EXPECT_NEAR(z(0), 1.0 / 0.002, 1e-9);
  EXPECT_NEAR(z(2), 1.0 / 2e-5, 1e-6);
}

// ---- the synthetic world: a stadium (two 30 m straights joined by 15 m
// radius half circles: 60 m x 30 m, 154 m round), cones 3 m either side
// every 5 m (the rules' widest spacing on a straight)

constexpr double kStraight = 30.0;
constexpr double kTurnRadius = 15.0;
constexpr double kLap = 2.0 * kStraight + 2.0 * kPi * kTurnRadius;
constexpr double kHalfWidth = 3.0;
constexpr double kSensorRange = 20.0;  // the test's sensor: 20 m, 180 deg (the object sensor's reach)

// the centreline's pose after s metres (counter-clockwise from (0, -15) heading +x)
Pose2 centreline(double s) {
  s = std::fmod(s, kLap);
  const double arc = kPi * kTurnRadius;
  if (s < kStraight) return {s, -kTurnRadius, 0.0};
  s -= kStraight;
  if (s < arc) {
    const double a = -kPi / 2.0 + s / kTurnRadius;
    return {kStraight + kTurnRadius * std::cos(a), kTurnRadius * std::sin(a), wrap_angle(a + kPi / 2.0)};
  }
  s -= arc;
  if (s < kStraight) return {kStraight - s, kTurnRadius, wrap_angle(kPi)};
  s -= kStraight;
  const double a = kPi / 2.0 + s / kTurnRadius;
  return {kTurnRadius * std::cos(a), kTurnRadius * std::sin(a), wrap_angle(a + kPi / 2.0)};
}

struct Cone {
  std::int64_t id;  // arbitrary, sparse, some negative
  Vec2 p;
};

// n cones per side, evenly spaced along the centreline
std::vector<Cone> stadium_cones(int per_side) {
  std::vector<Cone> w;
  for (int i = 0; i < per_side; ++i) {
    const Pose2 c = centreline(kLap * i / per_side);
    const Vec2 left = left_normal(c.heading());
    const std::int64_t k = static_cast<std::int64_t>(i);
    w.push_back({1000000007LL * k + 12345, c.position() + kHalfWidth * left});
    w.push_back({-998244353LL * k - 7, c.position() - kHalfWidth * left});
  }
  return w;
}

Pose2 delta_of(const Pose2& a, const Pose2& b) { return between(a, b); }

struct Drive {
  std::vector<Pose2> truth;     // per node
  std::vector<Pose2> odometry;  // per node, dead-reckoned with drift (also the initial estimate)
  std::vector<Cone> cones;
};

// nodes every metre for a lap and `extra` metres more; odometry with a 2 %
// scale error and a gyro bias of 0.01 rad/s at 10 m/s (1e-3 rad per metre)
Drive drifted_drive(double extra) {
  Drive d;
  d.cones = stadium_cones(31);
  const int n = static_cast<int>(std::ceil(kLap + extra));
  const double step = kLap / std::ceil(kLap);  // 1 m of arc, a whole number per lap
  d.truth.push_back(centreline(0.0));
  d.odometry.push_back(d.truth[0]);
  for (int i = 1; i <= n; ++i) {
    d.truth.push_back(centreline(i * step));
    const Pose2 t = delta_of(d.truth[static_cast<std::size_t>(i) - 1], d.truth.back());
    const Pose2 drifted{1.02 * t.x, 1.02 * t.y, t.yaw + 1e-3 * step};
    d.odometry.push_back(compose(d.odometry.back(), drifted));
  }
  return d;
}

struct SensorNoise {
  double range_std, range_per_m, bearing_std;
};

// the graph of a drive: each node with its odometry as the initial value,
// each cone in view observed with noise, a new landmark at its first sighting
PoseGraph graph_of(const Drive& d, const PoseGraphParams& p, const SensorNoise& n, std::uint64_t seed) {
  PoseGraph g(p);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  for (std::size_t i = 0; i < d.truth.size(); ++i) {
    const int node = g.add_pose(d.odometry[i], d.odometry[i]);
    for (const Cone& c : d.cones) {
      const Vec2 b = d.truth[i].inverse_transform(c.p);
      const double r = norm(b);
      if (r > kSensorRange || b.x < 0.0) continue;
      const double rn = r + (n.range_std + n.range_per_m * r) * gauss(rng);
      const Vec2 z = rn * unit_from_angle(angle_of(b) + n.bearing_std * gauss(rng));
      if (!g.landmark(c.id)) g.add_landmark(c.id, d.odometry[i].transform(z));
      g.add_observation(node, c.id, z);
    }
  }
  return g;
}

// ---- 2. a noise-free graph initialised at the truth stays there

TEST(PoseGraph, NoiseFreeGraphAtTheTruthHasZeroCostAndStays) {
  // exact odometry on a circle: every edge an arc, on which the midpoint
  // rule is exact (an edge that straddled a straight and an arc would not be)
  constexpr double R = 20.0;
  auto on_circle = [&](double s) {
    const double a = s / R;
    return Pose2{R * std::cos(a), R * std::sin(a), wrap_angle(a + kPi / 2.0)};
  };
  std::vector<Cone> cones;
  for (int i = 0; i < 24; ++i) {
    const double a = 2.0 * kPi * i / 24;
    cones.push_back({i, (R - 3.0) * unit_from_angle(a)});
    cones.push_back({100 + i, (R + 3.0) * unit_from_angle(a)});
  }
  PoseGraph g;
  const int n = 160;  // over a lap: crosses +-pi and closes the loop
  for (int i = 0; i < n; ++i) {
    const Pose2 t = on_circle(1.0 * i);
    const int node = g.add_pose(t, t);
    for (const Cone& c : cones) {
      const Vec2 b = t.inverse_transform(c.p);
      if (norm(b) > kSensorRange || b.x < 0.0) continue;
      g.add_landmark(c.id, c.p);
      g.add_observation(node, c.id, b);
    }
  }
  ASSERT_EQ(g.nodes(), n);
  ASSERT_GT(g.observations(), 5 * n);
  const PoseGraph::Result r = g.optimise();
  ASSERT_TRUE(r.ok) << r.reason;
  EXPECT_LT(r.initial_cost, 1e-18);
  EXPECT_LT(r.final_cost, 1e-18);
  for (int i = 0; i < n; ++i) {
    const Pose2 t = on_circle(1.0 * i);
    EXPECT_NEAR(g.pose(i).x, t.x, 1e-9);
    EXPECT_NEAR(g.pose(i).y, t.y, 1e-9);
    EXPECT_NEAR(wrap_angle(g.pose(i).yaw - t.yaw), 0.0, 1e-9);
  }
  for (const Cone& c : cones) {
    ASSERT_TRUE(g.landmark(c.id));
    EXPECT_NEAR(g.landmark(c.id)->x, c.p.x, 1e-9);
    EXPECT_NEAR(g.landmark(c.id)->y, c.p.y, 1e-9);
  }
}

// ---- 3. a drifted loop pulled back to the truth

// the graph knows the sensor's noise and how bad the odometry is (its std
// covers the 2 % scale error and the 1e-3 rad/m gyro bias)
constexpr SensorNoise kSmallNoise{0.002, 0.001, 0.02 * kPi / 180.0};  // 2 mm + 0.1 %, 0.02 deg

PoseGraphParams loop_params() {
  PoseGraphParams p;
  p.range_std = kSmallNoise.range_std;
  p.range_std_per_m = kSmallNoise.range_per_m;
  p.bearing_std = kSmallNoise.bearing_std;
  p.motion_std_xy_per_m = 0.03;
  p.motion_std_yaw_per_m = 2e-3;
  return p;
}

TEST(PoseGraph, PullsAKnownDriftedLoopBackToWithinFiveCentimetres) {
  // a lap and 12 m more (the first cones seen again close the loop); three
  // noise draws, each must hold. What limits the result is the observations'
  // noise, not the odometry's systematic drift: without observation noise
  // the same graph ends within 1 mm; with FastSlamParams' realistic 2 cm +
  // 1 %, 0.2 deg within 7-25 cm, and with cones 10 m apart (30) and this
  // noise within 2-5 cm (four seeds each; the information is the limit:
  // least squares with the true noise model is the best estimate there is)
  const Drive d = drifted_drive(12.0);
  for (std::uint64_t seed : {7u, 8u, 9u}) {
    PoseGraph g = graph_of(d, loop_params(), kSmallNoise, seed);
    ASSERT_EQ(g.landmarks(), 62);
    ASSERT_EQ(g.rejected(), 0);
    ASSERT_GT(g.observations(), 7 * g.nodes());

    double drift = 0.0;
    for (int i = 0; i < g.nodes(); ++i)
      drift = std::max(drift, distance(g.pose(i).position(), d.truth[static_cast<std::size_t>(i)].position()));
    EXPECT_GT(drift, 1.0) << "the drift the graph must remove";

    const PoseGraph::Result r = g.optimise();
    ASSERT_TRUE(r.ok) << r.reason;
    EXPECT_LT(r.final_cost, r.initial_cost);
    double worst = 0.0, worst_yaw = 0.0;
    for (int i = 0; i < g.nodes(); ++i) {
      const Pose2& t = d.truth[static_cast<std::size_t>(i)];
      worst = std::max(worst, distance(g.pose(i).position(), t.position()));
      worst_yaw = std::max(worst_yaw, std::abs(wrap_angle(g.pose(i).yaw - t.yaw)));
    }
    double worst_lm = 0.0;
    for (const Cone& c : d.cones) worst_lm = std::max(worst_lm, distance(*g.landmark(c.id), c.p));
    std::printf("seed %d: drift before %.2f m; after: poses within %.4f m and %.5f rad, landmarks within %.4f m "
                "(%d iterations)\n",
                static_cast<int>(seed), drift, worst, worst_yaw, worst_lm, r.iterations);
    EXPECT_LT(worst, 0.05);
    EXPECT_LT(worst_lm, 0.05);
    EXPECT_LT(worst_yaw, 0.005);
  }
}

// the step test (PoseGraphParams::step_tolerance) ends the solve early, and
// within its tolerance of where the solve run to Ceres' own tests ends: the
// drifted loop with FastSlamParams' realistic noise model and observations
// twice as noisy as it says (as the raw perception's centroids are: a part
// of the residuals then sits in Huber's linear range, and LM closes in
// linearly there, as on the default run's windows)
TEST(PoseGraph, TheStepTestEndsWithinItsToleranceOfTheFullSolve) {
  const Drive d = drifted_drive(12.0);
  for (std::uint64_t seed : {7u, 8u}) {
    PoseGraphParams quick = loop_params();
    quick.range_std = 0.02;
    quick.range_std_per_m = 0.01;
    quick.bearing_std = 0.2 * kPi / 180.0;
    quick.step_tolerance = 1e-4;
    PoseGraphParams full = quick;
    full.step_tolerance = 0.0;
    const SensorNoise noise{2.0 * quick.range_std, 2.0 * quick.range_std_per_m, 2.0 * quick.bearing_std};
    PoseGraph a = graph_of(d, quick, noise, seed), b = graph_of(d, full, noise, seed);
    const PoseGraph::Result ra = a.optimise(), rb = b.optimise();
    ASSERT_TRUE(ra.ok) << ra.reason;
    ASSERT_TRUE(rb.ok) << rb.reason;
    EXPECT_EQ(ra.reason, "");
    double worst = 0.0;
    for (int i = 0; i < a.nodes(); ++i) {
      worst = std::max({worst, distance(a.pose(i).position(), b.pose(i).position()),
                        std::abs(wrap_angle(a.pose(i).yaw - b.pose(i).yaw))});
    }
    for (const Cone& c : d.cones) worst = std::max(worst, distance(*a.landmark(c.id), *b.landmark(c.id)));
    std::printf("seed %d: %d iterations with the step test, %d without; %.2g apart at most\n", static_cast<int>(seed),
                ra.iterations, rb.iterations, worst);
    EXPECT_LT(ra.iterations, rb.iterations);
    EXPECT_LT(worst, quick.step_tolerance);
    EXPECT_LE(ra.final_cost, ra.initial_cost);
  }
}

// ---- 4. Ceres' solution against a dense Gauss-Newton written here

// a small noisy problem: 5 poses 1.5 m apart on a 10 m arc, 4 cones each
// seen from every pose; odometry with 2 cm and 0.01 rad of noise per step,
// observations with FastSlamParams' (2 cm + 1 %, 0.2 deg)
struct Small {
  std::vector<Pose2> odometry;
  struct Obs {
    int node, lm;
    Vec2 z;
  };
  std::vector<Obs> obs;
  std::vector<Vec2> lm_initial;
};

Small small_problem() {
  Small s;
  std::mt19937_64 rng(3);
  std::normal_distribution<double> g(0.0, 1.0);
  const std::vector<Vec2> cones{{3.0, 4.0}, {5.0, -2.0}, {7.0, 6.0}, {2.0, 9.0}};
  Pose2 prev_truth;
  for (int i = 0; i < 5; ++i) {
    const double a = 1.5 * i / 10.0;  // on the circle about (0, 10)
    const Pose2 truth{10.0 * std::sin(a), 10.0 - 10.0 * std::cos(a), a};
    if (i == 0) {
      s.odometry.push_back(truth);
    } else {  // the true motion with 2 cm and 0.01 rad of noise
      const Pose2 t = delta_of(prev_truth, truth);
      s.odometry.push_back(compose(s.odometry.back(), {t.x + 0.02 * g(rng), t.y + 0.02 * g(rng), t.yaw + 0.01 * g(rng)}));
    }
    prev_truth = truth;
    for (int j = 0; j < 4; ++j) {
      const Vec2 b = truth.inverse_transform(cones[static_cast<std::size_t>(j)]);
      const double r = norm(b) * (1.0 + 0.01 * g(rng)) + 0.02 * g(rng);
      const Vec2 z = r * unit_from_angle(angle_of(b) + 0.0035 * g(rng));
      s.obs.push_back({i, j, z});
      if (i == 0) s.lm_initial.push_back(s.odometry[0].transform(z));
    }
  }
  return s;
}

// the stacked whitened residuals of both kinds, written out again from the
// paper's formulas; x: poses held..4 (x, y, theta), then the 4 landmarks
// (x, y); the poses before `held` at their odometry (held fixed).
// The observations' whitening is diag(1/sr, 1/(r sb)) R(b)^T, another square
// root of C^-1 than the graph's Cholesky factor: the same objective
Eigen::VectorXd stacked(const Eigen::VectorXd& x, const Small& s, const PoseGraphParams& p, int held = 1) {
  auto pose = [&](int i) -> Eigen::Vector3d {
    const Pose2& o = s.odometry[static_cast<std::size_t>(i)];
    if (i < held) return {o.x, o.y, o.yaw};
    return x.segment<3>(3 * (i - held));
  };
  const int lm0 = 3 * (5 - held);  // the landmarks' first coordinate in x
  Eigen::VectorXd r(4 * 3 + static_cast<int>(s.obs.size()) * 2);
  int k = 0;
  for (int i = 1; i < 5; ++i) {
    const Pose2 &a = s.odometry[static_cast<std::size_t>(i) - 1], &b = s.odometry[static_cast<std::size_t>(i)];
    const double v = std::hypot(b.x - a.x, b.y - a.y), dth = wrap_angle(b.yaw - a.yaw);
    // the chord's offset across the midpoint direction a.yaw + dth / 2
    const double off = v * std::sin(std::atan2(b.y - a.y, b.x - a.x) - a.yaw - dth / 2.0);
    const double sxy = std::max(std::sqrt(std::pow(p.motion_std_xy_per_m * v, 2) + off * off), p.motion_std_xy_min);
    const double syaw = std::max(p.motion_std_yaw_per_m * v + p.motion_std_yaw_per_rad * std::abs(dth), p.motion_std_yaw_min);
    const Eigen::Vector3d P = pose(i - 1), C = pose(i);
    r(k++) = (C(0) - P(0) - v * std::cos(P(2) + dth / 2.0)) / sxy;
    r(k++) = (C(1) - P(1) - v * std::sin(P(2) + dth / 2.0)) / sxy;
    r(k++) = wrap_angle(C(2) - P(2) - dth) / syaw;
  }
  for (const Small::Obs& o : s.obs) {
    const Eigen::Vector3d P = pose(o.node);
    const Eigen::Vector2d l = x.segment<2>(lm0 + 2 * o.lm);
    const double c = std::cos(P(2)), sn = std::sin(P(2));
    const Eigen::Vector2d e(c * (l(0) - P(0)) + sn * (l(1) - P(1)) - o.z.x, -sn * (l(0) - P(0)) + c * (l(1) - P(1)) - o.z.y);
    const double range = norm(o.z), b = angle_of(o.z);
    const double sr = p.range_std + p.range_std_per_m * range, st = range * p.bearing_std;
    // R(b)^T e: its radial and tangential parts
    r(k++) = (std::cos(b) * e(0) + std::sin(b) * e(1)) / sr;
    r(k++) = (-std::sin(b) * e(0) + std::cos(b) * e(1)) / st;
  }
  return r;
}

Eigen::VectorXd gauss_newton(Eigen::VectorXd x, const Small& s, const PoseGraphParams& p, int held = 1) {
  for (int it = 0; it < 100; ++it) {
    const Eigen::VectorXd r = stacked(x, s, p, held);
    Eigen::MatrixXd J(r.size(), x.size());
    for (int j = 0; j < x.size(); ++j) {  // central differences
      const double h = 1e-6;
      Eigen::VectorXd xp = x, xm = x;
      xp(j) += h;
      xm(j) -= h;
      J.col(j) = (stacked(xp, s, p, held) - stacked(xm, s, p, held)) / (2.0 * h);
    }
    const Eigen::VectorXd dx = (J.transpose() * J).ldlt().solve(-J.transpose() * r);
    x += dx;
    if (dx.lpNorm<Eigen::Infinity>() < 1e-13) break;
  }
  return x;
}

TEST(PoseGraph, CeresSolutionEqualsADenseGaussNewton) {
  const Small s = small_problem();
  PoseGraphParams p;
  p.huber_scale = 0.0;  // plain least squares: the objective Gauss-Newton minimises
  p.step_tolerance = 0.0;  // to the end, as the reference goes (the default; the step test: above)
  PoseGraph g(p);
  Eigen::VectorXd x0(20);
  for (int i = 0; i < 5; ++i) {
    ASSERT_EQ(g.add_pose(s.odometry[static_cast<std::size_t>(i)], s.odometry[static_cast<std::size_t>(i)]), i);
    if (i > 0) x0.segment<3>(3 * (i - 1)) << s.odometry[static_cast<std::size_t>(i)].x, s.odometry[static_cast<std::size_t>(i)].y, s.odometry[static_cast<std::size_t>(i)].yaw;
  }
  for (int j = 0; j < 4; ++j) {
    ASSERT_TRUE(g.add_landmark(100 + j, s.lm_initial[static_cast<std::size_t>(j)]));
    x0.segment<2>(12 + 2 * j) << s.lm_initial[static_cast<std::size_t>(j)].x, s.lm_initial[static_cast<std::size_t>(j)].y;
  }
  for (const Small::Obs& o : s.obs) ASSERT_TRUE(g.add_observation(o.node, 100 + o.lm, o.z));
  // both start at the same cost
  const PoseGraph::Result res = g.optimise();
  ASSERT_TRUE(res.ok) << res.reason;
  EXPECT_NEAR(res.initial_cost, 0.5 * stacked(x0, s, p).squaredNorm(), 1e-9 * res.initial_cost);

  const Eigen::VectorXd x = gauss_newton(x0, s, p);
  std::printf("Gauss-Newton vs Ceres: max coordinate difference %.3g\n", [&] {
    double m = 0.0;
    for (int i = 1; i < 5; ++i) {
      m = std::max({m, std::abs(g.pose(i).x - x(3 * (i - 1))), std::abs(g.pose(i).y - x(3 * (i - 1) + 1)),
                    std::abs(wrap_angle(g.pose(i).yaw - x(3 * (i - 1) + 2)))});
    }
    for (int j = 0; j < 4; ++j)
      m = std::max({m, std::abs(g.landmark(100 + j)->x - x(12 + 2 * j)), std::abs(g.landmark(100 + j)->y - x(13 + 2 * j))});
    return m;
  }());
  EXPECT_GT((x - x0).lpNorm<Eigen::Infinity>(), 0.01) << "the problem must move";
  EXPECT_NEAR(res.final_cost, 0.5 * stacked(x, s, p).squaredNorm(), 1e-9 * res.final_cost);
  for (int i = 1; i < 5; ++i) {
    EXPECT_NEAR(g.pose(i).x, x(3 * (i - 1)), 1e-6) << "pose " << i;
    EXPECT_NEAR(g.pose(i).y, x(3 * (i - 1) + 1), 1e-6) << "pose " << i;
    EXPECT_NEAR(wrap_angle(g.pose(i).yaw - x(3 * (i - 1) + 2)), 0.0, 1e-6) << "pose " << i;
  }
  for (int j = 0; j < 4; ++j) {
    EXPECT_NEAR(g.landmark(100 + j)->x, x(12 + 2 * j), 1e-6) << "landmark " << j;
    EXPECT_NEAR(g.landmark(100 + j)->y, x(12 + 2 * j + 1), 1e-6) << "landmark " << j;
  }
  // the first pose is the gauge: untouched
  EXPECT_EQ(g.pose(0).x, s.odometry[0].x);
  EXPECT_EQ(g.pose(0).y, s.odometry[0].y);
}

// optimise(n) holds the first n nodes where they are and solves the rest
// against them: the dense Gauss-Newton of the same objective with those
// poses as constants
TEST(PoseGraph, HeldNodesStayPutAndTheRestSolveAgainstThem) {
  const Small s = small_problem();
  PoseGraphParams p;
  p.huber_scale = 0.0;
  constexpr int kHeld = 3;
  PoseGraph g(p), free(p);
  Eigen::VectorXd x0(3 * (5 - kHeld) + 8);
  for (int i = 0; i < 5; ++i) {
    const Pose2& o = s.odometry[static_cast<std::size_t>(i)];
    ASSERT_EQ(g.add_pose(o, o), i);
    ASSERT_EQ(free.add_pose(o, o), i);
    if (i >= kHeld) x0.segment<3>(3 * (i - kHeld)) << o.x, o.y, o.yaw;
  }
  const int lm0 = 3 * (5 - kHeld);
  for (int j = 0; j < 4; ++j) {
    const Vec2 l = s.lm_initial[static_cast<std::size_t>(j)];
    ASSERT_TRUE(g.add_landmark(100 + j, l));
    ASSERT_TRUE(free.add_landmark(100 + j, l));
    x0.segment<2>(lm0 + 2 * j) << l.x, l.y;
  }
  for (const Small::Obs& o : s.obs) {
    ASSERT_TRUE(g.add_observation(o.node, 100 + o.lm, o.z));
    ASSERT_TRUE(free.add_observation(o.node, 100 + o.lm, o.z));
  }
  const PoseGraph::Result res = g.optimise(kHeld);
  ASSERT_TRUE(res.ok) << res.reason;
  ASSERT_TRUE(free.optimise().ok);
  // the held nodes: as given, to the bit (the free solve moves them)
  double moved_free = 0.0;
  for (int i = 0; i < kHeld; ++i) {
    const Pose2& o = s.odometry[static_cast<std::size_t>(i)];
    EXPECT_EQ(g.pose(i).x, o.x) << "node " << i;
    EXPECT_EQ(g.pose(i).y, o.y) << "node " << i;
    EXPECT_EQ(g.pose(i).yaw, wrap_angle(o.yaw)) << "node " << i;
    moved_free = std::max(moved_free, distance(free.pose(i).position(), o.position()));
  }
  EXPECT_GT(moved_free, 1e-3) << "the held nodes must be ones a free solve moves";
  // the rest: the constrained minimum
  const Eigen::VectorXd x = gauss_newton(x0, s, p, kHeld);
  EXPECT_GT((x - x0).lpNorm<Eigen::Infinity>(), 0.01) << "the problem must move";
  EXPECT_NEAR(res.final_cost, 0.5 * stacked(x, s, p, kHeld).squaredNorm(), 1e-9 * res.final_cost);
  for (int i = kHeld; i < 5; ++i) {
    EXPECT_NEAR(g.pose(i).x, x(3 * (i - kHeld)), 1e-6) << "pose " << i;
    EXPECT_NEAR(g.pose(i).y, x(3 * (i - kHeld) + 1), 1e-6) << "pose " << i;
    EXPECT_NEAR(wrap_angle(g.pose(i).yaw - x(3 * (i - kHeld) + 2)), 0.0, 1e-6) << "pose " << i;
  }
  for (int j = 0; j < 4; ++j) {
    EXPECT_NEAR(g.landmark(100 + j)->x, x(lm0 + 2 * j), 1e-6) << "landmark " << j;
    EXPECT_NEAR(g.landmark(100 + j)->y, x(lm0 + 2 * j + 1), 1e-6) << "landmark " << j;
  }
  // holding more nodes than there are holds them all: nothing to solve but the landmarks
  PoseGraph all(p);
  for (int i = 0; i < 5; ++i) all.add_pose(s.odometry[static_cast<std::size_t>(i)], s.odometry[static_cast<std::size_t>(i)]);
  for (int j = 0; j < 4; ++j) all.add_landmark(100 + j, s.lm_initial[static_cast<std::size_t>(j)]);
  for (const Small::Obs& o : s.obs) all.add_observation(o.node, 100 + o.lm, o.z);
  ASSERT_TRUE(all.optimise(1000).ok);
  for (int i = 0; i < 5; ++i) EXPECT_EQ(all.pose(i).x, s.odometry[static_cast<std::size_t>(i)].x) << "node " << i;
}

// ---- 5. determinism

TEST(PoseGraph, IdenticalGraphsOptimiseToBitIdenticalResults) {
  const Drive d = drifted_drive(12.0);
  PoseGraph a = graph_of(d, loop_params(), kSmallNoise, 11);
  PoseGraph b = graph_of(d, loop_params(), kSmallNoise, 11);
  const PoseGraph::Result ra = a.optimise(), rb = b.optimise();
  ASSERT_TRUE(ra.ok);
  EXPECT_EQ(ra.iterations, rb.iterations);
  EXPECT_EQ(ra.final_cost, rb.final_cost);
  for (int i = 0; i < a.nodes(); ++i) {
    EXPECT_EQ(a.pose(i).x, b.pose(i).x);
    EXPECT_EQ(a.pose(i).y, b.pose(i).y);
    EXPECT_EQ(a.pose(i).yaw, b.pose(i).yaw);
  }
  ASSERT_EQ(a.landmark_ids(), b.landmark_ids());
  for (std::int64_t id : a.landmark_ids()) {
    EXPECT_EQ(a.landmark(id)->x, b.landmark(id)->x);
    EXPECT_EQ(a.landmark(id)->y, b.landmark(id)->y);
  }
}

// ---- 6. bad input

TEST(PoseGraph, BadInputIsRejectedAndCounted) {
  PoseGraph g;
  const PoseGraph::Result empty = g.optimise();
  EXPECT_FALSE(empty.ok);
  EXPECT_FALSE(empty.reason.empty());

  EXPECT_EQ(g.add_pose({kNaN, 0.0, 0.0}, {0.0, 0.0, 0.0}), -1);
  EXPECT_EQ(g.add_pose({0.0, 0.0, 0.0}, {0.0, std::numeric_limits<double>::infinity(), 0.0}), -1);
  EXPECT_EQ(g.nodes(), 0);
  EXPECT_EQ(g.rejected(), 2);
  EXPECT_FALSE(g.optimise().ok);

  ASSERT_EQ(g.add_pose({0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}), 0);
  ASSERT_EQ(g.add_pose({1.0, 0.0, 0.0}, {1.0, 0.0, 0.0}), 1);
  EXPECT_FALSE(g.add_landmark(5, {kNaN, 1.0}));
  EXPECT_FALSE(g.landmark(5));
  EXPECT_EQ(g.rejected(), 3);
  ASSERT_TRUE(g.add_landmark(5, {5.0, 1.0}));
  EXPECT_FALSE(g.add_observation(0, 6, {5.0, 1.0}));           // unknown landmark
  EXPECT_FALSE(g.add_observation(2, 5, {5.0, 1.0}));           // unknown node
  EXPECT_FALSE(g.add_observation(-1, 5, {5.0, 1.0}));
  EXPECT_FALSE(g.add_observation(0, 5, {kNaN, 1.0}));          // not finite
  EXPECT_FALSE(g.add_observation(0, 5, {0.1, 0.0}));           // nearer than min_range
  EXPECT_EQ(g.rejected(), 8);
  EXPECT_EQ(g.observations(), 0);

  // what was accepted still solves
  ASSERT_TRUE(g.add_observation(0, 5, {5.0, 1.0}));
  ASSERT_TRUE(g.add_observation(1, 5, {4.0, 1.0}));
  const PoseGraph::Result r = g.optimise();
  EXPECT_TRUE(r.ok) << r.reason;
  EXPECT_NEAR(g.landmark(5)->x, 5.0, 1e-9);
  EXPECT_NEAR(g.pose(1).x, 1.0, 1e-9);

  g.clear();
  EXPECT_EQ(g.nodes(), 0);
  EXPECT_EQ(g.landmarks(), 0);
  EXPECT_EQ(g.observations(), 0);
  EXPECT_FALSE(g.optimise().ok);
}

TEST(PoseGraph, InvalidParamsThrowAtConstruction) {
  PoseGraphParams p;
  p.range_std = 0.0;
  EXPECT_THROW(PoseGraph{p}, std::invalid_argument);
  p = {};
  p.max_iterations = 0;
  EXPECT_THROW(PoseGraph{p}, std::invalid_argument);
  p = {};
  p.huber_scale = kNaN;
  EXPECT_THROW(PoseGraph{p}, std::invalid_argument);
}

// ---- the rest of the interface

TEST(PoseGraph, LandmarksAreIdempotentWithSparseIds) {
  PoseGraph g;
  const std::int64_t big = std::numeric_limits<std::int64_t>::max(), small = std::numeric_limits<std::int64_t>::min();
  ASSERT_TRUE(g.add_landmark(big, {1.0, 2.0}));
  ASSERT_TRUE(g.add_landmark(small, {3.0, 4.0}));
  ASSERT_TRUE(g.add_landmark(big, {9.0, 9.0}));  // known: keeps its first value
  EXPECT_EQ(g.landmarks(), 2);
  EXPECT_EQ(g.landmark_ids(), (std::vector<std::int64_t>{big, small}));
  EXPECT_EQ(g.landmark(big)->x, 1.0);
  EXPECT_EQ(g.landmark(small)->y, 4.0);
  EXPECT_FALSE(g.landmark(0));
}

TEST(PoseGraph, WantsANodeAfterItsSpacingInDistanceOrHeading) {
  PoseGraphParams p;
  p.node_spacing = 1.0;
  p.node_spacing_yaw = 0.15;
  PoseGraph g(p);
  EXPECT_TRUE(g.wants_node({5.0, 5.0, 3.1}));  // the first
  g.add_pose({5.0, 5.0, 3.1}, {5.0, 5.0, 3.1});
  EXPECT_FALSE(g.wants_node({5.9, 5.0, 3.1}));
  EXPECT_TRUE(g.wants_node({5.0, 6.0, 3.1}));
  EXPECT_FALSE(g.wants_node({5.0, 5.0, -3.1}));  // 0.083 rad across +-pi
  EXPECT_TRUE(g.wants_node({5.0, 5.0, -3.0}));   // 0.183 rad
}

TEST(PoseGraph, HuberKeepsAWrongAssociationFromBendingTheLoop) {
  // the drifted loop, plus one cone wrongly associated from five nodes: seen
  // where its neighbour 5 m along is (an association FastSLAM got wrong)
  const Drive d = drifted_drive(12.0);
  const Cone& wrong = d.cones[20];
  const Vec2 actual = d.cones[22].p;  // the same side, the next cone
  auto run = [&](double huber) {
    PoseGraphParams p = loop_params();
    p.huber_scale = huber;
    PoseGraph g = graph_of(d, p, kSmallNoise, 7);
    int added = 0;
    for (int i = 0; i < g.nodes() && added < 5; ++i) {
      const Vec2 b = d.truth[static_cast<std::size_t>(i)].inverse_transform(actual);
      if (norm(b) < 15.0 && b.x > 0.0) added += g.add_observation(i, wrong.id, b) ? 1 : 0;
    }
    EXPECT_EQ(added, 5);
    EXPECT_TRUE(g.optimise().ok);
    double worst = 0.0;
    for (int i = 0; i < g.nodes(); ++i)
      worst = std::max(worst, distance(g.pose(i).position(), d.truth[static_cast<std::size_t>(i)].position()));
    return worst;
  };
  const double with = run(3.0), without = run(0.0);
  std::printf("one wrong association from 5 nodes: poses within %.4f m with Huber, %.4f m without\n", with, without);
  EXPECT_LT(with, 0.05);
  EXPECT_GT(without, 2.0 * with);
}

}  // namespace
}  // namespace paddock::slam
