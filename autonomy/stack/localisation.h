#pragma once
// the stack's own localisation (slam != ground_truth), from the HAL's
// messages and nothing else:
//   odometry: the velocity EKF (IMU, wheel speeds, steering angle) dead
//     reckons from the start pose; the map is built at its poses
//   fastslam: FastSLAM (1.0 or 2.0) on each frame of cone detections, moved
//     between frames by the EKF's pose change; its highest-weight particle's
//     pose corrects the dead reckoning and its map is the stack's
//
// The estimate the stack drives on is the odometry's, carried into the map
// frame by the newest correction C = s (+) o^-1 (s: SLAM's pose of the base
// at the last frame's stamp, o: the odometry's at that stamp): between frames
// it moves with the odometry at the IMU rate; at a frame it jumps by what
// SLAM corrected (centimetres). Velocities are the EKF's (base frame).
//
// A frame of detections is processed at the odometry's pose at its stamp
// (interpolated); a frame newer than the newest odometry waits for it.
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "autonomy/common/geometry.h"
#include "autonomy/common/params.h"
#include "autonomy/common/time.h"
#include "autonomy/estimation/velocity_ekf.h"
#include "autonomy/hal/messages.h"
#include "autonomy/slam/cone_map.h"
#include "autonomy/slam/fastslam.h"

namespace paddock::stack {

enum class SlamMode { GroundTruth, Odometry, FastSlam };

// [slam]: how the stack estimates its own state (slam != ground_truth)
struct SlamParams {
  estimation::VelocityEkfParams velocity;
  // FastSLAM's keys sit in [slam] itself (fastslam_version, particles, ...)
  slam::FastSlamParams fastslam;
  // not visited: the runner fills them from the vehicle ([vehicle]) and the
  // scenario's seed
  estimation::CarGeometry geometry;
  std::uint64_t seed = 1;

  template <class V>
  void visit(V& v) {
    fastslam.visit(v);
    v.section(PADDOCK_PARAM(velocity), "the velocity and odometry EKF: IMU, wheel speeds, steering angle");
  }
};

// what the localisation did, for the run's report
struct LocalisationStats {
  long frames = 0;          // frames of detections processed by SLAM
  long empty_frames = 0;    // frames without a cone: motion only, no expectation of the map
  long dropped_frames = 0;  // frames with no odometry at their stamp
  int loop_closures = 0;    // pose-graph optimisations at a closed loop
  std::vector<double> update_ms;  // wall time of each SLAM update (not part of any result)
  std::string last_fault;   // the reason of the last fallback
};

class Localisation {
 public:
  // throws std::invalid_argument on invalid params; mode != GroundTruth
  Localisation(const SlamParams& p, SlamMode mode, const Pose2& start);

  // a new estimate to drive on when the IMU sample was taken
  std::optional<hal::StateEstimate> on_imu(const hal::Imu& m);
  void on_wheel_speeds(const hal::WheelSpeeds& m);
  void on_steering(const hal::SteeringAngle& m);
  // one frame of detections (base frame at d.stamp); processed now or, when
  // newer than the odometry, once the odometry reaches its stamp
  void on_detections(const hal::ConeDetections& d);

  // mode = odometry: the stack builds its map at the poses (pose_at);
  // mode = fastslam: the map is SLAM's
  bool owns_map() const { return mode_ != SlamMode::Odometry; }
  // true once after SLAM's map changed
  bool take_map_news();
  // SLAM's map: the confirmed landmarks of the highest-weight particle
  std::vector<slam::MappedCone> map() const;
  const LocalisationStats& stats() const { return stats_; }
  // var(x) + var(y) of the estimate (m^2): the EKF's (odometry); SLAM's
  // particle spread at the last frame plus what the odometry added since
  double position_variance() const;
  const slam::FastSlam* fastslam() const { return fastslam_ ? &*fastslam_ : nullptr; }

 private:
  struct Odom {
    TimeNs stamp;
    Pose2 pose;  // odometry frame
  };
  std::optional<Pose2> odometry_at(TimeNs t) const;
  double odometry_variance() const;
  void process(const hal::ConeDetections& d, const Pose2& odom);

  SlamParams params_;
  SlamMode mode_;
  estimation::VelocityEkf ekf_;
  std::optional<slam::FastSlam> fastslam_;
  std::deque<Odom> odom_;                    // the last second of odometry, oldest first
  std::deque<hal::ConeDetections> waiting_;  // frames newer than the odometry
  Pose2 last_frame_odom_;                    // the odometry at the last processed frame
  Pose2 correction_;                         // map <- odometry
  double slam_variance_ = 0.0;               // SLAM's var(x) + var(y) at the last frame
  double odom_variance_at_frame_ = 0.0;      // the EKF's then
  bool map_news_ = false;
  LocalisationStats stats_;
};

}  // namespace paddock::stack
