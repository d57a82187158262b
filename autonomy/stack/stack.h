#pragma once
// the autonomy pipeline behind the HAL: the AS state machine, the mission
// logic of each event, the cone map, planning and control at the control rate.
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "autonomy/common/geometry.h"
#include "autonomy/common/params.h"
#include "autonomy/common/profile.h"
#include "autonomy/common/time.h"
#include "autonomy/common/trajectory.h"
#include "autonomy/control/controller.h"
#include "autonomy/hal/hal.h"
#include "autonomy/perception/perception.h"
#include "autonomy/planning/path_planner.h"
#include "autonomy/planning/skidpad.h"
#include "autonomy/slam/cone_map.h"
#include "autonomy/stack/as_machine.h"
#include "autonomy/stack/gates.h"
#include "autonomy/stack/health.h"
#include "autonomy/stack/localisation.h"
#include "autonomy/stack/perception_stage.h"

namespace paddock::stack {

// where each layer's input comes from (the scenario's [autonomy] section)
// perception: ground_truth = the simulator's object-level cone sensor posts
// cone detections; lidar = the LiDAR pipeline on raw scans (intensity colour);
// lidar_camera = the LiDAR pipeline fused with the camera detector's boxes
enum class PerceptionMode { GroundTruth, Lidar, LidarCamera };
enum class PlannerMode { Oracle, Delaunay };

struct AutonomyModes {
  static constexpr params::Choice<PerceptionMode> kPerceptionNames[] = {
      {"ground_truth", PerceptionMode::GroundTruth}, {"lidar", PerceptionMode::Lidar}, {"lidar_camera", PerceptionMode::LidarCamera}};
  static constexpr params::Choice<SlamMode> kSlamNames[] = {
      {"ground_truth", SlamMode::GroundTruth},
      {"odometry", SlamMode::Odometry},
      {"fastslam", SlamMode::FastSlam},
      {"fastslam_graph", SlamMode::FastSlamGraph},
      {"lio", SlamMode::Lio},
      {"lio_graph", SlamMode::LioGraph}};
  static constexpr params::Choice<PlannerMode> kPlannerNames[] = {{"delaunay", PlannerMode::Delaunay},
                                                                  {"oracle", PlannerMode::Oracle}};
  PerceptionMode perception = PerceptionMode::GroundTruth;
  SlamMode slam = SlamMode::GroundTruth;
  PlannerMode planner = PlannerMode::Delaunay;

  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(perception), kPerceptionNames, "where the cones come from");
    v(PADDOCK_PARAM(slam), kSlamNames, "where the pose comes from");
    v(PADDOCK_PARAM(planner), kPlannerNames, "where the reference path comes from");
  }
};

// the dynamic events of the FS rules, as selected on the car's mission switch
enum class Mission { Acceleration, Skidpad, Autocross, Trackdrive };

struct MissionParams {
  // the stop after the finish: the speed cap ramps down at
  // v_finish^2 / (2 stop_distance), at least stop_decel and at most
  // stop_decel_max; on the last lap the car approaches the finish no faster
  // than it can stop from in stop_distance at stop_decel_max (braking to it
  // at stop_decel_max). The rules allow 30 m; the rest of them is for the
  // speed loop's lag and the braking's build-up. Both share the grip with
  // the turn: braking and the path's v^2 |kappa| stay within a friction
  // circle of radius stop_decel_max (a finish in mid-corner is approached
  // slower, and the stop brakes less while the path still turns).
  double stop_decel = 8.0;
  double stop_distance = 20.0;
  double stop_decel_max = 12.0;
  double standstill_speed = 0.05;
  double state_timeout = 0.2;
  // a car at rest needs a reference above zero to start on
  double launch_speed = 2.0;
  // trackdrive: a closed centreline is the lap, planned once and driven from
  // then on, when the car has driven at least loop_closure_distance and is
  // back within loop_closure_radius of where it started: then every cone of
  // the lap has been seen; earlier closures are the search cutting across a
  // map still being explored
  double loop_closure_distance = 100.0;
  double loop_closure_radius = 15.0;
  // a closed lap the car drives (before it is taken for good at the start)
  // is planned again only when the map is no longer the one it was planned
  // on: a cone added, lost or of another colour, or one moved by more than
  // this. Planned again on the same map it is the same ring of midpoints
  // (its spline begun elsewhere on it); planned every frame, the whole
  // lap's search and profile were half a run's planning time (FSG 2023 on
  // the true cones), spent in the first lap's last 40 m
  double lap_replan_tolerance = 0.05;
  // so the handover does not jerk the car sideways
  double lap_switch_offset = 0.1;
  // ... and heads within this of the car's heading: a racing line crosses
  // the exploring path at an angle, and taking it over there at speed
  // swings the car across it
  double lap_switch_heading = 0.1;
  // a timekeeping gate is learned from big orange cones seen at least
  // gate_min_observations times as big orange cones (their votes: a cone
  // seen as small often and as big once, by a ghost that fell on it, is no
  // post) whose gate's middle lies within
  // gate_max_offset of the planned path: a ghost cone of perception must not
  // become a finish line
  int gate_min_observations = 5;
  double gate_max_offset = 2.0;
  // a line marked by two rows of big orange cones is one line
  double gate_refractory_distance = 10.0;
  // 75 m to the finish and the braking zone after it
  double acceleration_length = 150.0;
  // the rules' start position; the first guess of the alignment
  double skidpad_crossing_ahead = 16.5;
  int skidpad_min_cones = 20;

  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(stop_decel), {"m/s^2", params::in(0.1, 50.0), "least deceleration of the stop after the finish"});
    v(PADDOCK_PARAM(stop_distance), {"m", params::in(1.0, 1000.0), "the stop after the finish is planned to end within this"});
    v(PADDOCK_PARAM(stop_decel_max), {"m/s^2", params::in(0.1, 50.0), "hardest planned stop, and the approach to the finish on the last lap"});
    v(PADDOCK_PARAM(standstill_speed), {"m/s", params::in(0.0, 5.0), "below this the stack counts as stopped"});
    v(PADDOCK_PARAM(state_timeout), {"s", params::in(0.001, 10.0), "a staler state estimate triggers the safe stop"});
    v(PADDOCK_PARAM(launch_speed), {"m/s", params::at_least(0.0), "the least start speed of a planned profile"});
    v(PADDOCK_PARAM(loop_closure_distance), {"m", params::in(0.0, 10000.0), "driving before a closed centreline is the lap"});
    v(PADDOCK_PARAM(loop_closure_radius), {"m", params::in(0.0, 10000.0),
                                           "the car must be this close to its start for the lap to be taken (0: anywhere)"});
    v(PADDOCK_PARAM(lap_replan_tolerance), {"m", params::in(0.0, 10.0),
                                            "a closed lap is planned again when a mapped cone moved more than this since it was planned, or cones came or went (0: every frame)"});
    v(PADDOCK_PARAM(lap_switch_offset), {"m", params::in(0.0, 10.0), "the closed lap takes over where the car is this close to it"});
    v(PADDOCK_PARAM(lap_switch_heading), {"rad", params::in(0.0, 3.2), "... and where it heads within this of the car's heading"});
    v(PADDOCK_PARAM(gate_min_observations), {"", params::at_least(1), "a timekeeping gate is learned from big orange cones seen this often ..."});
    v(PADDOCK_PARAM(gate_max_offset), {"m", params::at_least(0.0), "... whose gate's middle lies this close to the planned path"});
    v(PADDOCK_PARAM(gate_refractory_distance), {"m", params::at_least(0.0), "gate crossings closer together than this count once"});
    v(PADDOCK_PARAM(acceleration_length), {"m", params::above(0.0), "acceleration: the straight is planned this far from the start"});
    v(PADDOCK_PARAM(skidpad_crossing_ahead), {"m", params::at_least(0.0),
                                              "skidpad: the car's base starts this far before the timekeeping line at the crossing"});
    v(PADDOCK_PARAM(skidpad_min_cones), {"", params::at_least(0), "skidpad: mapped cones needed before the layout is aligned"});
  }
};

struct StackParams {
  AutonomyModes autonomy;
  // perception = lidar | lidar_camera (use_camera follows the mode)
  perception::PerceptionParams perception;
  // its reference params serve the oracle mode too
  planning::PathPlannerParams planning;
  planning::SkidpadParams skidpad;
  control::ControlParams control;
  // not visited: the runner fills it from the vehicle ([vehicle]); check()
  // checks it
  control::VehicleKnowledge vehicle;
  MissionParams mission;
  slam::ConeMapParams cone_map;
  GateParams gates;
  SlamParams slam;
  AsParams as;
  HealthParams health;

  template <class V>
  void visit(V& v) {
    v.section(PADDOCK_PARAM(autonomy), "where each layer's input comes from");
    v.section(PADDOCK_PARAM(perception), "the perception front (perception = lidar | lidar_camera)");
    v.section(PADDOCK_PARAM(planning), "one planning cycle (planner = delaunay); its reference serves the oracle mode too");
    v.section(PADDOCK_PARAM(skidpad), "the skidpad's precalculated path and its alignment");
    v.section(PADDOCK_PARAM(control), "the lateral law and the speed loop");
    v.section(PADDOCK_PARAM(mission), "the mission logic of each event");
    v.section(PADDOCK_PARAM(cone_map), "the stack's map of cones");
    v.section(PADDOCK_PARAM(gates), "timekeeping gates from the big orange cones");
    v.section(PADDOCK_PARAM(slam), "the stack's own state estimation (slam != ground_truth)");
    v.section(PADDOCK_PARAM(as), "the rules' autonomous system state machine");
    v.section(PADDOCK_PARAM(health), "the stack's watch over its inputs and cycle, and its degraded modes");
  }
  std::string check() const {
    const std::string why = params::validate(vehicle);
    return why.empty() ? "" : "vehicle." + why;
  }
};

// what the car is told before the start
struct MissionSpec {
  Mission mission = Mission::Trackdrive;
  // gate crossings after which the car stops (trackdrive: 11, the first one
  // starts lap 1; acceleration: 2, the start and the finish gate); 0: drive to
  // the end of an open path and stop there (skidpad)
  int finish_crossings = 0;
  // timekeeping gates known in advance {left post, right post} (forward crosses
  // right to left); planner = delaunay learns them from big orange cones
  std::vector<Segment> gates;
  // planner = oracle: the reference path (a centreline) known in advance
  std::vector<Vec2> oracle_path;
  bool oracle_closed = false;
  // where the team placed the car on the grid (the base frame's pose): the
  // origin of the stack's own estimate (slam != ground_truth); the identity
  // when unknown
  Pose2 start_pose;
};

// what the stack reports of itself each cycle (telemetry, for logs)
struct Telemetry {
  hal::AsState as_state = hal::AsState::Off;
  control::Diagnostics control;
  bool control_ok = true;
  int finish_crossings = 0;   // gate crossings counted by the stack
  bool stopping = false;      // the mission is over and the car brakes to a stop
  int fallbacks = 0;          // control cycles that ran the safe stop instead of the plan
  std::string last_fault;     // the reason of the last fallback or planning failure
  int mapped_cones = 0;       // cones in the stack's map (seen often enough)
  int plans = 0;              // planning cycles run
  int plan_failures = 0;      // planning cycles that kept the previous trajectory
  bool lap_locked = false;    // the full closed lap is planned and driven
};

class Stack {
 public:
  // detector: perception = lidar_camera with the network in the stack, run on
  // the camera frames; none when a detector node posts its boxes through the
  // HAL (the simulator's does)
  Stack(const StackParams& params, MissionSpec spec, std::unique_ptr<perception::ConeDetector> detector = nullptr);

  // drains the HAL's messages, plans when there is news, runs one control
  // cycle, sends one command
  void tick(TimeNs now, hal::Hal& hal);
  // a fault the stack cannot drive with (the car binary's watchdogs: a
  // sensor went silent): AS Emergency from the next cycle on (from Ready or
  // Driving; AS Off stays Off, waiting for it), latched; `reason` becomes the
  // last fault
  void emergency(const std::string& reason);

  const Telemetry& telemetry() const { return telemetry_; }
  // the AS state machine: its state, transitions and what it waits for
  const AsMachine& as_machine() const { return as_; }
  // what the stack noticed of its inputs and cycle, and its degraded modes
  const Health& health() const { return health_; }
  const Trajectory& trajectory() const { return trajectory_; }
  const slam::ConeMap& cone_map() const { return cone_map_; }
  // slam != ground_truth: the stack's own localisation, else null
  const Localisation* localisation() const { return localisation_ ? &*localisation_ : nullptr; }
  // the state estimate the stack drives on (the newest), if any
  const std::optional<hal::StateEstimate>& estimate() const { return state_; }
  // the last planning cycle's result (planner = delaunay), for plots
  const planning::PlanResult& last_plan() const { return last_plan_; }
  // the map the last plan was made on (its triangulation indexes these)
  const std::vector<Cone>& last_plan_cones() const { return last_plan_cones_; }
  const std::vector<Segment>& gates() const { return gates_; }
  // perception = lidar | lidar_camera: the pipeline as the stack runs it
  // (the frame it delivered last, its stats), else null
  PerceptionStage* perception() { return perception_.get(); }
  // the last frame of cones perception delivered (base frame at its stamp) and
  // how many frames came so far: for the perception metrics
  const hal::ConeDetections& last_detections() const { return last_detections_; }
  long detection_frames() const { return detection_frames_; }
  // the frames whose SLAM update ran beside the loop, on the perception's
  // thread (slam_beside_; the rest were mapped on the stack's thread)
  long slam_steps_beside() const { return slam_steps_beside_; }
  // where the stack's time goes, by stage (perception, localisation,
  // planning, control), timed into `profile` from now on; null: not timed
  void set_profile(Profile* profile) { profile_ = profile; }

 private:
  void on_message(hal::SensorMessage&& m);
  // a state estimate the stack now drives on (handed in, or its own)
  void take_estimate(const hal::StateEstimate& est);
  // stepped: the frame's SLAM step, done beside the loop (published here)
  void on_detections(const hal::ConeDetections& d, SlamStep* stepped = nullptr);
  // perception's frames due by now, into the map
  void deliver_perception(TimeNs now);
  void add_to_map(const hal::ConeDetections& d);
  // the base pose at time t from the recent state estimates (interpolated), if known
  std::optional<Pose2> pose_at(TimeNs t) const;
  // planner = delaunay: a new plan from the cone map when the map has news
  void plan(const hal::StateEstimate& st);
  // the closed lap the car drives still stands on this map (MissionParams::lap_replan_tolerance)
  bool lap_still_holds(const hal::StateEstimate& st, const std::vector<Cone>& cones) const;
  void learn_gates(const Pose2& pose, TimeNs now, double speed);
  // on the last lap: the fastest speed from which the car can still brake to
  // the finish speed that stops within the stop distance (infinite otherwise)
  double finish_approach_cap(Vec2 base) const;
  // the highest speed at arc length s of the trajectory from which the car
  // brakes to rest within `to_rest` metres further along it, braking and the
  // path's turn sharing a friction circle of radius a (infinite when above
  // every speed of the trajectory)
  double stop_speed_cap(double s, double to_rest, double a) const;
  // the stop's deceleration now: `nominal` where the turn leaves it the grip
  double stop_deceleration(const hal::StateEstimate& st, double nominal) const;
  // the lap that just took over, ramped up from the car's speed
  void catch_up(const hal::StateEstimate& st);
  void count_crossings(Vec2 base, TimeNs now, double speed);
  // counts a crossing made at driven distance `at` (m) unless it is within the
  // refractory distance of the last one; true when counted
  bool count_crossing(double at, TimeNs now, double speed);
  // where the driven path crossed g since the last counted crossing (the
  // latest such crossing): the motion's direction there and the driven
  // distance (m)
  std::optional<std::pair<Vec2, double>> crossed_since_last(const Segment& g, Vec2 base) const;
  // the map still holds both posts of g among `posts` (find_posts of gate_cones)
  static bool gate_still_seen(const Segment& g, const std::vector<Vec2>& posts);
  // the map's big orange cones seen as big at least gate_min_observations
  // times (votes), what the gates are found in
  std::vector<Cone> gate_cones() const;
  void start_stopping(TimeNs now, double speed);
  hal::ActuatorCommand safe_stop(TimeNs now, const std::string& reason);
  // what the machine sees this cycle
  AsInputs as_inputs(bool mission_done);
  // AS Emergency: the steering along the trajectory while the EBS brakes
  // (0 when there is no fresh estimate or trajectory)
  double emergency_steering(TimeNs now, double dt);

  // the trajectory driven from now on (every assignment goes through here)
  void set_trajectory(Trajectory t);

  StackParams params_;
  MissionSpec spec_;
  Trajectory trajectory_;
  std::uint64_t trajectory_version_ = 0;  // counts set_trajectory()
  std::uint64_t speeds_version_ = 0;      // counts every change of its speeds (set_trajectory() too)
  // stop_speed_cap's highest speed of the trajectory, for speeds version top_version_
  mutable double top_speed_ = 0.0;
  mutable std::uint64_t top_version_ = 0;
  // finish_approach_cap's gates on trajectory_ (arc length, offset), kept
  // for the trajectory version and the gates they were projected for (at
  // first none, for version 0: no trajectory, nothing asked)
  struct GateOnPath {
    double s = 0.0, offset = 0.0;
  };
  mutable std::vector<GateOnPath> gates_on_path_;
  mutable std::vector<Segment> gates_projected_;
  mutable std::uint64_t gates_projected_version_ = 0;
  // and the car's arc length on it last cycle, for that trajectory version
  mutable double car_s_ = 0.0;
  mutable std::uint64_t car_projected_version_ = 0;
  control::Controller controller_;
  Telemetry telemetry_;
  Profile* profile_ = nullptr;

  // slam != ground_truth: the stack's own estimate, from the HAL's sensors
  std::optional<Localisation> localisation_;
  // SLAM beside the loop ([perception] threads = 2 with a latency, slam =
  // fastslam | fastslam_graph): each scan's frame is stepped through SLAM
  // on the perception's thread once the odometry has reached its stamp, and
  // published when the frame is delivered (Localisation::step, publish).
  // The frames in flight, oldest first: each with its job, whether its step
  // was posted, and the step
  struct SlamInFlight {
    TimeNs stamp = 0;
    std::uint64_t job = 0;
    bool stepped = false;
    std::unique_ptr<SlamStep> step;
  };
  bool slam_beside_ = false;
  long slam_steps_beside_ = 0;
  std::deque<SlamInFlight> slam_in_flight_;
  std::vector<std::unique_ptr<SlamStep>> slam_spare_;
  // the steps of the frames in flight whose odometry has come, in order
  void post_slam_steps();
  // perception = lidar | lidar_camera (last: its thread, which runs the
  // SLAM steps, ends before the localisation and the steps go)
  std::unique_ptr<PerceptionStage> perception_;
  std::optional<hal::StateEstimate> state_;
  std::deque<hal::StateEstimate> history_;  // the last second of state estimates, oldest first
  slam::ConeMap cone_map_;
  bool map_news_ = false;                   // detections since the last plan
  std::deque<hal::ConeDetections> waiting_;  // frames newer than the newest state estimate
  hal::ConeDetections last_detections_;
  long detection_frames_ = 0;
  planning::PlanResult last_plan_;
  std::vector<Cone> last_plan_cones_;       // the map last_plan_ was planned on
  Trajectory pending_lap_;                  // the closed lap, waiting for a smooth handover
  std::vector<double> lap_speed_;           // the lap's own speeds while its first metres ramp up to them
  std::optional<double> catch_up_until_;    // driven_ where the ramp meets the lap's speeds (m)
  std::vector<Segment> gates_;              // known and learned timekeeping gates
  std::optional<Vec2> last_base_position_;  // for the gate crossing test
  double driven_ = 0.0;                     // distance driven (m)
  std::optional<Vec2> start_position_;      // where the car began to drive
  // driven_ when a trackdrive's lap could first have been locked but the
  // pose graph had not closed the loop yet (Stack::plan)
  std::optional<double> lap_ready_at_;
  double last_crossing_at_ = -1e9;          // driven_ at the last counted crossing (m)
  // the base positions driven since the last counted crossing, with driven_
  // at each (one every kPathMarkSpacing m): a gate first seen after the car
  // crossed it (its cones beside the car at the start, out of the sensors'
  // view) still counts
  std::vector<std::pair<Vec2, double>> path_marks_;
  AsMachine as_;
  Health health_;
  TimeNs now_ = 0;                     // the cycle draining the messages
  std::optional<hal::VcuStatus> vcu_;  // the VCU's last status
  bool go_ = false;                    // a go came since the last cycle
  bool emergency_ = false;             // the RES's emergency stop, latched
  std::string fault_;                  // a fault the stack cannot drive with, latched
  std::optional<TimeNs> last_tick_;
  TimeNs stop_start_ = 0;
  double stop_speed_ = 0.0;
  // the speed the stop's ramp gave up to the turn's grip so far (m/s)
  double stop_held_ = 0.0;
};

const char* to_string(Mission m);
// what the car's mission selector shows for a mission
hal::MissionCode mission_code(Mission m);
// the scenario's names: ground_truth, lidar, lidar_camera
const char* to_string(PerceptionMode m);
const char* to_string(SlamMode m);

}  // namespace paddock::stack
