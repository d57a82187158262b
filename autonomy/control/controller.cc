#include "autonomy/control/controller.h"

#include <algorithm>
#include <cmath>

namespace paddock::control {

namespace {

SpeedModel speed_model_of(const VehicleKnowledge& v) {
  SpeedModel m;
  m.mass = v.equivalent_mass;
  m.drag_coefficient = v.drag_coefficient;
  m.rolling_resistance = v.rolling_resistance;
  m.max_drive_force = v.max_drive_force;
  m.max_drive_power = v.max_drive_power;
  m.max_brake_force = v.max_brake_force;
  return m;
}

// d(speed)/ds of the reference around s, over about one sample spacing (1/s)
double speed_slope(const Trajectory& traj, double s) {
  const double nseg = static_cast<double>(traj.closed ? traj.points.size() : traj.points.size() - 1);
  const double h = 0.5 * traj.length / nseg;
  double lo = s - h;
  double hi = s + h;
  if (!traj.closed) {
    lo = std::clamp(lo, 0.0, traj.length);
    hi = std::clamp(hi, 0.0, traj.length);
  }
  if (hi - lo <= 0.0) return 0.0;
  return (traj.at(hi).speed - traj.at(lo).speed) / (hi - lo);
}

}  // namespace

const char* to_string(Status s) {
  switch (s) {
    case Status::Ok: return "ok";
    case Status::NoTrajectory: return "no_trajectory";
    case Status::BadState: return "bad_state";
  }
  return "bad_state";
}

Controller::Controller(const ControlParams& params, const VehicleKnowledge& vehicle)
    : params_(params), vehicle_(vehicle), speed_model_(speed_model_of(vehicle)) {}

void Controller::reset() {
  speed_.reset();
  have_hint_ = false;
  s_hint_ = 0.0;
  last_cap_ = 0.0;
  last_cap_finite_ = false;
  traj_ptr_ = nullptr;
  last_ = ControlOutput{};
}

ControlOutput Controller::fault(Status status, const char* reason) {
  reset();
  ControlOutput out;  // wheels straight, full brake
  out.status = status;
  out.reason = reason;
  last_ = out;
  return out;
}

bool Controller::same_trajectory(const Trajectory& t) const {
  return &t == traj_ptr_ && t.points.size() == traj_size_ && t.length == traj_length_ &&
         t.points.front().position() == traj_first_;
}

ControlOutput Controller::update(const ControlInput& in) {
  // reject what cannot be controlled on
  if (in.trajectory == nullptr) return fault(Status::NoTrajectory, "no trajectory");
  const Trajectory& traj = *in.trajectory;
  if (traj.empty()) return fault(Status::NoTrajectory, "trajectory has fewer than two points");
  if (!(traj.length > 0.0) || !finite(traj.length))
    return fault(Status::NoTrajectory, "trajectory length is not positive and finite");
  const Pose2& pose = in.base_pose;
  if (!finite(pose.x) || !finite(pose.y) || !finite(pose.yaw))
    return fault(Status::BadState, "pose is not finite");
  if (!finite(in.vx) || !finite(in.vy) || !finite(in.yaw_rate))
    return fault(Status::BadState, "velocity or yaw rate is not finite");
  if (!finite(in.dt) || in.dt < 0.0) return fault(Status::BadState, "dt is negative or not finite");
  if (std::isnan(in.max_speed)) return fault(Status::BadState, "max_speed is NaN");

  const VehicleKnowledge& car = vehicle_;
  const double v = std::max(in.vx, 0.0);  // forward driving only
  const Vec2 rear = pose.position();
  const Vec2 front = pose.transform({car.wheelbase, 0.0});

  // the base's projection: around last cycle's, advanced by the distance
  // driven since; a full search when there is nothing to go on
  const bool hint_valid = have_hint_ && same_trajectory(traj);
  TrajectoryProjection base;
  if (hint_valid) {
    base = project_near(traj, rear, s_hint_ + v * in.dt, params_.projection_window, params_.relocalize_distance);
  } else {
    base = project(traj, rear, 0.0, 0.0);
  }
  // the front axle's, one wheelbase further on
  const TrajectoryProjection fa = project(traj, front, base.s + car.wheelbase, params_.projection_window);
  if (!finite(base.ref) || !finite(fa.ref) || !finite(base.offset) || !finite(fa.offset))
    return fault(Status::NoTrajectory, "trajectory has non-finite values");

  ControlOutput out;
  Diagnostics& d = out.diagnostics;
  d.s = base.s;

  // Stanley at the front axle: e > 0 when the path lies left of it
  const double preview = v * params_.stanley.preview_time;
  const double path_heading = preview > 0.0 ? traj.at(fa.s + preview).heading : fa.ref.heading;
  const double psi_e = wrap_angle(path_heading - pose.yaw);
  const double e = -fa.offset;
  const double r_traj = v * fa.ref.curvature;  // yaw rate of the trajectory (rad/s)
  d.lateral_error = fa.offset;
  d.heading_error = psi_e;
  d.theta_ss = params_.stanley.use_steady_state_yaw
                   ? steady_state_yaw(car.mass, r_traj, v, car.front_cornering_stiffness, car.lf, car.lr)
                   : 0.0;
  d.delta_st = stanley_steer(psi_e, e, v, params_.stanley.k, params_.stanley.k_soft) + d.theta_ss;

  // pure pursuit from the rear axle; the law uses the point's actual distance
  // when it is farther than L_d (the fallback, far off the path: the arc
  // through it), and L_d when it is nearer (the end of an open path: no
  // blow-up of 1 / distance)
  const double L_d = lookahead_distance(v, params_.pure_pursuit.L_min, params_.pure_pursuit.k_v);
  const LookAhead la = find_lookahead(traj, rear, base.s, L_d);
  const double alpha = wrap_angle(angle_of(la.point - rear) - pose.yaw);
  d.lookahead_distance = std::max(la.distance, L_d);
  d.delta_pp = pure_pursuit_steer(alpha, d.lookahead_distance, car.wheelbase);

  // the blend, weighted by the curvature at the look-ahead point
  switch (params_.lateral) {
    case LateralMode::Combined: {
      const CombinedParams& c = params_.combined;
      d.k_pp = combined_weight(la.curvature, c.k_min, c.k_max, c.kappa_ref, c.k_curve);
      break;
    }
    case LateralMode::Stanley: d.k_pp = 0.0; break;
    case LateralMode::PurePursuit: d.k_pp = 1.0; break;
  }
  double delta = (1.0 - d.k_pp) * d.delta_st + d.k_pp * d.delta_pp;

  // yaw-rate damping: yawing left faster than the path asks -> steer right
  delta -= params_.k_d_yaw * (in.yaw_rate - r_traj);
  out.yaw_moment = -params_.k_tv_yaw * (in.yaw_rate - r_traj);
  out.steering_angle = std::clamp(delta, -car.max_steering_angle, car.max_steering_angle);

  // the reference speed, read speed_preview_time ahead for the actuators' lag
  const LongitudinalParams& lp = params_.longitudinal;
  const double s_preview = base.s + v * lp.speed_preview_time;
  const double v_traj = std::max(traj.at(s_preview).speed, 0.0);
  double a_ref = v_traj * speed_slope(traj, s_preview);  // a = v dv/ds
  const double cap = std::max(in.max_speed, 0.0);
  const bool cap_active = cap < v_traj;
  if (cap_active) {
    // the cap rules: feed forward its own slope (the mission's ramp down)
    const bool slope_known = have_hint_ && last_cap_finite_ && in.dt > 0.0;
    a_ref = slope_known ? std::min((cap - last_cap_) / in.dt, 0.0) : 0.0;
    speed_.release_drive();
  }
  d.v_ref = cap_active ? cap : v_traj;
  d.a_ref = a_ref;
  last_cap_ = cap;
  last_cap_finite_ = finite(in.max_speed);

  const LongitudinalCommand lc = speed_.update(d.v_ref, d.a_ref, in.vx, in.dt, lp, speed_model_);
  out.throttle = lc.throttle;
  out.brake = lc.brake;

  // remember where we were
  have_hint_ = true;
  s_hint_ = base.s;
  traj_ptr_ = &traj;
  traj_size_ = traj.points.size();
  traj_length_ = traj.length;
  traj_first_ = traj.points.front().position();
  last_ = out;
  return out;
}

}  // namespace paddock::control
