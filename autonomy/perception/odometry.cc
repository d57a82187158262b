#include "autonomy/perception/odometry.h"

#include <algorithm>
#include <cmath>

#include "autonomy/common/same_bits.h"

namespace paddock::perception {

namespace {

// sin(h) / h, its Taylor series near 0
double sinc(double h) { return std::abs(h) < 1e-6 ? 1.0 - h * h / 6.0 : std::sin(h) / h; }

}  // namespace

bool Odometry::same_state(const Odometry& o) const {
  const OdometryParams& p = params_;
  const OdometryParams& q = o.params_;
  if (!same_bits(p.wheel_radius, q.wheel_radius) || !same_bits(p.history, q.history) ||
      !same_bits(p.extrapolation, q.extrapolation) || p.lateral_velocity != q.lateral_velocity)
    return false;
  if (has_v_ != o.has_v_ || has_w_ != o.has_w_ || any_ != o.any_ || newest_ != o.newest_ || !same_bits(v_, o.v_) ||
      !same_bits(w_, o.w_) || !same_bits(u_, o.u_) || knots_.size() != o.knots_.size())
    return false;
  for (std::size_t i = 0; i < knots_.size(); ++i) {
    const Knot& a = knots_[i];
    const Knot& b = o.knots_[i];
    if (a.stamp != b.stamp || !same_bits(a.pose.x, b.pose.x) || !same_bits(a.pose.y, b.pose.y) ||
        !same_bits(a.pose.yaw, b.pose.yaw) || !same_bits(a.v, b.v) || !same_bits(a.w, b.w) || !same_bits(a.u, b.u))
      return false;
  }
  return true;
}

Odometry::Odometry(const OdometryParams& params) : params_(params) {
  params::require_valid(params_, "OdometryParams");
}

void Odometry::add(const hal::Imu& imu) {
  if (!finite(imu.yaw_rate) || (any_ && imu.stamp < newest_)) {
    ++rejected_;
    return;
  }
  step(imu.stamp);
  w_ = imu.yaw_rate;
  has_w_ = true;
  if (!knots_.empty() && knots_.back().stamp == imu.stamp) knots_.back().w = w_;
  if (knots_.empty() && has_v_) knots_.push_back({imu.stamp, Pose2{}, v_, w_, u_});
}

void Odometry::add(const hal::WheelSpeeds& wheels) {
  // the rear wheels (RL, RR): unsteered, their mean is the base origin's speed
  const double rl = wheels.omega[2], rr = wheels.omega[3];
  if (!finite(rl) || !finite(rr) || (any_ && wheels.stamp < newest_)) {
    ++rejected_;
    return;
  }
  step(wheels.stamp);
  v_ = 0.5 * (rl + rr) * params_.wheel_radius;
  has_v_ = true;
  if (!knots_.empty() && knots_.back().stamp == wheels.stamp) knots_.back().v = v_;
  if (knots_.empty() && has_w_) knots_.push_back({wheels.stamp, Pose2{}, v_, w_, u_});
}

void Odometry::add(const hal::StateEstimate& estimate) {
  if (!params_.lateral_velocity) return;
  if (!finite(estimate.vy)) {
    ++rejected_;
    return;
  }
  if (!any_ || estimate.stamp >= newest_) step(estimate.stamp);
  u_ = estimate.vy;
  if (!knots_.empty() && knots_.back().stamp == newest_) knots_.back().u = u_;
}

void Odometry::step(TimeNs stamp) {
  any_ = true;
  newest_ = stamp;
  if (knots_.empty()) return;
  const Knot& last = knots_.back();
  if (stamp > last.stamp) {
    // advance with the held values; the caller then stores the new value
    knots_.push_back({stamp, arc(last, to_seconds(stamp - last.stamp)), v_, w_, u_});
  }
  // forget knots older than the history, keeping one at or before its start
  const TimeNs horizon = stamp - from_seconds(params_.history);
  while (knots_.size() >= 2 && knots_[1].stamp <= horizon) knots_.pop_front();
}

Pose2 Odometry::arc(const Knot& k, double dt) {
  // exact integration at constant v, u and w: the body-frame velocity (v, u)
  // turns with the base, so the displacement is (v, u) dt sinc(w dt / 2)
  // turned to the mean heading yaw + w dt / 2 (the chord of the arc)
  const double dyaw = k.w * dt;
  const double f = dt * sinc(0.5 * dyaw);
  const double along = k.v * f, across = k.u * f;
  const double mid = k.pose.yaw + 0.5 * dyaw;
  const double c = std::cos(mid), s = std::sin(mid);
  return {k.pose.x + (along * c - across * s), k.pose.y + (along * s + across * c), k.pose.yaw + dyaw};
}

std::optional<Pose2> Odometry::pose_at(TimeNs t) const {
  if (knots_.empty()) return std::nullopt;
  const TimeNs tol = from_seconds(params_.extrapolation);
  if (t < knots_.front().stamp - tol || t > knots_.back().stamp + tol) return std::nullopt;
  // the last knot at or before t (the first one when t precedes it)
  auto it = std::upper_bound(knots_.begin(), knots_.end(), t,
                             [](TimeNs s, const Knot& k) { return s < k.stamp; });
  const Knot& k = it == knots_.begin() ? *it : *std::prev(it);
  return arc(k, to_seconds(t - k.stamp));
}

std::optional<Pose2> Odometry::relative(TimeNs from, TimeNs to) const {
  Pose2 out;
  if (!relative(from, &to, 1, &out)) return std::nullopt;
  return out;
}

bool Odometry::relative(TimeNs from, const TimeNs* to, std::size_t n, Pose2* out) const {
  const std::optional<Pose2> a = pose_at(from);
  if (!a) return false;
  // a->inverse_transform(q) is rotate(q - a->position(), -a->yaw): its cosine
  // and sine, once
  const double c = std::cos(-a->yaw), s = std::sin(-a->yaw);
  const TimeNs tol = from_seconds(params_.extrapolation);
  std::size_t k = 0;  // pose_at's knot for to[i]: the last at or before it, else the first
  for (std::size_t i = 0; i < n; ++i) {
    const TimeNs t = to[i];
    if (t < knots_.front().stamp - tol || t > knots_.back().stamp + tol) return false;
    if (i > 0 && t < to[i - 1]) k = 0;  // not ascending: walk again from the start
    while (k + 1 < knots_.size() && knots_[k + 1].stamp <= t) ++k;
    const Pose2 b = arc(knots_[k], to_seconds(t - knots_[k].stamp));
    const Vec2 d = b.position() - a->position();
    out[i] = Pose2{c * d.x - s * d.y, s * d.x + c * d.y, wrap_angle(b.yaw - a->yaw)};
  }
  return true;
}

}  // namespace paddock::perception
