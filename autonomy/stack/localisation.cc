#include "autonomy/stack/localisation.h"

#include <algorithm>
#include <chrono>
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
    : params_(p), mode_(mode), ekf_(p.velocity, p.geometry), last_frame_odom_(start) {
  if (mode == SlamMode::GroundTruth) throw std::invalid_argument("localisation: slam = ground_truth needs none");
  ekf_.reset(start, 0);
  if (mode_ == SlamMode::FastSlam) {
    fastslam_.emplace(p.fastslam, p.seed);
    fastslam_->reset(start);
  }
}

std::optional<hal::StateEstimate> Localisation::on_imu(const hal::Imu& m) {
  if (ekf_.on_imu(m) != estimation::EkfStatus::Ok) return std::nullopt;
  const estimation::VelocityEstimate e = ekf_.estimate();
  odom_.push_back({e.stamp, e.pose});
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
  return hal::StateEstimate{e.stamp, compose(correction_, e.pose), e.vx, e.vy, e.yaw_rate};
}

void Localisation::on_wheel_speeds(const hal::WheelSpeeds& m) { ekf_.on_wheel_speeds(m); }
void Localisation::on_steering(const hal::SteeringAngle& m) { ekf_.on_steering(m); }

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

std::optional<Pose2> Localisation::odometry_at(TimeNs t) const {
  if (odom_.empty() || t < odom_.front().stamp || t > odom_.back().stamp) return std::nullopt;
  std::size_t i = 1;
  while (i < odom_.size() && odom_[i].stamp < t) ++i;
  if (i == odom_.size()) return odom_.back().pose;
  const Odom& a = odom_[i - 1];
  const Odom& b = odom_[i];
  const double f = b.stamp > a.stamp ? static_cast<double>(t - a.stamp) / static_cast<double>(b.stamp - a.stamp) : 1.0;
  return Pose2{a.pose.x + f * (b.pose.x - a.pose.x), a.pose.y + f * (b.pose.y - a.pose.y),
               wrap_angle(a.pose.yaw + f * wrap_angle(b.pose.yaw - a.pose.yaw))};
}

void Localisation::process(const hal::ConeDetections& d, const Pose2& odom) {
  const auto t0 = std::chrono::steady_clock::now();
  fastslam_->predict(between(last_frame_odom_, odom));
  last_frame_odom_ = odom;
  ++stats_.frames;
  if (d.cones.empty()) {
    // no cone at all is a sensor's failure more likely than an empty track:
    // the map is not told that its cones in view went unseen
    ++stats_.empty_frames;
    stats_.last_fault = "a frame without a cone";
  } else {
    std::vector<slam::Observation> obs;
    obs.reserve(d.cones.size());
    for (const hal::DetectedCone& c : d.cones) obs.push_back({c.position, c.color, c.colour_from_camera});
    fastslam_->update(obs);
    map_news_ = true;
  }
  correction_ = compose(fastslam_->pose(), between(odom, Pose2{}));
  const Eigen::Matrix3d cov = fastslam_->pose_covariance();
  slam_variance_ = cov(0, 0) + cov(1, 1);
  odom_variance_at_frame_ = odometry_variance();
  const auto t1 = std::chrono::steady_clock::now();
  stats_.update_ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
}

double Localisation::odometry_variance() const {
  const estimation::VelocityEstimate e = ekf_.estimate();
  return e.variance[estimation::kX] + e.variance[estimation::kY];
}

double Localisation::position_variance() const {
  if (!fastslam_) return odometry_variance();
  return slam_variance_ + std::max(0.0, odometry_variance() - odom_variance_at_frame_);
}

bool Localisation::take_map_news() {
  const bool news = map_news_;
  map_news_ = false;
  return news;
}

std::vector<slam::MappedCone> Localisation::map() const {
  std::vector<slam::MappedCone> out;
  if (!fastslam_) return out;
  for (const slam::Landmark& l : fastslam_->map()) {
    slam::MappedCone m;
    m.position = l.mean;
    m.observations = l.sightings;
    m.votes = l.votes;
    out.push_back(m);
  }
  return out;
}

}  // namespace paddock::stack
