#include "sim/runner/simulation.h"

#include <algorithm>
#include <chrono>
#include <future>
#include <cmath>
#include <cstdio>

#include <sys/resource.h>

#include "sim/runner/allocations.h"

namespace paddock::runner {
namespace {

// whether a periodic part falls due at this instant (k % every == 0 without a
// division): run_due meets each instant once, from k = 0, and asks each part
// once there
inline bool falls_due(long& left, long every) {
  if (--left > 0) return false;
  left = every;
  return true;
}

// the cone sensor's frame of the cones as they stand now, delivered after its latency
void measure_cones(SimState& s, const Pose2& base) {
  for (int i = 0; i < s.cones.cone_count(); ++i) {
    const auto u = static_cast<std::size_t>(i);
    s.cones_now[u] = {s.cones.cone_position(i), s.faults.colour(i, s.cones.cone(i).color, s.t)};
    s.cones_knocked[u] = s.cones.cone_knocked(i);
  }
  s.in_flight.emplace_back(s.now + s.cone_sensor.latency_ns(), s.cone_sensor.measure(s.cones_now, s.cones_knocked, base, s.now));
  s.visible.emplace_back(s.now, s.cone_sensor.last_visible());
  while (s.visible.size() > 4) s.visible.pop_front();
}

// the vertical acceleration of the IMU's mounting point as it keeps its
// height above the ground under it: z = h(p(t)), so z'' = grad h . a + v^T H v
// with the point's horizontal velocity v and acceleration a (world frame);
// a_base: the base origin's acceleration in the base frame
double imu_vertical_accel(const SimModel& model, const SimState& s, const Pose2& base, double ax_base,
                          double ay_base) {
  if (sensors::flat(model.scenario.ground)) return 0.0;
  const sensors::ImuParams& imu = s.imu.params();
  const double rx = imu.mount_x, ry = imu.mount_y, w = s.car.r, dw = s.car.yaw_accel;
  const Vec2 vb = vehicle::base_velocity(model.scenario.vehicle, s.car);
  // the point's velocity and acceleration in the base frame (rigid body)
  const Vec2 v{vb.x - w * ry, vb.y + w * rx};
  const Vec2 a{ax_base - dw * ry - w * w * rx, ay_base + dw * rx - w * w * ry};
  const double c = std::cos(base.yaw), sn = std::sin(base.yaw);
  const Vec2 vw{c * v.x - sn * v.y, sn * v.x + c * v.y};
  const Vec2 aw{c * a.x - sn * a.y, sn * a.x + c * a.y};
  const Vec2 p = base.transform({rx, ry});
  const sensors::GroundShape g = sensors::ground_shape(model.scenario.ground, p.x, p.y);
  return g.dx * aw.x + g.dy * aw.y + g.dxx * vw.x * vw.x + 2.0 * g.dxy * vw.x * vw.y + g.dyy * vw.y * vw.y;
}

// a frame the VCU puts on the CAN bus, unless the bus loses it
void post_can(SimState& s, hal::SensorMessage m) {
  if (s.faults.can_delivers(s.t)) s.hal.post(std::move(m));
}

// the odometry sensors due now: the IMU at the base origin's acceleration
// (from the CG's: a_base = a_cg + alpha x r - omega^2 r with r = (-lr, 0)),
// the wheel speeds, the steering angle
void measure_odometry(const SimModel& model, SimState& s, const Pose2& base) {
  const vehicle::VehicleParams& car = model.scenario.vehicle;
  if (falls_due(s.due_in.imu, model.every.imu)) {
    const double ax_base = s.car.ax + s.car.r * s.car.r * car.lr;
    const double ay_base = s.car.ay - s.car.yaw_accel * car.lr;
    const double az = imu_vertical_accel(model, s, base, ax_base, ay_base);
    const sensors::ImuSample m = s.imu.measure(ax_base, ay_base, s.car.r, s.car.yaw_accel, s.now, az);
    s.last_imu = hal::Imu{m.stamp, m.ax, m.ay, m.gz, m.az, m.gx, m.gy};
    s.faults.apply(s.t, s.last_imu, static_cast<double>(model.every.imu) * model.dt);
    post_can(s, s.last_imu);
  }
  if (falls_due(s.due_in.wheel_speeds, model.every.wheel_speeds)) {
    const sensors::WheelSpeedSample m = s.wheel_speeds.measure(vehicle::wheel_speeds(car, s.car), s.now);
    hal::WheelSpeeds w{m.stamp, m.omega};
    s.faults.apply(s.t, w);
    post_can(s, std::move(w));
  }
  if (falls_due(s.due_in.steering, model.every.steering)) {
    const sensors::SteeringSample m = s.steering.measure(s.car.steering, s.now);
    hal::SteeringAngle a{m.stamp, m.angle};
    s.faults.apply(s.t, a);
    post_can(s, std::move(a));
  }
}

// the VCU's status and the RES's frames; the RES's emergency stop and the
// EBS's tank as the faults have them
void vcu_due(const SimModel& model, SimState& s) {
  if (const std::optional<double> tank = s.faults.ebs_tank(s.t)) s.vcu.set_ebs_tank(*tank);
  const bool pressed = s.faults.res_pressed(s.t);
  if (pressed && !s.vcu.ebs_fired()) s.vcu.res_emergency(s.now);
  if (!falls_due(s.due_in.vcu_status, model.every.vcu_status)) return;
  post_can(s, s.vcu.status(s.now));
  // the RES's frame goes on repeating the emergency stop
  if (pressed) post_can(s, hal::ResSignal{s.now, false, true});
}

// the control cycle: the delivered frames, the state estimate and the go
// signal into the HAL, the stack, its command to the actuators
void control(const SimModel& model, SimState& s, const Pose2& base) {
  while (!s.in_flight.empty() && s.in_flight.front().first <= s.now) {
    s.hal.post(std::move(s.in_flight.front().second));
    s.in_flight.pop_front();
  }
  // slam = ground_truth: the stack is handed its true state; otherwise it
  // estimates its own from the sensors (the HAL refuses the truth then)
  if (s.hal.true_state()) {
    const Vec2 v = vehicle::base_velocity(model.scenario.vehicle, s.car);
    s.hal.post(hal::StateEstimate{s.now, base, v.x, v.y, s.car.r});
  }
  // the official gives the go once the car has shown AS Ready for go_time
  if (!s.go_sent && s.ready_since && s.now - *s.ready_since >= model.go) {
    s.hal.post(hal::ResSignal{s.now, true, false});
    s.go_sent = true;
    s.event.start(s.t);
  }
  // transport = udp: the stack is the car binary's, in its own process
  if (s.hal.remote()) {
    s.hal.remote_cycle();
  } else {
    s.stack.tick(s.now, s.hal);
  }
  if (s.hal.command()) {
    const hal::ActuatorCommand& c = *s.hal.command();
    s.vcu.command(s.now, c);
    s.as_state = c.as_state;
    if (!s.ready_since && c.as_state == hal::AsState::Ready) s.ready_since = s.now;
  }
  ++s.control_cycles;
}

// the event's sample: penalties, finish and DNF
void sample(const SimModel& model, SimState& s, const Pose2& base) {
  const vehicle::VehicleParams& car = model.scenario.vehicle;
  events::CarSample c;
  c.t = s.t;
  c.nose = base.transform({model.footprint.x_max, 0.0});
  c.wheels = vehicle::wheel_positions(car, s.car);
  c.speed = norm(vehicle::base_velocity(car, s.car));
  c.as_finished = s.as_state == hal::AsState::Finished;
  c.as_emergency = s.as_state == hal::AsState::Emergency;
  c.doo_total = s.cones.doo_count();
  c.energy = s.car.energy;
  s.event.on_sample(c);
  s.done = s.event.done();
}

// what falls due at the state's instant, in the order a car meets it: the
// sensors' measurements, the control cycle, the event's sample
void run_due(const SimModel& model, SimState& s, const Pose2& base) {
  s.hal.set_now(s.now);
  s.sensed = false;
  if (!model.raw_perception && falls_due(s.due_in.cone_sensor, model.every.cone_sensor)) {
    measure_cones(s, base);
    s.sensed = true;
  }
  // a LiDAR rotation that ends now, cast from the poses it was taken at
  s.true_poses.record(s.now, base);
  if (s.raw && s.raw->rotation_ends(s.now)) {
    s.sensed = true;
    const std::vector<std::int32_t>& hit = s.raw->emit(s.now, s.cones, s.true_poses, s.hal, s.faults, s.t);
    s.visible.emplace_back(s.raw->scan_end(s.now), cones_hit(hit, static_cast<std::size_t>(s.cones.cone_count())));
    while (s.visible.size() > model.visible_scans) s.visible.pop_front();
  }
  measure_odometry(model, s, base);
  vcu_due(model, s);
  // the stack's cycle, unless its computer stalls
  s.controlled = falls_due(s.due_in.control, model.every.control) && s.faults.control_runs(s.t);
  if (s.controlled) control(model, s, base);
  // the VCU's watchdog and the EBS, then what the actuators hold until the next step
  s.input = s.vcu.actuate(s.now);
  s.faults.apply(s.t, s.input);
  s.sampled = falls_due(s.due_in.log, model.every.log);
  if (s.sampled) sample(model, s, base);
}

// the EBS's stop: from the instant it fired, the distance to rest
void measure_ebs_stop(const SimModel& model, SimState& s, double speed) {
  EbsStop& e = s.ebs;
  if (!e.fired) {
    if (!s.vcu.ebs_fired()) return;
    e.fired = true;
    e.cause = s.vcu.ebs_cause();
    e.t = to_seconds(*s.vcu.ebs_fired());
    e.speed = speed;
    return;
  }
  if (e.stopped_at) return;
  e.distance += speed * model.dt;
  if (speed < model.scenario.event.standstill_speed) e.stopped_at = s.t + model.dt;
}

std::unique_ptr<RawSensors> make_raw_sensors(const SimModel& model) {
  if (!model.raw_perception) return nullptr;
  const Scenario& scenario = model.scenario;
  const std::uint64_t seed = scenario.scenario.seed;
  return std::make_unique<RawSensors>(scenario.lidar, scenario.ground, model.blocks, model.camera, scenario.detector,
                                      stream_seed(seed, "lidar"), stream_seed(seed, "camera"), stream_seed(seed, "detector"),
                                      scenario.sim.threads);
}

// what the run leaves behind besides the observers' records: the event's
// result, the stack's last plan and map (for the figures), the cones hit
RunResult results_of(const SimState& s) {
  RunResult r;
  r.event = s.event.result();
  r.fallbacks = s.stack.telemetry().fallbacks;
  r.fault = s.stack.telemetry().last_fault;
  r.cycles = s.control_cycles;
  r.ebs = s.ebs;
  r.as_transitions = s.stack.as_machine().transitions();
  r.health = s.stack.health().events();
  r.energy = s.car.energy;
  const planning::PlanResult& plan = s.stack.last_plan();
  const std::vector<Cone>& plan_cones = s.stack.last_plan_cones();
  for (const planning::TriEdge& e : plan.triangulation.edges) {
    if (e.a < plan_cones.size() && e.b < plan_cones.size()) {
      r.plan.triangulation.push_back({plan_cones[e.a].position, plan_cones[e.b].position});
      r.plan.midpoints.push_back(e.midpoint);
    }
  }
  r.plan.centreline = plan.search.points;
  r.plan.mapped_cones = s.stack.cone_map().cones();
  r.plan.gates = s.stack.gates();
  for (const TrajectoryPoint& p : s.stack.trajectory().points) r.plan.reference.push_back(p.position());
  for (const world::DooEvent& d : s.cones.doo_events()) {
    const Cone& c = s.cones.cone(d.cone);
    r.cones_hit.push_back({c.position, c.color, to_seconds(d.time_ns), d.cause == world::DooCause::Knocked});
  }
  return r;
}

// transport = wire | udp: the car's wires (the LiDAR's only when the stack
// reads it); udp: to a car binary
std::unique_ptr<WireLink> make_wire(const Scenario& sc) {
  if (sc.hal.transport == Transport::Memory) return nullptr;
  const bool lidar = sc.autonomy.perception != stack::PerceptionMode::GroundTruth;
  auto wire = std::make_unique<WireLink>(lidar ? sc.lidar_info : std::nullopt, sc.lidar, *sc.dbc, sc.hal.dbc);
  if (sc.hal.transport == Transport::Udp) wire->set_remote(std::make_unique<CarLink>(sc.car));
  return wire;
}

// the run's MCAP log (the HAL's traffic it is handed), timed as logging
struct TimedTap final : WireTap {
  explicit TimedTap(WireTap* inner_tap) : inner(inner_tap) {}
  void lidar_packet(TimeNs at, const std::uint8_t* data, std::size_t size) override {
    const StageScope scope(profile, Stage::Logging);
    inner->lidar_packet(at, data, size);
  }
  void can_frame(TimeNs at, bool to_stack, const std::uint8_t* frame) override {
    const StageScope scope(profile, Stage::Logging);
    inner->can_frame(at, to_stack, frame);
  }
  void message(TimeNs at, const hal::SensorMessage& m) override {
    const StageScope scope(profile, Stage::Logging);
    inner->message(at, m);
  }
  WireTap* inner;
  Profile* profile = nullptr;
};

// this thread's page faults so far (minor: a page first touched; major: read
// from the disk) and the process's peak resident set (KiB)
struct PageFaults {
  long minor = 0, major = 0, peak_rss_kib = 0;
};
PageFaults page_faults_now() {
  rusage u{};
  PageFaults f;
  if (getrusage(RUSAGE_THREAD, &u) == 0) {
    f.minor = u.ru_minflt;
    f.major = u.ru_majflt;
  }
  if (getrusage(RUSAGE_SELF, &u) == 0) f.peak_rss_kib = u.ru_maxrss;
  return f;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

SimState::SimState(const SimModel& model, WireTap* tap)
    : car(vehicle::initial_state(model.scenario.vehicle, model.start)),
      cones(model.cones, model.scenario.cones,
            world::Footprint{-model.footprint.x_min, model.footprint.x_max, model.footprint.y_max}),
      event(model.scenario.scenario.event, model.track, model.scenario.event),
      stack(model.stack, model.mission),
      hal(model.stack.autonomy.slam == stack::SlamMode::GroundTruth, make_wire(model.scenario)),
      vcu(model.scenario.vcu, stack::mission_code(model.mission.mission)),
      faults(model.scenario.faults, stream_seed(model.scenario.scenario.seed, "faults")),
      cone_sensor(model.cone_sensor, stream_seed(model.scenario.scenario.seed, "cone_sensor")),
      cones_now(model.cones.size()),
      cones_knocked(model.cones.size()),
      raw(make_raw_sensors(model)),
      imu(model.scenario.imu, stream_seed(model.scenario.scenario.seed, "imu")),
      wheel_speeds(model.scenario.wheel_speeds, stream_seed(model.scenario.scenario.seed, "wheel_speeds")),
      steering(model.scenario.steering_sensor, stream_seed(model.scenario.scenario.seed, "steering_sensor")),
      true_poses(model.pose_history_span),
      profile(nullptr, allocations_counted() ? &thread_allocations : nullptr) {
  hal.set_tap(tap);
  stack.set_profile(&profile);
  if (raw) raw->set_profile(&profile);
  faults.place(model.track, model.cones);
  const Pose2 base = vehicle::base_pose(model.scenario.vehicle, car);
  nose = base.transform({model.footprint.x_max, 0.0});
  run_due(model, *this, base);
}

namespace {

// the physics of one step: the car's base pose after it, or none when the
// state diverged (the run ends)
std::optional<Pose2> physics_step(const SimModel& model, SimState& s) {
  const StageScope physics(&s.profile, Stage::Physics);
  const vehicle::VehicleParams& car = model.scenario.vehicle;
  // in the rain ([faults.rain]) the tyres grip less
  const double grip = s.faults.grip(s.t);
  if (grip < 1.0 && !s.wet) {
    vehicle::VehicleParams wet = car;
    wet.tyre_d *= grip;
    wet.tyre_dx *= grip;
    s.wet.emplace(wet);
  }
  vehicle::step(grip < 1.0 ? *s.wet : model.car, s.car, s.input, model.dt);
  if (!vehicle::is_finite(s.car)) {
    // a state that is no number cannot be stepped, sensed or timed: the run
    // ends here, with its reason; nothing falls due at this instant
    ++s.k;
    s.now = s.k * model.dt_ns;
    s.t = static_cast<double>(s.k) * model.dt;
    char why[96];
    std::snprintf(why, sizeof why, "simulation diverged at t = %.3f s (the vehicle state is not finite)", s.t);
    s.event.abort(s.t, why);
    s.done = true;
    s.controlled = s.sampled = false;
    return std::nullopt;
  }
  // the base pose, its heading's cosine and sine taken once (vehicle::base_pose,
  // rotate and Pose2::transform would each take them again: the same bits)
  const double c = std::cos(s.car.yaw), sn = std::sin(s.car.yaw);
  const Pose2 base{s.car.x - car.lr * c, s.car.y - car.lr * sn, s.car.yaw};
  const auto rotated = [c, sn](Vec2 v) { return Vec2{c * v.x - sn * v.y, sn * v.x + c * v.y}; };
  const Vec2 v_world = rotated(vehicle::base_velocity(car, s.car));
  // a gust ([faults.wind]) moves cones: not the car's doing
  for (const FaultInjector::Gust& g : s.faults.gust_due(s.t)) s.cones.disturb_cone(g.cone, g.shift, g.topple);
  s.cones.step(base, v_world.x, v_world.y, s.car.r, model.dt);
  measure_ebs_stop(model, s, norm(v_world));
  const double t0 = s.t;
  ++s.k;
  s.now = s.k * model.dt_ns;
  s.t = static_cast<double>(s.k) * model.dt;
  const Vec2 nose0 = s.nose;
  s.nose = base.position() + rotated({model.footprint.x_max, 0.0});
  s.event.on_motion(t0, nose0, t0 + model.dt, s.nose);
  return base;
}

}  // namespace

void step(const SimModel& model, SimState& s) {
  // physics: the car, the cones it may hit, the timing gates; then what
  // falls due, outside every stage (each stage in it times itself)
  if (const std::optional<Pose2> base = physics_step(model, s)) run_due(model, s, *base);
}


RunResult run(const Scenario& scenario, const world::TrackModel& track, const std::vector<Observer*>& extra,
              WireTap* tap) {
  const auto wall0 = std::chrono::steady_clock::now();
  // the limit lap, on a second thread while the run goes on: it reads only
  // the vehicle's parameters and the track (the car's envelope measured once
  // per process: a sweep's points share it)
  std::future<std::optional<LimitLines>> limit;
  if (track.kind == world::TrackKind::Circuit && track.closed) {
    limit = std::async(std::launch::async, [&scenario, &track]() -> std::optional<LimitLines> {
      try {
        return limit_lines(track, shared_car_envelope(scenario.vehicle));
      } catch (const std::exception&) {
        return std::nullopt;
      }
    });
  }
  const SimModel model = compile_model(scenario, track);
  TimedTap timed_tap(tap);
  SimState state(model, tap ? &timed_tap : nullptr);
  timed_tap.profile = &state.profile;
  LogRecorder log;
  PerceptionScorer scorer;
  SlamScorer slam;
  SnapshotRecorder snapshot;
  Observer* const scorers[] = {&snapshot, &scorer, &slam};
  const PageFaults faults0 = page_faults_now();
  state.profile.start();
  for (;;) {
    // the observers work only at an instant that sensed, controlled or
    // sampled; at the others (most physics steps) they return at once, and
    // those few ns go to Other rather than cost four clock reads a step
    const bool due = state.sensed || state.controlled || state.sampled || state.done;
    {
      const StageScope scope(due ? &state.profile : nullptr, Stage::Scoring);
      for (Observer* o : scorers) o->observe(model, state);
    }
    {
      const StageScope scope(due ? &state.profile : nullptr, Stage::Logging);
      log.observe(model, state);
    }
    for (Observer* o : extra) {
      const StageScope scope(&state.profile, Stage::Logging);  // the caller's: a run's MCAP log
      o->observe(model, state);
    }
    if (state.done) break;
    step(model, state);
  }
  state.profile.stop();
  const PageFaults faults1 = page_faults_now();

  RunResult result = results_of(state);
  result.stack_remote = state.hal.remote();
  result.faults = fault_notes(scenario.faults);
  for (FaultNote& n : result.faults) {
    if (n.name == "wind") n.what += " (" + state.faults.gust_words() + ")";
  }
  result.log = std::move(log.rows());
  result.sim_time = result.log.empty() ? 0.0 : result.log.back().t;
  tracking_from_log(result.event.laps, result.log, 1.0 / scenario.sim.log_rate, result.lap_tracking, result.tracking);
  result.perception = scorer.metrics();
  result.slam = slam.metrics(model, state, result.event.laps);
  result.snapshot = std::move(snapshot.snapshot());
  if (limit.valid()) result.limit = limit.get();
  if (result.limit) result.limit_lap = result.limit->min_curvature.lap_time;
  result.profile = state.profile;
  result.page_faults = (faults1.minor - faults0.minor) + (faults1.major - faults0.major);
  result.peak_rss_mb = static_cast<double>(faults1.peak_rss_kib) / 1024.0;
  result.wall_time = seconds_since(wall0);
  return result;
}

}  // namespace paddock::runner
