// the LiDAR's fast cast (LidarCast::Exploit: over flat ground the ground in
// closed form for the beams outside the cones' windows, the window beams
// through Embree; over a height field every beam through the whole scene)
// against the plain one (LidarCast::Single: every beam through the whole
// Embree scene with rtcIntersect1) and the packets before
// (LidarCast::Packets), point by point: the same beams return (same ring,
// column time and object: the ground or the same cone) with the same noise
// draws, and every point agrees to float rounding. On flat ground the closed
// form is Embree's own arithmetic: the scans agree to the bit.
//
// The scenes: two lines of cones along a curve with big orange ones, a
// scattered field with knocked cones, a cone against the sensor and cones at
// the range limit, on flat, sloped, bumpy and sloped-bumpy ground, with a
// car that drives and turns through the rotation (the windows must follow
// it), a pitched sensor, noise and dropout; and the same with the venue's
// barrier blocks (rows along the curve, tents, a block across the range
// limit, one against the sensor).
#include "sim/sensors/lidar.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <functional>
#include <ostream>
#include <string>
#include <vector>

namespace paddock::sensors {
namespace {

struct Scene {
  std::vector<Cone> cones;
  std::vector<bool> knocked;
  std::vector<world::Block> blocks;
};

// a splitmix64 stream in [0, 1)
double uniform01(std::uint64_t& state) {
  std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  z ^= z >> 31;
  return static_cast<double>(z >> 11) * 0x1.0p-53;
}

// the car starts at the origin looking along +x (the sensor 2.2 m ahead)
Scene make_scene(bool blocks) {
  Scene s;
  const auto add = [&s](Vec2 p, ConeColor c, bool down) {
    s.cones.push_back({p, c});
    s.knocked.push_back(down);
  };
  // a left-hand curve of radius 40 m, cones 1.5 m either side, every 3 m;
  // every fifth a big orange one, every seventh knocked
  for (int i = 0; i < 40; ++i) {
    const double a = 3.0 * i / 40.0;  // rad along the curve
    const Vec2 centre{40.0 * std::sin(a), 40.0 - 40.0 * std::cos(a)};
    const Vec2 n{-std::sin(a), std::cos(a)};
    const bool big = i % 5 == 0, down = i % 7 == 3;
    add(centre + 1.5 * n, big ? ConeColor::BigOrange : ConeColor::Blue, down);
    add(centre - 1.5 * n, big ? ConeColor::BigOrange : ConeColor::Yellow, i % 7 == 5);
  }
  // a scattered field all round, a quarter knocked
  std::uint64_t state = 2024;
  for (int i = 0; i < 120; ++i) {
    const double r = 1.0 + 55.0 * uniform01(state), a = 2.0 * kPi * uniform01(state);
    const ConeColor colors[] = {ConeColor::Blue, ConeColor::Yellow, ConeColor::SmallOrange,
                                ConeColor::BigOrange, ConeColor::Unknown};
    add({2.2 + r * std::cos(a), r * std::sin(a)}, colors[i % 5], uniform01(state) < 0.25);
  }
  // one just ahead of the sensor (inside the blind zone), one knocked just
  // ahead, and a ring of cones about the range limit (50 m + tfar's margin)
  add({2.6, 0.05}, ConeColor::Blue, false);
  add({3.0, -0.6}, ConeColor::Yellow, true);
  for (int i = 0; i < 24; ++i) {
    const double a = 2.0 * kPi * i / 24.0, r = 49.8 + 0.05 * (i % 8);
    add({2.2 + r * std::cos(a), r * std::sin(a)}, ConeColor::BigOrange, i % 3 == 0);
  }
  if (!blocks) return s;
  // rows of 2 m barrier blocks 5 m either side of the curve, a gap every tenth
  for (int i = 0; i < 60; ++i) {
    if (i % 10 == 9) continue;
    const double a = (2.0 * i + 1.0) / 40.0, side = i % 2 == 0 ? 5.0 : -5.0;
    const Vec2 centre{40.0 * std::sin(a), 40.0 - 40.0 * std::cos(a)};
    const Vec2 n{-std::sin(a), std::cos(a)};
    s.blocks.push_back({centre + side * n, a, 1.95, 0.6, 1.0});
  }
  // tents and odd boxes around, one reaching over the sensor's height, one
  // across the range limit, one just beside the sensor
  s.blocks.push_back({{-12.0, 9.0}, 0.3, 3.0, 3.0, 2.5});
  s.blocks.push_back({{10.0, -20.0}, -0.7, 6.0, 4.0, 3.0});
  s.blocks.push_back({{2.2 + 50.0, 1.0}, 1.2, 2.0, 0.6, 1.0});
  s.blocks.push_back({{2.2, 1.2}, 0.0, 1.0, 0.4, 0.8});
  return s;
}

GroundParams ground(const std::string& kind) {
  GroundParams g;
  if (kind == "sloped" || kind == "sloped_bumpy") {
    g.slope_x = 0.04;
    g.slope_y = -0.03;
  }
  if (kind == "bumpy" || kind == "sloped_bumpy") {
    g.bump_height = 0.08;
    g.bump_wavelength = 12.0;
  }
  return g;
}

// driving at 15 m/s and turning at 1.5 rad/s through the rotation, or at rest
std::function<Pose2(TimeNs)> trajectory(bool moving) {
  if (!moving) return [](TimeNs) { return Pose2{0.0, 0.0, 0.0}; };
  return [](TimeNs t) {
    const double s = to_seconds(t), w = 1.5, v = 15.0;
    const double yaw = 0.2 + w * s;
    return Pose2{v / w * (std::sin(yaw) - std::sin(0.2)), -v / w * (std::cos(yaw) - std::cos(0.2)),
                 yaw};
  };
}

struct Compared {
  std::size_t points = 0, cone_points = 0, identical = 0;
  double worst_range = 0.0;      // relative
  double worst_intensity = 0.0;  // absolute
};

// a against ref point by point: same ring, time and object, ranges within
// rel (relative), positions within rel of the range, intensities within tol
Compared compare(const std::vector<LidarPoint>& a, const std::vector<LidarPoint>& ref, double rel,
                 double tol, const std::string& what) {
  Compared r;
  EXPECT_EQ(a.size(), ref.size()) << what;
  if (a.size() != ref.size()) return r;
  int bad = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const LidarPoint& p = a[i];
    const LidarPoint& q = ref[i];
    ++r.points;
    if (q.cone >= 0) ++r.cone_points;
    if (std::memcmp(&p, &q, sizeof p) == 0 ||
        (p.x == q.x && p.y == q.y && p.z == q.z && p.intensity == q.intensity && p.ring == q.ring &&
         p.t == q.t && p.cone == q.cone)) {
      ++r.identical;
      continue;
    }
    const double range = std::sqrt(double(q.x) * q.x + double(q.y) * q.y + double(q.z) * q.z);
    const double ex = double(p.x) - q.x, ey = double(p.y) - q.y, ez = double(p.z) - q.z;
    const double d = std::sqrt(ex * ex + ey * ey + ez * ez);
    r.worst_range = std::max(r.worst_range, d / range);
    r.worst_intensity = std::max(r.worst_intensity, std::abs(double(p.intensity) - q.intensity));
    const bool ok = p.ring == q.ring && p.t == q.t && p.cone == q.cone && d <= rel * range &&
                    std::abs(double(p.intensity) - q.intensity) <= tol;
    if (!ok && ++bad <= 5) {
      ADD_FAILURE() << what << ": point " << i << " ring " << p.ring << "/" << q.ring << " t "
                    << p.t << "/" << q.t << " cone " << p.cone << "/" << q.cone << " range "
                    << range << " off by " << d << " intensity " << p.intensity << "/"
                    << q.intensity;
    }
  }
  EXPECT_EQ(bad, 0) << what;
  return r;
}

struct Case {
  std::string ground;
  bool moving;
  double pitch;  // rad
  bool noise;
  bool blocks = false;
  // a clockwise head (an Ouster's) with an uneven fan of beams, denser at
  // the horizon, reporting ranges in mm and intensities in 16-bit steps
  bool ouster = false;
};

// the uneven fan: -15 .. +15 deg, the spacing growing away from the horizon
void ouster_layout(LidarParams& p) {
  p.clockwise = true;
  p.beam_elevation.clear();
  for (int i = 0; i < p.channels; ++i) {
    const double u = -1.0 + 2.0 * i / (p.channels - 1.0);  // [-1, 1]
    p.beam_elevation.push_back(15.0 * kPi / 180.0 * u * std::abs(u) * 0.7 + 15.0 * kPi / 180.0 * u * 0.3);
  }
  p.elevation_min = p.beam_elevation.front();
  p.elevation_max = p.beam_elevation.back();
  p.range_resolution = 0.001;
  p.intensity_full_scale = 65535.0;
}

void PrintTo(const Case& k, std::ostream* os) {
  *os << k.ground << (k.moving ? " moving" : " still") << " pitch " << k.pitch
      << (k.noise ? " noisy" : "") << (k.blocks ? " blocks" : "") << (k.ouster ? " ouster" : "");
}

class LidarCastSame : public ::testing::TestWithParam<Case> {};

TEST_P(LidarCastSame, ExploitMatchesTheWholeScenePointByPoint) {
  const Case k = GetParam();
  const Scene s = make_scene(k.blocks);
  LidarWorld world(s.cones, s.knocked, ground(k.ground), s.blocks);
  EXPECT_EQ(world.block_count(), s.blocks.size());
  LidarParams p;
  p.mount_pitch = k.pitch;
  if (k.noise) {
    p.dropout = 0.05;  // draws from the sensor's own stream, before the noise
  } else {
    p.range_noise = 0.0;
    p.intensity_noise = 0.0;
  }
  if (k.ouster) ouster_layout(p);
  const auto traj = trajectory(k.moving);
  const std::string what = k.ground + (k.moving ? " moving" : " at rest") +
                           (k.pitch != 0.0 ? " pitched" : "") + (k.noise ? " noisy" : "") +
                           (k.blocks ? " blocks" : "") + (k.ouster ? " ouster" : "");
  const TimeNs start = from_seconds(0.3);
  // three scans in a row from each sensor: the streams must stay in step
  Lidar fast(p, 77), single(p, 77), packets(p, 77);
  Compared single_cmp, packets_cmp;
  std::size_t window = 0, block_points = 0;
  // the packets' scans into one buffer, as the runner casts every rotation
  // (what a scan leaves there must not reach the next): garbage at first
  std::vector<LidarPoint> c(7, LidarPoint{1.0f, 2.0f, 3.0f, 0.5f, 9, 9, 99, 3});
  for (int scan = 0; scan < 3; ++scan) {
    const TimeNs t0 = start + scan * fast.period_ns();
    const auto a = fast.scan(world, traj, t0, LidarCast::Exploit);
    window += fast.window_beams();
    const auto b = single.scan(world, traj, t0, LidarCast::Single);
    packets.scan(world, traj, t0, c, LidarCast::Packets);
    for (const LidarPoint& q : b) block_points += q.cone == kHitStructure;
    // within a few float ulps of the range; the intensity follows the range
    // (through 1/r^2 and the stripe at the hit's height) and the facet
    const Compared x = compare(a, b, 1e-5, 1e-5, what + " vs single");
    const Compared y = compare(a, c, 1e-5, 1e-5, what + " vs packets");
    single_cmp.points += x.points;
    single_cmp.cone_points += x.cone_points;
    single_cmp.identical += x.identical;
    single_cmp.worst_range = std::max(single_cmp.worst_range, x.worst_range);
    packets_cmp.points += y.points;
    packets_cmp.identical += y.identical;
    packets_cmp.worst_range = std::max(packets_cmp.worst_range, y.worst_range);
  }
  std::printf("%s: %zu beams in windows, %zu points (%zu on cones); vs single: %zu identical, "
              "worst range off %.2e; vs packets: %zu identical, worst %.2e\n",
              what.c_str(), window, single_cmp.points, single_cmp.cone_points, single_cmp.identical,
              single_cmp.worst_range, packets_cmp.identical, packets_cmp.worst_range);
  EXPECT_GT(single_cmp.points, 3u * 10000u);
  EXPECT_GT(single_cmp.cone_points, 3u * 300u);
  if (k.blocks) {
    EXPECT_GT(block_points, 3u * 1000u);
  } else {
    EXPECT_EQ(block_points, 0u);
  }
  EXPECT_EQ(world.ground_closed_form(), flat(world.ground()));
  if (flat(world.ground())) {
    EXPECT_GT(window, 3u * 300u);
    // the windows are the cones' (and blocks'), not the whole scan
    EXPECT_LT(window, 3u * 32u * 1024u / (k.blocks ? 1u : 2u));
    // the closed form is Embree's own arithmetic: the same scan to the bit
    EXPECT_EQ(packets_cmp.identical, packets_cmp.points) << what;
  } else {
    EXPECT_EQ(window, 0u);
  }
}

INSTANTIATE_TEST_SUITE_P(
    Grounds, LidarCastSame,
    ::testing::Values(Case{"flat", false, 0.0, false}, Case{"flat", true, 0.0, true},
                      Case{"flat", true, 0.06, true}, Case{"sloped", true, 0.0, true},
                      Case{"bumpy", true, 0.0, true}, Case{"sloped_bumpy", false, 0.0, false},
                      Case{"sloped_bumpy", true, -0.04, true}, Case{"flat", false, 0.0, false, true},
                      Case{"flat", true, 0.06, true, true}, Case{"sloped_bumpy", true, 0.0, true, true},
                      Case{"flat", true, 0.0, true, false, true}, Case{"flat", true, 0.06, true, true, true},
                      Case{"sloped", true, 0.0, true, false, true}),
    [](const ::testing::TestParamInfo<Case>& i) {
      return i.param.ground + (i.param.moving ? "_moving" : "_still") +
             (i.param.pitch != 0.0 ? "_pitched" : "") + (i.param.noise ? "_noisy" : "") +
             (i.param.blocks ? "_blocks" : "") + (i.param.ouster ? "_ouster" : "");
    });

// a clockwise head with the layout's own beams: each point lies on its beam
// (column c at pi - 2 pi c / columns, ring j at beam_elevation[j]), is fired at
// its column's time, reports its range in whole mm and its intensity in
// 16-bit steps; and a head standing still sees the mirror image of what the
// counter-clockwise head sees in the mirrored world, column by column (column
// c of one looks at the mirror image of column c's azimuth of the other)
TEST(LidarSpin, ClockwiseHeadFiresItsColumnsClockwise) {
  const Scene s = make_scene(false);
  Scene mirror = s;
  for (Cone& c : mirror.cones) c.position.y = -c.position.y;
  LidarWorld world(s.cones, s.knocked, ground("flat"));
  LidarWorld mirrored(mirror.cones, mirror.knocked, ground("flat"));
  LidarParams p;
  p.range_noise = 0.0;
  p.intensity_noise = 0.0;
  LidarParams cw = p;
  cw.clockwise = true;
  const auto still = trajectory(false);
  const TimeNs start = from_seconds(0.3);
  Lidar ccw_lidar(p, 5), cw_lidar(cw, 5);
  const auto a = cw_lidar.scan(world, still, start);
  const auto b = ccw_lidar.scan(mirrored, still, start);
  ASSERT_GT(a.size(), 10000u);
  // on its beam, at its column's time
  double worst = 0.0;
  for (const LidarPoint& q : a) {
    const double az = kPi - 2.0 * kPi * q.column / cw.columns;
    const double el = cw.elevation_min + (cw.elevation_max - cw.elevation_min) * q.ring / (cw.channels - 1);
    const double r = std::sqrt(double(q.x) * q.x + double(q.y) * q.y + double(q.z) * q.z);
    worst = std::max({worst, std::abs(q.x - r * std::cos(el) * std::cos(az)),
                      std::abs(q.y - r * std::cos(el) * std::sin(az)), std::abs(q.z - r * std::sin(el))});
    EXPECT_EQ(q.t, cw_lidar.column_time(start, q.column));
  }
  EXPECT_LT(worst, 1e-4);
  // the mirror image, column by column
  std::vector<std::vector<LidarPoint>> by_column(static_cast<std::size_t>(cw.columns));
  for (const LidarPoint& q : b) by_column[q.column].push_back(q);
  std::size_t matched = 0;
  for (const LidarPoint& q : a) {
    const auto& other = by_column[q.column];
    for (const LidarPoint& o : other) {
      if (o.ring != q.ring) continue;
      EXPECT_NEAR(q.x, o.x, 1e-4);
      EXPECT_NEAR(q.y, -o.y, 1e-4);
      EXPECT_NEAR(q.z, o.z, 1e-4);
      ++matched;
    }
  }
  EXPECT_GT(matched, a.size() * 99 / 100);
  EXPECT_LE(matched, a.size());
  // the sensor's units
  LidarParams units = cw;
  ouster_layout(units);
  units.range_noise = 0.02;
  units.intensity_noise = 0.01;
  Lidar unit_lidar(units, 5);
  const auto c = unit_lidar.scan(world, trajectory(true), start);
  ASSERT_GT(c.size(), 10000u);
  for (const LidarPoint& q : c) {
    const double r = std::sqrt(double(q.x) * q.x + double(q.y) * q.y + double(q.z) * q.z);
    // (to float rounding of the coordinates: 0.006 mm at 50 m)
    ASSERT_NEAR(r * 1000.0, std::round(r * 1000.0), 0.02) << "a range in whole mm";
    ASSERT_NEAR(q.intensity * 65535.0, std::round(q.intensity * 65535.0), 1e-2) << "a 16-bit intensity";
    ASSERT_NEAR(std::asin(q.z / r), units.beam_elevation[q.ring], 1e-5);
  }
}

}  // namespace
}  // namespace paddock::sensors

namespace paddock::sensors {
namespace {

// a head spinning either way on a car that drives and turns: every point on
// a standing cone, carried into the world from the pose at its own time, lies
// on that cone (within its base radius of its axis, between the ground and
// its top)
TEST(LidarSpin, AMovingHeadsPointsLieOnWhatTheyHitEitherWay) {
  const Scene s = make_scene(false);
  LidarWorld world(s.cones, s.knocked, ground("flat"));
  const auto traj = trajectory(true);
  for (const bool cw : {false, true}) {
    LidarParams p;
    p.range_noise = 0.0;
    p.intensity_noise = 0.0;
    p.clockwise = cw;
    Lidar lidar(p, 3);
    const auto pts = lidar.scan(world, traj, from_seconds(0.3));
    std::size_t on = 0;
    double worst = 0.0;
    for (const LidarPoint& q : pts) {
      if (q.cone < 0 || s.knocked[static_cast<std::size_t>(q.cone)]) continue;
      const Pose2 b = traj(q.t);
      const Vec2 w = b.transform({p.mount_x + q.x, p.mount_y + q.y});
      const Cone& c = s.cones[static_cast<std::size_t>(q.cone)];
      const double base = c.color == ConeColor::BigOrange ? kBigConeBaseWidth / 2 : kSmallConeBaseWidth / 2;
      worst = std::max(worst, distance(w, c.position) - base);
      ++on;
    }
    EXPECT_GT(on, 500u) << (cw ? "clockwise" : "counter-clockwise");
    EXPECT_LT(worst, 2e-3) << (cw ? "clockwise" : "counter-clockwise");
  }
}

}  // namespace
}  // namespace paddock::sensors
