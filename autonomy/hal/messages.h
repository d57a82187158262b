#pragma once
// what crosses the HAL: timestamped sensor messages in, actuator commands out.
// The sim back end and the hardware back end produce exactly these, so every
// field is one a part of the car fills (or, for a command, takes): nothing
// that only a simulator knows (tests/hal/messages_test.cc names the part
// behind each field and fails on a field without one).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <variant>
#include <vector>

#include "autonomy/common/cone.h"
#include "autonomy/common/geometry.h"
#include "autonomy/common/time.h"

namespace paddock::hal {

// the autonomous system state machine of the FS rules
enum class AsState { Off, Ready, Driving, Finished, Emergency };

// a full state estimate of the vehicle base frame (rear axle centre) in the
// map frame, as an INS (GNSS + IMU) unit would give it; the `slam =
// ground_truth` source
struct StateEstimate {
  TimeNs stamp = 0;
  Pose2 pose;             // base frame in the map frame
  double vx = 0.0;        // longitudinal velocity of the base origin, base frame (m/s)
  double vy = 0.0;        // lateral velocity of the base origin, base frame (m/s)
  double yaw_rate = 0.0;  // rad/s, > 0 counter-clockwise
};

// the remote emergency system: the "go" signal and the emergency stop
struct ResSignal {
  TimeNs stamp = 0;
  bool go = false;
  bool emergency = false;
};

// the missions of the car's mission selector (the FS rules' autonomous
// missions and the others a driverless car offers), as the VCU reports the
// one selected: the DBC's value table of VCU_Status.Mission
enum class MissionCode : std::uint8_t {
  None = 0,
  Acceleration = 1,
  Skidpad = 2,
  Autocross = 3,
  Trackdrive = 4,
  EbsTest = 5,
  Inspection = 6,
  Manual = 7,
};

// what the vehicle control unit reports of the car's safety chain, as the
// rules' AS state machine needs it: the autonomous system master switch, the
// mission on the selector, the pressure stored for the emergency brake
// system (EBS) and the brake lines' pressures
struct VcuStatus {
  TimeNs stamp = 0;
  bool asms_on = false;               // the ASMS is switched on
  MissionCode mission = MissionCode::None;
  double ebs_pressure = 0.0;          // bar, the EBS's energy storage (its pneumatic tank)
  double brake_pressure_front = 0.0;  // bar, the front brake line
  double brake_pressure_rear = 0.0;   // bar, the rear brake line
};

// a cone seen by perception, in the vehicle base frame at the measurement time
struct DetectedCone {
  Vec2 position;                        // base frame (m)
  ConeColor color = ConeColor::Unknown;
  // the colour came from a camera (a network's class, or an object-level
  // sensor's); else from the LiDAR's intensity profile, a weaker vote
  bool colour_from_camera = false;
};

// one frame of cone detections (the `perception = ground_truth` source: an
// object-level sensor standing in for a real pipeline's output)
struct ConeDetections {
  TimeNs stamp = 0;  // when the cones were measured; the message arrives later (latency)
  std::vector<DetectedCone> cones;
  // what hides the cones behind it: per bearing bin of the base frame at
  // `stamp` (free_range_bin), the horizontal range (m) of the nearest
  // obstacle that is no cone (a barrier, a wall), +infinity where none was
  // seen; empty when the node reports none (a cone beyond it in its bin is
  // hidden, not missing)
  std::vector<float> free_range;
};

// the bin of free_range (n bins) that holds `bearing` (rad, base frame):
// bin i covers [-pi + i 2 pi / n, -pi + (i + 1) 2 pi / n); a bearing off
// [-pi, pi) is wrapped onto the circle
inline std::size_t free_range_bin(double bearing, std::size_t n) {
  if (n == 0 || !std::isfinite(bearing)) return 0;
  const double f = std::floor((bearing + kPi) / (2.0 * kPi) * static_cast<double>(n));
  const double w = f - std::floor(f / static_cast<double>(n)) * static_cast<double>(n);
  return std::min(n - 1, static_cast<std::size_t>(std::max(0.0, w)));
}

// the inertial measurement unit, six axes: specific force (what an
// accelerometer measures: acceleration minus gravity, so a level car at rest
// reads az = +g) and angular rate, in the base frame's orientation (x
// forward, y left, z up), at the IMU's mounting point. The planar fields come
// first: the velocity estimator and the perception's odometry read ax, ay
// and yaw_rate only.
struct Imu {
  TimeNs stamp = 0;
  double ax = 0.0;          // m/s^2, forward
  double ay = 0.0;          // m/s^2, left
  double yaw_rate = 0.0;    // rad/s, about z (> 0 turning left)
  double az = 0.0;          // m/s^2, up
  double roll_rate = 0.0;   // rad/s, about x
  double pitch_rate = 0.0;  // rad/s, about y
};

// the four wheels' angular speeds: front left, front right, rear left, rear right
struct WheelSpeeds {
  TimeNs stamp = 0;
  std::array<double, 4> omega{};  // rad/s
};

// the measured road-wheel steering angle
struct SteeringAngle {
  TimeNs stamp = 0;
  double angle = 0.0;  // rad, > 0 left
};

// one return of a rotating LiDAR, in the sensor frame `lidar` (x forward, y
// left, z up; origin at the optical centre) as it stood at the point's own time
struct LidarPoint {
  float x = 0.0f, y = 0.0f, z = 0.0f;  // m
  float intensity = 0.0f;              // -, [0, 1]
  std::uint16_t ring = 0;              // channel, 0 = lowest elevation
  std::int64_t t = 0;                  // ns, when the point's column was fired
};

// one rotation of the LiDAR: raw points, column by column, each with its own
// time (a moving car's scan is distorted: nothing is corrected here)
struct LidarScan {
  TimeNs stamp = 0;  // the first column's time
  TimeNs end = 0;    // the last column's time
  std::vector<LidarPoint> points;
};

// one camera image (global shutter), triggered by the LiDAR once per rotation:
// what the camera driver gives, nothing more
struct CameraFrame {
  TimeNs stamp = 0;  // exposure time
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgb;  // row-major, 3 bytes a pixel, row 0 at the top
};

// one box a cone detector drew on a camera image, in pixels (x right, y
// down, row 0 at the top; pixel (i, j) covers [i, i+1) x [j, j+1))
struct CameraBox {
  double x_min = 0.0, y_min = 0.0, x_max = 0.0, y_max = 0.0;  // px
  ConeColor color = ConeColor::Unknown;                       // the detector's class
  double confidence = 1.0;                                    // -, [0, 1]
};

// the boxes a cone detector node (the paper's YOLOv5 on the car's computer)
// found on one camera frame, posted after the frame's exposure
struct CameraDetections {
  TimeNs stamp = 0;           // the frame's exposure time
  int width = 0, height = 0;  // px, the image the boxes are drawn on
  std::vector<CameraBox> boxes;
};

using SensorMessage = std::variant<StateEstimate, ResSignal, ConeDetections, Imu, WheelSpeeds, SteeringAngle,
                                   LidarScan, CameraFrame, CameraDetections, VcuStatus>;

// the stack's command to the car's low-level controllers
struct ActuatorCommand {
  TimeNs stamp = 0;
  double steering_angle = 0.0;  // road-wheel angle request (rad, > 0 left)
  double throttle = 0.0;        // fraction of the motor torque limit [0, 1]
  double brake = 1.0;           // fraction of the maximum brake torque [0, 1]
  double yaw_moment = 0.0;      // torque vectoring: a left/right drive torque difference (N m, > 0 counter-clockwise)
  AsState as_state = AsState::Off;
};

const char* to_string(AsState s);
const char* to_string(MissionCode m);

}  // namespace paddock::hal
