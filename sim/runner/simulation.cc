#include "sim/runner/simulation.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <memory>
#include <optional>

#include "sim/runner/raw_sensors.h"
#include "sim/runner/sim_hal.h"
#include "sim/sensors/cone_sensor.h"
#include "sim/sensors/imu.h"
#include "sim/sensors/odometry_sensors.h"
#include "sim/vehicle/vehicle.h"
#include "sim/world/cone_world.h"

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

// frame: the camera frame the runner rendered last (the one of the scan the
// stack just processed), or null
PerceptionSnapshot take_snapshot(const perception::Perception& p, const hal::CameraFrame* frame, const Pose2& pose,
                                 const world::ConeWorld& cones) {
  const perception::PerceptionFrame& f = p.last();
  PerceptionSnapshot s;
  s.t = to_seconds(f.output.stamp);
  for (const perception::LabelledPoint& q : f.lidar.points) {
    const std::uint8_t label = q.label == perception::PointLabel::Ground ? 0 : q.label == perception::PointLabel::Cone ? 2 : 1;
    s.points.push_back({q.x, q.y, q.z, label});
  }
  for (const hal::DetectedCone& c : f.output.cones) s.detected.push_back({c.position, c.color});
  for (int i = 0; i < cones.cone_count(); ++i) {
    const Vec2 local = pose.inverse_transform(cones.cone_position(i));
    if (norm(local) <= 40.0) s.truth.push_back({local, cones.cone(i).color});
  }
  if (f.camera_used && frame != nullptr && frame->stamp == f.camera_stamp) {
    s.camera = true;
    s.width = frame->width;
    s.height = frame->height;
    s.rgb = frame->rgb;
    for (const perception::BoundingBox& b : f.detections.boxes) s.boxes.push_back({b.x_min, b.y_min, b.x_max, b.y_max, b.color});
    for (const perception::FusedCone& c : f.fusion.cones) {
      if (!c.projected) continue;
      (c.source == perception::FusionSource::Dropped ? s.dropped : s.projected).push_back({c.pixel.x(), c.pixel.y()});
    }
  }
  return s;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

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

RunResult run(const Scenario& sc, const world::TrackModel& track) {
  const auto wall0 = std::chrono::steady_clock::now();
  const vehicle::VehicleParams& vp = sc.vehicle;
  const double dt = 1.0 / sc.sim.physics_rate;
  const TimeNs dt_ns = kNsPerSecond / sc.sim.physics_rate;
  const int control_every = sc.sim.physics_rate / sc.sim.control_rate;
  const int log_every = sc.sim.physics_rate / sc.sim.log_rate;
  const double log_dt = 1.0 / sc.sim.log_rate;

  // the world: car at the start pose, at rest, brakes on; cones in place
  const vehicle::Footprint footprint = vehicle::footprint(vp);
  vehicle::VehicleState car = vehicle::initial_state(vp, start_pose(track, footprint.x_max));
  world::ConeWorld cones(event_cones(track), sc.cones, world::Footprint{-footprint.x_min, footprint.x_max, footprint.y_max});
  events::Event event(sc.scenario.event, track, sc.event);
  stack::Stack stack(stack_params(sc), mission_for(sc.scenario.event, track, sc.autonomy.planner));
  SimHal hal;

  // perception = ground_truth: the object-level cone sensor, on its own random
  // stream of the scenario's seed, its frames delivered after their latency
  sensors::ConeSensorParams sensor_params = sc.cone_sensor;
  sensor_params.small_cone_radius = 0.5 * sc.cones.small_cone.base_width;
  sensor_params.big_cone_radius = 0.5 * sc.cones.big_cone.base_width;
  sensors::ConeSensor sensor(sensor_params, sc.scenario.seed * 0x9E3779B97F4A7C15ULL + 1);
  const long sensor_every = std::max(1L, std::lround(sc.sim.physics_rate / sensor_params.rate));
  std::deque<std::pair<TimeNs, hal::ConeDetections>> in_flight;  // (delivery time, frame)
  std::vector<Cone> seen(static_cast<std::size_t>(cones.cone_count()));
  std::vector<bool> knocked(seen.size());

  // the odometry sensors, each on its own random stream of the seed
  sensors::Imu imu(sc.imu, sc.scenario.seed * 0x9E3779B97F4A7C15ULL + 2);
  sensors::WheelSpeedSensor wheels(sc.wheel_speeds, sc.scenario.seed * 0x9E3779B97F4A7C15ULL + 3);
  sensors::SteeringSensor steering(sc.steering_sensor, sc.scenario.seed * 0x9E3779B97F4A7C15ULL + 4);
  auto every = [&](double rate) { return std::max(1L, std::lround(sc.sim.physics_rate / rate)); };
  const long imu_every = every(sc.imu.rate), wheels_every = every(sc.wheel_speeds.rate),
             steering_every = every(sc.steering_sensor.rate);

  // perception = lidar | lidar_camera: the raw sensors instead of the cone sensor
  const bool raw_perception = sc.autonomy.perception != stack::PerceptionMode::GroundTruth;
  std::unique_ptr<RawSensors> raw;
  if (raw_perception) {
    std::optional<sensors::CameraParams> camera;
    if (sc.autonomy.perception == stack::PerceptionMode::LidarCamera) camera = sc.camera;
    raw = std::make_unique<RawSensors>(sc.lidar, sc.ground, camera, sc.detector,
                                       sc.scenario.seed * 0x9E3779B97F4A7C15ULL + 5,
                                       sc.scenario.seed * 0x9E3779B97F4A7C15ULL + 6);
  }

  // perception metrics: each frame the stack got, against the truth of its instant
  PerceptionMetrics metrics;
  // the true base poses of the last second (two LiDAR rotations at least):
  // the LiDAR's columns and the metrics' frames look up the pose of their instant
  PoseHistory truth_poses(std::max(kNsPerSecond, 2 * from_seconds(1.0 / sc.lidar.rate)));
  // (frame stamp, cones the sensor could see): the LiDAR hit them, or the
  // cone sensor had them in view unoccluded
  std::deque<std::pair<TimeNs, std::vector<bool>>> scan_visible;
  const Vec2 sensor_mount = raw_perception ? Vec2{sc.lidar.mount_x, sc.lidar.mount_y}
                                           : Vec2{sc.cone_sensor.mount_x, sc.cone_sensor.mount_y};
  long scored_frames = 0;
  bool snapshot_armed = false;
  std::vector<Cone> truth_cones(static_cast<std::size_t>(cones.cone_count()));

  vehicle::DriverInput input{0.0, 0.0, 1.0};
  hal::AsState as = hal::AsState::Off;
  const TimeNs go_ns = from_seconds(sc.scenario.go_time);
  bool go_sent = false;

  RunResult res;
  auto nose_of = [&](const Pose2& base) { return base.transform({footprint.x_max, 0.0}); };

  for (long k = 0;; ++k) {
    const TimeNs now = k * dt_ns;
    const double t = static_cast<double>(k) * dt;
    Pose2 base = vehicle::base_pose(vp, car);

    // a perception frame of the cones as they stand now, delivered later
    if (!raw_perception && k % sensor_every == 0) {
      for (int i = 0; i < cones.cone_count(); ++i) {
        const auto u = static_cast<std::size_t>(i);
        seen[u] = {cones.cone_position(i), cones.cone(i).color};
        knocked[u] = cones.cone_knocked(i);
      }
      in_flight.emplace_back(now + sensor.latency_ns(), sensor.measure(seen, knocked, base, now));
      scan_visible.emplace_back(now, sensor.last_visible());
      while (scan_visible.size() > 4) scan_visible.pop_front();
    }

    // a LiDAR rotation that ends now, cast from the poses it was taken at
    truth_poses.record(now, base);
    if (raw && raw->rotation_ends(now)) {
      const std::vector<std::int32_t>& hit_truth = raw->emit(now, cones, truth_poses, hal);
      scan_visible.emplace_back(raw->scan_end(now), cones_hit(hit_truth, truth_cones.size()));
      while (scan_visible.size() > 4) scan_visible.pop_front();
    }

    // odometry: the IMU at the base origin's acceleration (from the CG's: a_base = a_cg
    // + alpha x r - omega^2 r with r = (-lr, 0)), wheel speeds, the steering angle
    if (k % imu_every == 0) {
      const double ax_base = car.ax + car.r * car.r * vp.lr;
      const double ay_base = car.ay - car.yaw_accel * vp.lr;
      const sensors::ImuSample m = imu.measure(ax_base, ay_base, car.r, car.yaw_accel, now);
      hal.post(hal::Imu{m.stamp, m.ax, m.ay, m.gz});
    }
    if (k % wheels_every == 0) {
      const sensors::WheelSpeedSample m = wheels.measure(vehicle::wheel_speeds(vp, car), now);
      hal.post(hal::WheelSpeeds{m.stamp, m.omega});
    }
    if (k % steering_every == 0) {
      const sensors::SteeringSample m = steering.measure(car.steering, now);
      hal.post(hal::SteeringAngle{m.stamp, m.angle});
    }

    // the control cycle: sensors into the HAL, the stack, its command to the actuators
    if (k % control_every == 0) {
      while (!in_flight.empty() && in_flight.front().first <= now) {
        hal.post(std::move(in_flight.front().second));
        in_flight.pop_front();
      }
      const Vec2 v = vehicle::base_velocity(vp, car);
      hal.post(hal::StateEstimate{now, base, v.x, v.y, car.r});
      if (!go_sent && now >= go_ns) {
        hal.post(hal::ResSignal{now, true, false});
        go_sent = true;
        event.start(t);
      }
      // the perception snapshot: keep the points of the first scan after snapshot_time
      const bool snap_pending = raw && !res.snapshot && t >= sc.sim.snapshot_time;
      if (snap_pending && !snapshot_armed) {
        stack.perception()->set_keep_points(true);
        snapshot_armed = true;
      }
      const long frames_before = stack.detection_frames();
      stack.tick(now, hal);
      if (snap_pending && stack.detection_frames() > frames_before) {
        res.snapshot = take_snapshot(*stack.perception(), raw->camera_frame(),
                                     truth_poses.at(stack.last_detections().stamp), cones);
        stack.perception()->set_keep_points(false);
      }
      if (stack.detection_frames() > scored_frames) {
        scored_frames = stack.detection_frames();
        const hal::ConeDetections& d = stack.last_detections();
        for (std::size_t i = 0; i < truth_cones.size(); ++i)
          truth_cones[i] = {cones.cone_position(static_cast<int>(i)), cones.cone(static_cast<int>(i)).color};
        std::vector<bool> visible;
        for (const auto& [stamp, hit] : scan_visible)
          if (std::llabs(stamp - d.stamp) < dt_ns) visible = hit;
        if (!visible.empty()) metrics.add(d, truth_poses.at(d.stamp), sensor_mount, truth_cones, visible);
      }
      if (hal.command()) {
        const hal::ActuatorCommand& c = *hal.command();
        input = vehicle::DriverInput{c.steering_angle, c.throttle, c.brake};
        as = c.as_state;
      }
      ++res.cycles;
    }

    // the sample: penalties, finish and DNF, and a log row
    if (k % log_every == 0) {
      const Vec2 v = vehicle::base_velocity(vp, car);
      events::CarSample s;
      s.t = t;
      s.nose = nose_of(base);
      s.wheels = vehicle::wheel_positions(vp, car);
      s.speed = norm(v);
      s.as_finished = as == hal::AsState::Finished;
      s.as_emergency = as == hal::AsState::Emergency;
      s.doo_total = cones.doo_count();
      event.on_sample(s);

      const stack::Telemetry& tm = stack.telemetry();
      LogRow row;
      row.t = t;
      row.x = base.x;
      row.y = base.y;
      row.yaw = base.yaw;
      row.vx = v.x;
      row.vy = v.y;
      row.yaw_rate = car.r;
      row.steer_cmd = input.steering_angle;
      row.steer = car.steering;
      row.throttle = input.throttle;
      row.brake = input.brake;
      row.v_ref = tm.control.v_ref;
      row.lateral_error = tm.control.lateral_error;
      row.heading_error = tm.control.heading_error;
      row.s = tm.control.s;
      row.lap = event.current_lap();
      row.as_state = static_cast<int>(as);
      res.log.push_back(row);
      if (event.done()) break;
    }

    // physics: the car, the cones it may hit, the timing gates
    const Vec2 nose0 = nose_of(base);
    vehicle::step(vp, car, input, dt);
    base = vehicle::base_pose(vp, car);
    const Vec2 v_world = rotate(vehicle::base_velocity(vp, car), base.yaw);
    cones.step(base, v_world.x, v_world.y, car.r, dt);
    event.on_motion(t, nose0, t + dt, nose_of(base));
  }

  res.event = event.result();
  res.perception = metrics;
  res.sim_time = res.log.empty() ? 0.0 : res.log.back().t;
  res.fallbacks = stack.telemetry().fallbacks;
  res.fault = stack.telemetry().last_fault;
  // the stack's last plan and map, for the figures
  const planning::PlanResult& plan = stack.last_plan();
  const std::vector<Cone>& plan_cones = stack.last_plan_cones();
  for (const planning::TriEdge& e : plan.triangulation.edges) {
    if (e.a < plan_cones.size() && e.b < plan_cones.size()) {
      res.plan.triangulation.push_back({plan_cones[e.a].position, plan_cones[e.b].position});
      res.plan.midpoints.push_back(e.midpoint);
    }
  }
  res.plan.centreline = plan.search.points;
  res.plan.mapped_cones = stack.cone_map().cones();
  res.plan.gates = stack.gates();
  for (const TrajectoryPoint& p : stack.trajectory().points) res.plan.reference.push_back(p.position());
  for (const world::DooEvent& d : cones.doo_events()) {
    const Cone& c = cones.cone(d.cone);
    res.cones_hit.push_back({c.position, c.color, to_seconds(d.time_ns), d.cause == world::DooCause::Knocked});
  }

  // tracking errors per completed lap, from the log samples of that lap
  const auto& laps = res.event.laps;
  res.lap_tracking.assign(laps.size(), LapTracking{});
  std::vector<double> sum2(laps.size(), 0.0);
  std::vector<int> count(laps.size(), 0);
  for (const LogRow& row : res.log) {
    if (row.lap < 1 || row.lap > static_cast<int>(laps.size())) continue;
    const auto i = static_cast<std::size_t>(row.lap - 1);
    const double e = std::abs(row.lateral_error);
    sum2[i] += e * e;
    ++count[i];
    res.lap_tracking[i].max = std::max(res.lap_tracking[i].max, e);
    res.lap_tracking[i].itae += (row.t - laps[i].start) * e * log_dt;
  }
  double all2 = 0.0;
  int all_n = 0;
  for (std::size_t i = 0; i < laps.size(); ++i) {
    res.lap_tracking[i].rms = count[i] > 0 ? std::sqrt(sum2[i] / count[i]) : 0.0;
    all2 += sum2[i];
    all_n += count[i];
    res.tracking.max = std::max(res.tracking.max, res.lap_tracking[i].max);
    res.tracking.itae += res.lap_tracking[i].itae / static_cast<double>(laps.size());
  }
  res.tracking.rms = all_n > 0 ? std::sqrt(all2 / all_n) : 0.0;
  res.wall_time = seconds_since(wall0);
  return res;
}

}  // namespace paddock::runner
