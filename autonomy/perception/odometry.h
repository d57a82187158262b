#pragma once
// planar dead reckoning of the base frame from the wheel speeds and the IMU's
// yaw rate, kept over a short history so that the LiDAR pipeline can ask where
// the base stood at any column's time relative to the scan's reference time
// (paper section "Lidar Perception": motion correction).
//
// Model: the base origin (rear axle centre) moves along its own x axis at the
// speed v of the rear wheels and turns at the gyro's yaw rate w:
//   x' = v cos(yaw), y' = v sin(yaw), yaw' = w (but for u, below).
// v is the mean of the two REAR wheels' speeds times the rolling radius: the
// rear wheels are not steered, so each rolls along the base's x axis, and at
// lateral offsets +-track/2 their speeds are v -+ w track/2, whose mean is
// exactly the base origin's longitudinal speed, whatever the yaw rate (the
// front wheels are steered and see the lever arm of the wheelbase). The
// lateral velocity of the rear axle u is the stack's own estimate of it when
// lateral_velocity is on and the stack hands one in (add(StateEstimate): the
// velocity estimator's vy, which the tyres' slip angles make 1-2 m/s at
// 20 m/s in a hard turn, 10-20 cm over a rotation), and zero otherwise (no
// side slip there: a kinematic model). The base's velocity in its own frame
// is then (v, u):
//   x' = v cos(yaw) - u sin(yaw), y' = v sin(yaw) + u cos(yaw).
//
// Each message starts a new interval: between two consecutive message stamps
// v, u and w are held at their latest values (zero-order hold) and the motion
// is integrated exactly (a circular arc, a straight line when w = 0), so a
// constant speed, lateral velocity and yaw rate give the exact arc. A pose
// between two knots is the arc from the earlier one.
//
// No I/O, no clock, no global state.
#include <cmath>
#include <cstddef>
#include <deque>
#include <optional>
#include <string>

#include "autonomy/common/geometry.h"
#include "autonomy/common/params.h"
#include "autonomy/common/time.h"
#include "autonomy/hal/messages.h"

namespace paddock::perception {

struct OdometryParams {
  // dynamic rolling radius of the rear wheels (m): not a parameter of its
  // own, the runner fills it from the vehicle's ([vehicle] wheel_radius);
  // the default is the gotthard car's (scenarios/vehicles/gotthard.ini,
  // FSSIM r_dyn)
  double wheel_radius = 0.231;
  // a LiDAR rotation (0.1 s) plus the scan's latency, with room to spare
  double history = 2.0;
  // the wheel speeds come every 10 ms and the IMU every 5 ms, so a scan
  // that ends between two messages is always covered by 25 ms
  double extrapolation = 0.025;
  // the rear axle's lateral velocity u from the stack's estimate
  // (add(StateEstimate)); off: u = 0, the kinematic model. Off by default
  // for now: on, the perceived cones' lateral error at 20-25 m/s in a
  // 0.6 rad/s turn falls from 5.7 cm to 0.2 cm and FastSLAM's drift on a
  // fast 500 m oval halves, but three CI scenarios then clip a hairpin
  // cone whose margin was already thin (see the README)
  bool lateral_velocity = false;

  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(history), {"s", params::above(0.0), "how far back the history reaches behind the newest message"});
    v(PADDOCK_PARAM(extrapolation), {"s", params::at_least(0.0),
                                     "how far relative() may extrapolate before the first or after the last message with the held speed and yaw rate"});
    v(PADDOCK_PARAM(lateral_velocity), "the motion correction takes the stack's estimated lateral velocity of the rear axle (else none: a kinematic model)");
  }
  std::string check() const {
    if (std::isfinite(wheel_radius) && wheel_radius > 0.0) return "";
    return "wheel_radius must be > 0 m (got " + params::number(wheel_radius) + ")";
  }
};

class Odometry {
 public:
  // throws std::invalid_argument when params::validate(params) fails
  explicit Odometry(const OdometryParams& params = {});

  // a message whose values are not finite, or whose stamp lies before the
  // newest message seen, is ignored (and counted in rejected())
  void add(const hal::Imu& imu);
  void add(const hal::WheelSpeeds& wheels);
  // the estimate's lateral velocity vy only (the speed and the yaw rate come
  // from the wheels and the gyro); one older than the newest message is held
  // from that message on. Ignored unless params().lateral_velocity
  void add(const hal::StateEstimate& estimate);

  // the pose of the base at `to` expressed in the base frame at `from`;
  // nullopt when the history (both signals known) does not cover both times
  // within the extrapolation tolerance
  std::optional<Pose2> relative(TimeNs from, TimeNs to) const;

  // relative(from, to[i]) for i < n into out[i], the same values to the bit,
  // for many times against one `from` (the motion correction's per-column
  // poses): pose_at(from) and its inverse rotation are taken once, and the
  // knots are walked along ascending times instead of searched for each.
  // False (out then holds no meaning) when relative() would give nullopt for
  // any of them
  bool relative(TimeNs from, const TimeNs* to, std::size_t n, Pose2* out) const;

  // the dead-reckoned pose at t in the odometry's own frame (its origin: the
  // pose where both signals were first known); nullopt as for relative()
  std::optional<Pose2> pose_at(TimeNs t) const;

  std::size_t rejected() const { return rejected_; }
  // the same params and state, bit for bit (the counts of rejected messages
  // aside): every question to either has the same answer
  bool same_state(const Odometry& other) const;
  const OdometryParams& params() const { return params_; }

 private:
  // a knot: the pose at `stamp` and the speed and yaw rate held from it on
  struct Knot {
    TimeNs stamp = 0;
    Pose2 pose;
    double v = 0.0;  // m/s
    double w = 0.0;  // rad/s
    double u = 0.0;  // m/s, lateral
  };

  // advance to `stamp` with the held values, then hold the new ones
  void step(TimeNs stamp);
  static Pose2 arc(const Knot& k, double dt);

  OdometryParams params_;
  std::deque<Knot> knots_;
  bool has_v_ = false, has_w_ = false;
  double v_ = 0.0, w_ = 0.0, u_ = 0.0;
  TimeNs newest_ = 0;
  bool any_ = false;
  std::size_t rejected_ = 0;
};

}  // namespace paddock::perception
