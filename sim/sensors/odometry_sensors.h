#pragma once
// the car's odometry sensors: four wheel-speed sensors and a steering-angle
// sensor, each with white noise per sample and quantisation to its
// resolution (the steering sensor also with a calibration offset).
//
// Models (WheelSpeedParams, SteeringSensorParams) + small classes holding
// only their random streams (WheelSpeedSensor, SteeringSensor). No I/O, no
// clock, no global state: measure() is a pure function of the inputs and the
// stream's state.
#include <array>
#include <cstdint>
#include <random>

#include "autonomy/common/params.h"
#include "autonomy/common/time.h"
#include "sim/sensors/gaussian.h"

namespace paddock::sensors {

// every field is the INI key `[wheel_speeds] <field>`
struct WheelSpeedParams {
  // DESIGN.md default rates
  double rate = 100.0;

  // added before the quantisation. 0.05 rad/s (1.2 cm/s at the default
  // 0.231 m rolling radius): the tooth/line spacing errors of the encoder
  // disc, the jitter of the 10 ms counting window and the hub's torsional
  // vibration, a fraction of one count.
  double noise = 0.05;

  // a wheel encoder counts the edges seen in each sample window of 1 / rate;
  // one edge is 2 pi / N rad of wheel for N edges per turn, so the speed
  // comes in steps of 2 pi * rate / N. The default: a 2048-line quadrature
  // encoder on the hub (N = 4 * 2048 = 8192 edges per turn) read at 100 Hz:
  // 2 pi * 100 / 8192 = 0.0767 rad/s (1.8 cm/s of car speed). Keep it in
  // step with `rate` when changing either.
  double resolution = 0.0767;

  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(rate), {"Hz", params::in(1.0, 10000.0), "samples per second"});
    v(PADDOCK_PARAM(noise), {"rad/s", params::in(0.0, 100.0), "white noise std per sample"});
    v(PADDOCK_PARAM(resolution), {"rad/s", params::in(0.0, 100.0), "quantisation step (0: none)"});
  }
};

// one wheel-speed sample
struct WheelSpeedSample {
  TimeNs stamp = 0;
  std::array<double, 4> omega{};  // rad/s, > 0 rolling forward: FL, FR, RL, RR
};

class WheelSpeedSensor {
 public:
  // throws std::invalid_argument when params::validate(params) fails. The seed starts
  // this sensor's own random stream (std::mt19937_64).
  WheelSpeedSensor(const WheelSpeedParams& params, std::uint64_t seed);

  // one sample at `stamp` of the true wheel speeds (rad/s, FL FR RL RR).
  // Each wheel: the noise is added to the speed's magnitude, which is clipped
  // at 0 (the noise never reverses a wheel's direction: an encoder turning
  // forward counts no backward edges), rounded to the nearest multiple of the
  // resolution and given the true sign back. A wheel at rest (true speed
  // exactly 0) reads exactly 0: an encoder that sees no edges counts none.
  // Four normal draws per call whatever the inputs. A NaN speed reads NaN.
  WheelSpeedSample measure(const std::array<double, 4>& true_omega, TimeNs stamp);

  const WheelSpeedParams& params() const { return params_; }
  // the sample period in integer nanoseconds
  TimeNs period_ns() const { return from_seconds(1.0 / params_.rate); }

 private:
  WheelSpeedParams params_;
  std::mt19937_64 rng_;
  Gaussian normal_{0.0, 1.0};
};

// every field is the INI key `[steering_sensor] <field>`. The angle is the
// road-wheel angle, the quantity of the steering command (rad, > 0 left).
struct SteeringSensorParams {
  // the control rate (DESIGN.md default rates)
  double rate = 100.0;

  // 0.5 mrad (0.03 deg) of road-wheel angle: a magnetic absolute encoder's
  // jitter (~0.05 deg rms at the column, divided by the steering ratio) plus
  // the rack's play under vibration.
  double noise = 5e-4;

  // a 12-bit absolute magnetic encoder on the steering column (AS5600 class,
  // 2 pi / 4096 = 1.53 mrad of column) through an FS steering ratio of about
  // 5:1: 2 pi / 4096 / 5 = 0.307 mrad of road wheel.
  double resolution = 3.07e-4;

  // a zero that was set with the wheels not quite straight. Default 0: a
  // calibrated car.
  double offset = 0.0;

  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(rate), {"Hz", params::in(1.0, 10000.0), "samples per second"});
    v(PADDOCK_PARAM(noise), {"rad", params::in(0.0, 1.0), "white noise std per sample"});
    v(PADDOCK_PARAM(resolution), {"rad", params::in(0.0, 1.0), "quantisation step (0: none)"});
    // a zero about a quarter turn of road wheel off is not a calibration
    v(PADDOCK_PARAM(offset), {"rad", params::in(-1.5, 1.5), "calibration offset: the reading is true + offset"});
  }
};

// one steering-angle sample
struct SteeringSample {
  TimeNs stamp = 0;
  double angle = 0.0;  // rad, road-wheel angle, > 0 left
};

class SteeringSensor {
 public:
  // throws std::invalid_argument when params::validate(params) fails. The seed starts
  // this sensor's own random stream (std::mt19937_64).
  SteeringSensor(const SteeringSensorParams& params, std::uint64_t seed);

  // one sample at `stamp`: true_angle + offset + noise, rounded to the nearest
  // multiple of the resolution (an absolute encoder quantises its own reading,
  // offset included). One normal draw per call. A NaN angle reads NaN.
  SteeringSample measure(double true_angle, TimeNs stamp);

  const SteeringSensorParams& params() const { return params_; }
  // the sample period in integer nanoseconds
  TimeNs period_ns() const { return from_seconds(1.0 / params_.rate); }

 private:
  SteeringSensorParams params_;
  std::mt19937_64 rng_;
  Gaussian normal_{0.0, 1.0};
};

}  // namespace paddock::sensors
