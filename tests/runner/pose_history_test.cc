// PoseHistory::at (the true pose the raw sensors are cast from) against a
// brute-force reference: a linear scan for the first pose at or after t and
// the same interpolation, bit for bit, whatever the spacing of the poses
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <deque>
#include <random>
#include <utility>
#include <vector>

#include "autonomy/common/geometry.h"
#include "sim/runner/raw_sensors.h"

namespace {

using namespace paddock;
using paddock::runner::PoseHistory;

// the poses within the span, as PoseHistory keeps them, and the pose at t
// found by scanning them all
struct Reference {
  TimeNs span;
  std::deque<std::pair<TimeNs, Pose2>> poses;
  void record(TimeNs now, const Pose2& p) {
    poses.emplace_back(now, p);
    while (poses.size() > 2 && poses.front().first < now - span) poses.pop_front();
  }
  Pose2 at(TimeNs t) const {
    if (poses.empty()) return {};
    if (t <= poses.front().first) return poses.front().second;
    if (t >= poses.back().first) return poses.back().second;
    std::size_t k = 0;
    while (poses[k].first < t) ++k;
    const auto& [t1, p1] = poses[k];
    const auto& [t0, p0] = poses[k - 1];
    const double u = static_cast<double>(t - t0) / static_cast<double>(t1 - t0);
    return {p0.x + u * (p1.x - p0.x), p0.y + u * (p1.y - p0.y), p0.yaw + u * wrap_angle(p1.yaw - p0.yaw)};
  }
};

void expect_same(const Pose2& a, const Pose2& b, TimeNs t) {
  EXPECT_EQ(a.x, b.x) << "t = " << t;
  EXPECT_EQ(a.y, b.y) << "t = " << t;
  EXPECT_EQ(a.yaw, b.yaw) << "t = " << t;
}

// poses recorded `steps` apart (ns, cycled), queried at every time of a
// window around them: on the poses, between them, before and after
void check(const std::vector<TimeNs>& steps, TimeNs span, int records) {
  PoseHistory history(span);
  Reference ref{span, {}};
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  TimeNs now = 1000;
  Pose2 p{0.0, 0.0, 3.0};
  for (int i = 0; i < records; ++i) {
    p = {p.x + u(rng), p.y + u(rng), wrap_angle(p.yaw + 0.3 * u(rng))};
    history.record(now, p);
    ref.record(now, p);
    // on, just before and just after each kept pose, and times spread over the whole span and beyond
    for (const auto& [tp, pose] : ref.poses) {
      for (TimeNs t = tp - 2; t <= tp + 2; ++t) expect_same(history.at(t), ref.at(t), t);
    }
    for (int k = 0; k < 50; ++k) {
      const TimeNs t = now - span - 5 + static_cast<TimeNs>((0.5 + 0.5 * u(rng)) * static_cast<double>(span + 10));
      expect_same(history.at(t), ref.at(t), t);
    }
    if (::testing::Test::HasFailure()) return;
    now += steps[static_cast<std::size_t>(i) % steps.size()];
  }
}

TEST(PoseHistory, StepsOfOnePhysicsStepGiveTheScansPose) { check({1000000}, 200000000, 300); }

TEST(PoseHistory, UnevenStepsGiveTheScansPose) {
  // the guess at a steady spacing misses: the search finds the pose
  check({1000000, 3, 250000, 7000000, 1, 999999}, 20000000, 300);
}

TEST(PoseHistory, EmptyAndSinglePoseHistories) {
  PoseHistory history(1000);
  const Pose2 none = history.at(5);
  EXPECT_EQ(none.x, 0.0);
  history.record(10, Pose2{1.0, 2.0, 0.5});
  for (TimeNs t : {0, 10, 20}) {
    const Pose2 p = history.at(t);
    EXPECT_EQ(p.x, 1.0);
    EXPECT_EQ(p.y, 2.0);
    EXPECT_EQ(p.yaw, 0.5);
  }
}

}  // namespace
