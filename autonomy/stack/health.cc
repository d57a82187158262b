#include "autonomy/stack/health.h"

#include <algorithm>
#include <limits>

#include "autonomy/common/format.h"

namespace paddock::stack {

namespace {

std::string secs(TimeNs d) { return fixed(to_seconds(d), 3) + " s"; }

bool same_boxes(const std::vector<hal::CameraBox>& a, const std::vector<hal::CameraBox>& b) {
  if (a.empty() || a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a[i].x_min != b[i].x_min || a[i].y_min != b[i].y_min || a[i].x_max != b[i].x_max || a[i].y_max != b[i].y_max ||
        a[i].color != b[i].color)
      return false;
  }
  return true;
}

}  // namespace

void Health::set_fault(TimeNs now, const std::string& why) {
  if (!fault_.empty()) return;
  fault_ = why;
  note(now, "fault: " + why);
}

void Health::lidar_scan(TimeNs now, std::size_t points) {
  last_scan_ = now;
  const double n = static_cast<double>(points);
  // the usual count settles over the first scans; a sparse scan does not move it
  sparse_ = scans_seen_ >= 5 && n < p_.lidar_sparse * usual_points_;
  if (sparse_) return;
  ++scans_seen_;
  usual_points_ = scans_seen_ <= 20 ? usual_points_ + (n - usual_points_) / scans_seen_ : 0.95 * usual_points_ + 0.05 * n;
}

void Health::camera(TimeNs now, const hal::CameraDetections& d, double speed) {
  last_camera_ = now;
  // a moving car's camera never sees the same boxes twice to the last bit
  if (speed > 1.0 && same_boxes(d.boxes, last_boxes_)) {
    ++same_boxes_;
  } else {
    same_boxes_ = 0;
  }
  last_boxes_ = d.boxes;
  frozen_ = same_boxes_ + 1 >= p_.camera_frozen_frames;
}

template <class Why>
void Health::slow_mode(Slow& m, TimeNs now, bool bad, double speed, const Why& why) {
  if (bad) {
    m.healthy_since.reset();
    if (m.since) return;
    m.since = now;
    m.from_speed = speed;
    note(now, "degraded: " + why());
    return;
  }
  if (!m.since) return;
  if (!m.healthy_since) m.healthy_since = now;
  if (now - *m.healthy_since >= from_seconds(p_.recover_time)) {
    note(now, std::string("recovered: ") + m.name + " healthy for " + secs(now - *m.healthy_since) + ": full speed");
    m.since.reset();
    m.healthy_since.reset();
  }
}

double Health::cap(const Slow& m, TimeNs now) const {
  if (!m.since) return std::numeric_limits<double>::infinity();
  return std::max(p_.degraded_speed, m.from_speed - p_.degraded_decel * to_seconds(now - *m.since));
}

void Health::cycle(TimeNs now, double speed) {
  if (last_cycle_ && now - *last_cycle_ > from_seconds(p_.cycle_overrun)) {
    set_fault(now, "stack cycle overrun: " + secs(now - *last_cycle_) + " since the last control cycle (limit " +
                       secs(from_seconds(p_.cycle_overrun)) + ")");
  }
  last_cycle_ = now;
  if (use_odometry_) {
    if (last_imu_ && now - *last_imu_ > from_seconds(p_.odometry_timeout))
      set_fault(now, "no IMU sample for " + secs(now - *last_imu_) + " (limit " + secs(from_seconds(p_.odometry_timeout)) + ")");
    if (last_wheels_ && now - *last_wheels_ > from_seconds(p_.odometry_timeout))
      set_fault(now, "no wheel speeds for " + secs(now - *last_wheels_) + " (limit " + secs(from_seconds(p_.odometry_timeout)) + ")");
  }
  if (use_lidar_ && last_scan_) {
    const TimeNs silent = now - *last_scan_;
    if (silent > from_seconds(p_.lidar_timeout))
      set_fault(now, "no LiDAR scan for " + secs(silent) + " (limit " + secs(from_seconds(p_.lidar_timeout)) + ")");
    const bool lost = silent > from_seconds(p_.lidar_lost);
    // the reason is built only when the mode is entered
    slow_mode(lidar_, now, lost || sparse_, speed, [&] {
      return (lost ? "LiDAR lost (no scan for " + secs(silent) + ")"
                   : "LiDAR scans sparse (under " + fixed(100.0 * p_.lidar_sparse, 0) + " % of the usual " +
                         fixed(usual_points_, 0) + " points)") +
             ": driving on the map and odometry at reduced speed";
    });
  }
  if (map_lost_ >= p_.map_lost_frames || map_.since) {
    slow_mode(map_, now, map_lost_ >= p_.map_lost_frames, speed, [&] {
      return "map inconsistent (SLAM lost " + std::to_string(map_lost_) + " frames in a row): reduced speed";
    });
  }
  if (use_camera_ && last_camera_) {
    const bool lost = now - *last_camera_ > from_seconds(p_.camera_lost);
    const bool out = lost || frozen_;
    if (out) {
      camera_healthy_since_.reset();
      if (!camera_out_) {
        camera_out_ = true;
        note(now, lost ? "degraded: camera lost (no detections for " + secs(now - *last_camera_) + "): LiDAR-only colour"
                       : "degraded: camera frozen (the same boxes in " + std::to_string(same_boxes_ + 1) +
                             " frames while moving): LiDAR-only colour");
      }
    } else if (camera_out_) {
      if (!camera_healthy_since_) camera_healthy_since_ = now;
      if (now - *camera_healthy_since_ >= from_seconds(p_.recover_time)) {
        camera_out_ = false;
        camera_healthy_since_.reset();
        note(now, "recovered: camera healthy for " + secs(from_seconds(p_.recover_time)) + ": fused colour");
      }
    }
  }
}

double Health::speed_cap(TimeNs now) const { return std::min(cap(lidar_, now), cap(map_, now)); }

}  // namespace paddock::stack
