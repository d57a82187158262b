#include "autonomy/control/longitudinal.h"

#include <algorithm>
#include <cmath>

namespace paddock::control {

namespace {

// the signed pedal of a force demand at speed v: > 0 throttle (of the
// motor's envelope at v), < 0 brake, unclamped
double pedal(double force, double v, const SpeedModel& m) {
  if (force < 0.0) return force / m.max_brake_force;
  const double drive = v > 0.0 ? std::min(m.max_drive_force, m.max_drive_power / v) : m.max_drive_force;
  return force / drive;
}

}  // namespace

LongitudinalCommand SpeedController::update(double v_ref, double a_ref, double v, double dt,
                                            const LongitudinalParams& p, const SpeedModel& m) {
  LongitudinalCommand out;

  // standstill hold: a zero reference and (almost) no speed -> full brake, and
  // the integrator forgets what it learned while driving
  if (v_ref <= 0.0 && v < p.stop_speed) {
    integral_ = 0.0;
    out.brake = 1.0;
    out.holding = true;
    return out;
  }
  if (v_ref <= 0.0) release_drive();

  // model feedforward: the force that would hold the reference acceleration
  // against the drag (of the measured speed) and the rolling resistance
  const double vp = std::max(v, 0.0);
  const double f_ff =
      p.feedforward_gain * (m.mass * a_ref + m.drag_coefficient * vp * vp + m.rolling_resistance);

  // anti-windup by conditional integration: the integrator stands still
  //  - while the pedal is saturated and the error would push it further into
  //    saturation (full throttle and still too slow, full brake and still too
  //    fast): unlike a clamp alone it does not fill up during a long launch or
  //    braking zone, so nothing has to unwind when the speed arrives;
  //  - while the error is outside the band |e| < integral_band: a large
  //    transient the pedal can follow would otherwise also fill it (the PI
  //    zero), and the speed would then overshoot and creep back for seconds.
  // The clamp |I| <= integral_limit still bounds what it can learn.
  const double e = v_ref - v;
  const double u_before = pedal(f_ff + m.mass * (p.kp * e + integral_), v, m);
  const bool pushes_high = u_before >= 1.0 && e > 0.0;
  const bool pushes_low = u_before <= -1.0 && e < 0.0;
  const bool in_band = std::abs(e) < p.integral_band;
  if (dt > 0.0 && in_band && !pushes_high && !pushes_low) {
    integral_ = std::clamp(integral_ + p.ki * e * dt, -p.integral_limit, p.integral_limit);
  }

  // feedback plus feedforward, then the pedal map
  out.accel_demand = p.kp * e + integral_;
  out.force_demand = f_ff + m.mass * out.accel_demand;
  const double u = pedal(out.force_demand, v, m);
  out.throttle = std::clamp(u, 0.0, 1.0);
  out.brake = std::clamp(-u, 0.0, 1.0);
  return out;
}

}  // namespace paddock::control
