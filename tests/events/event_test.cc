// the FS event rules on a hand-made track: a straight strip 4 m wide with a
// gate across it at x = 0 (and one at x = 75 for acceleration). The expected
// times and penalties are worked out by hand from the rules in ORACLES.md.
#include "sim/events/event.h"

#include <gtest/gtest.h>

namespace paddock::events {
namespace {

world::TrackModel strip_track() {
  world::TrackModel t;
  t.region.add_xor_polygon({{-200, -2}, {200, -2}, {200, 2}, {-200, 2}});
  // left post first: driving +x crosses from the gate's right side to its left
  t.gates = {Segment{{0, 2}, {0, -2}}, Segment{{75, 2}, {75, -2}}};
  return t;
}

// a car whose four wheels sit around the nose, on or off the strip
CarSample sample(double t, Vec2 nose, double speed, bool finished = false, int doo = 0) {
  CarSample s;
  s.t = t;
  s.nose = nose;
  s.wheels = {nose + Vec2{-0.5, 0.6}, nose + Vec2{-0.5, -0.6}, nose + Vec2{-2.0, 0.6}, nose + Vec2{-2.0, -0.6}};
  s.speed = speed;
  s.as_finished = finished;
  s.doo_total = doo;
  return s;
}

// crosses the gate at x = gate_x at exactly time t (a 10 ms step centred on it)
void cross(Event& e, double t, double gate_x = 0.0) {
  e.on_motion(t - 0.005, {gate_x - 0.05, 0.0}, t + 0.005, {gate_x + 0.05, 0.0});
}

TEST(EventParams, DefaultsAreValidAndABadValueIsNamed) {
  EXPECT_EQ(params::validate(EventParams{}), "");
  EventParams p;
  p.stall_time = 0.0;
  EXPECT_EQ(params::validate(p), "stall_time must be in [0.1, 600] s (got 0)");
  // and an event will not run with it
  EXPECT_THROW(Event(EventKind::Autocross, strip_track(), p), std::invalid_argument);
}

TEST(Event, LapTimesAreInterpolatedGateToGate) {
  const auto track = strip_track();
  Event e(EventKind::Autocross, track, EventParams{});
  e.start(0.0);
  cross(e, 6.25);
  EXPECT_EQ(e.current_lap(), 1);
  cross(e, 47.5);
  ASSERT_EQ(e.laps_completed(), 1);
  EXPECT_NEAR(e.result().laps[0].time, 41.25, 1e-9);
  // then it must stop in the zone with AS Finished
  e.on_sample(sample(49.0, {20.0, 0.0}, 0.0, true));
  ASSERT_TRUE(e.done());
  EXPECT_TRUE(e.result().finished);
  EXPECT_NEAR(e.result().total_time, 41.25, 1e-9);
  EXPECT_EQ(e.result().uss, 0);
}

TEST(Event, NotFooledByTheLineBesideTheGateOrByReversing) {
  const auto track = strip_track();
  Event e(EventKind::Autocross, track, EventParams{});
  e.start(0.0);
  // across the gate's line but beside its post
  e.on_motion(1.0, {-0.05, 2.3}, 1.01, {0.05, 2.3});
  EXPECT_EQ(e.current_lap(), 0);
  // backwards through the gate
  e.on_motion(2.0, {0.05, 0.0}, 2.01, {-0.05, 0.0});
  EXPECT_EQ(e.current_lap(), 0);
  // forwards: starts lap 1
  cross(e, 3.0);
  EXPECT_EQ(e.current_lap(), 1);
  // a crossing before the go does not count (the event has not started)
  Event before(EventKind::Autocross, track, EventParams{});
  cross(before, 1.0);
  EXPECT_EQ(before.current_lap(), 0);
}

TEST(Event, TrackdriveTenLapsWithDooAndOffCourse) {
  const auto track = strip_track();
  Event e(EventKind::Trackdrive, track, EventParams{});
  e.start(0.0);
  double t = 5.0;
  cross(e, t);
  for (int lap = 1; lap <= 10; ++lap) {
    // lap 3 knocks two cones; lap 5 has one excursion of all four wheels
    const int doo = lap >= 3 ? 2 : 0;
    e.on_sample(sample(t + 10.0, {10.0, 0.0}, 15.0, false, doo));
    if (lap == 5) {
      e.on_sample(sample(t + 11.0, {10.0, 5.0}, 15.0, false, doo));  // all four off (y 4.4..5.6)
      e.on_sample(sample(t + 11.5, {10.0, 5.0}, 15.0, false, doo));  // the same excursion
      e.on_sample(sample(t + 12.0, {10.0, 2.5}, 15.0, false, doo));  // two wheels back on: over
    }
    t += 40.0 + 0.1 * lap;
    cross(e, t);
  }
  ASSERT_EQ(e.laps_completed(), 10);
  EXPECT_EQ(e.result().laps[2].doo, 2);
  EXPECT_EQ(e.result().laps[4].oc, 1);
  e.on_sample(sample(t + 3.0, {20.0, 0.0}, 0.0, true, 2));  // at rest 20 m past the line
  ASSERT_TRUE(e.done());
  const Result& r = e.result();
  EXPECT_TRUE(r.finished) << r.dnf_reason;
  EXPECT_EQ(r.doo, 2);
  EXPECT_EQ(r.oc, 1);
  // raw: 10 laps of 40 s plus 0.1 s * (1 + ... + 10)
  EXPECT_NEAR(r.raw_time, 400.0 + 5.5, 1e-9);
  EXPECT_NEAR(r.total_time, 405.5 + 2 * 2.0 + 1 * 10.0, 1e-9);
}

TEST(Event, StoppingBeyondTheZoneIsAnUnsafeStop) {
  const auto track = strip_track();
  Event e(EventKind::Autocross, track, EventParams{});
  e.start(0.0);
  cross(e, 1.0);
  cross(e, 30.0);
  e.on_sample(sample(35.0, {45.0, 0.0}, 0.0, true));  // 45 m past the line, zone is 30 m
  ASSERT_TRUE(e.done());
  EXPECT_TRUE(e.result().finished);
  EXPECT_EQ(e.result().uss, 1);
  EXPECT_NEAR(e.result().total_time, 29.0 + 10.0, 1e-9);
}

TEST(Event, NoStopAfterTheFinishIsADnf) {
  const auto track = strip_track();
  EventParams p;
  p.stop_time = 20.0;
  Event e(EventKind::Autocross, track, p);
  e.start(0.0);
  cross(e, 1.0);
  cross(e, 30.0);
  e.on_sample(sample(45.0, {100.0, 0.0}, 10.0));
  EXPECT_FALSE(e.done());
  e.on_sample(sample(50.5, {150.0, 0.0}, 10.0));
  ASSERT_TRUE(e.done());
  EXPECT_FALSE(e.result().finished);
}

TEST(Event, LeavingTheTrackForGoodIsADnf) {
  const auto track = strip_track();
  EventParams p;
  p.off_track_dnf_time = 5.0;
  Event e(EventKind::Trackdrive, track, p);
  e.start(0.0);
  cross(e, 1.0);
  for (double t = 2.0; t < 7.0; t += 0.5) e.on_sample(sample(t, {10.0, 8.0}, 5.0));
  EXPECT_FALSE(e.done());
  e.on_sample(sample(7.5, {10.0, 8.0}, 5.0));
  ASSERT_TRUE(e.done());
  EXPECT_FALSE(e.result().finished);
  EXPECT_EQ(e.result().oc, 1);
}

TEST(Event, TimeoutAndStallAreDnfs) {
  const auto track = strip_track();
  EventParams p;
  p.timeout = 100.0;
  p.stall_time = 10.0;
  Event slow(EventKind::Trackdrive, track, p);
  slow.start(0.0);
  slow.on_sample(sample(99.0, {10.0, 0.0}, 3.0));
  EXPECT_FALSE(slow.done());
  slow.on_sample(sample(100.5, {10.0, 0.0}, 3.0));
  EXPECT_TRUE(slow.done());
  EXPECT_EQ(slow.result().dnf_reason, "timeout");

  Event stalled(EventKind::Trackdrive, track, p);
  stalled.start(0.0);
  for (double t = 0.0; t < 10.5; t += 0.5) stalled.on_sample(sample(t, {-3.0, 0.0}, 0.0));
  EXPECT_FALSE(stalled.done());
  stalled.on_sample(sample(11.0, {-3.0, 0.0}, 0.0));
  EXPECT_TRUE(stalled.done());
  EXPECT_FALSE(stalled.result().finished);
}

TEST(Event, AnEmergencyEndsTheRunOnceTheCarIsAtRestWithItsConesCounted) {
  const auto track = strip_track();
  Event e(EventKind::Autocross, track, EventParams{});
  e.start(0.0);
  cross(e, 5.0);
  CarSample s = sample(10.0, {40.0, 0.0}, 12.0);
  s.as_emergency = true;
  e.on_sample(s);
  EXPECT_FALSE(e.done());  // still rolling: the EBS brakes it
  s = sample(10.5, {44.0, 0.0}, 3.0, false, 1);
  s.as_emergency = true;
  e.on_sample(s);
  EXPECT_FALSE(e.done());
  s = sample(11.0, {45.0, 0.0}, 0.0, false, 1);
  s.as_emergency = true;
  e.on_sample(s);
  ASSERT_TRUE(e.done());
  EXPECT_FALSE(e.result().finished);
  EXPECT_EQ(e.result().dnf_reason, "the car went to AS Emergency");
  EXPECT_EQ(e.result().doo, 1);  // the cone hit while braking counts
  EXPECT_EQ(e.result().finish_time, 11.0);
}

TEST(Event, ACarThatNeverHoldsAsReadyIsADnfAfterTheReadyTimeout) {
  EventParams p;
  p.ready_timeout = 30.0;
  const auto track = strip_track();
  Event e(EventKind::Autocross, track, p);
  for (double t = 0.0; t <= 30.0; t += 0.5) e.on_sample(sample(t, {-1.0, 0.0}, 0.0));
  EXPECT_FALSE(e.done());
  e.on_sample(sample(30.01, {-1.0, 0.0}, 0.0));
  ASSERT_TRUE(e.done());
  EXPECT_EQ(e.result().dnf_reason, "no go: the car did not hold AS Ready long enough within 30 s");
}

TEST(Event, SkidpadScoresTheMeanOfTheTimedLapsAndCheapCones) {
  const auto track = strip_track();
  Event e(EventKind::Skidpad, track, EventParams{});
  e.start(0.0);
  // five crossings of the gate at the figure of eight's middle: four laps
  const double crossings[] = {4.0, 10.0, 15.0, 21.0, 26.5};
  for (double t : crossings) cross(e, t);
  ASSERT_EQ(e.laps_completed(), 4);
  EXPECT_FALSE(e.result().laps[0].timed);
  EXPECT_TRUE(e.result().laps[1].timed);
  EXPECT_FALSE(e.result().laps[2].timed);
  EXPECT_TRUE(e.result().laps[3].timed);
  e.on_sample(sample(30.0, {20.0, 0.0}, 0.0, true, 3));
  ASSERT_TRUE(e.done());
  // timed laps 2 (5.0 s) and 4 (5.5 s): mean 5.25 s; 3 cones at 0.2 s
  EXPECT_NEAR(e.result().raw_time, 5.25, 1e-9);
  EXPECT_NEAR(e.result().total_time, 5.25 + 0.6, 1e-9);
}

TEST(Event, AccelerationTimesStartGateToFinishGate) {
  const auto track = strip_track();
  Event e(EventKind::Acceleration, track, EventParams{});
  e.start(0.0);
  cross(e, 1.0, 0.0);
  cross(e, 4.5, 75.0);
  ASSERT_EQ(e.laps_completed(), 1);
  EXPECT_NEAR(e.result().laps[0].time, 3.5, 1e-9);
  // stopping 80 m after the finish is inside the 100 m braking zone
  e.on_sample(sample(9.0, {155.0, 0.0}, 0.0, true));
  ASSERT_TRUE(e.done());
  EXPECT_EQ(e.result().uss, 0);
  EXPECT_NEAR(e.result().total_time, 3.5, 1e-9);
}

}  // namespace
}  // namespace paddock::events
