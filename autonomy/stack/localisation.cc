#include "autonomy/stack/localisation.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace paddock::stack {

namespace {
// the odometry kept for the frames' stamps: a frame arrives within its
// perception latency (~0.1 s)
constexpr TimeNs kOdometryHistory = kNsPerSecond;
// frames waiting for the odometry: more means the odometry has stopped
constexpr std::size_t kMaxWaiting = 4;
}  // namespace

Localisation::Localisation(const SlamParams& p, SlamMode mode, const Pose2& start)
    : params_(p), mode_(mode), ekf_(p.velocity, p.geometry), published_frame_odom_(start), last_frame_odom_(start), start_(start) {
  if (mode == SlamMode::GroundTruth) throw std::invalid_argument("localisation: slam = ground_truth needs none");
  ekf_.reset(start, 0);
  if (mode_ == SlamMode::FastSlam || mode_ == SlamMode::FastSlamGraph || mode_ == SlamMode::LioGraph) {
    fastslam_.emplace(p.fastslam, p.seed);
    fastslam_->reset(start);
  }
  if (mode_ == SlamMode::Lio || mode_ == SlamMode::LioGraph) {
    // the IMU at its mounting point, the LiDAR at its own, both in the base frame
    slam::LioExtrinsics ext;
    ext.base_imu.translation() = Eigen::Vector3d(p.geometry.imu_x, p.geometry.imu_y, 0.0);
    ext.base_lidar.linear() = Eigen::AngleAxisd(p.lidar.mount_pitch, Eigen::Vector3d::UnitY()).toRotationMatrix();
    ext.base_lidar.translation() = Eigen::Vector3d(p.lidar.mount_x, p.lidar.mount_y, p.lidar.mount_z);
    lio_.emplace(p.lio, ext, start);
  }
  if (mode_ == SlamMode::Lio) {
    // the map: FastSLAM's logic with one particle that follows the LIO exactly
    slam::FastSlamParams mapper = p.fastslam;
    mapper.particles = 1;
    mapper.fastslam_version = 1;
    mapper.motion_std_xy_per_m = mapper.motion_std_yaw_per_m = mapper.motion_std_yaw_per_rad = 0.0;
    fastslam_.emplace(mapper, p.seed);
    fastslam_->reset(start);
  }
  // the graph's noise models are the front end's: the same sensors
  slam::PoseGraphParams& g = params_.graph;
  const slam::FastSlamParams& f = params_.fastslam;
  g.range_std = f.range_std;
  g.range_std_per_m = f.range_std_per_m;
  g.bearing_std = f.bearing_std;
  g.min_range = f.min_range;
  g.motion_std_xy_per_m = f.motion_std_xy_per_m;
  g.motion_std_yaw_per_m = f.motion_std_yaw_per_m;
  g.motion_std_yaw_per_rad = f.motion_std_yaw_per_rad;
  if (graph()) slam::PoseGraph check(g);  // throws on invalid params
}

std::optional<hal::StateEstimate> Localisation::on_imu(const hal::Imu& m) {
  if (ekf_.on_imu(m) != estimation::EkfStatus::Ok) {
    stats_.rejected_messages = static_cast<long>(ekf_.rejected());
    stats_.last_fault = "an IMU sample refused (not finite or out of order)";
    return std::nullopt;
  }
  const estimation::VelocityEstimate e = ekf_.estimate();
  Pose2 odom = e.pose;
  if (lio_) {
    // slam = lio: the odometry is the LIO's, carried to this sample
    lio_->on_imu(m);
    odom = lio_->predict_base_pose(e.stamp);
  }
  // (slam = lio: the LIO's last state may be newer than this sample)
  if (odom_.empty() || e.stamp > odom_.back().stamp || !lio_) odom_.push_back({e.stamp, odom});
  while (!odom_.empty() && e.stamp - odom_.front().stamp > kOdometryHistory) odom_.pop_front();
  // the frames the odometry has now reached
  while (!waiting_.empty() && waiting_.front().stamp <= e.stamp) {
    if (const std::optional<Pose2> o = odometry_at(waiting_.front().stamp)) {
      process(waiting_.front(), *o);
    } else {
      ++stats_.dropped_frames;
      stats_.last_fault = "no odometry at a frame's stamp";
    }
    waiting_.pop_front();
  }
  return hal::StateEstimate{e.stamp, compose(correction_, odom), e.vx, e.vy, e.yaw_rate};
}

void Localisation::on_scan(const hal::LidarScan& scan) {
  if (!lio_) return;
  const auto t0 = std::chrono::steady_clock::now();
  const long degenerate = lio_->stats().degenerate_slices, too_few = lio_->stats().too_few_points;
  const slam::LioStatus s = lio_->on_scan(scan);
  ++stats_.lio_scans;
  stats_.lio_degenerate_slices = lio_->stats().degenerate_slices;
  stats_.lio_too_few_points = lio_->stats().too_few_points;
  if (lio_->stats().degenerate_slices > degenerate) stats_.last_fault = "lio: a scan's geometry left a pose direction unobserved";
  if (lio_->stats().too_few_points > too_few) stats_.last_fault = "lio: too few planes matched in a slice";
  if (s == slam::LioStatus::NoImu) stats_.last_fault = "lio: a scan without IMU samples";
  // the odometry from the LIO's corrected state on: what was predicted past
  // it goes, the IMU samples to come carry it on
  const TimeNs at = lio_->stamp();
  while (!odom_.empty() && odom_.back().stamp >= at) odom_.pop_back();
  odom_.push_back({at, lio_->base_pose()});
  stats_.lio_ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
}

void Localisation::on_wheel_speeds(const hal::WheelSpeeds& m) {
  if (ekf_.on_wheel_speeds(m) != estimation::EkfStatus::Ok) stats_.last_fault = "wheel speeds refused (not finite or out of order)";
  stats_.rejected_messages = static_cast<long>(ekf_.rejected());
  stats_.slide_samples = static_cast<long>(ekf_.vy_gated());
}
void Localisation::on_steering(const hal::SteeringAngle& m) {
  if (ekf_.on_steering(m) != estimation::EkfStatus::Ok) stats_.last_fault = "a steering angle refused (not finite or out of order)";
  stats_.rejected_messages = static_cast<long>(ekf_.rejected());
}

void Localisation::on_detections(const hal::ConeDetections& d) {
  if (!fastslam_) return;
  if (odom_.empty() || d.stamp > odom_.back().stamp) {
    waiting_.push_back(d);
    while (waiting_.size() > kMaxWaiting) {
      waiting_.pop_front();
      ++stats_.dropped_frames;
      stats_.last_fault = "frames without odometry";
    }
    return;
  }
  if (const std::optional<Pose2> o = odometry_at(d.stamp)) {
    process(d, *o);
  } else {
    ++stats_.dropped_frames;
    stats_.last_fault = "a frame older than the odometry kept";
  }
}

Localisation::OdometryAt Localisation::odometry_for(TimeNs stamp, Pose2& odom) const {
  if (odom_.empty() || stamp > odom_.back().stamp) return OdometryAt::Later;
  const std::optional<Pose2> o = odometry_at(stamp);
  if (!o) return OdometryAt::Gone;
  odom = *o;
  return OdometryAt::Ready;
}

std::optional<Pose2> Localisation::odometry_at(TimeNs t) const {
  if (odom_.empty() || t < odom_.front().stamp || t > odom_.back().stamp) return std::nullopt;
  std::size_t i = 1;
  while (i < odom_.size() && odom_[i].stamp < t) ++i;
  if (i == odom_.size()) return odom_.back().pose;
  const Odom& a = odom_[i - 1];
  const Odom& b = odom_[i];
  const double f = b.stamp > a.stamp ? static_cast<double>(t - a.stamp) / static_cast<double>(b.stamp - a.stamp) : 1.0;
  return interpolate(a.pose, b.pose, f);
}

void Localisation::process(const hal::ConeDetections& d, const Pose2& odom) {
  step(d, odom, process_step_);
  publish(process_step_);
}

void Localisation::step(const hal::ConeDetections& d, const Pose2& odom, SlamStep& out) {
  const auto t0 = std::chrono::steady_clock::now();
  out.map_news = false;
  out.empty_frames = out.lost_frames = 0;
  out.loop_closures = out.graph_failures = out.relocalisations = out.relocalisation_failures = 0;
  out.optimise_ms.clear();
  out.last_fault.clear();
  const Pose2 delta = between(last_frame_odom_, odom);
  fastslam_->predict(delta);
  driven_ += std::hypot(delta.x, delta.y);
  last_frame_odom_ = odom;
  if (d.cones.empty()) {
    // no cone at all is a sensor's failure more likely than an empty track:
    // the map is not told that its cones in view went unseen
    out.empty_frames = 1;
    out.last_fault = "a frame without a cone";
  } else {
    std::vector<slam::Observation> obs;
    obs.reserve(d.cones.size());
    for (const hal::DetectedCone& c : d.cones) obs.push_back({c.position, c.color, c.colour_from_camera});
    fastslam_->update(obs, d.free_range);
    out.map_news = true;
    lost_run_ = lost_in_frame() ? lost_run_ + 1 : 0;
    if (lost_run_ > 0) out.lost_frames = 1;
    // (slam = lio: the pose is the LIO's, the cones do not move it)
    if (lost_run_ >= params_.relocalisation.lost_frames && mode_ != SlamMode::Lio) relocalise_on(obs, out);
    if (graph() && lost_run_ == 0) {
      const bool closure = closes_loop();
      record_node(odom, closure);
      if (closure) optimise_graph(out);
    }
  }
  out.correction = compose(fastslam_->pose(), between(odom, Pose2{}));
  const Eigen::Matrix3d cov = fastslam_->pose_covariance();
  out.slam_variance = cov(0, 0) + cov(1, 1);
  out.slam_yaw_variance = cov(2, 2);
  out.stamp = d.stamp;
  out.frame_odom = odom;
  out.lost_run = lost_run_;
  if (out.map_news) {
    // SLAM's map: the confirmed landmarks of the highest-weight particle
    out.map.clear();
    for (const slam::Landmark& l : fastslam_->map()) {
      slam::MappedCone m;
      m.position = l.mean;
      m.observations = l.sightings;
      m.votes = l.votes;
      out.map.push_back(m);
    }
  }
  const auto t1 = std::chrono::steady_clock::now();
  out.update_ms = std::chrono::duration<double, std::milli>(t1 - t0).count();
}

void Localisation::publish(SlamStep& s) {
  correction_ = s.correction;
  slam_variance_ = s.slam_variance;
  slam_yaw_variance_ = s.slam_yaw_variance;
  last_frame_stamp_ = s.stamp;
  published_frame_odom_ = s.frame_odom;
  published_lost_run_ = s.lost_run;
  if (s.map_news) {
    map_.swap(s.map);
    map_news_ = true;
  }
  ++stats_.frames;
  stats_.empty_frames += s.empty_frames;
  stats_.lost_frames += s.lost_frames;
  stats_.loop_closures += s.loop_closures;
  stats_.graph_failures += s.graph_failures;
  stats_.relocalisations += s.relocalisations;
  stats_.relocalisation_failures += s.relocalisation_failures;
  stats_.optimise_ms.insert(stats_.optimise_ms.end(), s.optimise_ms.begin(), s.optimise_ms.end());
  stats_.update_ms.push_back(s.update_ms);
  if (!s.last_fault.empty()) stats_.last_fault = s.last_fault;
}

void Localisation::record_node(const Pose2& odom, bool closure) {
  const Pose2 pose = fastslam_->pose();
  if (driven_ <= params_.loop_closure.start_distance) start_updates_ = fastslam_->updates();
  // a node when the odometry moved or turned enough since the last one (and
  // always at a closure: its pose is what the re-anchoring needs)
  if (!nodes_.empty()) {
    const Node& last = nodes_.back();
    const bool far = distance(odom.position(), last.odom.position()) >= params_.graph.node_spacing ||
                     std::abs(wrap_angle(odom.yaw - last.odom.yaw)) >= params_.graph.node_spacing_yaw;
    if (!far && !closure) return;
  }
  nodes_.push_back({pose, odom});
  const int node = static_cast<int>(nodes_.size()) - 1;
  for (const auto& [id, point] : fastslam_->best_sightings()) sightings_.push_back({node, id, point});
}

bool Localisation::closes_loop() const {
  const LoopClosureParams& lc = params_.loop_closure;
  if (driven_ - last_closure_at_ < lc.min_distance) return false;
  const Pose2 pose = fastslam_->pose();
  if (distance(pose.position(), start_.position()) > lc.radius) return false;
  int matches = 0;
  for (const auto& [id, point] : fastslam_->best_sightings())
    matches += id >= 0 && id / slam::FastSlam::kIdsPerUpdate < start_updates_ ? 1 : 0;
  return matches >= lc.min_matches;
}

void Localisation::optimise_graph(SlamStep& out) {
  const auto t0 = std::chrono::steady_clock::now();
  ++out.loop_closures;
  last_closure_at_ = driven_;
  closure_nodes_.push_back(static_cast<int>(nodes_.size()) - 1);
  // the window: from the closure window_laps back (the start until then)
  const int laps = params_.loop_closure.window_laps;
  const int first = static_cast<int>(closure_nodes_.size()) > laps
                        ? closure_nodes_[closure_nodes_.size() - 1 - static_cast<std::size_t>(laps)]
                        : 0;
  slam::PoseGraph graph(params_.graph);
  for (int i = first; i < static_cast<int>(nodes_.size()); ++i) graph.add_pose(nodes_[i].estimate, nodes_[i].odom);
  // the landmarks the front end still holds (its current estimate as the
  // initial value); sightings of landmarks it has dropped are left out
  std::vector<std::pair<std::int64_t, Vec2>> map;
  for (const slam::Landmark& l : fastslam_->all_landmarks()) map.emplace_back(l.id, l.mean);
  std::sort(map.begin(), map.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  for (const Sighting& s : sightings_) {
    if (s.node < first) continue;
    const auto it = std::lower_bound(map.begin(), map.end(), s.id, [](const auto& a, std::int64_t id) { return a.first < id; });
    if (it == map.end() || it->first != s.id) continue;
    graph.add_landmark(s.id, it->second);
    graph.add_observation(s.node - first, s.id, s.point);
  }
  // (hold_optimised: the nodes up to the last solved closure's held)
  const int held = params_.loop_closure.hold_optimised && optimised_until_ >= first ? optimised_until_ - first + 1 : 1;
  const slam::PoseGraph::Result r = graph.optimise(held);
  if (!r.ok) {
    ++out.graph_failures;
    out.last_fault = "pose graph: " + r.reason;
  } else {
    for (int i = first; i < static_cast<int>(nodes_.size()); ++i) nodes_[i].estimate = graph.pose(i - first);
    optimised_until_ = static_cast<int>(nodes_.size()) - 1;
    for (auto& [id, position] : map) {
      if (const std::optional<Vec2> l = graph.landmark(id)) position = *l;
    }
    // the loop closed on the optimised map: fewer particles localise in it
    // (reanchor takes 0 for the full set)
    fastslam_->reanchor(nodes_.back().estimate, map, std::numeric_limits<std::int64_t>::max(),
                        params_.fastslam.closed_particles);
  }
  out.optimise_ms.push_back(
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
}

bool Localisation::lost_in_frame() const {
  const auto& seen = fastslam_->best_sightings();
  const slam::RelocaliseParams& rp = params_.relocalisation;
  if (static_cast<int>(seen.size()) < rp.lost_min_observations) return false;
  // associated: with a landmark started before this update, and before the
  // lost frames in a row so far (their observations started ghosts, which
  // the next frame would associate with)
  const std::int64_t now = fastslam_->updates() - 1 - lost_run_;
  int associated = 0;
  for (const auto& [id, point] : seen) associated += id >= 0 && id / slam::FastSlam::kIdsPerUpdate < now ? 1 : 0;
  // with next to no map there is nothing to associate with
  return fastslam_->map().size() >= seen.size() &&
         static_cast<double>(associated) < rp.lost_ratio * static_cast<double>(seen.size());
}

void Localisation::relocalise_on(const std::vector<slam::Observation>& obs, SlamStep& out) {
  // the map as it was before the car got lost: the landmarks the lost
  // frames started are where the lost pose put them (ghosts of the cones it
  // sees, which would fit the lost pose); tentative ones count (the far
  // cones of the frame, seen a few times before)
  const std::int64_t lost_since = fastslam_->updates() - lost_run_;
  std::vector<Vec2> map, points;
  for (const slam::Landmark& l : fastslam_->all_landmarks())
    if (l.id / slam::FastSlam::kIdsPerUpdate < lost_since) map.push_back(l.mean);
  for (const slam::Observation& o : obs)
    if (finite(o.position)) points.push_back(o.position);
  const std::optional<slam::Relocalisation> r =
      slam::relocalise(map, points, fastslam_->pose(), params_.relocalisation);
  if (!r) {
    ++out.relocalisation_failures;
    out.last_fault = "lost: no pose near the estimate fits the map";
    return;
  }
  ++out.relocalisations;
  out.last_fault = "lost: relocalised";
  fastslam_->reanchor(r->pose, {}, lost_since);
  lost_run_ = 0;
  // the odometry's chain broke where the car was moved: the graph starts
  // again from here, its first node held where the relocalisation put it
  nodes_.clear();
  sightings_.clear();
  closure_nodes_.clear();
  optimised_until_ = -1;
}

double Localisation::odometry_variance() const {
  const estimation::VelocityEstimate e = ekf_.estimate();
  return e.variance[estimation::kX] + e.variance[estimation::kY];
}

double Localisation::position_variance() const {
  if (mode_ == SlamMode::Lio) {
    const Eigen::Matrix3d c = lio_->base_pose_covariance();
    return c(0, 0) + c(1, 1);
  }
  if (!fastslam_) return odometry_variance();
  const estimation::VelocityEstimate e = ekf_.estimate();
  const double d2 = squared_norm(e.pose.position() - published_frame_odom_.position());
  const double dt = std::max(0.0, to_seconds(e.stamp - last_frame_stamp_));
  const double added = d2 * slam_yaw_variance_ + dt * dt * (e.variance[estimation::kVx] + e.variance[estimation::kVy]) +
                       0.25 * d2 * dt * dt * e.variance[estimation::kR];
  return slam_variance_ + added;
}

bool Localisation::take_map_news() {
  const bool news = map_news_;
  map_news_ = false;
  return news;
}


}  // namespace paddock::stack
