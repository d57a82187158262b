#pragma once
// |a - b| in units of b's last place (the spacing of doubles at b): the
// math tests' measure of a function against glibc's
#include <cmath>
#include <limits>

namespace paddock::testing {

inline double ulps(double a, double b) {
  const double spacing = std::nextafter(std::abs(b), std::numeric_limits<double>::infinity()) - std::abs(b);
  return std::abs(a - b) / spacing;
}

}  // namespace paddock::testing
