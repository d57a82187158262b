#include "autonomy/hal/messages.h"

namespace paddock::hal {

const char* to_string(AsState s) {
  switch (s) {
    case AsState::Off: return "off";
    case AsState::Ready: return "ready";
    case AsState::Driving: return "driving";
    case AsState::Finished: return "finished";
    case AsState::Emergency: return "emergency";
  }
  return "off";
}

}  // namespace paddock::hal
