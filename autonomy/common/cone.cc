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

}  // namespace paddock
