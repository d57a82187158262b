#pragma once
// timed faults ([faults]): what goes wrong on the car during a run, injected
// between the simulated hardware and the HAL, seeded like every random draw of
// the run (stream "faults"). Each kind is a section of its own; a kind whose
// `at` is unset is not injected. Times are the run's sim time (s, the log's
// t); a duration of 0 lasts to the end of the run.
//
//   [faults.lidar]     dropout: whole rotations, an azimuth sector, or a band of rings
//   [faults.camera]    dead (no detections) or frozen (the same image, newly stamped)
//   [faults.imu]       a bias step on the accelerometer and gyro, and spikes
//   [faults.wheel]     one wheel-speed sensor stuck at its last value, or noisy
//   [faults.steering]  an offset on the steering sensor, or on the actuator
//   [faults.control]   the stack's computer stalls: no control cycle runs
//   [faults.can]       a share of the VCU's CAN frames lost
//   [faults.res]       the RES's emergency stop pressed
//   [faults.ebs]       the EBS's tank loses its pressure
//   [faults.cones]     cones of the wrong colour (blue and yellow swapped)
//   [faults.object]    a spectator's object by the track edge: a bag, a person's legs
//   [faults.rain]      rain: LiDAR returns lost, the tyres' grip down
//   [faults.wind]      a gust moves the cones of a stretch of track, and topples some
#include <cstdint>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "autonomy/common/params.h"
#include "autonomy/common/time.h"
#include "autonomy/hal/messages.h"
#include "sim/sensors/lidar.h"
#include "sim/vehicle/vehicle.h"
#include "sim/world/track.h"
#include "sim/world/venue.h"

namespace paddock::runner {

// when a fault is on: from `at` for `duration` (0: to the end)
struct FaultWindow {
  std::optional<double> at;
  double duration = 0.0;
  bool on(double t) const { return at && t >= *at && (duration <= 0.0 || t < *at + duration); }
  // the window's two keys; at_doc says what begins at `at`
  template <class V>
  void visit_window(V& v, const char* at_doc) {
    v(PADDOCK_PARAM(at), {"s", params::at_least(0.0), at_doc});
    v(PADDOCK_PARAM(duration), {"s", params::at_least(0.0), "how long it lasts (0: to the end of the run)"});
  }
};

enum class LidarDropout { Rotations, Sector, Rings };
struct LidarFault : FaultWindow {
  LidarDropout mode = LidarDropout::Rotations;
  double sector_from = -0.5;  // rad, sensor azimuth (0 ahead, > 0 left)
  double sector_to = 0.5;
  int ring_first = 0;
  int ring_last = 15;

  static constexpr params::Choice<LidarDropout> kModes[] = {
      {"rotations", LidarDropout::Rotations}, {"sector", LidarDropout::Sector}, {"rings", LidarDropout::Rings}};
  template <class V>
  void visit(V& v) {
    visit_window(v, "sim time the LiDAR dropout begins (unset: no such fault)");
    v(PADDOCK_PARAM(mode), kModes, "rotations: no packets at all; sector: no returns in [sector_from, sector_to]; rings: none from rings ring_first..ring_last");
    v(PADDOCK_PARAM(sector_from), {"rad", params::in(-3.1416, 3.1416), "mode = sector: the sector's first azimuth (0 ahead, > 0 left)"});
    v(PADDOCK_PARAM(sector_to), {"rad", params::in(-3.1416, 3.1416), "mode = sector: its last azimuth (counter-clockwise from sector_from)"});
    v(PADDOCK_PARAM(ring_first), {"", params::in(0, 1023), "mode = rings: the lowest ring lost"});
    v(PADDOCK_PARAM(ring_last), {"", params::in(0, 1023), "mode = rings: the highest ring lost"});
  }
  std::string check() const { return ring_last < ring_first ? "ring_last must be at least ring_first" : ""; }
};

enum class CameraFaultMode { Dead, Frozen };
struct CameraFault : FaultWindow {
  CameraFaultMode mode = CameraFaultMode::Dead;
  static constexpr params::Choice<CameraFaultMode> kModes[] = {{"dead", CameraFaultMode::Dead},
                                                               {"frozen", CameraFaultMode::Frozen}};
  template <class V>
  void visit(V& v) {
    visit_window(v, "sim time the camera fault begins (unset: no such fault)");
    v(PADDOCK_PARAM(mode), kModes, "dead: no frames, so no detections; frozen: the last image again, newly stamped");
  }
};

struct ImuFault : FaultWindow {
  double bias_ax = 0.0;        // m/s^2 added
  double bias_ay = 0.0;
  double bias_yaw_rate = 0.0;  // rad/s added
  double spike_rate = 0.0;     // spikes a second
  double spike_accel = 0.0;    // m/s^2, a spike's size on ax and ay (random sign)
  double spike_yaw_rate = 0.0; // rad/s, on the yaw rate
  template <class V>
  void visit(V& v) {
    visit_window(v, "sim time the IMU fault begins (unset: no such fault)");
    v(PADDOCK_PARAM(bias_ax), {"m/s^2", params::in(-50.0, 50.0), "a step on the forward accelerometer's bias"});
    v(PADDOCK_PARAM(bias_ay), {"m/s^2", params::in(-50.0, 50.0), "a step on the lateral accelerometer's bias"});
    v(PADDOCK_PARAM(bias_yaw_rate), {"rad/s", params::in(-5.0, 5.0), "a step on the gyro's yaw-rate bias"});
    v(PADDOCK_PARAM(spike_rate), {"Hz", params::in(0.0, 10000.0), "spikes a second (each sample: probability rate x period)"});
    v(PADDOCK_PARAM(spike_accel), {"m/s^2", params::in(0.0, 500.0), "a spike's size on ax and ay"});
    v(PADDOCK_PARAM(spike_yaw_rate), {"rad/s", params::in(0.0, 50.0), "a spike's size on the yaw rate"});
  }
};

enum class WheelFaultMode { Stuck, Noisy };
struct WheelFault : FaultWindow {
  int wheel = 0;  // 0 FL, 1 FR, 2 RL, 3 RR
  WheelFaultMode mode = WheelFaultMode::Stuck;
  double noise = 5.0;  // rad/s, standard deviation
  static constexpr params::Choice<WheelFaultMode> kModes[] = {{"stuck", WheelFaultMode::Stuck},
                                                              {"noisy", WheelFaultMode::Noisy}};
  template <class V>
  void visit(V& v) {
    visit_window(v, "sim time the wheel-speed fault begins (unset: no such fault)");
    v(PADDOCK_PARAM(wheel), {"", params::in(0, 3), "the sensor: 0 front left, 1 front right, 2 rear left, 3 rear right"});
    v(PADDOCK_PARAM(mode), kModes, "stuck: it repeats its last reading; noisy: white noise added");
    v(PADDOCK_PARAM(noise), {"rad/s", params::in(0.0, 1000.0), "mode = noisy: the noise's standard deviation"});
  }
};

enum class SteeringFaultMode { Sensor, Actuator };
struct SteeringFault : FaultWindow {
  SteeringFaultMode mode = SteeringFaultMode::Sensor;
  double offset = 0.0;  // rad
  static constexpr params::Choice<SteeringFaultMode> kModes[] = {{"sensor", SteeringFaultMode::Sensor},
                                                                 {"actuator", SteeringFaultMode::Actuator}};
  template <class V>
  void visit(V& v) {
    visit_window(v, "sim time the steering offset begins (unset: no such fault)");
    v(PADDOCK_PARAM(mode), kModes, "sensor: the measured angle is off; actuator: the road wheels are off the request (the sensor reads them true)");
    v(PADDOCK_PARAM(offset), {"rad", params::in(-0.5, 0.5), "the offset, > 0 left"});
  }
};

struct ControlFault : FaultWindow {
  template <class V>
  void visit(V& v) {
    visit_window(v, "sim time the stall of the stack's computer (no control cycle) begins (unset: no such fault)");
  }
};

struct CanFault : FaultWindow {
  double loss = 0.5;  // share of the VCU's frames lost
  template <class V>
  void visit(V& v) {
    visit_window(v, "sim time the CAN frame loss begins (unset: no such fault)");
    v(PADDOCK_PARAM(loss), {"", params::fraction(), "the share of the VCU's frames (IMU, wheels, steering, RES, status) lost"});
  }
};

struct ResFault {
  std::optional<double> at;
  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(at), {"s", params::at_least(0.0), "sim time the RES's emergency stop is pressed (unset: never)"});
  }
};

struct EbsFault {
  std::optional<double> at;
  double pressure = 0.0;  // bar left in the tank
  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(at), {"s", params::at_least(0.0), "sim time the EBS's tank loses its pressure (unset: never)"});
    v(PADDOCK_PARAM(pressure), {"bar", params::in(0.0, 40.0), "the pressure left"});
  }
};

struct ConesFault {
  std::optional<double> at;
  int wrong_colour = 4;  // blue and yellow cones whose colour is swapped
  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(at), {"s", params::at_least(0.0), "sim time from which cones stand in the wrong colour (unset: never)"});
    v(PADDOCK_PARAM(wrong_colour), {"", params::in(0, 10000), "how many blue or yellow cones, drawn at random, show the other colour"});
  }
};

enum class ObjectKind { Bag, Legs };
struct ObjectFault {
  std::optional<double> at;
  ObjectKind kind = ObjectKind::Legs;
  double along = 60.0;       // m along the centreline from its start
  double edge_offset = 0.3;  // m beyond the boundary (> 0 outside the track)
  bool left = true;
  static constexpr params::Choice<ObjectKind> kKinds[] = {{"bag", ObjectKind::Bag}, {"legs", ObjectKind::Legs}};
  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(at), {"s", params::at_least(0.0), "sim time from which the object stands there (unset: never)"});
    v(PADDOCK_PARAM(kind), kKinds, "bag: a 0.4 x 0.3 x 0.3 m box; legs: two 0.12 m posts 0.9 m high, 0.25 m apart");
    v(PADDOCK_PARAM(along), {"m", params::at_least(0.0), "where: this far along the centreline from its start"});
    v(PADDOCK_PARAM(edge_offset), {"m", params::in(-2.0, 20.0), "this far beyond the boundary (> 0 outside the track)"});
    v(PADDOCK_PARAM(left), "by the left boundary (false: the right)");
  }
};

struct RainFault : FaultWindow {
  double returns_lost = 0.3;  // share of the LiDAR's returns
  double grip = 0.6;          // factor on the tyres' peak friction
  template <class V>
  void visit(V& v) {
    visit_window(v, "sim time the rain begins (unset: no such fault)");
    v(PADDOCK_PARAM(returns_lost), {"", params::fraction(), "the share of the LiDAR's returns the spray and drops take"});
    v(PADDOCK_PARAM(grip), {"", params::in(0.1, 1.0), "the tyres' peak friction (lateral and longitudinal) is this times the dry one"});
  }
};

struct WindFault {
  std::optional<double> at;
  double along = 60.0;       // m along the centreline from its start
  double radius = 6.0;       // m around that point
  double direction = 1.5708; // rad from the centreline's heading there (> 0 to the left)
  double slide = 0.5;        // m, the mean slide
  double topple = 0.3;       // share of the moved cones that fall over
  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(at), {"s", params::at_least(0.0), "sim time the gust comes (unset: never)"});
    v(PADDOCK_PARAM(along), {"m", params::at_least(0.0), "where: this far along the centreline from its start"});
    v(PADDOCK_PARAM(radius), {"m", params::in(0.0, 100.0), "the cones within this distance of that point are moved"});
    v(PADDOCK_PARAM(direction), {"rad", params::in(-3.1416, 3.1416), "where the wind blows to, from the centreline's heading there (0 along it, > 0 to the left)"});
    v(PADDOCK_PARAM(slide), {"m", params::in(0.0, 10.0), "how far a cone slides, on average (each from 0.5 to 1.5 times this, its direction within 0.2 rad)"});
    v(PADDOCK_PARAM(topple), {"", params::fraction(), "the share of the moved cones that fall over"});
  }
};

// [faults]
struct FaultsSection {
  LidarFault lidar;
  CameraFault camera;
  ImuFault imu;
  WheelFault wheel;
  SteeringFault steering;
  ControlFault control;
  CanFault can;
  ResFault res;
  EbsFault ebs;
  ConesFault cones;
  ObjectFault object;
  RainFault rain;
  WindFault wind;

  template <class V>
  void visit(V& v) {
    v.section(PADDOCK_PARAM(lidar), "a LiDAR dropout: rotations, a sector, rings");
    v.section(PADDOCK_PARAM(camera), "a dead or frozen camera");
    v.section(PADDOCK_PARAM(imu), "an IMU bias step and spikes");
    v.section(PADDOCK_PARAM(wheel), "a wheel-speed sensor stuck or noisy");
    v.section(PADDOCK_PARAM(steering), "a steering offset (sensor or actuator)");
    v.section(PADDOCK_PARAM(control), "a stall of the stack's computer");
    v.section(PADDOCK_PARAM(can), "CAN frames lost");
    v.section(PADDOCK_PARAM(res), "the RES's emergency stop");
    v.section(PADDOCK_PARAM(ebs), "the EBS losing its pressure");
    v.section(PADDOCK_PARAM(cones), "cones of the wrong colour");
    v.section(PADDOCK_PARAM(object), "a spectator's object by the track edge");
    v.section(PADDOCK_PARAM(rain), "rain: LiDAR returns lost, less grip");
    v.section(PADDOCK_PARAM(wind), "a gust that moves cones (not the car's DOO) and topples some");
  }
};

// one fault of the scenario, for the summary
struct FaultNote {
  std::string name;      // "lidar", "camera", ...
  std::string what;      // in words
  double at = 0.0;       // s
};

// the faults the scenario injects, in words, by time
std::vector<FaultNote> fault_notes(const FaultsSection& f);

// the faults at work in one run (a SimState's): each sensor's output passes here
class FaultInjector {
 public:
  FaultInjector(const FaultsSection& faults, std::uint64_t seed) : f_(faults), rng_(seed) {}
  // where the faults meet the world: the object's place by the track, the
  // cones whose colour is swapped (drawn from `cones`, the event's)
  void place(const world::TrackModel& track, const std::vector<Cone>& cones);

  // whether the LiDAR sends the rotation that ends at t (s) at all
  bool lidar_sends(double t) const { return !(f_.lidar.mode == LidarDropout::Rotations && f_.lidar.on(t)); }
  // drops the points a sector or ring dropout, or the rain, loses (rotation ending at t)
  void filter_lidar(double t, std::vector<sensors::LidarPoint>& points);
  // the colour cone i (of `color`) shows at t
  ConeColor colour(int i, ConeColor color, double t) const;
  // the spectator's object at t (none before it comes)
  const std::vector<world::Block>& objects(double t) const {
    static const std::vector<world::Block> none;
    return f_.object.at && t >= *f_.object.at ? object_ : none;
  }
  // the cones the gust moves: each once, at the first call at or after the
  // gust's time (empty otherwise)
  struct Gust {
    int cone = -1;
    Vec2 shift;  // m, map frame
    bool topple = false;
  };
  std::vector<Gust> gust_due(double t);
  // the gust in words: how many cones it moves, how many it topples
  std::string gust_words() const;
  // the tyres' peak friction factor at t (1 dry)
  double grip(double t) const { return f_.rain.on(t) ? f_.rain.grip : 1.0; }
  // the camera at t: true when its frame (and so its detections) is lost
  bool camera_dead(double t) const { return f_.camera.mode == CameraFaultMode::Dead && f_.camera.on(t); }
  bool camera_frozen(double t) const { return f_.camera.mode == CameraFaultMode::Frozen && f_.camera.on(t); }
  // the sensors' samples at t, as the faults change them
  void apply(double t, hal::Imu& m, double period);
  void apply(double t, hal::WheelSpeeds& m);
  void apply(double t, hal::SteeringAngle& m) const;
  // the actuators' input: a steering actuator's offset
  void apply(double t, vehicle::DriverInput& in) const;
  // whether the stack's computer runs its cycle at t
  bool control_runs(double t) const { return !f_.control.on(t); }
  // whether a CAN frame sent at t arrives
  bool can_delivers(double t);
  bool res_pressed(double t) const { return f_.res.at && t >= *f_.res.at; }
  std::optional<double> ebs_tank(double t) const {
    return f_.ebs.at && t >= *f_.ebs.at ? std::optional<double>(f_.ebs.pressure) : std::nullopt;
  }

 private:
  FaultsSection f_;
  std::mt19937_64 rng_;
  std::optional<double> stuck_;  // the stuck wheel's frozen reading
  std::vector<world::Block> object_;
  std::vector<int> recoloured_;  // sorted cone indices
  std::vector<Gust> gust_;       // the gust's cones, drawn in place()
  bool gust_done_ = false;
};

}  // namespace paddock::runner
