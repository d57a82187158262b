#include "autonomy/estimation/velocity_ekf.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Cholesky>

namespace paddock::estimation {

namespace {

constexpr double kGravity = 9.80665;  // m/s^2
// the vehicle model's slip ratio divides by the contact point's speed, at least this
constexpr double kSlipSpeedFloor = 1.0;  // m/s

std::string check_geometry(const CarGeometry& g) {
  const auto ok = [](double v, double lo, double hi) { return std::isfinite(v) && v >= lo && v <= hi; };
  if (!ok(g.lf, 0.05, 5.0)) return "lf must be in [0.05, 5] m (got " + params::number(g.lf) + ")";
  if (!ok(g.lr, 0.05, 5.0)) return "lr must be in [0.05, 5] m (got " + params::number(g.lr) + ")";
  if (!ok(g.track_front, 0.2, 5.0)) return "track_front must be in [0.2, 5] m (got " + params::number(g.track_front) + ")";
  if (!ok(g.track_rear, 0.2, 5.0)) return "track_rear must be in [0.2, 5] m (got " + params::number(g.track_rear) + ")";
  if (!ok(g.wheel_radius, 0.05, 2.0)) return "wheel_radius must be in [0.05, 2] m (got " + params::number(g.wheel_radius) + ")";
  if (!ok(g.imu_x, -10.0, 10.0) || !ok(g.imu_y, -5.0, 5.0))
    return "the IMU's mount must lie within 10 m of the rear axle (got " + params::number(g.imu_x) + ", " + params::number(g.imu_y) + ")";
  if (!ok(g.slip_per_accel, 0.0, 1.0)) return "slip_per_accel must be in [0, 1] s^2/m (got " + params::number(g.slip_per_accel) + ")";
  if (!ok(g.drag_per_mass, 0.0, 1.0)) return "drag_per_mass must be in [0, 1] 1/m (got " + params::number(g.drag_per_mass) + ")";
  if (!ok(g.cornering_stiffness, 1e-3, 1000.0)) return "cornering_stiffness must be in (0, 1000] 1/rad (got " + params::number(g.cornering_stiffness) + ")";
  return "";
}

}  // namespace

VelocityEkf::VelocityEkf(const VelocityEkfParams& p, const CarGeometry& g) : params_(p), geometry_(g) {
  params::require_valid(params_, "VelocityEkfParams");
  params::require_valid_or_throw(check_geometry(geometry_), "CarGeometry");
  // FL, FR, RL, RR in the base frame (origin at the rear axle centre)
  const double wheelbase = g.lf + g.lr;
  wheel_x_ = {wheelbase, wheelbase, 0.0, 0.0};
  wheel_y_ = {0.5 * g.track_front, -0.5 * g.track_front, 0.5 * g.track_rear, -0.5 * g.track_rear};
  reset(Pose2{}, 0);
  started_ = false;
}

void VelocityEkf::reset(const Pose2& pose, TimeNs stamp) {
  const VelocityEkfParams& p = params_;
  x_ = Vector::Zero();
  x_(kX) = pose.x;
  x_(kY) = pose.y;
  x_(kYaw) = pose.yaw;
  P_ = Matrix::Zero();
  const double v2 = p.velocity_std_initial * p.velocity_std_initial;
  P_(kVx, kVx) = v2;
  P_(kVy, kVy) = v2;
  P_(kR, kR) = p.yaw_rate_std_initial * p.yaw_rate_std_initial;
  P_(kBax, kBax) = p.accel_bias_std_initial * p.accel_bias_std_initial;
  P_(kBay, kBay) = p.accel_bias_std_initial * p.accel_bias_std_initial;
  P_(kBr, kBr) = p.gyro_bias_std_initial * p.gyro_bias_std_initial;
  stamp_ = stamp;
  started_ = true;
  has_imu_ = false;
  has_steering_ = false;
  steering_ = 0.0;
  has_wheels_ = false;
  wheels_used_ = 0;
  acquired_ = false;
}

void VelocityEkf::start_if_needed(TimeNs stamp) {
  if (!started_) reset(Pose2{}, stamp);
}

bool VelocityEkf::state_finite() const { return x_.allFinite() && P_.allFinite(); }

EkfStatus VelocityEkf::on_imu(const hal::Imu& m) {
  if (!finite(m.ax) || !finite(m.ay) || !finite(m.yaw_rate) || (started_ && m.stamp < stamp_)) {
    ++rejected_;
    return EkfStatus::Rejected;
  }
  start_if_needed(m.stamp);
  const Vector x0 = x_;
  const Matrix P0 = P_;
  const double dt = to_seconds(m.stamp - stamp_);
  // the trapezoid of the previous and this sample's accelerations over the step
  const double ax = has_imu_ ? 0.5 * (ax_m_ + m.ax) : m.ax;
  const double ay = has_imu_ ? 0.5 * (ay_m_ + m.ay) : m.ay;
  predict(dt, ax, ay, m.yaw_rate);
  if (!state_finite()) {
    x_ = x0;
    P_ = P0;
    ++rejected_;
    return EkfStatus::Rejected;
  }
  stamp_ = m.stamp;
  has_imu_ = true;
  ax_m_ = m.ax;
  ay_m_ = m.ay;
  g_m_ = m.yaw_rate;
  return EkfStatus::Ok;
}

void VelocityEkf::predict(double dt, double ax_m, double ay_m, double g_m) {
  const VelocityEkfParams& p = params_;
  const double mx = geometry_.imu_x, my = geometry_.imu_y;
  const double yaw = x_(kYaw), vx = x_(kVx), vy = x_(kVy), r = x_(kR);
  const double ax = ax_m - x_(kBax), ay = ay_m - x_(kBay);
  const double rn = g_m - x_(kBr);
  const double rb = 0.5 * (r + rn);

  // velocity of the base origin (see the header: the IMU point's kinematics,
  // the lever arm's alpha dt as the change of the yaw rate)
  const double vxn = vx + dt * (ax + rb * vy + rb * rb * mx) + (rn - r) * my;
  const double vyn = vy + dt * (ay - rb * vx + rb * rb * my) - (rn - r) * mx;
  // pose: the mean velocity at the mid-step heading
  const double yawn = yaw + dt * rb;
  const double th = yaw + 0.5 * dt * rb;
  const double c = std::cos(th), s = std::sin(th);
  const double vmx = 0.5 * (vx + vxn), vmy = 0.5 * (vy + vyn);
  const double dx = dt * (c * vmx - s * vmy), dy = dt * (s * vmx + c * vmy);

  // the Jacobian F = d x+ / d x; the rows of vx+ and vy+ first
  Matrix F = Matrix::Zero();
  // d rb / d r = 0.5, d rb / d b_r = -0.5
  F(kVx, kVx) = 1.0;
  F(kVx, kVy) = dt * rb;
  F(kVx, kR) = dt * (0.5 * vy + rb * mx) - my;
  F(kVx, kBax) = -dt;
  F(kVx, kBr) = -dt * (0.5 * vy + rb * mx) - my;
  F(kVy, kVx) = -dt * rb;
  F(kVy, kVy) = 1.0;
  F(kVy, kR) = dt * (-0.5 * vx + rb * my) + mx;
  F(kVy, kBay) = -dt;
  F(kVy, kBr) = -dt * (-0.5 * vx + rb * my) + mx;
  // r+ = g_m - b_r: the previous r does not carry over
  F(kR, kBr) = -1.0;
  // yaw+ = yaw + dt (r + g_m - b_r) / 2
  F(kYaw, kYaw) = 1.0;
  F(kYaw, kR) = 0.5 * dt;
  F(kYaw, kBr) = -0.5 * dt;
  // position: d(dx) = dt (c d vmx - s d vmy) - dy d th, d(dy) = dt (s d vmx + c d vmy) + dx d th
  Eigen::Matrix<double, 1, 9> dvmx = 0.5 * F.row(kVx), dvmy = 0.5 * F.row(kVy), dth = Eigen::Matrix<double, 1, 9>::Zero();
  dvmx(kVx) += 0.5;
  dvmy(kVy) += 0.5;
  dth(kYaw) = 1.0;
  dth(kR) = 0.25 * dt * dt;
  dth(kBr) = -0.25 * dt * dt;
  F.row(kX) = dt * (c * dvmx - s * dvmy) - dy * dth;
  F.row(kY) = dt * (s * dvmx + c * dvmy) + dx * dth;
  F(kX, kX) += 1.0;
  F(kY, kY) += 1.0;
  // biases: random walks
  F(kBax, kBax) = 1.0;
  F(kBay, kBay) = 1.0;
  F(kBr, kBr) = 1.0;

  // the inputs' noise enters as a bias does (with the opposite sign, which
  // the quadratic form ignores): G = the bias columns of F's velocity, yaw
  // and position rows
  Eigen::Matrix<double, 9, 3> G = F.block<9, 3>(0, kBax);
  G.block<3, 3>(kBax, 0).setZero();
  const double sa2 = p.accel_noise * p.accel_noise, sg2 = p.gyro_noise * p.gyro_noise;
  const Eigen::Vector3d noise(sa2, sa2, sg2);
  Matrix Q = G * noise.asDiagonal() * G.transpose();
  const double vw2 = p.velocity_walk * p.velocity_walk * dt;
  Q(kVx, kVx) += vw2;
  Q(kVy, kVy) += vw2;
  Q(kBax, kBax) += p.accel_bias_walk * p.accel_bias_walk * dt;
  Q(kBay, kBay) += p.accel_bias_walk * p.accel_bias_walk * dt;
  Q(kBr, kBr) += p.gyro_bias_walk * p.gyro_bias_walk * dt;

  x_(kX) += dx;
  x_(kY) += dy;
  x_(kYaw) = wrap_angle(yawn);
  x_(kVx) = vxn;
  x_(kVy) = vyn;
  x_(kR) = rn;
  P_ = F * P_ * F.transpose() + Q;
  P_ = 0.5 * (P_ + P_.transpose()).eval();
}

void VelocityEkf::update(double innovation, const Vector& H, double var) {
  const Vector PH = P_ * H;
  const double S = H.dot(PH) + var;
  if (!(S > 0.0)) return;
  // the position is left as integrated (see the header): its gain rows are
  // zero, and with a gain that is not the optimal one the covariance takes
  // the Joseph form
  Vector K = PH / S;
  K(kX) = K(kY) = 0.0;
  x_ += K * innovation;
  const Matrix IKH = Matrix::Identity() - K * H.transpose();
  P_ = IKH * P_ * IKH.transpose() + var * K * K.transpose();
  P_ = 0.5 * (P_ + P_.transpose()).eval();
  x_(kYaw) = wrap_angle(x_(kYaw));
}

double VelocityEkf::modelled_slip() const {
  if (!has_imu_) return 0.0;
  // the longitudinal acceleration of the base origin: the IMU's, bias
  // corrected, less its centripetal lever-arm term (-r^2 mx)
  const double r = x_(kR);
  const double ax = ax_m_ - x_(kBax) + r * r * geometry_.imu_x;
  const double vx = x_(kVx);
  return geometry_.slip_per_accel * (ax + geometry_.drag_per_mass * vx * std::abs(vx));
}

EkfStatus VelocityEkf::on_steering(const hal::SteeringAngle& m) {
  if (!finite(m.angle) || (has_steering_ && m.stamp < steering_stamp_)) {
    ++rejected_;
    return EkfStatus::Rejected;
  }
  steering_ = m.angle;
  steering_stamp_ = m.stamp;
  has_steering_ = true;
  return EkfStatus::Ok;
}

bool VelocityEkf::at_rest(const hal::WheelSpeeds& m, double ax, double ay) {
  // every wheel still and the IMU quiet for standstill_time (a car whose
  // wheels have just stopped may still creep on its tyres' deflections)
  const VelocityEkfParams& p = params_;
  bool still = has_imu_;
  for (double w : m.omega) still = still && std::abs(w) <= p.standstill_wheel_speed;
  still = still && std::hypot(ax, ay) <= p.standstill_accel && std::abs(x_(kR)) <= p.standstill_yaw_rate;
  if (!still) still_since_.reset();
  else if (!still_since_) still_since_ = m.stamp;
  return still && m.stamp - *still_since_ >= from_seconds(p.standstill_time);
}

void VelocityEkf::zero_velocity_update() {
  const double var = params_.standstill_std * params_.standstill_std;
  for (std::size_t k : {kVx, kVy, kR}) {
    Vector H = Vector::Zero();
    H(k) = 1.0;
    update(-x_(k), H, var);
  }
  wheels_used_ = 4;
  acquired_ = true;
}

VelocityEkf::WheelModel VelocityEkf::wheel_model(const hal::WheelSpeeds& m, double kappa) const {
  const VelocityEkfParams& p = params_;
  const double R = geometry_.wheel_radius;
  const double r = x_(kR);
  WheelModel w;
  // the slip's error: one part common to the four wheels (the same force
  // on the same tyres: what the model gets wrong, it gets wrong for all),
  // one part each wheel's own (load transfer, brake balance)
  const double common_sigma = p.slip_std + p.slip_model_error * std::abs(kappa);
  // (in a corner the inner and outer tyres' combined slips differ: a
  // left-right difference of 0.1 % at 1.5 g that would read as 0.01 rad/s
  // of yaw rate for as long as the corner lasts)
  const double own_sigma = p.wheel_slip_std + p.wheel_slip_model_error * std::abs(kappa) +
                           p.wheel_slip_lateral * std::abs(r * x_(kVx));
  // each wheel's model: predicted reading, Jacobian, slip sensitivity, the vx it implies
  std::array<double, 4> slip{};
  for (std::size_t i = 0; i < 4; ++i) {
    const double d = i < 2 ? steering_ : 0.0;
    const double cd = std::cos(d), sd = std::sin(d);
    const double px = wheel_x_[i], py = wheel_y_[i];
    const double vy = x_(kVy), vx = x_(kVx);
    const double u = (vx - r * py) * cd + (vy + r * px) * sd;
    const double scale = std::max(std::abs(u), kSlipSpeedFloor);
    const double h = (u + kappa * scale) / R;
    // d h / d u: 1 + k sign(u) above the slip's speed floor
    const double dh = 1.0 + (std::abs(u) > kSlipSpeedFloor ? std::copysign(kappa, u) : 0.0);
    // the Jacobian leaves out the lateral term (vy + r px) sin d of the
    // steered wheels: what it would observe, the front axle's lateral
    // velocity, is drowned by the difference of the front and rear tyres'
    // slips (0.1 % of 15 m/s reads as 0.13 m/s of it at 0.1 rad of
    // steering) and would leak into vy, r and the gyro bias
    w.H[i] = Vector::Zero();
    w.H[i](kVx) = dh * cd / R;
    w.H[i](kR) = -dh * py * cd / R;
    w.nu[i] = m.omega[i] - h;
    slip[i] = scale / R;  // rad/s per unit slip ratio
    // the vx for which this wheel's reading is the prediction (cd > 0: |d| < pi/2)
    w.implied[i] = vx + w.nu[i] * R / std::max(dh * cd, 0.1);
  }
  // the measurement covariance: encoder noise and own slip on the diagonal,
  // the common slip fully correlated: C = c^2 s s^T
  for (std::size_t i = 0; i < 4; ++i)
    for (std::size_t j = 0; j < 4; ++j) w.C(i, j) = common_sigma * common_sigma * slip[i] * slip[j];
  for (std::size_t i = 0; i < 4; ++i) w.C(i, i) += p.wheel_noise * p.wheel_noise + own_sigma * own_sigma * slip[i] * slip[i];
  return w;
}

std::array<bool, 4> VelocityEkf::consistent_wheels(const WheelModel& w, double kappa) const {
  const VelocityEkfParams& p = params_;
  // the reference: the median, or under a driving (braking) force the slowest (fastest) wheel
  std::array<double, 4> sorted = w.implied;
  std::sort(sorted.begin(), sorted.end());
  double reference = 0.5 * (sorted[1] + sorted[2]);
  if (acquired_ && kappa > p.drive_threshold) reference = sorted[0];
  if (acquired_ && kappa < -p.drive_threshold) reference = sorted[3];
  const double tolerance = p.consistency_tolerance + p.consistency_relative * std::abs(reference);
  std::array<bool, 4> use{};
  for (std::size_t i = 0; i < 4; ++i) {
    const double S = w.H[i].dot(P_ * w.H[i]) + w.C(i, i);
    use[i] = std::abs(w.implied[i] - reference) <= tolerance && (!acquired_ || w.nu[i] * w.nu[i] <= p.wheel_gate * S);
  }
  return use;
}

int VelocityEkf::wheel_update(WheelModel w, const std::array<bool, 4>& use) {
  // the accepted wheels together (their slip errors are correlated): a
  // fixed 4 x 4 update in which a rejected wheel is a row of zeros with a
  // unit variance of its own (it then moves nothing)
  Eigen::Matrix<double, 4, 9> Hu = Eigen::Matrix<double, 4, 9>::Zero();
  Eigen::Vector4d nuu = Eigen::Vector4d::Zero();
  int used = 0;
  for (std::size_t i = 0; i < 4; ++i) {
    if (!use[i]) continue;
    ++used;
    Hu.row(static_cast<Eigen::Index>(i)) = w.H[i].transpose();
    nuu(static_cast<Eigen::Index>(i)) = w.nu[i];
  }
  for (std::size_t i = 0; i < 4; ++i)
    for (std::size_t j = 0; j < 4; ++j)
      if (!use[i] || !use[j]) w.C(i, j) = i == j ? 1.0 : 0.0;
  if (used == 0) return 0;
  const Eigen::Matrix<double, 9, 4> PHt = P_ * Hu.transpose();
  const Eigen::Matrix4d S = Hu * PHt + w.C;
  const Eigen::LLT<Eigen::Matrix4d> llt(S);
  if (llt.info() != Eigen::Success) return used;
  // K = P H^T S^-1 with the position's rows zero (update()'s Joseph form)
  Eigen::Matrix<double, 9, 4> K = llt.solve(PHt.transpose()).transpose();
  K.row(kX).setZero();
  K.row(kY).setZero();
  x_ += K * nuu;
  const Matrix IKH = Matrix::Identity() - K * Hu;
  P_ = IKH * P_ * IKH.transpose() + K * w.C * K.transpose();
  P_ = 0.5 * (P_ + P_.transpose()).eval();
  x_(kYaw) = wrap_angle(x_(kYaw));
  return used;
}

void VelocityEkf::rear_slip_update() {
  // the rear axle's lateral slip: vy = -r vx^2 / (g C), the model's value
  // taken as the measurement of vy alone (its Jacobian left out on purpose:
  // the model's error must not leak into vx, r or the gyro bias)
  const double model = -x_(kR) * x_(kVx) * x_(kVx) / (kGravity * geometry_.cornering_stiffness);
  Vector Hy = Vector::Zero();
  Hy(kVy) = 1.0;
  const double sigma = params_.vy_std + params_.vy_relative * std::abs(model);
  const double nu = model - x_(kVy);
  // past the gate the car slides: the tyres are out of the model's range
  if (params_.vy_gate > 0.0 && nu * nu > params_.vy_gate * (P_(kVy, kVy) + sigma * sigma)) {
    ++vy_gated_;
    return;
  }
  update(nu, Hy, sigma * sigma);
}

EkfStatus VelocityEkf::on_wheel_speeds(const hal::WheelSpeeds& m) {
  const VelocityEkfParams& p = params_;
  bool ok = true;
  for (double w : m.omega) ok = ok && finite(w);
  if (!ok || (has_wheels_ && m.stamp < wheel_stamp_) ||
      (started_ && m.stamp < stamp_ - from_seconds(p.max_wheel_lag))) {
    ++rejected_;
    return EkfStatus::Rejected;
  }
  start_if_needed(m.stamp);
  const Vector x0 = x_;
  const Matrix P0 = P_;
  // a message ahead of the newest IMU sample: predict to it with that sample held
  if (m.stamp > stamp_) {
    predict(to_seconds(m.stamp - stamp_), ax_m_, ay_m_, has_imu_ ? g_m_ : x_(kR) + x_(kBr));
    stamp_ = m.stamp;
  }
  has_wheels_ = true;
  wheel_stamp_ = m.stamp;

  const double r = x_(kR);
  const double ax = has_imu_ ? ax_m_ - x_(kBax) + r * r * geometry_.imu_x : 0.0;
  const double ay = has_imu_ ? ay_m_ - x_(kBay) : 0.0;
  if (at_rest(m, ax, ay)) {
    zero_velocity_update();
  } else {
    const double kappa = modelled_slip();
    const WheelModel w = wheel_model(m, kappa);
    const int used = wheel_update(w, consistent_wheels(w, kappa));
    wheels_used_ = used;
    if (used >= 2) acquired_ = true;
    rear_slip_update();
  }
  if (!state_finite()) {
    x_ = x0;
    P_ = P0;
    ++rejected_;
    return EkfStatus::Rejected;
  }
  return EkfStatus::Ok;
}

VelocityEstimate VelocityEkf::estimate() const {
  VelocityEstimate e;
  e.stamp = stamp_;
  e.pose = Pose2{x_(kX), x_(kY), x_(kYaw)};
  e.vx = x_(kVx);
  e.vy = x_(kVy);
  e.yaw_rate = x_(kR);
  e.accel_bias_x = x_(kBax);
  e.accel_bias_y = x_(kBay);
  e.gyro_bias = x_(kBr);
  for (std::size_t i = 0; i < kStateSize; ++i) e.variance[i] = P_(i, i);
  e.wheels_used = wheels_used_;
  return e;
}

}  // namespace paddock::estimation
