// the closed loop against independent figures: the lap the car drives against
// the lap its own reference trajectory predicts, the tracking metrics against a
// recomputation from the log by their README definitions, and physical limits
#include <gtest/gtest.h>

#include <cmath>

#include "autonomy/planning/reference.h"
#include "sim/runner/scenario.h"
#include "sim/runner/simulation.h"
#include "sim/world/track.h"

namespace paddock::runner {
namespace {

const std::string kRoot = PADDOCK_SOURCE_DIR;

struct LoopRun {
  Scenario scenario;
  world::TrackModel track;
  RunResult result;
};

const LoopRun& default_run() {
  static const LoopRun r = [] {
    LoopRun out;
    // the ground-truth centreline: the reference is known, so the laps can be
    // checked against it (and the cones need not be perceived); the paper's
    // stack, whose profile the centreline was planned for
    out.scenario = load_scenario(kRoot + "/scenarios/fsg_2023_trackdrive_paper.ini",
                                 {"autonomy.planner=oracle", "autonomy.perception=ground_truth"});
    out.track = world::build_track(load_track_file(out.scenario.track_path));
    out.result = run(out.scenario, out.track);
    return out;
  }();
  return r;
}

TEST(ClosedLoop, FlyingLapsMatchTheReferenceTrajectorysOwnLapTime) {
  const LoopRun& r = default_run();
  ASSERT_TRUE(r.result.event.finished) << r.result.event.dnf_reason;
  // the reference as the stack plans it, timed at its own speeds
  const auto ref = planning::build_reference(r.track.centreline, true, stack_params(r.scenario).planning.reference);
  ASSERT_TRUE(ref.ok()) << ref.reason;
  const double planned = planning::lap_time(ref.trajectory);
  // laps 2..10 start at speed, as the profile assumes; a car that tracks the
  // profile drives them within a few percent of the prediction
  for (std::size_t i = 1; i < r.result.event.laps.size(); ++i) {
    EXPECT_NEAR(r.result.event.laps[i].time, planned, 0.03 * planned) << "lap " << i + 1;
  }
}

TEST(ClosedLoop, TrackingMetricsFollowTheirDefinitions) {
  const LoopRun& r = default_run();
  const auto& laps = r.result.event.laps;
  ASSERT_EQ(laps.size(), 10u);
  const double dt = 1.0 / r.scenario.sim.log_rate;
  double all_sq = 0.0, all_max = 0.0, itae_sum = 0.0;
  int all_n = 0;
  for (const events::Lap& lap : laps) {
    // the samples inside the lap, by time, from the log alone
    double sq = 0.0, mx = 0.0, itae = 0.0;
    int n = 0;
    for (const LogRow& row : r.result.log) {
      if (row.t < lap.start || row.t >= lap.start + lap.time) continue;
      const double e = std::abs(row.lateral_error);
      sq += e * e;
      mx = std::max(mx, e);
      itae += (row.t - lap.start) * e * dt;
      ++n;
    }
    const auto& tr = r.result.lap_tracking[static_cast<std::size_t>(lap.number - 1)];
    // a sample at the very crossing may fall on either side: allow one sample's worth
    EXPECT_NEAR(tr.rms, std::sqrt(sq / n), 1e-3);
    EXPECT_NEAR(tr.max, mx, 1e-9);
    EXPECT_NEAR(tr.itae, itae, 0.01 * itae + lap.time * 0.3 * dt);
    all_sq += sq;
    all_n += n;
    all_max = std::max(all_max, mx);
    itae_sum += itae;
  }
  EXPECT_NEAR(r.result.tracking.rms, std::sqrt(all_sq / all_n), 1e-3);
  EXPECT_NEAR(r.result.tracking.max, all_max, 1e-9);
  const double nlaps = static_cast<double>(laps.size());
  EXPECT_NEAR(r.result.tracking.itae, itae_sum / nlaps, 0.01 * itae_sum / nlaps);
}

TEST(ClosedLoop, TheCarStaysWithinWhatItsTyresCanDo) {
  const LoopRun& r = default_run();
  // lateral acceleration v r of the base frame: below the tyres' mu g plus the
  // downforce at that speed, (D (m g + c_down v^2)) / m
  const auto& v = r.scenario.vehicle;
  double worst = 0.0;
  for (const LogRow& row : r.result.log) {
    const double speed = std::hypot(row.vx, row.vy);
    const double limit = v.tyre_d * (v.mass * kGravity + v.c_down * speed * speed) / v.mass;
    worst = std::max(worst, std::abs(row.vx * row.yaw_rate) / limit);
  }
  EXPECT_LT(worst, 1.0);
  EXPECT_GT(worst, 0.3);  // and it does use its grip
}

TEST(ClosedLoop, StopsAfterTheLastLapWithinTheZone) {
  const LoopRun& r = default_run();
  EXPECT_EQ(r.result.event.uss, 0);
  const LogRow& last = r.result.log.back();
  EXPECT_EQ(last.as_state, static_cast<int>(hal::AsState::Finished));
  EXPECT_LT(std::hypot(last.vx, last.vy), 0.05);
}

}  // namespace
}  // namespace paddock::runner
