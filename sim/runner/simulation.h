#pragma once
// the closed loop as model, state and step (MuJoCo's mj_step(m, d)):
//   SimModel  constant, compiled once from the scenario (model.h)
//   SimState  everything that changes: the car, the cones, the event, the
//             stack, the sensors and their random streams, the messages in
//             flight, the true poses of the last second
//   step()    one physics step, then what falls due at the new instant: the
//             sensors into the sim HAL, the stack's control cycle, the event's
//             sample
// Observers (observers.h) watch from outside the loop. run() is "step until
// the event is done". States share nothing: two simulations of one model run
// side by side on two threads exactly as each runs alone.
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "autonomy/common/profile.h"
#include "autonomy/stack/stack.h"
#include "sim/events/event.h"
#include "sim/runner/faults.h"
#include "sim/runner/limit_report.h"
#include "sim/runner/model.h"
#include "sim/runner/observers.h"
#include "sim/runner/perception_metrics.h"
#include "sim/runner/raw_sensors.h"
#include "sim/runner/scenario.h"
#include "sim/runner/sim_hal.h"
#include "sim/sensors/cone_sensor.h"
#include "sim/sensors/imu.h"
#include "sim/sensors/odometry_sensors.h"
#include "sim/vehicle/vcu.h"
#include "sim/vehicle/vehicle.h"
#include "sim/world/cone_world.h"
#include "sim/world/track.h"

namespace paddock::runner {

// the emergency brake system's stop, measured on the car (ground truth)
struct EbsStop {
  bool fired = false;
  std::string cause;                 // what fired it (the VCU's words)
  double t = 0.0;                    // s, when it fired
  double speed = 0.0;                // m/s at that instant
  double distance = 0.0;             // m driven since, to standstill
  std::optional<double> stopped_at;  // s, at rest (none: still rolling when the run ended)
  // the mean deceleration from the trigger to rest, v0 / time (m/s^2)
  double mean_decel() const {
    return stopped_at && *stopped_at > t ? speed / (*stopped_at - t) : 0.0;
  }
};

// the rules' EBS requirement at a speed: the distance within which the car
// must stop from the EBS's trigger. FS Rules 2024 T 15.3 allow 200 ms from the
// trigger to the start of braking, and the EBS test (IN 6.3) asks a car at
// 40 km/h to stop within 10 m of the RES's trigger: 200 ms of reaction and a
// mean deceleration of 8 m/s^2 give 9.94 m there, so those two figures are
// the requirement at any speed
inline constexpr double kEbsRulesReaction = 0.2;  // s
inline constexpr double kEbsRulesDecel = 8.0;     // m/s^2
inline double ebs_rules_distance(double speed) {
  return speed * kEbsRulesReaction + speed * speed / (2.0 * kEbsRulesDecel);
}

struct SimState {
  // the world at t = 0 (car at the start pose, at rest, brakes on; cones in
  // place; every sensor's random stream seeded), with what falls due at t = 0
  // already run. The model must outlive the state.
  // tap: who watches the HAL's traffic from the first instant on (a run's log)
  explicit SimState(const SimModel& model, WireTap* tap = nullptr);
  SimState(const SimState&) = delete;
  SimState& operator=(const SimState&) = delete;

  long k = 0;  // physics steps taken
  // the steps until each periodic part falls due again: k % every == 0,
  // counted down (each starts at 1: everything falls due at k = 0)
  StepPeriods due_in;
  TimeNs now = 0;
  double t = 0.0;  // s, k dt
  bool done = false;  // the event is over (finish or DNF): step no more

  vehicle::VehicleState car;
  Vec2 nose;  // the car's nose in the map now (where the next step's motion starts)
  world::ConeWorld cones;
  events::Event event;
  stack::Stack stack;
  SimHal hal;
  vehicle::DriverInput input{0.0, 0.0, 1.0};  // the stack's last command, as the actuators take it
  hal::AsState as_state = hal::AsState::Off;
  // the car's VCU and EBS between the stack's command and the actuators
  vehicle::Vcu vcu;
  std::optional<TimeNs> ready_since;  // when the car first showed AS Ready (the official's clock)
  bool go_sent = false;
  EbsStop ebs;
  FaultInjector faults;  // [faults] at work
  std::optional<vehicle::Car> wet;  // the car in the rain ([faults.rain]), once it rains
  int control_cycles = 0;
  // what the current instant ran
  bool sensed = false;      // a sensor frame: the cone sensor's, or a LiDAR rotation (and its camera frame)
  bool controlled = false;  // a control cycle
  bool sampled = false;     // the event's sample (and a log row)

  // perception = ground_truth: the object-level sensor; its frames reach the
  // HAL after their latency (delivery time, frame)
  sensors::ConeSensor cone_sensor;
  std::deque<std::pair<TimeNs, hal::ConeDetections>> in_flight;
  std::vector<Cone> cones_now;        // scratch: the cones as they stand
  std::vector<bool> cones_knocked;
  // perception = lidar | lidar_camera: the LiDAR and the camera it triggers
  std::unique_ptr<RawSensors> raw;
  sensors::Imu imu;
  hal::Imu last_imu;  // the IMU's last sample, as posted
  sensors::WheelSpeedSensor wheel_speeds;
  sensors::SteeringSensor steering;

  // the truth behind the sensors, for the observers: the true base poses of
  // the last second, and per sensor frame (stamp) the cones it could see (the
  // LiDAR hit them, or the cone sensor had them in view unoccluded)
  PoseHistory true_poses;
  std::deque<std::pair<TimeNs, std::vector<bool>>> visible;

  // where the wall time goes, by stage: the physics, the sensors and the
  // stack time themselves into it (run() starts it; untimed until then)
  Profile profile;
};

// advances the state one physics step (the car, the cones it may hit, the
// timing gates), then runs what falls due at the new instant. Must not be
// called once state.done.
void step(const SimModel& model, SimState& state);

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

struct RunResult {
  events::Result event;
  PlanSnapshot plan;
  std::vector<ConeHit> cones_hit;
  std::vector<LapTracking> lap_tracking;  // one per completed lap
  Tracking tracking;
  std::vector<LogRow> log;
  double sim_time = 0.0;   // s
  double wall_time = 0.0;  // s
  double energy = 0.0;     // J drawn from the accumulator over the run, regeneration counted off
  int fallbacks = 0;       // control cycles in the safe stop
  std::string fault;       // the stack's last fault, if any
  int cycles = 0;          // control cycles run
  EbsStop ebs;             // the EBS's stop, if it fired
  // the stack's AS state machine: its transitions (none when the stack runs
  // in the car binary)
  std::vector<stack::AsTransition> as_transitions;
  // the faults injected ([faults]), and what the stack noticed of its inputs
  std::vector<FaultNote> faults;
  std::vector<stack::HealthEvent> health;
  // transport = udp: the stack ran in the car binary, so what is measured
  // inside it (tracking, the estimate, the map, fallbacks, perception) is
  // not known here
  bool stack_remote = false;
  PerceptionMetrics perception;  // the stack's perceived cones against the truth, per range bin
  SlamMetrics slam;              // the stack's state estimate against the truth
  std::optional<PerceptionSnapshot> snapshot;
  // the car's limit on a circuit: `paddock report limit`'s lines and its
  // limit lap (the QSS on the minimum-curvature line 1 m from the
  // boundaries, s), computed beside the run; nothing for other tracks, or
  // when they cannot be built
  std::optional<LimitLines> limit;
  std::optional<double> limit_lap;
  // the run's wall time by stage (a measurement of the machine, as wall_time)
  Profile profile;
  // the closed loop's page faults (its thread's: pages first touched, or
  // read from the disk), and the process's peak resident memory (MiB)
  long page_faults = 0;
  double peak_rss_mb = 0.0;
};

// runs one scenario to its end (finish or DNF); deterministic for a given
// scenario and build, apart from wall_time. `extra`: observers the caller
// adds (a run's log), after the run's own
RunResult run(const Scenario& scenario, const world::TrackModel& track, const std::vector<Observer*>& extra = {},
              WireTap* tap = nullptr);

}  // namespace paddock::runner
