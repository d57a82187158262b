#include "sim/runner/scenario.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <filesystem>
#include <functional>
#include <map>
#include <set>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <tuple>
#include <utility>

#include "sim/runner/files.h"
#include "sim/runner/ini.h"
#include "sim/runner/schema.h"

namespace paddock::runner {
namespace {

// keys renamed when the sections began to follow the struct paths
// (2026-11): an old key's error names its new place
constexpr std::pair<const char*, const char*> kRenamed[] = {
    {"perception.cluster_tolerance", "perception.lidar.clustering.tolerance"},
    {"perception.cluster_max_range", "perception.lidar.clustering.max_range"},
    {"perception.camera_range", "perception.fusion.camera_range"},
    {"perception.box_margin", "perception.fusion.box_margin"},
    {"cones.small_mass", "cones.small_cone.mass"},
    {"cones.small_knock_impulse", "cones.small_cone.knock_impulse"},
    {"cones.big_mass", "cones.big_cone.mass"},
    {"cones.big_knock_impulse", "cones.big_cone.knock_impulse"},
    {"cones.car_friction", "cones.car_cone_friction"},
    {"cones.car_restitution", "cones.car_cone_restitution"},
    {"control.stanley_k", "control.stanley.k"},
    {"control.stanley_k_soft", "control.stanley.k_soft"},
    {"control.stanley_steady_state_yaw", "control.stanley.use_steady_state_yaw"},
    {"control.pp_lookahead_min", "control.pure_pursuit.L_min"},
    {"control.pp_lookahead_gain", "control.pure_pursuit.k_v"},
    {"control.k_min", "control.combined.k_min"},
    {"control.k_max", "control.combined.k_max"},
    {"control.kappa_ref", "control.combined.kappa_ref"},
    {"control.k_curve", "control.combined.k_curve"},
    {"control.speed_kp", "control.longitudinal.kp"},
    {"control.speed_ki", "control.longitudinal.ki"},
    {"control.speed_integral_limit", "control.longitudinal.integral_limit"},
    {"control.speed_feedforward", "control.longitudinal.feedforward_gain"},
    {"control.speed_preview", "control.longitudinal.speed_preview_time"},
    {"planning.knot_spacing", "planning.reference.knot_spacing"},
    {"planning.ds", "planning.reference.ds"},
    {"planning.ax_max", "planning.reference.profile.ax_max"},
    {"planning.ay_max", "planning.reference.profile.ay_max"},
    {"planning.ax_brake_max", "planning.reference.profile.ax_brake_max"},
    {"planning.exponent", "planning.reference.profile.exponent"},
    {"planning.ax_machine", "planning.reference.profile.ax_machine"},
    {"planning.v_max", "planning.reference.profile.v_max"},
    {"planning.turn_accel_scale", "planning.reference.profile.turn_accel_scale"},
    {"slam.association_distance", "cone_map.association_distance"},
    {"slam.min_observations", "cone_map.min_observations"},
    {"planning.horizon_depth", "planning.search.horizon_depth"},
    {"planning.first_beam_width", "planning.search.first_beam_width"},
    {"planning.beam_width", "planning.search.beam_width"},
    {"planning.smoothing_window", "planning.smoothing.window"},
    {"planning.opheim_min_tol", "planning.smoothing.opheim_min_tol"},
    {"planning.opheim_max_tol", "planning.smoothing.opheim_max_tol"},
    {"planning.clearance", "planning.clearance.clearance"},
    {"planning.smoothing", "planning.smoothing.method"},
    {"planning.search_radius", "planning.search.search_radius"},
    {"planning.min_step", "planning.search.min_step"},
    {"planning.max_turn", "planning.search.max_turn"},
    {"planning.min_clearance", "planning.search.min_clearance"},
    {"planning.weight_colour", "planning.search.weight_colour"},
    {"planning.weight_width", "planning.search.weight_width"},
    {"planning.weight_angle", "planning.search.weight_angle"},
    {"planning.weight_step", "planning.search.weight_step"},
    {"planning.weight_prediction", "planning.search.weight_prediction"},
    {"planning.weight_crossing", "planning.search.weight_crossing"},
    {"planning.colour_radius", "planning.search.colour_radius"},
    {"planning.width_min", "planning.search.width_min"},
    {"planning.width_max", "planning.search.width_max"},
    {"planning.width_sigma", "planning.search.width_sigma"},
    {"planning.angle_sigma", "planning.search.angle_sigma"},
    {"planning.step_preferred", "planning.search.step_preferred"},
    {"planning.step_sigma", "planning.search.step_sigma"},
    {"planning.prediction_sigma", "planning.search.prediction_sigma"},
    {"planning.min_reward", "planning.search.min_reward"},
    {"planning.min_horizon_reward", "planning.search.min_horizon_reward"},
    {"planning.closure_min_length", "planning.search.closure_min_length"},
    {"planning.closure_max_angle", "planning.search.closure_max_angle"}
};

std::string renamed_hint(const IniEntry& e) {
  const std::string old = e.section + "." + e.key;
  for (const auto& [from, to] : kRenamed) {
    if (old == from) {
      const std::string path = to;
      const auto dot = path.rfind('.');
      return "; it is now [" + path.substr(0, dot) + "] " + path.substr(dot + 1);
    }
  }
  return "";
}

// --set section.key=value, the section being everything before the key's last dot
IniEntry override_entry(const std::string& o, int number) {
  const auto eq = o.find('=');
  const auto dot = eq == std::string::npos ? std::string::npos : o.rfind('.', eq);
  if (eq == std::string::npos || dot == std::string::npos) {
    throw UserError("--set " + o + ": expected section.key=value (e.g. perception.lidar.clustering.tolerance=0.5)");
  }
  return {trim(o.substr(0, dot)), trim(o.substr(dot + 1, eq - dot - 1)), trim(o.substr(eq + 1)), "--set", number};
}

// the file named by `e`, relative to the file it was written in (as given,
// and absolute)
std::pair<std::string, std::string> resolve_file(const IniEntry& e) {
  namespace fs = std::filesystem;
  const fs::path p(e.value);
  const fs::path base = e.file == "--set" ? fs::path() : fs::path(e.file).parent_path();
  const std::string path = (p.is_absolute() ? p : (base / p)).lexically_normal().string();
  return {path, fs::absolute(path).lexically_normal().string()};
}

// the track file named by `e`
void resolve_track(Scenario& s, const IniEntry& e) {
  if (e.value.empty()) throw UserError(e.where() + ": [scenario] track needs a file name");
  std::tie(s.track_path, s.scenario.track) = resolve_file(e);
}

// a [hal] file named by `e` (empty: none), written absolute
void resolve_hal_file(std::string& field, const IniEntry& e) {
  if (!e.value.empty()) field = resolve_file(e).second;
}

using Given = std::set<std::pair<std::string, std::string>>;

// sets each entry's key among `keys` (then calls after(key, entry)); unknown
// sections and keys are errors naming what was expected; returns the
// (section, key) pairs given
Given set_keys(std::vector<Key>& keys, const std::vector<IniEntry>& entries,
               const std::function<void(const Key&, const IniEntry&)>& after) {
  std::map<std::pair<std::string, std::string>, Key*> index;
  std::map<std::string, std::string> names_in;  // section -> its keys, for messages
  for (Key& k : keys) {
    index[{k.section, k.name}] = &k;
    std::string& names = names_in[k.section];
    names += (names.empty() ? "" : ", ") + k.name;
  }
  Given given;
  for (const IniEntry& e : entries) {
    const auto it = index.find({e.section, e.key});
    if (it != index.end()) {
      it->second->set(e);
      if (after) after(*it->second, e);
      given.insert({e.section, e.key});
      continue;
    }
    const std::string hint = renamed_hint(e);
    if (names_in.count(e.section)) {
      throw UserError(e.where() + ": unknown key '" + e.key + "' in [" + e.section + "]" +
                      (hint.empty() ? "; expected one of: " + names_in[e.section] : hint));
    }
    std::string sections;
    for (const auto& [section, names] : names_in) sections += (sections.empty() ? "" : ", ") + ("[" + section + "]");
    throw UserError(e.where() + ": unknown section [" + e.section + "]" +
                    (hint.empty() ? "; expected one of: " + sections : hint));
  }
  return given;
}

// every required key among `keys` must have been given
void require_given(const std::vector<Key>& keys, const Given& given, const std::string& path, const std::string& hint) {
  for (const Key& k : keys) {
    if (k.required && !given.count({k.section, k.name})) {
      throw UserError(path + ": [" + k.section + "] " + k.name + " is not set" + (k.unit.empty() ? "" : " (" + k.unit + ")") +
                      (k.section == "vehicle" ? hint : ""));
    }
  }
}

// the [hal] files: the LiDAR's metadata sets its layout (a [lidar] key it
// sets may be given only with the file's value), the DBC is parsed and
// checked against what the car sends; wire needs both where they are used
void load_hal_files(Scenario& s, const std::vector<IniEntry>& entries, const std::string& path, const FileTable* files) {
  const auto read = [files](const std::string& file) { return read_input(file, files); };
  if (!s.hal.lidar_metadata.empty()) {
    const std::string& file = s.hal.lidar_metadata;
    try {
      s.lidar_info = hal::ouster::parse_sensor_info(read(file), file);
    } catch (const std::invalid_argument& e) {
      throw UserError(e.what());
    }
    sensors::LidarParams& l = s.lidar;
    const sensors::LidarParams keys = l;
    static_cast<hal::LidarLayout&>(l) = hal::ouster::layout_of(*s.lidar_info, l);
    l.rate = s.lidar_info->frequency;
    // the keys the file sets: one given must have the file's value (the
    // resolved scenario writes them so)
    const std::tuple<const char*, double, double> from_file[] = {
        {"channels", keys.channels, l.channels},
        {"columns", keys.columns, l.columns},
        {"elevation_min", keys.elevation_min, l.elevation_min},
        {"elevation_max", keys.elevation_max, l.elevation_max},
        {"rate", keys.rate, l.rate}};
    for (const auto& [key, given, value] : from_file) {
      const auto it = std::find_if(entries.rbegin(), entries.rend(),
                                   [key = key](const IniEntry& e) { return e.section == "lidar" && e.key == key; });
      if (it == entries.rend() || std::abs(given - value) <= 1e-12 * std::max(1.0, std::abs(value))) continue;
      throw UserError(it->where() + ": [lidar] " + key + " = " + it->value + " contradicts the metadata file " + file +
                      " ([hal] lidar_metadata), which sets it to " + params::number(value) +
                      "; expected that value or no key");
    }
  }
  if (!s.hal.dbc.empty()) {
    const std::string& file = s.hal.dbc;
    try {
      s.dbc_text = read(file);
      s.dbc = std::make_shared<const hal::Dbc>(hal::parse_dbc(s.dbc_text, file));
      // the car's frames must all be there (throws naming what is missing)
      const hal::CarCan check(*s.dbc, file);
    } catch (const std::invalid_argument& e) {
      throw UserError(e.what());
    }
  }
  if (s.hal.transport != Transport::Memory) {
    const bool lidar = s.autonomy.perception != stack::PerceptionMode::GroundTruth;
    if (lidar && s.hal.lidar_metadata.empty())
      throw UserError(path + ": [hal] transport = wire or udp sends the LiDAR's packets: [hal] lidar_metadata must name its metadata file");
    if (s.hal.dbc.empty())
      throw UserError(path + ": [hal] transport = wire or udp sends the car's CAN frames: [hal] dbc must name the car's DBC file");
  }
}

// sets every entry's key; unknown sections and keys, and required keys left
// unset, are errors
void apply_entries(Scenario& s, const std::vector<IniEntry>& entries, const std::string& path, const FileTable* files) {
  std::vector<Key> keys = scenario_keys(s);
  const Given given = set_keys(keys, entries, [&s](const Key& k, const IniEntry& e) {
    if (k.path() == "scenario.track") resolve_track(s, e);
    if (k.path() == "hal.lidar_metadata") resolve_hal_file(s.hal.lidar_metadata, e);
    if (k.path() == "hal.dbc") resolve_hal_file(s.hal.dbc, e);
  });
  require_given(keys, given, path, "; include a vehicle file, e.g. include = vehicles/default.ini");
  if (s.track_path.empty()) throw UserError(path + ": [scenario] track is not set; expected the track's CSV file");
  load_hal_files(s, entries, path, files);
}

// a problem from params::validate ("a.b.key must be ...") as "[a.b] key must be ..."
std::string as_section_key(const std::string& problem) {
  const auto space = problem.find(' ');
  const auto dot = problem.rfind('.', space);
  if (dot == std::string::npos) return problem;
  return "[" + problem.substr(0, dot) + "] " + problem.substr(dot + 1);
}

}  // namespace

std::string Scenario::check() const {
  if (scenario.go_time < as.ready_wait)
    return "scenario.go_time (" + params::number(scenario.go_time) + " s) is shorter than as.ready_wait (" +
           params::number(as.ready_wait) + " s): the stack would ignore the go";
  if ((autonomy.slam == stack::SlamMode::Lio || autonomy.slam == stack::SlamMode::LioGraph) &&
      autonomy.perception == stack::PerceptionMode::GroundTruth)
    return "autonomy.slam = lio or lio_graph needs the LiDAR's scans: autonomy.perception = lidar or lidar_camera";
  const double limit = vehicle::stable_step_limit(vehicle);
  if (1.0 / sim.physics_rate > limit) {
    return "sim.physics_rate must be at least " + std::to_string(static_cast<int>(std::ceil(1.0 / limit))) +
           " Hz for this vehicle (its tyre modes need a step of at most " + params::number(std::floor(limit * 1e4) / 10.0) +
           " ms to integrate stably)";
  }
  if (sim.physics_rate % vcu.status_rate != 0) return "sim.physics_rate must be a whole multiple of vcu.status_rate";
  // each sensor samples every physics_rate / rate steps: a rate that does
  // not divide the physics rate would be sampled at another (rounded) one
  const std::pair<const char*, double> sampled[] = {{"[imu] rate", imu.rate},
                                                    {"[wheel_speeds] rate", wheel_speeds.rate},
                                                    {"[steering_sensor] rate", steering_sensor.rate},
                                                    {"[cone_sensor] rate", cone_sensor.rate}};
  for (const auto& [key, rate] : sampled) {
    const double steps = static_cast<double>(sim.physics_rate) / rate;
    const double whole = std::max(1.0, std::round(steps));
    if (std::abs(steps - whole) > 1e-9 * whole) {
      return "sim.physics_rate (" + params::number(sim.physics_rate) + " Hz) must be a whole multiple of " + key + " (" +
             params::number(rate) + " Hz): it would be sampled every " +
             (whole > 1.0 ? params::number(whole) + " steps" : std::string("step")) + ", at " +
             params::number(std::round(10.0 * sim.physics_rate / whole) / 10.0) + " Hz";
    }
  }
  return "";
}

std::vector<std::string> thread_overrides(int n, const Scenario& s) {
  const bool perception_thread =
      n > 1 && s.autonomy.perception != stack::PerceptionMode::GroundTruth && s.perception.latency > 0.0;
  return {"sim.threads=" + std::to_string(std::min(n, SimSection::kMaxThreads)),
          "perception.threads=" + std::to_string(perception_thread ? 2 : 1),
          "slam.threads=" + std::to_string(perception_thread ? n - 1 : n)};
}

Scenario load_scenario(const std::string& path, const std::vector<std::string>& overrides) {
  return load_scenario_entries(read_ini_file(path), path, overrides);
}

Scenario load_scenario_entries(std::vector<IniEntry> entries, const std::string& path,
                               const std::vector<std::string>& overrides, const FileTable* files) {
  // command-line overrides come last, so they win
  for (std::size_t i = 0; i < overrides.size(); ++i) entries.push_back(override_entry(overrides[i], static_cast<int>(i + 1)));
  Scenario s;
  apply_entries(s, entries, path, files);
  // every field's bounds were checked as it was read; what ties fields
  // together is checked on the whole tree, the stack's sections as the stack
  // receives them (with the calibrations the runner derives from [lidar] and
  // [camera], the car's figures from [vehicle])
  const stack::StackParams stack = stack_params(s);
  Scenario as_used = s;
  as_used.perception = stack.perception;
  as_used.planning = stack.planning;
  as_used.skidpad = stack.skidpad;
  if (const std::string why = params::validate(as_used); !why.empty()) throw UserError(path + ": " + as_section_key(why));
  // and what the stack knows of its car (the rest of its parameters is as_used's)
  if (const std::string why = params::validate(stack.vehicle); !why.empty()) {
    throw UserError(path + ": [vehicle] what the stack knows of the car: " + why);
  }
  s.source = path;
  s.name = std::filesystem::path(path).stem().string();
  return s;
}

vehicle::VehicleParams load_vehicle_file(const std::string& path) {
  const std::vector<IniEntry> entries = read_ini_file(path);
  // the [vehicle] keys of a scenario, and no others
  Scenario s;
  std::vector<Key> keys = scenario_keys(s);
  keys.erase(std::remove_if(keys.begin(), keys.end(), [](const Key& k) { return k.section != "vehicle"; }), keys.end());
  require_given(keys, set_keys(keys, entries, nullptr), path, "");
  if (const std::string why = params::validate(s.vehicle); !why.empty()) throw UserError(path + ": " + as_section_key("vehicle." + why));
  // the physics step of a default scenario (1 kHz) must integrate this car stably
  if (const std::string why = s.check(); !why.empty()) throw UserError(path + ": [vehicle] at the default physics rate: " + why);
  return s.vehicle;
}

std::string resolved_ini(const Scenario& scenario) {
  std::ostringstream o;
  o << "; the resolved scenario of a run: every key, defaults included, in SI units\n";
  o << "; from " << scenario.source << "\n";
  std::string section;
  for (const Key& k : scenario_keys(const_cast<Scenario&>(scenario))) {  // get() only reads
    if (k.section != section) {
      section = k.section;
      o << "\n[" << section << "]\n";
    }
    const std::string v = k.get();
    const std::string comment = k.unit.empty() ? k.doc : k.doc.empty() ? k.unit : k.unit + ", " + k.doc;
    // an unset optional value stays a comment; an empty text is a value
    if (v.empty() && k.expected != "text") o << "; " << k.name << " =  ; (unset) " << comment << "\n";
    else o << k.name << " = " << v << "  ; " << comment << "\n";
  }
  return o.str();
}

}  // namespace paddock::runner

namespace paddock::runner {

std::string read_input(const std::string& path, const FileTable* files) {
  if (files) {
    if (const auto it = files->find(path); it != files->end()) return it->second;
  }
  return read_file(path);
}

world::TrackFile load_track_file(const std::string& path, const FileTable* files) {
  return world::parse_track(read_input(path, files), path);
}

std::uint64_t stream_seed(std::uint64_t scenario_seed, std::string_view stream) {
  // one offset per stream on a Weyl step of the golden ratio; the camera's
  // stream is the LiDAR's, scrambled
  struct Stream {
    std::string_view name;
    std::uint64_t offset, scramble;
  };
  static constexpr Stream kStreams[] = {{"cone_sensor", 1, 0},     {"imu", 2, 0},   {"wheel_speeds", 3, 0},
                                        {"steering_sensor", 4, 0}, {"lidar", 5, 0}, {"camera", 5, 0xC0FFEEULL},
                                        {"detector", 6, 0},        {"slam", 7, 0},  {"faults", 8, 0}};
  for (const Stream& s : kStreams)
    if (s.name == stream) return (scenario_seed * 0x9E3779B97F4A7C15ULL + s.offset) ^ s.scramble;
  assert(false && "unknown random stream");
  return scenario_seed;
}

estimation::CarGeometry car_geometry(const vehicle::VehicleParams& v, const sensors::ImuParams& imu) {
  estimation::CarGeometry g;
  g.lf = v.lf;
  g.lr = v.lr;
  g.track_front = v.track_front;
  g.track_rear = v.track_rear;
  g.wheel_radius = v.wheel_radius;
  g.imu_x = imu.mount_x;
  g.imu_y = imu.mount_y;
  // the slip the wheels show per m/s^2: 1 / (g B_x C D_x), the tyre's slip stiffness per load
  g.slip_per_accel = 1.0 / (kGravity * v.tyre_bx * v.tyre_c * v.tyre_dx);
  g.drag_per_mass = v.c_drag / v.mass;
  g.cornering_stiffness = v.tyre_b * v.tyre_c * v.tyre_d;
  return g;
}

stack::StackParams stack_params(const Scenario& s) {
  stack::StackParams p;
  p.autonomy = s.autonomy;
  p.control = s.control;
  p.mission = s.mission;
  p.cone_map = s.cone_map;
  p.gates = s.gates;
  p.as = s.as;
  p.health = s.health;
  // what the stack knows of its car comes from the same [vehicle] section as
  // the simulated car: one place for each value
  const vehicle::VehicleParams& v = s.vehicle;
  control::VehicleKnowledge& k = p.vehicle;
  k.mass = v.mass;
  k.equivalent_mass = vehicle::equivalent_mass(v);
  k.lf = v.lf;
  k.lr = v.lr;
  k.wheelbase = v.lf + v.lr;
  k.front_cornering_stiffness = control::front_axle_cornering_stiffness(v.tyre_b, v.tyre_c, v.tyre_d, v.mass, v.lf, v.lr);
  k.max_steering_angle = v.steering_max;
  k.max_drive_force = vehicle::drive_torque_limit(v, 0.0) / v.wheel_radius;
  k.max_drive_power = vehicle::drive_power_limit(v);
  k.max_brake_force = v.brake_force_max;
  k.drag_coefficient = v.c_drag;
  k.rolling_resistance = v.cr0;
  // perception: the sensors' calibration is their true mounting and layout,
  // the odometry's wheel radius the car's
  p.perception = s.perception;
  p.perception.odometry.wheel_radius = v.wheel_radius;
  p.perception.lidar.calibration = static_cast<const hal::LidarLayout&>(s.lidar);
  p.perception.camera = sensors::camera_calibration(s.camera);
  p.planning = s.planning;
  p.slam = s.slam;
  p.slam.geometry = car_geometry(v, s.imu);
  p.slam.lidar = static_cast<const hal::LidarLayout&>(s.lidar);
  p.slam.lio = s.lio;
  p.slam.seed = stream_seed(s.scenario.seed, "slam");
  p.planning.reference.profile.mass = v.mass;
  p.planning.reference.profile.drag_coefficient = v.c_drag;
  // the skidpad's reference uses the same planned limits
  p.skidpad = s.skidpad;
  p.skidpad.reference = p.planning.reference;
  return p;
}

}  // namespace paddock::runner
