#pragma once
// the simulator's back end of the HAL: the runner posts sensor messages, the
// stack drains them and leaves its command here for the actuators.
#include <deque>
#include <optional>
#include <utility>

#include "autonomy/hal/hal.h"

namespace paddock::runner {

class SimHal final : public hal::Hal {
 public:
  void post(hal::SensorMessage m) { inbox_.push_back(std::move(m)); }
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
  std::deque<hal::SensorMessage> inbox_;
  std::optional<hal::ActuatorCommand> command_;
};

}  // namespace paddock::runner
