#pragma once
// the stack's watch over its own inputs and cycle: what it notices, and the
// degraded modes it chooses by itself (each entered and left with a reason,
// kept for the run's log):
//
//   LiDAR silent for lidar_lost      -> degraded: drive on the map and the
//                                       odometry at reduced speed
//   LiDAR silent for lidar_timeout   -> fault (AS Emergency)
//   a scan far sparser than usual    -> degraded (a sector or rings lost)
//   camera silent (lidar_camera)     -> LiDAR-only colour
//   camera frozen (the same boxes    -> LiDAR-only colour (the stale boxes
//   frame after frame while moving)     would drop true cones and recolour them)
//   the map inconsistent (SLAM's     -> degraded: reduced speed until the
//   front end lost map_lost_frames      frames fit the map again
//   frames in a row)
//   IMU or wheel speeds silent       -> fault (AS Emergency): the estimate has
//   (slam != ground_truth)              nothing to dead-reckon on
//   the control cycle late by        -> fault (AS Emergency)
//   cycle_overrun
//
// Every watchdog arms with its input's first message. Nothing here reads a
// clock: the stack says what time it is.
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "autonomy/common/params.h"
#include "autonomy/common/time.h"
#include "autonomy/hal/messages.h"

namespace paddock::stack {

// [health]
struct HealthParams {
  double lidar_lost = 0.15;      // 1.5 rotations at 10 Hz
  double lidar_timeout = 1.0;
  double lidar_sparse = 0.5;
  double camera_lost = 0.35;
  int camera_frozen_frames = 3;
  double odometry_timeout = 0.1;
  double cycle_overrun = 0.1;
  double degraded_speed = 5.0;
  double degraded_decel = 4.0;
  double recover_time = 0.5;
  int map_lost_frames = 2;

  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(lidar_lost), {"s", params::in(0.001, 60.0), "no LiDAR scan for this long: degraded (map and odometry, reduced speed)"});
    v(PADDOCK_PARAM(lidar_timeout), {"s", params::in(0.001, 600.0), "no LiDAR scan for this long: AS Emergency"});
    v(PADDOCK_PARAM(lidar_sparse), {"", params::fraction(), "a scan with fewer points than this share of the usual: degraded"});
    v(PADDOCK_PARAM(camera_lost), {"s", params::in(0.001, 60.0), "no camera detections for this long: LiDAR-only colour"});
    v(PADDOCK_PARAM(camera_frozen_frames), {"", params::in(2, 1000), "this many camera frames with the same boxes while moving: frozen, LiDAR-only colour"});
    v(PADDOCK_PARAM(odometry_timeout), {"s", params::in(0.001, 60.0), "no IMU sample or wheel speeds for this long (own estimate): AS Emergency"});
    v(PADDOCK_PARAM(cycle_overrun), {"s", params::in(0.001, 60.0), "a control cycle this late after the last: AS Emergency"});
    v(PADDOCK_PARAM(degraded_speed), {"m/s", params::in(0.0, 100.0), "the speed cap of degraded driving"});
    v(PADDOCK_PARAM(degraded_decel), {"m/s^2", params::in(0.1, 50.0), "the cap ramps down to it at this rate"});
    v(PADDOCK_PARAM(recover_time), {"s", params::in(0.0, 60.0), "an input healthy this long again ends its degraded mode"});
    v(PADDOCK_PARAM(map_lost_frames), {"", params::in(1, 1000), "SLAM lost this many frames in a row: the map is inconsistent, degraded (reduced speed)"});
  }
  std::string check() const {
    return lidar_timeout < lidar_lost ? "lidar_timeout must be at least lidar_lost" : "";
  }
};

// something the stack noticed, or a mode it entered or left
struct HealthEvent {
  TimeNs t = 0;
  std::string what;
};

class Health {
 public:
  // lidar: the stack reads the LiDAR; camera: and fuses the camera's boxes;
  // odometry: it estimates its own state from the IMU and wheels
  Health(const HealthParams& params, bool lidar, bool camera, bool odometry)
      : p_(params), use_lidar_(lidar), use_camera_(camera), use_odometry_(odometry) {}

  // inputs as they arrive (now: the cycle that drained them)
  void lidar_scan(TimeNs now, std::size_t points);
  void camera(TimeNs now, const hal::CameraDetections& d, double speed);
  void imu(TimeNs now) { last_imu_ = now; }
  void wheels(TimeNs now) { last_wheels_ = now; }
  // SLAM's front end: how many frames in a row it was lost (0: the last fit the map)
  void map_fit(int lost_run) { map_lost_ = lost_run; }

  // the control cycle at now, at speed (m/s): the watchdogs, the modes
  void cycle(TimeNs now, double speed);

  // a fault the stack cannot drive with (the first), or empty
  const std::string& fault() const { return fault_; }
  // driving degraded (LiDAR lost or sparse): the speed cap now (m/s); +inf otherwise
  double speed_cap(TimeNs now) const;
  bool lidar_degraded() const { return lidar_.since.has_value(); }
  bool map_degraded() const { return map_.since.has_value(); }
  // the camera's boxes are not to be trusted (lost or frozen)
  bool camera_distrusted() const { return camera_out_; }
  const std::vector<HealthEvent>& events() const { return events_; }

 private:
  void note(TimeNs now, std::string what) { events_.push_back({now, std::move(what)}); }
  void set_fault(TimeNs now, const std::string& why);
  // a degraded mode of reduced speed: since when, from what speed, healthy again since
  struct Slow {
    const char* name;
    std::optional<TimeNs> since;
    double from_speed = 0.0;
    std::optional<TimeNs> healthy_since;
  };
  // enters or leaves the slow mode m; why() gives the reason when it is entered
  template <class Why>
  void slow_mode(Slow& m, TimeNs now, bool bad, double speed, const Why& why);
  double cap(const Slow& m, TimeNs now) const;

  HealthParams p_;
  bool use_lidar_, use_camera_, use_odometry_;
  std::optional<TimeNs> last_scan_, last_camera_, last_imu_, last_wheels_, last_cycle_;
  // the usual points of a scan (a running mean of the healthy ones)
  double usual_points_ = 0.0;
  int scans_seen_ = 0;
  bool sparse_ = false;
  Slow lidar_{"LiDAR", {}, 0.0, {}};
  Slow map_{"map", {}, 0.0, {}};
  int map_lost_ = 0;
  // camera: frozen boxes counted, out of use
  std::vector<hal::CameraBox> last_boxes_;
  int same_boxes_ = 0;
  bool frozen_ = false;
  bool camera_out_ = false;
  std::optional<TimeNs> camera_healthy_since_;
  std::string fault_;
  std::vector<HealthEvent> events_;
};

}  // namespace paddock::stack
