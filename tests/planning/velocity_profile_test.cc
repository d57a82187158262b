// the forward-backward velocity profile against the ORACLES figures (TUM
// trajectory_planning_helpers calc_vel_profile v0.80) and against brute force.
#include "autonomy/planning/velocity_profile.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "autonomy/common/geometry.h"

namespace paddock::planning {
namespace {

// the ORACLES car: g-g 12/12 m/s^2, machine 5.3 m/s^2 (constant), 250 kg
VelocityProfileParams oracle_params(double p, double c_d) {
  VelocityProfileParams q;
  q.ax_max = 12.0;
  q.ay_max = 12.0;
  q.ax_brake_max = 12.0;
  q.ax_machine = 5.3;
  q.mass = 250.0;
  q.exponent = p;
  q.drag_coefficient = c_d;
  q.v_max = 40.0;
  q.turn_accel_scale = 1.0;  // the reference has no reduced limits in turns
  return q;
}

struct Path {
  std::vector<double> kappa;
  std::vector<double> ds;  // closed: one per point; open: one fewer
};

// an open straight of `length` m in steps of ds
Path straight(double length, double ds) {
  const auto n = static_cast<std::size_t>(std::lround(length / ds));
  return {std::vector<double>(n + 1, 0.0), std::vector<double>(n, ds)};
}

// ORACLES D: two 50 m straights and two semicircles of R = 10 m, 326 points.
// Each piece owns its first point: a straight is 100 points 0.5 m apart
// (curvature 0), a semicircle 63 points pi*10/63 = 0.4987 m apart
// (curvature 0.1), so the point where a straight meets a semicircle belongs
// to the piece that starts there. This is the construction that reproduces
// the oracle's figures (equal 0.4995 m spacing, or junction points with the
// other piece's curvature, give v_max and lap times 1e-2 away).
Path oval(std::size_t rotate = 0) {
  Path p;
  for (int half = 0; half < 2; ++half) {
    for (int i = 0; i < 100; ++i) {
      p.kappa.push_back(0.0);
      p.ds.push_back(0.5);
    }
    for (int i = 0; i < 63; ++i) {
      p.kappa.push_back(0.1);
      p.ds.push_back(kPi * 10.0 / 63.0);
    }
  }
  std::rotate(p.kappa.begin(), p.kappa.begin() + static_cast<long>(rotate), p.kappa.end());
  std::rotate(p.ds.begin(), p.ds.begin() + static_cast<long>(rotate), p.ds.end());
  return p;
}

double vmin(const std::vector<double>& v) { return *std::min_element(v.begin(), v.end()); }
double vmax(const std::vector<double>& v) { return *std::max_element(v.begin(), v.end()); }

TEST(VelocityProfile, OracleA_ClosedCircle) {
  // R = 10 m, no drag: the corner speed sqrt(12 * 10) everywhere, any exponent
  const std::size_t n = 126;
  const std::vector<double> kappa(n, 0.1);
  const std::vector<double> ds(n, 2.0 * kPi * 10.0 / static_cast<double>(n));
  for (double p : {1.0, 2.0}) {
    const auto prof = solve_velocity_profile(kappa, ds, true, oracle_params(p, 0.0), std::nullopt, std::nullopt);
    ASSERT_TRUE(prof.ok()) << prof.reason;
    ASSERT_EQ(prof.speed.size(), n);
    for (double v : prof.speed) EXPECT_NEAR(v, 10.954451, 1e-3);
  }
}

TEST(VelocityProfile, OracleB_OpenStraightStartStop) {
  const Path path = straight(100.0, 1.0);
  const auto prof = solve_velocity_profile(path.kappa, path.ds, false, oracle_params(1.0, 0.0), 0.0, 0.0);
  ASSERT_TRUE(prof.ok()) << prof.reason;
  const auto& v = prof.speed;
  ASSERT_EQ(v.size(), 101u);
  const auto top = std::max_element(v.begin(), v.end());
  EXPECT_NEAR(*top, 27.0444, 1e-3);
  EXPECT_EQ(top - v.begin(), 69);  // at s = 69 m
  const double first[] = {3.2558, 4.6043, 5.6391, 6.5115, 7.2801};
  for (int i = 0; i < 5; ++i) EXPECT_NEAR(v[static_cast<std::size_t>(i + 1)], first[i], 1e-3) << i + 1;
  EXPECT_DOUBLE_EQ(v.front(), 0.0);
  EXPECT_DOUBLE_EQ(v.back(), 0.0);
  EXPECT_NEAR(profile_time(v, path.ds, false), 7.3759, 1e-3);
}

TEST(VelocityProfile, OracleC_OpenStraightWithDrag) {
  const Path path = straight(75.0, 0.5);
  const auto prof =
      solve_velocity_profile(path.kappa, path.ds, false, oracle_params(2.0, 0.8), 0.0, std::nullopt);
  ASSERT_TRUE(prof.ok()) << prof.reason;
  ASSERT_EQ(prof.speed.size(), 151u);
  EXPECT_NEAR(prof.speed.back(), 25.1432, 1e-3);
  EXPECT_NEAR(profile_time(prof.speed, path.ds, false), 5.5313, 1e-3);
}

struct OvalCase {
  const char* name;
  double p, c_d, v_min, v_max, lap;
};

TEST(VelocityProfile, OracleD_ClosedOval) {
  const OvalCase cases[] = {
      {"D1", 1.0, 0.0, 10.9545, 21.9180, 11.8356},
      {"D2", 1.0, 0.8, 10.7835, 21.0107, 12.0703},
      {"D3", 2.0, 0.8, 10.9370, 21.0286, 11.9672},
  };
  const Path path = oval();
  ASSERT_EQ(path.kappa.size(), 326u);
  for (const auto& c : cases) {
    const auto prof =
        solve_velocity_profile(path.kappa, path.ds, true, oracle_params(c.p, c.c_d), std::nullopt, std::nullopt);
    ASSERT_TRUE(prof.ok()) << prof.reason;
    EXPECT_NEAR(vmin(prof.speed), c.v_min, 1e-3) << c.name;
    EXPECT_NEAR(vmax(prof.speed), c.v_max, 1e-3) << c.name;
    EXPECT_NEAR(profile_time(prof.speed, path.ds, true), c.lap, 1e-3) << c.name;
  }
}

// the lap does not depend on where it starts. The reference keeps the lap of
// its backward pass that had no run-in, so a start inside a braking zone
// loses that braking zone there (v_max 24.3 instead of 21.9 for D1 started
// 10 points before a semicircle); this solver does not.
TEST(VelocityProfile, ClosedLapIndependentOfStartPoint) {
  const Path base = oval();
  const auto params = oracle_params(2.0, 0.8);
  const auto ref = solve_velocity_profile(base.kappa, base.ds, true, params, std::nullopt, std::nullopt);
  ASSERT_TRUE(ref.ok());
  const double t_ref = profile_time(ref.speed, base.ds, true);
  for (std::size_t rot : {50u, 90u, 99u, 120u, 200u, 325u}) {
    const Path path = oval(rot);
    const auto prof = solve_velocity_profile(path.kappa, path.ds, true, params, std::nullopt, std::nullopt);
    ASSERT_TRUE(prof.ok());
    EXPECT_NEAR(profile_time(prof.speed, path.ds, true), t_ref, 1e-9) << rot;
    for (std::size_t i = 0; i < path.kappa.size(); ++i)
      ASSERT_NEAR(prof.speed[i], ref.speed[(i + rot) % path.kappa.size()], 1e-9) << rot << " " << i;
  }
}

// a wavy closed path with tight and gentle corners of both signs, uneven steps
Path wavy(std::size_t n) {
  Path p;
  for (std::size_t i = 0; i < n; ++i) {
    const double t = 2.0 * kPi * static_cast<double>(i) / static_cast<double>(n);
    double k = 0.08 * std::sin(3.0 * t) + 0.03 * std::cos(7.0 * t);
    if (i % 97 < 12) k = (i % 2 == 0 ? 0.2 : 0.19);  // short hairpins
    if (i % 53 < 20) k = 0.0;                         // straights
    p.kappa.push_back(k);
    p.ds.push_back(0.4 + 0.2 * std::abs(std::sin(5.0 * t)));
  }
  return p;
}

// every point respects the lateral limit and v_max, every step the
// acceleration and braking the car has: checked pair by pair. The solver
// takes a step's acceleration at its start and its braking at its end; once
// both passes have run, a step in a corner where drag exceeds what the tyre
// has left can be off by O(ds * drag difference) (1e-5 m/s) when judged from
// one end only, so a step passes when the limit at either of its ends allows it.
void check_limits(const std::vector<double>& v, const Path& path, bool closed, const VelocityProfileParams& q) {
  const std::size_t n = v.size();
  constexpr double tol = 1e-9;
  for (std::size_t i = 0; i < n; ++i) {
    ASSERT_TRUE(std::isfinite(v[i])) << i;
    ASSERT_GE(v[i], 0.0) << i;
    ASSERT_LE(v[i], q.v_max + tol) << i;
    const double k = std::abs(path.kappa[i]);
    if (k > 0.0) {
      ASSERT_LE(v[i], std::sqrt(q.ay_max / k) + tol) << i;
    }
  }
  const std::size_t nseg = closed ? n : n - 1;
  for (std::size_t i = 0; i < nseg; ++i) {
    const std::size_t j = (i + 1) % n;
    const double ds = path.ds[i];
    // accelerating from i to j
    const double a = std::max(available_acceleration(v[i], path.kappa[i], q),
                              available_acceleration(v[j], path.kappa[j], q));
    ASSERT_LE(v[j] * v[j], std::max(v[i] * v[i] + 2.0 * a * ds, 0.0) + 1e-9) << "acceleration " << i;
    // braking from i to j
    const double b = std::max(available_deceleration(v[i], path.kappa[i], q),
                              available_deceleration(v[j], path.kappa[j], q));
    ASSERT_LE(v[i] * v[i], v[j] * v[j] + 2.0 * b * ds + 1e-9) << "braking " << i;
  }
}

TEST(VelocityProfile, RespectsLimitsBruteForce) {
  const Path path = wavy(900);
  for (double p : {1.0, 1.5, 2.0, 3.0}) {
    for (double c_d : {0.0, 0.7, 3.0}) {
      for (double scale : {1.0, 0.6, 0.0}) {
        VelocityProfileParams q;  // the car's defaults
        q.exponent = p;
        q.drag_coefficient = c_d;
        q.turn_accel_scale = scale;
        q.ax_brake_max = 10.0;
        q.ax_machine = 8.0;
        const auto closed = solve_velocity_profile(path.kappa, path.ds, true, q, std::nullopt, std::nullopt);
        ASSERT_TRUE(closed.ok()) << closed.reason;
        check_limits(closed.speed, path, true, q);

        Path open = path;
        open.ds.pop_back();
        const auto prof = solve_velocity_profile(open.kappa, open.ds, false, q, 1.0, 2.0);
        ASSERT_TRUE(prof.ok()) << prof.reason;
        check_limits(prof.speed, open, false, q);
        EXPECT_LE(prof.speed.front(), 1.0);
        EXPECT_LE(prof.speed.back(), 2.0);
      }
    }
  }
}

// the profile is as fast as the limits allow: each speed is bound by one of
// them (corner speed, v_max, or an acceleration/braking step from a neighbour)
TEST(VelocityProfile, TightAgainstSomeLimit) {
  const Path path = wavy(600);
  VelocityProfileParams q;
  const auto prof = solve_velocity_profile(path.kappa, path.ds, true, q, std::nullopt, std::nullopt);
  ASSERT_TRUE(prof.ok());
  const auto& v = prof.speed;
  const std::size_t n = v.size();
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t a = (i + n - 1) % n, b = (i + 1) % n;
    const double k = std::abs(path.kappa[i]);
    double bound = std::min(q.v_max, k > 0.0 ? std::sqrt(q.ay_max / k) : q.v_max);
    const double up = v[a] * v[a] + 2.0 * available_acceleration(v[a], path.kappa[a], q) * path.ds[a];
    bound = std::min(bound, std::sqrt(std::max(up, 0.0)));
    const double c = std::sqrt(v[b] * v[b] + 2.0 * available_deceleration(v[b], path.kappa[b], q) * path.ds[i]);
    const double c2 = std::sqrt(v[b] * v[b] + 2.0 * available_deceleration(c, path.kappa[i], q) * path.ds[i]);
    bound = std::min({bound, c, c2});
    EXPECT_NEAR(v[i], bound, 1e-9) << i;
  }
}

TEST(VelocityProfile, TurnAccelScaleOnlySlowsDown) {
  const Path path = wavy(600);
  VelocityProfileParams q;
  q.turn_accel_scale = 1.0;
  const auto full = solve_velocity_profile(path.kappa, path.ds, true, q, std::nullopt, std::nullopt);
  q.turn_accel_scale = 0.5;
  const auto reduced = solve_velocity_profile(path.kappa, path.ds, true, q, std::nullopt, std::nullopt);
  ASSERT_TRUE(full.ok() && reduced.ok());
  // pointwise it can be a hair faster: near the lateral limit the friction
  // ellipse gives more acceleration to a slightly slower car, so a profile
  // that arrives slower can leave faster (discretisation-sized)
  for (std::size_t i = 0; i < full.speed.size(); ++i) EXPECT_LE(reduced.speed[i], full.speed[i] + 0.05);
  EXPECT_GT(profile_time(reduced.speed, path.ds, true), profile_time(full.speed, path.ds, true));
  // on a straight nothing changes: a launch from rest is the same
  const Path s = straight(30.0, 0.5);
  const auto a = solve_velocity_profile(s.kappa, s.ds, false, q, 0.0, std::nullopt);
  q.turn_accel_scale = 1.0;
  const auto b = solve_velocity_profile(s.kappa, s.ds, false, q, 0.0, std::nullopt);
  EXPECT_EQ(a.speed, b.speed);
}

TEST(VelocityProfile, StraightsAreFiniteNotNaN) {
  // zero curvature: an infinite corner speed, capped by v_max
  const std::vector<double> kappa(50, 0.0);
  const std::vector<double> ds(50, 1.0);
  VelocityProfileParams q;
  const auto closed = solve_velocity_profile(kappa, ds, true, q, std::nullopt, std::nullopt);
  ASSERT_TRUE(closed.ok());
  for (double v : closed.speed) EXPECT_DOUBLE_EQ(v, q.v_max);
  // a tiny curvature of either sign
  std::vector<double> k2(50, 1e-300);
  k2[3] = -1e-300;
  const auto tiny = solve_velocity_profile(k2, ds, true, q, std::nullopt, std::nullopt);
  ASSERT_TRUE(tiny.ok());
  for (double v : tiny.speed) EXPECT_DOUBLE_EQ(v, q.v_max);
  // an open straight with free ends
  const std::vector<double> ds_open(49, 1.0);
  const auto open = solve_velocity_profile(kappa, ds_open, false, q, std::nullopt, std::nullopt);
  ASSERT_TRUE(open.ok());
  for (double v : open.speed) EXPECT_DOUBLE_EQ(v, q.v_max);
}

TEST(VelocityProfile, StartAndEndBounds) {
  const Path s = straight(40.0, 0.5);
  VelocityProfileParams q;
  const auto prof = solve_velocity_profile(s.kappa, s.ds, false, q, 3.0, 1.0);
  ASSERT_TRUE(prof.ok());
  EXPECT_DOUBLE_EQ(prof.speed.front(), 3.0);
  EXPECT_DOUBLE_EQ(prof.speed.back(), 1.0);
  // a negative bound counts as 0
  const auto neg = solve_velocity_profile(s.kappa, s.ds, false, q, -1.0, -0.5);
  ASSERT_TRUE(neg.ok());
  EXPECT_DOUBLE_EQ(neg.speed.front(), 0.0);
  EXPECT_DOUBLE_EQ(neg.speed.back(), 0.0);
  // closed paths ignore them
  std::vector<double> ds(s.kappa.size(), 0.5);
  const auto closed = solve_velocity_profile(s.kappa, ds, true, q, 0.0, 0.0);
  ASSERT_TRUE(closed.ok());
  EXPECT_DOUBLE_EQ(closed.speed.front(), q.v_max);
}

TEST(VelocityProfile, AbnormalInputsGiveAReason) {
  const VelocityProfileParams q;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  auto fails = [&](const std::vector<double>& k, const std::vector<double>& ds, bool closed,
                   const VelocityProfileParams& p = VelocityProfileParams{},
                   std::optional<double> v0 = std::nullopt) {
    const auto r = solve_velocity_profile(k, ds, closed, p, v0, std::nullopt);
    EXPECT_FALSE(r.ok());
    EXPECT_FALSE(r.reason.empty());
    EXPECT_TRUE(r.speed.empty());
    return r.reason;
  };
  fails({}, {}, false);
  fails({}, {}, true);
  fails({0.1}, {}, false);
  fails({0.1, 0.1, 0.1}, {1.0, 1.0}, true);       // closed needs 3 lengths
  fails({0.1, 0.1, 0.1}, {1.0, 1.0, 1.0}, false);  // open needs 2
  fails({0.1, nan, 0.1}, {1.0, 1.0}, false);
  fails({0.1, inf, 0.1}, {1.0, 1.0}, false);
  fails({0.1, 0.1, 0.1}, {1.0, nan}, false);
  fails({0.1, 0.1, 0.1}, {1.0, 0.0}, false);
  fails({0.1, 0.1, 0.1}, {1.0, -1.0}, false);
  fails({0.1, 0.1, 0.1}, {1.0, 1.0}, false, q, nan);
  VelocityProfileParams bad = q;
  bad.ay_max = 0.0;
  EXPECT_EQ(fails({0.0, 0.0}, {1.0}, false, bad), "velocity profile: ay_max must be in [0.1, 100] m/s^2 (got 0)");
  bad = q;
  bad.exponent = 0.5;
  fails({0.0, 0.0}, {1.0}, false, bad);
  bad = q;
  bad.v_max = inf;
  fails({0.0, 0.0}, {1.0}, false, bad);
  bad = q;
  bad.turn_accel_scale = 1.5;
  fails({0.0, 0.0}, {1.0}, false, bad);
  bad = q;
  bad.mass = nan;
  EXPECT_EQ(fails({0.0, 0.0}, {1.0}, false, bad), "velocity profile: mass must be > 0 kg (got nan)");
}

TEST(VelocityProfile, ProfileTime) {
  EXPECT_DOUBLE_EQ(profile_time({2.0, 2.0, 2.0}, {1.0, 3.0}, false), 2.0);
  EXPECT_DOUBLE_EQ(profile_time({2.0, 2.0, 2.0}, {1.0, 3.0, 2.0}, true), 3.0);
  // constant acceleration from rest: 0 -> 4 m/s over 4 m takes 2 s
  EXPECT_DOUBLE_EQ(profile_time({0.0, 4.0}, {4.0}, false), 2.0);
  EXPECT_TRUE(std::isinf(profile_time({0.0, 0.0}, {1.0}, false)));
  EXPECT_TRUE(std::isnan(profile_time({1.0, 1.0}, {1.0, 1.0}, false)));
}

// the defaults are the car's and are valid
TEST(VelocityProfile, DefaultsAreValid) {
  const VelocityProfileParams q;
  EXPECT_EQ(params::validate(q), "");
  // the planned limits stay inside what the gotthard car can do: mu g, the motor
  EXPECT_LE(q.ax_max, 1.6 * kGravity);
  EXPECT_LE(q.ay_max, 1.6 * kGravity);
  EXPECT_LE(q.ax_brake_max, 1.6 * kGravity);
  EXPECT_LE(q.ax_machine, 5000.0 / 190.0);
}


// ---- the g-g-v envelope (limits = ggv) --------------------------------------

// an envelope with the given lines at speeds 0 and 40 m/s (linear between)
VelocityProfileParams ggv_params(double lat0, double lat40, double acc0, double acc40, double brk0, double brk40) {
  VelocityProfileParams q;
  q.limits = VelocityProfileParams::Ggv;
  q.ggv_speed = {0.0, 40.0};
  q.ggv_lateral = {lat0, lat40};
  q.ggv_accel = {acc0, acc40};
  q.ggv_brake = {brk0, brk40};
  q.margin_lateral = 1.0;
  q.margin_longitudinal = 1.0;
  q.turn_accel_scale = 1.0;
  q.v_max = 100.0;
  return q;
}

TEST(VelocityProfileGgv, ConstantEnvelopeReproducesOraclesAAndB) {
  // a flat envelope is the constant model without drag: ORACLES A (lateral
  // only) and B (the machine's 5.3 m/s^2 on a straight, braking at 12)
  VelocityProfileParams q = ggv_params(12.0, 12.0, 5.3, 5.3, 12.0, 12.0);
  q.exponent = 1.0;
  const std::size_t n = 126;
  const auto circle = solve_velocity_profile(std::vector<double>(n, 0.1),
                                             std::vector<double>(n, 2.0 * kPi * 10.0 / static_cast<double>(n)), true, q);
  ASSERT_TRUE(circle.ok()) << circle.reason;
  for (double v : circle.speed) EXPECT_NEAR(v, 10.954451, 1e-3);
  const Path path = straight(100.0, 1.0);
  const auto prof = solve_velocity_profile(path.kappa, path.ds, false, q, 0.0, 0.0);
  ASSERT_TRUE(prof.ok()) << prof.reason;
  EXPECT_NEAR(vmax(prof.speed), 27.0444, 1e-3);
  EXPECT_NEAR(prof.speed[1], 3.2558, 1e-3);
  EXPECT_NEAR(profile_time(prof.speed, path.ds, false), 7.3759, 1e-3);
}

TEST(VelocityProfileGgv, CircleWithDownforceSolvesTheQuadratic) {
  // ay(v) = 10 + 0.2 v (downforce): on R = 20 m, v^2 / 20 = 10 + 0.2 v,
  // v = 2 + sqrt(204) = 16.2829 m/s, a speed between the nodes
  const VelocityProfileParams q = ggv_params(10.0, 18.0, 5.0, 5.0, 10.0, 10.0);
  const std::size_t n = 200;
  const auto prof = solve_velocity_profile(std::vector<double>(n, -0.05),
                                           std::vector<double>(n, 2.0 * kPi * 20.0 / static_cast<double>(n)), true, q);
  ASSERT_TRUE(prof.ok()) << prof.reason;
  const double expected = 2.0 + std::sqrt(204.0);
  for (double v : prof.speed) EXPECT_NEAR(v, expected, 1e-9);
  EXPECT_NEAR(planned_lateral_limit(expected, q), expected * expected / 20.0, 1e-9);
}

TEST(VelocityProfileGgv, CornerSpeedBeyondTheTableAndTheMargin) {
  // the last node's limit is held beyond it; the margin scales it: R = 100 m
  // at 0.5 x 18 m/s^2 gives sqrt(900) = 30 m/s, under the 40 m/s node...
  VelocityProfileParams q = ggv_params(10.0, 18.0, 5.0, 5.0, 10.0, 10.0);
  q.ggv_speed = {0.0, 20.0};
  q.margin_lateral = 0.5;
  const std::size_t n = 400;
  const std::vector<double> ds(n, 2.0 * kPi * 100.0 / static_cast<double>(n));
  auto prof = solve_velocity_profile(std::vector<double>(n, 0.01), ds, true, q);
  ASSERT_TRUE(prof.ok()) << prof.reason;
  for (double v : prof.speed) EXPECT_NEAR(v, 30.0, 1e-9);
  // ...and with the full envelope: sqrt(18 * 100) = 42.43 m/s, above the last node
  q.margin_lateral = 1.0;
  prof = solve_velocity_profile(std::vector<double>(n, 0.01), ds, true, q);
  ASSERT_TRUE(prof.ok()) << prof.reason;
  for (double v : prof.speed) EXPECT_NEAR(v, std::sqrt(1800.0), 1e-9);
}

// the distance to reach speed v from rest at a(u) = a0 - k u (closed form of
// ds = u du / a(u))
double distance_to_speed(double v, double a0, double k) {
  return -v / k - a0 / (k * k) * std::log(1.0 - k * v / a0);
}

TEST(VelocityProfileGgv, StraightFromRestMatchesTheClosedForm) {
  // full throttle with a(v) = 12 - 0.3 v (drag and power in the measured
  // line), reaching 40 m/s asymptotically; the speed at 20, 50 and 100 m
  // against the closed form, solved by bisection
  const VelocityProfileParams q = ggv_params(15.0, 15.0, 12.0, 0.0, 10.0, 10.0);
  const double ds = 0.02;
  const Path path = straight(100.0, ds);
  const auto prof = solve_velocity_profile(path.kappa, path.ds, false, q, 0.0, std::nullopt);
  ASSERT_TRUE(prof.ok()) << prof.reason;
  for (double s : {20.0, 50.0, 100.0}) {
    double lo = 0.0, hi = 39.999999;
    for (int it = 0; it < 200; ++it) {
      const double mid = 0.5 * (lo + hi);
      (distance_to_speed(mid, 12.0, 0.3) < s ? lo : hi) = mid;
    }
    const auto i = static_cast<std::size_t>(std::lround(s / ds));
    EXPECT_NEAR(prof.speed[i], lo, 2e-3 * lo) << "at " << s << " m";
  }
  // and the braking end: from 30 m/s to rest at a constant 10 m/s^2 takes 45 m
  const auto stop = solve_velocity_profile(path.kappa, path.ds, false, q, 30.0, 0.0);
  ASSERT_TRUE(stop.ok()) << stop.reason;
  const auto j = static_cast<std::size_t>(std::lround((100.0 - 20.0) / ds));
  EXPECT_NEAR(stop.speed[j], std::sqrt(2.0 * 10.0 * 20.0), 1e-6);
}

TEST(VelocityProfileGgv, BadEnvelopesGiveAReason) {
  VelocityProfileParams q = ggv_params(10.0, 18.0, 5.0, 5.0, 10.0, 10.0);
  const std::vector<double> kappa(10, 0.0), ds(9, 1.0);
  q.ggv_brake = {10.0};
  auto prof = solve_velocity_profile(kappa, ds, false, q);
  EXPECT_NE(prof.reason.find("ggv_brake"), std::string::npos) << prof.reason;
  q = ggv_params(10.0, 18.0, 5.0, 5.0, 10.0, 10.0);
  q.ggv_speed = {10.0, 10.0};
  prof = solve_velocity_profile(kappa, ds, false, q);
  EXPECT_NE(prof.reason.find("ascending"), std::string::npos) << prof.reason;
  q = ggv_params(10.0, -1.0, 5.0, 5.0, 10.0, 10.0);
  prof = solve_velocity_profile(kappa, ds, false, q);
  EXPECT_NE(prof.reason.find("ggv_lateral[1]"), std::string::npos) << prof.reason;
}

// catch_up_profile: the forward pass from the car's state
TEST(VelocityProfileCatchUp, RampFromTheCarsSpeedMatchesTheClosedForm) {
  // a closed 200 m loop of straight (a lap planned at 24.9 m/s everywhere)
  // and a constant 4 m/s^2 of acceleration: from 5 m/s at point 380 (of 400,
  // 0.5 m apart) the speed is sqrt(25 + 8 s) until it meets 24.9 m/s after
  // (24.9^2 - 25) / 8 = 74.4 m, round the loop's end
  const VelocityProfileParams q = ggv_params(15.0, 15.0, 4.0, 4.0, 10.0, 10.0);
  const std::size_t n = 400;
  const std::vector<double> kappa(n, 0.0), ds(n, 0.5);
  std::vector<double> v(n, 24.9);
  const std::size_t from = 380;
  const std::size_t lowered = catch_up_profile(v, kappa, ds, true, from, 5.0, q);
  EXPECT_EQ(lowered, 149u);  // the points up to 74 m (sqrt(617) = 24.84 m/s)
  for (std::size_t k = 0; k < 149; ++k) {
    const double s = 0.5 * static_cast<double>(k);
    EXPECT_NEAR(v[(from + k) % n], std::sqrt(25.0 + 8.0 * s), 1e-9) << "at " << s << " m";
  }
  // nothing after the ramp, nothing before the car
  for (std::size_t i = (from + 149) % n; i < from; ++i) EXPECT_DOUBLE_EQ(v[i], 24.9) << i;
}

TEST(VelocityProfileCatchUp, TurnsLeaveLessToAccelerateAndAFastCarNothing) {
  // on a circle the friction ellipse leaves less than on a straight: the
  // ramp is longer; at or above the profile nothing changes
  const VelocityProfileParams q = ggv_params(15.0, 15.0, 4.0, 4.0, 10.0, 10.0);
  const std::size_t n = 400;
  const std::vector<double> straight_k(n, 0.0), circle_k(n, 1.0 / 60.0), ds(n, 0.5);
  std::vector<double> a(n, 25.0), b(n, 25.0);
  const std::size_t on_straight = catch_up_profile(a, straight_k, ds, true, 0, 5.0, q);
  const std::size_t on_circle = catch_up_profile(b, circle_k, ds, true, 0, 5.0, q);
  EXPECT_GT(on_circle, on_straight);
  for (std::size_t i = 1; i < on_straight; ++i) EXPECT_LT(b[i], a[i]) << i;
  std::vector<double> c(n, 25.0);
  EXPECT_EQ(catch_up_profile(c, straight_k, ds, true, 7, 25.0, q), 0u);
  EXPECT_EQ(catch_up_profile(c, straight_k, ds, true, 7, 30.0, q), 0u);
  EXPECT_EQ(c, std::vector<double>(n, 25.0));
}

TEST(VelocityProfileCatchUp, OpenPathsStopAtTheirEndAndBadInputChangesNothing) {
  const VelocityProfileParams q = ggv_params(15.0, 15.0, 4.0, 4.0, 10.0, 10.0);
  const Path path = straight(20.0, 0.5);  // 41 points: too short to catch up
  std::vector<double> v(path.kappa.size(), 25.0);
  EXPECT_EQ(catch_up_profile(v, path.kappa, path.ds, false, 0, 5.0, q), v.size());
  EXPECT_NEAR(v.back(), std::sqrt(25.0 + 8.0 * 20.0), 1e-9);
  const std::vector<double> before(path.kappa.size(), 25.0);
  std::vector<double> w = before;
  EXPECT_EQ(catch_up_profile(w, path.kappa, path.ds, false, w.size(), 5.0, q), 0u);  // from out of range
  EXPECT_EQ(catch_up_profile(w, path.kappa, path.ds, true, 0, 5.0, q), 0u);           // closed needs n lengths
  EXPECT_EQ(catch_up_profile(w, path.kappa, path.ds, false, 0, std::numeric_limits<double>::quiet_NaN(), q), 0u);
  EXPECT_EQ(w, before);
}

}  // namespace
}  // namespace paddock::planning
