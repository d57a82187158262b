#pragma once
// the Scenario: one struct tree compiled from an INI file at the edge of the
// program, with every default filled in and an explicit seed. Nothing inside
// sim/ or autonomy/ reads files; they get pieces of this.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "autonomy/stack/stack.h"
#include "sim/events/event.h"
#include "sim/sensors/annotation_detector.h"
#include "sim/sensors/cone_sensor.h"
#include "sim/sensors/camera.h"
#include "sim/sensors/imu.h"
#include "sim/sensors/lidar.h"
#include "sim/sensors/odometry_sensors.h"
#include "sim/vehicle/vehicle.h"
#include "sim/world/cone_world.h"
#include "sim/world/track.h"
#include "sim/runner/schema.h"

namespace paddock::runner {

// [scenario]
struct ScenarioSection {
  std::string track;                                  // track CSV, relative to the file that names it
  events::EventKind event = events::EventKind::Trackdrive;
  std::uint64_t seed = 1;                             // every random draw of the run derives from it
  double go_time = 5.0;                               // s in AS Ready before the go signal (rules: at least 5 s)
};

// [sim]
struct SimSection {
  int physics_rate = 1000;  // Hz, vehicle and world integration
  int control_rate = 100;   // Hz, the stack's cycle (and the state estimate's rate)
  int log_rate = 100;       // Hz, rows of log.csv; also the rate of the off-course test
  double snapshot_time = 12.0;  // s: the first scan after this is kept for the perception figures
};

// [expect]: what a CI scenario must achieve; unset entries are not checked
struct Expectations {
  std::optional<bool> finished;
  std::optional<int> laps;
  std::optional<int> doo_max;
  std::optional<int> oc_max;
  std::optional<int> uss_max;
  std::optional<double> lap_time_max;        // s, every completed lap
  std::optional<double> lap_time_min;        // s, every completed lap
  std::optional<double> total_time_max;      // s, penalised
  std::optional<double> lateral_rms_max;     // m
  std::optional<double> lateral_error_max;   // m
  std::optional<int> fallbacks_max;          // control cycles in the safe stop
};

struct Scenario {
  std::string source;   // the file it was read from
  std::string name;     // its stem
  std::string track_path;  // [scenario] track resolved against the naming file's folder

  ScenarioSection scenario;
  stack::AutonomyModes autonomy;
  sensors::ConeSensorParams cone_sensor;  // [cone_sensor]: the object-level sensor of perception = ground_truth
  sensors::ImuParams imu;                 // [imu]
  sensors::WheelSpeedParams wheel_speeds;  // [wheel_speeds]
  sensors::SteeringSensorParams steering_sensor;  // [steering_sensor]
  sensors::LidarParams lidar;             // [lidar]: the rotating LiDAR of perception = lidar, lidar_camera
  sensors::CameraParams camera;           // [camera]: the camera of perception = lidar_camera
  sensors::DetectorParams detector;       // [detector]: the camera's detector node (its error model)
  // [perception]: the stack's perception front (perception = lidar |
  // lidar_camera); its calibration is filled from [lidar] and [camera]
  perception::PerceptionParams perception;
  sensors::GroundParams ground;           // [ground]: the ground's shape, as the sensors see it
  vehicle::VehicleParams vehicle;
  control::ControlParams control;
  planning::PathPlannerParams planning;
  planning::SkidpadParams skidpad;
  stack::MissionParams mission;
  slam::ConeMapParams cone_map;  // [slam]: the cone map of slam = ground_truth
  world::ConeWorldParams cones;
  events::EventParams event;
  SimSection sim;
  Expectations expect;
};

// reads, resolves includes, applies the overrides ("section.key=value"), checks
// every key and value; throws UserError "file:line: ..." on any problem
Scenario load_scenario(const std::string& path, const std::vector<std::string>& overrides = {});


// the resolved scenario as INI text: every key, defaults included, in SI units,
// loadable again to the same Scenario
std::string resolved_ini(const Scenario& s);

// reads and parses a track file; throws UserError "path: cannot open ..." or
// world::TrackError "path:line: ..."
world::TrackFile load_track_file(const std::string& path);

// the seed of one named random stream of a run: every random draw of a run
// comes from the scenario's seed through this function. The streams:
// "cone_sensor", "imu", "wheel_speeds", "steering_sensor", "lidar", "camera",
// "detector"; any other name is a programming error. Their numbering is fixed:
// changing it changes every result.
std::uint64_t stream_seed(std::uint64_t scenario_seed, std::string_view stream);

// the stack's parameters as compiled from the scenario (the vehicle knowledge
// comes from the same [vehicle] section as the simulated car)
stack::StackParams stack_params(const Scenario& s);

}  // namespace paddock::runner
