#pragma once
// the autonomy pipeline behind the HAL: mission logic, the AS state machine,
// planning and control at the control rate.
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "autonomy/common/geometry.h"
#include "autonomy/common/time.h"
#include "autonomy/common/trajectory.h"
#include "autonomy/control/controller.h"
#include "autonomy/hal/hal.h"
#include "autonomy/planning/reference.h"
#include "autonomy/slam/cone_map.h"

namespace paddock::stack {

// where each layer's input comes from (the scenario's [autonomy] section)
enum class PerceptionMode { GroundTruth };
enum class SlamMode { GroundTruth };
enum class PlannerMode { Oracle };

struct AutonomyModes {
  PerceptionMode perception = PerceptionMode::GroundTruth;
  SlamMode slam = SlamMode::GroundTruth;
  PlannerMode planner = PlannerMode::Oracle;
};

// the dynamic events of the FS rules, as selected on the car's mission switch
enum class Mission { Acceleration, Skidpad, Autocross, Trackdrive };

struct MissionParams {
  double stop_decel = 8.0;         // deceleration of the stop after the finish (m/s^2), the planner's braking limit
  double standstill_speed = 0.05;  // below this the car counts as stopped (m/s)
  double state_timeout = 0.2;      // a state estimate older than this triggers the safe stop (s)
};

struct StackParams {
  AutonomyModes modes;
  planning::ReferenceParams reference;
  control::ControlParams control;
  control::VehicleKnowledge vehicle;
  MissionParams mission;
  slam::ConeMapParams cone_map;
};

// what the car is told before the start
struct MissionSpec {
  Mission mission = Mission::Trackdrive;
  // crossings of the finish line after which the car stops (trackdrive: 11, the
  // first one starts lap 1); 0: drive to the end of an open path and stop there
  int finish_crossings = 0;
  std::optional<Segment> finish_line;  // {left post, right post}; forward crosses right to left
  // planner = oracle: the reference path (a centreline) known in advance
  std::vector<Vec2> oracle_path;
  bool oracle_closed = false;
};

// what the stack reports of itself each cycle (telemetry, for logs)
struct Telemetry {
  hal::AsState as_state = hal::AsState::Off;
  control::Diagnostics control;
  bool control_ok = true;
  int finish_crossings = 0;   // finish-line crossings counted by the stack
  bool stopping = false;      // the mission is over and the car brakes to a stop
  int fallbacks = 0;          // control cycles that ran the safe stop instead of the plan
  std::string last_fault;     // the reason of the last fallback or planning failure
  int mapped_cones = 0;       // cones in the stack's map (seen often enough)
};

class Stack {
 public:
  Stack(const StackParams& params, MissionSpec spec);

  // drains the HAL's messages, runs one control cycle, sends one command
  void tick(TimeNs now, hal::Hal& hal);

  const Telemetry& telemetry() const { return telemetry_; }
  const Trajectory& trajectory() const { return trajectory_; }
  const slam::ConeMap& cone_map() const { return cone_map_; }

 private:
  void on_message(const hal::SensorMessage& m);
  void on_detections(const hal::ConeDetections& d);
  // the base pose at time t from the recent state estimates (interpolated), if known
  std::optional<Pose2> pose_at(TimeNs t) const;
  hal::ActuatorCommand safe_stop(TimeNs now, const std::string& reason);

  StackParams params_;
  MissionSpec spec_;
  Trajectory trajectory_;
  control::Controller controller_;
  Telemetry telemetry_;

  std::optional<hal::StateEstimate> state_;
  std::deque<hal::StateEstimate> history_;  // the last second of state estimates, oldest first
  slam::ConeMap cone_map_;
  std::optional<Vec2> last_base_position_;  // for the finish-line crossing test
  bool go_ = false;
  bool emergency_ = false;
  std::optional<TimeNs> last_tick_;
  TimeNs stop_start_ = 0;
  double stop_speed_ = 0.0;
};

const char* to_string(Mission m);

}  // namespace paddock::stack
