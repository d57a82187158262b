#pragma once
// the autonomous system (AS) state machine of the Formula Student rules
// (FS Rules 2024, T 14 "Autonomous System" and T 15 "Emergency Brake
// System"; the state diagram of the FSG AS beginners' guide):
//
//   AS Off -> AS Ready       ASMS on, the stack's mission selected, the EBS
//                            armed (its tank pressurised), the brakes closed,
//                            the stack ready to drive (a state estimate and
//                            a trajectory), no fault
//   AS Ready -> AS Driving   the RES's go, once the AS has been Ready for at
//                            least 5 s (an earlier go is ignored, and logged)
//   AS Ready -> AS Off       ASMS off
//   AS Driving -> AS Finished  the mission is over and the car at rest
//   Ready, Driving, Finished -> AS Emergency  the RES's emergency stop;
//                            Ready and Driving also on a fault the stack
//                            cannot drive with (a watchdog, a stalled cycle),
//                            the EBS disarmed (tank pressure lost), the ASMS
//                            switched off while driving
//   AS Finished, AS Emergency -> AS Off  ASMS off
//
// Every transition is kept with its time and reason, for the run's log. The
// machine decides the state only: what the car does in each (brakes closed
// outside Driving, the EBS in Emergency) is the stack's and the VCU's.
#include <string>
#include <vector>

#include "autonomy/common/params.h"
#include "autonomy/common/time.h"
#include "autonomy/hal/messages.h"

namespace paddock::stack {

// [as]
struct AsParams {
  // the rules: the go is accepted only after at least 5 s in AS Ready
  double ready_wait = 5.0;
  // the EBS counts as armed with at least this in its tank (a pneumatic EBS
  // stores ~8-10 bar; below the minimum its actuators cannot close the brakes)
  double ebs_pressure_min = 6.0;
  // both brake lines at least this: the brakes are closed (AS Ready needs them closed)
  double brakes_closed_pressure = 5.0;
  // AS Emergency: keep steering along the trajectory while the EBS brakes
  // (else the wheels go straight)
  bool steer_in_emergency = true;

  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(ready_wait), {"s", params::in(0.0, 600.0), "time in AS Ready before the go is accepted (the rules: 5 s)"});
    v(PADDOCK_PARAM(ebs_pressure_min), {"bar", params::in(0.0, 40.0), "the EBS's tank at least this: the EBS is armed"});
    v(PADDOCK_PARAM(brakes_closed_pressure), {"bar", params::in(0.0, 600.0), "both brake lines at least this: the brakes are closed"});
    v(PADDOCK_PARAM(steer_in_emergency), "AS Emergency: steer along the trajectory while the EBS brakes (else wheels straight)");
  }
};

// what the machine looks at in one control cycle
struct AsInputs {
  bool vcu_known = false;        // a VCU status has come (else the car's switches are unknown: AS Off)
  bool asms_on = false;
  bool mission_selected = false;  // the selector shows the stack's own mission
  double ebs_pressure = 0.0;      // bar
  double brake_pressure = 0.0;    // bar, the lower of the two lines
  bool stack_ready = false;       // a state estimate and a trajectory to drive
  bool go = false;                // the RES's go came since the last cycle
  bool res_emergency = false;     // the RES's emergency stop (latched by the caller)
  std::string fault;              // a fault the stack cannot drive with; empty: none
  bool mission_done = false;      // the mission is over and the car at rest
};

struct AsTransition {
  TimeNs t = 0;
  hal::AsState from = hal::AsState::Off;
  hal::AsState to = hal::AsState::Off;
  std::string reason;
};

class AsMachine {
 public:
  explicit AsMachine(const AsParams& params) : params_(params) {}

  // the state after this cycle's inputs
  hal::AsState update(TimeNs now, const AsInputs& in);

  hal::AsState state() const { return state_; }
  // every transition so far, oldest first
  const std::vector<AsTransition>& transitions() const { return transitions_; }
  // in AS Off: what Ready still waits for (empty once every condition holds);
  // the last go ignored and why, if any
  const std::string& waiting_for() const { return waiting_for_; }
  const std::string& ignored_go() const { return ignored_go_; }

 private:
  void step(TimeNs now, const AsInputs& in);
  void enter(TimeNs now, hal::AsState to, std::string reason);
  // why AS Ready cannot be entered (empty: it can)
  std::string not_ready(const AsInputs& in) const;

  AsParams params_;
  hal::AsState state_ = hal::AsState::Off;
  TimeNs entered_ = 0;  // when the current state was entered
  std::vector<AsTransition> transitions_;
  std::string waiting_for_ = "no VCU status yet";
  std::string ignored_go_;
};

}  // namespace paddock::stack
