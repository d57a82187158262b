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

const char* to_string(MissionCode m) {
  switch (m) {
    case MissionCode::None: return "none";
    case MissionCode::Acceleration: return "acceleration";
    case MissionCode::Skidpad: return "skidpad";
    case MissionCode::Autocross: return "autocross";
    case MissionCode::Trackdrive: return "trackdrive";
    case MissionCode::EbsTest: return "ebs_test";
    case MissionCode::Inspection: return "inspection";
    case MissionCode::Manual: return "manual";
  }
  return "none";
}

}  // namespace paddock::hal
