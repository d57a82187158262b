// the stack's watch over its inputs: the LiDAR lost and back (degraded, then
// full speed), gone for good (a fault), sparse scans; the camera lost or
// frozen; the odometry silent; a late control cycle. Each noticed within its
// limit and not before, each mode left with a reason.
#include "autonomy/stack/health.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace paddock::stack {
namespace {

constexpr TimeNs kMs = 1'000'000;

bool noted(const Health& h, const std::string& what) {
  for (const HealthEvent& e : h.events())
    if (e.what.find(what) != std::string::npos) return true;
  return false;
}

// 10 Hz scans of n points and 100 Hz cycles from `from` to `to` (ms)
void drive(Health& h, TimeNs from, TimeNs to, std::size_t points, double speed = 10.0, bool scans = true) {
  for (TimeNs t = from; t < to; t += 10 * kMs) {
    if (scans && t % (100 * kMs) == 0) h.lidar_scan(t, points);
    h.imu(t);
    h.wheels(t);
    h.cycle(t, speed);
  }
}

TEST(Health, ALostLidarIsNoticedWithinTwoTenthsThenDegradedUntilBack) {
  Health h(HealthParams{}, true, false, true);
  drive(h, 0, 2000 * kMs, 10000);
  EXPECT_FALSE(h.lidar_degraded());
  EXPECT_TRUE(std::isinf(h.speed_cap(2000 * kMs)));
  // the last scan at 1.9 s; the next (2.0 s) never comes
  drive(h, 2000 * kMs, 2060 * kMs, 10000, 10.0, false);
  EXPECT_FALSE(h.lidar_degraded()) << "0.15 s of silence is not yet lost";
  drive(h, 2060 * kMs, 2070 * kMs, 10000, 10.0, false);
  EXPECT_TRUE(h.lidar_degraded());
  ASSERT_FALSE(h.events().empty());
  EXPECT_EQ(h.events().back().t, 2060 * kMs);  // 0.06 s after the missing scan was due
  EXPECT_TRUE(noted(h, "LiDAR lost"));
  // the cap ramps down from 10 m/s at 4 m/s^2 to 5 m/s
  EXPECT_NEAR(h.speed_cap(2560 * kMs), 8.0, 1e-9);
  EXPECT_NEAR(h.speed_cap(4000 * kMs), 5.0, 1e-9);
  EXPECT_TRUE(h.fault().empty());
  drive(h, 2070 * kMs, 2400 * kMs, 10000, 10.0, false);
  // back at 2.4 s: full speed again after 0.5 s of healthy scans
  drive(h, 2400 * kMs, 2890 * kMs, 10000);
  EXPECT_TRUE(h.lidar_degraded());
  drive(h, 2890 * kMs, 3000 * kMs, 10000);
  EXPECT_FALSE(h.lidar_degraded());
  EXPECT_TRUE(noted(h, "recovered: LiDAR healthy"));
  EXPECT_TRUE(h.fault().empty());
}

TEST(Health, ALidarGoneForASecondIsAFault) {
  Health h(HealthParams{}, true, false, true);
  drive(h, 0, 1000 * kMs, 10000);
  drive(h, 1000 * kMs, 1910 * kMs, 10000, 10.0, false);
  EXPECT_TRUE(h.fault().empty());  // silent 1.0 s at 1.9 s: the limit, not past it
  drive(h, 1910 * kMs, 1920 * kMs, 10000, 10.0, false);
  EXPECT_NE(h.fault().find("no LiDAR scan for 1.010 s"), std::string::npos) << h.fault();
}

TEST(Health, SparseScansDegradeAndTheirEndRecovers) {
  Health h(HealthParams{}, true, false, true);
  drive(h, 0, 1000 * kMs, 10000);
  drive(h, 1000 * kMs, 1100 * kMs, 5200);  // just over half: healthy
  EXPECT_FALSE(h.lidar_degraded());
  drive(h, 1100 * kMs, 1200 * kMs, 4000);  // under half (of the usual, which the 5200 lowered a little)
  EXPECT_TRUE(h.lidar_degraded());
  EXPECT_TRUE(noted(h, "LiDAR scans sparse"));
  drive(h, 1200 * kMs, 1800 * kMs, 10000);
  EXPECT_FALSE(h.lidar_degraded());
}

TEST(Health, ACameraLostOrFrozenIsDistrustedAndTrustedAgain) {
  HealthParams p;
  Health lost(p, true, true, false);
  hal::CameraDetections d;
  d.boxes = {{10, 10, 20, 40, ConeColor::Blue, 0.9}};
  for (TimeNs t = 0; t < 1000 * kMs; t += 100 * kMs) {
    d.boxes[0].x_min = 10.0 + 0.01 * static_cast<double>(t / kMs);  // moving: the boxes change
    lost.camera(t, d, 5.0);
    lost.cycle(t, 5.0);
  }
  EXPECT_FALSE(lost.camera_distrusted());
  lost.cycle(1250 * kMs, 5.0);  // last frame at 0.9 s: 0.35 s silent
  EXPECT_FALSE(lost.camera_distrusted());
  lost.cycle(1260 * kMs, 5.0);
  EXPECT_TRUE(lost.camera_distrusted());
  EXPECT_TRUE(noted(lost, "camera lost"));

  Health frozen(p, true, true, false);
  for (TimeNs t = 0; t < 300 * kMs; t += 100 * kMs) {
    frozen.camera(t, d, 5.0);  // the same boxes three frames running, at 5 m/s
    frozen.cycle(t, 5.0);
  }
  EXPECT_TRUE(frozen.camera_distrusted());
  EXPECT_TRUE(noted(frozen, "camera frozen"));
  // at rest the same boxes are no sign of a frozen camera
  Health parked(p, true, true, false);
  for (TimeNs t = 0; t < 1000 * kMs; t += 100 * kMs) {
    parked.camera(t, d, 0.0);
    parked.cycle(t, 0.0);
  }
  EXPECT_FALSE(parked.camera_distrusted());
  // moving boxes again: trusted after recover_time
  for (TimeNs t = 300 * kMs; t < 900 * kMs; t += 100 * kMs) {
    d.boxes[0].x_min += 1.0;
    frozen.camera(t, d, 5.0);
    frozen.cycle(t, 5.0);
  }
  EXPECT_FALSE(frozen.camera_distrusted());
  EXPECT_TRUE(noted(frozen, "recovered: camera"));
}

TEST(Health, AnInconsistentMapSlowsTheCarUntilTheFramesFitAgain) {
  Health h(HealthParams{}, false, false, true);
  drive(h, 0, 1000 * kMs, 0, 12.0, false);
  h.map_fit(1);  // one frame lost: not yet
  drive(h, 1000 * kMs, 1100 * kMs, 0, 12.0, false);
  EXPECT_FALSE(h.map_degraded());
  h.map_fit(2);
  drive(h, 1100 * kMs, 1110 * kMs, 0, 12.0, false);
  EXPECT_TRUE(h.map_degraded());
  EXPECT_TRUE(noted(h, "map inconsistent (SLAM lost 2 frames in a row)"));
  EXPECT_NEAR(h.speed_cap(1600 * kMs), 10.0, 1e-9);  // from 12 m/s at 4 m/s^2
  h.map_fit(0);
  drive(h, 1110 * kMs, 1600 * kMs, 0, 12.0, false);
  EXPECT_TRUE(h.map_degraded());
  drive(h, 1600 * kMs, 1700 * kMs, 0, 12.0, false);
  EXPECT_FALSE(h.map_degraded());
  EXPECT_TRUE(noted(h, "recovered: map healthy"));
  EXPECT_TRUE(h.fault().empty());
}

TEST(Health, SilentOdometryAndALateCycleAreFaults) {
  Health imu(HealthParams{}, false, false, true);
  for (TimeNs t = 0; t <= 500 * kMs; t += 10 * kMs) {
    if (t <= 300 * kMs) imu.imu(t);
    imu.wheels(t);
    imu.cycle(t, 5.0);
  }
  EXPECT_NE(imu.fault().find("no IMU sample for 0.110 s"), std::string::npos) << imu.fault();
  // with the truth handed in, the odometry is not watched
  Health truth(HealthParams{}, false, false, false);
  truth.imu(0);
  truth.cycle(0, 5.0);
  truth.cycle(1000 * kMs, 5.0);
  EXPECT_NE(truth.fault().find("stack cycle overrun"), std::string::npos) << truth.fault();
  Health steady(HealthParams{}, false, false, false);
  steady.imu(0);
  for (TimeNs t = 0; t <= 1000 * kMs; t += 100 * kMs) steady.cycle(t, 5.0);  // 0.1 s: the limit itself
  EXPECT_TRUE(steady.fault().empty()) << steady.fault();
}

}  // namespace
}  // namespace paddock::stack
