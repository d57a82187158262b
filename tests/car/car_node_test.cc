// the car binary's node without its sockets: the watchdogs turn a silent
// sensor into AS Emergency (brakes on) after their timeouts and not before,
// only the car's own frames count as a sign of life, a watchdog waits for its
// sensor's first message, and a bad object message is dropped and counted;
// a camera device that is not there is named
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "autonomy/car/camera.h"
#include "autonomy/car/car_node.h"
#include "autonomy/hal/car_can.h"
#include "autonomy/hal/dbc.h"
#include "autonomy/hal/ouster.h"

namespace paddock::car {
namespace {

std::string shipped(const std::string& name) {
  std::ifstream f(std::string(PADDOCK_SOURCE_DIR) + "/scenarios/sensors/" + name);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

// the stack drives a given straight (the oracle planner), so a car that
// reports itself ready (can()) is in AS Ready at once: a watchdog's fault then
// takes it to AS Emergency
stack::StackParams oracle_stack() {
  stack::StackParams p;
  p.autonomy.planner = stack::PlannerMode::Oracle;
  return p;
}
stack::MissionSpec straight() {
  stack::MissionSpec m;
  m.mission = stack::Mission::Trackdrive;
  for (int i = 0; i <= 10; ++i) m.oracle_path.push_back({5.0 * i, 0.0});
  return m;
}

struct Car {
  hal::Dbc dbc = hal::parse_dbc(shipped("paddock.dbc"), "paddock.dbc");
  hal::ouster::SensorInfo info = hal::ouster::parse_sensor_info(shipped("os2_32.json"), "os2_32.json");
  hal::LidarLayout layout = hal::ouster::layout_of(info, hal::LidarLayout{});
  hal::CarCan vcu{dbc, "paddock.dbc"};  // the car's side of the bus
  CarNode node{oracle_stack(), straight(), info, layout, dbc, "paddock.dbc", WatchdogParams{}};
  std::uint16_t frame = 0;

  // the VCU's frames (the wheels, the safety chain ready to drive), and an
  // INS's state estimate at rest at the start
  void can(TimeNs t) {
    node.can_frame(vcu.encode(hal::WheelSpeeds{t, {10.0, 10.0, 10.0, 10.0}}));
    node.can_frame(vcu.encode(hal::VcuStatus{t, true, hal::MissionCode::Trackdrive, 10.0, 100.0, 100.0}));
    const std::string est = R"({"type": "state_estimate", "stamp": )" + std::to_string(t) +
                            R"(, "x": 0, "y": 0, "yaw": 0, "vx": 0, "vy": 0, "yaw_rate": 0})";
    node.object(t, est.data(), est.size());
  }
  // one rotation's packets, empty (no returns), received at t
  void rotation(TimeNs t) {
    std::vector<std::uint8_t> bytes;
    hal::ouster::encode(info, hal::ouster::make_range_image(info, frame++, t), bytes);
    const std::size_t n = hal::ouster::packet_size(info);
    for (std::size_t at = 0; at + n <= bytes.size(); at += n) node.lidar_packet(t, bytes.data() + at, n);
  }
};

constexpr TimeNs kMs = 1'000'000;

TEST(CarNode, NoLidarForHalfASecondIsAnEmergency) {
  Car car;
  TimeNs t = 0;
  for (; t <= 1000 * kMs; t += 10 * kMs) {
    car.can(t);
    if (t % (100 * kMs) == 0) car.rotation(t);
    EXPECT_EQ(car.node.tick(t).as_state, hal::AsState::Ready) << t;
  }
  EXPECT_GT(car.node.counters().lidar.rotations, 5u);
  // the LiDAR's last packets came at 1.0 s; the CAN bus goes on
  for (; t <= 1500 * kMs; t += 10 * kMs) {
    car.can(t);
    EXPECT_NE(car.node.tick(t).as_state, hal::AsState::Emergency) << t;
  }
  car.can(1510 * kMs);
  const hal::ActuatorCommand c = car.node.tick(1510 * kMs);
  EXPECT_EQ(c.as_state, hal::AsState::Emergency);
  EXPECT_EQ(c.brake, 1.0);
  EXPECT_EQ(c.throttle, 0.0);
  ASSERT_TRUE(car.node.watchdog_fault());
  EXPECT_NE(car.node.watchdog_fault()->find("no LiDAR packet for 0.510 s"), std::string::npos)
      << *car.node.watchdog_fault();
  EXPECT_EQ(car.node.stack().telemetry().last_fault, *car.node.watchdog_fault());
  // latched: the LiDAR's return does not undo it
  car.rotation(1600 * kMs);
  car.can(1600 * kMs);
  EXPECT_EQ(car.node.tick(1600 * kMs).as_state, hal::AsState::Emergency);
}

TEST(CarNode, NoCanFrameForATenthOfASecondIsAnEmergency) {
  Car car;
  for (TimeNs t = 0; t <= 500 * kMs; t += 10 * kMs) {
    car.can(t);
    if (t % (100 * kMs) == 0) car.rotation(t);
    EXPECT_EQ(car.node.tick(t).as_state, hal::AsState::Ready);
  }
  // the bus silent; the cycles run on time
  for (TimeNs t = 510 * kMs; t <= 600 * kMs; t += 10 * kMs) {
    EXPECT_EQ(car.node.tick(t).as_state, hal::AsState::Ready) << t;  // 0.1 s exactly: not yet
  }
  const hal::ActuatorCommand c = car.node.tick(610 * kMs);
  EXPECT_EQ(c.as_state, hal::AsState::Emergency);
  EXPECT_EQ(c.brake, 1.0);
  ASSERT_TRUE(car.node.watchdog_fault());
  EXPECT_NE(car.node.watchdog_fault()->find("no sensor frame on the CAN bus"), std::string::npos);
}

TEST(CarNode, AnotherNodesFramesAreNoSignOfLife) {
  Car car;
  car.can(0);
  EXPECT_EQ(car.node.tick(0).as_state, hal::AsState::Ready);
  for (TimeNs t = 10 * kMs; t <= 300 * kMs; t += 10 * kMs) {
    hal::CanFrame foreign;
    foreign.stamp = t;
    foreign.id = 0x7FF;  // on the bus, but no frame of the car's DBC
    foreign.dlc = 8;
    car.node.can_frame(foreign);
    car.node.tick(t);
  }
  EXPECT_EQ(car.node.tick(310 * kMs).as_state, hal::AsState::Emergency);
  EXPECT_EQ(car.node.counters().can.unknown_id, 30u);
}

TEST(CarNode, AWatchdogWaitsForItsSensorsFirstMessage) {
  Car car;
  for (TimeNs t = 0; t <= 10'000 * kMs; t += 10 * kMs) EXPECT_EQ(car.node.tick(t).as_state, hal::AsState::Off);
  EXPECT_FALSE(car.node.watchdog_fault());
}

TEST(CarNode, ABadObjectMessageIsDroppedAndCounted) {
  Car car;
  const std::string bad = R"({"type": "camera_detections", "stamp": 5})";
  car.node.object(0, bad.data(), bad.size());
  const std::string garbage = "\x01\x02 not json";
  car.node.object(0, garbage.data(), garbage.size());
  const std::string good = R"({"type": "camera_detections", "stamp": 5, "width": 640, "height": 480, "boxes": []})";
  car.node.object(0, good.data(), good.size());
  EXPECT_EQ(car.node.counters().bad_objects, 2u);
  EXPECT_EQ(car.node.counters().objects, 1u);
  EXPECT_NE(car.node.last_bad_object().find("no JSON"), std::string::npos) << car.node.last_bad_object();
  EXPECT_NE(car.node.tick(0).as_state, hal::AsState::Emergency);
}

// a camera that is not there, or a device that is no camera, says so
TEST(V4l2Camera, AMissingCameraIsNamed) {
  try {
    V4l2Camera c("/dev/paddock_no_camera", 800, 500);
    ADD_FAILURE() << "opened";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("no camera at /dev/paddock_no_camera: No such file or directory"),
              std::string::npos)
        << e.what();
  }
  try {
    V4l2Camera c("/dev/null", 800, 500);
    ADD_FAILURE() << "opened";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/dev/null is no V4L2 camera (VIDIOC_QUERYCAP:"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace paddock::car
