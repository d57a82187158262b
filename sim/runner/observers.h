#pragma once
// what watches a simulation from outside its loop: each observer is called
// once on the started state and then after every step (simulation.h), reads
// what it needs and keeps its own record. log.csv's rows, the perception
// metrics and the perception snapshot are observers; so can be a live view, a
// tuner's early stop or a test's probe.
#include <cstdint>
#include <deque>
#include <optional>
#include <vector>

#include "autonomy/common/cone.h"
#include "autonomy/common/geometry.h"
#include "sim/events/event.h"
#include "sim/runner/perception_metrics.h"
#include "sim/runner/slam_metrics.h"

namespace paddock::runner {

struct SimModel;
struct SimState;

// one row of log.csv (100 Hz by default)
struct LogRow {
  double t = 0.0;          // sim time (s)
  double x = 0.0;          // base frame (rear axle centre) in the map (m)
  double y = 0.0;
  double yaw = 0.0;        // rad
  double vx = 0.0;         // base-frame velocity (m/s)
  double vy = 0.0;
  double yaw_rate = 0.0;   // rad/s
  double steer_cmd = 0.0;  // commanded road-wheel angle (rad)
  double steer = 0.0;      // actual road-wheel angle (rad)
  double throttle = 0.0;   // commanded [0, 1]
  double brake = 0.0;      // commanded [0, 1]
  double v_ref = 0.0;      // reference speed (m/s)
  double lateral_error = 0.0;  // front axle offset from the reference path, > 0 left (m)
  double heading_error = 0.0;  // path heading - vehicle yaw (rad)
  double s = 0.0;          // arc length of the projection on the reference (m)
  int lap = 0;             // lap being driven, 0 before the first crossing
  int as_state = 0;        // hal::AsState as an integer
};

// tracking errors over the timed laps (definitions in the README)
struct Tracking {
  double rms = 0.0;   // m
  double max = 0.0;   // m
  double itae = 0.0;  // m s^2, mean over the completed laps of integral (t - t_lap) |e| dt
};

struct LapTracking {
  double rms = 0.0;
  double max = 0.0;
  double itae = 0.0;
};

// one perception frame of the run, kept for the perception figures (perception
// = lidar | lidar_camera): the first scan the stack processed after
// [sim] snapshot_time. Everything in the base frame at the scan's end.
struct PerceptionSnapshot {
  double t = 0.0;  // s, the scan's reference time
  struct Point {
    float x, y, z;
    std::uint8_t label;  // 0 ground, 1 non-ground, 2 cone
  };
  std::vector<Point> points;
  std::vector<Cone> detected;  // what perception delivered
  std::vector<Cone> truth;     // the true cones within 40 m
  // the camera frame fused with that scan (lidar_camera), if any
  bool camera = false;
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgb;
  struct Box {
    double x_min, y_min, x_max, y_max;
    ConeColor color;
  };
  std::vector<Box> boxes;
  std::vector<Vec2> projected;  // cluster centres the camera coloured or left to the LiDAR, px
  std::vector<Vec2> dropped;    // cluster centres fusion dropped, px
};

class Observer {
 public:
  virtual ~Observer() = default;
  // the state just stepped (or started); an observer may only change what
  // does not alter the run (the snapshot asks perception to keep its points)
  virtual void observe(const SimModel& model, SimState& state) = 0;
};

// log.csv: a row at every event sample
class LogRecorder final : public Observer {
 public:
  void observe(const SimModel& model, SimState& state) override;
  std::vector<LogRow>& rows() { return rows_; }

 private:
  std::vector<LogRow> rows_;
};

// how far the stack's state estimate lies from the truth: at every log
// sample, the newest estimate against the true pose at the estimate's own
// stamp (so a 200 Hz estimate is not blamed for its age); with the stack's
// own localisation, its final map against the true cones and its cost
struct SlamSample {
  double t = 0.0;              // s, the estimate's stamp
  Pose2 estimate, truth;       // the base's pose
  double error = 0.0;          // m, position error
  double heading_error = 0.0;  // rad
  double sigma = 0.0;          // m, sqrt(var x + var y) of the estimate (0: ground truth)
};
struct SlamLap {
  double ate_rms = 0.0, ate_max = 0.0;  // m, over the lap's samples
};
struct SlamMetrics {
  double ate_rms = 0.0;      // m, position error (absolute trajectory error)
  double ate_max = 0.0;      // m
  double heading_rms = 0.0;  // rad
  Drift drift;               // over 100 m windows of the drive (relative_drift)
  long samples = 0;
  std::vector<SlamLap> laps;       // per lap of the event
  MapMetrics map;                  // the stack's final map (cone_map.min_observations)
  int loop_closures = 0;
  long frames = 0;                 // frames SLAM processed
  long fallbacks = 0;              // frames it could not use (no cone, no odometry)
  long lost_frames = 0;            // frames the front end associated too little in
  int relocalisations = 0;         // re-anchored where a frame fit the map
  long rejected_messages = 0;      // odometry messages the EKF refused
  long slide_samples = 0;          // wheel updates the EKF judged a slide (its lateral-slip model skipped)
  double update_ms_mean = 0.0, update_ms_p99 = 0.0;  // wall time of a SLAM update (slam = lio: of a scan's LIO)
  long lio_slices = 0, lio_degenerate_slices = 0, lio_too_few_points = 0;  // slam = lio
  std::vector<SlamSample> series;  // every log sample, for the figures
};
class SlamScorer final : public Observer {
 public:
  void observe(const SimModel& model, SimState& state) override;
  // the map and the localisation's cost at the end of the run; per lap from
  // the event's laps. The series moves into the metrics: call it once
  SlamMetrics metrics(const SimModel& model, const SimState& state, const std::vector<events::Lap>& laps);

 private:
  double sum2_ = 0.0, heading2_ = 0.0, max_ = 0.0;
  long n_ = 0;
  std::vector<SlamSample> series_;
  std::vector<Vec2> path_;  // the true path, a point every metre
};

// the perception metrics: every frame of cones the stack received, against
// the truth of the frame's instant (the true pose, the cones as they stood,
// the cones the sensor could see at all)
class PerceptionScorer final : public Observer {
 public:
  void observe(const SimModel& model, SimState& state) override;
  const PerceptionMetrics& metrics() const { return metrics_; }

 private:
  PerceptionMetrics metrics_;
  long scored_frames_ = 0;
  std::vector<Cone> truth_;
};

// the perception snapshot (perception = lidar | lidar_camera): the first scan
// the stack processes at a control cycle at or after [sim] snapshot_time,
// with its labelled points (perception keeps them from the step before)
class SnapshotRecorder final : public Observer {
 public:
  void observe(const SimModel& model, SimState& state) override;
  std::optional<PerceptionSnapshot>& snapshot() { return snapshot_; }

 private:
  bool armed_ = false;
  bool pixels_before_ = false;  // whether the camera painted its frames before arming
  long frames_seen_ = 0;
  // once armed, the camera's frames of the scans still in perception's
  // hands ([perception] latency), newest last
  std::deque<hal::CameraFrame> frames_;
  std::optional<PerceptionSnapshot> snapshot_;
};

// the tracking errors of each completed lap and of all of them, from the log
// rows (definitions in the README); log_dt is the rows' spacing (s)
void tracking_from_log(const std::vector<events::Lap>& laps, const std::vector<LogRow>& log, double log_dt,
                       std::vector<LapTracking>& per_lap, Tracking& all);

}  // namespace paddock::runner
