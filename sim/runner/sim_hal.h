#pragma once
// the simulator's back end of the HAL: the runner posts sensor messages, the
// stack drains them and leaves its command here for the actuators.
#include <deque>
#include <optional>
#include <stdexcept>
#include <utility>
#include <variant>

#include "autonomy/hal/hal.h"

namespace paddock::runner {

class SimHal final : public hal::Hal {
 public:
  // true_state: whether the simulator may hand the stack its true state
  // (slam = ground_truth); otherwise posting a hal::StateEstimate is a bug
  // in the simulator and throws, so the truth can never reach the stack
  // unnoticed
  explicit SimHal(bool true_state = true) : true_state_(true_state) {}
  void post(hal::SensorMessage m) {
    if (!true_state_ && std::holds_alternative<hal::StateEstimate>(m))
      throw std::logic_error("the true state may not cross the HAL: the stack estimates its own (slam != ground_truth)");
    inbox_.push_back(std::move(m));
  }
  bool true_state() const { return true_state_; }
  std::optional<hal::SensorMessage> receive() override {
    if (inbox_.empty()) return std::nullopt;
    hal::SensorMessage m = std::move(inbox_.front());
    inbox_.pop_front();
    return m;
  }
  void send(const hal::ActuatorCommand& c) override { command_ = c; }
  // the last command sent, if any
  const std::optional<hal::ActuatorCommand>& command() const { return command_; }

 private:
  bool true_state_ = true;
  std::deque<hal::SensorMessage> inbox_;
  std::optional<hal::ActuatorCommand> command_;
};

}  // namespace paddock::runner
