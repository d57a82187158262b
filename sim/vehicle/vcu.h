#pragma once
// the car's vehicle control unit (VCU) and emergency brake system (EBS) as
// the simulator models them: what stands between the stack's command and the
// actuators, and what the rules make independent of the stack.
//
// The VCU passes the autonomous computer's (ACU's) command to the actuators
// and reports the safety chain on the bus (hal::VcuStatus: the ASMS, the
// selected mission, the EBS tank's and the brake lines' pressures). The EBS
// fires (latched) when
//   - the RES's emergency stop is pressed: it opens the shutdown circuit
//     directly, whatever the ACU does;
//   - the ACU reports AS Emergency;
//   - the ACU falls silent for acu_timeout while Ready or Driving (the VCU's
//     watchdog on the ACU's command).
// From the trigger the drive is off (the shutdown circuit opens the
// tractive system); after ebs_delay (the valves and the pneumatic
// actuator: the rules allow 200 ms of reaction, T 15.3) the EBS holds the
// brakes fully closed. The steering still takes the ACU's request (its last
// one if the ACU is silent).
#include <optional>
#include <string>

#include "autonomy/common/params.h"
#include "autonomy/common/time.h"
#include "autonomy/hal/messages.h"
#include "sim/vehicle/vehicle.h"

namespace paddock::vehicle {

// [vcu]
struct VcuParams {
  int status_rate = 50;               // Hz, VCU_Status
  double ebs_pressure = 10.0;         // bar in the charged EBS tank
  double brake_pressure_max = 100.0;  // bar in the brake lines at full brake
  double ebs_delay = 0.15;            // s from the EBS's trigger to the brakes fully closed by it
  double acu_timeout = 0.1;           // s without an ACU command (Ready or Driving): the EBS fires

  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(status_rate), {"Hz", params::in(1, 100000), "the VCU's status frame (ASMS, mission, EBS and brake pressures)"});
    v(PADDOCK_PARAM(ebs_pressure), {"bar", params::in(0.0, 40.0), "pressure in the charged EBS tank"});
    v(PADDOCK_PARAM(brake_pressure_max), {"bar", params::in(1.0, 600.0), "brake line pressure at full brake"});
    v(PADDOCK_PARAM(ebs_delay), {"s", params::in(0.0, 5.0), "from the EBS's trigger to the brakes fully closed by it"});
    v(PADDOCK_PARAM(acu_timeout), {"s", params::in(0.001, 60.0), "the VCU's watchdog: no ACU command for this long while Ready or Driving fires the EBS"});
  }
};

class Vcu {
 public:
  // mission: what the team set on the car's selector
  Vcu(const VcuParams& params, hal::MissionCode mission) : params_(params), mission_(mission), ebs_tank_(params.ebs_pressure) {}

  // the ACU's command, received now
  void command(TimeNs now, const hal::ActuatorCommand& c);
  // the RES's emergency stop, pressed now
  void res_emergency(TimeNs now);
  // the EBS tank's pressure from now on (a leak: a fault)
  void set_ebs_tank(double bar) { ebs_tank_ = bar; }

  // the watchdog, then what the actuators get now
  DriverInput actuate(TimeNs now);
  // the status frame's content now (the brake lines as the last actuation closed them)
  hal::VcuStatus status(TimeNs now) const;

  // the AS state the ACU reported last
  hal::AsState as_state() const { return last_ ? last_->as_state : hal::AsState::Off; }
  // when and why the EBS fired, if it did
  const std::optional<TimeNs>& ebs_fired() const { return ebs_at_; }
  const std::string& ebs_cause() const { return ebs_cause_; }

 private:
  void fire(TimeNs now, std::string cause);

  VcuParams params_;
  hal::MissionCode mission_;
  double ebs_tank_;
  std::optional<hal::ActuatorCommand> last_;
  TimeNs last_at_ = 0;
  std::optional<TimeNs> ebs_at_;
  std::string ebs_cause_;
  double brake_ = 1.0;  // the brake fraction the actuators got last (the car starts braked)
};

}  // namespace paddock::vehicle
