#include "sim/runner/vehicle_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>

#include "autonomy/common/format.h"
#include "render/colormap.h"
#include "sim/runner/files.h"
#include "sim/runner/plots.h"

namespace paddock::runner {
namespace {

using vehicle::DriverInput;
using vehicle::VehicleParams;
using vehicle::VehicleState;

constexpr double kDt = 1e-3;                 // s, the physics step of every experiment
constexpr long kStepsPerSecond = 1000;
constexpr double kStoppedSpeed = 0.05;       // m/s: a stop is over below this
constexpr double kStopTimeout = 60.0;        // s: a stop that takes longer did not stop
constexpr double kRunTimeout = 120.0;        // s: the longest acceleration run
constexpr double kTopSpeedChange = 0.01;     // m/s over 1 s: the top speed is reached
constexpr long kWindowFirst = 101, kWindowLast = 300;  // steps: the longitudinal window, t in (0.1, 0.3] s
constexpr double kSkidpadTolerance = 0.25;   // m: the radius the skidpad must hold
constexpr double kGgvStep = 5.0;             // m/s between the g-g-v's speeds
// m/s: the g-g-v's last speed at most (a car without drag never stops accelerating)
constexpr double kGgvMaxSpeed = 100.0;

// the brake pedals tried for the shortest stop: 1.0 down to 0.3 in 0.02 steps
std::vector<double> brake_pedals() {
  std::vector<double> pedals;
  for (int k = 50; k >= 15; --k) pedals.push_back(k / 50.0);
  return pedals;
}

// the car under test: its model, how quickly the circle driver may steer it
// (its gains' share of those tuned for a car answering its steering in
// 60 ms), and the time simulated so far
struct TestCar {
  explicit TestCar(const VehicleParams& params) : p(params), compiled(params) {}
  const VehicleParams& p;
  vehicle::Car compiled;
  double driver_scale = 1.0;
  double simulated = 0.0;  // s
};

// the car on an empty test ground: its state, the clock and the distance its CG travelled
class Drive {
 public:
  Drive(TestCar& car, const VehicleState& s) : car_(car), s_(s) {}
  const VehicleState& state() const { return s_; }
  double t() const { return static_cast<double>(steps_) * kDt; }
  long steps() const { return steps_; }
  double path() const { return path_; }
  double speed() const { return vehicle::speed(s_); }

  // one step; a state that is no longer finite is an error (the step is too long for this car)
  void step(const DriverInput& in) {
    const double x = s_.x, y = s_.y;
    vehicle::step(car_.compiled, s_, in, kDt);
    if (!vehicle::is_finite(s_)) {
      throw UserError("the vehicle model diverged " + fixed(t(), 3) +
                      " s into an experiment (its state is no longer finite)");
    }
    ++steps_;
    car_.simulated += kDt;
    path_ += std::hypot(s_.x - x, s_.y - y);
  }

 private:
  TestCar& car_;
  VehicleState s_;
  long steps_ = 0;
  double path_ = 0.0;
};

// ---- straight line ----

// full throttle from rest: the 75 m time (linear within the step) and the top speed
AccelerationRun full_throttle_from_rest(TestCar& car) {
  Drive d(car, vehicle::initial_state(car.p, Pose2{}));
  AccelerationRun r;
  double speed_a_second_ago = 0.0;
  while (d.t() < kRunTimeout - 0.5 * kDt) {
    const double path0 = d.path(), v0 = d.speed();
    d.step({0.0, 1.0, 0.0});
    if (!r.reached_75m && d.path() >= kAccelerationLength) {
      const double f = (kAccelerationLength - path0) / (d.path() - path0);
      r.reached_75m = true;
      r.time_75m = d.t() - (1.0 - f) * kDt;
      r.speed_75m = v0 + f * (d.speed() - v0);
    }
    if (d.steps() % kStepsPerSecond != 0 || r.top_speed_settled) continue;
    r.top_speed = d.speed();
    r.top_speed_time = d.t();
    r.top_speed_settled = std::abs(d.speed() - speed_a_second_ago) < kTopSpeedChange;
    speed_a_second_ago = d.speed();
    // a car that settles at rest never gets to 75 m
    if (r.top_speed_settled && (r.reached_75m || d.speed() < kStoppedSpeed)) break;
  }
  return r;
}

// a straight stop from v0 at a constant pedal; gives up once past max_distance
BrakingRun stop_from(TestCar& car, double v0, double pedal, double max_distance) {
  Drive d(car, vehicle::rolling_state(car.p, Pose2{}, v0));
  BrakingRun r;
  r.pedal = pedal;
  while (d.t() < kStopTimeout && d.path() <= max_distance) {
    d.step({0.0, 0.0, pedal});
    if (d.speed() < kStoppedSpeed) {
      r.stopped = true;
      break;
    }
  }
  r.distance = d.path();
  r.time = d.t();
  r.mean_deceleration = r.stopped ? v0 * v0 / (2.0 * d.path()) : 0.0;
  return r;
}

// the stop at full brake and at the best constant pedal (the shortest; a
// driver or an ABS modulates): each pedal gives up once longer than the best
std::pair<BrakingRun, BrakingRun> stops_from(TestCar& car, double v0) {
  BrakingRun full, best;
  for (double pedal : brake_pedals()) {
    const double bound = best.stopped ? best.distance : std::numeric_limits<double>::infinity();
    const BrakingRun run = stop_from(car, v0, pedal, bound);
    if (pedal == 1.0) full = best = run;
    // brakes that cannot stop the car in a minute at full pedal: no pedal will
    if (!full.stopped) break;
    if (run.stopped && run.distance < best.distance) best = run;
  }
  return {full, best};
}

// mean ax over (0.1, 0.3] s from rolling_state(v) at constant pedals, while
// the car still rolls (above 0.5 m/s: a stop from 5 m/s can be over by 0.3 s)
double mean_ax(TestCar& car, double v, const DriverInput& in) {
  Drive d(car, vehicle::rolling_state(car.p, Pose2{}, v));
  double sum = 0.0;
  int n = 0;
  while (d.steps() < kWindowLast) {
    d.step(in);
    if (d.steps() >= kWindowFirst && d.speed() > 10.0 * kStoppedSpeed) sum += d.state().ax, ++n;
  }
  return n > 0 ? sum / n : 0.0;
}

// ---- closed loop ----

// holds a speed on the pedals: a PI on throttle whose integral is the
// throttle the speed needs; a negative output brakes
class SpeedPi {
 public:
  DriverInput update(double v, double v_target) {
    const double e = v_target - v;
    integral_ = std::clamp(integral_ + kKi * e * kDt, 0.0, 1.0);
    const double u = kKp * e + integral_;
    return {0.0, std::clamp(u, 0.0, 1.0), std::clamp(-u, 0.0, 1.0)};
  }

 private:
  static constexpr double kKp = 0.5;  // pedal per m/s
  static constexpr double kKi = 1.0;  // pedal per m
  double integral_ = 0.0;
};

// the acceleration of the CG normal to its path (m/s^2, > 0 to the left):
// v^2 / R on a circle, whatever the sideslip
double path_normal_acceleration(const VehicleState& s) {
  const double v = std::max(vehicle::speed(s), 1e-9);
  return (s.vx * s.ay - s.vy * s.ax) / v;
}

// drives counter-clockwise round a circle: the course rate the circle needs
// plus a turn towards a course that closes the radius error (Stanley-like:
// atan(k e / v) inwards), met by a PI on the yaw rate in kinematic steering
// units (wheelbase / v per rad/s); the speed by the SpeedPi. Before it has a
// circle it follows a yaw rate alone (the way in). Its gains are tuned for a
// car whose yaw rate answers a steering step in 60 ms (63 %) and scaled down
// for a slower one (TestCar::driver_scale)
class CircleDriver {
 public:
  explicit CircleDriver(const TestCar& car)
      : wheelbase_(car.p.lf + car.p.lr), steering_max_(car.p.steering_max), scale_(car.driver_scale) {}

  // the circle of `radius` the car is on now: its centre to the left of the course
  void take_circle(const VehicleState& s, double radius) {
    const double course = s.yaw + std::atan2(s.vy, s.vx);
    centre_ = {s.x - radius * std::sin(course), s.y + radius * std::cos(course)};
    radius_ = radius;
    touched_lock_ = false;
  }
  // distance to the centre minus the radius (> 0 outside)
  double radius_error(const VehicleState& s) const { return std::hypot(s.x - centre_.x, s.y - centre_.y) - radius_; }
  // a steering command since take_circle was at the lock
  bool touched_lock() const { return touched_lock_; }

  // on the circle
  DriverInput update(const VehicleState& s, double v_target) {
    const double v = std::max(vehicle::speed(s), 1.0);
    const double dist = std::max(std::hypot(s.x - centre_.x, s.y - centre_.y), 0.1);
    // the course's angle inwards from the tangent
    const double tangent = std::atan2(s.y - centre_.y, s.x - centre_.x) + 0.5 * kPi;
    const double inwards = wrap_angle(s.yaw + std::atan2(s.vy, s.vx) - tangent);
    const double wanted = std::atan(scale_ * kRadiusGain * (dist - radius_) / v);
    return follow_yaw_rate(s, v / dist + scale_ * kCourseGain * (wanted - inwards), v_target);
  }

  // a yaw rate (rad/s) alone
  DriverInput follow_yaw_rate(const VehicleState& s, double r_demand, double v_target) {
    const double per_yaw_rate = wheelbase_ / std::max(vehicle::speed(s), 1.0);
    const double r_error = r_demand - s.r;
    integral_ = std::clamp(integral_ + scale_ * kKi * per_yaw_rate * r_error * kDt, -steering_max_, steering_max_);
    const double steering = integral_ + scale_ * kKp * per_yaw_rate * r_error;
    touched_lock_ = touched_lock_ || std::abs(steering) >= steering_max_;
    DriverInput in = speed_.update(vehicle::speed(s), v_target);
    in.steering_angle = std::clamp(steering, -steering_max_, steering_max_);
    return in;
  }

 private:
  static constexpr double kRadiusGain = 0.5;  // 1/s: the radius error closes at about this rate
  static constexpr double kCourseGain = 3.0;  // 1/s: the course error closes at about this rate
  static constexpr double kKp = 1.5;          // yaw-rate loop, proportional
  static constexpr double kKi = 20.0;         // 1/s, yaw-rate loop, integral
  double wheelbase_, steering_max_, scale_;
  Vec2 centre_;
  double radius_ = 1.0;
  double integral_ = 0.0;   // rad, the steering the yaw rate needs
  bool touched_lock_ = false;
  SpeedPi speed_;
};

// the circle driver's gains for this car: min(1, 60 ms / the time its yaw
// rate takes to reach 63 % of its new value after a small steering step at
// 10 m/s, the speed held)
double driver_scale(TestCar& car) {
  Drive d(car, vehicle::rolling_state(car.p, Pose2{}, 10.0));
  SpeedPi pi;
  const double steer = std::min(0.01, 0.2 * car.p.steering_max);
  std::vector<double> r;
  while (d.steps() < 2 * kStepsPerSecond) {
    DriverInput in = pi.update(d.speed(), 10.0);
    in.steering_angle = steer;
    d.step(in);
    r.push_back(d.state().r);
  }
  if (!(r.back() > 0.0)) return 1.0;
  const auto reached = std::find_if(r.begin(), r.end(), [&](double x) { return x >= 0.632 * r.back(); });
  const double t63 = static_cast<double>(reached - r.begin() + 1) * kDt;
  return std::min(1.0, 0.06 / t63);
}

// how a circle went: held (within 0.25 m of the radius and within 2 % of
// the speed for the 10 s) or what lost it first
struct CircleRun {
  bool held = false;
  double radius_error_max = 0.0;  // m, over the 10 s
  double lateral = 0.0;           // m/s^2, the mean path-normal acceleration over the 10 s
  std::string lost_by;            // "speed", "spin", "steering lock" or "grip" (ran wide)
};

std::string lost_by(const CircleDriver& driver, const VehicleState& s, double v) {
  if (vehicle::speed(s) < 0.98 * v) return "speed";
  if (std::abs(std::atan2(s.vy, s.vx)) > 0.35) return "spin";
  return driver.touched_lock() ? "steering lock" : "grip";
}

// drives a circle of `radius` at speed v: from rolling_state(v), the yaw
// rate raised to v / radius in 2 s and held 1 s; then on the circle the car
// is on, 3 s to settle and 10 s that must keep within 0.25 m of the radius
// and 2 % of v
CircleRun drive_circle(TestCar& car, double v, double radius) {
  Drive d(car, vehicle::rolling_state(car.p, Pose2{}, v));
  CircleDriver driver(car);
  const long ramp = 2 * kStepsPerSecond, enter = 3 * kStepsPerSecond, settle = 3 * kStepsPerSecond;
  const long hold = 10 * kStepsPerSecond;
  while (d.steps() < enter) {
    const double f = std::min(1.0, static_cast<double>(d.steps() + 1) / static_cast<double>(ramp));
    d.step(driver.follow_yaw_rate(d.state(), f * v / radius, v));
  }
  driver.take_circle(d.state(), radius);
  CircleRun run;
  while (d.steps() < enter + settle + hold) {
    d.step(driver.update(d.state(), v));
    const double e = std::abs(driver.radius_error(d.state()));
    const bool holding = d.steps() > enter + settle;
    if (holding) run.radius_error_max = std::max(run.radius_error_max, e);
    if (e > 2.0 || (holding && (e > kSkidpadTolerance || d.speed() < 0.98 * v))) {
      run.lost_by = lost_by(driver, d.state(), v);
      return run;
    }
    if (holding) run.lateral += std::abs(path_normal_acceleration(d.state())) / static_cast<double>(hold);
  }
  run.held = true;
  return run;
}

// the largest x the car holds (held(x) true, taken as monotone): up from
// x0 by the factor `grow` until held fails or x passes x_max, then bisected
// until the bracket is within tol; 0 when x0 is not held
template <class Held>
double largest_held(double x0, double grow, double x_max, double tol, Held held) {
  if (!held(x0)) return 0.0;
  double lo = x0, hi = x0 * grow;
  for (; hi <= x_max; lo = hi, hi *= grow) {
    if (!held(hi)) break;
  }
  if (hi > x_max) return lo;
  while (hi - lo > tol) {
    const double mid = 0.5 * (lo + hi);
    (held(mid) ? lo : hi) = mid;
  }
  return lo;
}

// the highest speed the skidpad circle is held at: doubling from 4 m/s
// until it is lost, then bisection to 0.01 m/s
SkidpadRun skidpad_limit(TestCar& car) {
  SkidpadRun r;
  CircleRun best;
  r.speed = largest_held(4.0, 2.0, 64.0, 0.01, [&](double v) {
    const CircleRun run = drive_circle(car, v, kSkidpadRadius);
    if (run.held) best = run;
    return run.held;
  });
  r.held = r.speed > 0.0;
  if (!r.held) return r;
  r.lap_time = 2.0 * kPi * kSkidpadRadius / r.speed;
  r.lateral = r.speed * r.speed / kSkidpadRadius;
  r.radius_error_max = best.radius_error_max;
  return r;
}

// the largest steady lateral acceleration at speed v: circles of radius v^2
// / a, a up from `guess` (m/s^2; the last speed's figure, 0 for none) until
// one is lost, then bisected to 0.5 %; the lateral is the tightest circle's
// measured mean, its limit what lost the next circle. A guess that is not
// held starts again from 2 m/s^2
GgvRow lateral_limit(TestCar& car, double v, double guess) {
  GgvRow row;
  row.speed = v;
  double tightest = 0.0, lost_at = std::numeric_limits<double>::infinity();
  const auto held = [&](double a) {
    const CircleRun run = drive_circle(car, v, v * v / a);
    if (run.held && a > tightest) tightest = a, row.lateral = run.lateral;
    if (!run.held && a < lost_at) lost_at = a, row.lateral_limit = run.lost_by;
    return run.held;
  };
  const double tol = 0.005 * (guess > 0.0 ? guess : 10.0);
  if (guess <= 0.0 || largest_held(0.8 * guess, 1.25, 1000.0, tol, held) == 0.0) {
    largest_held(2.0, 2.0, 1000.0, tol, held);
  }
  if (row.lateral_limit.empty()) row.lateral_limit = "none";
  return row;
}

// one speed of the g-g-v: lateral, full throttle, and the best constant brake pedal
GgvRow ggv_row(TestCar& car, double v, double lateral_guess) {
  GgvRow row = lateral_limit(car, v, lateral_guess);
  row.acceleration = std::max(0.0, mean_ax(car, v, {0.0, 1.0, 0.0}));
  for (double pedal : brake_pedals()) {
    const double braking = -mean_ax(car, v, {0.0, 0.0, pedal});
    if (braking > row.braking) row.braking = braking, row.braking_pedal = pedal;
  }
  return row;
}

// the g-g-v from kGgvStep to the top speed
std::vector<GgvRow> ggv_rows(TestCar& car, double top_speed) {
  std::vector<GgvRow> rows;
  const double v_max = std::min(top_speed, kGgvMaxSpeed) + 1e-9;
  for (double v = kGgvStep; v <= v_max; v += kGgvStep) rows.push_back(ggv_row(car, v, rows.empty() ? 0.0 : rows.back().lateral));
  return rows;
}

}  // namespace

VehicleReport vehicle_report(const VehicleParams& p, const std::string& source) {
  VehicleReport r;
  r.source = source;
  TestCar car(p);
  r.acceleration = full_throttle_from_rest(car);
  std::tie(r.full_brake, r.best_brake) = stops_from(car, kBrakingSpeed);
  car.driver_scale = driver_scale(car);
  r.skidpad = skidpad_limit(car);
  r.ggv = ggv_rows(car, r.acceleration.top_speed);
  r.simulated_time = car.simulated;
  return r;
}

GgvMeasurement measure_ggv(const VehicleParams& p) {
  GgvMeasurement m;
  TestCar car(p);
  const AccelerationRun a = full_throttle_from_rest(car);
  m.top_speed = a.top_speed;
  car.driver_scale = driver_scale(car);
  m.rows = ggv_rows(car, a.top_speed);
  m.simulated_time = car.simulated;
  return m;
}

planning::VelocityProfileParams ggv_envelope(const std::vector<GgvRow>& rows, double top_speed) {
  planning::VelocityProfileParams e;
  e.limits = planning::VelocityProfileParams::Ggv;
  e.margin_lateral = 1.0;
  e.margin_longitudinal = 1.0;
  e.turn_accel_scale = 1.0;
  e.v_max = std::max(top_speed, 0.1);
  if (rows.empty()) {
    // a car that never reaches the first speed: its constant defaults say nothing; keep them
    return e;
  }
  // the grip line ay = a + b v^2 (downforce grows with v^2) through the
  // grip-limited rows, by least squares; one row: flat
  double s0 = 0, s1 = 0, s2 = 0, t0 = 0, t1 = 0;
  int grip = 0;
  for (const GgvRow& r : rows) {
    if (r.lateral_limit != "grip") continue;
    const double x = r.speed * r.speed;
    s0 += 1, s1 += x, s2 += x * x, t0 += r.lateral, t1 += x * r.lateral;
    ++grip;
  }
  double a = 0.0, b = 0.0;
  if (grip >= 2 && s0 * s2 - s1 * s1 > 0.0) {
    b = (s0 * t1 - s1 * t0) / (s0 * s2 - s1 * s1);
    a = (t0 - b * s1) / s0;
  } else if (grip == 1) {
    a = t0;
  }
  const auto lateral = [&](const GgvRow& r) {
    // a row bounded by the steering lock says how tight the car turns, not
    // how hard it grips: the grip line's value there (the lock is a limit of
    // the path's curvature, not of its speed)
    if (r.lateral_limit == "steering lock" && grip > 0) return std::max(r.lateral, a + b * r.speed * r.speed);
    return r.lateral;
  };
  // from rest: the first row's values, the grip line's at 0
  e.ggv_speed = {0.0};
  e.ggv_lateral = {grip > 0 ? a : rows.front().lateral};
  e.ggv_accel = {rows.front().acceleration};
  e.ggv_brake = {rows.front().braking};
  for (const GgvRow& r : rows) {
    e.ggv_speed.push_back(r.speed);
    e.ggv_lateral.push_back(lateral(r));
    e.ggv_accel.push_back(r.acceleration);
    e.ggv_brake.push_back(r.braking);
  }
  // the top speed: no acceleration left
  if (top_speed > e.ggv_speed.back() + 0.1) {
    e.ggv_speed.push_back(top_speed);
    e.ggv_lateral.push_back(e.ggv_lateral.back());
    e.ggv_accel.push_back(0.0);
    e.ggv_brake.push_back(e.ggv_brake.back());
  }
  return e;
}

std::string ggv_ini(const planning::VelocityProfileParams& e) {
  const auto list = [](const std::vector<double>& v) {
    std::string t;
    for (double x : v) t += (t.empty() ? "" : ", ") + fixed(x, 2);
    return t;
  };
  return "[planning.reference.profile]\nlimits = ggv\nggv_speed = " + list(e.ggv_speed) +
         "\nggv_lateral = " + list(e.ggv_lateral) + "\nggv_accel = " + list(e.ggv_accel) +
         "\nggv_brake = " + list(e.ggv_brake) + "\n";
}

namespace {


std::string in_g(double a) { return fixed(a / kGravity, 2); }

std::string stop_text(const BrakingRun& b) {
  if (!b.stopped) return "not at rest after " + fixed(b.time, 0) + " s (" + fixed(b.distance, 1) + " m)";
  return fixed(b.distance, 2) + " m in " + fixed(b.time, 2) + " s, mean " + in_g(b.mean_deceleration) + " g (" +
         fixed(b.mean_deceleration, 2) + " m/s^2)";
}

std::string ggv_text(const std::vector<GgvRow>& rows) {
  std::ostringstream o;
  o << "  g-g-v       steady lateral; full throttle and the best brake pedal, mean over 0.1-0.3 s\n";
  o << "    v [m/s]   lateral [g] [m/s^2]  limit          accel [g] [m/s^2]   brake [g] [m/s^2] pedal\n";
  if (rows.empty()) o << "    (the car does not reach " << fixed(kGgvStep, 0) << " m/s)\n";
  for (const GgvRow& g : rows) {
    char buf[200];
    std::snprintf(buf, sizeof buf, "    %6.1f   %9.2f %8.2f  %-13s  %9.2f %8.2f   %9.2f %8.2f  %4.2f\n", g.speed,
                  g.lateral / kGravity, g.lateral, g.lateral_limit.c_str(), g.acceleration / kGravity, g.acceleration,
                  g.braking / kGravity, g.braking, g.braking_pedal);
    o << buf;
  }
  return o.str();
}

}  // namespace

std::string vehicle_report_text(const VehicleReport& r) {
  std::ostringstream o;
  const AccelerationRun& a = r.acceleration;
  o << "vehicle report: " << r.source << " (closed-loop experiments on the model, 1 ms steps)\n";
  o << "  0-75 m      ";
  if (a.reached_75m) {
    o << fixed(a.time_75m, 3) << " s, " << fixed(a.speed_75m, 2) << " m/s (" << fixed(a.speed_75m * 3.6, 1)
      << " km/h) at 75 m\n";
  } else {
    o << "not reached" << (a.top_speed < kStoppedSpeed ? " (the car does not move)" : " in " + fixed(kRunTimeout, 0) + " s")
      << "\n";
  }
  o << "  top speed   " << fixed(a.top_speed * 3.6, 1) << " km/h (" << fixed(a.top_speed, 2) << " m/s)"
    << (a.top_speed_settled ? ", settled at " : ", still rising at ") << fixed(a.top_speed_time, 0) << " s\n";
  o << "  braking     from " << fixed(kBrakingSpeed * 3.6, 0) << " km/h (" << fixed(kBrakingSpeed, 2)
    << " m/s) to rest\n";
  o << "    full brake      " << stop_text(r.full_brake) << "\n";
  o << "    best pedal " << fixed(r.best_brake.pedal, 2) << " " << stop_text(r.best_brake) << "\n";
  const SkidpadRun& k = r.skidpad;
  o << "  skidpad     R = " << fixed(kSkidpadRadius, 3) << " m: ";
  if (k.held) {
    o << "held up to " << fixed(k.speed, 2) << " m/s (" << fixed(k.speed * 3.6, 1) << " km/h), " << in_g(k.lateral)
      << " g (" << fixed(k.lateral, 2) << " m/s^2), lap " << fixed(k.lap_time, 3) << " s (radius within "
      << fixed(k.radius_error_max, 3) << " m)\n";
  } else {
    o << "not held even at 4 m/s\n";
  }
  o << ggv_text(r.ggv);
  o << "  for the stack: its planned envelope (limits = ggv) as measured here, with margins of its own\n";
  std::istringstream lines(ggv_ini(ggv_envelope(r.ggv, a.top_speed)));
  for (std::string line; std::getline(lines, line);) o << "    " << line << "\n";
  return o.str();
}

std::string vehicle_report_json(const VehicleReport& r) {
  using Json = nlohmann::ordered_json;
  const auto g = [](double a) { return a / kGravity; };
  // a figure that was not measured (not reached, not held, not stopped) is null
  const auto when = [](bool measured, double v) { return measured ? Json(v) : Json(nullptr); };
  const auto stop = [&](const BrakingRun& b) {
    return Json{{"pedal", b.pedal},
                {"stopped", b.stopped},
                {"distance", b.distance},
                {"time", b.time},
                {"mean_deceleration", when(b.stopped, b.mean_deceleration)},
                {"mean_deceleration_g", when(b.stopped, g(b.mean_deceleration))}};
  };
  const AccelerationRun& a = r.acceleration;
  const SkidpadRun& k = r.skidpad;
  Json ggv = Json::array();
  for (const GgvRow& row : r.ggv) {
    ggv.push_back({{"speed", row.speed}, {"lateral", row.lateral}, {"lateral_g", g(row.lateral)},
                   {"lateral_limit", row.lateral_limit}, {"acceleration", row.acceleration},
                   {"acceleration_g", g(row.acceleration)}, {"braking", row.braking}, {"braking_g", g(row.braking)},
                   {"braking_pedal", row.braking_pedal}});
  }
  const Json j = {
      {"vehicle", r.source},
      {"dt", kDt},
      {"acceleration_75m",
       {{"reached", a.reached_75m},
        {"time", when(a.reached_75m, a.time_75m)},
        {"speed", when(a.reached_75m, a.speed_75m)}}},
      {"top_speed", {{"speed", a.top_speed}, {"speed_kmh", a.top_speed * 3.6}, {"time", a.top_speed_time},
                     {"settled", a.top_speed_settled}}},
      {"braking",
       {{"initial_speed", kBrakingSpeed}, {"full_brake", stop(r.full_brake)}, {"best_pedal", stop(r.best_brake)}}},
      {"skidpad",
       {{"radius", kSkidpadRadius},
        {"held", k.held},
        {"speed", when(k.held, k.speed)},
        {"lateral", when(k.held, k.lateral)},
        {"lateral_g", when(k.held, g(k.lateral))},
        {"lap_time", when(k.held, k.lap_time)},
        {"radius_error_max", when(k.held, k.radius_error_max)}}},
      {"ggv", ggv},
      {"simulated_time", r.simulated_time}};
  return j.dump(2) + "\n";
}

render::LineChartData ggv_chart(const VehicleReport& r) {
  render::LineChartData c;
  c.title = "g-g-v envelope: " + r.source;
  c.x_label = "speed [m/s]";
  c.y_label = "acceleration [g]";
  render::LineSeries lateral{"max lateral (steady)", {}, {}, render::kTabBlue, render::Marker::Circle};
  render::LineSeries accel{"max acceleration", {}, {}, render::kTabGreen, render::Marker::Triangle};
  render::LineSeries brake{"max braking", {}, {}, render::kTabRed, render::Marker::Square};
  for (const GgvRow& row : r.ggv) {
    for (auto* s : {&lateral, &accel, &brake}) s->x.push_back(row.speed);
    lateral.y.push_back(row.lateral / kGravity);
    accel.y.push_back(row.acceleration / kGravity);
    brake.y.push_back(row.braking / kGravity);
  }
  c.series = {lateral, accel, brake};
  return c;
}

std::vector<std::string> write_vehicle_report(const VehicleReport& r, const std::string& dir, const PlotOptions& o) {
  const std::vector<std::uint8_t> font = read_font(o);
  const render::FigureStyle style = chart_style(o, font);
  const std::vector<std::string> paths = {dir + "/vehicle_report.json", dir + "/ggv.png"};
  write_file_atomic(paths[0], vehicle_report_json(r));
  write_png(paths[1], render::draw_line_chart(ggv_chart(r), style).image);
  return paths;
}

}  // namespace paddock::runner
