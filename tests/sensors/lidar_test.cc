// the ray-cast LiDAR, checked against independent geometry: an analytic
// ray / truncated-cone intersection, the cone's profile, the ground plane, the
// expected point count E(d) of ORACLES.md, the configured noise and dropout,
// and the rotation a turning car puts into a scan.
#include "sim/sensors/lidar.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <algorithm>
#include <cstdio>
#include <iterator>
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
  p.intensity_noise = 0.0;
  return p;
}

// the channels that meet a flat ground within the range limits, from the
// layout (elevations evenly spaced, both ends included): downward, and the
// slant range mount_z / sin(depression) in [range_min, range_max]
int ground_channels(const LidarParams& p) {
  int n = 0;
  for (int i = 0; i < p.channels; ++i) {
    const double e =
        p.elevation_min + (p.elevation_max - p.elevation_min) * i / std::max(1, p.channels - 1);
    if (e >= 0.0) continue;
    const double r = p.mount_z / std::sin(-e);
    if (r >= p.range_min && r <= p.range_max) ++n;
  }
  return n;
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
    // blue (0.25) or white (0.9), cos(incidence) <= 1, full fall-off at <= 5 m
    EXPECT_GT(q.intensity, 0.0f);
    EXPECT_LE(q.intensity, 0.9f * (d <= 5.0 ? 1.0f : 25.0f / float(d * d)) + 1e-5f);
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

// a barrier block 8 m ahead of the sensor, across its view: its near face is
// the plane x = mount_x + 8 (world), 4 m wide, 2 m high on flat ground. Every
// beam whose ray meets that rectangle (computed here from the layout's
// elevations and azimuths alone) returns from it with the range of the
// ray/plane intersection and the block's intensity, labelled a structure;
// no other beam does
TEST(LidarBlock, ItsFaceIsHitExactlyWhereTheBeamsMeetTheRectangle) {
  const LidarParams p = noiseless();
  const double face = p.mount_x + 8.0, half = 2.0, height = 2.0;
  const world::Block block{{face + 0.3, 0.0}, kPi / 2.0, 2.0 * half, 0.6, height};
  LidarWorld world({}, {}, {}, {block});
  ASSERT_EQ(world.block_count(), 1u);
  Lidar lidar(p, 1);
  const std::vector<LidarPoint> pts = lidar.scan(world, at_rest(), 0);
  // the beams that meet the face, well inside its edges (1 cm)
  int expected = 0, edge = 0;
  for (int c = 0; c < p.columns; ++c) {
    const double az = -kPi + 2.0 * kPi * c / p.columns;
    if (std::cos(az) <= 0.0) continue;
    for (int j = 0; j < p.channels; ++j) {
      const double el = p.elevation_min + (p.elevation_max - p.elevation_min) * j / (p.channels - 1);
      const double t = 8.0 / (std::cos(el) * std::cos(az));  // the range to the plane
      const double y = t * std::cos(el) * std::sin(az), z = p.mount_z + t * std::sin(el);
      const double inside = std::min({half - std::abs(y), z, height - z});
      if (z < 0.0) continue;  // the ground first
      if (inside > 0.01) ++expected;
      else if (inside > -0.01) ++edge;
    }
  }
  int hits = 0;
  double worst = 0.0;
  for (const LidarPoint& q : pts) {
    if (q.cone != kHitStructure) {
      EXPECT_EQ(q.cone, kHitGround);
      continue;
    }
    ++hits;
    const P3 w = to_world(q, Pose2{}, p);
    worst = std::max(worst, std::abs(w.x - face));
    EXPECT_LE(std::abs(w.y), half + 1e-3);
    EXPECT_GE(w.z, -1e-3);
    EXPECT_LE(w.z, height + 1e-3);
    // Lambert on the face (normal along x): rho cos(inc) min(1, (5 / r)^2)
    const double r = range_of(q);
    const double cos_inc = (w.x - p.mount_x) / r;
    EXPECT_NEAR(q.intensity, p.reflect_barrier * cos_inc * std::min(1.0, 25.0 / (r * r)), 1e-4);
  }
  std::printf("block face 8 m ahead: %d hits, %d expected inside, %d on the edges; worst off the face %.2e m\n",
              hits, expected, edge, worst);
  EXPECT_LT(worst, 1e-4);
  EXPECT_GE(hits, expected);
  EXPECT_LE(hits, expected + edge);
  EXPECT_GT(expected, 500);
}

TEST(LidarTest, GroundHitsLieOnTheGroundAndAreInRange) {
  const LidarParams p = noiseless();
  LidarWorld world({});
  Lidar lidar(p, 2);
  const Pose2 base{10.0, -3.0, 0.7};
  const std::vector<LidarPoint> pts = lidar.scan(world, at_rest(base), 5);
  // every downward channel whose slant range lies within the limits hits:
  // by default -8 .. -0.5 deg, 16 of them, the shallowest at 0.15 / sin(0.5
  // deg) = 17.2 m; the rings ascend in elevation, so they are the lowest ones
  const int n_ground = ground_channels(p);
  EXPECT_EQ(n_ground, 16);
  EXPECT_EQ(pts.size(), static_cast<std::size_t>(n_ground) * 1024u);
  for (const LidarPoint& q : pts) {
    EXPECT_EQ(q.cone, -1);
    EXPECT_LT(q.ring, n_ground);
    EXPECT_NEAR(to_world(q, base, p).z, 0.0, 1e-4);
    const double r = range_of(q);
    // asphalt 0.15 * cos(incidence) (= sin of the depression angle) * fall-off,
    // from independent numbers
    const double sin_dep = -q.z / r;
    const double expect_i = 0.15 * sin_dep * std::min(1.0, (5.0 / r) * (5.0 / r));
    EXPECT_NEAR(q.intensity, expect_i, 1e-4);
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

// (world height, noise-free intensity) of the points on a cone d ahead
std::vector<std::pair<double, double>> cone_profile(ConeColor color, double d, int cone_index = 0) {
  const LidarParams p = noiseless();
  LidarWorld world({Cone{{p.mount_x + d, 0.0}, color}});
  std::vector<std::pair<double, double>> zi;
  for (const LidarPoint& q : Lidar(p, 11).scan(world, at_rest(), 0)) {
    if (q.cone != cone_index) continue;
    zi.push_back({to_world(q, Pose2{}, p).z, q.intensity});
  }
  return zi;
}

// the least-squares fit I(z) = a z^2 + b z + c to (z, I) pairs: returns a
double quadratic_a(const std::vector<std::pair<double, double>>& zi) {
  // normal equations for [z^2 z 1], solved by Cramer's rule
  double s[5] = {0, 0, 0, 0, 0}, t[3] = {0, 0, 0};
  for (const auto& [z, i] : zi) {
    double zk = 1.0;
    for (int k = 0; k < 5; ++k) {
      s[k] += zk;
      if (k < 3) t[k] += zk * i;
      zk *= z;
    }
  }
  // M = [[s4 s3 s2] [s3 s2 s1] [s2 s1 s0]], rhs [t2 t1 t0]
  const auto det3 = [](double a, double b, double c, double d, double e, double f, double g,
                       double h, double i) {
    return a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g);
  };
  const double det = det3(s[4], s[3], s[2], s[3], s[2], s[1], s[2], s[1], s[0]);
  return det3(t[2], s[3], s[2], t[1], s[2], s[1], t[0], s[1], s[0]) / det;
}

TEST(LidarIntensity, BlueConePeaksAndYellowConeDipsInTheMiddle) {
  const auto blue = cone_profile(ConeColor::Blue, 4.0);
  const auto yellow = cone_profile(ConeColor::Yellow, 4.0);
  ASSERT_GE(blue.size(), 10u);
  ASSERT_GE(yellow.size(), 10u);
  const double a_blue = quadratic_a(blue), a_yellow = quadratic_a(yellow);
  std::printf("cone at 4 m: blue %zu points a = %.3f, yellow %zu points a = %.3f\n",
              blue.size(), a_blue, yellow.size(), a_yellow);
  EXPECT_LT(a_blue, 0.0);
  EXPECT_GT(a_yellow, 0.0);
  // the middle stripe (130 .. 195 mm of 325 mm) is white on blue, black on
  // yellow: compare the brightest point of each band (points at the silhouette
  // are dim whatever their material: grazing incidence)
  const auto band_max = [](const std::vector<std::pair<double, double>>& zi, bool middle) {
    double m = 0.0;
    for (const auto& [z, i] : zi) {
      const bool in_mid = z > 0.135 && z < 0.19, outside = z < 0.125 || z > 0.2;
      if (middle ? in_mid : outside) m = std::max(m, i);
    }
    return m;
  };
  EXPECT_GT(band_max(blue, true), 0.8);      // white 0.9
  EXPECT_LT(band_max(blue, false), 0.26);    // blue 0.25
  EXPECT_LT(band_max(yellow, true), 0.06);   // black 0.05
  EXPECT_GT(band_max(yellow, false), 0.5);   // yellow 0.6
}

TEST(LidarIntensity, MaterialsOfTheStripes) {
  EXPECT_EQ(cone_material(ConeColor::Blue, 0.2), LidarMaterial::Blue);
  EXPECT_EQ(cone_material(ConeColor::Blue, 0.5), LidarMaterial::White);
  EXPECT_EQ(cone_material(ConeColor::Yellow, 0.5), LidarMaterial::Black);
  EXPECT_EQ(cone_material(ConeColor::Yellow, 0.9), LidarMaterial::Yellow);
  EXPECT_EQ(cone_material(ConeColor::SmallOrange, 0.5), LidarMaterial::White);
  EXPECT_EQ(cone_material(ConeColor::SmallOrange, 0.1), LidarMaterial::Orange);
  EXPECT_EQ(cone_material(ConeColor::BigOrange, 0.35), LidarMaterial::White);
  EXPECT_EQ(cone_material(ConeColor::BigOrange, 0.5), LidarMaterial::Orange);
  EXPECT_EQ(cone_material(ConeColor::BigOrange, 0.65), LidarMaterial::White);
  EXPECT_EQ(cone_material(ConeColor::Unknown, 0.5), LidarMaterial::Grey);
}

TEST(LidarIntensity, FallsWithRangeAndIncidence) {
  // ground only: with the fall-off switched off (reference range far beyond
  // the range limit) the intensity is rho cos(incidence); the default divides
  // it by (r / 5 m)^2 past 5 m
  LidarParams flat = noiseless();
  flat.intensity_range_ref = 1e4;
  const LidarParams def = noiseless();
  LidarWorld world({});
  std::map<std::pair<std::int64_t, int>, double> no_falloff;
  for (const LidarPoint& q : Lidar(flat, 12).scan(world, at_rest(), 0)) {
    no_falloff[{q.t, q.ring}] = q.intensity;
  }
  // per ring (one range, one incidence) at column 512 (straight ahead)
  std::map<int, std::pair<double, double>> ring_ri;  // ring -> (range, intensity)
  int checked = 0;
  for (const LidarPoint& q : Lidar(def, 12).scan(world, at_rest(), 0)) {
    const double r = range_of(q);
    const double ratio = q.intensity / no_falloff.at({q.t, q.ring});
    EXPECT_NEAR(ratio, std::min(1.0, 25.0 / (r * r)), 1e-4) << r;
    ++checked;
    if (std::abs(q.y) < 1e-3 && q.x > 0.0) ring_ri[q.ring] = {r, q.intensity};
  }
  EXPECT_GT(checked, 1000);
  // nearer ground (steeper incidence, shorter range) is brighter: rings ascend
  // in elevation, so range grows and intensity falls with the ring
  ASSERT_EQ(ring_ri.size(), static_cast<std::size_t>(ground_channels(def)));
  for (auto it = std::next(ring_ri.begin()); it != ring_ri.end(); ++it) {
    const auto prev = std::prev(it);
    EXPECT_GT(it->second.first, prev->second.first);
    EXPECT_LT(it->second.second, prev->second.second);
  }
  std::printf("ground straight ahead: %.2f m -> I %.4f, %.2f m -> I %.5f\n",
              ring_ri.begin()->second.first, ring_ri.begin()->second.second,
              ring_ri.rbegin()->second.first, ring_ri.rbegin()->second.second);
}

TEST(LidarIntensity, NoiseHasTheConfiguredStd) {
  LidarParams exact = noiseless();
  exact.reflect_ground = 1.0;  // bright ground: far from the clamp at 0
  LidarParams noisy = exact;
  noisy.intensity_noise = 0.005;
  LidarWorld world({});
  std::map<std::pair<std::int64_t, int>, double> truth;
  for (const LidarPoint& q : Lidar(exact, 13).scan(world, at_rest(), 0)) {
    truth[{q.t, q.ring}] = q.intensity;
  }
  Lidar b(noisy, 13);
  double sum = 0.0, sum2 = 0.0;
  int n = 0;
  for (int rep = 0; rep < 4; ++rep) {
    for (const LidarPoint& q : b.scan(world, at_rest(), 0)) {
      const double t = truth.at({q.t, q.ring});
      if (t < 0.04) continue;  // 8 std from 0: the clamp never acts
      const double e = q.intensity - t;
      sum += e;
      sum2 += e * e;
      ++n;
    }
  }
  const double mean = sum / n, std = std::sqrt(sum2 / n - mean * mean);
  std::printf("intensity noise over %d points: mean %.6f, std %.6f\n", n, mean, std);
  EXPECT_GT(n, 10000);
  EXPECT_NEAR(std, 0.005, 0.05 * 0.005);
  EXPECT_NEAR(mean, 0.0, 0.0003);
}

TEST(LidarKnocked, KnockedConeLiesOnItsSide) {
  const LidarParams p = noiseless();
  const double cx = p.mount_x + 4.0;
  // cone 0 knocked, cone 1 (far to the side) standing
  LidarWorld world({Cone{{cx, 0.0}, ConeColor::Blue}, Cone{{cx, 3.0}, ConeColor::Blue}},
                   {true, false});
  int lying = 0, standing = 0;
  double top_lying = 0.0, top_standing = 0.0;
  for (const LidarPoint& q : Lidar(p, 14).scan(world, at_rest(), 0)) {
    if (q.cone < 0) continue;
    const P3 w = to_world(q, Pose2{}, p);
    if (q.cone == 0) {
      ++lying;
      top_lying = std::max(top_lying, w.z);
      EXPECT_LE(w.z, 0.228 + 1e-3);                 // its base width
      EXPECT_LE(std::abs(w.x - cx), 0.1625 + 1e-3);  // half its length along x
      EXPECT_LE(std::abs(w.y), 0.114 + 1e-3);
    } else {
      ++standing;
      top_standing = std::max(top_standing, w.z);
    }
  }
  std::printf("knocked cone: %d points up to %.3f m; standing: %d points up to %.3f m\n",
              lying, top_lying, standing, top_standing);
  EXPECT_GT(lying, 5);
  EXPECT_GT(standing, 5);
  EXPECT_LT(top_lying, 0.23);
  EXPECT_GT(top_standing, 0.25);  // the standing cone is seen above the lying height
  EXPECT_THROW(LidarWorld({Cone{{cx, 0.0}, ConeColor::Blue}}, {true, false}),
               std::invalid_argument);
}

TEST(LidarTest, InvalidParamsAreRejected) {
  LidarParams p;
  EXPECT_EQ(params::validate(p), "");
  p.channels = 0;
  EXPECT_THROW(Lidar(p, 1), std::invalid_argument);
  p = LidarParams{};
  p.range_max = p.range_min;
  EXPECT_NE(params::validate(p).find("range_max"), std::string::npos);
  p = LidarParams{};
  p.dropout = 1.0;
  EXPECT_NE(params::validate(p).find("dropout"), std::string::npos);
  p = LidarParams{};
  p.elevation_max = p.elevation_min;
  EXPECT_NE(params::validate(p).find("elevation_max"), std::string::npos);
  p = LidarParams{};
  p.rate = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(params::validate(p).find("rate"), std::string::npos);
  p = LidarParams{};
  p.reflect_blue = 1.5;
  EXPECT_NE(params::validate(p).find("reflect_"), std::string::npos);
  p = LidarParams{};
  p.intensity_noise = -0.1;
  EXPECT_NE(params::validate(p).find("intensity_noise"), std::string::npos);
  p = LidarParams{};
  p.intensity_range_ref = 0.0;
  EXPECT_NE(params::validate(p).find("intensity_range_ref"), std::string::npos);
}


// a point in the world frame over sloped or bumpy ground: the sensor stands
// mount_z above the ground under its mounting point
P3 to_world_on(const LidarPoint& q, const Pose2& base, const LidarParams& p,
               const LidarWorld& world) {
  P3 w = to_world(q, base, p);
  const Vec2 o = base.transform({p.mount_x, p.mount_y});
  w.z += world.ground_z(o.x, o.y);
  return w;
}

TEST(LidarGround, HeightFieldFormulaAndValidation) {
  GroundParams g;
  EXPECT_TRUE(flat(g));
  EXPECT_EQ(params::validate(g), "");
  EXPECT_DOUBLE_EQ(ground_height(g, 3.0, -7.0), 0.0);
  g.slope_x = 0.1;
  g.slope_y = -0.05;
  EXPECT_FALSE(flat(g));
  EXPECT_NEAR(ground_height(g, 3.0, 2.0), 0.3 - 0.1, 1e-12);
  g = GroundParams{};
  g.bump_height = 0.1;
  g.bump_wavelength = 8.0;
  EXPECT_NEAR(ground_height(g, 2.0, 2.0), 0.1, 1e-12);   // sin(pi/2)^2
  EXPECT_NEAR(ground_height(g, 2.0, -2.0), -0.1, 1e-12);
  EXPECT_NEAR(ground_height(g, 4.0, 1.0), 0.0, 1e-12);
  GroundParams bad;
  bad.cell = 0.0;
  EXPECT_EQ(params::validate(bad), "cell must be in [0.01, 100] m (got 0)");
  EXPECT_THROW(LidarWorld({}, {}, bad), std::invalid_argument);
  bad = GroundParams{};
  bad.bump_wavelength = -1.0;
  EXPECT_EQ(params::validate(bad), "bump_wavelength must be in [0.1, 1000] m (got -1)");
  bad = GroundParams{};
  bad.slope_x = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(params::validate(bad).rfind("slope_x must be in [-1, 1]", 0), 0u) << params::validate(bad);
  // flat: the two-triangle fast path
  LidarWorld flat_world({Cone{{5.0, 0.0}, ConeColor::Blue}});
  EXPECT_EQ(flat_world.ground_triangles(), 2u);
  EXPECT_EQ(flat_world.ground_cell(), 0.0);
}

TEST(LidarGround, GridIsBoundedInSize) {
  GroundParams g;
  g.slope_x = 0.05;
  // a 1 km x 1 km cone field: the cell grows so the grid stays bounded
  LidarWorld world({Cone{{0.0, 0.0}, ConeColor::Blue}, Cone{{1000.0, 1000.0}, ConeColor::Blue}},
                   {}, g);
  EXPECT_LE(world.ground_triangles(), 2u * 200000u);
  EXPECT_GT(world.ground_cell(), 0.5);
  LidarWorld small({Cone{{0.0, 0.0}, ConeColor::Blue}, Cone{{30.0, 20.0}, ConeColor::Blue}}, {},
                   g);
  EXPECT_DOUBLE_EQ(small.ground_cell(), 0.5);
  // (30 + 120) x (20 + 120) m at 0.5 m: 300 x 280 cells, 2 triangles each
  EXPECT_EQ(small.ground_triangles(), 2u * 300u * 280u);
}

TEST(LidarGround, SlopedGroundPointsLieOnThePlane) {
  const LidarParams p = noiseless();
  GroundParams g;
  g.slope_x = 0.1;
  const std::vector<Cone> cones = {Cone{{-20.0, -15.0}, ConeColor::Blue},
                                   Cone{{40.0, 15.0}, ConeColor::Yellow}};
  const auto t0 = std::chrono::steady_clock::now();
  LidarWorld world(cones, {}, g);
  const auto t1 = std::chrono::steady_clock::now();
  Lidar lidar(p, 21);
  const Pose2 base{1.0, 2.0, 0.4};
  const std::vector<LidarPoint> pts = lidar.scan(world, at_rest(base), 0);
  const auto t2 = std::chrono::steady_clock::now();
  std::printf("sloped world: %zu ground triangles, build %.1f ms, one scan %.1f ms (%zu points)\n",
              world.ground_triangles(),
              std::chrono::duration<double, std::milli>(t1 - t0).count(),
              std::chrono::duration<double, std::milli>(t2 - t1).count(), pts.size());
  int ground = 0;
  double worst = 0.0;
  for (const LidarPoint& q : pts) {
    if (q.cone != -1) continue;
    ++ground;
    const P3 w = to_world_on(q, base, p, world);
    worst = std::max(worst, std::abs(w.z - 0.1 * w.x));
  }
  std::printf("sloped ground: %d points, worst |z - 0.1 x| %.4f m\n", ground, worst);
  EXPECT_GT(ground, 16 * 1024 / 2);
  EXPECT_LT(worst, 0.01);
}

TEST(LidarGround, ConesStandOnTheSlopedGround) {
  // a dense fan of channels so the lowest ring on the cone lies near its base
  LidarParams p = noiseless();
  p.channels = 281;
  p.elevation_min = -2.0 * kPi / 180.0;
  p.elevation_max = 12.0 * kPi / 180.0;  // 0.05 deg: 9 mm at 10 m
  GroundParams g;
  g.slope_x = 0.1;
  const double cx = 12.0;
  // cone 0 standing ahead, uphill; cone 1 knocked, beside it
  LidarWorld world({Cone{{cx, 0.0}, ConeColor::Blue}, Cone{{cx, 2.0}, ConeColor::Yellow}},
                   {false, true}, g);
  const double gz = ground_height(g, cx, 0.0);  // 1.2 m
  double lo[2] = {1e9, 1e9}, hi[2] = {-1e9, -1e9};
  int n[2] = {0, 0};
  for (const LidarPoint& q : Lidar(p, 22).scan(world, at_rest(), 0)) {
    if (q.cone < 0) continue;
    const P3 w = to_world_on(q, Pose2{}, p, world);
    const auto k = static_cast<std::size_t>(q.cone);
    ++n[k];
    lo[k] = std::min(lo[k], w.z);
    hi[k] = std::max(hi[k], w.z);
  }
  std::printf("on the slope (ground %.3f m): standing %d points %.3f .. %.3f m, knocked %d "
              "points %.3f .. %.3f m\n",
              gz, n[0], lo[0], hi[0], n[1], lo[1], hi[1]);
  ASSERT_GT(n[0], 10);
  ASSERT_GT(n[1], 10);
  EXPECT_NEAR(lo[0], gz, 0.02);
  EXPECT_NEAR(hi[0], gz + 0.325, 0.02);
  EXPECT_NEAR(lo[1], gz, 0.02);
  EXPECT_LE(hi[1], gz + 0.228 + 1e-3);
  // the same cones on flat ground stand 1.2 m lower: the slope really lifts them
  EXPECT_GT(lo[0], 1.0);
}

TEST(LidarGround, BumpyGroundPointsLieOnTheHeightField) {
  const LidarParams p = noiseless();
  GroundParams g;
  g.bump_height = 0.1;
  g.bump_wavelength = 10.0;
  // the grid's error bound: bump_height (2 pi / L)^2 cell^2 / 4 = 2.5 mm
  const double bound = 0.1 * std::pow(2.0 * kPi / 10.0, 2) * 0.25 / 4.0;
  EXPECT_LT(bound, 0.003);
  LidarWorld world({Cone{{-20.0, -15.0}, ConeColor::Blue}, Cone{{40.0, 15.0}, ConeColor::Yellow}},
                   {}, g);
  EXPECT_DOUBLE_EQ(world.ground_cell(), 0.5);
  const Pose2 base{3.0, 1.0, -0.3};
  int ground = 0;
  double worst = 0.0;
  for (const LidarPoint& q : Lidar(p, 23).scan(world, at_rest(base), 0)) {
    if (q.cone != -1) continue;
    ++ground;
    const P3 w = to_world_on(q, base, p, world);
    worst = std::max(worst, std::abs(w.z - ground_height(g, w.x, w.y)));
  }
  std::printf("bumpy ground: %d points, worst |z - ground_height| %.4f m (bound %.4f m)\n",
              ground, worst, bound);
  EXPECT_GT(ground, 1000);
  EXPECT_LT(worst, 0.02);
  EXPECT_LT(worst, bound + 1e-3);  // float rounding on top of the interpolation
}

}  // namespace
}  // namespace paddock::sensors
