#include "sim/vehicle/vehicle.h"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace paddock::vehicle {

// ---------------------------------------------------------------------------
// tyre and blend
// ---------------------------------------------------------------------------

// Pacejka magic formula, lateral, without shifts:
//   mu_y(a) = D sin(C atan(B a - E (B a - atan(B a))))
//   Fy      = -mu_y(a) Fz      (the force opposes the slip angle)
// FSSIM writes the same curve as D sin(C atan(B (1 - E) a + E atan(B a))) with C = -1.38,
// which folds the minus sign into C (sin and atan are odd).
namespace {
inline double tyre_mu(const VehicleParams& p, double alpha) {
  const double ba = p.tyre_b * alpha;
  return p.tyre_d * std::sin(p.tyre_c * std::atan(ba - p.tyre_e * (ba - std::atan(ba))));
}
}  // namespace

double tyre_lateral_force(const VehicleParams& p, double alpha, double fz) { return -tyre_mu(p, alpha) * fz; }

// FSSIM: lambda = clamp(0.5 (|v| - 1.5), 0, 1)
// the slip angle of a wheel whose rolling direction points at `steer` in the
// body frame, its contact point moving at (vx, vy): phi = atan2(vy, vx) -
// steer, the velocity's angle from the rolling direction. A wheel rolling
// backwards (|phi| > pi/2) slips by the angle from its backward direction,
// pi - phi folded into (-pi/2, pi/2]: the force -mu(alpha) Fz then still
// opposes the lateral velocity (atan2 alone gives +-pi there, flipping sign
// from step to step, and a spun car drove itself backwards for ever)
double slip_angle(double vx, double vy, double steer) {
  const double phi = std::atan2(vy, vx) - steer;
  // |phi| < 3 pi / 2 for |steer| < pi / 2: rolling forwards is |phi| <= pi / 2 (no cos in the hot path)
  if (std::abs(phi) <= 0.5 * kPi) return phi;
  return wrap_angle(kPi - phi);
}

double dynamic_weight(double speed_abs) { return std::clamp(0.5 * (speed_abs - 1.5), 0.0, 1.0); }

// ---------------------------------------------------------------------------
// the model
// ---------------------------------------------------------------------------
//
// Single-track model at the CG, body frame (x forward, y left), yaw rate r.
// Newton in the rotating body frame: the inertial acceleration of the CG is
//   a = d/dt (vx, vy) + r x (vx, vy) = (vx' - r vy, vy' + r vx),
// so with the front axle forces (Fxf, Fyf) in the wheel frame, steered by delta,
// and the rear axle forces (Fxr, Fyr) in the body frame:
//   m (vx' - r vy) = Fxf cos(delta) - Fyf sin(delta) + Fxr + Fres
//   m (vy' + r vx) = Fxf sin(delta) + Fyf cos(delta) + Fyr
//   Iz r'          = lf (Fxf sin(delta) + Fyf cos(delta)) - lr Fyr
// where Fres = -c_drag vx |vx| - Cr0 sat(vx) collects drag and rolling resistance
// (applied at the CG along x). The pose follows from rotating the body velocity:
//   X' = vx cos(yaw) - vy sin(yaw),  Y' = vx sin(yaw) + vy cos(yaw),  yaw' = r.
//
// Slip angles: the axle velocities in the body frame are (vx, vy + lf r) at the
// front and (vx, vy - lr r) at the rear; a slip angle is the angle of that velocity
// from the wheel heading:
//   alpha_f = atan2(vy + lf r, vx) - delta,   alpha_r = atan2(vy - lr r, vx).
// The sideslip angle of the CG is beta = atan2(vy, vx); it is not a state here
// (vy is), and at low speed it is undefined, which is why the slip angles are
// evaluated only where the dynamic model has weight (|v| > 1.5 m/s).
//
// Kinematic model (FSSIM, no tyre slip): the rear axle moves along the body x axis
// and the front axle along the front wheel, so with the speed of the rear axle vx
//   r_kin = vx tan(delta) / L,   vy_kin = lr r_kin,   m vx' = Fxf + Fxr + Fres.
// As a state derivative: vy, r track their kinematic values through
//   r'  = d/dt r_kin  + (r_kin  - r)  / tau_kin,
//   vy' = d/dt vy_kin + (vy_kin - vy) / tau_kin,
//   d/dt r_kin = (vx' tan(delta) + vx delta' / cos^2(delta)) / L,
// the first term keeps them exactly on the kinematic values once there, the second
// pulls them there when the car enters the kinematic regime with a residual slip
// (FSSIM overwrites them after each step, i.e. tau_kin = dt).
// The state derivative is lambda * f_dyn + (1 - lambda) * f_kin (pose and actuator
// rows are the same in both models).
//
// Normal loads per axle: static share + aero share + longitudinal load transfer
//   Fzf = m g lr / L + bal c_down vx^2       - m ax_load h_cg / L
//   Fzr = m g lf / L + (1 - bal) c_down vx^2 + m ax_load h_cg / L
// The transfer uses ax_load, a state that follows the CG acceleration ax through a
// first-order lag (the pitch dynamics of the suspension):
//   ax_load' = (ax - ax_load) / pitch_time_constant.
// ax depends on the normal loads (through the friction limits), so using ax itself
// would be an algebraic loop; the lag breaks it without iteration.
//
// Longitudinal force per axle: motor (throttle cm1 split front/rear) minus brake
// (brake F_brake_max split front/rear, opposing vx), limited by the friction ellipse
// (Fx/(D Fz))^2 + (Fy/(D Fz))^2 <= 1. The lateral force has priority:
//   |Fx| <= sqrt((D Fz)^2 - Fy^2)
// because the lateral curve is the FSSIM reference (kept unchanged it keeps the
// lateral dynamics and the tyre oracle identical), and because the longitudinal force
// here is an actuator demand with no slip model: clipping it is what the car's traction
// control and ABS do, whereas clipping Fy would make a full-brake demand steal the
// cornering force, which an ABS prevents.

namespace {

// the integrated state: rigid body, actuators, load transfer
struct X {
  double px, py, yaw, vx, vy, r, steer, thr, brk, ax_load;
};

inline X axpy(const X& s, double h, const X& k) {
  return {s.px + h * k.px,       s.py + h * k.py,         s.yaw + h * k.yaw, s.vx + h * k.vx,
          s.vy + h * k.vy,       s.r + h * k.r,           s.steer + h * k.steer,
          s.thr + h * k.thr,     s.brk + h * k.brk,       s.ax_load + h * k.ax_load};
}

// a state derivative, plus the CG acceleration in the body frame it implies
struct Deriv {
  X d;
  double ax;  // m/s^2, vx' - r vy
  double ay;  // m/s^2, vy' + r vx
};

// kinematic tracking time constant, s: how fast vy and r settle on their kinematic
// values when the car enters the kinematic regime with a residual slip. Its rate
// 1/tau_kin = 100 1/s gives |z| = dt / tau_kin = 0.1 at 1 kHz, far inside the RK4
// stability interval (|z| < 2.785), and is fast compared with the vehicle motion.
constexpr double kKinematicTimeConstant = 0.01;

// smallest regularisation speed of the standstill forces, m/s (see standstill_speed)
constexpr double kMinStandstillSpeed = 0.02;

// everything constant over one step
struct Model {
  const VehicleParams* p;
  double inv_m, inv_iz, wheelbase, inv_l;
  double fz_front_static, fz_rear_static;  // N
  double load_transfer_gain;               // N per m/s^2: m h_cg / L
  double inv_v_reg;                        // 1 / (m/s): standstill regularisation
  double inv_tau_steer, inv_tau_thr, inv_tau_brk, inv_tau_pitch;  // 1/s, 0 = instantaneous (set outside RK4)
  // commands after dead time and limits
  double steer_cmd, thr_cmd, brk_cmd;
};

// standstill regularisation: sat(vx) = clamp(vx / v_reg, -1, 1) replaces sign(vx) in
// the rolling resistance and the brakes, so that at vx = 0 they are exactly zero (no
// creeping, the car at rest stays at rest) and near vx = 0 they are a linear damper.
// Stiffness limit: inside |vx| < v_reg they act as m vx' = -c vx with
// c = (F_brake_max + Cr0) / v_reg, eigenvalue lambda = -c / m. RK4's amplification
// R(z) = 1 + z + z^2/2 + z^3/6 + z^4/24, z = lambda dt, is stable for z > -2.785
// and stays in (0, 1) there, so vx decays monotonically and never changes sign (no
// rolling backwards under braking). Above v_reg the deceleration is at most
// a_max = (F_brake_max + Cr0 + F_drag) / m, and one step cannot jump over the band
// [0, v_reg] if a_max dt <= v_reg. Both hold with margin for
//   v_reg = 2 (F_brake_max + Cr0) dt / m   (z = -0.5, and drag up to F_brake_max + Cr0),
// floored at 2 cm/s; with the default car at 1 kHz, v_reg = 3.9 cm/s.
double standstill_speed_impl(const VehicleParams& p, double dt) {
  return std::max(kMinStandstillSpeed, 2.0 * (p.brake_force_max + p.cr0) * dt / p.mass);
}

// first-order lag rate, 0 (= instantaneous, applied outside RK4) when tau < dt/2:
// such a lag is not resolvable at this step and explicit RK4 would go unstable for
// dt / tau > 2.785
inline double lag_rate(double tau, double dt) { return tau < 0.5 * dt ? 0.0 : 1.0 / tau; }

// the state derivative
Deriv derivative(const Model& m, const X& s) {
  const VehicleParams& p = *m.p;
  Deriv out{};
  X& d = out.d;

  // actuators: first-order lags, steering also rate limited
  d.steer = std::clamp((m.steer_cmd - s.steer) * m.inv_tau_steer, -p.steering_rate_max, p.steering_rate_max);
  d.thr = (m.thr_cmd - s.thr) * m.inv_tau_thr;
  d.brk = (m.brk_cmd - s.brk) * m.inv_tau_brk;

  // aero: downforce and drag grow with vx^2
  const double vx2 = s.vx * s.vx;
  const double f_down = p.c_down * vx2;
  const double f_drag = p.c_drag * s.vx * std::abs(s.vx);

  // normal loads: static + aero + lagged longitudinal load transfer
  const double transfer = m.load_transfer_gain * s.ax_load;
  const double fz_f = std::max(0.0, m.fz_front_static + p.aero_balance_front * f_down - transfer);
  const double fz_r = std::max(0.0, m.fz_rear_static + (1.0 - p.aero_balance_front) * f_down + transfer);

  // standstill regularisation of the forces that oppose motion
  const double sat = std::clamp(s.vx * m.inv_v_reg, -1.0, 1.0);

  // longitudinal demand per axle (wheel frame): motor minus brake
  const double f_motor = s.thr * p.cm1;
  const double f_brake = s.brk * p.brake_force_max * sat;
  const double fx_f_demand = p.drive_split_front * f_motor - p.brake_split_front * f_brake;
  const double fx_r_demand = (1.0 - p.drive_split_front) * f_motor - (1.0 - p.brake_split_front) * f_brake;
  const double f_res = -f_drag - p.cr0 * sat;

  // blend weight of the dynamic model
  const double v = std::sqrt(vx2 + s.vy * s.vy);
  const double lambda = dynamic_weight(v);

  // lateral tyre forces, only where the dynamic model has weight (no slip angle at rest)
  double fy_f = 0.0, fy_r = 0.0;
  if (lambda > 0.0) {
    const double alpha_f = slip_angle(s.vx, s.vy + p.lf * s.r, s.steer);
    const double alpha_r = slip_angle(s.vx, s.vy - p.lr * s.r, 0.0);
    fy_f = -tyre_mu(p, alpha_f) * fz_f;
    fy_r = -tyre_mu(p, alpha_r) * fz_r;
  }

  // friction ellipse per axle, lateral first: |Fx| <= sqrt((D Fz)^2 - Fy^2)
  const double fmax_f = p.tyre_d * fz_f;
  const double fmax_r = p.tyre_d * fz_r;
  const double fx_lim_f = fy_f == 0.0 ? fmax_f : std::sqrt(std::max(0.0, fmax_f * fmax_f - fy_f * fy_f));
  const double fx_lim_r = fy_r == 0.0 ? fmax_r : std::sqrt(std::max(0.0, fmax_r * fmax_r - fy_r * fy_r));
  const double fx_f = std::clamp(fx_f_demand, -fx_lim_f, fx_lim_f);
  const double fx_r = std::clamp(fx_r_demand, -fx_lim_r, fx_lim_r);

  const double sd = std::sin(s.steer);
  const double cd = std::cos(s.steer);

  // kinematic and dynamic velocity derivatives, blended
  double vx_dot = 0.0, vy_dot = 0.0, r_dot = 0.0;
  if (lambda < 1.0) {
    const double vx_dot_k = (fx_f + fx_r + f_res) * m.inv_m;
    const double td = sd / cd;
    const double r_kin = s.vx * td * m.inv_l;
    const double r_kin_dot = (vx_dot_k * td + s.vx * d.steer / (cd * cd)) * m.inv_l;
    const double w = 1.0 - lambda;
    vx_dot += w * vx_dot_k;
    r_dot += w * (r_kin_dot + (r_kin - s.r) * (1.0 / kKinematicTimeConstant));
    vy_dot += w * (p.lr * r_kin_dot + (p.lr * r_kin - s.vy) * (1.0 / kKinematicTimeConstant));
  }
  if (lambda > 0.0) {
    const double fy_f_body = fx_f * sd + fy_f * cd;  // front axle force along body y
    vx_dot += lambda * (s.r * s.vy + (fx_f * cd - fy_f * sd + fx_r + f_res) * m.inv_m);
    vy_dot += lambda * (-s.r * s.vx + (fy_f_body + fy_r) * m.inv_m);
    r_dot += lambda * ((p.lf * fy_f_body - p.lr * fy_r) * m.inv_iz);
  }
  d.vx = vx_dot;
  d.vy = vy_dot;
  d.r = r_dot;

  // the CG acceleration in the body frame, and the suspension's lagged copy of ax
  out.ax = vx_dot - s.r * s.vy;
  out.ay = vy_dot + s.r * s.vx;
  d.ax_load = (out.ax - s.ax_load) * m.inv_tau_pitch;

  // pose: rotate the body velocity into the map
  const double cy = std::cos(s.yaw);
  const double sy = std::sin(s.yaw);
  d.px = s.vx * cy - s.vy * sy;
  d.py = s.vx * sy + s.vy * cy;
  d.yaw = s.r;
  return out;
}

// a command replaced by a safe value when it is not finite (NaN from a broken
// controller must not poison the state)
inline double finite_or(double v, double fallback) { return std::isfinite(v) ? v : fallback; }

}  // namespace

double standstill_speed(const VehicleParams& p, double dt) { return standstill_speed_impl(p, dt); }

double stable_step_limit(const VehicleParams& p) {
  const double v = 1.5;  // m/s, where dynamic_weight starts to rise
  const double wheelbase = p.lf + p.lr;
  const double fz_front = p.mass * kGravity * p.lr / wheelbase;
  const double fz_rear = p.mass * kGravity * p.lf / wheelbase;
  const double bcd = p.tyre_b * p.tyre_c * p.tyre_d;
  const double c_front = bcd * fz_front, c_rear = bcd * fz_rear;
  const double lateral = (c_front + c_rear) / (p.mass * v);
  const double yaw = (c_front * p.lf * p.lf + c_rear * p.lr * p.lr) / (p.inertia_z * v);
  return 2.5 / std::max(lateral, yaw);
}

bool is_finite(const VehicleState& s) {
  for (const double v : {s.x, s.y, s.yaw, s.vx, s.vy, s.r, s.steering, s.throttle, s.brake, s.ax_load, s.ax, s.ay, s.yaw_accel})
    if (!std::isfinite(v)) return false;
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
  return s;
}

void step(const VehicleParams& p, VehicleState& s, const DriverInput& in, double dt) {
  assert(dt > 0.0);

  // commands: non-finite ones replaced by safe values, then limited
  const double steer_req = std::clamp(finite_or(in.steering_angle, s.steering), -p.steering_max, p.steering_max);
  const double thr_cmd = std::clamp(finite_or(in.throttle, 0.0), 0.0, 1.0);
  const double brk_cmd = std::clamp(finite_or(in.brake, 1.0), 0.0, 1.0);

  // steering dead time: a ring buffer of the last n commands; n rounded to whole steps
  double steer_cmd = steer_req;
  if (p.steering_dead_time > 0.0) {
    constexpr std::size_t cap = kMaxDelaySteps + 1;
    auto n = static_cast<std::size_t>(std::lround(p.steering_dead_time / dt));
    assert(n <= kMaxDelaySteps && "steering_dead_time / dt exceeds the delay line");
    n = std::min(n, kMaxDelaySteps);
    s.steering_delay[s.delay_head] = steer_req;
    steer_cmd = s.steering_delay[(s.delay_head + cap - n) % cap];
    s.delay_head = (s.delay_head + 1) % cap;
  }

  // the model for this step
  Model m;
  m.p = &p;
  m.inv_m = 1.0 / p.mass;
  m.inv_iz = 1.0 / p.inertia_z;
  m.wheelbase = p.lf + p.lr;
  m.inv_l = 1.0 / m.wheelbase;
  m.fz_front_static = p.mass * kGravity * p.lr * m.inv_l;
  m.fz_rear_static = p.mass * kGravity * p.lf * m.inv_l;
  m.load_transfer_gain = p.mass * p.h_cg * m.inv_l;
  m.inv_v_reg = 1.0 / standstill_speed_impl(p, dt);
  m.inv_tau_steer = lag_rate(p.steering_time_constant, dt);
  m.inv_tau_thr = lag_rate(p.throttle_time_constant, dt);
  m.inv_tau_brk = lag_rate(p.brake_time_constant, dt);
  // the pitch lag breaks the load-transfer loop, so it is never instantaneous:
  // shorter than dt/2 it is stretched to dt/2 (|z| = 2 < 2.785, still stable)
  m.inv_tau_pitch = 1.0 / std::max(p.pitch_time_constant, 0.5 * dt);
  m.steer_cmd = steer_cmd;
  m.thr_cmd = thr_cmd;
  m.brk_cmd = brk_cmd;

  // instantaneous actuators jump to the command at the start of the step
  // (steering still rate limited), and are held over the step
  if (m.inv_tau_steer == 0.0) {
    const double max_move = p.steering_rate_max * dt;
    s.steering += std::clamp(steer_cmd - s.steering, -max_move, max_move);
  }
  if (m.inv_tau_thr == 0.0) s.throttle = thr_cmd;
  if (m.inv_tau_brk == 0.0) s.brake = brk_cmd;

  // classic RK4
  const X x0{s.x, s.y, s.yaw, s.vx, s.vy, s.r, s.steering, s.throttle, s.brake, s.ax_load};
  const double h = 0.5 * dt;
  const Deriv k1 = derivative(m, x0);
  const Deriv k2 = derivative(m, axpy(x0, h, k1.d));
  const Deriv k3 = derivative(m, axpy(x0, h, k2.d));
  const Deriv k4 = derivative(m, axpy(x0, dt, k3.d));
  X k;
  k.px = k1.d.px + 2.0 * (k2.d.px + k3.d.px) + k4.d.px;
  k.py = k1.d.py + 2.0 * (k2.d.py + k3.d.py) + k4.d.py;
  k.yaw = k1.d.yaw + 2.0 * (k2.d.yaw + k3.d.yaw) + k4.d.yaw;
  k.vx = k1.d.vx + 2.0 * (k2.d.vx + k3.d.vx) + k4.d.vx;
  k.vy = k1.d.vy + 2.0 * (k2.d.vy + k3.d.vy) + k4.d.vy;
  k.r = k1.d.r + 2.0 * (k2.d.r + k3.d.r) + k4.d.r;
  k.steer = k1.d.steer + 2.0 * (k2.d.steer + k3.d.steer) + k4.d.steer;
  k.thr = k1.d.thr + 2.0 * (k2.d.thr + k3.d.thr) + k4.d.thr;
  k.brk = k1.d.brk + 2.0 * (k2.d.brk + k3.d.brk) + k4.d.brk;
  k.ax_load = k1.d.ax_load + 2.0 * (k2.d.ax_load + k3.d.ax_load) + k4.d.ax_load;
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

  // mean accelerations over the step, with RK4's weights
  s.ax = (k1.ax + 2.0 * (k2.ax + k3.ax) + k4.ax) / 6.0;
  s.ay = (k1.ay + 2.0 * (k2.ay + k3.ay) + k4.ay) / 6.0;
  s.yaw_accel = k.r / 6.0;
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

namespace {
// contact patches in the body frame relative to the CG: FL, FR, RL, RR
std::array<Vec2, 4> wheel_offsets_cg(const VehicleParams& p) {
  return {Vec2{p.lf, 0.5 * p.track_front}, Vec2{p.lf, -0.5 * p.track_front}, Vec2{-p.lr, 0.5 * p.track_rear},
          Vec2{-p.lr, -0.5 * p.track_rear}};
}
}  // namespace

std::array<Vec2, 4> wheel_positions(const VehicleParams& p, const VehicleState& s) {
  const Pose2 cg{s.x, s.y, s.yaw};
  std::array<Vec2, 4> out;
  const std::array<Vec2, 4> off = wheel_offsets_cg(p);
  for (std::size_t i = 0; i < 4; ++i) out[i] = cg.transform(off[i]);
  return out;
}

std::array<double, 4> wheel_speeds(const VehicleParams& p, const VehicleState& s) {
  const std::array<Vec2, 4> off = wheel_offsets_cg(p);
  const Vec2 front_heading{std::cos(s.steering), std::sin(s.steering)};
  std::array<double, 4> out;
  for (std::size_t i = 0; i < 4; ++i) {
    // velocity of the contact point: v_cg + r x offset
    const Vec2 v{s.vx - s.r * off[i].y, s.vy + s.r * off[i].x};
    const Vec2 heading = i < 2 ? front_heading : Vec2{1.0, 0.0};
    out[i] = dot(v, heading) / p.wheel_radius;
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
