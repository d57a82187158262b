// the ray-cast LiDAR, checked against independent geometry: an analytic
// ray / truncated-cone intersection, the cone's profile, the ground plane, the
// expected point count E(d) of ORACLES.md, the configured noise and dropout,
// and the rotation a turning car puts into a scan.
#include "sim/sensors/lidar.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <stdexcept>
#include <utility>
#include <vector>

namespace paddock::sensors {
namespace {

LidarParams noiseless() {
  LidarParams p;
  p.range_noise = 0.0;
  p.dropout = 0.0;
  return p;
}

std::function<Pose2(TimeNs)> at_rest(Pose2 pose = {}) {
  return [pose](TimeNs) { return pose; };
}

struct P3 {
  double x, y, z;
};

// a point in the map frame, for a sensor with no pitch
P3 to_world(const LidarPoint& q, const Pose2& base, const LidarParams& p) {
  const Vec2 o = base.transform({p.mount_x, p.mount_y});
  const Vec2 xy = o + rotate({q.x, q.y}, base.yaw);
  return {xy.x, xy.y, p.mount_z + q.z};
}

// the first intersection s > 0 of the ray o + s u (|u| = 1) with the lateral
// surface of an ideal truncated cone on (cx, cy), base radius r0, top radius
// ra at height h; NaN when it misses
double ray_cone(P3 o, P3 u, double cx, double cy, double r0, double ra, double h) {
  const double k = (ra - r0) / h;  // dr/dz
  const double ox = o.x - cx, oy = o.y - cy;
  // (ox + s ux)^2 + (oy + s uy)^2 = (r0 + k (oz + s uz))^2
  const double rz = r0 + k * o.z;
  const double a = u.x * u.x + u.y * u.y - k * k * u.z * u.z;
  const double b = 2.0 * (ox * u.x + oy * u.y - rz * k * u.z);
  const double c = ox * ox + oy * oy - rz * rz;
  const double disc = b * b - 4.0 * a * c;
  if (disc < 0.0) return std::numeric_limits<double>::quiet_NaN();
  const double sq = std::sqrt(disc);
  for (double s : {(-b - sq) / (2.0 * a), (-b + sq) / (2.0 * a)}) {
    const double z = o.z + s * u.z;
    if (s > 0.0 && z >= 0.0 && z <= h) return s;
  }
  return std::numeric_limits<double>::quiet_NaN();
}

double range_of(const LidarPoint& q) {
  return std::sqrt(double(q.x) * q.x + double(q.y) * q.y + double(q.z) * q.z);
}

class LidarSingleCone : public ::testing::TestWithParam<double> {};

TEST_P(LidarSingleCone, HitsLieOnTheConeAndCountIsNearExpected) {
  const double d = GetParam();
  const LidarParams p = noiseless();
  // small cone: 0.228 m base, 0.325 m high, 0.03 m flat top (independent numbers)
  const double r0 = 0.114, ra = 0.03, h = 0.325;
  const double cx = p.mount_x + d, cy = 0.0;
  LidarWorld world({Cone{{cx, cy}, ConeColor::Blue}});
  Lidar lidar(p, 1);
  const std::vector<LidarPoint> pts = lidar.scan(world, at_rest(), 0);

  int on_cone = 0, analytic_checked = 0;
  double worst_profile = 0.0, worst_range = 0.0;
  const P3 o{p.mount_x, p.mount_y, p.mount_z};
  for (const LidarPoint& q : pts) {
    const P3 w = to_world(q, Pose2{}, p);
    if (q.cone == -1) {
      EXPECT_NEAR(w.z, 0.0, 1e-3);
      continue;
    }
    ASSERT_EQ(q.cone, 0);
    ++on_cone;
    EXPECT_FLOAT_EQ(q.intensity, 0.5f);
    // on the profile: radius at height z
    ASSERT_GE(w.z, -1e-3);
    ASSERT_LE(w.z, h + 1e-3);
    const double rxy = std::hypot(w.x - cx, w.y - cy);
    const double profile = r0 + (ra - r0) * w.z / h;
    worst_profile = std::max(worst_profile, std::abs(rxy - profile));
    // range against the analytic ray / cone intersection. The mesh is an
    // inscribed 16-gon (radius off by <= r0 (1 - cos(pi/16)) = 2.2 mm), so the
    // range matches to 1 cm except for rays grazing the silhouette, where a
    // 2 mm radial offset moves the hit along the ray by up to sqrt(2 r0 2.2 mm)
    // = 2.2 cm: those (within 40 mm of the silhouette's edge) are skipped.
    const double r = range_of(q);
    const P3 u{w.x - o.x, w.y - o.y, w.z - o.z};
    const P3 un{u.x / r, u.y / r, u.z / r};
    const double s = ray_cone(o, un, cx, cy, r0, ra, h);
    // lateral offset of the ray from the cone axis at the hit, vs the radius
    const double lateral = std::abs(w.y - cy);
    if (lateral < 0.7 * profile) {
      ASSERT_FALSE(std::isnan(s)) << "ray hit the mesh but not the ideal cone";
      worst_range = std::max(worst_range, std::abs(s - r));
      ++analytic_checked;
    }
  }
  EXPECT_LT(worst_profile, 0.01);
  EXPECT_LT(worst_range, 0.01);
  // E(d), ORACLES.md (h_c = 0.31, w_c = 0.30), with this sensor's resolutions
  const double rv = lidar.vertical_resolution(), rh = lidar.horizontal_resolution();
  const double expected =
      0.5 * 0.31 / (2.0 * d * std::tan(rv / 2.0)) * 0.30 / (2.0 * d * std::tan(rh / 2.0));
  std::printf("cone at %.0f m: %d points (E = %.1f), %d checked analytically, "
              "worst profile error %.4f m, worst range error %.4f m\n",
              d, on_cone, expected, analytic_checked, worst_profile, worst_range);
  EXPECT_GT(analytic_checked, 0);
  EXPECT_GE(on_cone, expected / 2.0);
  EXPECT_LE(on_cone, expected * 2.0);
}

INSTANTIATE_TEST_SUITE_P(LidarRanges, LidarSingleCone, ::testing::Values(5.0, 10.0));

TEST(LidarTest, GroundHitsLieOnTheGroundAndAreInRange) {
  const LidarParams p = noiseless();
  LidarWorld world({});
  Lidar lidar(p, 2);
  const Pose2 base{10.0, -3.0, 0.7};
  const std::vector<LidarPoint> pts = lidar.scan(world, at_rest(base), 5);
  // every downward channel (-16 .. -1 deg, 16 of them) hits within 50 m:
  // the shallowest at 0.15 / sin(1 deg) = 8.6 m
  EXPECT_EQ(pts.size(), 16u * 1024u);
  for (const LidarPoint& q : pts) {
    EXPECT_EQ(q.cone, -1);
    EXPECT_FLOAT_EQ(q.intensity, 0.1f);
    EXPECT_LT(q.ring, 16);
    EXPECT_NEAR(to_world(q, base, p).z, 0.0, 1e-4);
    const double r = range_of(q);
    EXPECT_GE(r, p.range_min);
    EXPECT_LE(r, p.range_max);
  }
}

TEST(LidarTest, RangeNoiseHasTheConfiguredStd) {
  LidarParams exact = noiseless();
  LidarParams noisy = exact;
  noisy.range_noise = 0.02;
  noisy.range_min = 0.0;  // keep the nearest ground ring (0.54 m) whatever the noise
  exact.range_min = 0.0;
  LidarWorld world({});
  Lidar a(exact, 3), b(noisy, 3);
  std::map<std::pair<std::int64_t, int>, double> truth;
  for (const LidarPoint& q : a.scan(world, at_rest(), 0)) truth[{q.t, q.ring}] = range_of(q);
  double sum = 0.0, sum2 = 0.0;
  int n = 0;
  for (int rep = 0; rep < 4; ++rep) {
    for (const LidarPoint& q : b.scan(world, at_rest(), 0)) {
      const auto it = truth.find({q.t, q.ring});
      ASSERT_NE(it, truth.end());
      const double e = range_of(q) - it->second;
      sum += e;
      sum2 += e * e;
      ++n;
    }
  }
  const double mean = sum / n;
  const double std = std::sqrt(sum2 / n - mean * mean);
  std::printf("range noise over %d points: mean %.5f m, std %.5f m\n", n, mean, std);
  EXPECT_NEAR(std, 0.02, 0.05 * 0.02);
  EXPECT_NEAR(mean, 0.0, 0.001);
}

TEST(LidarTest, DropoutRemovesTheConfiguredFraction) {
  LidarParams p = noiseless();
  LidarWorld world({});
  const double full = static_cast<double>(Lidar(p, 4).scan(world, at_rest(), 0).size());
  p.dropout = 0.3;
  const double kept = static_cast<double>(Lidar(p, 4).scan(world, at_rest(), 0).size());
  EXPECT_NEAR(kept / full, 0.7, 0.02);
}

// mean bearing (sensor frame) and mean time of the points on one cone
struct ConeView {
  double bearing;
  double t;
  int n;
};

ConeView view_of(const std::vector<LidarPoint>& pts, int cone) {
  double sx = 0.0, sy = 0.0, st = 0.0;
  int n = 0;
  for (const LidarPoint& q : pts) {
    if (q.cone != cone) continue;
    sx += q.x;
    sy += q.y;
    st += to_seconds(q.t);
    ++n;
  }
  return {std::atan2(sy, sx), n > 0 ? st / n : 0.0, n};
}

TEST(LidarTest, TurningCarDistortsTheScanByTheRotationOverTheSweep) {
  LidarParams p = noiseless();
  p.mount_x = 0.0;  // the sensor on the yaw axis: the turn only rotates it
  std::vector<Cone> cones;
  const std::vector<double> angles = {-150, -90, -30, 30, 90, 150};  // deg
  for (double a : angles) cones.push_back({8.0 * unit_from_angle(a * kPi / 180.0), ConeColor::Blue});
  LidarWorld world(cones);
  const double omega = 1.0;  // rad/s
  const auto still = Lidar(p, 5).scan(world, at_rest(), 0);
  const auto turning = Lidar(p, 5).scan(
      world, [omega](TimeNs t) { return Pose2{0.0, 0.0, omega * to_seconds(t)}; }, 0);

  double first_rot = 0.0, last_rot = 0.0;
  for (int i = 0; i < static_cast<int>(cones.size()); ++i) {
    const ConeView a = view_of(still, i), b = view_of(turning, i);
    ASSERT_GT(a.n, 0);
    ASSERT_GT(b.n, 0);
    const double rot = wrap_angle(b.bearing - a.bearing);
    // at time t the sensor has turned by omega t: the cone appears rotated back by it
    EXPECT_NEAR(rot, -omega * b.t, 0.01) << "cone " << i;
    if (i == 0) first_rot = rot;
    if (i + 1 == static_cast<int>(cones.size())) last_rot = rot;
    // and the scan, brought to the map with each point's own pose, is the still one
    for (const LidarPoint& q : turning) {
      if (q.cone != i) continue;
      const P3 w = to_world(q, Pose2{0.0, 0.0, omega * to_seconds(q.t)}, p);
      EXPECT_LT(std::hypot(w.x - cones[static_cast<std::size_t>(i)].position.x,
                           w.y - cones[static_cast<std::size_t>(i)].position.y),
                0.12);
    }
  }
  std::printf("first cone (seen at ~%.3f s) rotated %.4f rad, last rotated %.4f rad\n",
              view_of(turning, 0).t, first_rot, last_rot);
  EXPECT_GT(first_rot, -0.02);
  EXPECT_LT(last_rot, -0.08);
  EXPECT_NEAR(last_rot - first_rot, -0.1 * (150.0 + 150.0) / 360.0 * 1.0, 0.02);
}

TEST(LidarTest, SameSeedSamePoints) {
  LidarParams p;
  p.dropout = 0.2;
  std::vector<Cone> cones;
  for (int i = 0; i < 20; ++i) cones.push_back({{3.0 + i, (i % 2 ? 1.5 : -1.5)}, ConeColor::Yellow});
  LidarWorld world(cones);
  auto traj = [](TimeNs t) { return Pose2{5.0 * to_seconds(t), 0.0, 0.3 * to_seconds(t)}; };
  const auto a = Lidar(p, 42).scan(world, traj, 100);
  const auto b = Lidar(p, 42).scan(world, traj, 100);
  const auto c = Lidar(p, 43).scan(world, traj, 100);
  ASSERT_EQ(a.size(), b.size());
  ASSERT_FALSE(a.empty());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].x, b[i].x);
    EXPECT_EQ(a[i].y, b[i].y);
    EXPECT_EQ(a[i].z, b[i].z);
    EXPECT_EQ(a[i].intensity, b[i].intensity);
    EXPECT_EQ(a[i].ring, b[i].ring);
    EXPECT_EQ(a[i].t, b[i].t);
    EXPECT_EQ(a[i].cone, b[i].cone);
  }
  bool differs = a.size() != c.size();
  for (std::size_t i = 0; !differs && i < a.size(); ++i) differs = a[i].x != c[i].x;
  EXPECT_TRUE(differs);
}

TEST(LidarTest, ColumnTimesSpanOneRotation) {
  Lidar lidar(LidarParams{}, 6);
  LidarWorld world({});
  const auto pts = lidar.scan(world, at_rest(), 1000);
  ASSERT_FALSE(pts.empty());
  EXPECT_EQ(pts.front().t, 1000);
  EXPECT_EQ(pts.back().t, 1000 + 100'000'000LL * 1023 / 1024);
}

TEST(LidarTest, NanPoseGivesEmptyScan) {
  Lidar lidar(LidarParams{}, 7);
  LidarWorld world({Cone{{7.0, 0.0}, ConeColor::Blue}});
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(lidar.scan(world, at_rest(Pose2{nan, 0.0, 0.0}), 0).empty());
  EXPECT_TRUE(lidar.scan(world, at_rest(Pose2{0.0, 0.0, nan}), 0).empty());
}

TEST(LidarTest, NonFiniteConeIsSkippedAndIndicesKept) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  LidarWorld world({Cone{{nan, 0.0}, ConeColor::Blue}, Cone{{7.2, 0.0}, ConeColor::BigOrange}});
  const auto pts = Lidar(noiseless(), 8).scan(world, at_rest(), 0);
  int on_big = 0;
  for (const LidarPoint& q : pts) {
    EXPECT_NE(q.cone, 0);
    on_big += q.cone == 1;
    if (q.cone == 1) {
      EXPECT_LE(to_world(q, Pose2{}, noiseless()).z, 0.505 + 1e-3);
    }
  }
  EXPECT_GT(on_big, 0);
}

TEST(LidarTest, InvalidParamsAreRejected) {
  LidarParams p;
  EXPECT_EQ(validate(p), "");
  p.channels = 0;
  EXPECT_THROW(Lidar(p, 1), std::invalid_argument);
  p = LidarParams{};
  p.range_max = p.range_min;
  EXPECT_NE(validate(p).find("range_max"), std::string::npos);
  p = LidarParams{};
  p.dropout = 1.0;
  EXPECT_NE(validate(p).find("dropout"), std::string::npos);
  p = LidarParams{};
  p.elevation_max = p.elevation_min;
  EXPECT_NE(validate(p).find("elevation_max"), std::string::npos);
  p = LidarParams{};
  p.rate = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(validate(p).find("rate"), std::string::npos);
}

}  // namespace
}  // namespace paddock::sensors
