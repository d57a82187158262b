#pragma once
// the closed loop: vehicle, cone world and event at the physics rate; the
// stack behind the sim HAL at the control rate; log rows at the log rate.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "autonomy/stack/stack.h"
#include "sim/events/event.h"
#include "sim/runner/perception_metrics.h"
#include "sim/runner/scenario.h"
#include "sim/world/track.h"

namespace paddock::runner {

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

// a cone that went down or out
struct ConeHit {
  Vec2 position;      // where it stood (m)
  ConeColor color = ConeColor::Unknown;
  double t = 0.0;     // sim time (s)
  bool knocked = false;  // knocked over by an impact (else: displaced out of its place)
};

// what the stack planned last, for the map's layers (planner = delaunay)
struct PlanSnapshot {
  std::vector<Segment> triangulation;  // the Delaunay edges of the map it planned on
  std::vector<Vec2> midpoints;         // the candidate points: the edges' midpoints
  std::vector<Vec2> centreline;        // the points the search chose
  std::vector<Cone> mapped_cones;      // the stack's cone map at the end of the run
  std::vector<Segment> gates;          // the timekeeping gates the stack knew or learned
  std::vector<Vec2> reference;         // the trajectory it drove last
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

struct RunResult {
  events::Result event;
  PlanSnapshot plan;
  std::vector<ConeHit> cones_hit;
  std::vector<LapTracking> lap_tracking;  // one per completed lap
  Tracking tracking;
  std::vector<LogRow> log;
  double sim_time = 0.0;   // s
  double wall_time = 0.0;  // s
  int fallbacks = 0;       // control cycles in the safe stop
  std::string fault;       // the stack's last fault, if any
  int cycles = 0;          // control cycles run
  PerceptionMetrics perception;  // the stack's perceived cones against the truth, per range bin
  std::optional<PerceptionSnapshot> snapshot;
};

// the mission the car is given for an event on a track (planner = oracle: also
// the ground-truth path of the event and its timekeeping gates)
stack::MissionSpec mission_for(events::EventKind kind, const world::TrackModel& track, stack::PlannerMode planner);

// the cones standing at the event: the track's, plus a big orange cone at
// each timekeeping post when the file has no big orange cones at all (the
// rules mark timekeeping lines with them; some files only give the posts)
std::vector<Cone> event_cones(const world::TrackModel& track);

// where the car starts: the track's start pose, moved back along its heading
// when that would put the car's nose less than 0.3 m behind the first gate
// (the rules' start position; some files give the pose of the car's centre)
Pose2 start_pose(const world::TrackModel& track, double nose_offset);

// runs one scenario to its end (finish or DNF); deterministic for a given
// scenario and build, apart from wall_time
RunResult run(const Scenario& scenario, const world::TrackModel& track);

}  // namespace paddock::runner
