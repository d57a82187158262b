// the fault injector against brute force: a sector and a band of rings drop
// exactly the points in them, a window is on from `at` for `duration`, a
// stuck wheel repeats its first faulty reading, the CAN's loss share is what
// was asked (binomial bounds), and the summary's words name every fault
#include "sim/runner/faults.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace paddock::runner {
namespace {

std::vector<sensors::LidarPoint> ring_of_points() {
  std::vector<sensors::LidarPoint> pts;
  for (int ring = 0; ring < 32; ++ring) {
    for (int a = 0; a < 360; ++a) {
      const double az = (a + 0.5) * kPi / 180.0 - kPi;
      sensors::LidarPoint p{};
      p.x = static_cast<float>(10.0 * std::cos(az));
      p.y = static_cast<float>(10.0 * std::sin(az));
      p.ring = static_cast<std::uint16_t>(ring);
      pts.push_back(p);
    }
  }
  return pts;
}

// a straight 3 m wide track along +x, centreline every 0.5 m; cones every
// 5 m on both sides, blue left, yellow right
world::TrackModel straight_track() {
  world::TrackModel track;
  for (int i = 0; i <= 200; ++i) {
    track.centreline.push_back({0.5 * i, 0.0});
    track.width.push_back(3.0);
  }
  return track;
}
std::vector<Cone> straight_cones() {
  std::vector<Cone> cones;
  for (int i = 0; i < 20; ++i) {
    cones.push_back({{5.0 * i, 1.5}, ConeColor::Blue});
    cones.push_back({{5.0 * i, -1.5}, ConeColor::Yellow});
  }
  return cones;
}

TEST(Faults, AWindowIsOnFromAtForItsDuration) {
  FaultWindow w;
  EXPECT_FALSE(w.on(0.0));
  w.at = 2.0;
  w.duration = 0.5;
  EXPECT_FALSE(w.on(1.999));
  EXPECT_TRUE(w.on(2.0));
  EXPECT_TRUE(w.on(2.499));
  EXPECT_FALSE(w.on(2.5));
  w.duration = 0.0;
  EXPECT_TRUE(w.on(1e6));
}

TEST(Faults, ASectorOrABandOfRingsLosesExactlyItsPoints) {
  FaultsSection f;
  f.lidar.at = 1.0;
  f.lidar.mode = LidarDropout::Sector;
  f.lidar.sector_from = 3.0;  // across the +-pi seam: 3.0 .. -3.0 (0.28 rad)
  f.lidar.sector_to = -3.0;
  FaultInjector sector(f, 1);
  std::vector<sensors::LidarPoint> pts = ring_of_points();
  sector.filter_lidar(0.5, pts);
  EXPECT_EQ(pts.size(), 32u * 360u);  // not yet on
  sector.filter_lidar(1.5, pts);
  std::size_t expected = 0;
  for (const sensors::LidarPoint& p : ring_of_points()) {
    const double az = std::atan2(p.y, p.x);
    expected += std::abs(az) < 3.0 ? 1 : 0;
  }
  EXPECT_EQ(pts.size(), expected);
  EXPECT_EQ(32u * 360u - expected, 32u * 16u);  // 16 one-degree columns per ring in 0.283 rad
  f.lidar.mode = LidarDropout::Rings;
  f.lidar.ring_first = 4;
  f.lidar.ring_last = 11;
  FaultInjector rings(f, 1);
  pts = ring_of_points();
  rings.filter_lidar(1.5, pts);
  EXPECT_EQ(pts.size(), 24u * 360u);
  for (const sensors::LidarPoint& p : pts) EXPECT_TRUE(p.ring < 4 || p.ring > 11);
  EXPECT_TRUE(rings.lidar_sends(1.5));
  f.lidar.mode = LidarDropout::Rotations;
  EXPECT_FALSE(FaultInjector(f, 1).lidar_sends(1.5));
}

TEST(Faults, AStuckWheelRepeatsItsReadingAndTheOthersGoOn) {
  FaultsSection f;
  f.wheel.at = 1.0;
  f.wheel.duration = 1.0;
  f.wheel.wheel = 2;
  FaultInjector inj(f, 1);
  for (int k = 0; k < 300; ++k) {
    const double t = k * 0.01;
    hal::WheelSpeeds w{0, {t, t, t, t}};
    inj.apply(t, w);
    EXPECT_EQ(w.omega[0], t);
    EXPECT_EQ(w.omega[2], f.wheel.on(t) ? 1.0 : t) << t;
  }
}

TEST(Faults, TheCanLosesTheShareAskedAndNothingOutsideItsWindow) {
  FaultsSection f;
  f.can.at = 1.0;
  f.can.duration = 1.0;
  f.can.loss = 0.3;
  FaultInjector inj(f, 7);
  int lost = 0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) lost += inj.can_delivers(1.5) ? 0 : 1;
  // binomial: 6000 +- 4.5 sigma (sigma = 64.8)
  EXPECT_NEAR(lost, 0.3 * n, 4.5 * std::sqrt(n * 0.3 * 0.7));
  for (int i = 0; i < 1000; ++i) EXPECT_TRUE(inj.can_delivers(0.5) && inj.can_delivers(2.0));
}

TEST(Faults, TheImuStepAddsItsBiasAndTheNotesNameEveryFault) {
  FaultsSection f;
  f.imu.at = 3.0;
  f.imu.bias_ax = 0.3;
  f.imu.bias_yaw_rate = -0.01;
  FaultInjector inj(f, 1);
  hal::Imu m;
  inj.apply(2.0, m, 0.005);
  EXPECT_EQ(m.ax, 0.0);
  inj.apply(3.0, m, 0.005);
  EXPECT_EQ(m.ax, 0.3);
  EXPECT_EQ(m.yaw_rate, -0.01);
  f.res.at = 10.0;
  f.camera.at = 5.0;
  f.camera.mode = CameraFaultMode::Frozen;
  const std::vector<FaultNote> notes = fault_notes(f);
  ASSERT_EQ(notes.size(), 3u);
  EXPECT_EQ(notes[0].name, "imu");  // by time
  EXPECT_EQ(notes[1].name, "camera");
  EXPECT_EQ(notes[1].what, "camera frozen to the end");
  EXPECT_EQ(notes[2].name, "res");
  EXPECT_EQ(notes[2].at, 10.0);
}

TEST(Faults, TheObjectStandsBesideTheBoundaryAndTheColoursSwapOnTime) {
  const world::TrackModel track = straight_track();
  std::vector<Cone> cones = straight_cones();
  cones.push_back({{0.0, 3.0}, ConeColor::BigOrange});
  FaultsSection f;
  f.object.at = 2.0;
  f.object.kind = ObjectKind::Bag;
  f.object.along = 30.0;
  f.object.edge_offset = 0.5;
  f.object.left = false;
  f.cones.at = 1.0;
  f.cones.wrong_colour = 5;
  FaultInjector inj(f, 3);
  inj.place(track, cones);
  EXPECT_TRUE(inj.objects(1.9).empty());
  ASSERT_EQ(inj.objects(2.0).size(), 1u);
  const world::Block& b = inj.objects(2.0)[0];
  EXPECT_NEAR(b.centre.x, 30.0, 0.5);   // within one centreline step of 30 m
  EXPECT_NEAR(b.centre.y, -2.0, 1e-9);  // 1.5 m half width + 0.5 m, on the right
  int swapped = 0;
  for (int i = 0; i < static_cast<int>(cones.size()); ++i) {
    const ConeColor before = inj.colour(i, cones[static_cast<std::size_t>(i)].color, 0.5);
    const ConeColor after = inj.colour(i, cones[static_cast<std::size_t>(i)].color, 1.5);
    EXPECT_EQ(before, cones[static_cast<std::size_t>(i)].color);
    if (after != before) {
      ++swapped;
      EXPECT_EQ(after, before == ConeColor::Blue ? ConeColor::Yellow : ConeColor::Blue);
    }
  }
  EXPECT_EQ(swapped, 5);
  EXPECT_EQ(inj.colour(40, ConeColor::BigOrange, 1.5), ConeColor::BigOrange);
  // the rain: the returns lost in the asked share
  FaultsSection r;
  r.rain.at = 0.0;
  r.rain.returns_lost = 0.25;
  FaultInjector rain(r, 5);
  std::vector<sensors::LidarPoint> pts = ring_of_points();
  rain.filter_lidar(1.0, pts);
  const double n = 32.0 * 360.0;
  EXPECT_NEAR(static_cast<double>(pts.size()), 0.75 * n, 4.5 * std::sqrt(n * 0.25 * 0.75));
  EXPECT_EQ(rain.grip(1.0), r.rain.grip);
  EXPECT_EQ(FaultInjector(FaultsSection{}, 5).grip(1.0), 1.0);
}

TEST(Faults, TheGustMovesTheConesAroundItsPointOnceInItsDirection) {
  // the straight track along +x; the wind blows to the left of the heading
  const world::TrackModel track = straight_track();
  const std::vector<Cone> cones = straight_cones();
  FaultsSection f;
  f.wind.at = 4.0;
  f.wind.along = 40.0;
  f.wind.radius = 6.0;
  f.wind.direction = kPi / 2.0;
  f.wind.slide = 0.4;
  f.wind.topple = 0.5;
  FaultInjector inj(f, 7);
  inj.place(track, cones);
  EXPECT_TRUE(inj.gust_due(3.999).empty());
  const std::vector<FaultInjector::Gust> g = inj.gust_due(4.0);
  EXPECT_TRUE(inj.gust_due(4.5).empty()) << "once";
  // brute force: the cones within 6 m of (40, 0) are those at x = 35, 40, 45
  std::vector<int> want;
  for (int i = 0; i < static_cast<int>(cones.size()); ++i)
    if (std::hypot(cones[static_cast<std::size_t>(i)].position.x - 40.0, cones[static_cast<std::size_t>(i)].position.y) <= 6.0) want.push_back(i);
  ASSERT_EQ(want.size(), 6u);
  std::vector<int> got;
  for (const FaultInjector::Gust& k : g) {
    got.push_back(k.cone);
    EXPECT_GE(norm(k.shift), 0.2 - 1e-12);
    EXPECT_LE(norm(k.shift), 0.6 + 1e-12);
    EXPECT_NEAR(std::atan2(k.shift.y, k.shift.x), kPi / 2.0, 0.2 + 1e-12);
  }
  EXPECT_EQ(got, want);
  const auto toppled = std::count_if(g.begin(), g.end(), [](const FaultInjector::Gust& k) { return k.topple; });
  EXPECT_EQ(inj.gust_words(), "6 cones moved, " + std::to_string(toppled) + " of them toppled");
  // the same seed draws the same gust
  FaultInjector again(f, 7);
  again.place(track, cones);
  const std::vector<FaultInjector::Gust> h = again.gust_due(5.0);
  ASSERT_EQ(h.size(), g.size());
  for (std::size_t i = 0; i < g.size(); ++i) {
    EXPECT_EQ(h[i].shift.x, g[i].shift.x);
    EXPECT_EQ(h[i].topple, g[i].topple);
  }
  const std::vector<FaultNote> notes = fault_notes(f);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_EQ(notes[0].name, "wind");
  EXPECT_EQ(notes[0].at, 4.0);
}

}  // namespace
}  // namespace paddock::runner
