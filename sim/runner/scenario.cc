#include "sim/runner/scenario.h"

#include <cassert>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <set>
#include <sstream>

#include "sim/runner/files.h"
#include "sim/runner/ini.h"
#include "sim/runner/report.h"
#include "sim/runner/schema.h"

namespace paddock::runner {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t") - b + 1);
}

// other units accepted for a stored SI unit, with their factor to it
const std::map<std::string, std::map<std::string, double>>& conversions() {
  static const std::map<std::string, std::map<std::string, double>> table = {
      {"rad", {{"deg", kPi / 180.0}}},
      {"rad/s", {{"deg/s", kPi / 180.0}}},
      {"m/s", {{"km/h", 1.0 / 3.6}}},
      {"s", {{"ms", 1e-3}}},
      {"m", {{"cm", 1e-2}, {"mm", 1e-3}}},
      {"m/s^2", {{"g", kGravity}}},
  };
  return table;
}

std::string range_text(double lo, double hi, const std::string& unit) {
  std::string u = unit.empty() ? "" : " " + unit;
  if (std::isinf(hi)) return "at least " + fmt(lo) + u;
  return "between " + fmt(lo) + " and " + fmt(hi) + u;
}

// ---- field builders: each binds one key to one member through an accessor ----

template <class Acc>
Field real_field(const char* sec, const char* key, const char* unit, double lo, double hi, const char* doc, Acc acc,
                 bool required = false) {
  Field f{sec, key, unit, doc, required, {}, {}};
  const std::string u = unit;
  f.set = [=](Scenario& s, const IniEntry& e) { acc(s) = parse_quantity(e, u, lo, hi); };
  f.get = [=](const Scenario& s) { return fmt(acc(s)); };
  return f;
}

template <class Acc>
Field int_field(const char* sec, const char* key, const char* unit, long lo, long hi, const char* doc, Acc acc) {
  Field f{sec, key, unit, doc, false, {}, {}};
  f.set = [=](Scenario& s, const IniEntry& e) {
    acc(s) = static_cast<std::remove_reference_t<decltype(acc(s))>>(parse_integer(e, lo, hi));
  };
  f.get = [=](const Scenario& s) { return std::to_string(acc(s)); };
  return f;
}

template <class Acc>
Field bool_field(const char* sec, const char* key, const char* doc, Acc acc) {
  Field f{sec, key, "", doc, false, {}, {}};
  f.set = [=](Scenario& s, const IniEntry& e) { acc(s) = parse_bool(e); };
  f.get = [=](const Scenario& s) { return std::string(acc(s) ? "true" : "false"); };
  return f;
}

template <class E, class Acc>
Field enum_field(const char* sec, const char* key, const char* doc, std::vector<std::pair<std::string, E>> names,
                 Acc acc) {
  Field f{sec, key, "", doc, false, {}, {}};
  f.set = [=](Scenario& s, const IniEntry& e) {
    std::string options;
    for (const auto& [n, v] : names) {
      if (n == e.value) {
        acc(s) = v;
        return;
      }
      options += (options.empty() ? "" : ", ") + n;
    }
    throw UserError(e.where() + ": [" + e.section + "] " + e.key + " = '" + e.value + "' is not known; expected one of: " + options);
  };
  f.get = [=](const Scenario& s) {
    for (const auto& [n, v] : names)
      if (v == acc(s)) return n;
    return std::string("?");
  };
  return f;
}

// an optional [expect] value
template <class T, class Acc>
Field expect_field(const char* key, const char* unit, const char* doc, Acc acc) {
  Field f{"expect", key, unit, doc, false, {}, {}};
  const std::string u = unit;
  f.set = [=](Scenario& s, const IniEntry& e) {
    if constexpr (std::is_same_v<T, bool>) acc(s) = parse_bool(e);
    else if constexpr (std::is_same_v<T, int>) acc(s) = static_cast<int>(parse_integer(e, 0, 1000000));
    else acc(s) = parse_quantity(e, u, 0.0, kInf);
  };
  f.get = [=](const Scenario& s) -> std::string {
    const auto& v = acc(s);
    if (!v) return "";
    if constexpr (std::is_same_v<T, bool>) return *v ? "true" : "false";
    else if constexpr (std::is_same_v<T, int>) return std::to_string(*v);
    else return fmt(*v);
  };
  return f;
}

// the field of v named key (VehicleParams::visit lists them); v may be const
template <class VP>
auto& vehicle_field(VP& v, const char* key) {
  struct Find {
    const char* key;
    double* field = nullptr;
    void operator()(const char* name, double& member, const params::Spec&) {
      if (std::strcmp(name, key) == 0) field = &member;
    }
  } find{key};
  const_cast<vehicle::VehicleParams&>(v).visit(find);
  assert(find.field);
  if constexpr (std::is_const_v<VP>) return static_cast<const double&>(*find.field);
  else return *find.field;
}

// [vehicle]: every key required (the values come from a vehicle file such as
// scenarios/vehicles/default.ini, the one place they are written); the vehicle
// module lists its fields (visit) and validates them as a whole after loading
void add_vehicle_fields(std::vector<Field>& f) {
  struct Add {
    std::vector<Field>& f;
    void operator()(const char* key, double&, const params::Spec& spec) {
      // "-" marks a dimensionless field in the resolved scenario
      f.push_back(real_field("vehicle", key, *spec.unit ? spec.unit : "-", -kInf, kInf, "",
                             [key](auto& s) -> auto& { return vehicle_field(s.vehicle, key); }, true));
    }
  } add{f};
  vehicle::VehicleParams v;
  v.visit(add);
}

#define ACC(member) [](auto& s) -> auto& { return s.member; }

// [cone_sensor]: the object-level cone sensor (perception = ground_truth)
void add_cone_sensor_fields(std::vector<Field>& f) {
  f.push_back(real_field("cone_sensor", "mount_x", "m", -10.0, 10.0, "sensor position ahead of the rear axle", ACC(cone_sensor.mount_x)));
  f.push_back(real_field("cone_sensor", "mount_y", "m", -5.0, 5.0, "sensor position left of the centre", ACC(cone_sensor.mount_y)));
  f.push_back(real_field("cone_sensor", "range_min", "m", 0.0, 1000.0, "nearest cone seen", ACC(cone_sensor.range_min)));
  f.push_back(real_field("cone_sensor", "range_max", "m", 0.1, 1000.0, "farthest cone seen", ACC(cone_sensor.range_max)));
  f.push_back(real_field("cone_sensor", "fov", "rad", 0.01, 2.0 * kPi, "horizontal field of view, centred forward", ACC(cone_sensor.fov)));
  f.push_back(bool_field("cone_sensor", "occlusion", "cones hide cones behind them", ACC(cone_sensor.occlusion)));
  f.push_back(real_field("cone_sensor", "occlusion_fraction", "", 0.0, 1.0, "share of a cone's bearing that must be covered to hide it",
                         ACC(cone_sensor.occlusion_fraction)));
  f.push_back(real_field("cone_sensor", "range_noise", "m", 0.0, 10.0, "range noise std at 0 m", ACC(cone_sensor.range_noise)));
  f.push_back(real_field("cone_sensor", "range_noise_per_m", "m/m", 0.0, 1.0, "growth of the range noise std with range",
                         ACC(cone_sensor.range_noise_per_m)));
  f.push_back(real_field("cone_sensor", "bearing_noise", "rad", 0.0, 1.0, "bearing noise std", ACC(cone_sensor.bearing_noise)));
  f.push_back(real_field("cone_sensor", "miss_probability", "", 0.0, 1.0, "chance a cone in view is missed, near",
                         ACC(cone_sensor.miss_probability)));
  f.push_back(real_field("cone_sensor", "miss_probability_growth", "", 0.0, 1.0, "added at range_max (quadratic in range)",
                         ACC(cone_sensor.miss_probability_growth)));
  f.push_back(real_field("cone_sensor", "unknown_color_probability", "", 0.0, 1.0, "chance of no colour, near",
                         ACC(cone_sensor.unknown_color_probability)));
  f.push_back(real_field("cone_sensor", "unknown_color_growth", "", 0.0, 1.0, "added at range_max (quadratic in range)",
                         ACC(cone_sensor.unknown_color_growth)));
  f.push_back(real_field("cone_sensor", "color_flip_probability", "", 0.0, 1.0, "chance of the look-alike colour, near",
                         ACC(cone_sensor.color_flip_probability)));
  f.push_back(real_field("cone_sensor", "color_flip_growth", "", 0.0, 1.0, "added at range_max (quadratic in range)",
                         ACC(cone_sensor.color_flip_growth)));
  f.push_back(real_field("cone_sensor", "false_positives_per_frame", "", 0.0, 100.0, "mean ghost cones per frame (Poisson)",
                         ACC(cone_sensor.false_positives_per_frame)));
  f.push_back(real_field("cone_sensor", "false_positive_unknown_probability", "", 0.0, 1.0, "share of ghosts without colour",
                         ACC(cone_sensor.false_positive_unknown_probability)));
  f.push_back(real_field("cone_sensor", "latency", "s", 0.0, 10.0, "measurement to delivery", ACC(cone_sensor.latency)));
  f.push_back(real_field("cone_sensor", "rate", "Hz", 0.1, 1000.0, "frames per second", ACC(cone_sensor.rate)));
}

// [imu], [wheel_speeds], [steering_sensor]: the odometry sensors
void add_odometry_fields(std::vector<Field>& f) {
  f.push_back(real_field("imu", "rate", "Hz", 1.0, 10000.0, "samples per second", ACC(imu.rate)));
  f.push_back(real_field("imu", "accel_noise", "m/s^2", 0.0, 100.0, "accelerometer noise std per sample", ACC(imu.accel_noise)));
  f.push_back(real_field("imu", "gyro_noise", "rad/s", 0.0, 10.0, "gyro noise std per sample", ACC(imu.gyro_noise)));
  f.push_back(real_field("imu", "accel_bias_walk", "m/s^2/sqrt(s)", 0.0, 10.0, "accelerometer bias random walk", ACC(imu.accel_bias_walk)));
  f.push_back(real_field("imu", "gyro_bias_walk", "rad/s/sqrt(s)", 0.0, 10.0, "gyro bias random walk", ACC(imu.gyro_bias_walk)));
  f.push_back(real_field("imu", "accel_bias_initial_std", "m/s^2", 0.0, 10.0, "turn-on accelerometer bias std", ACC(imu.accel_bias_initial_std)));
  f.push_back(real_field("imu", "gyro_bias_initial_std", "rad/s", 0.0, 10.0, "turn-on gyro bias std", ACC(imu.gyro_bias_initial_std)));
  f.push_back(real_field("imu", "mount_x", "m", -10.0, 10.0, "IMU position ahead of the rear axle", ACC(imu.mount_x)));
  f.push_back(real_field("imu", "mount_y", "m", -5.0, 5.0, "IMU position left of the centre", ACC(imu.mount_y)));
  f.push_back(real_field("wheel_speeds", "rate", "Hz", 1.0, 10000.0, "samples per second", ACC(wheel_speeds.rate)));
  f.push_back(real_field("wheel_speeds", "noise", "rad/s", 0.0, 100.0, "noise std", ACC(wheel_speeds.noise)));
  f.push_back(real_field("wheel_speeds", "resolution", "rad/s", 0.0, 100.0, "quantisation step (0: none)", ACC(wheel_speeds.resolution)));
  f.push_back(real_field("steering_sensor", "rate", "Hz", 1.0, 10000.0, "samples per second", ACC(steering_sensor.rate)));
  f.push_back(real_field("steering_sensor", "noise", "rad", 0.0, 1.0, "noise std", ACC(steering_sensor.noise)));
  f.push_back(real_field("steering_sensor", "resolution", "rad", 0.0, 1.0, "quantisation step (0: none)", ACC(steering_sensor.resolution)));
  f.push_back(real_field("steering_sensor", "offset", "rad", -1.5, 1.5, "calibration offset", ACC(steering_sensor.offset)));
}

// [lidar]: the rotating LiDAR; [ground]: the ground's shape the sensors see
// (the vehicle model stays planar)
void add_lidar_fields(std::vector<Field>& f) {
  f.push_back(int_field("lidar", "channels", "", 1, 65535, "channels, evenly spaced in elevation", ACC(lidar.channels)));
  f.push_back(real_field("lidar", "elevation_min", "rad", -kPi / 2, kPi / 2, "lowest channel's elevation", ACC(lidar.elevation_min)));
  f.push_back(real_field("lidar", "elevation_max", "rad", -kPi / 2, kPi / 2, "highest channel's elevation", ACC(lidar.elevation_max)));
  f.push_back(int_field("lidar", "columns", "", 1, 100000, "columns per rotation", ACC(lidar.columns)));
  f.push_back(real_field("lidar", "rate", "Hz", 0.1, 1000.0, "rotations per second", ACC(lidar.rate)));
  f.push_back(real_field("lidar", "range_min", "m", 0.0, 1000.0, "blind zone", ACC(lidar.range_min)));
  f.push_back(real_field("lidar", "range_max", "m", 0.1, 1000.0, "farthest return", ACC(lidar.range_max)));
  f.push_back(real_field("lidar", "range_noise", "m", 0.0, 10.0, "range noise std along the ray", ACC(lidar.range_noise)));
  f.push_back(real_field("lidar", "dropout", "", 0.0, 0.99, "chance a ray returns nothing", ACC(lidar.dropout)));
  f.push_back(real_field("lidar", "mount_x", "m", -10.0, 10.0, "optical centre ahead of the rear axle", ACC(lidar.mount_x)));
  f.push_back(real_field("lidar", "mount_y", "m", -5.0, 5.0, "optical centre left of the centre", ACC(lidar.mount_y)));
  f.push_back(real_field("lidar", "mount_z", "m", 0.01, 5.0, "optical centre above the ground", ACC(lidar.mount_z)));
  f.push_back(real_field("lidar", "mount_pitch", "rad", -0.5, 0.5, "pitch, > 0 nose down", ACC(lidar.mount_pitch)));
  f.push_back(real_field("lidar", "reflect_white", "", 0.0, 1.0, "reflectivity of a white stripe", ACC(lidar.reflect_white)));
  f.push_back(real_field("lidar", "reflect_yellow", "", 0.0, 1.0, "reflectivity of a yellow body", ACC(lidar.reflect_yellow)));
  f.push_back(real_field("lidar", "reflect_orange", "", 0.0, 1.0, "reflectivity of an orange body", ACC(lidar.reflect_orange)));
  f.push_back(real_field("lidar", "reflect_blue", "", 0.0, 1.0, "reflectivity of a blue body", ACC(lidar.reflect_blue)));
  f.push_back(real_field("lidar", "reflect_black", "", 0.0, 1.0, "reflectivity of a black stripe", ACC(lidar.reflect_black)));
  f.push_back(real_field("lidar", "reflect_grey", "", 0.0, 1.0, "reflectivity of a cone of unknown colour", ACC(lidar.reflect_grey)));
  f.push_back(real_field("lidar", "reflect_ground", "", 0.0, 1.0, "reflectivity of the asphalt", ACC(lidar.reflect_ground)));
  f.push_back(real_field("lidar", "intensity_range_ref", "m", 0.01, 1000.0, "intensity falls off as (ref / r)^2 beyond this",
                         ACC(lidar.intensity_range_ref)));
  f.push_back(real_field("lidar", "intensity_noise", "", 0.0, 1.0, "intensity noise std", ACC(lidar.intensity_noise)));
  f.push_back(int_field("camera", "width", "px", 16, 8192, "image width", ACC(camera.width)));
  f.push_back(int_field("camera", "height", "px", 16, 8192, "image height", ACC(camera.height)));
  f.push_back(real_field("camera", "hfov", "rad", 10.0 * kPi / 180.0, 170.0 * kPi / 180.0, "horizontal field of view", ACC(camera.hfov)));
  f.push_back(real_field("camera", "mount_x", "m", -10.0, 10.0, "optical centre ahead of the rear axle", ACC(camera.mount_x)));
  f.push_back(real_field("camera", "mount_y", "m", -5.0, 5.0, "optical centre left of the centre", ACC(camera.mount_y)));
  f.push_back(real_field("camera", "mount_z", "m", 0.01, 5.0, "optical centre above the ground", ACC(camera.mount_z)));
  f.push_back(real_field("camera", "mount_pitch", "rad", -1.5, 1.5, "pitch, > 0 nose down", ACC(camera.mount_pitch)));
  f.push_back(real_field("camera", "trigger_azimuth", "rad", -kPi, kPi, "the LiDAR azimuth that triggers the exposure (0 ahead)",
                         ACC(camera.trigger_azimuth)));
  f.push_back(real_field("camera", "sun_azimuth", "rad", -kPi, kPi, "sun direction from map +x", ACC(camera.sun_azimuth)));
  f.push_back(real_field("camera", "sun_elevation", "rad", 0.0, kPi / 2, "sun height", ACC(camera.sun_elevation)));
  f.push_back(real_field("camera", "ambient", "", 0.0, 1.0, "ambient light share", ACC(camera.ambient)));
  f.push_back(real_field("camera", "pixel_noise", "", 0.0, 64.0, "pixel noise std in 8-bit levels", ACC(camera.pixel_noise)));
  f.push_back(real_field("ground", "slope_x", "", -1.0, 1.0, "dz/dx of the ground plane (map frame)", ACC(ground.slope_x)));
  f.push_back(real_field("ground", "slope_y", "", -1.0, 1.0, "dz/dy of the ground plane (map frame)", ACC(ground.slope_y)));
  f.push_back(real_field("ground", "bump_height", "m", 0.0, 1.0, "amplitude of the sinusoidal bumps", ACC(ground.bump_height)));
  f.push_back(real_field("ground", "bump_wavelength", "m", 0.1, 1000.0, "wavelength of the bumps", ACC(ground.bump_wavelength)));
  f.push_back(real_field("ground", "cell", "m", 0.01, 100.0, "height-field grid cell (a lower bound)", ACC(ground.cell)));
}

// [perception]: the stack's perception front; [detector]: the camera's detector node
void add_perception_fields(std::vector<Field>& f) {
  f.push_back(real_field("perception", "cluster_tolerance", "m", 0.01, 5.0, "Euclidean clustering: largest gap inside a cluster",
                         ACC(perception.lidar.clustering.tolerance)));
  f.push_back(real_field("perception", "cluster_max_range", "m", 1.0, 200.0, "only points this close are clustered",
                         ACC(perception.lidar.clustering.max_range)));
  f.push_back(real_field("perception", "camera_range", "m", 0.1, 200.0, "fusion: beyond this the camera is not trusted (LiDAR only)",
                         ACC(perception.fusion.camera_range)));
  f.push_back(real_field("perception", "box_margin", "px", 0.0, 100.0, "fusion: a projected centre this far outside a box is in it",
                         ACC(perception.fusion.box_margin)));
  f.push_back(real_field("perception", "camera_sync_tolerance", "s", 0.0, 1.0, "a camera frame serves the rotation it was exposed in, give or take this",
                         ACC(perception.camera_sync_tolerance)));
  f.push_back(real_field("detector", "p_miss_near", "", 0.0, 1.0, "chance of missing an unoccluded cone up to range_full",
                         ACC(detector.p_miss_near)));
  f.push_back(real_field("detector", "range_full", "m", 0.0, 1000.0, "misses start to grow beyond this", ACC(detector.range_full)));
  f.push_back(real_field("detector", "range_max", "m", 0.0, 1000.0, "every cone is missed beyond this", ACC(detector.range_max)));
  f.push_back(real_field("detector", "visible_min", "", 0.0, 1.0, "a cone less visible than this is always missed",
                         ACC(detector.visible_min)));
  f.push_back(real_field("detector", "visible_full", "", 0.0, 1.0, "occlusion adds no misses above this visible share",
                         ACC(detector.visible_full)));
  f.push_back(real_field("detector", "p_confuse_blue_yellow", "", 0.0, 1.0, "chance of calling blue yellow or yellow blue",
                         ACC(detector.p_confuse_blue_yellow)));
  f.push_back(real_field("detector", "p_confuse_orange_size", "", 0.0, 1.0, "chance of calling a small orange big or a big one small",
                         ACC(detector.p_confuse_orange_size)));
  f.push_back(real_field("detector", "box_jitter", "", 0.0, 1.0, "std of each box edge as a share of the box size",
                         ACC(detector.box_jitter)));
  f.push_back(real_field("detector", "min_box_height", "px", 0.0, 1000.0, "smaller boxes are never found", ACC(detector.min_box_height)));
}

// [cones]: the Box2D cone world's physics
void add_cone_fields(std::vector<Field>& f) {
  f.push_back(real_field("cones", "small_mass", "kg", 0.01, 100.0, "small cone mass", ACC(cones.small_cone.mass)));
  f.push_back(real_field("cones", "small_knock_impulse", "N s", 0.0, 1000.0, "impulse that knocks a small cone over",
                         ACC(cones.small_cone.knock_impulse)));
  f.push_back(real_field("cones", "big_mass", "kg", 0.01, 100.0, "big orange cone mass", ACC(cones.big_cone.mass)));
  f.push_back(real_field("cones", "big_knock_impulse", "N s", 0.0, 1000.0, "impulse that knocks a big cone over",
                         ACC(cones.big_cone.knock_impulse)));
  f.push_back(real_field("cones", "ground_friction", "", 0.0, 5.0, "cone-on-asphalt friction coefficient", ACC(cones.ground_friction)));
  f.push_back(real_field("cones", "car_friction", "", 0.0, 5.0, "car-cone friction coefficient", ACC(cones.car_cone_friction)));
  f.push_back(real_field("cones", "car_restitution", "", 0.0, 1.0, "car-cone restitution", ACC(cones.car_cone_restitution)));
}

std::vector<Field> build_fields() {
  using events::EventKind;
  std::vector<Field> f;
  // [scenario]
  {
    Field track{"scenario", "track", "", "track CSV file, relative to the file that names it", true, {}, {}};
    track.set = [](Scenario& s, const IniEntry& e) {
      if (e.value.empty()) throw UserError(e.where() + ": [scenario] track needs a file name");
      namespace fs = std::filesystem;
      const fs::path p(e.value);
      const fs::path base = e.file == "--set" ? fs::path() : fs::path(e.file).parent_path();
      s.scenario.track = e.value;
      s.track_path = (p.is_absolute() ? p : (base / p)).lexically_normal().string();
    };
    track.get = [](const Scenario& s) { return std::filesystem::absolute(s.track_path).lexically_normal().string(); };
    f.push_back(track);
  }
  f.push_back(enum_field<EventKind>("scenario", "event", "the FS event and its rules",
                                    {{"trackdrive", EventKind::Trackdrive}, {"autocross", EventKind::Autocross},
                                     {"acceleration", EventKind::Acceleration}, {"skidpad", EventKind::Skidpad}},
                                    ACC(scenario.event)));
  {
    Field seed{"scenario", "seed", "", "the run's random seed (every random draw derives from it)", false, {}, {}};
    seed.set = [](Scenario& s, const IniEntry& e) {
      s.scenario.seed = static_cast<std::uint64_t>(parse_integer(e, 0, std::numeric_limits<long>::max()));
    };
    seed.get = [](const Scenario& s) { return std::to_string(s.scenario.seed); };
    f.push_back(seed);
  }
  f.push_back(real_field("scenario", "go_time", "s", 0.0, 600.0, "time in AS Ready before the go signal", ACC(scenario.go_time)));

  // [autonomy]
  using namespace stack;
  f.push_back(enum_field<PerceptionMode>("autonomy", "perception", "where the cones come from",
                                         {{"ground_truth", PerceptionMode::GroundTruth}, {"lidar", PerceptionMode::Lidar},
                                          {"lidar_camera", PerceptionMode::LidarCamera}},
                                         ACC(autonomy.perception)));
  f.push_back(enum_field<SlamMode>("autonomy", "slam", "where the pose comes from", {{"ground_truth", SlamMode::GroundTruth}},
                                   ACC(autonomy.slam)));
  f.push_back(enum_field<PlannerMode>("autonomy", "planner", "where the reference path comes from",
                                      {{"delaunay", PlannerMode::Delaunay}, {"oracle", PlannerMode::Oracle}}, ACC(autonomy.planner)));

  // [control]
  using control::LateralMode;
  f.push_back(enum_field<LateralMode>("control", "lateral", "lateral control law",
                                      {{"combined", LateralMode::Combined}, {"stanley", LateralMode::Stanley},
                                       {"pure_pursuit", LateralMode::PurePursuit}},
                                      ACC(control.lateral)));
  f.push_back(real_field("control", "stanley_k", "1/s", 0.0, 100.0, "Stanley cross-track gain", ACC(control.stanley.k)));
  f.push_back(real_field("control", "stanley_k_soft", "m/s", 0.0, 100.0, "Stanley softening speed", ACC(control.stanley.k_soft)));
  f.push_back(bool_field("control", "stanley_steady_state_yaw", "add Hoffmann's steady-state yaw to Stanley",
                         ACC(control.stanley.use_steady_state_yaw)));
  f.push_back(real_field("control", "pp_lookahead_min", "m", 0.1, 100.0, "pure pursuit look-ahead at standstill L_min",
                         ACC(control.pure_pursuit.L_min)));
  f.push_back(real_field("control", "pp_lookahead_gain", "s", 0.0, 10.0, "pure pursuit look-ahead growth k_v",
                         ACC(control.pure_pursuit.k_v)));
  f.push_back(real_field("control", "k_min", "", 0.0, 1.0, "combined: pure pursuit weight on a straight", ACC(control.combined.k_min)));
  f.push_back(real_field("control", "k_max", "", 0.0, 1.0, "combined: largest pure pursuit weight", ACC(control.combined.k_max)));
  f.push_back(real_field("control", "kappa_ref", "1/m", 1e-6, 100.0, "combined: curvature scale", ACC(control.combined.kappa_ref)));
  f.push_back(real_field("control", "k_curve", "", 0.0, 10.0, "combined: weight added per kappa_ref", ACC(control.combined.k_curve)));
  f.push_back(real_field("control", "k_d_yaw", "s", 0.0, 10.0, "yaw-rate damping gain", ACC(control.k_d_yaw)));
  f.push_back(real_field("control", "speed_kp", "1/s", 0.0, 100.0, "speed loop proportional gain", ACC(control.longitudinal.kp)));
  f.push_back(real_field("control", "speed_ki", "1/s^2", 0.0, 100.0, "speed loop integral gain", ACC(control.longitudinal.ki)));
  f.push_back(real_field("control", "speed_integral_limit", "m/s^2", 0.0, 100.0, "bound of the integral term",
                         ACC(control.longitudinal.integral_limit)));
  f.push_back(real_field("control", "speed_feedforward", "", 0.0, 2.0, "scale of the model feedforward",
                         ACC(control.longitudinal.feedforward_gain)));
  f.push_back(real_field("control", "speed_preview", "s", 0.0, 5.0, "the reference speed is read this far ahead",
                         ACC(control.longitudinal.speed_preview_time)));
  f.push_back(real_field("control", "projection_window", "m", 0.1, 100.0, "arc-length window of the path projection",
                         ACC(control.projection_window)));

  // [planning]
  f.push_back(real_field("planning", "knot_spacing", "m", 0.1, 50.0, "spline knot spacing along the centreline",
                         ACC(planning.reference.knot_spacing)));
  f.push_back(real_field("planning", "ds", "m", 0.01, 10.0, "trajectory sample spacing", ACC(planning.reference.ds)));
  f.push_back(real_field("planning", "ax_max", "m/s^2", 0.1, 100.0, "tyre acceleration limit of the profile", ACC(planning.reference.profile.ax_max)));
  f.push_back(real_field("planning", "ay_max", "m/s^2", 0.1, 100.0, "tyre lateral limit of the profile", ACC(planning.reference.profile.ay_max)));
  f.push_back(real_field("planning", "ax_brake_max", "m/s^2", 0.1, 100.0, "tyre deceleration limit of the profile",
                         ACC(planning.reference.profile.ax_brake_max)));
  f.push_back(real_field("planning", "exponent", "", 1.0, 10.0, "g-g diagram exponent p", ACC(planning.reference.profile.exponent)));
  f.push_back(real_field("planning", "ax_machine", "m/s^2", 0.1, 100.0, "motor acceleration limit", ACC(planning.reference.profile.ax_machine)));
  f.push_back(real_field("planning", "v_max", "m/s", 0.1, 100.0, "top speed of the profile", ACC(planning.reference.profile.v_max)));
  f.push_back(real_field("planning", "turn_accel_scale", "", 0.0, 1.0, "longitudinal limits kept in a full-grip turn",
                         ACC(planning.reference.profile.turn_accel_scale)));

  // [slam]
  f.push_back(real_field("slam", "association_distance", "m", 0.01, 10.0, "a detection farther from every mapped cone starts a new one",
                         ACC(cone_map.association_distance)));
  f.push_back(int_field("slam", "min_observations", "", 1, 1000, "sightings before a mapped cone counts", ACC(cone_map.min_observations)));

  // [planning]: the centreline search (the paper's reward factors and their weights)
  {
    struct Key {
      const char* key;
      const char* unit;
      double lo, hi;
      double planning::CentrelineParams::*member;
      const char* doc;
    };
    using C = planning::CentrelineParams;
    static const Key keys[] = {
        {"search_radius", "m", 0.5, 100.0, &C::search_radius, "candidate midpoints within this of the last point"},
        {"min_step", "m", 0.0, 10.0, &C::min_step, "shortest step"},
        {"max_turn", "rad", 0.0, 3.2, &C::max_turn, "largest heading change of a step"},
        {"min_clearance", "m", 0.0, 5.0, &C::min_clearance, "a step passes at least this far from every cone"},
        {"weight_colour", "", 0.0, 100.0, &C::weight_colour, "reward weight: blue left, yellow right"},
        {"weight_width", "", 0.0, 100.0, &C::weight_width, "reward weight: track width (3-5 m, Gaussian edges)"},
        {"weight_angle", "", 0.0, 100.0, &C::weight_angle, "reward weight: small change of angle"},
        {"weight_step", "", 0.0, 100.0, &C::weight_step, "reward weight: distance between midpoints"},
        {"weight_prediction", "", 0.0, 100.0, &C::weight_prediction, "reward weight: near the predicted position"},
        {"weight_crossing", "", 0.0, 100.0, &C::weight_crossing, "reward weight: the step crosses its edge squarely"},
        {"colour_radius", "m", 0.0, 50.0, &C::colour_radius, "cones within this vote on the colour factor"},
        {"width_min", "m", 0.0, 20.0, &C::width_min, "full width reward from"},
        {"width_max", "m", 0.0, 20.0, &C::width_max, "full width reward up to"},
        {"width_sigma", "m", 0.01, 10.0, &C::width_sigma, "Gaussian edges of the width reward"},
        {"angle_sigma", "rad", 0.01, 10.0, &C::angle_sigma, "scale of the angle factor"},
        {"step_preferred", "m", 0.0, 50.0, &C::step_preferred, "the typical step"},
        {"step_sigma", "m", 0.01, 50.0, &C::step_sigma, "scale of the step factor"},
        {"prediction_sigma", "m", 0.01, 50.0, &C::prediction_sigma, "scale of the prediction factor"},
        {"min_reward", "", -10.0, 10.0, &C::min_reward, "a step below this reward is not taken"},
        {"min_horizon_reward", "", -10.0, 10.0, &C::min_horizon_reward, "stop when the best continuation averages below this"},
        {"closure_min_length", "m", 0.0, 10000.0, &C::closure_min_length, "a loop closes only after this length"},
        {"closure_max_angle", "rad", 0.0, 3.2, &C::closure_max_angle, "largest heading difference at a loop closure"},
    };
    for (const Key& k : keys) {
      const auto m = k.member;
      f.push_back(real_field("planning", k.key, k.unit, k.lo, k.hi, k.doc, [m](auto& s) -> auto& { return s.planning.search.*m; }));
    }
    f.push_back(int_field("planning", "horizon_depth", "", 1, 10, "event horizon: steps evaluated before committing", ACC(planning.search.horizon_depth)));
    f.push_back(int_field("planning", "first_beam_width", "", 1, 50, "event horizon: first steps kept", ACC(planning.search.first_beam_width)));
    f.push_back(int_field("planning", "beam_width", "", 1, 50, "event horizon: continuations kept per step", ACC(planning.search.beam_width)));
    f.push_back(int_field("planning", "smoothing_window", "", 1, 99, "moving-average window (odd)", ACC(planning.smoothing.window)));
    f.push_back(real_field("planning", "opheim_min_tol", "m", 0.0, 10.0, "Opheim radial and perpendicular tolerance", ACC(planning.smoothing.opheim_min_tol)));
    f.push_back(real_field("planning", "opheim_max_tol", "m", 0.0, 1000.0, "Opheim largest step", ACC(planning.smoothing.opheim_max_tol)));
    f.push_back(enum_field<planning::SmoothingParams::Method>(
        "planning", "smoothing", "centreline smoothing",
        {{"combined", planning::SmoothingParams::Combined}, {"moving_average", planning::SmoothingParams::MovingAverage},
         {"opheim", planning::SmoothingParams::Opheim}, {"raw", planning::SmoothingParams::Raw}},
        ACC(planning.smoothing.method)));
    f.push_back(real_field("planning", "clearance", "m", 0.0, 5.0, "planned path points stay this far from cone centres",
                           ACC(planning.clearance.clearance)));
  }

  // [mission]
  f.push_back(real_field("mission", "stop_decel", "m/s^2", 0.1, 50.0, "deceleration of the stop after the finish", ACC(mission.stop_decel)));
  f.push_back(real_field("mission", "standstill_speed", "m/s", 0.0, 5.0, "below this the stack counts as stopped",
                         ACC(mission.standstill_speed)));
  f.push_back(real_field("mission", "state_timeout", "s", 0.001, 10.0, "a staler state estimate triggers the safe stop",
                         ACC(mission.state_timeout)));

  f.push_back(real_field("mission", "loop_closure_distance", "m", 0.0, 10000.0, "driving before a closed centreline is the lap",
                         ACC(mission.loop_closure_distance)));
  f.push_back(real_field("mission", "loop_closure_radius", "m", 0.0, 10000.0,
                         "the car must be this close to its start for the lap to be taken (0: anywhere)", ACC(mission.loop_closure_radius)));
  f.push_back(real_field("mission", "lap_switch_offset", "m", 0.0, 10.0, "the closed lap takes over where the car is this close to it",
                         ACC(mission.lap_switch_offset)));

  // [event]
  f.push_back(real_field("event", "timeout", "s", 1.0, 86400.0, "sim time after the go before a DNF", ACC(event.timeout)));
  f.push_back(real_field("event", "stop_time", "s", 1.0, 600.0, "time after the finish to come to rest", ACC(event.stop_time)));
  f.push_back(real_field("event", "off_track_dnf_time", "s", 0.01, 600.0, "time with all wheels off that ends the run",
                         ACC(event.off_track_dnf_time)));
  f.push_back(real_field("event", "stall_time", "s", 0.1, 600.0, "time at rest before the finish that ends the run", ACC(event.stall_time)));
  f.push_back(real_field("event", "standstill_speed", "m/s", 0.0, 5.0, "slower counts as at rest", ACC(event.standstill_speed)));

  // [sim]
  f.push_back(int_field("sim", "physics_rate", "Hz", 1, 100000, "vehicle and world integration rate", ACC(sim.physics_rate)));
  f.push_back(int_field("sim", "control_rate", "Hz", 1, 100000, "stack cycle rate", ACC(sim.control_rate)));
  f.push_back(int_field("sim", "log_rate", "Hz", 1, 100000, "log.csv rows and off-course checks", ACC(sim.log_rate)));
  f.push_back(real_field("sim", "snapshot_time", "s", 0.0, 1e6, "the first LiDAR scan after this is kept for the perception figures",
                         ACC(sim.snapshot_time)));

  // [cone_sensor], [vehicle] and [cones]: see add_cone_sensor_fields, add_vehicle_fields and add_cone_fields
  add_cone_sensor_fields(f);
  add_odometry_fields(f);
  add_lidar_fields(f);
  add_perception_fields(f);
  add_vehicle_fields(f);
  add_cone_fields(f);

  // [expect]
  f.push_back(expect_field<bool>("finished", "", "the run finishes", ACC(expect.finished)));
  f.push_back(expect_field<int>("laps", "", "completed laps", ACC(expect.laps)));
  f.push_back(expect_field<int>("doo_max", "", "cones down or out, at most", ACC(expect.doo_max)));
  f.push_back(expect_field<int>("oc_max", "", "off-course excursions, at most", ACC(expect.oc_max)));
  f.push_back(expect_field<int>("uss_max", "", "unsafe stops, at most", ACC(expect.uss_max)));
  f.push_back(expect_field<double>("lap_time_max", "s", "every lap at most", ACC(expect.lap_time_max)));
  f.push_back(expect_field<double>("lap_time_min", "s", "every lap at least", ACC(expect.lap_time_min)));
  f.push_back(expect_field<double>("total_time_max", "s", "penalised time at most", ACC(expect.total_time_max)));
  f.push_back(expect_field<double>("lateral_rms_max", "m", "RMS lateral error at most", ACC(expect.lateral_rms_max)));
  f.push_back(expect_field<double>("lateral_error_max", "m", "largest lateral error at most", ACC(expect.lateral_error_max)));
  f.push_back(expect_field<int>("fallbacks_max", "", "safe-stop control cycles, at most", ACC(expect.fallbacks_max)));
  return f;
}

}  // namespace

double parse_quantity(const IniEntry& e, const std::string& unit, double lo, double hi) {
  const std::string& v = e.value;
  const char* begin = v.c_str();
  char* end = nullptr;
  errno = 0;
  const double x = std::strtod(begin, &end);
  const std::string what = "[" + e.section + "] " + e.key;
  const std::string expected = "expected a number" + (unit.empty() ? std::string() : " in " + unit);
  if (end == begin || errno == ERANGE || !std::isfinite(x)) {
    throw UserError(e.where() + ": " + what + " = '" + v + "' is not a number; " + expected);
  }
  const std::string suffix = trim(std::string(end));
  double factor = 1.0;
  if (!suffix.empty() && suffix != unit) {
    const auto table = conversions().find(unit);
    const auto conv = table == conversions().end() ? nullptr : &table->second;
    if (!conv || conv->find(suffix) == conv->end()) {
      throw UserError(e.where() + ": " + what + " = '" + v + "': unit '" + suffix + "' does not fit; " + expected);
    }
    factor = conv->at(suffix);
  }
  const double value = x * factor;
  if (value < lo || value > hi) {
    throw UserError(e.where() + ": " + what + " = " + v + " is out of range; expected " + range_text(lo, hi, unit));
  }
  return value;
}

long parse_integer(const IniEntry& e, long lo, long hi) {
  const char* begin = e.value.c_str();
  char* end = nullptr;
  errno = 0;
  const long x = std::strtol(begin, &end, 10);
  const std::string what = "[" + e.section + "] " + e.key;
  if (end == begin || *end != '\0' || errno == ERANGE) {
    throw UserError(e.where() + ": " + what + " = '" + e.value + "' is not an integer; expected a whole number");
  }
  if (x < lo || x > hi) {
    throw UserError(e.where() + ": " + what + " = " + e.value + " is out of range; expected between " + std::to_string(lo) +
                    " and " + std::to_string(hi));
  }
  return x;
}

bool parse_bool(const IniEntry& e) {
  if (e.value == "true" || e.value == "yes" || e.value == "on" || e.value == "1") return true;
  if (e.value == "false" || e.value == "no" || e.value == "off" || e.value == "0") return false;
  throw UserError(e.where() + ": [" + e.section + "] " + e.key + " = '" + e.value + "' is not a boolean; expected true or false");
}

const std::vector<Field>& scenario_fields() {
  static const std::vector<Field> fields = build_fields();
  return fields;
}

Scenario load_scenario(const std::string& path, const std::vector<std::string>& overrides) {
  std::vector<IniEntry> entries = read_ini_file(path);
  // command-line overrides come last, so they win
  for (std::size_t i = 0; i < overrides.size(); ++i) {
    const std::string& o = overrides[i];
    const auto dot = o.find('.');
    const auto eq = o.find('=');
    if (dot == std::string::npos || eq == std::string::npos || dot > eq) {
      throw UserError("--set " + o + ": expected section.key=value");
    }
    entries.push_back({trim(o.substr(0, dot)), trim(o.substr(dot + 1, eq - dot - 1)), trim(o.substr(eq + 1)), "--set",
                       static_cast<int>(i + 1)});
  }

  // every entry must name a known key; later entries override earlier ones
  const auto& fields = scenario_fields();
  std::map<std::pair<std::string, std::string>, const Field*> index;
  std::set<std::string> sections;
  for (const auto& f : fields) {
    index[{f.section, f.key}] = &f;
    sections.insert(f.section);
  }
  Scenario s;
  std::set<std::pair<std::string, std::string>> given;
  for (const auto& e : entries) {
    if (!sections.count(e.section)) {
      std::string known;
      for (const auto& n : sections) known += (known.empty() ? "" : ", ") + ("[" + n + "]");
      throw UserError(e.where() + ": unknown section [" + e.section + "]; expected one of: " + known);
    }
    const auto it = index.find({e.section, e.key});
    if (it == index.end()) {
      std::string known;
      for (const auto& f : fields)
        if (f.section == e.section) known += (known.empty() ? "" : ", ") + f.key;
      throw UserError(e.where() + ": unknown key '" + e.key + "' in [" + e.section + "]; expected one of: " + known);
    }
    it->second->set(s, e);
    given.insert({e.section, e.key});
  }
  for (const auto& f : fields) {
    if (f.required && !given.count({f.section, f.key})) {
      throw UserError(path + ": [" + f.section + "] " + f.key + " is not set" +
                      (f.unit.empty() ? "" : " (" + f.unit + ")") +
                      (f.section == "vehicle" ? "; include a vehicle file, e.g. include = vehicles/default.ini" : ""));
    }
  }

  // whole-scenario checks
  if (const std::string why = params::validate(s.vehicle); !why.empty()) throw UserError(path + ": [vehicle] " + why);
  if (s.sim.physics_rate % s.sim.control_rate != 0 || s.sim.physics_rate % s.sim.log_rate != 0) {
    throw UserError(path + ": [sim] physics_rate (" + std::to_string(s.sim.physics_rate) +
                    " Hz) must be a whole multiple of control_rate and log_rate");
  }
  if (const std::string why = params::validate(s.control); !why.empty()) throw UserError(path + ": [control] " + why);
  if (const std::string why = params::validate(stack_params(s).vehicle); !why.empty()) {
    throw UserError(path + ": [control] vehicle." + why);
  }
  if (const std::string why = params::validate(s.cone_sensor); !why.empty()) throw UserError(path + ": [cone_sensor] " + why);
  if (const std::string why = params::validate(s.planning); !why.empty()) throw UserError(path + ": [planning] " + why);
  if (const std::string why = params::validate(s.imu); !why.empty()) throw UserError(path + ": [imu] " + why);
  if (const std::string why = params::validate(s.wheel_speeds); !why.empty()) throw UserError(path + ": [wheel_speeds] " + why);
  if (const std::string why = params::validate(s.steering_sensor); !why.empty()) throw UserError(path + ": [steering_sensor] " + why);
  if (const std::string why = params::validate(s.lidar); !why.empty()) throw UserError(path + ": [lidar] " + why);
  if (const std::string why = params::validate(s.ground); !why.empty()) throw UserError(path + ": [ground] " + why);
  if (const std::string why = params::validate(s.camera); !why.empty()) throw UserError(path + ": [camera] " + why);
  if (const std::string why = sensors::validate(s.detector); !why.empty()) throw UserError(path + ": [detector] " + why);
  if (const std::string why = params::validate(stack_params(s).perception); !why.empty()) {
    throw UserError(path + ": [perception] " + why);
  }

  s.source = path;
  s.name = std::filesystem::path(path).stem().string();
  return s;
}

std::string resolved_ini(const Scenario& s) {
  std::ostringstream o;
  o << "; the resolved scenario of a run: every key, defaults included, in SI units\n";
  o << "; from " << s.source << "\n";
  std::string section;
  for (const auto& f : scenario_fields()) {
    if (f.section != section) {
      section = f.section;
      o << "\n[" << section << "]\n";
    }
    const std::string v = f.get(s);
    std::string comment = f.unit.empty() ? f.doc : f.doc.empty() ? f.unit : f.unit + ", " + f.doc;
    if (v.empty()) o << "; " << f.key << " =  ; (not checked) " << comment << "\n";
    else o << f.key << " = " << v << "  ; " << comment << "\n";
  }
  return o.str();
}

}  // namespace paddock::runner

namespace paddock::runner {

world::TrackFile load_track_file(const std::string& path) {
  return world::parse_track(read_file(path), path);
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
                                        {"detector", 6, 0}};
  for (const Stream& s : kStreams)
    if (s.name == stream) return (scenario_seed * 0x9E3779B97F4A7C15ULL + s.offset) ^ s.scramble;
  assert(false && "unknown random stream");
  return scenario_seed;
}

stack::StackParams stack_params(const Scenario& s) {
  stack::StackParams p;
  p.modes = s.autonomy;
  p.control = s.control;
  p.mission = s.mission;
  p.cone_map = s.cone_map;
  // what the stack knows of its car comes from the same [vehicle] section as
  // the simulated car: one place for each value
  const vehicle::VehicleParams& v = s.vehicle;
  control::VehicleKnowledge& k = p.vehicle;
  k.mass = v.mass;
  k.lf = v.lf;
  k.lr = v.lr;
  k.wheelbase = v.lf + v.lr;
  k.front_cornering_stiffness = control::front_axle_cornering_stiffness(v.tyre_b, v.tyre_c, v.tyre_d, v.mass, v.lf, v.lr);
  k.max_steering_angle = v.steering_max;
  k.max_drive_force = v.cm1;
  k.max_brake_force = v.brake_force_max;
  k.drag_coefficient = v.c_drag;
  k.rolling_resistance = v.cr0;
  // perception: the sensors' calibration is their true mounting and layout,
  // the odometry's wheel radius the car's
  p.perception = s.perception;
  p.perception.odometry.wheel_radius = v.wheel_radius;
  p.perception.lidar.calibration = static_cast<const hal::LidarLayout&>(s.lidar);
  p.perception.camera = sensors::camera_calibration(s.camera);
  p.planner = s.planning;
  p.planner.reference.profile.mass = v.mass;
  p.planner.reference.profile.drag_coefficient = v.c_drag;
  // the skidpad's reference uses the same planned limits
  p.skidpad = s.skidpad;
  p.skidpad.reference = p.planner.reference;
  return p;
}

}  // namespace paddock::runner
