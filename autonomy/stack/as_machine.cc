#include "autonomy/stack/as_machine.h"

#include <utility>

#include "autonomy/common/format.h"

namespace paddock::stack {

namespace {

std::string bar(double p) { return fixed(p, 1) + " bar"; }

}  // namespace

void AsMachine::enter(TimeNs now, hal::AsState to, std::string reason) {
  transitions_.push_back({now, state_, to, std::move(reason)});
  state_ = to;
  entered_ = now;
}

std::string AsMachine::not_ready(const AsInputs& in) const {
  if (!in.vcu_known) return "no VCU status yet";
  if (!in.asms_on) return "ASMS off";
  if (!in.mission_selected) return "the selected mission is not the stack's";
  if (in.ebs_pressure < params_.ebs_pressure_min)
    return "EBS not armed (tank " + bar(in.ebs_pressure) + ", needs " + bar(params_.ebs_pressure_min) + ")";
  if (in.brake_pressure < params_.brakes_closed_pressure)
    return "brakes not closed (" + bar(in.brake_pressure) + ", needs " + bar(params_.brakes_closed_pressure) + ")";
  if (!in.fault.empty()) return in.fault;
  if (in.res_emergency) return "RES emergency stop pressed";
  if (!in.stack_ready) return "no state estimate or trajectory yet";
  return "";
}

hal::AsState AsMachine::update(TimeNs now, const AsInputs& in) {
  // one cycle takes one transition, except that a car just Ready may take
  // the go in the same cycle (with no ready wait)
  step(now, in);
  if (state_ == hal::AsState::Ready && !transitions_.empty() && transitions_.back().t == now) step(now, in);
  return state_;
}

void AsMachine::step(TimeNs now, const AsInputs& in) {
  using hal::AsState;
  const bool asms_off = in.vcu_known && !in.asms_on;
  switch (state_) {
    case AsState::Off:
      waiting_for_ = not_ready(in);
      if (waiting_for_.empty()) enter(now, AsState::Ready, "ASMS on, mission selected, EBS armed, brakes closed, stack ready");
      break;
    case AsState::Ready:
    case AsState::Driving: {
      const bool driving = state_ == AsState::Driving;
      if (in.res_emergency) {
        enter(now, AsState::Emergency, "RES emergency stop");
      } else if (!in.fault.empty()) {
        enter(now, AsState::Emergency, in.fault);
      } else if (in.ebs_pressure < params_.ebs_pressure_min) {
        enter(now, AsState::Emergency, "EBS disarmed: tank " + bar(in.ebs_pressure) + " below " + bar(params_.ebs_pressure_min));
      } else if (asms_off) {
        if (driving) {
          enter(now, AsState::Emergency, "ASMS switched off while driving");
        } else {
          enter(now, AsState::Off, "ASMS switched off");
        }
      } else if (!driving && in.go) {
        const TimeNs ready_for = now - entered_;
        if (ready_for >= from_seconds(params_.ready_wait)) {
          enter(now, AsState::Driving, "go");
        } else {
          ignored_go_ = "go ignored at " + fixed(to_seconds(now), 3) + " s: " + fixed(to_seconds(ready_for), 3) +
                        " s in AS Ready, the rules ask for " + fixed(params_.ready_wait, 3) + " s";
        }
      } else if (driving && in.mission_done) {
        enter(now, AsState::Finished, "mission over, at rest");
      }
      break;
    }
    case AsState::Finished:
      if (in.res_emergency) {
        enter(now, AsState::Emergency, "RES emergency stop");
      } else if (asms_off) {
        enter(now, AsState::Off, "ASMS switched off");
      }
      break;
    case AsState::Emergency:
      if (asms_off) enter(now, AsState::Off, "ASMS switched off");
      break;
  }
}

}  // namespace paddock::stack
