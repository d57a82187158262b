// the simulated VCU and EBS: the ACU's command passes through; the EBS fires
// on the RES, on AS Emergency and on a silent ACU (only once it was Ready or
// Driving), cuts the drive at once and closes the brakes after its delay;
// the status frame reports the brake lines as actuated
#include "sim/vehicle/vcu.h"

#include <gtest/gtest.h>

namespace paddock::vehicle {
namespace {

constexpr TimeNs kMs = 1'000'000;

hal::ActuatorCommand cmd(TimeNs t, hal::AsState as, double throttle, double brake, double steer = 0.1) {
  hal::ActuatorCommand c;
  c.stamp = t;
  c.as_state = as;
  c.throttle = throttle;
  c.brake = brake;
  c.steering_angle = steer;
  c.yaw_moment = 50.0;
  return c;
}

TEST(Vcu, PassesTheCommandAndReportsTheLines) {
  VcuParams p;
  Vcu v(p, hal::MissionCode::Trackdrive);
  const DriverInput rest = v.actuate(0);
  EXPECT_EQ(rest.brake, 1.0);  // braked before any command
  v.command(10 * kMs, cmd(10 * kMs, hal::AsState::Driving, 0.7, 0.2));
  const DriverInput in = v.actuate(10 * kMs);
  EXPECT_EQ(in.throttle, 0.7);
  EXPECT_EQ(in.brake, 0.2);
  EXPECT_EQ(in.steering_angle, 0.1);
  EXPECT_EQ(in.yaw_moment, 50.0);
  const hal::VcuStatus s = v.status(10 * kMs);
  EXPECT_TRUE(s.asms_on);
  EXPECT_EQ(s.mission, hal::MissionCode::Trackdrive);
  EXPECT_EQ(s.ebs_pressure, p.ebs_pressure);
  EXPECT_DOUBLE_EQ(s.brake_pressure_front, 0.2 * p.brake_pressure_max);
  EXPECT_FALSE(v.ebs_fired());
}

TEST(Vcu, TheResCutsTheDriveAtOnceAndBrakesAfterTheDelay) {
  VcuParams p;
  p.ebs_delay = 0.15;
  Vcu v(p, hal::MissionCode::Autocross);
  v.command(0, cmd(0, hal::AsState::Driving, 0.8, 0.0));
  v.res_emergency(5 * kMs);
  ASSERT_TRUE(v.ebs_fired());
  EXPECT_EQ(*v.ebs_fired(), 5 * kMs);
  EXPECT_EQ(v.ebs_cause(), "RES emergency stop");
  // the ACU, unaware, still asks for drive: cut; the brakes still its
  DriverInput in = v.actuate(5 * kMs);
  EXPECT_EQ(in.throttle, 0.0);
  EXPECT_EQ(in.yaw_moment, 0.0);
  EXPECT_EQ(in.brake, 0.0);
  EXPECT_EQ(v.actuate(154 * kMs).brake, 0.0);
  in = v.actuate(155 * kMs);
  EXPECT_EQ(in.brake, 1.0);
  EXPECT_EQ(in.steering_angle, 0.1);  // the steering stays the ACU's
}

TEST(Vcu, AnAcuInEmergencyFiresTheEbs) {
  Vcu v(VcuParams{}, hal::MissionCode::Autocross);
  v.command(0, cmd(0, hal::AsState::Emergency, 0.0, 1.0));
  ASSERT_TRUE(v.ebs_fired());
  EXPECT_EQ(v.ebs_cause(), "the ACU reported AS Emergency");
}

TEST(Vcu, ASilentAcuFiresTheEbsOnlyOnceReadyOrDriving) {
  VcuParams p;
  p.acu_timeout = 0.1;
  Vcu off(p, hal::MissionCode::Autocross);
  off.command(0, cmd(0, hal::AsState::Off, 0.0, 1.0));
  off.actuate(5000 * kMs);
  EXPECT_FALSE(off.ebs_fired());
  Vcu driving(p, hal::MissionCode::Autocross);
  driving.command(0, cmd(0, hal::AsState::Driving, 0.5, 0.0));
  driving.actuate(100 * kMs);
  EXPECT_FALSE(driving.ebs_fired());  // 0.1 s exactly
  driving.actuate(101 * kMs);
  ASSERT_TRUE(driving.ebs_fired());
  EXPECT_NE(driving.ebs_cause().find("no ACU command for 0.101 s"), std::string::npos) << driving.ebs_cause();
}

}  // namespace
}  // namespace paddock::vehicle
