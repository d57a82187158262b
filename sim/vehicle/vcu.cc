#include "sim/vehicle/vcu.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

namespace paddock::vehicle {

void Vcu::fire(TimeNs now, std::string cause) {
  if (ebs_at_) return;
  ebs_at_ = now;
  ebs_cause_ = std::move(cause);
}

void Vcu::command(TimeNs now, const hal::ActuatorCommand& c) {
  last_ = c;
  last_at_ = now;
  if (c.as_state == hal::AsState::Emergency) fire(now, "the ACU reported AS Emergency");
}

void Vcu::res_emergency(TimeNs now) { fire(now, "RES emergency stop"); }

DriverInput Vcu::actuate(TimeNs now) {
  const hal::AsState as = as_state();
  if ((as == hal::AsState::Ready || as == hal::AsState::Driving) && now - last_at_ > from_seconds(params_.acu_timeout)) {
    char why[96];
    std::snprintf(why, sizeof why, "no ACU command for %.3f s (the VCU's watchdog: %.3f s)", to_seconds(now - last_at_),
                  params_.acu_timeout);
    fire(now, why);
  }
  DriverInput in{0.0, 0.0, 1.0, 0.0};
  if (last_) in = DriverInput{last_->steering_angle, last_->throttle, last_->brake, last_->yaw_moment};
  if (ebs_at_) {
    // the shutdown circuit is open: no drive; the EBS closes the brakes once it has acted
    in.throttle = 0.0;
    in.yaw_moment = 0.0;
    if (now - *ebs_at_ >= from_seconds(params_.ebs_delay)) in.brake = 1.0;
  }
  brake_ = std::isnan(in.brake) ? 1.0 : std::clamp(in.brake, 0.0, 1.0);
  return in;
}

hal::VcuStatus Vcu::status(TimeNs now) const {
  const double line = brake_ * params_.brake_pressure_max;
  return hal::VcuStatus{now, true, mission_, ebs_tank_, line, line};
}

}  // namespace paddock::vehicle
