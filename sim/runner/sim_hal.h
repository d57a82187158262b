#pragma once
// the simulator's back end of the HAL: the runner posts sensor messages, the
// stack drains them and leaves its command here for the actuators.
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <stdexcept>
#include <utility>
#include <variant>
#include <vector>

#include "autonomy/hal/hal.h"
#include "sim/runner/wire.h"

namespace paddock::runner {

class SimHal final : public hal::Hal {
 public:
  // true_state: whether the simulator may hand the stack its true state
  // (slam = ground_truth); otherwise posting a hal::StateEstimate is a bug
  // in the simulator and throws, so the truth can never reach the stack
  // unnoticed. wire: transport = wire (what the car sends on its wires goes
  // through them), or none (transport = memory)
  explicit SimHal(bool true_state = true, std::unique_ptr<WireLink> wire = nullptr)
      : true_state_(true_state), wire_(std::move(wire)) {}
  void post(hal::SensorMessage m) {
    if (!true_state_ && std::holds_alternative<hal::StateEstimate>(m))
      throw std::logic_error("the true state may not cross the HAL: the stack estimates its own (slam != ground_truth)");
    if (wire_ && WireLink::on_can(m)) return wire_->carry(m, inbox_, now_);
    if (wire_ && wire_->has_lidar() && std::holds_alternative<hal::LidarScan>(m))
      throw std::logic_error("transport = wire: the LiDAR's scans cross the HAL as its packets (post_lidar)");
    if (tap_) tap_->message(now_, m);
    if (remote()) return wire_->send_object(now_, m);
    inbox_.push_back(std::move(m));
  }
  // transport = udp: the stack runs in a car binary, not in this process
  bool remote() const { return wire_ && wire_->remote(); }
  // transport = udp: the car binary's control cycle at the current instant;
  // its command to the actuators
  void remote_cycle() {
    if (std::optional<hal::ActuatorCommand> d = wire_->remote_cycle(now_)) sent_ = command_ = *d;
  }
  // transport = wire: one LiDAR rotation's packets, decoded by the car's decoder
  void post_lidar(const std::vector<std::uint8_t>& packets) { wire_->carry_lidar(packets, inbox_, now_); }
  // the simulation's instant: what is posted and sent now crosses at it
  void set_now(TimeNs now) { now_ = now; }
  // who watches the traffic (a run's log); none: nobody
  void set_tap(WireTap* tap) {
    tap_ = tap;
    if (wire_) wire_->set_tap(tap);
  }
  bool true_state() const { return true_state_; }
  // the wire, when transport = wire
  WireLink* wire() const { return wire_.get(); }
  std::optional<hal::SensorMessage> receive() override {
    if (inbox_.empty()) return std::nullopt;
    hal::SensorMessage m = std::move(inbox_.front());
    inbox_.pop_front();
    return m;
  }
  // the command as the actuators take it: with the wire, what the car's VCU
  // decoded from the stack's frame (a frame it dropped leaves the last one)
  void send(const hal::ActuatorCommand& c) override {
    sent_ = c;
    if (!wire_) {
      command_ = c;
    } else if (std::optional<hal::ActuatorCommand> d = wire_->carry(c, now_)) {
      command_ = *d;
    }
  }
  // the last command as the actuators took it, if any
  const std::optional<hal::ActuatorCommand>& command() const { return command_; }
  // the last command as the stack sent it (before a wire quantised it)
  const std::optional<hal::ActuatorCommand>& sent() const { return sent_; }

 private:
  bool true_state_ = true;
  std::unique_ptr<WireLink> wire_;
  WireTap* tap_ = nullptr;
  TimeNs now_ = 0;
  std::deque<hal::SensorMessage> inbox_;
  std::optional<hal::ActuatorCommand> command_, sent_;
};

}  // namespace paddock::runner
