#pragma once
// lateral control laws (paper section "Control", "Lateral Control"): Stanley
// with Hoffmann's steady-state yaw, pure pursuit, and their curvature-weighted
// combination. Pure functions of scalars plus the look-ahead search; the
// Controller (controller.h) feeds them from the pose and the trajectory.
//
// Conventions (ISO / REP-103): steering angle delta > 0 turns LEFT; angles are
// counter-clockwise; the vehicle `base` frame sits at the rear axle centre.
#include <string>

#include "autonomy/common/geometry.h"
#include "autonomy/common/params.h"
#include "autonomy/common/trajectory.h"

namespace paddock::control {

enum class LateralMode { Combined, Stanley, PurePursuit };

const char* to_string(LateralMode m);

// delta = psi_e + atan(k e / (k_soft + v)) (+ theta_ss)
struct StanleyParams {
  double k = 2.5;
  // keeps the gain finite at standstill
  double k_soft = 1.0;
  // theta_ss: the front axle's slip angle in a steady turn, see
  // steady_state_yaw
  bool use_steady_state_yaw = true;
  // the heading term reads the path this long ahead of the front axle (at
  // v * preview_time): the steering actuator and the tyres' relaxation lag
  // the command, so a car at speed that steers for the path where it is
  // turns in late and unwinds late at a corner's exit. 0: the paper's law
  double preview_time = 0.0;

  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(k), {"1/s", params::in(0.0, 100.0), "Stanley cross-track gain"});
    v(PADDOCK_PARAM(k_soft), {"m/s", params::above_up_to(0.0, 100.0), "Stanley softening speed"});
    v(PADDOCK_PARAM(use_steady_state_yaw), "add Hoffmann's steady-state yaw to Stanley");
    v(PADDOCK_PARAM(preview_time), {"s", params::in(0.0, 1.0), "the heading term reads the path this far ahead of the front axle"});
  }
};

// L_d = L_min + k_v v
struct PurePursuitParams {
  double L_min = 2.5;
  double k_v = 0.15;

  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(L_min), {"m", params::in(0.1, 100.0), "pure pursuit look-ahead at standstill L_min"});
    v(PADDOCK_PARAM(k_v), {"s", params::in(0.0, 10.0), "pure pursuit look-ahead growth k_v"});
  }
};

// k_pp = clamp(min(k_min + |kappa| / kappa_ref * k_curve, k_max), 0, 1)
struct CombinedParams {
  double k_min = 0.2;
  double k_max = 0.8;
  // a 10 m radius adds k_curve
  double kappa_ref = 0.1;
  double k_curve = 0.6;

  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(k_min), {"", params::fraction(), "pure pursuit weight on a straight"});
    v(PADDOCK_PARAM(k_max), {"", params::fraction(), "largest pure pursuit weight (>= k_min)"});
    v(PADDOCK_PARAM(kappa_ref), {"1/m", params::in(1e-6, 100.0), "curvature scale"});
    v(PADDOCK_PARAM(k_curve), {"", params::in(0.0, 10.0), "weight added per kappa_ref of curvature"});
  }
  std::string check() const { return k_max >= k_min ? "" : "k_max must be >= k_min"; }
};

// Stanley, kinematic part: delta = psi_e + atan(k e / (k_soft + v)) (rad).
// psi_e = wrap(path heading - yaw) (rad); e = the path's lateral offset from
// the front axle centre, > 0 when the path lies to the LEFT (m); v (m/s).
double stanley_steer(double psi_e, double e, double v, double k, double k_soft);

// L_d = L_min + k_v v (m); a negative speed counts as 0
double lookahead_distance(double v, double L_min, double k_v);

// pure pursuit: delta = atan(2 L sin(alpha) / L_d) (rad); alpha is the bearing
// of the look-ahead point from the rear axle, relative to the heading (> 0 left)
double pure_pursuit_steer(double alpha, double L_d, double wheelbase);

// the pure pursuit weight of the combined law,
// k_pp = min(k_min + |kappa| / kappa_ref * k_curve, k_max), clamped to [0, 1]
double combined_weight(double kappa, double k_min, double k_max, double kappa_ref, double k_curve);

// Hoffmann et al.'s steady-state yaw, theta_ss = m r_traj v / (C_y (1 + lf/lr)) (rad),
// signed like r_traj; mass (kg), r_traj = yaw rate of the trajectory (rad/s),
// v (m/s), C_y = FRONT axle cornering stiffness (N/rad), lf, lr = CG to axles (m).
// In our convention the full Stanley law ADDS it:
//   delta_st = psi_e + theta_ss + atan(k e / (k_soft + v))
// (the derivation of the sign is in lateral.cc).
double steady_state_yaw(double mass, double r_traj, double v, double C_y, double lf, double lr);

// the linear front axle cornering stiffness of a Pacejka tyre at its static
// load: C_y = B C D Fz_front (N/rad), Fz_front = m g lr / (lf + lr); D is the
// friction coefficient (Fy = D Fz sin(C atan(B alpha ...))), so dFy/dalpha at 0 = B C D Fz
constexpr double front_axle_cornering_stiffness(double B, double C, double D, double mass,
                                                double lf, double lr) {
  return B * C * D * mass * kGravity * lr / (lf + lr);
}

// the pure pursuit look-ahead point
struct LookAhead {
  double s = 0.0;         // arc length of the point on the trajectory (m)
  Vec2 point;             // the point (m, map frame)
  double distance = 0.0;  // its Euclidean distance from the rear axle (m)
  double curvature = 0.0; // trajectory curvature there (1/m)
  bool found = false;     // false: the fallback s_rear + L_d was used
};

// the first point ahead of the rear axle at Euclidean distance L_d: walks the
// trajectory forward from the rear axle's projection s_rear (at most
// max(4 L_d, L_d + 10 m) of arc length, and never past the end of an open
// trajectory) and intersects the circle of radius L_d with the segment where
// the distance first reaches L_d. When the rear axle is already farther than
// L_d from the path, or no crossing exists, falls back to the point at
// s_rear + L_d. The trajectory must not be empty.
LookAhead find_lookahead(const Trajectory& traj, Vec2 rear_axle, double s_rear, double L_d);

}  // namespace paddock::control
