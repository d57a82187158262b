#include "sim/sensors/param_check.h"

#include <cmath>
#include <sstream>

namespace paddock::sensors {

std::string check_range(const char* name, double value, double lo, double hi, const char* unit) {
  if (std::isfinite(value) && value >= lo && value <= hi) return {};
  std::ostringstream s;
  s << name << " must be a finite number in [" << lo << ", " << hi << "]" << (unit[0] ? " " : "") << unit
    << " (got " << value << ")";
  return s.str();
}

}  // namespace paddock::sensors
