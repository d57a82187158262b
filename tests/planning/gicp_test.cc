// 2D Generalised ICP: known transforms of the skidpad cones (the ORACLES-type
// test of issue 4), the objective at its minimum by brute force, GICP
// against point-to-point ICP, and abnormal inputs.
#include "autonomy/planning/gicp.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <vector>

#include "autonomy/common/geometry.h"
#include "autonomy/planning/skidpad.h"

namespace paddock::planning {
namespace {

constexpr double kHalfDegree = 0.5 * kPi / 180.0;

std::vector<Vec2> template_points() {
  std::vector<Vec2> pts;
  for (const Cone& c : skidpad_template_cones()) pts.push_back(c.position);
  return pts;
}

// the template seen in another frame: moved by T, Gaussian noise of sigma
// on each coordinate, a fraction of the cones dropped, only cones within
// `range` of the template point `eye` kept (range <= 0: all)
std::vector<Vec2> observe(const std::vector<Vec2>& pts, const Pose2& T, double sigma, double drop,
                          unsigned seed, double range = 0.0, Vec2 eye = {}) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::vector<Vec2> out;
  for (const Vec2& p : pts) {
    const double u = uniform(rng);
    const Vec2 n{sigma * noise(rng), sigma * noise(rng)};
    if (u < drop) continue;
    if (range > 0.0 && distance(p, eye) > range) continue;
    out.push_back(T.transform(p) + n);
  }
  return out;
}

double translation_error(const Pose2& a, const Pose2& b) {
  return std::hypot(a.x - b.x, a.y - b.y);
}
double rotation_error(const Pose2& a, const Pose2& b) {
  return std::abs(wrap_angle(a.yaw - b.yaw));
}

bool recovered(const GicpResult& r, const Pose2& truth) {
  return r.converged && translation_error(r.transform, truth) < 0.05 &&
         rotation_error(r.transform, truth) < kHalfDegree;
}

// point-to-point ICP: the same solver with identity covariances everywhere
GicpResult point_to_point(const std::vector<Vec2>& source, const std::vector<Vec2>& target,
                          const Pose2& initial, const GicpParams& params) {
  return align(source, std::vector<Covariance2>(source.size()), target,
               std::vector<Covariance2>(target.size()), initial, params);
}

void print(const char* what, const GicpResult& r, const Pose2& truth) {
  std::printf(
      "  %s: converged %d in %d iterations, (%.4f, %.4f, %.5f rad), error %.4f m %.4f deg, "
      "rmse %.4f m, %d inliers%s%s\n",
      what, r.converged ? 1 : 0, r.iterations, r.transform.x, r.transform.y, r.transform.yaw,
      translation_error(r.transform, truth), rotation_error(r.transform, truth) * 180.0 / kPi,
      r.rmse, r.inliers, r.reason.empty() ? "" : ": ", r.reason.c_str());
}

TEST(Gicp, RecoversAKnownTransformOfTheSkidpadCones) {
  // 0.2 rad and (3.0, -1.5) m, 2 cm noise, 10 % of the cones dropped, from identity
  const std::vector<Vec2> source = template_points();
  const Pose2 truth{3.0, -1.5, 0.2};
  const std::vector<Vec2> target = observe(source, truth, 0.02, 0.10, 42);
  ASSERT_LT(target.size(), source.size());
  const GicpResult r = align(source, target, Pose2{}, GicpParams{});
  print("gicp from identity", r, truth);
  ASSERT_TRUE(r.converged) << r.reason;
  EXPECT_TRUE(r.reason.empty());
  EXPECT_LT(translation_error(r.transform, truth), 0.05);
  EXPECT_LT(rotation_error(r.transform, truth), kHalfDegree);
  // every observed cone matched, at about the noise
  EXPECT_EQ(r.inliers, static_cast<int>(target.size()));
  EXPECT_LT(r.rmse, 0.05);
}

TEST(Gicp, RecoversTransformsOverManyNoiseDraws) {
  const std::vector<Vec2> source = template_points();
  for (unsigned seed = 1; seed <= 10; ++seed) {
    for (const Pose2& truth :
         {Pose2{3.0, -1.5, 0.2}, Pose2{-2.0, 2.5, -0.3}, Pose2{0.0, 0.0, 0.3}}) {
      const std::vector<Vec2> target = observe(source, truth, 0.02, 0.10, seed);
      const GicpResult r = align(source, target, Pose2{}, GicpParams{});
      EXPECT_TRUE(recovered(r, truth))
          << "seed " << seed << " truth (" << truth.x << ", " << truth.y << ", " << truth.yaw
          << "): " << r.transform.x << ", " << r.transform.y << ", " << r.transform.yaw << " "
          << r.reason;
    }
  }
}

TEST(Gicp, ExactDataGivesTheExactTransform) {
  const std::vector<Vec2> source = template_points();
  const Pose2 truth{100.0, -50.0, 2.5};  // far from the origin, yaw past pi/2
  const std::vector<Vec2> target = observe(source, truth, 0.0, 0.0, 1);
  const GicpResult r = align(source, target, Pose2{99.0, -49.0, 2.4}, GicpParams{});
  ASSERT_TRUE(r.converged) << r.reason;
  EXPECT_NEAR(r.transform.x, truth.x, 1e-6);
  EXPECT_NEAR(r.transform.y, truth.y, 1e-6);
  EXPECT_NEAR(r.transform.yaw, truth.yaw, 1e-8);
  EXPECT_LT(r.rmse, 1e-6);
  EXPECT_EQ(r.inliers, static_cast<int>(source.size()));
}

TEST(Gicp, ResultIsAMinimumOfTheObjectiveByBruteForce) {
  const std::vector<Vec2> source = template_points();
  const Pose2 truth{3.0, -1.5, 0.2};
  const std::vector<Vec2> target = observe(source, truth, 0.02, 0.10, 42);
  const GicpParams params;
  const GicpResult r = align(source, target, Pose2{}, params);
  ASSERT_TRUE(r.converged) << r.reason;
  // the objective with the covariances align() estimates, at the gate of its last stage
  const std::vector<Covariance2> cs = estimate_covariances(source, params);
  const std::vector<Covariance2> ct = estimate_covariances(target, params);
  GicpParams at_gate = params;
  at_gate.max_correspondence_distance = params.refine_correspondence_distance;
  const GicpObjective best = gicp_objective(source, cs, target, ct, r.transform, at_gate);
  ASSERT_TRUE(best.reason.empty()) << best.reason;
  EXPECT_EQ(best.inliers, r.inliers);
  // every step of a 3x3x3 grid around the result (1 mm, 1 mm, 0.1 mrad ~ 2 mm
  // at the far cones) and twice as far along each axis raises it
  const double hx = 1e-3, hy = 1e-3, ht = 1e-4;
  int probes = 0;
  for (int i = -1; i <= 1; ++i)
    for (int j = -1; j <= 1; ++j)
      for (int k = -1; k <= 1; ++k) {
        if (i == 0 && j == 0 && k == 0) continue;
        const Pose2 p{r.transform.x + i * hx, r.transform.y + j * hy, r.transform.yaw + k * ht};
        const GicpObjective o = gicp_objective(source, cs, target, ct, p, at_gate);
        EXPECT_GT(o.value, best.value) << i << " " << j << " " << k;
        ++probes;
      }
  for (int axis = 0; axis < 3; ++axis)
    for (const double sign : {-2.0, 2.0}) {
      Pose2 p = r.transform;
      if (axis == 0) p.x += sign * hx;
      if (axis == 1) p.y += sign * hy;
      if (axis == 2) p.yaw += sign * ht;
      EXPECT_GT(gicp_objective(source, cs, target, ct, p, at_gate).value, best.value);
      ++probes;
    }
  EXPECT_EQ(probes, 32);
}

TEST(Gicp, ConvergesFromTheStartLineWherePointToPointSlides) {
  // what the car sees from the skidpad's start line (template x = -16.68):
  // cones within 20 m, i.e. the entry lane and the near halves of both
  // circles; the start-pose guess is 0.3 rad off. Point-to-point ICP pairs
  // cones with their ring neighbours and settles rotated along the rings;
  // GICP's ring-normal weights pull it back.
  const std::vector<Vec2> source = template_points();
  const Pose2 truth{3.0, -1.5, 0.2};
  int gicp_ok = 0, p2p_ok = 0, trials = 0;
  for (unsigned seed = 1; seed <= 10; ++seed)
    for (const double yaw_error : {0.3, -0.3}) {
      const std::vector<Vec2> target =
          observe(source, truth, 0.02, 0.10, seed, 20.0, {-16.68, 0.0});
      const Pose2 guess{truth.x, truth.y, truth.yaw + yaw_error};
      const GicpResult g = align(source, target, guess, GicpParams{});
      const GicpResult p = point_to_point(source, target, guess, GicpParams{});
      if (seed == 1) {
        std::printf("  %zu cones seen, yaw guess off by %+.1f rad\n", target.size(), yaw_error);
        print("gicp          ", g, truth);
        print("point-to-point", p, truth);
      }
      gicp_ok += recovered(g, truth) ? 1 : 0;
      p2p_ok += recovered(p, truth) ? 1 : 0;
      ++trials;
    }
  std::printf("  recovered: gicp %d/%d, point-to-point %d/%d\n", gicp_ok, trials, p2p_ok, trials);
  EXPECT_EQ(gicp_ok, trials);
  EXPECT_LE(p2p_ok, trials / 4);
}

TEST(GicpBasin, RandomStartPoseErrorsWithMissedAndFalseCones) {
  // a small version of the sweep behind the defaults: truth within
  // +-0.3 rad and +-3 m of the guess, cones within 20 m of the start line,
  // 10 % missed, 5 cm noise, 3 false cones anywhere on the skidpad
  const std::vector<Vec2> source = template_points();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Pose2 guess{100.0, -50.0, 1.0};
  int gicp_ok = 0, p2p_ok = 0;
  const int trials = 40;
  for (int t = 0; t < trials; ++t) {
    const Pose2 truth{guess.x + 3.0 * u(rng), guess.y + 3.0 * u(rng), guess.yaw + 0.3 * u(rng)};
    std::vector<Vec2> target =
        observe(source, truth, 0.05, 0.10, static_cast<unsigned>(t), 20.0, {-16.68, 0.0});
    for (int f = 0; f < 3; ++f)
      target.push_back(truth.transform({2.5 + 22.5 * u(rng), 22.0 * u(rng)}));
    gicp_ok += recovered(align(source, target, guess, GicpParams{}), truth) ? 1 : 0;
    p2p_ok += recovered(point_to_point(source, target, guess, GicpParams{}), truth) ? 1 : 0;
  }
  std::printf("  recovered: gicp %d/%d, point-to-point %d/%d\n", gicp_ok, trials, p2p_ok, trials);
  EXPECT_GE(gicp_ok, 36);
  EXPECT_LT(p2p_ok, gicp_ok);
}

TEST(Gicp, CovarianceIsWideAlongTheCurveAndThinAcrossIt) {
  GicpParams params;
  params.covariance_epsilon = 1e-3;
  // points along a line at 30 degrees: variance 1 along it, eps across it
  const Vec2 dir = unit_from_angle(kPi / 6.0);
  std::vector<Vec2> line;
  for (int i = 0; i < 8; ++i)
    line.push_back(Vec2{5.0, -2.0} + dir * (3.0 * i) + left_normal(dir) * (i % 2 ? 0.01 : -0.01));
  const std::vector<Covariance2> cov = estimate_covariances(line, params);
  ASSERT_EQ(cov.size(), line.size());
  const Vec2 nrm = left_normal(dir);
  for (const Covariance2& c : cov) {
    const auto quad = [&c](Vec2 v) {
      return c.xx * v.x * v.x + 2.0 * c.xy * v.x * v.y + c.yy * v.y * v.y;
    };
    EXPECT_NEAR(quad(dir), 1.0, 1e-3);
    EXPECT_NEAR(quad(nrm), 1e-3, 1e-3);
  }
  // on a ring of cones: the tangent is the wide direction
  std::vector<Vec2> ring;
  for (int i = 0; i < 16; ++i) ring.push_back(7.475 * unit_from_angle(2.0 * kPi * i / 16.0));
  params.k_neighbours = 3;
  const std::vector<Covariance2> rc = estimate_covariances(ring, params);
  ASSERT_EQ(rc.size(), ring.size());
  for (std::size_t i = 0; i < ring.size(); ++i) {
    const Vec2 radial = ring[i] / norm(ring[i]);
    const Vec2 tangent = left_normal(radial);
    const Covariance2& c = rc[i];
    const auto quad = [&c](Vec2 v) {
      return c.xx * v.x * v.x + 2.0 * c.xy * v.x * v.y + c.yy * v.y * v.y;
    };
    EXPECT_NEAR(quad(tangent), 1.0, 1e-9);
    EXPECT_NEAR(quad(radial), 1e-3, 1e-9);
  }
}

TEST(Gicp, AbnormalInputsFailCleanly) {
  const GicpParams params;
  const std::vector<Vec2> good = template_points();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const auto expect_fail = [&](const std::vector<Vec2>& s, const std::vector<Vec2>& t,
                               const Pose2& init, const GicpParams& p, const char* what) {
    const GicpResult r = align(s, t, init, p);
    EXPECT_FALSE(r.converged) << what;
    EXPECT_FALSE(r.ok()) << what;
    EXPECT_FALSE(r.reason.empty()) << what;
    std::printf("  %-26s -> %s\n", what, r.reason.c_str());
  };
  expect_fail({}, good, Pose2{}, params, "empty source");
  expect_fail(good, {}, Pose2{}, params, "empty target");
  expect_fail({{1.0, 2.0}}, good, Pose2{}, params, "one source point");
  expect_fail(good, {{1.0, 2.0}}, Pose2{}, params, "one target point");
  expect_fail({{0.0, 0.0}, {1.0, 1.0}}, good, Pose2{}, params, "two source points");
  std::vector<Vec2> collinear;
  for (int i = 0; i < 20; ++i) collinear.push_back({0.5 * i, 0.25 * i - 3.0});
  expect_fail(collinear, collinear, Pose2{}, params, "collinear clouds");
  expect_fail(good, collinear, Pose2{}, params, "collinear target");
  expect_fail(std::vector<Vec2>(10, Vec2{1.0, 1.0}), good, Pose2{}, params, "coincident source");
  std::vector<Vec2> with_nan = good;
  with_nan[5].y = nan;
  expect_fail(with_nan, good, Pose2{}, params, "NaN in source");
  expect_fail(good, with_nan, Pose2{}, params, "NaN in target");
  std::vector<Vec2> with_inf = good;
  with_inf[0].x = std::numeric_limits<double>::infinity();
  expect_fail(good, with_inf, Pose2{}, params, "infinity in target");
  expect_fail(good, good, Pose2{nan, 0.0, 0.0}, params, "NaN initial transform");
  // the target 1 km away: nothing within the gate
  expect_fail(good, observe(good, Pose2{1000.0, 0.0, 0.0}, 0.0, 0.0, 1), Pose2{}, params,
              "no correspondences");
  GicpParams bad = params;
  bad.k_neighbours = 1;
  expect_fail(good, good, Pose2{}, bad, "k_neighbours = 1");
  bad = params;
  bad.covariance_epsilon = 0.0;
  expect_fail(good, good, Pose2{}, bad, "covariance_epsilon = 0");
  bad = params;
  bad.max_correspondence_distance = nan;
  expect_fail(good, good, Pose2{}, bad, "NaN max distance");
  // no convergence in the iterations allowed
  bad = params;
  bad.max_iterations = 1;
  expect_fail(good, observe(good, Pose2{3.0, -1.5, 0.2}, 0.02, 0.1, 3), Pose2{}, bad,
              "one iteration");
  // covariances that do not match the points, or are not positive definite
  const std::vector<Covariance2> cov(good.size());
  EXPECT_FALSE(align(good, cov, good, {}, Pose2{}, params).converged);
  std::vector<Covariance2> singular = cov;
  singular[3] = {1.0, 1.0, 1.0};
  EXPECT_FALSE(align(good, singular, good, cov, Pose2{}, params).converged);
  // the objective reports the same problems instead of a number
  EXPECT_FALSE(gicp_objective({}, {}, good, cov, Pose2{}, params).reason.empty());
  EXPECT_FALSE(gicp_objective(with_nan, cov, good, cov, Pose2{}, params).reason.empty());
  // and covariance estimation gives nothing rather than garbage
  EXPECT_TRUE(estimate_covariances(with_nan, params).empty());
  EXPECT_TRUE(estimate_covariances({}, params).empty());
}

TEST(Gicp, IdenticalCloudsAlignAtIdentity) {
  const std::vector<Vec2> pts = template_points();
  const GicpResult r = align(pts, pts, Pose2{}, GicpParams{});
  ASSERT_TRUE(r.converged) << r.reason;
  EXPECT_NEAR(r.transform.x, 0.0, 1e-9);
  EXPECT_NEAR(r.transform.y, 0.0, 1e-9);
  EXPECT_NEAR(r.transform.yaw, 0.0, 1e-9);
  EXPECT_LE(r.iterations, 4);
  // three points (the minimum) in a triangle
  const std::vector<Vec2> tri = {{0.0, 0.0}, {4.0, 0.0}, {0.0, 3.0}};
  const Pose2 T{0.3, -0.2, 0.05};
  std::vector<Vec2> moved;
  for (const Vec2& p : tri) moved.push_back(T.transform(p));
  const GicpResult t = align(tri, moved, Pose2{}, GicpParams{});
  ASSERT_TRUE(t.converged) << t.reason;
  EXPECT_NEAR(t.transform.x, T.x, 1e-6);
  EXPECT_NEAR(t.transform.y, T.y, 1e-6);
  EXPECT_NEAR(t.transform.yaw, T.yaw, 1e-6);
}

}  // namespace
}  // namespace paddock::planning
