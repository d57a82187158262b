// fast_atan2 against glibc's correctly rounded std::atan2: the error in
// units in the last place over a million random argument pairs, half near
// the unit circle, half spread over 40 orders of magnitude, in every octant;
// and the special values (zeros of both signs, infinities, NaN) one by one.
#include "autonomy/common/fast_math.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "tests/common/ulps.h"

namespace paddock {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

using testing::ulps;

// a magnitude from 1e-20 to 1e20, log-uniform, either sign
double spread(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> e(-20.0, 20.0), s(0.0, 1.0);
  const double m = std::pow(10.0, e(rng));
  return s(rng) < 0.5 ? -m : m;
}

TEST(FastMath, Atan2IsWithinOneUlpOfTheLibraryInEveryOctant) {
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);  // both folds (|y/x| past 0.66 and under)
  double worst = 0.0, worst_abs = 0.0;
  for (int i = 0; i < 1000000; ++i) {
    const double y = i % 2 == 0 ? unit(rng) : spread(rng);
    const double x = i % 2 == 0 ? unit(rng) : spread(rng);
    const double a = fast_atan2(y, x), b = std::atan2(y, x);
    worst = std::max(worst, ulps(a, b));
    worst_abs = std::max(worst_abs, std::abs(a - b));
  }
  std::printf("fast_atan2: worst %.2f ulp, %.3g rad\n", worst, worst_abs);
  // near +-pi and +-pi/2 the last place is 2.2e-16 or 4.4e-16 rad; pi's
  // own rounding adds at most 1.2e-16 rad
  EXPECT_LE(worst, 1.5);
  EXPECT_LE(worst_abs, 5e-16);
}

TEST(FastMath, SpecialValuesAreTheLibrarys) {
  const double nan = std::nan("");
  for (double y : {0.0, -0.0, 1.0, -1.0, kInf, -kInf}) {
    for (double x : {0.0, -0.0, 1.0, -1.0, kInf, -kInf}) {
      if (std::isinf(x) && std::isinf(y)) continue;  // documented: NaN, the library pi/4's odd multiples
      const double a = fast_atan2(y, x), b = std::atan2(y, x);
      EXPECT_EQ(a, b) << "atan2(" << y << ", " << x << ")";
      EXPECT_EQ(std::signbit(a), std::signbit(b)) << "atan2(" << y << ", " << x << ")";
    }
  }
  EXPECT_TRUE(std::isnan(fast_atan2(nan, 1.0)));
  EXPECT_TRUE(std::isnan(fast_atan2(1.0, nan)));
  EXPECT_TRUE(std::isnan(fast_atan2(kInf, kInf)));
}

}  // namespace
}  // namespace paddock
