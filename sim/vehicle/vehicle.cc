#include "sim/vehicle/vehicle.h"

#include <algorithm>
#include <cassert>
#include <cmath>

#include "autonomy/common/simd_math.h"
#include "sim/vehicle/tyre_tables.h"

namespace paddock::vehicle {

// ---------------------------------------------------------------------------
// tyre and motor
// ---------------------------------------------------------------------------

namespace {

// a wheel turning slower than this (rad/s) counts as at rest for its friction
// torques (brakes, rolling resistance): they hold it instead of turning it back
constexpr double kRestSpin = 1e-3;
// the low-speed damping of the tyre deflections fades out up to this contact speed (m/s)
constexpr double kLowSpeed = 2.0;
// its damping ratio against a quarter of the car on the tyre's stiffness
constexpr double kLowSpeedDamping = 0.3;
// the largest normalised slip B kappa, B alpha the deflections carry: a sliding
// tyre's deflection stops growing there (2.3x the peak of the gotthard curve,
// g = 0.94 of the peak), so a car that stops sliding keeps only a few cm of it
constexpr double kSlipCap = 4.0;
// the motor torque fades to 0 over this share of the motor speed range
constexpr double kMotorFade = 0.05;
// traction control: the slip ratio's speed floor (m/s; a launch from rest lets
// the wheels slip by kappa* x this), and the band over which the torque is cut
constexpr double kTractionSpeedFloor = 3.0;
constexpr double kTractionBand = 2.0;  // x traction_control_slip
// the brake plausibility check (FS rules EV 2.3): braking (a brake command of
// at least kPlausibilityBrake) with more than 25 % throttle cuts the motor
// torque until the throttle falls below 5 %
constexpr double kPlausibilityBrake = 0.1;
constexpr double kPlausibilityCut = 0.25;
constexpr double kPlausibilityReset = 0.05;
// regeneration fades in between these wheel speeds (m/s): 5 and 10 km/h
constexpr double kRegenOff = 5.0 / 3.6;
constexpr double kRegenFull = 10.0 / 3.6;

inline double sign(double v) { return v > 0.0 ? 1.0 : (v < 0.0 ? -1.0 : 0.0); }

// a wheel's share of the drive torque: the axle's, split equally left and right
double drive_share(const VehicleParams& p, std::size_t i) {
  return 0.5 * (i < 2 ? p.drive_split_front : 1.0 - p.drive_split_front);
}

// a wheel's spin inertia: its own, and a driven wheel's motor and gears
double wheel_inertia_of(const VehicleParams& p, std::size_t i) {
  return p.wheel_inertia + (drive_share(p, i) > 0.0 ? p.driveline_inertia : 0.0);
}

}  // namespace

double load_factor(const VehicleParams& p, double fz) {
  return std::max(0.0, 1.0 + p.tyre_load_sensitivity * (fz / p.tyre_load_nominal - 1.0));
}

namespace {

using simd::D4;

// every lane true
PADDOCK_SIMD_INLINE bool all(simd::M4 m) { return (m[0] & m[1] & m[2] & m[3]) != 0; }

// Pacejka's curve without shifts, g(X) = sin(C atan(X - E (X - atan X))),
// over the normalised slip X, g(X) / X lane by lane at x2 = X^2 (C at 0):
// from the car's table (tables: null for the curve as written), the curve
// as written in a lane beyond the table
PADDOCK_SIMD_INLINE D4 curve_ratio(const VehicleParams& p, const TyreTables* tables, D4 x2) {
  const auto written = [&p, x2] {
    const D4 x = {std::sqrt(x2[0]), std::sqrt(x2[1]), std::sqrt(x2[2]), std::sqrt(x2[3])};
    const D4 g = simd::sin(p.tyre_c * simd::atan(x - p.tyre_e * (x - simd::atan(x))));
    return simd::select(x == 0.0, simd::splat(p.tyre_c), g / x);
  };
  if (!tables) return written();
  const D4 r = tables->curve_ratio(x2);
  const simd::M4 inside = x2 < EvenTable::kMax;
  return all(inside) ? r : simd::select(inside, r, written());
}

// the slip angle atan(t) lane by lane, likewise
PADDOCK_SIMD_INLINE D4 slip_angle(const TyreTables* tables, D4 t) {
  if (!tables) return simd::atan(t);
  const D4 s = t * t;
  const D4 a = t * tables->atan_ratio(s);
  const simd::M4 inside = s < EvenTable::kMax;
  return all(inside) ? a : simd::select(inside, a, simd::atan(t));
}

// four tyres' forces at once (lane i: wheel i), see tyre_force; the load
// factor's lanes out in mu (times fz: the friction the wheel has)
PADDOCK_SIMD_INLINE void tyre_lanes(const VehicleParams& p, const TyreTables* tables, D4 kappa, D4 alpha, D4 fz,
                                    D4& fx, D4& fy, D4& mu) {
  const D4 xs = p.tyre_bx * kappa;
  const D4 ys = p.tyre_b * alpha;
  // load_factor's max(0, .) as std::max(0, v): v unless 0 < v is false
  const D4 lf = 1.0 + p.tyre_load_sensitivity * (fz / p.tyre_load_nominal - 1.0);
  mu = simd::select(0.0 < lf, lf, simd::splat(0.0)) * fz;
  const D4 k = simd::select(fz <= 0.0, simd::splat(0.0), mu * curve_ratio(p, tables, xs * xs + ys * ys));
  fx = p.tyre_dx * k * xs;
  fy = -p.tyre_d * k * ys;
}

}  // namespace

TyreForce tyre_force(const VehicleParams& p, double kappa, double alpha, double fz) {
  D4 fx, fy, mu;
  tyre_lanes(p, nullptr, simd::splat(kappa), simd::splat(alpha), simd::splat(fz), fx, fy, mu);
  return {fx[0], fy[0]};
}

TyreForce tyre_force(const Car& car, double kappa, double alpha, double fz) {
  D4 fx, fy, mu;
  tyre_lanes(car.params(), car.tyres(), simd::splat(kappa), simd::splat(alpha), simd::splat(fz), fx, fy, mu);
  return {fx[0], fy[0]};
}

double tyre_lateral_force(const VehicleParams& p, double alpha, double fz) { return tyre_force(p, 0.0, alpha, fz).fy; }

// the gears are lossless here: eta covers accumulator, inverter, motor and gears
double drive_power_limit(const VehicleParams& p) {
  return std::min(p.motor_power_max, p.drivetrain_efficiency * p.accumulator_power_max);
}

double drive_torque_limit(const VehicleParams& p, double wheel_speed) {
  const double w_max = p.motor_speed_max / p.gear_ratio;
  const double w = std::abs(wheel_speed);
  double t = p.motor_torque_max * p.gear_ratio;
  if (w > 0.0) t = std::min(t, drive_power_limit(p) / w);
  return t * std::clamp((w_max - w) / (kMotorFade * w_max), 0.0, 1.0);
}

double equivalent_mass(const VehicleParams& p) {
  double m = p.mass;
  for (std::size_t i = 0; i < 4; ++i) m += wheel_inertia_of(p, i) / (p.wheel_radius * p.wheel_radius);
  return m;
}

double top_speed(const VehicleParams& p) {
  // the drive force falls and the resistance rises with v: bisect on their difference
  auto surplus = [&](double v) {
    return drive_torque_limit(p, v / p.wheel_radius) / p.wheel_radius - p.c_drag * v * v - p.cr0;
  };
  double lo = 0.0, hi = p.motor_speed_max / p.gear_ratio * p.wheel_radius;
  if (surplus(lo) <= 0.0) return 0.0;
  for (int i = 0; i < 80; ++i) {
    const double mid = 0.5 * (lo + hi);
    (surplus(mid) > 0.0 ? lo : hi) = mid;
  }
  return lo;
}

// ---------------------------------------------------------------------------
// the model
// ---------------------------------------------------------------------------
//
// Chassis: a single-track model at the CG, body frame (x forward, y left),
// yaw rate r, with the tyre forces of the four wheels (Fx_i, Fy_i in the wheel
// frame, the front wheels steered by delta) acting at their contact points
// (x_i, y_i) from the CG. Newton in the rotating body frame:
//   m (vx' - r vy) = sum_i FX_i - c_drag vx |vx|
//   m (vy' + r vx) = sum_i FY_i
//   Iz r'          = sum_i (x_i FY_i - y_i FX_i)
// with (FX_i, FY_i) = R(delta_i) (Fx_i, Fy_i). The pose follows from rotating
// the body velocity: X' = vx cos(yaw) - vy sin(yaw), Y' = vx sin(yaw) + vy cos(yaw).
// Normal loads per wheel: static + aero (per the balance) -+ half the lagged
// longitudinal load transfer m h_cg ax / L per axle (no lateral transfer: a
// single-track model).
//
// Wheels: I_i omega_i' = T_drive_i - Fx_i r - T_friction_i, the friction
// torque (brake + rolling resistance cr0 r / 4) opposing the spin; at rest it
// holds the wheel while the other torques stay below it (static friction),
// decided once per step (see step()).
//
// Tyres: the contact point moves at (v_cx, v_cy) in the wheel frame; the
// deflections follow first-order relaxation (Pacejka, Tyre and Vehicle
// Dynamics, ch. 7):
//   u_x' = (omega r - v_cx) - |v_cx| u_x / sigma_x,  kappa = u_x / sigma_x
//   u_y' = v_cy - |v_cx| u_y / sigma_y,              alpha = atan(u_y / sigma_y)
// In steady state kappa = (omega r - v_cx) / |v_cx| and tan(alpha) = v_cy / |v_cx|,
// the usual slips, in every direction of travel; at low speed the tyre is a
// spring instead of a 0/0, so no kinematic blend is needed. The tyre's stored
// energy E = int F du only falls: dE/dt + (power of the forces on car and
// wheel) = -F |v_cx| u / sigma <= 0, so without drive the kinetic energy never
// grows. Below 2 m/s a damper on the contact's slip velocity (ratio 0.3 of
// critical against a quarter of the car) settles the spring at rest.
//
// Powertrain: the throttle asks its share of the motor torque limit of each
// driven wheel (drive_split_front, equal left/right) plus the torque-vectoring
// shift +-M r / track; each wheel's torque fades at the motor speed limit, the
// brake demand goes first to regeneration (if any), and the sum of the wheel
// powers is capped by the motor and accumulator limits. Electrical power =
// mechanical / eta driving, mechanical x eta regenerating.

namespace {

struct X {
  double px, py, yaw, vx, vy, r, steer, thr, brk, ax_load, energy;
  std::array<double, 4> w, ux, uy;
};

inline X axpy(const X& s, double h, const X& k) {
  X o{s.px + h * k.px,       s.py + h * k.py,       s.yaw + h * k.yaw, s.vx + h * k.vx,   s.vy + h * k.vy,
      s.r + h * k.r,         s.steer + h * k.steer, s.thr + h * k.thr, s.brk + h * k.brk, s.ax_load + h * k.ax_load,
      s.energy + h * k.energy, {}, {}, {}};
  for (std::size_t i = 0; i < 4; ++i) {
    o.w[i] = s.w[i] + h * k.w[i];
    o.ux[i] = s.ux[i] + h * k.ux[i];
    o.uy[i] = s.uy[i] + h * k.uy[i];
  }
  return o;
}

// a state derivative, plus what it implies
struct Deriv {
  X d;
  double ax;     // m/s^2, vx' - r vy
  double ay;     // m/s^2, vy' + r vx
  double power;  // W, electrical
  std::array<double, 4> t_net;   // N m, drive torque - Fx r: what turns the wheel apart from friction
  std::array<double, 4> t_fric;  // N m, the friction torque available (brake + rolling resistance)
};

}  // namespace

// what a car's parameters imply for every step (Car): computed once
struct CarConstants {
  double inv_m, inv_iz;
  double transfer_per_wheel;  // N per m/s^2: m h_cg / L / 2
  std::array<double, 4> x, y;  // contact points from the CG, m
  std::array<double, 4> fz_static, aero_share, inv_fz_static;
  std::array<double, 4> inv_inertia;
  std::array<double, 4> drive_share;  // of the wheel torque limit
  std::array<double, 4> brake_torque;  // N m at full brake
  std::array<double, 4> regen_torque;  // N m available at the wheel
  std::array<double, 4> c_x, c_y;      // N s/m, low-speed damping at the static load
  double rr_torque;                     // N m per wheel
  double radius;
  double t_wheel_max, p_wheel_max, w_max, inv_fade;
  double eta, inv_eta, inv_sigma_x, inv_sigma_y;
  double ux_cap, uy_cap;  // m, the deflections at kSlipCap
};

namespace {

// everything constant over one step: the car's constants, and what the step's
// start decides
struct Model {
  const CarConstants* k;  // the car's constants (not copied: 700 bytes a step)
  const VehicleParams* p;
  const TyreTables* tyres;  // null: the curve as written
  std::array<double, 4> tv_torque;     // N m, torque vectoring shift
  std::array<double, 4> traction;      // traction control's torque factor, held over the step
  std::array<double, 4> friction_sign;  // 0: held at rest; +-1: friction opposes that spin
  double inv_tau_steer, inv_tau_thr, inv_tau_brk, inv_tau_pitch;  // 1/s, 0 = instantaneous (set outside RK4)
  double steer_cmd, thr_cmd, brk_cmd;
};

// first-order lag rate, 0 (= instantaneous, applied outside RK4) when tau < dt/2:
// such a lag is not resolvable at this step and explicit RK4 would go unstable for
// dt / tau > 2.785
inline double lag_rate(double tau, double dt) { return tau < 0.5 * dt ? 0.0 : 1.0 / tau; }

// the motors' torque at each wheel (N m) and the regeneration that replaces
// friction braking, under the motor and power limits; returns the electrical power (W)
double motor_torques(const Model& m, const X& s, std::array<double, 4>& torque, std::array<double, 4>& regen) {
  const double request = s.thr * m.k->t_wheel_max;
  double p_drive = 0.0, p_regen = 0.0;
  for (std::size_t i = 0; i < 4; ++i) {
    regen[i] = 0.0;
    torque[i] = 0.0;
    if (m.k->drive_share[i] == 0.0) continue;
    const double w = s.w[i];
    const double limit = m.k->drive_share[i] * m.k->t_wheel_max * std::clamp((m.k->w_max - std::abs(w)) * m.k->inv_fade, 0.0, 1.0);
    double t = m.k->drive_share[i] * request * m.traction[i] + m.tv_torque[i];
    if (m.k->regen_torque[i] > 0.0 && s.brk > 0.0) {
      const double fade = std::clamp((std::abs(w) * m.k->radius - kRegenOff) * (1.0 / (kRegenFull - kRegenOff)), 0.0, 1.0);
      regen[i] = std::min(m.k->regen_torque[i] * fade, s.brk * m.k->brake_torque[i]);
      t -= regen[i] * sign(w);
    }
    torque[i] = std::clamp(t, -limit, limit);
    const double pw = torque[i] * w;
    (pw > 0.0 ? p_drive : p_regen) += pw;
  }
  const double k_drive = p_drive > m.k->p_wheel_max ? m.k->p_wheel_max / p_drive : 1.0;
  const double k_regen = -p_regen > m.k->p_wheel_max ? m.k->p_wheel_max / -p_regen : 1.0;
  if (k_drive < 1.0 || k_regen < 1.0) {
    for (std::size_t i = 0; i < 4; ++i) {
      const double k = torque[i] * s.w[i] > 0.0 ? k_drive : k_regen;
      torque[i] *= k;
      regen[i] *= k_regen;
    }
  }
  return p_drive * k_drive * m.k->inv_eta + p_regen * k_regen * m.k->eta;
}

// std::min(a, b), std::clamp(v, lo, hi), lane by lane and alike for NaN
PADDOCK_SIMD_INLINE D4 min_lanes(D4 a, D4 b) { return simd::select(b < a, b, a); }
PADDOCK_SIMD_INLINE D4 clamp_lanes(D4 v, D4 lo, D4 hi) {
  return simd::select(v < lo, lo, simd::select(hi < v, hi, v));
}

// the state derivative (the wheels' spin with the friction decided in step()):
// the four tyres as the four lanes of one vector (simd_math.h); built twice,
// for AVX2 and for baseline x86-64, with the same result (see below)
PADDOCK_SIMD_INLINE Deriv derivative_body(const Model& m, const X& s) {
  const VehicleParams& p = *m.p;
  Deriv out;  // every field is set below (zeroing it first cost a rep stos a derivative)
  X& d = out.d;

  // actuators: first-order lags, steering also rate limited
  d.steer = std::clamp((m.steer_cmd - s.steer) * m.inv_tau_steer, -p.steering_rate_max, p.steering_rate_max);
  d.thr = (m.thr_cmd - s.thr) * m.inv_tau_thr;
  d.brk = (m.brk_cmd - s.brk) * m.inv_tau_brk;

  // aero: downforce and drag grow with vx^2; the lagged load transfer per wheel
  const double f_down = p.c_down * s.vx * s.vx;
  const double f_drag = p.c_drag * s.vx * std::abs(s.vx);
  const double transfer = m.k->transfer_per_wheel * s.ax_load;

  std::array<double, 4> t_drive, regen;
  out.power = motor_torques(m, s, t_drive, regen);
  d.energy = out.power;

  // the steering's and the heading's sine and cosine in one go
  D4 sines, cosines;
  simd::sincos(D4{s.steer, s.yaw, 0.0, 0.0}, sines, cosines);
  const double sd = sines[0], cd = cosines[0];

  // each contact point's velocity, body frame then wheel frame; sideways,
  // the axle centre's (the single-track model: in effect Ackermann steering,
  // the two wheels of an axle share its slip angle); its load
  alignas(32) double c[4], sn[4], vcx[4], vcy[4], fz[4], v_slip[4];
  for (std::size_t i = 0; i < 4; ++i) {
    const bool front = i < 2;
    c[i] = front ? cd : 1.0;
    sn[i] = front ? sd : 0.0;
    const double vbx = s.vx - s.r * m.k->y[i];
    const double vby = s.vy + s.r * m.k->x[i];
    vcx[i] = c[i] * vbx + sn[i] * vby;
    vcy[i] = c[i] * vby - sn[i] * s.vx;
    fz[i] = std::max(0.0, m.k->fz_static[i] + m.k->aero_share[i] * f_down + (front ? -transfer : transfer));
    v_slip[i] = s.w[i] * m.k->radius - vcx[i];
  }

  // the tyres' forces (wheel frame): the deflections' force, and below
  // kLowSpeed the damper on the slip velocities. The damper adds to the
  // spring up to the friction the wheel has: it still opposes the slip
  // (dissipates), never beyond what the road takes
  alignas(32) double fx[4], fy[4];
  {
    const D4 load = simd::load(fz);
    D4 fx4, fy4, mu;
    tyre_lanes(p, m.tyres, simd::load(s.ux.data()) * m.k->inv_sigma_x,
               slip_angle(m.tyres, simd::load(s.uy.data()) * m.k->inv_sigma_y), load, fx4, fy4, mu);
    const D4 vx4 = simd::load(vcx);
    const D4 low = 1.0 - simd::abs(vx4) * (1.0 / kLowSpeed);
    const D4 k = low * min_lanes(simd::splat(1.0), load * simd::load(m.k->inv_fz_static.data()));
    const D4 fx_damped = clamp_lanes(fx4 + k * simd::load(m.k->c_x.data()) * simd::load(v_slip), -p.tyre_dx * mu,
                                     p.tyre_dx * mu);
    const D4 fy_damped = clamp_lanes(fy4 - k * simd::load(m.k->c_y.data()) * simd::load(vcy), -p.tyre_d * mu,
                                     p.tyre_d * mu);
    const auto slow = low > 0.0;
    simd::store(fx, simd::select(slow, fx_damped, fx4));
    simd::store(fy, simd::select(slow, fy_damped, fy4));
  }

  double fx_sum = 0.0, fy_sum = 0.0, mz = 0.0;
  for (std::size_t i = 0; i < 4; ++i) {
    // the deflections relax towards the slips
    d.ux[i] = v_slip[i] - std::abs(vcx[i]) * s.ux[i] * m.k->inv_sigma_x;
    d.uy[i] = vcy[i] - std::abs(vcx[i]) * s.uy[i] * m.k->inv_sigma_y;
    // the wheel's spin
    out.t_net[i] = t_drive[i] - fx[i] * m.k->radius;
    out.t_fric[i] = s.brk * m.k->brake_torque[i] - regen[i] + m.k->rr_torque;
    d.w[i] = m.friction_sign[i] == 0.0 ? 0.0
                                       : (out.t_net[i] - m.friction_sign[i] * out.t_fric[i]) * m.k->inv_inertia[i];
    // the force on the chassis, body frame: the longitudinal part at the
    // contact point, the lateral part at the axle centre (where its slip was
    // taken, so that each part's power is the force times its slip velocity
    // and the energy argument above holds)
    const double fbx = c[i] * fx[i] - sn[i] * fy[i];
    const double fby = sn[i] * fx[i] + c[i] * fy[i];
    fx_sum += fbx;
    fy_sum += fby;
    mz += m.k->x[i] * fby - m.k->y[i] * c[i] * fx[i];
  }

  d.vx = s.r * s.vy + (fx_sum - f_drag) * m.k->inv_m;
  d.vy = -s.r * s.vx + fy_sum * m.k->inv_m;
  d.r = mz * m.k->inv_iz;

  // the CG acceleration in the body frame, and the suspension's lagged copy of ax
  out.ax = d.vx - s.r * s.vy;
  out.ay = d.vy + s.r * s.vx;
  d.ax_load = (out.ax - s.ax_load) * m.inv_tau_pitch;

  // pose: rotate the body velocity into the map
  const double sy = sines[1], cy = cosines[1];
  d.px = s.vx * cy - s.vy * sy;
  d.py = s.vx * sy + s.vy * cy;
  d.yaw = s.r;
  return out;
}

// the derivative for the CPU at hand: the AVX2 build (one register for the
// four lanes) where the CPU has AVX2, else baseline x86-64's (two SSE2
// registers). Both are elementwise IEEE arithmetic without FMA, so they give
// the same bits (Determinism.TheAvx2AndBaselineStepsAgreeBitForBit)
Deriv derivative_baseline(const Model& m, const X& s) { return derivative_body(m, s); }
#if defined(__x86_64__)
__attribute__((target("avx2"))) Deriv derivative_avx2(const Model& m, const X& s) { return derivative_body(m, s); }
#endif

using DerivativeFn = Deriv (*)(const Model&, const X&);

DerivativeFn best_derivative() {
#if defined(__x86_64__)
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx2")) return derivative_avx2;
#endif
  return derivative_baseline;
}

// a command replaced by a safe value when it is not finite (NaN from a broken
// controller must not poison the state)
inline double finite_or(double v, double fallback) { return std::isfinite(v) ? v : fallback; }

// contact points from the CG: FL, FR, RL, RR
std::array<Vec2, 4> wheel_offsets_cg(const VehicleParams& p) {
  return {Vec2{p.lf, 0.5 * p.track_front}, Vec2{p.lf, -0.5 * p.track_front}, Vec2{-p.lr, 0.5 * p.track_rear},
          Vec2{-p.lr, -0.5 * p.track_rear}};
}

// static wheel load (N) and the tyre's slip and cornering stiffness there
struct WheelStatics {
  double fz;        // N
  double c_kappa;   // N per unit slip ratio
  double c_alpha;   // N/rad
};
WheelStatics wheel_statics(const VehicleParams& p, std::size_t i) {
  const double axle = i < 2 ? p.lr : p.lf;
  WheelStatics w;
  w.fz = 0.5 * p.mass * kGravity * axle / (p.lf + p.lr);
  const double scale = p.tyre_c * load_factor(p, w.fz) * w.fz;
  w.c_kappa = p.tyre_bx * p.tyre_dx * scale;
  w.c_alpha = p.tyre_b * p.tyre_d * scale;
  return w;
}


// the low-speed damper: kLowSpeedDamping of critical for a quarter of the car on
// a spring of stiffness c / sigma
double low_speed_damping(const VehicleParams& p, double stiffness, double sigma) {
  return kLowSpeedDamping * 2.0 * std::sqrt(stiffness / sigma * 0.25 * p.mass);
}

}  // namespace

double stable_step_limit(const VehicleParams& p) {
  const double r = p.wheel_radius;
  const double v_top = std::max(top_speed(p), 1.0);
  const std::array<Vec2, 4> off = wheel_offsets_cg(p);
  double lambda = v_top / std::min(p.relaxation_length_x, p.relaxation_length_y);  // relaxation at top speed
  double k_lat = 0.0, k_yaw = 0.0, c_lat = 0.0;
  for (std::size_t i = 0; i < 4; ++i) {
    const WheelStatics w = wheel_statics(p, i);
    const double inertia = wheel_inertia_of(p, i);
    // the wheel's spin on the tyre's longitudinal spring, at twice the static
    // load plus the downforce at top speed
    const double share = i < 2 ? p.aero_balance_front : 1.0 - p.aero_balance_front;
    const double fz_max = 2.0 * w.fz + 0.5 * share * p.c_down * v_top * v_top;
    const double c_kappa_max = p.tyre_bx * p.tyre_c * p.tyre_dx * load_factor(p, fz_max) * fz_max;
    lambda = std::max(lambda, std::sqrt(c_kappa_max * r * r / (inertia * p.relaxation_length_x)));
    lambda = std::max(lambda, low_speed_damping(p, w.c_kappa, p.relaxation_length_x) * r * r / inertia);
    const double k = w.c_alpha / p.relaxation_length_y;
    k_lat += k;
    k_yaw += k * off[i].x * off[i].x;
    c_lat += low_speed_damping(p, w.c_alpha, p.relaxation_length_y);
  }
  // the chassis on the lateral tyre springs: sideways, in yaw, and their damping
  lambda = std::max({lambda, std::sqrt(k_lat / p.mass), std::sqrt(k_yaw / p.inertia_z), c_lat / p.mass});
  return 2.5 / lambda;
}

bool is_finite(const VehicleState& s) {
  for (const double v : {s.x, s.y, s.yaw, s.vx, s.vy, s.r, s.steering, s.throttle, s.brake, s.ax_load, s.ax, s.ay,
                         s.yaw_accel, s.energy, s.power})
    if (!std::isfinite(v)) return false;
  for (std::size_t i = 0; i < 4; ++i)
    if (!std::isfinite(s.omega[i]) || !std::isfinite(s.u_x[i]) || !std::isfinite(s.u_y[i])) return false;
  return true;
}

VehicleState initial_state(const VehicleParams& p, Pose2 base_pose_in) {
  VehicleState s;
  // the CG lies lr ahead of the rear axle centre
  const Vec2 cg = base_pose_in.transform({p.lr, 0.0});
  s.x = cg.x;
  s.y = cg.y;
  s.yaw = wrap_angle(base_pose_in.yaw);
  return s;
}

VehicleState rolling_state(const VehicleParams& p, Pose2 base_pose_in, double speed) {
  VehicleState s = initial_state(p, base_pose_in);
  s.vx = speed;
  s.omega.fill(speed / p.wheel_radius);
  return s;
}

namespace {

// the car's constants, as step() takes them
CarConstants car_constants(const VehicleParams& p) {
  CarConstants k;
  k.inv_m = 1.0 / p.mass;
  k.inv_iz = 1.0 / p.inertia_z;
  k.transfer_per_wheel = 0.5 * p.mass * p.h_cg / (p.lf + p.lr);
  k.radius = p.wheel_radius;
  k.rr_torque = 0.25 * p.cr0 * p.wheel_radius;
  k.t_wheel_max = p.motor_torque_max * p.gear_ratio;
  k.p_wheel_max = drive_power_limit(p);
  k.w_max = p.motor_speed_max / p.gear_ratio;
  k.inv_fade = 1.0 / (kMotorFade * k.w_max);
  k.eta = p.drivetrain_efficiency;
  k.inv_eta = 1.0 / p.drivetrain_efficiency;
  k.inv_sigma_x = 1.0 / p.relaxation_length_x;
  k.inv_sigma_y = 1.0 / p.relaxation_length_y;
  const std::array<Vec2, 4> off = wheel_offsets_cg(p);
  for (std::size_t i = 0; i < 4; ++i) {
    const bool front = i < 2;
    const WheelStatics w = wheel_statics(p, i);
    k.x[i] = off[i].x;
    k.y[i] = off[i].y;
    k.fz_static[i] = w.fz;
    k.inv_fz_static[i] = 1.0 / w.fz;
    k.aero_share[i] = 0.5 * (front ? p.aero_balance_front : 1.0 - p.aero_balance_front);
    k.inv_inertia[i] = 1.0 / wheel_inertia_of(p, i);
    k.drive_share[i] = drive_share(p, i);
    k.brake_torque[i] = 0.5 * (front ? p.brake_split_front : 1.0 - p.brake_split_front) * p.brake_force_max * p.wheel_radius;
    k.regen_torque[i] = k.drive_share[i] * p.regen_torque_max * p.gear_ratio;
    k.c_x[i] = low_speed_damping(p, w.c_kappa, p.relaxation_length_x);
    k.c_y[i] = low_speed_damping(p, w.c_alpha, p.relaxation_length_y);
  }
  // a sliding tyre's deflection stops growing at kSlipCap
  k.ux_cap = kSlipCap / p.tyre_bx * p.relaxation_length_x;
  k.uy_cap = std::tan(std::min(kSlipCap / p.tyre_b, 1.4)) * p.relaxation_length_y;
  return k;
}

}  // namespace

// the tyre tables are kept when they meet the curve within this (relative;
// they reach 1.1e-14 over the whole range of C and E); otherwise the car
// takes the curve as written
constexpr double kTableTolerance = 1e-13;

Car::Car(const VehicleParams& p) : p_(p), constants_(std::make_shared<const CarConstants>(car_constants(p))) {
  auto tables = std::make_shared<const TyreTables>(p.tyre_c, p.tyre_e);
  if (tables->error <= kTableTolerance) tyres_ = std::move(tables);
}

namespace {

// the model of one step: the car's constants, the commands, and what the VCU
// (traction control, torque vectoring) decided from the state at its start
Model make_model(const Car& car, const VehicleState& s, const DriverInput& in, double steer_cmd, double dt) {
  const VehicleParams& p = car.params();
  Model m;
  m.k = &car.constants();
  m.p = &p;
  m.tyres = car.tyres();
  const double yaw_moment = finite_or(in.yaw_moment, 0.0);
  const double sd = std::sin(s.steering), cd = std::cos(s.steering);
  for (std::size_t i = 0; i < 4; ++i) {
    const bool front = i < 2;
    // torque vectoring: the driven axles share the yaw moment as their drive
    // shares, each as a left/right force difference M / track: +-M r / track
    const double track = front ? p.track_front : p.track_rear;
    m.tv_torque[i] = (m.k->y[i] > 0.0 ? -1.0 : 1.0) * 2.0 * m.k->drive_share[i] * yaw_moment * p.wheel_radius / track;
    // traction control: each driven wheel's torque is cut linearly from the
    // slip ratio kappa* to (1 + kTractionBand) kappa*, sampled at the step's start
    m.traction[i] = 1.0;
    if (p.traction_control_slip > 0.0 && m.k->drive_share[i] > 0.0) {
      const double vbx = s.vx - s.r * m.k->y[i], vby = s.vy + s.r * m.k->x[i];
      const double vcx = front ? cd * vbx + sd * vby : vbx;
      const double kappa = (s.omega[i] * p.wheel_radius - vcx) / std::max(std::abs(vcx), kTractionSpeedFloor);
      const double excess = (kappa - p.traction_control_slip) / (kTractionBand * p.traction_control_slip);
      m.traction[i] = std::clamp(1.0 - excess, 0.0, 1.0);
    }
  }
  m.inv_tau_steer = lag_rate(p.steering_time_constant, dt);
  m.inv_tau_thr = lag_rate(p.throttle_time_constant, dt);
  m.inv_tau_brk = lag_rate(p.brake_time_constant, dt);
  // the pitch lag breaks the load-transfer loop, so it is never instantaneous:
  // shorter than dt/2 it is stretched to dt/2 (|z| = 2 < 2.785, still stable)
  m.inv_tau_pitch = 1.0 / std::max(p.pitch_time_constant, 0.5 * dt);
  m.steer_cmd = steer_cmd;
  m.thr_cmd = std::clamp(finite_or(in.throttle, 0.0), 0.0, 1.0);
  m.brk_cmd = std::clamp(finite_or(in.brake, 1.0), 0.0, 1.0);
  return m;
}

// the steering command after the dead time: a ring buffer of the last n
// requests; n rounded to whole steps
double delayed_steering(const VehicleParams& p, VehicleState& s, double steer_req, double dt) {
  if (p.steering_dead_time <= 0.0) return steer_req;
  constexpr std::size_t cap = kMaxDelaySteps + 1;
  auto n = static_cast<std::size_t>(std::lround(p.steering_dead_time / dt));
  assert(n <= kMaxDelaySteps && "steering_dead_time / dt exceeds the delay line");
  n = std::min(n, kMaxDelaySteps);
  s.steering_delay[s.delay_head] = steer_req;
  const double out = s.steering_delay[(s.delay_head + cap - n) % cap];
  s.delay_head = (s.delay_head + 1) % cap;
  return out;
}

// the friction torques of each wheel for this step (static friction, decided
// at its start from the first RK4 stage): a wheel at rest stays held while the
// torques that turn it are within the friction available; otherwise the
// friction opposes its spin (or, from rest, the torque that breaks it away)
void decide_friction(Model& m, const X& x0, Deriv& k1) {
  for (std::size_t i = 0; i < 4; ++i) {
    double sgn = sign(x0.w[i]);
    if (sgn == 0.0) sgn = std::abs(k1.t_net[i]) <= k1.t_fric[i] ? 0.0 : sign(k1.t_net[i]);
    m.friction_sign[i] = sgn;
    k1.d.w[i] = sgn == 0.0 ? 0.0 : (k1.t_net[i] - sgn * k1.t_fric[i]) * m.k->inv_inertia[i];
  }
}

}  // namespace

namespace {

void step_with(DerivativeFn derivative, const Car& car, VehicleState& s, const DriverInput& in, double dt) {
  assert(dt > 0.0);
  const VehicleParams& p = car.params();

  // commands: non-finite ones replaced by safe values, then limited
  const double steer_req = std::clamp(finite_or(in.steering_angle, s.steering), -p.steering_max, p.steering_max);
  const double steer_cmd = delayed_steering(p, s, steer_req, dt);
  Model m = make_model(car, s, in, steer_cmd, dt);
  if (m.brk_cmd >= kPlausibilityBrake && m.thr_cmd > kPlausibilityCut) s.torque_cut = true;
  if (m.thr_cmd < kPlausibilityReset) s.torque_cut = false;
  if (s.torque_cut) m.thr_cmd = 0.0;

  // instantaneous actuators jump to the command at the start of the step
  // (steering still rate limited), and are held over the step
  if (m.inv_tau_steer == 0.0) {
    const double max_move = p.steering_rate_max * dt;
    s.steering += std::clamp(steer_cmd - s.steering, -max_move, max_move);
  }
  if (m.inv_tau_thr == 0.0) s.throttle = m.thr_cmd;
  if (m.inv_tau_brk == 0.0) s.brake = m.brk_cmd;

  // a wheel turning slower than kRestSpin is at rest
  for (double& w : s.omega)
    if (std::abs(w) < kRestSpin) w = 0.0;

  // classic RK4, the wheels' friction decided at the first stage
  const X x0{s.x, s.y, s.yaw, s.vx, s.vy, s.r, s.steering, s.throttle, s.brake, s.ax_load, s.energy, s.omega, s.u_x, s.u_y};
  const double h = 0.5 * dt;
  m.friction_sign.fill(1.0);
  Deriv k1 = derivative(m, x0);
  decide_friction(m, x0, k1);
  const Deriv k2 = derivative(m, axpy(x0, h, k1.d));
  const Deriv k3 = derivative(m, axpy(x0, h, k2.d));
  const Deriv k4 = derivative(m, axpy(x0, dt, k3.d));
  X k = axpy(axpy(k1.d, 2.0, k2.d), 2.0, k3.d);
  k = axpy(k, 1.0, k4.d);
  const X x1 = axpy(x0, dt / 6.0, k);

  s.x = x1.px;
  s.y = x1.py;
  s.yaw = x1.yaw;
  if (s.yaw >= kPi || s.yaw < -kPi) s.yaw = wrap_angle(s.yaw);
  s.vx = x1.vx;
  s.vy = x1.vy;
  s.r = x1.r;
  // the lags approach their (limited) commands without overshoot (RK4's R(z) is in
  // (0, 1) for the stable z); the clamps only guard the last ulp
  s.steering = std::clamp(x1.steer, -p.steering_max, p.steering_max);
  s.throttle = std::clamp(x1.thr, 0.0, 1.0);
  s.brake = std::clamp(x1.brk, 0.0, 1.0);
  s.ax_load = x1.ax_load;
  s.energy = x1.energy;
  // friction stops a wheel, never turns it back; a sliding tyre's deflection
  // stops growing at kSlipCap
  for (std::size_t i = 0; i < 4; ++i) {
    s.omega[i] = x1.w[i] * m.friction_sign[i] < 0.0 ? 0.0 : x1.w[i];
    s.u_x[i] = std::clamp(x1.ux[i], -m.k->ux_cap, m.k->ux_cap);
    s.u_y[i] = std::clamp(x1.uy[i], -m.k->uy_cap, m.k->uy_cap);
  }

  // mean accelerations and power over the step, with RK4's weights
  s.ax = (k1.ax + 2.0 * (k2.ax + k3.ax) + k4.ax) / 6.0;
  s.ay = (k1.ay + 2.0 * (k2.ay + k3.ay) + k4.ay) / 6.0;
  s.yaw_accel = k.r / 6.0;
  s.power = (k1.power + 2.0 * (k2.power + k3.power) + k4.power) / 6.0;
}

}  // namespace

void step(const Car& car, VehicleState& s, const DriverInput& in, double dt) {
  static const DerivativeFn derivative = best_derivative();
  step_with(derivative, car, s, in, dt);
}

void step_baseline(const Car& car, VehicleState& s, const DriverInput& in, double dt) {
  step_with(derivative_baseline, car, s, in, dt);
}

// ---------------------------------------------------------------------------
// accessors
// ---------------------------------------------------------------------------

Pose2 base_pose(const VehicleParams& p, const VehicleState& s) {
  const double c = std::cos(s.yaw), sn = std::sin(s.yaw);
  return {s.x - p.lr * c, s.y - p.lr * sn, s.yaw};
}

// rigid body: v_base = v_cg + r x (-lr, 0) = (vx, vy - lr r)
Vec2 base_velocity(const VehicleParams& p, const VehicleState& s) { return {s.vx, s.vy - p.lr * s.r}; }

Vec2 body_acceleration(const VehicleState& s) { return {s.ax, s.ay}; }

double speed(const VehicleState& s) { return std::sqrt(s.vx * s.vx + s.vy * s.vy); }


std::array<Vec2, 4> wheel_positions(const VehicleParams& p, const VehicleState& s) {
  const Pose2 cg{s.x, s.y, s.yaw};
  std::array<Vec2, 4> out;
  const std::array<Vec2, 4> off = wheel_offsets_cg(p);
  for (std::size_t i = 0; i < 4; ++i) out[i] = cg.transform(off[i]);
  return out;
}

std::array<double, 4> wheel_speeds(const VehicleParams&, const VehicleState& s) { return s.omega; }

std::array<double, 4> slip_ratios(const VehicleParams& p, const VehicleState& s) {
  const std::array<Vec2, 4> off = wheel_offsets_cg(p);
  const Vec2 front_heading{std::cos(s.steering), std::sin(s.steering)};
  std::array<double, 4> out;
  for (std::size_t i = 0; i < 4; ++i) {
    // velocity of the contact point: v_cg + r x offset, along the wheel
    const Vec2 v{s.vx - s.r * off[i].y, s.vy + s.r * off[i].x};
    const double along = dot(v, i < 2 ? front_heading : Vec2{1.0, 0.0});
    out[i] = (s.omega[i] * p.wheel_radius - along) / std::max(std::abs(along), 1.0);
  }
  return out;
}

Footprint footprint(const VehicleParams& p) {
  Footprint f;
  f.x_min = -p.rear_overhang;
  f.x_max = p.lf + p.lr + p.front_overhang;
  f.y_min = -0.5 * p.body_width;
  f.y_max = 0.5 * p.body_width;
  return f;
}

}  // namespace paddock::vehicle
