// the shared finite() checks: every component counts, NaN and both
// infinities; wrap_angle against the plain fmod form, bit for bit.
#include "autonomy/common/geometry.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

namespace paddock {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
const double kNan = std::nan("");

TEST(Geometry, FiniteDouble) {
  EXPECT_TRUE(finite(0.0));
  EXPECT_TRUE(finite(-1e308));
  EXPECT_TRUE(finite(std::numeric_limits<double>::denorm_min()));
  EXPECT_FALSE(finite(kNan));
  EXPECT_FALSE(finite(kInf));
  EXPECT_FALSE(finite(-kInf));
  EXPECT_TRUE(finite(1.5f));  // a float is checked as the double it promotes to
}

TEST(Geometry, FiniteVec2AndPose2) {
  EXPECT_TRUE(finite(Vec2{1.0, -2.0}));
  for (double bad : {kNan, kInf, -kInf}) {
    EXPECT_FALSE(finite(Vec2{bad, 0.0}));
    EXPECT_FALSE(finite(Vec2{0.0, bad}));
    EXPECT_FALSE(finite(Pose2{bad, 0.0, 0.0}));
    EXPECT_FALSE(finite(Pose2{0.0, bad, 0.0}));
    EXPECT_FALSE(finite(Pose2{0.0, 0.0, bad}));
  }
  EXPECT_TRUE(finite(Pose2{3.0, 4.0, -kPi}));
}

// wrap_angle as written before its fast path: fmod on every call
double wrap_angle_by_fmod(double a) {
  a = std::fmod(a + kPi, 2.0 * kPi);
  if (a < 0.0) a += 2.0 * kPi;
  return a - kPi;
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

TEST(Geometry, WrapAngleGivesTheBitsOfTheFmodForm) {
  std::vector<double> angles = {0.0, -0.0, kPi, -kPi, 2.0 * kPi, -2.0 * kPi, 3.0 * kPi, -3.0 * kPi, 1e-300, -1e-300,
                                std::nextafter(kPi, 0.0), std::nextafter(-kPi, 0.0), std::nextafter(kPi, 4.0),
                                std::nextafter(-kPi, -4.0), 1e6, -1e6, 1e300, kInf, -kInf, kNan};
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> near(-4.0 * kPi, 4.0 * kPi), far(-1e4, 1e4);
  for (int i = 0; i < 100000; ++i) angles.push_back(i % 2 ? near(rng) : far(rng));
  int outside = 0;
  for (const double a : angles) {
    const double w = wrap_angle(a), expected = wrap_angle_by_fmod(a);
    if (std::isnan(expected)) {
      EXPECT_TRUE(std::isnan(w)) << a;
      continue;
    }
    EXPECT_TRUE(same_bits(w, expected)) << a << ": " << w << " against " << expected;
    // (within [-pi, pi]: an angle one ulp below -pi wraps to 2 pi - 1e-16,
    // which rounds to 2 pi, and so comes out as pi)
    EXPECT_GE(w, -kPi);
    EXPECT_LE(w, kPi);
    outside += !(a + kPi >= 0.0 && a + kPi < 2.0 * kPi);
  }
  EXPECT_GT(outside, 10000);  // both paths are exercised
}

}  // namespace
}  // namespace paddock
