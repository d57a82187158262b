#include "sim/runner/model.h"

#include <algorithm>
#include <cmath>

namespace paddock::runner {
namespace {

// points every `step` metres along an arc of a circle around c, from angle a0
// turning by `sweep` (> 0 counter-clockwise), the start point excluded
void append_arc(std::vector<Vec2>& out, Vec2 c, double r, double a0, double sweep, double step) {
  const int n = std::max(1, static_cast<int>(std::ceil(std::abs(sweep) * r / step)));
  for (int i = 1; i <= n; ++i) out.push_back(c + unit_from_angle(a0 + sweep * i / n) * r);
}

// points every `step` metres from a (excluded) to b (included)
void append_line(std::vector<Vec2>& out, Vec2 a, Vec2 b, double step) {
  const int n = std::max(1, static_cast<int>(std::ceil(distance(a, b) / step)));
  for (int i = 1; i <= n; ++i) out.push_back(a + (b - a) * (static_cast<double>(i) / n));
}

// the skidpad's path from the rules' geometry: in, right circle twice, left twice, out
std::vector<Vec2> skidpad_path(const world::SkidpadGeometry& g) {
  const double step = 0.5;
  std::vector<Vec2> p{g.entry_start};
  append_line(p, g.entry_start, g.crossing, step);
  const double a_right = angle_of(g.crossing - g.centre_right);
  const double a_left = angle_of(g.crossing - g.centre_left);
  append_arc(p, g.centre_right, g.radius, a_right, -4.0 * kPi, step);
  append_arc(p, g.centre_left, g.radius, a_left, 4.0 * kPi, step);
  // the lane ends in a cone: stop the base 5 m short of it (nose ~2.3 m ahead of the base)
  const Vec2 out = g.exit_end - unit_from_angle(g.heading) * 5.0;
  append_line(p, g.crossing, out, step);
  return p;
}

}  // namespace

SimModel compile_model(const Scenario& scenario, const world::TrackModel& track) {
  SimModel m(scenario);
  m.track = track;
  m.cones = event_cones(track);
  m.blocks = world::venue_blocks(track, m.cones, scenario.venue);
  m.footprint = vehicle::footprint(scenario.vehicle);
  m.start = start_pose(track, m.footprint.x_max);
  m.stack = stack_params(scenario);
  m.mission = mission_for(scenario.scenario.event, track, scenario.autonomy.planner);
  // where the team placed the car: the origin of the stack's own estimate
  m.mission.start_pose = m.start;

  // the object-level sensor knows the cones' true sizes; the raw sensors see them
  m.cone_sensor = scenario.cone_sensor;
  m.cone_sensor.small_cone_radius = 0.5 * scenario.cones.small_cone.base_width;
  m.cone_sensor.big_cone_radius = 0.5 * scenario.cones.big_cone.base_width;
  m.raw_perception = scenario.autonomy.perception != stack::PerceptionMode::GroundTruth;
  if (scenario.autonomy.perception == stack::PerceptionMode::LidarCamera) m.camera = scenario.camera;
  m.perception_mount = m.raw_perception ? Vec2{scenario.lidar.mount_x, scenario.lidar.mount_y}
                                        : Vec2{scenario.cone_sensor.mount_x, scenario.cone_sensor.mount_y};

  // time: the physics step, and every periodic part as a whole number of steps
  const SimSection& sim = scenario.sim;
  m.dt = 1.0 / sim.physics_rate;
  m.dt_ns = kNsPerSecond / sim.physics_rate;
  const auto steps_per = [&sim](double rate) { return std::max(1L, std::lround(sim.physics_rate / rate)); };
  m.every.control = sim.physics_rate / sim.control_rate;
  m.every.log = sim.physics_rate / sim.log_rate;
  m.every.cone_sensor = steps_per(m.cone_sensor.rate);
  m.every.imu = steps_per(scenario.imu.rate);
  m.every.wheel_speeds = steps_per(scenario.wheel_speeds.rate);
  m.every.steering = steps_per(scenario.steering_sensor.rate);
  m.every.vcu_status = sim.physics_rate / scenario.vcu.status_rate;
  m.go = from_seconds(scenario.scenario.go_time);
  // (a scan's cones are scored when perception delivers them, its latency later)
  const TimeNs latency = from_seconds(scenario.perception.latency);
  m.pose_history_span = std::max(kNsPerSecond, 2 * from_seconds(1.0 / scenario.lidar.rate)) + latency;
  m.visible_scans = 4 + static_cast<std::size_t>(std::ceil(scenario.perception.latency * scenario.lidar.rate));
  m.log_samples = static_cast<std::size_t>(
      std::min(scenario.event.longest_run() * sim.log_rate + 1.0, static_cast<double>(kMaxReservedSamples)));
  return m;
}

stack::MissionSpec mission_for(events::EventKind kind, const world::TrackModel& track, stack::PlannerMode planner) {
  stack::MissionSpec m;
  const events::Rules rules = events::rules_for(kind);
  const bool oracle = planner == stack::PlannerMode::Oracle;
  switch (kind) {
    case events::EventKind::Trackdrive:
    case events::EventKind::Autocross:
      // the first crossing starts lap 1, so the finish is one more
      m.mission = kind == events::EventKind::Trackdrive ? stack::Mission::Trackdrive : stack::Mission::Autocross;
      m.finish_crossings = rules.laps + 1;
      if (oracle) {
        m.oracle_path = track.centreline;
        m.oracle_closed = track.closed;
        if (!track.gates.empty()) m.gates = {track.gates.front()};
      }
      break;
    case events::EventKind::Acceleration:
      // the start gate, then the finish gate 75 m on
      m.mission = stack::Mission::Acceleration;
      m.finish_crossings = 2;
      if (oracle) {
        m.oracle_path = track.centreline;
        m.gates = track.gates;
      }
      break;
    case events::EventKind::Skidpad:
      // the path ends at rest in the exit lane; no gates to count
      m.mission = stack::Mission::Skidpad;
      m.finish_crossings = 0;
      if (oracle && track.skidpad) m.oracle_path = skidpad_path(*track.skidpad);
      break;
  }
  return m;
}

std::vector<Cone> event_cones(const world::TrackModel& track) {
  std::vector<Cone> cones = track.cones;
  for (const Cone& c : cones)
    if (c.color == ConeColor::BigOrange) return cones;
  for (const Segment& g : track.gates) {
    cones.push_back({g.a, ConeColor::BigOrange});
    cones.push_back({g.b, ConeColor::BigOrange});
  }
  return cones;
}

Pose2 start_pose(const world::TrackModel& track, double nose_offset) {
  Pose2 start = track.start;
  if (track.gates.empty()) return start;
  // the nose's distance behind the gate's line, along the heading
  const Segment& g = track.gates.front();
  const Vec2 nose = start.transform({nose_offset, 0.0});
  const Vec2 across = g.b - g.a;
  const Vec2 forward = left_normal(across) / norm(across);  // from the gate's right side to its left
  const double behind = dot(g.a - nose, forward);
  const double clearance = 0.3;  // m, front of the car behind the start line
  const double heading_along = dot(start.heading(), forward);
  // only a start just at the line is moved (a start metres before it stays)
  if (behind < clearance && behind > -nose_offset - 1.0 && heading_along > 0.5) {
    const Vec2 shift = start.heading() * ((clearance - behind) / heading_along);
    start.x -= shift.x;
    start.y -= shift.y;
  }
  return start;
}

}  // namespace paddock::runner
