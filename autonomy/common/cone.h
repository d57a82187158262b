#pragma once
// cones as the stack and the simulator name them (DESIGN.md conventions).
#include <string_view>

#include "autonomy/common/geometry.h"

namespace paddock {

// blue: left boundary; yellow: right; small orange: lanes of acceleration and
// skidpad; big orange: timekeeping lines; unknown: no colour known
enum class ConeColor { Blue, Yellow, SmallOrange, BigOrange, Unknown };

struct Cone {
  Vec2 position;
  ConeColor color = ConeColor::Unknown;
};

// the track-file tag of a colour: blue, yellow, orange, big_orange, unknown
std::string_view cone_tag(ConeColor c);

// the colour a classifier mistakes it for: blue <-> yellow, small <-> big
// orange (unknown stays unknown)
ConeColor look_alike(ConeColor c);

}  // namespace paddock
