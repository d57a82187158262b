// the shared finite() checks: every component counts, NaN and both infinities.
#include "autonomy/common/geometry.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

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

}  // namespace
}  // namespace paddock
