#include "autonomy/stack/stack.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "autonomy/common/polyline.h"

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

Stack::Stack(const StackParams& params, MissionSpec spec)
    : params_(params), spec_(std::move(spec)), controller_(params.control, params.vehicle), cone_map_(params.cone_map) {
  // planner = oracle: the whole reference is planned once, before the start;
  // an open path starts free (the car launches at full drive) and ends at rest
  const std::optional<double> v_end =
      spec_.oracle_closed ? std::nullopt : std::optional<double>(0.0);
  auto result = planning::build_reference(spec_.oracle_path, spec_.oracle_closed, params_.reference,
                                          std::nullopt, v_end);
  if (result.ok()) {
    trajectory_ = std::move(result.trajectory);
  } else {
    telemetry_.last_fault = "planning: " + result.reason;
  }
}

void Stack::on_message(const hal::SensorMessage& m) {
  if (const auto* est = std::get_if<hal::StateEstimate>(&m)) {
    state_ = *est;
    history_.push_back(*est);
    while (!history_.empty() && est->stamp - history_.front().stamp > kNsPerSecond) history_.pop_front();
  } else if (const auto* det = std::get_if<hal::ConeDetections>(&m)) {
    on_detections(*det);
  } else if (const auto* res = std::get_if<hal::ResSignal>(&m)) {
    go_ = go_ || res->go;
    emergency_ = emergency_ || res->emergency;
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
  return Pose2{a.pose.x + f * (b.pose.x - a.pose.x), a.pose.y + f * (b.pose.y - a.pose.y),
               wrap_angle(a.pose.yaw + f * wrap_angle(b.pose.yaw - a.pose.yaw))};
}

void Stack::on_detections(const hal::ConeDetections& d) {
  // slam = ground_truth: the detections go into the map at the pose the car had when they were measured
  const std::optional<Pose2> pose = pose_at(d.stamp);
  if (!pose) return;
  std::vector<Cone> in_map;
  in_map.reserve(d.cones.size());
  for (const hal::DetectedCone& c : d.cones) in_map.push_back({pose->transform(c.position), c.color});
  cone_map_.add(in_map);
  telemetry_.mapped_cones = static_cast<int>(cone_map_.cones().size());
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

void Stack::tick(TimeNs now, hal::Hal& hal) {
  while (auto m = hal.receive()) on_message(*m);
  const double dt = last_tick_ ? to_seconds(now - *last_tick_) : 0.0;
  last_tick_ = now;

  // the AS state machine: off -> ready (plan and state known) -> driving (go)
  // -> finished (stopped after the mission); emergency from any state
  auto& as = telemetry_.as_state;
  if (emergency_) as = hal::AsState::Emergency;
  if (as == hal::AsState::Off && state_ && !trajectory_.empty()) as = hal::AsState::Ready;
  if (as == hal::AsState::Ready && go_) as = hal::AsState::Driving;

  hal::ActuatorCommand cmd;
  cmd.stamp = now;
  cmd.as_state = as;
  if (as != hal::AsState::Driving) {
    // not driving: wheels straight, brakes on
    hal.send(cmd);
    return;
  }
  if (!state_ || now - state_->stamp > from_seconds(params_.mission.state_timeout)) {
    hal.send(safe_stop(now, "state estimate missing or stale"));
    return;
  }
  const hal::StateEstimate& st = *state_;

  // mission progress: count finish-line crossings of the base origin
  const Vec2 base = st.pose.position();
  if (spec_.finish_line && spec_.finish_crossings > 0 && last_base_position_ &&
      crossing_right_to_left(*last_base_position_, base, *spec_.finish_line)) {
    ++telemetry_.finish_crossings;
    if (telemetry_.finish_crossings >= spec_.finish_crossings && !telemetry_.stopping) {
      telemetry_.stopping = true;
      stop_start_ = now;
      stop_speed_ = std::max(st.vx, 0.0);
    }
  }
  last_base_position_ = base;

  // after the finish the speed cap ramps down at the stop deceleration
  double max_speed = std::numeric_limits<double>::infinity();
  if (telemetry_.stopping) {
    max_speed = std::max(0.0, stop_speed_ - params_.mission.stop_decel * to_seconds(now - stop_start_));
  }

  control::ControlInput in;
  in.dt = dt;
  in.base_pose = st.pose;
  in.vx = st.vx;
  in.vy = st.vy;
  in.yaw_rate = st.yaw_rate;
  in.trajectory = &trajectory_;
  in.max_speed = max_speed;
  const control::ControlOutput out = controller_.update(in);
  telemetry_.control = out.diagnostics;
  telemetry_.control_ok = out.status == control::Status::Ok;
  if (!telemetry_.control_ok) {
    hal.send(safe_stop(now, std::string("control: ") + control::to_string(out.status)));
    return;
  }

  // an open path ends at rest (the profile's end speed is 0): near its end the
  // mission is over (the speed feedforward of the last metres' hard braking
  // can bring the car to rest a little short of the very end)
  const double end_margin = 3.0;  // m
  if (!trajectory_.closed && out.diagnostics.s >= trajectory_.length - end_margin && !telemetry_.stopping) {
    telemetry_.stopping = true;
    stop_start_ = now;
    stop_speed_ = std::max(st.vx, 0.0);
  }
  const bool at_rest = std::hypot(st.vx, st.vy) < params_.mission.standstill_speed;
  if (telemetry_.stopping && at_rest) as = hal::AsState::Finished;

  cmd.as_state = as;
  if (as == hal::AsState::Finished) {
    cmd.brake = 1.0;
  } else {
    cmd.steering_angle = out.steering_angle;
    cmd.throttle = out.throttle;
    cmd.brake = out.brake;
  }
  hal.send(cmd);
}

}  // namespace paddock::stack
