#pragma once
// longitudinal control (paper section "Control", "Longitudinal Control"): a PI
// speed controller with anti-windup and a model feedforward. The paper's car
// ran a P controller and names the integral term as the fix for its
// steady-state errors; here it is.
//
// The loop works in acceleration: the demand
//   a_cmd = kp e + I,   e = v_ref - v,   I = integral of ki e dt
// (conditional integration for anti-windup, see longitudinal.cc)
// becomes a force with the feedforward of the reference acceleration and the
// resistances,
//   F = m a_cmd + g_ff (m a_ref + c_drag v^2 + F_roll),
// and the force becomes a pedal: u = F / F_drive,max(v) when F > 0 (throttle;
// F_drive,max(v) = min(F_drive,max, P_drive,max / v), the motor's envelope),
// u = F / F_brake,max when F < 0 (brake), each clamped to [0, 1]. Gains in
// acceleration units keep their meaning when the car's mass or motor changes,
// and the separate force scales are the separate throttle and brake gains.
#include <algorithm>

#include "autonomy/common/params.h"

namespace paddock::control {

struct LongitudinalParams {
  // a 1 m/s error asks 2 m/s^2; time constant 0.5 s
  double kp = 2.0;
  // integrates model errors out in a few seconds
  double ki = 0.5;
  double integral_limit = 2.0;
  // the integrator is there for the small steady-state errors of a wrong
  // model, not for the big transients of a launch or a braking zone, which
  // kp and the feedforward handle
  double integral_band = 1.0;
  double feedforward_gain = 1.0;
  // for actuator lag
  double speed_preview_time = 0.2;
  double stop_speed = 0.1;

  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(kp), {"1/s", params::in(0.0, 100.0), "speed loop proportional gain (acceleration per speed error)"});
    v(PADDOCK_PARAM(ki), {"1/s^2", params::in(0.0, 100.0), "speed loop integral gain"});
    v(PADDOCK_PARAM(integral_limit), {"m/s^2", params::in(0.0, 100.0), "bound of the integral term |I|"});
    v(PADDOCK_PARAM(integral_band), {"m/s", params::above(0.0), "the integrator runs only while the speed error is below this"});
    v(PADDOCK_PARAM(feedforward_gain), {"", params::in(0.0, 2.0), "scale of the model feedforward (0: off)"});
    v(PADDOCK_PARAM(speed_preview_time), {"s", params::in(0.0, 5.0), "the reference speed is read this far ahead"});
    v(PADDOCK_PARAM(stop_speed), {"m/s", params::at_least(0.0), "at a reference of 0 and a speed below this, hold full brake"});
  }
};

// what the speed loop knows of the car
struct SpeedModel {
  double mass = 190.0;                // kg
  double drag_coefficient = 0.7;      // F_drag = c v^2 (N s^2/m^2)
  double rolling_resistance = 180.0;  // constant resistance while moving (N)
  double max_drive_force = 5000.0;    // force at throttle 1 below the base speed (N)
  double max_drive_power = 1e12;      // power at throttle 1 above it (W): the force is min(F, P / v)
  double max_brake_force = 3000.0;    // force at brake 1 (N)
};

struct LongitudinalCommand {
  double throttle = 0.0;      // [0, 1]
  double brake = 1.0;         // [0, 1]
  double accel_demand = 0.0;  // feedback part a_cmd = kp e + I (m/s^2)
  double force_demand = 0.0;  // F before the pedal map and its saturation (N)
  bool holding = false;       // standstill hold at a zero reference
};

// the PI state: the integrator, nothing else
class SpeedController {
 public:
  // one step: v_ref (m/s), a_ref (m/s^2, feedforward), v measured (m/s), dt (s)
  LongitudinalCommand update(double v_ref, double a_ref, double v, double dt,
                             const LongitudinalParams& p, const SpeedModel& m);
  void reset() { integral_ = 0.0; }
  // a stop: what the integrator learned of the car's losses while driving
  // (drive held against cornering drag) must not hold the car against it
  void release_drive() { integral_ = std::min(integral_, 0.0); }
  double integral() const { return integral_; }  // I (m/s^2)

 private:
  double integral_ = 0.0;
};

}  // namespace paddock::control
