#pragma once
// the raw perception sensors of perception = lidar | lidar_camera in the
// closed loop: the rotating LiDAR (and the camera it triggers) ray-cast the
// cone world as it stands, from the car's pose at each column's own time;
// and the camera's detector node, which turns each frame into the boxes a
// network on the car would post.
//
// The loop records the base pose every physics step (PoseHistory); when a
// rotation is over, the whole scan is cast from the recorded poses of that rotation (each column
// from the pose at its own time, interpolated between physics steps), and
// posted to the HAL as it would arrive from the driver: at the end of the
// rotation. The camera frame's detections go first, as the detector node on
// the car posts them (the frame itself stays here: nothing behind the HAL
// looks at its pixels in the simulator). The Embree scene is rebuilt only when
// a cone moved or fell.
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "autonomy/common/profile.h"
#include "autonomy/hal/shared_frame.h"
#include "autonomy/common/workers.h"
#include "autonomy/hal/messages.h"
#include "sim/runner/faults.h"
#include "sim/runner/sim_hal.h"
#include "sim/sensors/annotation_detector.h"
#include "sim/sensors/camera.h"
#include "sim/sensors/lidar.h"
#include "sim/world/cone_world.h"
#include "sim/world/venue.h"

namespace paddock::runner {

// the base poses of the last `span` of simulation time, interpolated between
// the recorded steps (clamped at the ends)
class PoseHistory {
 public:
  explicit PoseHistory(TimeNs span) : span_(span) {}
  void record(TimeNs now, const Pose2& base);
  Pose2 at(TimeNs t) const;

 private:
  TimeNs span_;
  std::deque<std::pair<TimeNs, Pose2>> poses_;  // oldest first
};

// per cone of the world, whether a scan hit it with at least one point
std::vector<bool> cones_hit(const std::vector<std::int32_t>& truth, std::size_t cone_count);

class RawSensors {
 public:
  // camera: the camera the LiDAR triggers (perception = lidar_camera), or
  // none; detector: the error model of its detector node. The LiDAR, the
  // camera and the detector each draw from their own random stream
  RawSensors(const sensors::LidarParams& lidar, const sensors::GroundParams& ground,
             const std::vector<world::Block>& blocks, const std::optional<sensors::CameraParams>& camera, const sensors::DetectorParams& detector,
             std::uint64_t lidar_seed, std::uint64_t camera_seed, std::uint64_t detector_seed,
             int threads = 1);

  // true when a rotation ends at `now` (one starts at 0, then every period)
  bool rotation_ends(TimeNs now) const;
  // casts the rotation that ends at `now` against the cones as they stand,
  // each column from its pose in `poses` (which must cover the rotation), and
  // posts the detections of the camera frame it triggered (exposed at the
  // trigger column's time, from the pose of that instant), then the scan;
  // returns its ground truth: per point the cone index hit (sensors::kHitGround
  // the ground, kHitStructure a barrier block), in
  // the order of the scan's points
  // faults: the LiDAR's and the camera's at t (s, now): a rotation not sent,
  // returns lost, a dead or frozen camera
  const std::vector<std::int32_t>& emit(TimeNs now, const world::ConeWorld& cones, const PoseHistory& poses,
                                        SimHal& hal, FaultInjector& faults, double t);
  // the stamp of the scan's last column (the scan's `end`) for a rotation ending at `now`
  TimeNs scan_end(TimeNs now) const;
  // whether the camera's frames are painted: only a reader of their pixels
  // (a run's log, the perception snapshot) needs them, and asks; else each
  // frame is only annotated, all the detector node reads (the same
  // detections: Camera::render's pixels = false), off by default
  void set_pixels(bool on) { pixels_ = on; }
  bool pixels() const { return pixels_; }
  // the last camera frame rendered with its pixels (for the perception
  // figures and the log), or null (none yet, or the last one without them)
  const hal::CameraFrame* camera_frame() const {
    return camera_ && frame_->frame.width > 0 && frame_painted_ ? &frame_->frame : nullptr;
  }
  // the same frame lent to a reader on another thread (the log's), without
  // a copy: the next render goes into a new frame while the lease is out
  hal::FrameLease lend_camera_frame() const { return hal::FrameLease(frame_); }
  // the LiDAR's and the camera's time, timed into `profile` (null: not timed).
  // With two threads the camera's is the time the loop waits for it beyond
  // the LiDAR's cast
  void set_profile(Profile* profile) { profile_ = profile; }

 private:
  Profile* profile_ = nullptr;
  // the cones as they stand (in the colours the faults give them at t) and
  // the blocks (the venue's and a fault's object): rebuilt when they changed
  void update_scene(const world::ConeWorld& cones, const FaultInjector& faults, double t);

  // threads = 2: the camera's render and detector on the second (each
  // sensor draws from its own stream, the scene is only read, and the
  // detections are posted before the scan as on one thread)
  Workers workers_;
  sensors::Lidar lidar_;
  std::unique_ptr<sensors::Camera> camera_;
  std::unique_ptr<sensors::AnnotationDetector> detector_;
  std::shared_ptr<hal::SharedFrame> frame_ = std::make_shared<hal::SharedFrame>();
  bool pixels_ = false;         // set_pixels
  bool frame_painted_ = false;  // the last frame was rendered with its pixels
  std::optional<hal::CameraDetections> frozen_;  // a frozen camera's last detections
  sensors::CameraAnnotation annotation_;
  sensors::GroundParams ground_;
  std::vector<world::Block> blocks_;
  std::size_t scene_objects_ = 0;  // a fault's object blocks in the scene
  std::unique_ptr<sensors::LidarWorld> world_;
  std::vector<Cone> scene_cones_;
  std::vector<bool> scene_knocked_;
  std::vector<std::int32_t> truth_;
  std::vector<sensors::LidarPoint> raw_;  // the last rotation's scan (its buffer reused)
  // transport = wire: the rotation counter (the packets' frame_id), the
  // columns' times, the packets (kept to save their allocations)
  std::uint16_t frame_id_ = 0;
  std::vector<TimeNs> column_time_;
  std::vector<std::uint8_t> packets_;
};

}  // namespace paddock::runner
