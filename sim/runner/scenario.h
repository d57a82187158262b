#pragma once
// the Scenario: one struct tree compiled from an INI file at the edge of the
// program, with every default filled in and an explicit seed. Nothing inside
// sim/ or autonomy/ reads files; they get pieces of this.
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "autonomy/car/car.h"
#include "autonomy/hal/car_can.h"
#include "autonomy/hal/dbc.h"
#include "autonomy/hal/ouster.h"
#include "autonomy/stack/stack.h"
#include "sim/events/event.h"
#include "sim/sensors/annotation_detector.h"
#include "sim/sensors/cone_sensor.h"
#include "sim/sensors/camera.h"
#include "sim/sensors/imu.h"
#include "sim/sensors/lidar.h"
#include "sim/sensors/odometry_sensors.h"
#include "sim/vehicle/vcu.h"
#include "sim/vehicle/vehicle.h"
#include "sim/world/cone_world.h"
#include "sim/world/track.h"
#include "sim/world/venue.h"
#include "autonomy/common/params.h"
#include "sim/runner/faults.h"
#include "sim/runner/ini.h"
#include "sim/runner/schema.h"

namespace paddock::runner {

// [scenario]
struct ScenarioSection {
  // relative to the file that names it; the resolved scenario writes it absolute
  std::string track;
  events::EventKind event = events::EventKind::Trackdrive;
  // every random draw of the run derives from it (stream_seed)
  std::uint64_t seed = 1;
  // the rules ask for at least 5 s in AS Ready
  // the official gives the go once the car has shown AS Ready this long
  double go_time = 5.0;

  static constexpr params::Choice<events::EventKind> kEvents[] = {{"trackdrive", events::EventKind::Trackdrive},
                                                                  {"autocross", events::EventKind::Autocross},
                                                                  {"acceleration", events::EventKind::Acceleration},
                                                                  {"skidpad", events::EventKind::Skidpad}};
  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(track), "the track CSV file, relative to the file that names it (required)");
    v(PADDOCK_PARAM(event), kEvents, "the FS event and its rules");
    v(PADDOCK_PARAM(seed), {"", params::in(0, 9.2e18), "the run's random seed (every random draw derives from it)"});
    v(PADDOCK_PARAM(go_time), {"s", params::in(0.0, 600.0), "time in AS Ready before the go signal"});
  }
};

// [hal]: what crosses the HAL, and how
enum class Transport {
  // the sensor messages as the stack's structs
  Memory,
  // every sensor message the car's hardware sends on a wire is encoded into
  // its wire format (the LiDAR's UDP packets, CAN frames) and decoded by the
  // car's own decoders, as on the car; the actuator command goes back as a
  // CAN frame
  Wire,
  // the wire's bytes over UDP to a car binary (paddock car, with the same
  // scenario) that runs the stack in its own process, in lock-step: the
  // software-in-the-loop test of the car's binary ([car] says where it listens)
  Udp,
};

struct HalSection {
  Transport transport = Transport::Memory;
  // files relative to the file that names them; the resolved scenario writes
  // them absolute. Empty: none.
  std::string lidar_metadata;
  std::string dbc;

  static constexpr params::Choice<Transport> kTransports[] = {
      {"memory", Transport::Memory}, {"wire", Transport::Wire}, {"udp", Transport::Udp}};
  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(transport), kTransports, "memory: the messages as structs; wire: through their wire formats and the car's decoders; udp: the wire's bytes to a car binary (paddock car) in lock-step");
    v(PADDOCK_PARAM(lidar_metadata), "the LiDAR's metadata file (Ouster sensor_info JSON): the layout the simulated LiDAR casts and the decoder reads");
    v(PADDOCK_PARAM(dbc), "the car's CAN database (DBC): the frames of the IMU, wheel speeds, steering, RES, VCU status and commands");
  }
};

// [sim]
struct SimSection {
  int physics_rate = 1000;
  int control_rate = 100;
  int log_rate = 100;
  double snapshot_time = 12.0;
  // 2: the camera renders (and its detector node reads the frame) on a
  // second thread while the LiDAR casts on the loop's; the same result. No
  // more than kMaxThreads: nothing else of the loop runs beside them
  static constexpr int kMaxThreads = 2;
  int threads = 1;

  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(physics_rate), {"Hz", params::in(1, 100000), "vehicle and world integration rate: a whole multiple of the control, log, VCU and sensor rates"});
    v(PADDOCK_PARAM(control_rate), {"Hz", params::in(1, 100000), "the stack's cycle (and the state estimate's rate)"});
    v(PADDOCK_PARAM(log_rate), {"Hz", params::in(1, 100000), "rows of log.csv, and the event's off-course checks"});
    v(PADDOCK_PARAM(snapshot_time), {"s", params::in(0.0, 1e6), "the first LiDAR scan after this is kept for the perception figures"});
    v(PADDOCK_PARAM(threads), {"", params::in(1, kMaxThreads), "2: the camera renders beside the LiDAR's cast, on a thread of its own (the result is the same)"});
  }
  std::string check() const {
    return physics_rate % control_rate == 0 && physics_rate % log_rate == 0
               ? ""
               : "physics_rate must be a whole multiple of control_rate and log_rate";
  }
};

// [expect]: what a CI scenario must achieve; unset entries are not checked
struct Expectations {
  std::optional<bool> finished;
  std::optional<int> laps;
  std::optional<int> doo_max;
  std::optional<int> oc_max;
  std::optional<int> uss_max;
  std::optional<double> lap_time_max;
  std::optional<double> lap_time_min;
  std::optional<double> total_time_max;
  std::optional<double> lateral_rms_max;
  std::optional<double> lateral_error_max;
  std::optional<int> fallbacks_max;
  std::optional<double> ate_rms_max;
  std::optional<double> ate_max_max;
  std::optional<double> map_recall_min;
  std::optional<double> best_above_limit_max;
  std::optional<bool> emergency;
  std::optional<bool> ebs_within_rules;
  std::optional<double> notice_max;
  std::optional<int> doo_after_fault_max;

  template <class V>
  void visit(V& v) {
    const params::Bounds count = params::in(0, 1000000), positive = params::at_least(0.0);
    v(PADDOCK_PARAM(finished), "the run finishes");
    v(PADDOCK_PARAM(laps), {"", count, "completed laps"});
    v(PADDOCK_PARAM(doo_max), {"", count, "cones down or out, at most"});
    v(PADDOCK_PARAM(oc_max), {"", count, "off-course excursions, at most"});
    v(PADDOCK_PARAM(uss_max), {"", count, "unsafe stops, at most"});
    v(PADDOCK_PARAM(lap_time_max), {"s", positive, "every lap at most"});
    v(PADDOCK_PARAM(lap_time_min), {"s", positive, "every lap at least"});
    v(PADDOCK_PARAM(total_time_max), {"s", positive, "penalised time at most"});
    v(PADDOCK_PARAM(lateral_rms_max), {"m", positive, "RMS lateral error at most"});
    v(PADDOCK_PARAM(lateral_error_max), {"m", positive, "largest lateral error at most"});
    v(PADDOCK_PARAM(fallbacks_max), {"", count, "safe-stop control cycles, at most"});
    v(PADDOCK_PARAM(ate_rms_max), {"m", positive, "the state estimate's RMS position error (ATE) at most"});
    v(PADDOCK_PARAM(ate_max_max), {"m", positive, "the state estimate's largest position error (ATE max) at most"});
    v(PADDOCK_PARAM(map_recall_min), {"", params::fraction(), "the final map's recall (true cones along the path it holds) at least"});
    v(PADDOCK_PARAM(best_above_limit_max), {"", positive, "the best lap's share above the car's limit lap (circuits), at most"});
    v(PADDOCK_PARAM(emergency), "the car goes to AS Emergency (the EBS brakes it to rest)");
    v(PADDOCK_PARAM(notice_max), {"s", positive, "each injected fault noticed by the stack (or the VCU) within this"});
    v(PADDOCK_PARAM(doo_after_fault_max), {"", count, "cones down or out from the first fault on, at most"});
    v(PADDOCK_PARAM(ebs_within_rules), "the EBS fired and stopped the car within the rules' distance from its speed (0.2 s, then 8 m/s^2)");
  }
};

// the whole tree. Its sections are its members, in this order; a nested
// Params struct is a section of its own ([perception.lidar.clustering])
struct Scenario {
  std::string source;      // the file it was read from
  std::string name;        // its stem
  std::string track_path;  // [scenario] track resolved against the naming file's folder

  // what the [hal] files say, read and checked at load (none when unnamed)
  std::optional<hal::ouster::SensorInfo> lidar_info;
  std::shared_ptr<const hal::Dbc> dbc;
  std::string dbc_text;  // the DBC file as read (a run's log carries it)

  ScenarioSection scenario;
  stack::AutonomyModes autonomy;
  HalSection hal;
  car::CarParams car;
  // the car and the world
  vehicle::VehicleParams vehicle;
  vehicle::VcuParams vcu;
  world::ConeWorldParams cones;
  sensors::GroundParams ground;
  world::VenueParams venue;
  events::EventParams event;
  // the sensors
  sensors::ConeSensorParams cone_sensor;
  sensors::LidarParams lidar;
  sensors::CameraParams camera;
  sensors::DetectorParams detector;
  sensors::ImuParams imu;
  sensors::WheelSpeedParams wheel_speeds;
  sensors::SteeringSensorParams steering_sensor;
  // the stack (stack_params adds what it knows of the car and its sensors)
  perception::PerceptionParams perception;
  slam::ConeMapParams cone_map;
  planning::PathPlannerParams planning;
  planning::SkidpadParams skidpad;
  control::ControlParams control;
  stack::MissionParams mission;
  stack::GateParams gates;
  stack::SlamParams slam;
  slam::LioParams lio;
  stack::AsParams as;
  stack::HealthParams health;
  // what goes wrong, the simulation itself, and what a CI run must achieve
  FaultsSection faults;
  SimSection sim;
  Expectations expect;

  template <class V>
  void visit(V& v) {
    v.section(PADDOCK_PARAM(scenario), "the event, its track and the run's seed");
    v.section(PADDOCK_PARAM(autonomy), "where each layer of the stack gets its input: the real module or ground truth");
    v.section(PADDOCK_PARAM(hal), "the HAL between the simulator and the stack: transport and the sensors' wire descriptions");
    v.section(PADDOCK_PARAM(car), "the car binary (paddock car): its sockets, clock and watchdogs; transport = udp sends to it");
    v.section(PADDOCK_PARAM(vehicle), "every physical parameter of the car, all required: include = vehicles/default.ini");
    v.section(PADDOCK_PARAM(vcu), "the car's vehicle control unit and emergency brake system (EBS): status frame, pressures, EBS delay, ACU watchdog");
    v.section(PADDOCK_PARAM(cones), "the cones' physics (Box2D): masses, knock-over impulses, frictions");
    v.section(PADDOCK_PARAM(ground), "the ground the sensors see (the vehicle model stays planar)");
    v.section(PADDOCK_PARAM(venue), "what stands around the track besides the cones: barrier rows the sensors see");
    v.section(PADDOCK_PARAM(event), "the event's limits: timeout, stop, off-track and stall times");
    v.section(PADDOCK_PARAM(cone_sensor), "the object-level cone sensor of perception = ground_truth");
    v.section(PADDOCK_PARAM(lidar), "the rotating LiDAR of perception = lidar | lidar_camera");
    v.section(PADDOCK_PARAM(camera), "the camera the LiDAR triggers (perception = lidar_camera)");
    v.section(PADDOCK_PARAM(detector), "the camera's detector node: the error model of a network (misses, confusions, box jitter)");
    v.section(PADDOCK_PARAM(imu), "the inertial measurement unit");
    v.section(PADDOCK_PARAM(wheel_speeds), "the four wheel-speed sensors");
    v.section(PADDOCK_PARAM(steering_sensor), "the steering-angle sensor");
    v.section(PADDOCK_PARAM(perception), "the stack's perception front (perception = lidar | lidar_camera)");
    v.section(PADDOCK_PARAM(cone_map), "the stack's cone map");
    v.section(PADDOCK_PARAM(planning), "the stack's path planner (planner = delaunay) and reference trajectory");
    v.section(PADDOCK_PARAM(skidpad), "the stack's skidpad mission");
    v.section(PADDOCK_PARAM(control), "the stack's controllers");
    v.section(PADDOCK_PARAM(mission), "the stack's mission logic");
    v.section(PADDOCK_PARAM(gates), "the timekeeping gates the stack learns from big orange cones");
    v.section(PADDOCK_PARAM(slam), "the stack's own state estimation (slam != ground_truth)");
    v.section(PADDOCK_PARAM(lio), "the LiDAR-inertial odometry (slam = lio)");
    v.section(PADDOCK_PARAM(as), "the stack's AS state machine of the rules (ready wait, EBS and brake checks)");
    v.section(PADDOCK_PARAM(health), "the stack's watchdogs and degraded modes (LiDAR lost or sparse, camera lost or frozen, cycle overrun)");
    v.section(PADDOCK_PARAM(faults), "timed faults injected into the car's sensors, computer, bus and safety chain");
    v.section(PADDOCK_PARAM(sim), "the simulation's rates");
    v.section(PADDOCK_PARAM(expect), "what a CI scenario must achieve (unset entries are not checked)");
  }
  // what ties sections together: the physics step must be one the vehicle
  // model integrates stably (vehicle::stable_step_limit)
  std::string check() const;
};

// the overrides of a run of scenario s on n threads (paddock run --threads
// n): the camera beside the LiDAR (sim.threads, at most
// SimSection::kMaxThreads); when s's perception is raw and has a latency
// (its scans' processing can then go on beside the loop), the scans on a
// thread of their own (perception.threads = 2) and FastSLAM's particles
// split n - 1 ways, else split n ways (slam.threads); the same result
std::vector<std::string> thread_overrides(int n, const Scenario& s);

// reads, resolves includes, applies the overrides ("section.key=value"), checks
// every key and value; throws UserError "file:line: ..." on any problem
Scenario load_scenario(const std::string& path, const std::vector<std::string>& overrides = {});
// the same from entries already read (a sweep's point: its base scenario's
// entries, then the sweep's own); `path` names the scenario and its stem
// the run
// `files`, if given, holds files in memory by their absolute path (a log's
// attachments): the LiDAR metadata and the DBC are read from it first
using FileTable = std::map<std::string, std::string>;
Scenario load_scenario_entries(std::vector<IniEntry> entries, const std::string& path,
                               const std::vector<std::string>& overrides = {}, const FileTable* files = nullptr);

// a vehicle parameter file (scenarios/vehicles/default.ini's format: one
// [vehicle] section, includes allowed) read with the scenario's keys and
// checks: an unknown section or key, a bad number, a value out of range or a
// key left unset throws UserError "file:line: ..." ("file: ..." when no line
// is to blame), as in a scenario; so does a car the default physics step
// (1 kHz) cannot integrate stably
vehicle::VehicleParams load_vehicle_file(const std::string& path);

// what the stack's state estimator knows of the car and its IMU: the
// geometry, the IMU's mount, and the tyres' slip and cornering stiffnesses
estimation::CarGeometry car_geometry(const vehicle::VehicleParams& v, const sensors::ImuParams& imu);


// the resolved scenario as INI text: every key, defaults included, in SI units,
// loadable again to the same Scenario
std::string resolved_ini(const Scenario& s);

// a file's text: from `files` when it holds `path`, else from disk
// (read_file: UserError "path: cannot open ...")
std::string read_input(const std::string& path, const FileTable* files);

// reads (as read_input) and parses a track file; throws UserError "path:
// cannot open ..." or world::TrackError "path:line: ..."
world::TrackFile load_track_file(const std::string& path, const FileTable* files = nullptr);

// the seed of one named random stream of a run: every random draw of a run
// comes from the scenario's seed through this function. The streams:
// "cone_sensor", "imu", "wheel_speeds", "steering_sensor", "lidar", "camera",
// "detector", "slam" (the stack's particle filter), "faults" ([faults]); any other name is a
// programming error. Their numbering is fixed: changing it changes every result.
std::uint64_t stream_seed(std::uint64_t scenario_seed, std::string_view stream);

// the stack's parameters as compiled from the scenario (the vehicle knowledge
// comes from the same [vehicle] section as the simulated car)
stack::StackParams stack_params(const Scenario& s);

}  // namespace paddock::runner
