// the shared finite() check of a trajectory point: the fields a controller
// follows count, the arc-length coordinate does not.
#include "autonomy/common/trajectory.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

namespace paddock {
namespace {

TEST(Trajectory, FinitePointChecksWhatAControllerFollows) {
  const TrajectoryPoint ok{0.0, 1.0, 2.0, 0.5, 0.1, 8.0};
  EXPECT_TRUE(finite(ok));
  const double nan = std::nan("");
  for (double TrajectoryPoint::*field : {&TrajectoryPoint::x, &TrajectoryPoint::y, &TrajectoryPoint::heading,
                                         &TrajectoryPoint::curvature, &TrajectoryPoint::speed}) {
    TrajectoryPoint p = ok;
    p.*field = nan;
    EXPECT_FALSE(finite(p));
  }
  TrajectoryPoint p = ok;
  p.s = nan;
  EXPECT_TRUE(finite(p));
}

// a closed trajectory's arc length wrapped into [0, length): the bits fmod gives
TEST(Trajectory, ClosedWrapGivesTheBitsOfFmod) {
  Trajectory t;
  t.closed = true;
  t.length = 318.37;
  std::vector<double> s = {0.0, -0.0, t.length, -t.length, std::nextafter(t.length, 0.0), 2.5 * t.length,
                           -2.5 * t.length, 1e-300, -1e-300};
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-3.0 * t.length, 3.0 * t.length);
  for (int i = 0; i < 100000; ++i) s.push_back(u(rng));
  for (const double x : s) {
    double expected = std::fmod(x, t.length);
    if (expected < 0.0) expected += t.length;
    const double w = t.wrap(x);
    EXPECT_EQ(std::memcmp(&w, &expected, sizeof w), 0) << x << ": " << w << " against " << expected;
  }
  EXPECT_TRUE(std::isnan(t.wrap(std::nan(""))));
}

}  // namespace
}  // namespace paddock
