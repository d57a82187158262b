#include "autonomy/stack/stack.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

#include "autonomy/common/polyline.h"
#include "autonomy/planning/velocity_profile.h"

namespace paddock::stack {

const char* to_string(Mission m) {
  switch (m) {
    case Mission::Acceleration: return "acceleration";
    case Mission::Skidpad: return "skidpad";
    case Mission::Autocross: return "autocross";
    case Mission::Trackdrive: return "trackdrive";
  }
  return "trackdrive";
}

const char* to_string(SlamMode m) {
  for (const auto& c : AutonomyModes::kSlamNames)
    if (c.value == m) return c.name;
  return "ground_truth";
}

const char* to_string(PerceptionMode m) {
  switch (m) {
    case PerceptionMode::GroundTruth: return "ground_truth";
    case PerceptionMode::Lidar: return "lidar";
    case PerceptionMode::LidarCamera: return "lidar_camera";
  }
  return "ground_truth";
}

Stack::Stack(const StackParams& params, MissionSpec spec, std::unique_ptr<perception::ConeDetector> detector)
    : params_(params),
      spec_(std::move(spec)),
      controller_(params.control, params.vehicle),
      cone_map_(params.cone_map),
      gates_(spec_.gates),
      as_(params.as),
      health_(params.health, params.autonomy.perception != PerceptionMode::GroundTruth,
              params.autonomy.perception == PerceptionMode::LidarCamera, params.autonomy.slam != SlamMode::GroundTruth) {
  if (params_.autonomy.perception != PerceptionMode::GroundTruth) {
    perception::PerceptionParams pp = params_.perception;
    pp.use_camera = params_.autonomy.perception == PerceptionMode::LidarCamera;
    perception_ = std::make_unique<PerceptionStage>(pp, std::move(detector));
  }
  if (params_.autonomy.slam != SlamMode::GroundTruth)
    localisation_.emplace(params_.slam, params_.autonomy.slam, spec_.start_pose);
  // (with no latency a scan's frame is mapped within the message that brought it)
  slam_beside_ = perception_ && perception_->threaded() && params_.perception.latency > 0.0 && localisation_ &&
                 localisation_->steps_beside();
  if (params_.autonomy.planner != PlannerMode::Oracle) return;
  // planner = oracle: the whole reference is planned once, before the start;
  // an open path starts free (the car launches at full drive) and ends at rest
  const std::optional<double> v_end = spec_.oracle_closed ? std::nullopt : std::optional<double>(0.0);
  auto result = planning::build_reference(spec_.oracle_path, spec_.oracle_closed, params_.planning.reference,
                                          std::nullopt, v_end);
  if (result.ok()) {
    set_trajectory(std::move(result.trajectory));
  } else {
    telemetry_.last_fault = "planning: " + result.reason;
  }
}

void Stack::take_estimate(const hal::StateEstimate& est) {
  state_ = est;
  // the LiDAR's motion correction takes its lateral velocity
  if (perception_) perception_->add(est);
  history_.push_back(est);
  while (!history_.empty() && est.stamp - history_.front().stamp > kNsPerSecond) history_.pop_front();
}

void Stack::on_message(hal::SensorMessage&& m) {
  // the odometry sensors feed the localisation (slam != ground_truth) and the
  // LiDAR's motion correction (perception = lidar | lidar_camera)
  if (const auto* imu = std::get_if<hal::Imu>(&m)) {
    health_.imu(now_);
    if (localisation_) {
      const StageScope scope(profile_, Stage::Localisation);
      if (const std::optional<hal::StateEstimate> e = localisation_->on_imu(*imu)) take_estimate(*e);
    }
    if (perception_) perception_->add(*imu);
    return;
  }
  if (const auto* wheels = std::get_if<hal::WheelSpeeds>(&m)) {
    health_.wheels(now_);
    if (localisation_) {
      const StageScope scope(profile_, Stage::Localisation);
      localisation_->on_wheel_speeds(*wheels);
    }
    if (perception_) perception_->add(*wheels);
    return;
  }
  if (const auto* steering = std::get_if<hal::SteeringAngle>(&m)) {
    if (localisation_) {
      const StageScope scope(profile_, Stage::Localisation);
      localisation_->on_steering(*steering);
    }
    return;
  }
  if (const auto* est = std::get_if<hal::StateEstimate>(&m)) {
    // slam = ground_truth: handed in; otherwise the stack keeps its own
    if (!localisation_) take_estimate(*est);
  } else if (const auto* det = std::get_if<hal::ConeDetections>(&m)) {
    const StageScope scope(profile_, Stage::Localisation);
    on_detections(*det);
  } else if (const auto* res = std::get_if<hal::ResSignal>(&m)) {
    go_ = go_ || res->go;
    emergency_ = emergency_ || res->emergency;
  } else if (const auto* vcu = std::get_if<hal::VcuStatus>(&m)) {
    vcu_ = *vcu;
  } else if (!perception_) {
    // perception = ground_truth: the raw sensors' messages are not used
  } else if (auto* scan = std::get_if<hal::LidarScan>(&m)) {
    // the scan's job (perception_stage.h); slam = lio: the scan localises
    // the car meanwhile, the cones are then placed at the pose it gave
    health_.lidar_scan(now_, scan->points.size());
    const hal::LidarScan& posted =
        timed(profile_, Stage::Perception, [&]() -> const hal::LidarScan& { return perception_->post(std::move(*scan), now_); });
    if (slam_beside_) {
      SlamInFlight f;
      f.stamp = posted.end;
      f.job = perception_->last_posted();
      if (!slam_spare_.empty()) {
        f.step = std::move(slam_spare_.back());
        slam_spare_.pop_back();
      } else {
        f.step = std::make_unique<SlamStep>();
      }
      slam_in_flight_.push_back(std::move(f));
    }
    if (localisation_) {
      const StageScope scope(profile_, Stage::Localisation);
      localisation_->on_scan(posted);
    }
    // (latency 0: the cones at once)
    deliver_perception(now_);
  } else if (auto* boxes = std::get_if<hal::CameraDetections>(&m)) {
    health_.camera(now_, *boxes, state_ ? std::hypot(state_->vx, state_->vy) : 0.0);
    perception_->add(std::move(*boxes));
  } else if (auto* frame = std::get_if<hal::CameraFrame>(&m)) {
    perception_->add(std::move(*frame));
  }
}

void Stack::deliver_perception(TimeNs now) {
  // (every cycle asks: nothing timed when no scan is on its way)
  while (perception_->in_flight() > 0) {
    const perception::PerceptionFrame* f =
        timed(profile_, Stage::Perception, [&] { return perception_->deliver(now); });
    if (f == nullptr) return;
    const StageScope mapping(profile_, Stage::Localisation);
    if (!slam_beside_) {
      on_detections(f->output);
      continue;
    }
    // the oldest in flight is this frame: published if it was stepped
    // beside, else mapped as on one thread
    SlamInFlight done = std::move(slam_in_flight_.front());
    slam_in_flight_.pop_front();
    on_detections(f->output, done.stepped ? done.step.get() : nullptr);
    if (done.stepped) ++slam_steps_beside_;
    slam_spare_.push_back(std::move(done.step));
  }
}

void Stack::post_slam_steps() {
  // in the frames' order, each once the odometry has reached its stamp: the
  // steps then come in the order, and at the odometry, on_detections takes
  // them in. (None while a frame mapped on this thread waits for its
  // odometry: the localisation maps a waiting frame in the IMU sample that
  // reaches its stamp, so while one waits every later frame's is Later too)
  for (SlamInFlight& f : slam_in_flight_) {
    if (f.stepped) continue;
    Pose2 odom;
    if (localisation_->odometry_for(f.stamp, odom) != Localisation::OdometryAt::Ready) return;
    Localisation* loc = &*localisation_;
    SlamStep* step = f.step.get();
    const TimeNs stamp = f.stamp;
    perception_->then(f.job, [loc, step, odom, stamp](const perception::PerceptionFrame& frame) {
      if (frame.output.stamp != stamp) throw std::logic_error("slam beside the loop: a frame not stamped at its scan's end");
      loc->step(frame.output, odom, *step);
    });
    f.stepped = true;
  }
}

std::optional<Pose2> Stack::pose_at(TimeNs t) const {
  if (history_.empty() || t < history_.front().stamp || t > history_.back().stamp) return std::nullopt;
  // the two estimates around t, linearly interpolated (yaw on the circle)
  std::size_t i = 1;
  while (i < history_.size() && history_[i].stamp < t) ++i;
  if (i == history_.size()) return history_.back().pose;
  const hal::StateEstimate& a = history_[i - 1];
  const hal::StateEstimate& b = history_[i];
  const double f = b.stamp > a.stamp ? static_cast<double>(t - a.stamp) / static_cast<double>(b.stamp - a.stamp) : 1.0;
  return interpolate(a.pose, b.pose, f);
}

void Stack::on_detections(const hal::ConeDetections& d, SlamStep* stepped) {
  last_detections_ = d;
  ++detection_frames_;
  // slam = fastslam or fastslam_graph: the map is SLAM's
  if (localisation_ && localisation_->owns_map()) {
    if (stepped != nullptr) {
      localisation_->publish(*stepped);
    } else {
      localisation_->on_detections(d);
    }
    return;
  }
  // slam = ground_truth: the detections go into the map at the pose the car
  // had when they were measured; a frame newer than the newest state estimate
  // waits for it (a scan closes just before the state of that instant arrives)
  if (!history_.empty() && d.stamp > history_.back().stamp) {
    waiting_.push_back(d);
    return;
  }
  add_to_map(d);
}

void Stack::add_to_map(const hal::ConeDetections& d) {
  const std::optional<Pose2> pose = pose_at(d.stamp);
  if (!pose) return;
  std::vector<Cone> in_map;
  in_map.reserve(d.cones.size());
  for (const hal::DetectedCone& c : d.cones) in_map.push_back({pose->transform(c.position), c.color});
  cone_map_.add(in_map);
  map_news_ = true;
}

namespace {
// the spacing of the driven path's marks (m)
constexpr double kPathMarkSpacing = 0.25;
}  // namespace

void Stack::learn_gates(const Pose2& pose, TimeNs now, double speed) {
  if (trajectory_.empty()) return;
  const MissionParams& mp = params_.mission;
  // a learned gate whose posts the map no longer holds as big cones is
  // forgotten (and a better one may be learned in its place)
  const std::vector<Cone> big = gate_cones();
  const std::vector<Vec2> posts = find_posts(big, params_.gates);
  for (std::size_t i = gates_.size(); i-- > spec_.gates.size();)
    if (!gate_still_seen(gates_[i], posts)) gates_.erase(gates_.begin() + static_cast<std::ptrdiff_t>(i));
  for (const Segment& g : find_gates(big, params_.gates)) {
    const Vec2 mid = (g.a + g.b) * 0.5;
    bool known = false;
    for (const Segment& k : gates_) known = known || distance((k.a + k.b) * 0.5, mid) < 3.0;
    if (known) continue;
    // a gate behind the car counts when the car drove through it since the
    // last counted crossing (it came into view only after): oriented by the
    // motion through it, and that crossing counted
    if (dot(mid - pose.position(), pose.heading()) <= 0.0) {
      if (const auto crossed = crossed_since_last(g, pose.position())) {
        gates_.push_back(orient_gate(g, crossed->first));
        count_crossing(crossed->second, now, speed);
      }
      continue;
    }
    // a new gate lies across the path ahead, and is oriented by the path's
    // heading where it passes the gate: the car's own heading, far from the
    // gate, may lie along the line or against it (a gate seen again from
    // across the track, 44 m away, was stored back to front and never
    // counted a lap again)
    const TrajectoryProjection through = project(trajectory_, mid, 0.0, 0.0);
    if (std::abs(through.offset) > mp.gate_max_offset) continue;
    gates_.push_back(orient_gate(g, unit_from_angle(through.ref.heading)));
  }
}

bool Stack::lap_still_holds(const hal::StateEstimate& st, const std::vector<Cone>& cones) const {
  const MissionParams& mp = params_.mission;
  const double tolerance = mp.lap_replan_tolerance;
  if (!(tolerance > 0.0) || !last_plan_.ok() || !last_plan_.closed || !trajectory_.closed || !pending_lap_.empty()) {
    return false;
  }
  // near the start, where the lap is taken (plan() below), it is planned anew
  if (!(mp.loop_closure_radius > 0.0) || !start_position_ ||
      !(distance(st.pose.position(), *start_position_) >= mp.loop_closure_radius)) {
    return false;
  }
  if (cones.size() != last_plan_cones_.size()) return false;
  for (std::size_t i = 0; i < cones.size(); ++i) {
    if (cones[i].color != last_plan_cones_[i].color ||
        !(distance(cones[i].position, last_plan_cones_[i].position) <= tolerance)) {
      return false;
    }
  }
  return true;
}

void Stack::plan(const hal::StateEstimate& st) {
  map_news_ = false;
  const std::vector<Cone> cones = cone_map_.cones();
  telemetry_.mapped_cones = static_cast<int>(cones.size());
  if (telemetry_.lap_locked || telemetry_.stopping) return;
  // nothing to plan on until the map holds a few cones (the first frames)
  if (cones.size() < 3) return;
  const MissionParams& mp = params_.mission;
  // the profile starts at the car's speed, but never below the launch speed,
  // so that a car at rest gets a reference to start on
  const double speed = std::max(st.vx, mp.launch_speed);

  // skidpad: the rules' layout aligned to the cones once enough are mapped, then driven as it is
  if (spec_.mission == Mission::Skidpad) {
    if (static_cast<int>(cones.size()) < mp.skidpad_min_cones) return;
    const Pose2 guess{st.pose.transform({mp.skidpad_crossing_ahead, 0.0}).x,
                      st.pose.transform({mp.skidpad_crossing_ahead, 0.0}).y, st.pose.yaw};
    planning::SkidpadPlan sp = planning::plan_skidpad(cones, guess, params_.skidpad);
    ++telemetry_.plans;
    if (!sp.ok()) {
      ++telemetry_.plan_failures;
      telemetry_.last_fault = "skidpad: " + sp.reason;
      return;
    }
    set_trajectory(std::move(sp.trajectory));
    telemetry_.lap_locked = true;
    return;
  }

  // a closed lap the car drives already is kept while the map is the one it
  // was planned on (lap_replan_tolerance): planned again, it would be the
  // same ring
  if (lap_still_holds(st, cones)) {
    if (spec_.gates.empty()) learn_gates(st.pose, st.stamp, st.vx);
    return;
  }

  // acceleration: a line fitted to the centreline, to the end of the braking zone
  // autocross and trackdrive: the centreline of the map explored so far
  planning::PlanResult res =
      spec_.mission == Mission::Acceleration
          ? planning::plan_acceleration(cones, st.pose, speed, params_.planning,
                                        std::max(10.0, mp.acceleration_length - driven_))
          : planning::plan_path(cones, st.pose, speed, params_.planning,
                                driven_ >= mp.loop_closure_distance);
  ++telemetry_.plans;
  if (!res.ok()) {
    // hold the last trajectory; with none the car stays parked
    ++telemetry_.plan_failures;
    telemetry_.last_fault = "planning: " + res.reason;
  } else if (res.closed) {
    // a closed centreline is the whole lap once the car has driven most of it;
    // before that it may be the search cutting across a map still being
    // explored (or a long-range map that already shows the whole circuit), so
    // the planner gives the open path along it (plan_path's `lap`)
    const bool back_at_start =
        start_position_ && distance(st.pose.position(), *start_position_) < mp.loop_closure_radius;
    // with a pose graph, the lap a trackdrive keeps is planned on the map
    // its first loop closure optimised: planned on the first lap's map, the
    // lap would keep that lap's drift, which the closure then takes out of
    // the map the car localises in (FSG 2023 with a noisy perception, seed
    // 2: the lap planned 0.3 s before the closure, its far end 0.5 m off
    // the cones there, three of them knocked in lap 3)
    // A closure the localisation misses (too few of the start's cones
    // matched on this pass) is not waited for past loop_closure_radius of
    // driving: the lap is then planned on the map as it is, as before
    bool map_closed = spec_.mission != Mission::Trackdrive || !localisation_ || !localisation_->owns_map() ||
                      !localisation_->awaits_loop_closure();
    if (!map_closed && back_at_start) {
      if (!lap_ready_at_) lap_ready_at_ = driven_;
      map_closed = driven_ - *lap_ready_at_ >= mp.loop_closure_radius;
    }
    if ((back_at_start || mp.loop_closure_radius <= 0.0) && map_closed) {
      // the lap to drive from now on: its racing line when asked for (the
      // centreline when that fails, and the fault says why)
      if (spec_.mission == Mission::Trackdrive && !planning::plan_locked_lap(res, cones, params_.planning)) {
        telemetry_.last_fault = "planning: " + (res.racing_fallback.empty() ? "the locked lap kept its exploring profile" : res.racing_fallback);
      }
      pending_lap_ = res.trajectory;
      telemetry_.lap_locked = spec_.mission == Mission::Trackdrive;
    } else {
      // the search closes the loop from the car before the car is back at its
      // start: the path is good ahead, so drive it, and keep planning
      set_trajectory(res.trajectory);
    }
  } else {
    set_trajectory(res.trajectory);
  }
  last_plan_ = std::move(res);
  last_plan_cones_ = cones;
  if (spec_.gates.empty()) learn_gates(st.pose, st.stamp, st.vx);
}

void Stack::catch_up(const hal::StateEstimate& st) {
  // the lap's profile from the car's speed where it takes over: a lap faster
  // than the path it replaces (the racing line after the exploring lap)
  // ramps up at what the tyres allow, not at the speed loop's full throttle
  // in a turn; the lap's own speeds come back once the ramp has met them
  std::vector<TrajectoryPoint>& pts = trajectory_.points;
  const std::size_t n = pts.size();
  if (n < 2 || !trajectory_.closed) return;
  std::vector<double> speed(n), kappa(n), ds(n);
  for (std::size_t i = 0; i < n; ++i) {
    speed[i] = pts[i].speed;
    kappa[i] = pts[i].curvature;
    ds[i] = (i + 1 < n ? pts[i + 1].s : trajectory_.length) - pts[i].s;
  }
  if (std::any_of(ds.begin(), ds.end(), [](double d) { return !(d > 0.0); })) return;
  const double s_car = project(trajectory_, st.pose.position(), 0.0, 0.0).s;
  const auto after = std::upper_bound(pts.begin(), pts.end(), s_car,
                                      [](double s, const TrajectoryPoint& p) { return s < p.s; });
  const std::size_t from = after == pts.begin() ? 0 : static_cast<std::size_t>(after - pts.begin()) - 1;
  lap_speed_ = speed;
  // until it has caught up the car is still leaving the exploring path: it
  // accelerates at the exploring margins
  planning::VelocityProfileParams ramp_profile = params_.planning.reference.profile;
  if (ramp_profile.limits == planning::VelocityProfileParams::Ggv) {
    ramp_profile.margin_lateral = params_.planning.explore_margin_lateral;
    ramp_profile.margin_longitudinal = params_.planning.explore_margin_longitudinal;
  }
  const std::size_t lowered = planning::catch_up_profile(speed, kappa, ds, true, from, st.vx, ramp_profile);
  if (lowered == 0) return;
  double ramp = 0.0;  // from the car to the ramp's last point
  for (std::size_t k = 0; k < lowered; ++k) {
    const std::size_t i = (from + k) % n;
    pts[i].speed = speed[i];
    if (k + 1 < lowered) ramp += ds[i];
  }
  ++speeds_version_;
  catch_up_until_ = driven_ + ramp;
}

void Stack::set_trajectory(Trajectory t) {
  trajectory_ = std::move(t);
  ++trajectory_version_;
  ++speeds_version_;
}

double Stack::finish_approach_cap(Vec2 base) const {
  const MissionParams& mp = params_.mission;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  if (spec_.finish_crossings <= 0 || telemetry_.finish_crossings != spec_.finish_crossings - 1 || trajectory_.empty())
    return kInf;
  // the gates' places on the path: projected once per trajectory and gate
  // list (every control cycle of the last lap asked for them again)
  const auto same = [](const Segment& x, const Segment& y) { return x.a == y.a && x.b == y.b; };
  if (gates_projected_version_ != trajectory_version_ ||
      !std::equal(gates_.begin(), gates_.end(), gates_projected_.begin(), gates_projected_.end(), same)) {
    gates_on_path_.clear();
    for (const Segment& g : gates_) {
      const TrajectoryProjection gate = project(trajectory_, 0.5 * (g.a + g.b), 0.0, 0.0);
      gates_on_path_.push_back({gate.s, gate.offset});
    }
    gates_projected_ = gates_;
    gates_projected_version_ = trajectory_version_;
  }
  // the car's place on the path: around last cycle's on the same trajectory
  // (as the controller's), a full search the first time or when that misses
  const control::ControlParams& cp = params_.control;
  const TrajectoryProjection car =
      car_projected_version_ == trajectory_version_
          ? project_near(trajectory_, base, car_s_, cp.projection_window, cp.relocalize_distance)
          : project(trajectory_, base, 0.0, 0.0);
  car_s_ = car.s;
  car_projected_version_ = trajectory_version_;
  // braking at stop_decel_max (less in turns) to the finish speed that stops
  // in stop_distance
  double cap = kInf;
  for (const GateOnPath& gate : gates_on_path_) {
    if (std::abs(gate.offset) > mp.gate_max_offset) continue;  // not a gate on this path
    double ahead = gate.s - car.s;
    if (trajectory_.closed && ahead < 0.0) ahead += trajectory_.length;
    if (ahead < 0.0) continue;
    cap = std::min(cap, stop_speed_cap(car.s, ahead + mp.stop_distance, mp.stop_decel_max));
  }
  return cap;
}

double Stack::stop_speed_cap(double s, double to_rest, double a) const {
  // the velocity profile's backward pass with braking alone, from rest at
  // s + to_rest: v^2 grows by 2 d ds going back, d = sqrt(a^2 - (v^2 kappa)^2)
  // (none where the turn takes all of a: there the cap stays under
  // sqrt(a / |kappa|)); an open path's last curvature goes on past its end
  constexpr double kInf = std::numeric_limits<double>::infinity();
  if (top_version_ != speeds_version_) {
    top_speed_ = 0.0;
    for (const TrajectoryPoint& p : trajectory_.points) top_speed_ = std::max(top_speed_, p.speed);
    top_version_ = speeds_version_;
  }
  const double top = top_speed_;
  constexpr double kStep = 0.25;  // m
  const int steps = std::max(1, static_cast<int>(std::ceil(to_rest / kStep)));
  const double h = to_rest / steps;
  double v2 = 0.0;
  for (int k = steps - 1; k >= 0; --k) {
    const double kappa = trajectory_.at(s + (k + 0.5) * h).curvature;
    const double ay = v2 * std::abs(kappa);
    v2 += 2.0 * std::sqrt(std::max(0.0, a * a - ay * ay)) * h;
    if (v2 > top * top) return kInf;  // above the whole trajectory: binds nowhere
  }
  return std::sqrt(v2);
}

double Stack::stop_deceleration(const hal::StateEstimate& st, double nominal) const {
  // the grip the turn leaves (friction circle of radius stop_decel_max), but
  // never under a floor: a stop in a turn that takes all of it still ends
  const MissionParams& mp = params_.mission;
  if (trajectory_.empty()) return nominal;
  const double a = std::max(mp.stop_decel, mp.stop_decel_max);
  const double kappa = project(trajectory_, st.pose.position(), 0.0, 0.0).ref.curvature;
  const double ay = st.vx * st.vx * std::abs(kappa);
  const double floor = 0.1 * mp.stop_decel;
  return std::clamp(std::sqrt(std::max(0.0, a * a - ay * ay)), std::min(floor, nominal), nominal);
}

void Stack::start_stopping(TimeNs now, double speed) {
  if (telemetry_.stopping) return;
  telemetry_.stopping = true;
  stop_start_ = now;
  stop_speed_ = std::max(speed, 0.0);
  stop_held_ = 0.0;
}

std::vector<Cone> Stack::gate_cones() const {
  // a vote weighs 1 a sighting, or more for the camera's (FastSLAM's
  // camera_vote_weight): at least gate_min_observations of a LiDAR's
  const double min_votes = params_.mission.gate_min_observations;
  std::vector<Cone> out;
  for (const slam::MappedCone& c : cone_map_.all()) {
    if (c.observations < params_.mission.gate_min_observations || c.color() != ConeColor::BigOrange) continue;
    if (c.votes[static_cast<std::size_t>(ConeColor::BigOrange)] >= min_votes) out.push_back({c.position, ConeColor::BigOrange});
  }
  return out;
}

bool Stack::gate_still_seen(const Segment& g, const std::vector<Vec2>& posts) {
  // the map still holds both of this gate's posts (from its big orange
  // cones, as it was learned): a gate learned from cones the map later saw as
  // small (their early sightings misjudged their size) is no gate. The posts,
  // not find_gates' pairing: one cone misjudged as big a few metres from a
  // post pairs with it more nearly than its true partner does, and the gate
  // would be lost (FSG 2019 without colours, seed 12: a yellow cone of the
  // start straight taken for a big one, the finish line forgotten 0.6 s
  // before the car reached it, and the car drove on)
  bool a = false, b = false;
  for (const Vec2& post : posts) {
    a = a || distance(post, g.a) < 0.5;
    b = b || distance(post, g.b) < 0.5;
  }
  return a && b;
}

bool Stack::count_crossing(double at, TimeNs now, double speed) {
  // a line marked twice, or two gates close together, count once
  if (at - last_crossing_at_ < params_.mission.gate_refractory_distance) return false;
  last_crossing_at_ = at;
  ++telemetry_.finish_crossings;
  if (spec_.finish_crossings > 0 && telemetry_.finish_crossings >= spec_.finish_crossings) start_stopping(now, speed);
  // the path before a counted crossing can count nothing more
  path_marks_.clear();
  return true;
}

std::optional<std::pair<Vec2, double>> Stack::crossed_since_last(const Segment& g, Vec2 base) const {
  std::optional<std::pair<Vec2, double>> latest;
  const Segment reversed{g.b, g.a};
  for (std::size_t i = 0; i < path_marks_.size(); ++i) {
    const Vec2 p0 = path_marks_[i].first;
    const Vec2 p1 = i + 1 < path_marks_.size() ? path_marks_[i + 1].first : base;
    const double d1 = i + 1 < path_marks_.size() ? path_marks_[i + 1].second : driven_;
    if (distance(p0, p1) <= 0.0) continue;
    std::optional<double> f = crossing_right_to_left(p0, p1, g);
    if (!f) f = crossing_right_to_left(p0, p1, reversed);
    if (!f) continue;
    const double d0 = path_marks_[i].second;
    if (d0 + *f * (d1 - d0) > last_crossing_at_) latest = std::make_pair(p1 - p0, d0 + *f * (d1 - d0));
  }
  return latest;
}

void Stack::count_crossings(Vec2 base, TimeNs now, double speed) {
  if (last_base_position_) {
    for (std::size_t i = 0; i < gates_.size(); ++i) {
      const Segment& g = gates_[i];
      if (!crossing_right_to_left(*last_base_position_, base, g)) continue;
      // a learned gate must still be one when the car crosses it
      if (i >= spec_.gates.size() && !gate_still_seen(g, find_posts(gate_cones(), params_.gates))) continue;
      count_crossing(driven_, now, speed);
    }
  }
  last_base_position_ = base;
  if (path_marks_.empty() || distance(path_marks_.back().first, base) >= kPathMarkSpacing)
    path_marks_.emplace_back(base, driven_);
}

hal::ActuatorCommand Stack::safe_stop(TimeNs now, const std::string& reason) {
  ++telemetry_.fallbacks;
  telemetry_.last_fault = reason;
  hal::ActuatorCommand cmd;
  cmd.stamp = now;
  cmd.steering_angle = 0.0;
  cmd.throttle = 0.0;
  cmd.brake = 1.0;
  cmd.as_state = telemetry_.as_state;
  return cmd;
}

void Stack::emergency(const std::string& reason) {
  if (fault_.empty()) fault_ = reason;
  telemetry_.last_fault = reason;
}

hal::MissionCode mission_code(Mission m) {
  switch (m) {
    case Mission::Acceleration: return hal::MissionCode::Acceleration;
    case Mission::Skidpad: return hal::MissionCode::Skidpad;
    case Mission::Autocross: return hal::MissionCode::Autocross;
    case Mission::Trackdrive: return hal::MissionCode::Trackdrive;
  }
  return hal::MissionCode::None;
}

AsInputs Stack::as_inputs(bool mission_done) {
  AsInputs in;
  if (vcu_) {
    in.vcu_known = true;
    in.asms_on = vcu_->asms_on;
    in.mission_selected = vcu_->mission == mission_code(spec_.mission);
    in.ebs_pressure = vcu_->ebs_pressure;
    in.brake_pressure = std::min(vcu_->brake_pressure_front, vcu_->brake_pressure_rear);
  }
  in.stack_ready = state_.has_value() && !trajectory_.empty();
  in.res_emergency = emergency_;
  in.fault = fault_;
  in.mission_done = mission_done;
  return in;
}

double Stack::emergency_steering(TimeNs now, double dt) {
  if (!state_ || trajectory_.empty() || now - state_->stamp > from_seconds(params_.mission.state_timeout)) return 0.0;
  control::ControlInput in;
  in.dt = dt;
  in.base_pose = state_->pose;
  in.vx = state_->vx;
  in.vy = state_->vy;
  in.yaw_rate = state_->yaw_rate;
  in.trajectory = &trajectory_;
  in.max_speed = 0.0;
  const control::ControlOutput out = timed(profile_, Stage::Control, [&] { return controller_.update(in); });
  return out.status == control::Status::Ok ? out.steering_angle : 0.0;
}

void Stack::tick(TimeNs now, hal::Hal& hal) {
  now_ = now;
  while (auto m = hal.receive()) on_message(std::move(*m));
  // (after the messages: the odometry at a scan's end comes just after it)
  if (slam_beside_) post_slam_steps();
  // the cones of the scans whose processing has taken [perception] latency
  // by now (after this cycle's messages: a scan that came in them is on its
  // way meanwhile)
  if (perception_) deliver_perception(now);
  // the watchdogs and the degraded modes (health.h); a fault it cannot drive with ends in AS Emergency
  if (localisation_ && localisation_->owns_map()) health_.map_fit(localisation_->lost_run());
  health_.cycle(now, state_ ? std::hypot(state_->vx, state_->vy) : 0.0);
  if (!health_.fault().empty() && fault_.empty()) emergency(health_.fault());
  if (perception_) perception_->set_camera_distrusted(health_.camera_distrusted());
  // frames that came before the state estimate of their instant
  {
    const StageScope scope(profile_, Stage::Localisation);
    while (!waiting_.empty() && !history_.empty() && waiting_.front().stamp <= history_.back().stamp) {
      add_to_map(waiting_.front());
      waiting_.pop_front();
    }
    while (waiting_.size() > 4) waiting_.pop_front();  // no state estimates: the old frames are of no use
    if (localisation_ && localisation_->take_map_news()) {
      cone_map_.assign(localisation_->map());
      map_news_ = true;
    }
  }
  const double dt = last_tick_ ? to_seconds(now - *last_tick_) : 0.0;
  last_tick_ = now;

  // planner = delaunay: plan whenever the map has news (also before the go, so the car is ready)
  if (params_.autonomy.planner == PlannerMode::Delaunay && state_ && map_news_) {
    const StageScope scope(profile_, Stage::Planning);
    plan(*state_);
  }

  // the AS state machine (as_machine.h); the mission's end is looked at
  // below, once this cycle's control has run
  AsInputs as_in = as_inputs(false);
  as_in.go = go_;
  go_ = false;
  auto& as = telemetry_.as_state;
  as = as_.update(now, as_in);

  hal::ActuatorCommand cmd;
  cmd.stamp = now;
  cmd.as_state = as;
  if (as != hal::AsState::Driving) {
    // not driving: brakes on; wheels straight, or in AS Emergency along the
    // trajectory while the EBS brakes
    if (as == hal::AsState::Emergency && params_.as.steer_in_emergency) cmd.steering_angle = emergency_steering(now, dt);
    hal.send(cmd);
    return;
  }
  if (!state_ || now - state_->stamp > from_seconds(params_.mission.state_timeout)) {
    hal.send(safe_stop(now, "state estimate missing or stale"));
    return;
  }
  const hal::StateEstimate& st = *state_;
  const double speed = std::hypot(st.vx, st.vy);
  if (!start_position_) start_position_ = st.pose.position();

  // the closed lap takes over where the car is on it
  if (!pending_lap_.empty()) {
    const Vec2 front = st.pose.transform({params_.vehicle.wheelbase, 0.0});
    const TrajectoryProjection on = project(pending_lap_, front, 0.0, 0.0);
    if (std::abs(on.offset) < params_.mission.lap_switch_offset &&
        std::abs(wrap_angle(on.ref.heading - st.pose.yaw)) < params_.mission.lap_switch_heading) {
      set_trajectory(std::move(pending_lap_));
      pending_lap_ = Trajectory{};
      catch_up(st);
    }
  }
  if (catch_up_until_ && driven_ >= *catch_up_until_) {
    // caught up: the lap's own speeds from here on
    for (std::size_t i = 0; i < trajectory_.points.size() && i < lap_speed_.size(); ++i)
      trajectory_.points[i].speed = lap_speed_[i];
    ++speeds_version_;
    catch_up_until_.reset();
  }
  driven_ += speed * dt;

  // mission progress: gate crossings of the base origin
  count_crossings(st.pose.position(), now, st.vx);

  // after the finish the speed cap ramps down to rest within the stop
  // distance; before the last finish it caps the approach
  const MissionParams& mp = params_.mission;
  double max_speed = std::numeric_limits<double>::infinity();
  if (telemetry_.stopping) {
    const double decel = std::clamp(stop_speed_ * stop_speed_ / (2.0 * mp.stop_distance), mp.stop_decel,
                                    std::max(mp.stop_decel, mp.stop_decel_max));
    // what the turn's grip held back is given up by the ramp (nothing on a
    // straight: the ramp is then exactly decel * t)
    stop_held_ += (decel - stop_deceleration(st, decel)) * dt;
    max_speed = std::max(0.0, stop_speed_ - decel * to_seconds(now - stop_start_) + stop_held_);
  } else {
    max_speed = finish_approach_cap(st.pose.position());
  }
  // degraded (the LiDAR lost or sparse): on the map and the odometry, slower
  max_speed = std::min(max_speed, health_.speed_cap(now));

  control::ControlInput in;
  in.dt = dt;
  in.base_pose = st.pose;
  in.vx = st.vx;
  in.vy = st.vy;
  in.yaw_rate = st.yaw_rate;
  in.trajectory = &trajectory_;
  in.max_speed = max_speed;
  const control::ControlOutput out = timed(profile_, Stage::Control, [&] { return controller_.update(in); });
  telemetry_.control = out.diagnostics;
  telemetry_.control_ok = out.status == control::Status::Ok;
  if (!telemetry_.control_ok) {
    hal.send(safe_stop(now, std::string("control: ") + control::to_string(out.status)));
    return;
  }

  // a mission without gates to count (skidpad) ends where its open path ends,
  // at rest (the profile's end speed is 0); the speed feedforward of the last
  // metres' hard braking can bring the car to rest a little short of the end
  const double end_margin = 3.0;  // m
  if (spec_.finish_crossings == 0 && !trajectory_.closed && out.diagnostics.s >= trajectory_.length - end_margin) {
    start_stopping(now, st.vx);
  }
  if (telemetry_.stopping && speed < mp.standstill_speed) as = as_.update(now, as_inputs(true));

  cmd.as_state = as;
  if (as == hal::AsState::Finished) {
    cmd.brake = 1.0;
  } else {
    cmd.steering_angle = out.steering_angle;
    cmd.throttle = out.throttle;
    cmd.yaw_moment = out.yaw_moment;
    cmd.brake = out.brake;
  }
  hal.send(cmd);
}

}  // namespace paddock::stack
