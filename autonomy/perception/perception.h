#pragma once
// the perception front of the stack (the paper's section "Perception"): raw
// LiDAR scans and the camera detector's boxes in, cone detections out.
//
//   odometry  IMU yaw rate + wheel speeds, dead-reckoned over the last seconds
//   LiDAR     motion correction -> ground removal -> clustering ->
//             reconstruction -> rule filters -> intensity colour
//             (LidarPipeline): cone candidates in the base frame at the end of
//             the rotation
//   camera    the detector's boxes on the frame the LiDAR triggered during
//             that rotation: posted through the HAL by a detector node
//             (hal::CameraDetections; in the simulator its annotation
//             detector), or found by a ConeDetector given to Perception,
//             which then runs it on the camera frames itself
//   fusion    each candidate moved by the odometry to the base frame at the
//             camera's exposure, projected through K [R|T]: in a box -> the
//             box's colour, in view but in no box -> dropped, out of view ->
//             the LiDAR's colour (fuse)
//
// use_camera = false is the LiDAR-only mode (perception = lidar). Missing or
// unusable camera detections degrade a lidar_camera scan to LiDAR only for
// that scan (counted in the stats), they never stop the output.
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "autonomy/common/params.h"
#include "autonomy/hal/messages.h"
#include "autonomy/perception/detector.h"
#include "autonomy/perception/fusion.h"
#include "autonomy/perception/lidar_pipeline.h"
#include "autonomy/perception/odometry.h"
#include "autonomy/perception/types.h"

namespace paddock::perception {

struct PerceptionParams {
  // not visited: the stack sets it from the perception mode ([autonomy]
  // perception: lidar_camera uses the camera, lidar not)
  bool use_camera = true;
  OdometryParams odometry;
  // its calibration: the LiDAR's mounting and beams
  LidarPipelineParams lidar;
  // K and T_camera_base; not visited: the runner fills it from the camera's
  // model and mounting ([camera]); check() checks it when use_camera
  CameraCalibration camera;
  FusionParams fusion;
  // a camera frame's detections serve the scan during whose rotation the
  // frame was exposed, give or take this much
  double camera_sync_tolerance = 0.02;
  // not Perception's own: how the stack runs it (stack/perception_stage.h).
  // A scan's cones reach the localisation this long after the scan came
  // (the pipeline's compute on the car), and 2 threads process the scans
  // beside the loop (the same result)
  double latency = 0.0;
  int threads = 1;

  template <class V>
  void visit(V& v) {
    v.section(PADDOCK_PARAM(odometry), "the dead reckoning that motion-corrects the scans");
    v.section(PADDOCK_PARAM(lidar), "the LiDAR pipeline");
    v.section(PADDOCK_PARAM(fusion), "the LiDAR-camera fusion");
    v(PADDOCK_PARAM(camera_sync_tolerance), {"s", params::in(0.0, 1.0),
                                             "a camera frame serves the rotation it was exposed in, give or take this"});
    // (at most half the second of odometry and state estimates the stack
    // keeps to place a frame at the pose of its stamp)
    v(PADDOCK_PARAM(latency), {"s", params::in(0.0, 0.5),
                               "a scan's cones reach the localisation this long after the scan (the pipeline's compute on the car)"});
    v(PADDOCK_PARAM(threads), {"", params::in(1, 2),
                               "2: the scans are processed on a thread of their own beside the loop (the result is the same)"});
  }
  // the camera's calibration when use_camera
  std::string check() const;
};

// what the last scan went through, for plots and diagnostics
struct PerceptionFrame {
  LidarResult lidar;
  bool camera_used = false;            // the scan was fused with a camera frame's detections
  std::string camera_note;             // why not, when the mode has a camera
  TimeNs camera_stamp = 0;             // the fused frame's exposure (camera_used), else 0
  hal::CameraDetections detections;    // the fused frame's boxes (camera_used)
  FusionResult fusion;                 // per LiDAR candidate (camera_used)
  hal::ConeDetections output;
};

struct PerceptionStats {
  long scans = 0;
  long scans_uncorrected = 0;     // no odometry over the rotation
  long scans_failed = 0;          // the LiDAR pipeline returned no usable result
  long scans_without_camera = 0;  // lidar_camera scans that fell back to LiDAR only
  long dropped_by_fusion = 0;     // candidates dropped as false detections
};

// the LiDAR pipeline's result on a scan, computed ahead of the stack
// elsewhere (a replay's second thread, car/read_ahead.h). Perception
// takes it in place of its own run of the pipeline only when it was computed
// on exactly its own inputs, so the result is the same either way
class LidarAhead {
 public:
  virtual ~LidarAhead() = default;
  // LidarPipeline(params).process(scan, &odometry)'s result, if one was
  // computed with the perception's LiDAR params on the same scan and an
  // odometry in the same state, bit for bit; else none
  virtual std::optional<LidarResult> take(const hal::LidarScan& scan, const Odometry& odometry) = 0;
};

class Perception {
 public:
  // throws std::invalid_argument when params::validate(params) fails. detector: a
  // network run on the camera frames (add(CameraFrame)), or none when a
  // detector node posts its boxes (add(CameraDetections))
  explicit Perception(const PerceptionParams& params, std::unique_ptr<ConeDetector> detector = nullptr);

  void add(const hal::Imu& imu) { odometry_.add(imu); }
  void add(const hal::WheelSpeeds& wheels) { odometry_.add(wheels); }
  void add(const hal::StateEstimate& estimate) { odometry_.add(estimate); }
  // the newest camera detections are kept for the scan of their rotation
  void add(hal::CameraDetections detections);
  // with a detector of its own: its boxes on the frame, kept as the newest
  // detections (or, when it fails, the reason); without one the frame is not looked at
  void add(const hal::CameraFrame& frame);

  // the stack distrusts the camera (lost or frozen): its boxes are not fused
  // until this is cleared (lidar_camera scans fall back to LiDAR only)
  void set_camera_distrusted(bool d) { camera_distrusted_ = d; }

  // one rotation -> the cones, base frame at the scan's reference time (its end)
  const hal::ConeDetections& process(const hal::LidarScan& scan);

  // keep the labelled points of the next scans (for plots); results
  // computed ahead (with the former params) are no longer taken
  void set_keep_points(bool keep) {
    params_.lidar.keep_points = keep;
    pipeline_ = LidarPipeline(params_.lidar);
    ahead_ = nullptr;
  }
  // the LiDAR pipeline's results computed ahead (null: none), asked first
  // for each scan; it must outlive its use here
  void set_ahead(LidarAhead* ahead) { ahead_ = ahead; }
  const PerceptionParams& params() const { return params_; }
  const PerceptionFrame& last() const { return last_; }
  // the last frame exchanged for `other` (its buffers reused by the next scan)
  void swap_last(PerceptionFrame& other) { std::swap(last_, other); }
  const PerceptionStats& stats() const { return stats_; }

 private:
  // the newest camera input: a frame's detections, or why the own detector found none on it
  struct CameraInput {
    hal::CameraDetections detections;
    std::string failure;  // "" when the detections are usable
  };

  PerceptionParams params_;
  Odometry odometry_;
  LidarPipeline pipeline_;
  std::unique_ptr<ConeDetector> detector_;
  std::optional<CameraInput> camera_;
  bool camera_distrusted_ = false;
  LidarAhead* ahead_ = nullptr;
  PerceptionFrame last_;
  PerceptionStats stats_;
};

}  // namespace paddock::perception
