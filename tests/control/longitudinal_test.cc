// the PI speed loop on a first-order plant dv/dt = a u - d.
#include "autonomy/control/longitudinal.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace paddock::control {
namespace {

// a model that turns the pedal into the plant's own units: with mass 1 and
// both force limits equal to a, u = a_cmd / a, so dv/dt = a u = a_cmd while unsaturated
SpeedModel unit_model(double a) {
  SpeedModel m;
  m.mass = 1.0;
  m.drag_coefficient = 0.0;
  m.rolling_resistance = 0.0;
  m.max_drive_force = a;
  m.max_brake_force = a;
  return m;
}

struct PlantRun {
  double v_end = 0.0;
  double v_max = 0.0;
  double integral_at_saturation_end = 0.0;
  double saturation_time = 0.0;
};

// dv/dt = a (throttle - brake) - d, at 100 Hz for `seconds`
PlantRun simulate(SpeedController& pi, const LongitudinalParams& p, double a, double d, double v_ref,
             double seconds) {
  const SpeedModel m = unit_model(a);
  const double dt = 0.01;
  double v = 0.0;
  PlantRun r;
  bool saturated = true;
  const int steps = static_cast<int>(std::lround(seconds / dt));
  for (int k = 0; k < steps; ++k) {
    const LongitudinalCommand c = pi.update(v_ref, 0.0, v, dt, p, m);
    if (saturated && c.throttle < 1.0) {
      saturated = false;
      r.integral_at_saturation_end = pi.integral();
      r.saturation_time = k * dt;
    }
    v += dt * (a * (c.throttle - c.brake) - d);
    r.v_max = std::max(r.v_max, v);
  }
  r.v_end = v;
  return r;
}

TEST(SpeedController, ProportionalAloneLeavesASteadyStateError) {
  // the check that the next test means something: P on a plant with a
  // constant resistance d settles at e = d / kp
  LongitudinalParams p;
  p.ki = 0.0;
  SpeedController pi;
  const PlantRun r = simulate(pi, p, 5.0, 1.0, 10.0, 30.0);
  EXPECT_NEAR(10.0 - r.v_end, 1.0 / p.kp, 1e-3);
}

TEST(SpeedController, IntegralRemovesTheSteadyStateError) {
  LongitudinalParams p;  // defaults: kp 2, ki 0.5
  SpeedController pi;
  const PlantRun r = simulate(pi, p, 5.0, 1.0, 10.0, 40.0);
  EXPECT_NEAR(r.v_end, 10.0, 1e-3);
  EXPECT_NEAR(pi.integral(), 1.0, 1e-3);  // it learned the resistance
}

TEST(SpeedController, AntiWindupKeepsTheOvershootSmall) {
  // a weak plant (2 m/s^2) asked for 20 m/s: ~9.5 s at full throttle. Without
  // anti-windup the integrator would fill to its limit (2 m/s^2) and the speed
  // overshoot by ~1 m/s as it unwinds; with conditional integration it stays
  // at 0 through the saturation, and the linear PI that follows overshoots
  // by 0.081 m/s (e'' + kp e' + ki e = 0 from e = 1 m/s, e' = -2 m/s^2).
  // The error band is opened wide so that the saturation rule alone is tested.
  LongitudinalParams p;
  p.integral_band = std::numeric_limits<double>::infinity();
  SpeedController pi;
  const PlantRun r = simulate(pi, p, 2.0, 0.0, 20.0, 40.0);
  EXPECT_GT(r.saturation_time, 9.0);
  EXPECT_NEAR(r.integral_at_saturation_end, 0.0, 0.01);
  EXPECT_LT(r.v_max - 20.0, 0.12);
  EXPECT_NEAR(r.v_end, 20.0, 1e-3);
}

TEST(SpeedController, BigStepInsideThePedalRangeDoesNotOvershoot) {
  // a strong plant (30 m/s^2) asked for 10 m/s: the pedal never saturates
  // (kp e = 20 m/s^2 at most), but outside |e| < integral_band the
  // integrator stands still: the overshoot is 0.083 m/s, against 0.81 m/s
  // when it integrates the whole step
  LongitudinalParams p;
  SpeedController pi;
  const PlantRun r = simulate(pi, p, 30.0, 0.0, 10.0, 20.0);
  EXPECT_LT(r.v_max - 10.0, 0.1);
  EXPECT_NEAR(r.v_end, 10.0, 1e-3);
}

TEST(SpeedController, IntegralRespectsItsLimit) {
  // a resistance larger than the plant can beat: full throttle forever, and
  // the integrator neither winds past its limit nor grows while saturated
  LongitudinalParams p;
  p.integral_limit = 0.5;
  SpeedController pi;
  simulate(pi, p, 2.0, 3.0, 10.0, 20.0);
  EXPECT_LE(std::abs(pi.integral()), 0.5);
}

TEST(SpeedController, BrakesWhenTooFast) {
  LongitudinalParams p;
  SpeedController pi;
  const LongitudinalCommand c = pi.update(5.0, 0.0, 10.0, 0.01, p, SpeedModel{});
  EXPECT_EQ(c.throttle, 0.0);
  EXPECT_GT(c.brake, 0.0);
  EXPECT_LE(c.brake, 1.0);
}

TEST(SpeedController, HoldsFullBrakeAtStandstill) {
  LongitudinalParams p;
  SpeedController pi;
  pi.update(10.0, 0.0, 5.0, 0.01, p, SpeedModel{});  // some integral
  const LongitudinalCommand c = pi.update(0.0, 0.0, 0.05, 0.01, p, SpeedModel{});
  EXPECT_TRUE(c.holding);
  EXPECT_EQ(c.throttle, 0.0);
  EXPECT_EQ(c.brake, 1.0);
  EXPECT_EQ(pi.integral(), 0.0);
  // still rolling at a zero reference: brake, but not the hold
  const LongitudinalCommand rolling = pi.update(0.0, 0.0, 2.0, 0.01, p, SpeedModel{});
  EXPECT_FALSE(rolling.holding);
  EXPECT_GT(rolling.brake, 0.0);
}

TEST(SpeedController, FeedforwardCoversDragRollingAndAcceleration) {
  // no feedback: the pedal is the model's force over the force limits
  LongitudinalParams p;
  p.kp = 0.0;
  p.ki = 0.0;
  SpeedController pi;
  const SpeedModel m;  // gotthard: 190 kg, 0.7 v^2, 180 N, 5000 N drive, 3000 N brake
  const LongitudinalCommand cruise = pi.update(10.0, 0.0, 10.0, 0.01, p, m);
  EXPECT_NEAR(cruise.throttle, (0.7 * 100.0 + 180.0) / 5000.0, 1e-12);
  EXPECT_EQ(cruise.brake, 0.0);
  const LongitudinalCommand accel = pi.update(10.0, 5.0, 10.0, 0.01, p, m);
  EXPECT_NEAR(accel.throttle, (190.0 * 5.0 + 250.0) / 5000.0, 1e-12);
  const LongitudinalCommand decel = pi.update(10.0, -10.0, 10.0, 0.01, p, m);
  EXPECT_NEAR(decel.brake, (1900.0 - 250.0) / 3000.0, 1e-12);
  // a gain of 0 switches it off
  p.feedforward_gain = 0.0;
  const LongitudinalCommand off = pi.update(10.0, 5.0, 10.0, 0.01, p, m);
  EXPECT_EQ(off.throttle, 0.0);
}

}  // namespace
}  // namespace paddock::control
