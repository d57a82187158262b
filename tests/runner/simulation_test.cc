// the closed loop as model, state and step: a simulation stepped from outside
// is the one run() runs, and simulations of one model share nothing (two on
// two threads give what each gives alone)
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <thread>

#include "sim/runner/model.h"
#include "sim/runner/sim_hal.h"
#include "sim/runner/simulation.h"
#include "sim/sensors/lidar.h"
#include "tests/runner/run_paddock.h"

namespace paddock::runner {
namespace {

const std::string kRoot = PADDOCK_SOURCE_DIR;

// the default scenario (raw LiDAR and camera: the Embree scenes, the
// perception, the stack's random streams) for the first few seconds of driving
struct ScenarioOnTrack {
  Scenario scenario;
  world::TrackModel track;
};
const ScenarioOnTrack& default_setup() {
  static const ScenarioOnTrack s = [] {
    ScenarioOnTrack out;
    out.scenario = load_scenario(kRoot + "/scenarios/fsg_2023_trackdrive.ini", {"event.timeout=6"});
    out.track = world::build_track(load_track_file(out.scenario.track_path));
    return out;
  }();
  return s;
}

// steps a state of the model to the end, recording its log and perception metrics
struct Trace {
  std::vector<LogRow> log;
  long scans = 0;
  long steps = 0;
  long frames = 0;             // frames of cones the stack took in
  long slam_steps_beside = 0;  // of them, those SLAM took in on the perception's thread
  events::Result event;
};
Trace drive(const SimModel& model) {
  SimState state(model);
  LogRecorder log;
  PerceptionScorer scorer;
  Trace out;
  for (;;) {
    log.observe(model, state);
    scorer.observe(model, state);
    if (state.done) break;
    step(model, state);
    ++out.steps;
  }
  out.log = log.rows();
  out.scans = scorer.metrics().frames();
  out.event = state.event.result();
  out.frames = state.stack.detection_frames();
  out.slam_steps_beside = state.stack.slam_steps_beside();
  return out;
}

// bit for bit: every field of every row
bool same_rows(const std::vector<LogRow>& a, const std::vector<LogRow>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const LogRow& x = a[i];
    const LogRow& y = b[i];
    const double xs[] = {x.t, x.x, x.y, x.yaw, x.vx, x.vy, x.yaw_rate, x.steer_cmd, x.steer, x.throttle, x.brake,
                         x.v_ref, x.lateral_error, x.heading_error, x.s};
    const double ys[] = {y.t, y.x, y.y, y.yaw, y.vx, y.vy, y.yaw_rate, y.steer_cmd, y.steer, y.throttle, y.brake,
                         y.v_ref, y.lateral_error, y.heading_error, y.s};
    if (std::memcmp(xs, ys, sizeof xs) != 0 || x.lap != y.lap || x.as_state != y.as_state) return false;
  }
  return true;
}

TEST(Simulation, SteppedFromOutsideItIsTheRunOfRun) {
  const ScenarioOnTrack& s = default_setup();
  const SimModel model = compile_model(s.scenario, s.track);
  const Trace stepped = drive(model);
  const RunResult ran = run(s.scenario, s.track);
  EXPECT_TRUE(same_rows(stepped.log, ran.log));
  EXPECT_EQ(stepped.scans, ran.perception.frames());
  EXPECT_EQ(stepped.event.dnf_reason, ran.event.dnf_reason);
  // the car drove and perception ran: the comparison is not of two empty runs
  ASSERT_FALSE(stepped.log.empty());
  EXPECT_GT(std::hypot(stepped.log.back().x - stepped.log.front().x, stepped.log.back().y - stepped.log.front().y), 20.0);
  EXPECT_GT(stepped.scans, 50);
}

TEST(Simulation, StepAdvancesTimeByOnePhysicsStep) {
  const ScenarioOnTrack& s = default_setup();
  const SimModel model = compile_model(s.scenario, s.track);
  SimState state(model);
  EXPECT_EQ(state.k, 0);
  EXPECT_EQ(state.now, 0);
  // at t = 0 the control cycle and the sample have already run
  EXPECT_TRUE(state.controlled);
  EXPECT_TRUE(state.sampled);
  EXPECT_EQ(state.control_cycles, 1);
  for (int i = 0; i < 25; ++i) step(model, state);
  EXPECT_EQ(state.k, 25);
  EXPECT_EQ(state.now, 25 * model.dt_ns);
  EXPECT_DOUBLE_EQ(state.t, 0.025);
  // 100 Hz control at 1 kHz physics: steps 0, 10, 20
  EXPECT_EQ(state.control_cycles, 3);
  EXPECT_FALSE(state.controlled);
}

TEST(Simulation, TwoSimulationsOfOneModelOnTwoThreadsGiveWhatEachGivesAlone) {
  const ScenarioOnTrack& s = default_setup();
  const SimModel model = compile_model(s.scenario, s.track);
  const Trace alone = drive(model);
  Trace a, b;
  std::thread ta([&] { a = drive(model); });
  std::thread tb([&] { b = drive(model); });
  ta.join();
  tb.join();
  EXPECT_TRUE(same_rows(alone.log, a.log));
  EXPECT_TRUE(same_rows(alone.log, b.log));
  EXPECT_EQ(alone.scans, a.scans);
  EXPECT_EQ(alone.scans, b.scans);
  EXPECT_EQ(alone.steps, a.steps);
}

TEST(Simulation, TwoModelsWithOtherSeedsOnTwoThreadsStayApart) {
  // a different seed changes the run; each still matches its own run alone
  const ScenarioOnTrack& s = default_setup();
  Scenario other = s.scenario;
  other.scenario.seed = 7;
  const SimModel m1 = compile_model(s.scenario, s.track);
  const SimModel m2 = compile_model(other, s.track);
  const Trace alone1 = drive(m1);
  const Trace alone2 = drive(m2);
  EXPECT_FALSE(same_rows(alone1.log, alone2.log));
  Trace a, b;
  std::thread ta([&] { a = drive(m1); });
  std::thread tb([&] { b = drive(m2); });
  ta.join();
  tb.join();
  EXPECT_TRUE(same_rows(alone1.log, a.log));
  EXPECT_TRUE(same_rows(alone2.log, b.log));
}

TEST(Simulation, APerceptionLatencyDelaysEachFrameAndTheScansThreadChangesNothing) {
  // each scan's cones reach the stack [perception] latency after the scan
  // came (at its rotation's end, a column after the last column's stamp):
  // none sooner, none later than the control cycle at that instant
  // (0.5 s: the most it may be, the frames still placed at their stamps' poses)
  const ScenarioOnTrack& s = default_setup();
  for (const double latency : {0.0, 0.1, 0.25, 0.5}) {
    Scenario sc = s.scenario;
    sc.perception.latency = latency;
    const SimModel model = compile_model(sc, s.track);
    SimState state(model);
    const TimeNs column = from_seconds(1.0 / sc.lidar.rate) / sc.lidar.columns;
    long frames = 0;
    while (!state.done) {
      step(model, state);
      if (state.stack.detection_frames() == frames) continue;
      ++frames;
      const TimeNs late = state.now - state.stack.last_detections().stamp;
      EXPECT_GE(late, from_seconds(latency) + column - 1) << latency << " s: frame " << frames;
      EXPECT_LT(late, from_seconds(latency) + model.dt_ns * model.every.control) << latency << " s: frame " << frames;
    }
    EXPECT_GT(frames, 40) << latency;
    // and SLAM took every one at its stamp's odometry (none too old for it)
    ASSERT_NE(state.stack.localisation(), nullptr);
    EXPECT_EQ(state.stack.localisation()->stats().dropped_frames, 0) << latency;
    EXPECT_GT(state.stack.localisation()->stats().frames, 40) << latency;
    // a scan on a thread of its own: the same run, bit for bit
    if (latency == 0.0) continue;
    const Trace one = drive(model);
    sc.perception.threads = 2;
    const Trace two = drive(compile_model(sc, s.track));
    EXPECT_TRUE(same_rows(one.log, two.log)) << latency;
    EXPECT_EQ(one.scans, two.scans);
    // (and FastSLAM's update of each frame went beside the loop too)
    EXPECT_EQ(one.slam_steps_beside, 0) << latency;
    EXPECT_GT(two.slam_steps_beside, 40) << latency;
  }
}

TEST(Simulation, AFrameWhoseOdometryIsLateIsMappedOnTheLoopsThreadAndTheRunStays) {
  // the VCU's frames (the IMU's among them) all lost for 0.6 s, with a
  // rotation's latency on two threads: the frames whose odometry has not
  // come when they are due are mapped on the stack's thread, as on one
  // thread (and no frame is stepped beside the loop while one waits), the
  // others beside it: the same run, bit for bit
  const ScenarioOnTrack& s = default_setup();
  Scenario sc = s.scenario;
  sc.perception.latency = 0.1;
  sc.faults.can.at = 3.0;
  sc.faults.can.duration = 0.6;
  sc.faults.can.loss = 1.0;
  const Trace one = drive(compile_model(sc, s.track));
  sc.perception.threads = 2;
  const Trace two = drive(compile_model(sc, s.track));
  EXPECT_TRUE(same_rows(one.log, two.log));
  EXPECT_EQ(one.frames, two.frames);
  EXPECT_GT(two.frames, 20);
  EXPECT_GT(two.slam_steps_beside, 10);
  // some waited for their odometry
  EXPECT_LT(two.slam_steps_beside, two.frames) << two.slam_steps_beside << " of " << two.frames;
}

TEST(Simulation, ADivergingCarEndsTheRunWithItsReasonNotACrash) {
  // a downforce coefficient of 1e300 on a tyre without load sensitivity
  // (far past the load-time bounds, set past them here: within the bounds
  // the model's forces saturate and nothing diverges any more) overflows as
  // soon as the car moves: the run stops at the first state that is not a
  // number, says so, and writes no row that is not one (with the raw LiDAR
  // and camera on)
  const ScenarioOnTrack& s = default_setup();
  Scenario light = s.scenario;
  light.vehicle.c_down = 1e300;
  light.vehicle.tyre_load_sensitivity = 0.0;
  const RunResult r = run(light, s.track);
  EXPECT_FALSE(r.event.finished);
  EXPECT_EQ(r.event.dnf_reason.rfind("simulation diverged at t = ", 0), 0u) << r.event.dnf_reason;
  ASSERT_FALSE(r.log.empty());
  for (const LogRow& row : r.log) {
    ASSERT_TRUE(std::isfinite(row.x) && std::isfinite(row.y) && std::isfinite(row.vx) && std::isfinite(row.yaw_rate))
        << "t = " << row.t;
  }
  EXPECT_LT(r.sim_time, 11.0);  // it stopped before the event's timeout
}

TEST(Simulation, WithTheTrueStateTheSlamErrorIsExactlyZero) {
  // slam = ground_truth hands the stack the true pose: scored against the
  // truth at the estimate's own stamp, every sample is exact
  const ScenarioOnTrack& s = default_setup();
  Scenario gt = s.scenario;
  gt.autonomy.slam = stack::SlamMode::GroundTruth;
  const RunResult r = run(gt, s.track);
  EXPECT_GT(r.slam.samples, 1000);
  EXPECT_EQ(r.slam.ate_rms, 0.0);
  EXPECT_EQ(r.slam.ate_max, 0.0);
  EXPECT_EQ(r.slam.heading_rms, 0.0);
}

TEST(Simulation, WithSlamOdometryTheTruthNeverCrossesTheHal) {
  // the HAL of a run that is not slam = ground_truth refuses the true state
  SimHal hal(false);
  EXPECT_THROW(hal.post(hal::StateEstimate{}), std::logic_error);
  EXPECT_NO_THROW(hal.post(hal::Imu{}));
  // and such a run drives on its own estimate: it gets under way, and its
  // dead-reckoned pose is off the truth, but not by much after 6 s
  const ScenarioOnTrack& s = default_setup();
  Scenario odo = s.scenario;
  odo.autonomy.slam = stack::SlamMode::Odometry;
  const RunResult r = run(odo, s.track);
  ASSERT_FALSE(r.log.empty());
  EXPECT_GT(std::hypot(r.log.back().x - r.log.front().x, r.log.back().y - r.log.front().y), 20.0);
  EXPECT_GT(r.slam.samples, 1000);
  EXPECT_GT(r.slam.ate_max, 0.0);
  EXPECT_LT(r.slam.ate_max, 0.5);
}

TEST(Simulation, WithFastSlamTheCarLocalisesOnItsOwnMap) {
  // slam = fastslam on the default perception: the first 6 s, ~60 frames of
  // LiDAR and camera; the estimate stays within decimetres of the truth
  // (the odometry alone drifts, see above) and the map the stack plans on
  // holds real cones where they stand
  const ScenarioOnTrack& s = default_setup();
  Scenario fs = s.scenario;
  fs.autonomy.slam = stack::SlamMode::FastSlam;
  const RunResult r = run(fs, s.track);
  ASSERT_FALSE(r.log.empty());
  EXPECT_GT(std::hypot(r.log.back().x - r.log.front().x, r.log.back().y - r.log.front().y), 20.0);
  EXPECT_GT(r.slam.frames, 40);
  EXPECT_EQ(r.slam.fallbacks, 0);
  EXPECT_LT(r.slam.ate_rms, 0.1);
  EXPECT_LT(r.slam.ate_max, 0.3);
  EXPECT_GT(r.slam.map.map_cones, 20);
  EXPECT_GE(r.slam.map.precision, 0.95);
  EXPECT_LT(r.slam.map.rmse, 0.1);
  EXPECT_EQ(r.fallbacks, 0);
  // deterministic: the particle filter's random stream comes from the seed
  const RunResult again = run(fs, s.track);
  ASSERT_EQ(again.log.size(), r.log.size());
  EXPECT_EQ(again.log.back().x, r.log.back().x);
  EXPECT_EQ(again.slam.ate_rms, r.slam.ate_rms);
}

TEST(Simulation, WithTheLioTheCarLocalisesOnTheRawScans) {
  // slam = lio: the LiDAR-inertial odometry on the raw scans and the six-axis
  // IMU gives the pose, FastSLAM's map logic places the cones at it
  const ScenarioOnTrack& s = default_setup();
  Scenario lio = s.scenario;
  lio.autonomy.slam = stack::SlamMode::Lio;
  const RunResult r = run(lio, s.track);
  ASSERT_FALSE(r.log.empty());
  EXPECT_GT(std::hypot(r.log.back().x - r.log.front().x, r.log.back().y - r.log.front().y), 20.0);
  EXPECT_GT(r.slam.frames, 40);
  EXPECT_LT(r.slam.ate_rms, 0.1);
  EXPECT_LT(r.slam.ate_max, 0.3);
  EXPECT_GT(r.slam.map.map_cones, 20);
  EXPECT_GE(r.slam.map.precision, 0.95);
  EXPECT_LT(r.slam.map.rmse, 0.15);
  EXPECT_EQ(r.fallbacks, 0);
  const RunResult again = run(lio, s.track);
  ASSERT_EQ(again.log.size(), r.log.size());
  EXPECT_EQ(again.log.back().x, r.log.back().x);
  // lio_graph: FastSLAM and the graph on the LIO's odometry (no closure in 6 s)
  lio.autonomy.slam = stack::SlamMode::LioGraph;
  const RunResult g = run(lio, s.track);
  EXPECT_GT(g.slam.frames, 40);
  EXPECT_LT(g.slam.ate_rms, 0.1);
  EXPECT_GE(g.slam.map.precision, 0.95);
  EXPECT_EQ(g.fallbacks, 0);
}

TEST(Simulation, WithTheGraphTheLoopClosesAndTheMapImproves) {
  // slam = fastslam_graph, one autocross lap on the object-level sensor: the
  // car back at the start closes the loop once, the graph's optimisation
  // re-anchors the filter, and the final map is nearer the true cones than
  // the front end's own. One run's map is a matter of chance (the front end's
  // rmse on seed 2 is 0.24 m, on seed 1 0.03 m), so the claims are on the
  // mean of six seeds: lower than the front end's, and within the 0.1 m
  // target; a seed alone within 0.2 m (the graph's map over seeds 1-32:
  // mean 0.053 m, 2 of 32 over 0.1 m, the worst 0.158 m, seed 3; seeds 1-6
  // 0.075, 0.071, 0.158, 0.026, 0.052, 0.071 m)
  // (the paper's stack: the SLAM figures were measured at its speeds)
  Scenario s = load_scenario(testing::with_paper(kRoot + "/scenarios/fsg_2023_autocross.ini"),
                             {"autonomy.perception=ground_truth"});
  const world::TrackModel track = world::build_track(load_track_file(s.track_path));
  double front_sum = 0.0, graph_sum = 0.0;
  for (const std::uint64_t seed : {1, 2, 3, 4, 5, 6}) {
    s.scenario.seed = seed;
    s.autonomy.slam = stack::SlamMode::FastSlam;
    const RunResult front = run(s, track);
    s.autonomy.slam = stack::SlamMode::FastSlamGraph;
    const RunResult graph = run(s, track);
    EXPECT_TRUE(graph.event.finished) << seed;
    EXPECT_EQ(front.slam.loop_closures, 0) << seed;
    EXPECT_EQ(graph.slam.loop_closures, 1) << seed;
    EXPECT_LT(graph.slam.map.rmse, 0.2) << seed;
    EXPECT_GE(graph.slam.map.precision, 0.98) << seed;
    EXPECT_GE(graph.slam.map.recall, 0.98) << seed;
    EXPECT_LT(graph.slam.ate_rms, 0.3) << seed;
    front_sum += front.slam.map.rmse;
    graph_sum += graph.slam.map.rmse;
  }
  EXPECT_LT(graph_sum, front_sum);
  EXPECT_LT(graph_sum / 6.0, 0.1);
}

// the CI's noisy trackdrive (the object-level sensor with perception
// errors) localised by FastSLAM and the pose graph
Scenario noisy_graph_trackdrive() {
  Scenario s = load_scenario(kRoot + "/scenarios/ci/fsg_2023_trackdrive_noisy.ini");
  s.autonomy.slam = stack::SlamMode::FastSlamGraph;
  return s;
}

// the first moment a run's lap was locked (-1 s: not by t_max) and the
// loop closures by then (-1: none locked)
struct LapLock {
  double at = -1.0;
  int closures = -1;
};
// steps the run until it is done or t_max, noting when its lap was locked
LapLock step_until(const SimModel& model, SimState& state, double t_max) {
  LapLock lock;
  while (!state.done && state.t < t_max) {
    step(model, state);
    if (lock.at < 0.0 && state.stack.telemetry().lap_locked) {
      lock.at = state.t;
      lock.closures = state.stack.localisation()->stats().loop_closures;
    }
  }
  return lock;
}

// a trackdrive on the pose graph keeps the lap it plans on the map the first
// loop closure optimised, not on the first lap's map just before it (whose
// drift the closure then takes out of the map the car localises in): on the
// object-level sensor with the noisy scenario's errors, the lap is locked
// only once a closure has been optimised, and its line keeps at least 1 m
// from every true cone (planned 1.4 m from the mapped ones). Locked 0.3 s
// before the closure, seeds 1 and 2 kept 1.10 and 0.95 m; after it, 1.31 and
// 1.09 m
TEST(Simulation, ATrackdriveLocksItsLapOnTheMapTheLoopClosureOptimised) {
  for (const unsigned seed : {1u, 2u}) {
    Scenario s = noisy_graph_trackdrive();
    s.scenario.seed = seed;
    const world::TrackModel track = world::build_track(load_track_file(s.track_path));
    const SimModel model = compile_model(s, track);
    SimState state(model);
    const LapLock lock = step_until(model, state, 45.0);
    ASSERT_GE(lock.closures, 0) << seed << ": no lap locked by 45 s";
    EXPECT_GE(lock.closures, 1) << seed;
    EXPECT_EQ(state.stack.telemetry().fallbacks, 0) << seed;
    // the locked lap against the true cones
    double nearest = std::numeric_limits<double>::infinity();
    for (const TrajectoryPoint& p : state.stack.trajectory().points)
      for (const Cone& c : track.cones)
        if (c.color == ConeColor::Blue || c.color == ConeColor::Yellow)
          nearest = std::min(nearest, distance(p.position(), c.position));
    EXPECT_GT(nearest, 1.0) << seed;
  }
}

// ... and a closure the localisation misses (here: none ever, too many of
// the start's cones asked for) is not waited for past loop_closure_radius
// of driving: the lap is locked on the map as it is, 15 m after it could
// first have been, and driven (FSG 2023 noisy, seed 6, misses every closure
// of its run now that its lap is locked later: its map doubled the start's
// cones at the end of the first lap, and the doubles take their sightings)
TEST(Simulation, ATrackdriveWhoseLoopNeverClosesStillLocksItsLap) {
  Scenario s = noisy_graph_trackdrive();
  s.slam.loop_closure.min_matches = 1000;
  const world::TrackModel track = world::build_track(load_track_file(s.track_path));
  const SimModel model = compile_model(s, track);
  SimState state(model);
  ASSERT_GT(step_until(model, state, 50.0).at, 0.0) << "no lap locked by 50 s";
  EXPECT_EQ(state.stack.localisation()->stats().loop_closures, 0);
  EXPECT_EQ(state.stack.telemetry().fallbacks, 0);
  EXPECT_TRUE(state.stack.trajectory().closed);
}

// the worst position error of the estimate from t = 27 s to 45 s of an
// autocross lap on the object-level sensor with slam = fastslam_graph; with
// `kidnap`, 20 s in, on a straight, the car is lifted 2 m forward
struct KidnapRun {
  bool moved = false;
  double worst_after = 0.0;
  stack::LocalisationStats stats;
  int fallbacks = 0, oc = 0;
  bool dnf = false;
};
KidnapRun kidnap_run(bool kidnap) {
  // the paper's stack: the kidnap's times are set on its lap
  Scenario s = load_scenario(testing::with_paper(kRoot + "/scenarios/fsg_2023_autocross.ini"),
                             {"autonomy.perception=ground_truth"});
  s.autonomy.slam = stack::SlamMode::FastSlamGraph;
  const world::TrackModel track = world::build_track(load_track_file(s.track_path));
  const SimModel model = compile_model(s, track);
  SimState state(model);
  KidnapRun out;
  while (!state.done && state.t < 45.0) {
    if (kidnap && !out.moved && state.t > 20.0 && std::abs(state.car.r) < 0.02 && state.car.vx > 5.0) {
      state.car.x += 2.0 * std::cos(state.car.yaw);
      state.car.y += 2.0 * std::sin(state.car.yaw);
      out.moved = true;
    }
    step(model, state);
    if (state.t > 27.0 && state.stack.estimate()) {
      const hal::StateEstimate& e = *state.stack.estimate();
      out.worst_after = std::max(out.worst_after, distance(e.pose.position(), state.true_poses.at(e.stamp).position()));
    }
  }
  out.stats = state.stack.localisation()->stats();
  out.fallbacks = state.stack.telemetry().fallbacks;
  out.oc = state.event.result().oc;
  out.dnf = !state.event.result().dnf_reason.empty();
  return out;
}

TEST(Simulation, AKidnappedCarRelocalisesAndDrivesOn) {
  // the odometry cannot see the kidnap; the front end finds its cones 2 m
  // off, is lost (a status counted), relocalises on the map as it was before
  // and drives on: 2 s later its error is what it is without a kidnap (the
  // map's own error on this sensor reaches ~0.4 m late in the first lap),
  // with no fallback and no excursion. (Measured: lost 3 frames, the
  // relocalisation 2.0 m along the heading; the lost 0.3 s cost one cone.)
  const KidnapRun calm = kidnap_run(false);
  const KidnapRun k = kidnap_run(true);
  ASSERT_TRUE(k.moved);
  EXPECT_EQ(calm.stats.relocalisations, 0);
  EXPECT_EQ(calm.stats.lost_frames, 0);
  EXPECT_GE(k.stats.relocalisations, 1);
  EXPECT_GT(k.stats.lost_frames, 0);
  EXPECT_LT(k.worst_after, calm.worst_after + 0.2);
  EXPECT_EQ(k.fallbacks, 0);
  EXPECT_EQ(k.oc, 0);
  EXPECT_FALSE(k.dnf);
}

TEST(Simulation, TheReportedSigmaDoesNotGrowWithTheRunsLength) {
  // between two frames the estimate is the last frame's SLAM pose carried by
  // the odometry: its uncertainty is SLAM's then plus what 0.1 s of
  // odometry adds (centimetres), whatever the odometry's own absolute
  // variance has grown to since the start. Four laps of FSG 2023 on the
  // object-level sensor: the largest sigma of the last 30 s stays within
  // 1.5 x that of 40-60 s (+ 1 cm), as the error does. (Measured: 0.028 m
  // against 0.028 m; the difference of the EKF's absolute variances, the
  // formula before, reached 0.30 m by 110 s against 0.10 m at 40-60 s,
  // while the error stayed at 0.2 m.)
  const Scenario s = load_scenario(kRoot + "/scenarios/fsg_2023_trackdrive.ini",
                                   {"autonomy.perception=ground_truth", "event.timeout=110"});
  const RunResult r = run(s, world::build_track(load_track_file(s.track_path)));
  const auto max_sigma = [&r](double from, double to) {
    double m = 0.0;
    for (const SlamSample& x : r.slam.series)
      if (x.t >= from && x.t < to) m = std::max(m, x.sigma);
    return m;
  };
  const double middle = max_sigma(40.0, 60.0), late = max_sigma(80.0, 110.0);
  std::printf("reported sigma: max %.4f m at 40-60 s, %.4f m at 80-110 s\n", middle, late);
  ASSERT_GT(middle, 0.0);
  EXPECT_LE(late, 1.5 * middle + 0.01);
}

TEST(Simulation, OnBumpyGroundTheImuFeelsTheClimbOfItsMountingPoint) {
  // a noise-free IMU on a sloped, bumpy ground: az - g against the second
  // difference of the true height of its mounting point over the samples
  // (the truth from the car's state, not from the sensor's formula)
  const Scenario sc = load_scenario(kRoot + "/scenarios/fsg_2023_trackdrive.ini",
                                    {"event.timeout=8", "autonomy.perception=ground_truth", "autonomy.slam=ground_truth",
                                     "ground.slope_x=0.02", "ground.bump_height=0.05", "ground.bump_wavelength=8",
                                     "imu.accel_noise=0", "imu.gyro_noise=0", "imu.accel_bias_walk=0",
                                     "imu.gyro_bias_walk=0", "imu.accel_bias_initial_std=0",
                                     "imu.gyro_bias_initial_std=0"});
  const SimModel model = compile_model(sc, default_setup().track);
  const sensors::ImuParams& imu = model.scenario.imu;
  SimState state(model);
  std::vector<double> z, az;  // at each IMU sample
  TimeNs last = -1;
  double peak = 0.0, worst = 0.0;
  while (!state.done) {
    if (state.last_imu.stamp != last) {
      last = state.last_imu.stamp;
      const Pose2 base = vehicle::base_pose(model.scenario.vehicle, state.car);
      const Vec2 p = base.transform({imu.mount_x, imu.mount_y});
      z.push_back(sensors::ground_height(model.scenario.ground, p.x, p.y));
      az.push_back(state.last_imu.az);
      EXPECT_EQ(state.last_imu.roll_rate, 0.0);
      EXPECT_EQ(state.last_imu.pitch_rate, 0.0);
      const std::size_t n = z.size();
      if (n >= 3) {
        const double h = to_seconds(state.imu.period_ns());
        const double fd = (z[n - 1] - 2.0 * z[n - 2] + z[n - 3]) / (h * h);
        const double measured = az[n - 2] - kGravity;
        peak = std::max(peak, std::abs(fd));
        worst = std::max(worst, std::abs(fd - measured));
      }
    }
    step(model, state);
  }
  std::printf("IMU vertical: |z''| up to %.2f m/s^2, off the second difference by at most %.3f m/s^2 over %zu samples\n",
              peak, worst, z.size());
  ASSERT_GT(z.size(), 500u);
  EXPECT_GT(peak, 1.0);   // the bumps were felt
  EXPECT_LT(worst, 0.05 * peak);
}

TEST(Simulation, StreamSeedsDifferPerStream) {
  const char* streams[] = {"cone_sensor", "imu", "wheel_speeds", "steering_sensor", "lidar", "camera", "detector", "slam"};
  for (const char* a : streams) {
    for (const char* b : streams) {
      if (std::strcmp(a, b) != 0) {
        EXPECT_NE(stream_seed(1, a), stream_seed(1, b)) << a << " " << b;
      }
    }
  }
  EXPECT_NE(stream_seed(1, "imu"), stream_seed(2, "imu"));
}

}  // namespace
}  // namespace paddock::runner
