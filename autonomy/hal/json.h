#pragma once
// the HAL messages that no wire of the car carries, as JSON: what a node with
// no hardware wire format of its own sends (the camera's detector node its
// boxes, an object-level cone sensor its cones, an INS its state). A run's log
// records them so (/hal/detections, /hal/cones, /hal/state), and the car
// binary takes them so on its objects port. Every number comes back to the
// bit (nlohmann's shortest round-trip doubles); +infinity, which JSON has no
// number for, travels as null.
//
//   {"type": "camera_detections", "stamp": ns, "width": px, "height": px,
//    "boxes": [{"x_min", "y_min", "x_max", "y_max", "color", "confidence"}]}
//   {"type": "cone_detections", "stamp": ns, "cones": [{"x", "y", "color",
//    "colour_from_camera"}], "free_range": [m or null]}
//   {"type": "state_estimate", "stamp": ns, "x", "y", "yaw", "vx", "vy", "yaw_rate"}
// color: ConeColor's number (0 blue, 1 yellow, 2 small orange, 3 big orange, 4 unknown).
#include <optional>
#include <string>

#include "autonomy/hal/messages.h"

namespace paddock::hal {

// the JSON of a camera_detections, cone_detections or state_estimate;
// nothing for a message a wire carries
std::optional<std::string> to_json(const SensorMessage& m);

// the message from its JSON; throws std::invalid_argument saying what is
// wrong (no JSON, an unknown type, a missing or mistyped field, a colour off
// the enum, a stamp below 0)
SensorMessage message_from_json(const char* data, std::size_t size);

}  // namespace paddock::hal
