#include "autonomy/control/lateral.h"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace paddock::control {

const char* to_string(LateralMode m) {
  switch (m) {
    case LateralMode::Combined: return "combined";
    case LateralMode::Stanley: return "stanley";
    case LateralMode::PurePursuit: return "pure_pursuit";
  }
  return "combined";
}

double stanley_steer(double psi_e, double e, double v, double k, double k_soft) {
  // heading term aligns the front wheels with the path; the cross-track term
  // turns them towards it, with a gain that falls with speed
  return psi_e + std::atan(k * e / (k_soft + v));
}

double lookahead_distance(double v, double L_min, double k_v) {
  return L_min + k_v * std::max(v, 0.0);
}

double pure_pursuit_steer(double alpha, double L_d, double wheelbase) {
  // the arc from the rear axle through the look-ahead point has curvature
  // 2 sin(alpha) / L_d; a kinematic bicycle follows it at delta = atan(L kappa)
  return std::atan(2.0 * wheelbase * std::sin(alpha) / L_d);
}

double combined_weight(double kappa, double k_min, double k_max, double kappa_ref, double k_curve) {
  const double k = std::min(k_min + std::abs(kappa) / kappa_ref * k_curve, k_max);
  return std::clamp(k, 0.0, 1.0);
}

// the sign of theta_ss. Hoffmann et al. (2007) steer with
//   delta_H = (psi_H - psi_ss) + atan(k e_H / v) + k_d,yaw (r_meas - r_traj) + ...
// where delta_H > 0 steers RIGHT and psi_H = vehicle yaw - path yaw: a car
// rotated left of the path (psi_H > 0) steers right. Ours is the mirror image,
// delta = -delta_H and psi_e = -psi_H, so
//   delta = psi_e + psi_ss + atan(k e / v) - k_d,yaw (r_meas - r_traj),
// psi_ss keeping the sign of r_traj (counter-clockwise, left turns > 0).
// The physics agrees: in a steady turn the front axle carries the lateral
// force F_yf = m v r lr / (lf + lr) towards the centre, which needs the slip
// angle alpha_f = F_yf / C_y = m v r / (C_y (1 + lf/lr)) = theta_ss. The
// kinematic law (delta = psi_e at e = 0) points the wheels along the front
// axle's velocity; they must point theta_ss further INTO the turn, so it is
// added with the sign of r_traj, and at equilibrium the car points more inward.
double steady_state_yaw(double mass, double r_traj, double v, double C_y, double lf, double lr) {
  return mass * r_traj * v / (C_y * (1.0 + lf / lr));
}

LookAhead find_lookahead(const Trajectory& traj, Vec2 rear_axle, double s_rear, double L_d) {
  const std::size_t n = traj.points.size();
  const std::size_t nseg = traj.closed ? n : n - 1;
  const double step = traj.length / static_cast<double>(nseg);
  const double s0 = traj.wrap(s_rear);

  LookAhead out;
  // walk forward from the rear axle's own projection
  Vec2 a = traj.at(s0).position();
  double s_a = s0;
  double max_arc = std::max(4.0 * L_d, L_d + 10.0);
  if (traj.closed) max_arc = std::min(max_arc, traj.length);
  if (distance(a, rear_axle) < L_d) {
    auto i = static_cast<std::size_t>(std::floor(s0 / step)) + 1;
    std::size_t at = i % n;  // i mod n, counted on with i
    for (; s_a - s0 < max_arc; ++i, at = at + 1 == n ? 0 : at + 1) {
      if (!traj.closed && i >= n) break;  // the end of an open trajectory
      const Vec2 b = traj.points[at].position();
      const double s_b = static_cast<double>(i) * step;  // unwrapped
      if (distance(b, rear_axle) >= L_d) {
        // |a + t (b - a) - c| = L_d: one root in (0, 1], since a is inside the
        // circle and b is not: d.d t^2 + 2 (d.(a - c)) t + |a - c|^2 - L_d^2 = 0
        const Vec2 d = b - a;
        const Vec2 ac = a - rear_axle;
        const double qa = squared_norm(d);
        const double qb = dot(d, ac);
        const double qc = squared_norm(ac) - L_d * L_d;
        const double t = qa > 0.0 ? std::clamp((-qb + std::sqrt(qb * qb - qa * qc)) / qa, 0.0, 1.0)
                                  : 1.0;
        out.s = traj.wrap(s_a + t * (s_b - s_a));
        out.point = a + d * t;
        out.found = true;
        break;
      }
      a = b;
      s_a = s_b;
    }
  }
  // fall back to the point L_d ahead in arc length
  if (!out.found) {
    out.s = traj.wrap(s0 + L_d);
    out.point = traj.at(out.s).position();
  }
  out.distance = distance(out.point, rear_axle);
  out.curvature = traj.at(out.s).curvature;
  return out;
}

}  // namespace paddock::control
