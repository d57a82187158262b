#pragma once
// the sample mean and standard deviation (n - 1) the noise tests compare with
// their configured values
#include <cmath>
#include <vector>

namespace paddock::sensors::testing {

struct Stats {
  double mean;
  double stddev;
};

inline Stats stats(const std::vector<double>& v) {
  double sum = 0.0;
  for (double x : v) sum += x;
  const double mean = sum / static_cast<double>(v.size());
  double ss = 0.0;
  for (double x : v) ss += (x - mean) * (x - mean);
  return {mean, std::sqrt(ss / static_cast<double>(v.size() - 1))};
}

}  // namespace paddock::sensors::testing
