#pragma once
// the only door between the stack and the world: a simulator or a car behind it.
#include <optional>

#include "autonomy/hal/messages.h"

namespace paddock::hal {

class Hal {
 public:
  virtual ~Hal() = default;
  // the oldest message not yet received, or nothing
  virtual std::optional<SensorMessage> receive() = 0;
  // hands a command to the actuators
  virtual void send(const ActuatorCommand& command) = 0;
};

}  // namespace paddock::hal
