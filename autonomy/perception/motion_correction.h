#pragma once
// the LiDAR pipeline's first stage (paper section "Lidar Perception"): take a
// raw rotation, drop unusable returns, order it column by column and move
// every point into the base frame at the scan's reference time (scan.end).
//
// A rotating LiDAR fires its columns one after another over the rotation
// (0.1 s at 10 Hz); a point of column c is in the `lidar` frame as it stood
// at the column's time t_c. With the odometry's relative pose
// T = relative(end, t_c) (the base at t_c expressed in the base at end), a
// point p in the lidar frame goes to
//   p_base(t_c) = mount + R_pitch p         (lidar -> base at t_c)
//   p_base(end) = T * p_base(t_c)           (planar: x, y rotate and shift, z stays)
// The lidar frame (sim/sensors/lidar.h): origin at the optical centre,
// mount_z above the ground under the mounting point; x forward, y left, z up;
// the base's yaw, pitched by mount_pitch about its y axis (> 0 nose down):
// R_pitch (x, y, z) = (cos p x + sin p z, y, -sin p x + cos p z).
// The base frame's origin lies on the ground at the rear axle, so the ground
// at the sensor is z = 0 in the base frame.
//
// The odometry is planar: a car driving over a slope also rises or sinks
// during the scan (0.1 m over a metre of a 10 % slope), which no correction
// here removes.
//
// No I/O, no clock, no global state; the corrector keeps scratch buffers.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "autonomy/common/geometry.h"
#include "autonomy/common/time.h"
#include "autonomy/hal/messages.h"
#include "autonomy/perception/odometry.h"
#include "autonomy/perception/types.h"

namespace paddock::perception {

// what the pipeline made of a point
enum class PointLabel : std::uint8_t { Ground, NonGround, Cone };

// one return after correction
struct CloudPoint {
  float x = 0.0f, y = 0.0f, z = 0.0f;  // m, base frame at the reference time
  // the levelled sensor frame at the point's own time (the lidar frame with
  // the pitch undone): horizontal range and height from the optical centre
  float range_xy = 0.0f, z_sensor = 0.0f;  // m
  float height = 0.0f;                     // m, above the local ground (ground segmentation)
  float intensity = 0.0f;                  // -
  std::uint16_t ring = 0;
  PointLabel label = PointLabel::NonGround;
  bool vertical = false;  // stage 1 of the ground segmentation found it on a vertical object
};

// the points of one column, [begin, end) in Cloud::points
struct CloudColumn {
  std::uint32_t begin = 0, end = 0;
  TimeNs t = 0;  // ns, the column's time
};

// a corrected rotation: column by column in time order, rings ascending
// within a column
struct Cloud {
  TimeNs stamp = 0;         // the reference time (scan.end)
  bool corrected = false;   // false: the points were taken as if all measured at `stamp`
  std::size_t points_in = 0;
  std::size_t invalid = 0;  // dropped: a non-finite coordinate or intensity, or a ring >= channels
  std::vector<CloudPoint> points;
  std::vector<CloudColumn> columns;
};

class MotionCorrector {
 public:
  // throws std::invalid_argument when params::validate(calibration) fails
  explicit MotionCorrector(const LidarCalibration& calibration);

  // fills `out` from the scan. With odometry covering every column's time
  // the points are motion-corrected (out.corrected); without (null, or a gap
  // in its history) they are only moved into the base frame, as if measured
  // at scan.end. Never throws on bad data.
  void correct(const hal::LidarScan& scan, const Odometry* odometry, Cloud& out);

  const LidarCalibration& calibration() const { return calib_; }

 private:
  LidarCalibration calib_;
  double cos_pitch_ = 1.0, sin_pitch_ = 0.0;
  std::vector<std::uint32_t> order_;  // scratch: the valid points in (t, ring) order
  std::vector<Pose2> motion_;         // scratch: per column, the base at t in the base at end
  std::vector<TimeNs> times_;         // scratch: per column, its time
};

}  // namespace paddock::perception
