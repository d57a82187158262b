#pragma once
// the constant half of a simulation (MuJoCo's mjModel): compiled once from a
// scenario and its track, never written afterwards. Everything that changes
// while the car drives lives in a SimState (simulation.h); any number of
// states can step against one model at once, on as many threads.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "autonomy/stack/stack.h"
#include "sim/events/event.h"
#include "sim/runner/scenario.h"
#include "sim/sensors/camera.h"
#include "sim/sensors/cone_sensor.h"
#include "sim/vehicle/vehicle.h"
#include "sim/world/track.h"
#include "sim/world/venue.h"

namespace paddock::runner {

// how many physics steps lie between two firings of each periodic part
struct StepPeriods {
  long control = 1;  // the stack's cycle (and the state estimate it is given)
  long log = 1;      // log rows and the event's sample (penalties, finish, DNF)
  long cone_sensor = 1;
  long imu = 1;
  long wheel_speeds = 1;
  long steering = 1;
  long vcu_status = 1;
};

struct SimModel {
  explicit SimModel(const Scenario& sc) : scenario(sc), car(sc.vehicle) {}

  Scenario scenario;           // as loaded: every module's and sensor's parameters
  vehicle::Car car;            // its vehicle, compiled for stepping
  world::TrackModel track;     // the event's track (the event's on-track test points into it)
  std::vector<Cone> cones;     // the cones standing at the event (event_cones)
  std::vector<world::Block> blocks;  // the venue's barrier blocks ([venue]; the sensors see them)
  Pose2 start;                 // the car's base pose at the start (start_pose)
  vehicle::Footprint footprint;
  stack::StackParams stack;    // the stack's parameters (stack_params)
  stack::MissionSpec mission;  // what the car is told before the start (mission_for)
  // perception = ground_truth: the object-level sensor, told the cones' real radii
  sensors::ConeSensorParams cone_sensor;
  // perception = lidar | lidar_camera: the raw sensors instead (camera: lidar_camera only)
  bool raw_perception = false;
  std::optional<sensors::CameraParams> camera;
  Vec2 perception_mount;       // the perceiving sensor's origin in the base frame (for the metrics)

  double dt = 0.001;           // s, one physics step
  TimeNs dt_ns = 1000000;
  StepPeriods every;
  TimeNs go = 0;               // the go signal comes this long after the car shows AS Ready
  // the true poses kept: a second, and two LiDAR rotations at least, and
  // perception's latency more
  TimeNs pose_history_span = 0;
  std::size_t visible_scans = 4;  // the scans' cones hit kept for the perception metrics
  // the log samples of a run that lasts its event's longest (at most
  // kMaxReservedSamples): the per-sample records reserve this much, so that
  // they never move while they grow (pages are only touched as rows come)
  std::size_t log_samples = 0;
};
inline constexpr std::size_t kMaxReservedSamples = std::size_t{1} << 20;

// compiles the model of a scenario on its track; the scenario was validated by
// load_scenario, so this cannot fail
SimModel compile_model(const Scenario& scenario, const world::TrackModel& track);

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

}  // namespace paddock::runner
