#pragma once
// the bound check the sensors' validate() functions share
#include <string>

namespace paddock::sensors {

// "no upper bound" that still prints as a number
inline constexpr double kNoUpperBound = 1e300;

// "" when value is finite and lo <= value <= hi, else
// "<name> must be a finite number in [lo, hi] unit (got value)"
std::string check_range(const char* name, double value, double lo, double hi, const char* unit);

}  // namespace paddock::sensors
