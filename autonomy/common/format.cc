#include "autonomy/common/format.h"

#include <cstdio>

namespace paddock {

std::string fixed(double v, int decimals) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

}  // namespace paddock
