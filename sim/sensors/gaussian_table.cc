#include "sim/sensors/gaussian_table.h"

#include <cmath>

namespace paddock::sensors {

namespace {

// q_k by bisection on Phi(z) = erfc(-z / sqrt 2) / 2 over [-8, 8] (48 halvings:
// 6e-14) for the lower half, mirrored to the upper (an exactly symmetric
// table: mean 0)
std::array<double, kGaussianTableSize> build() {
  std::array<double, kGaussianTableSize> t{};
  for (std::size_t k = 0; k < t.size() / 2; ++k) {
    const double q = (static_cast<double>(k) + 0.5) / static_cast<double>(t.size());
    double lo = -8.0, hi = 8.0;
    for (int it = 0; it < 48; ++it) {
      const double mid = 0.5 * (lo + hi);
      (0.5 * std::erfc(-mid / std::sqrt(2.0)) < q ? lo : hi) = mid;
    }
    t[k] = 0.5 * (lo + hi);
    t[t.size() - 1 - k] = -t[k];
  }
  return t;
}

}  // namespace

const std::array<double, kGaussianTableSize>& gaussian_quantiles() {
  static const std::array<double, kGaussianTableSize> table = build();
  return table;
}

}  // namespace paddock::sensors
