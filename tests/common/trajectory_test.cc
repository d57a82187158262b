// the shared finite() check of a trajectory point: the fields a controller
// follows count, the arc-length coordinate does not.
#include "autonomy/common/trajectory.h"

#include <gtest/gtest.h>

#include <cmath>

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

}  // namespace
}  // namespace paddock
