#include "autonomy/common/cone.h"

namespace paddock {

std::string_view cone_tag(ConeColor c) {
  switch (c) {
    case ConeColor::Blue: return "blue";
    case ConeColor::Yellow: return "yellow";
    case ConeColor::SmallOrange: return "orange";
    case ConeColor::BigOrange: return "big_orange";
    case ConeColor::Unknown: return "unknown";
  }
  return "unknown";
}

ConeColor look_alike(ConeColor c) {
  switch (c) {
    case ConeColor::Blue: return ConeColor::Yellow;
    case ConeColor::Yellow: return ConeColor::Blue;
    case ConeColor::SmallOrange: return ConeColor::BigOrange;
    case ConeColor::BigOrange: return ConeColor::SmallOrange;
    case ConeColor::Unknown: return ConeColor::Unknown;
  }
  return ConeColor::Unknown;
}

}  // namespace paddock
