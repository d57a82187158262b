// the perception front as the stack runs it (stack/perception_stage.h):
// its frames against a plain Perception fed the same messages in the same
// order and run on each scan as it comes (the stack's way before the stage,
// and the reference here), bit for bit, on one thread and two, with and
// without a latency; each frame delivered its latency after its scan came.
// The scans, frames and boxes are the simulator's, cast along a curve as
// sim/runner/raw_sensors.cc casts them.
#include "autonomy/stack/perception_stage.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include "autonomy/common/same_bits.h"
#include "sim/sensors/annotation_detector.h"
#include "sim/sensors/camera.h"
#include "sim/sensors/lidar.h"

namespace paddock::stack {
namespace {

const sensors::LidarParams kLidar{};
const sensors::CameraParams kCamera{};
constexpr TimeNs kStep = 5'000'000;  // the odometry's messages: every 5 ms

// a slalom of cones on both sides of a left curve of radius 40 m, the car
// on it at 8 m/s
constexpr double kV = 8.0, kW = 8.0 / 40.0;
Pose2 base_at(TimeNs t) {
  const double s = to_seconds(t);
  return {kV / kW * std::sin(kW * s), kV / kW * (1.0 - std::cos(kW * s)), kW * s};
}
std::vector<Cone> curve_cones() {
  std::vector<Cone> cones;
  for (double a = 0.05; a < 1.5; a += 0.075) {
    for (const double r : {38.5, 41.5}) {
      const Vec2 p{r * std::sin(a), 40.0 - r * std::cos(a)};
      cones.push_back({p, r < 40.0 ? ConeColor::Blue : ConeColor::Yellow});
    }
  }
  return cones;
}

perception::PerceptionParams stage_params(double latency, int threads) {
  // the sensors' own calibration, as the runner's stack_params gives it
  perception::PerceptionParams p;
  p.use_camera = true;
  p.lidar.calibration = static_cast<const hal::LidarLayout&>(kLidar);
  p.camera = sensors::camera_calibration(kCamera);
  p.latency = latency;
  p.threads = threads;
  return p;
}

// what the HAL delivers, in order, each at its instant: the odometry's
// samples, a rotation's camera boxes at its trigger time and its scan at its
// end, the camera's trust (distrusted over the third rotation)
struct Event {
  TimeNs at;
  std::variant<hal::Imu, hal::WheelSpeeds, hal::CameraDetections, hal::LidarScan, bool> what;
};

std::vector<Event> drive(int rotations, TimeNs lead = from_seconds(0.2)) {
  const std::vector<Cone> cones = curve_cones();
  sensors::LidarWorld world(cones);
  sensors::Lidar lidar(kLidar, 3);
  sensors::Camera camera(kCamera, 5);
  sensors::AnnotationDetector detector(sensors::DetectorParams{}, 7);
  const TimeNs period = lidar.period_ns();
  std::vector<Event> events;
  const double r = perception::OdometryParams{}.wheel_radius, track = 1.2;
  for (TimeNs t = 0; t <= lead + rotations * period; t += kStep) {
    events.push_back({t, hal::Imu{t, 0.0, kV * kW, kW}});
    const double left = (kV - 0.5 * track * kW) / r, right = (kV + 0.5 * track * kW) / r;
    events.push_back({t, hal::WheelSpeeds{t, {left, right, left, right}}});
  }
  hal::CameraFrame frame;
  sensors::CameraAnnotation annotation;
  for (int k = 0; k < rotations; ++k) {
    const TimeNs start = lead + k * period;
    const TimeNs end = start + period;
    const TimeNs exposure = sensors::trigger_time(kLidar, kCamera.trigger_azimuth, start);
    camera.render(world, base_at(exposure), exposure, frame, annotation);
    sensors::AnnotationDetection d = detector.detect(frame, annotation);
    EXPECT_TRUE(d.ok) << d.reason;
    events.push_back({exposure, std::move(d.detections)});
    hal::LidarScan scan;
    scan.stamp = start;
    scan.end = lidar.column_time(start, kLidar.columns - 1);
    for (const sensors::LidarPoint& p : lidar.scan(world, base_at, start))
      scan.points.push_back({p.x, p.y, p.z, p.intensity, p.ring, p.t});
    events.push_back({end, std::move(scan)});
    if (k == 2) events.push_back({start, true});
    if (k == 3) events.push_back({start, false});
  }
  std::stable_sort(events.begin(), events.end(), [](const Event& a, const Event& b) { return a.at < b.at; });
  return events;
}

// the frames' every result, bit for bit
void expect_same(const perception::PerceptionFrame& a, const perception::PerceptionFrame& b, const std::string& what) {
  SCOPED_TRACE(what);
  EXPECT_EQ(a.output.stamp, b.output.stamp);
  ASSERT_EQ(a.output.cones.size(), b.output.cones.size());
  for (std::size_t i = 0; i < a.output.cones.size(); ++i) {
    EXPECT_TRUE(same_bits(a.output.cones[i].position.x, b.output.cones[i].position.x)) << i;
    EXPECT_TRUE(same_bits(a.output.cones[i].position.y, b.output.cones[i].position.y)) << i;
    EXPECT_EQ(a.output.cones[i].color, b.output.cones[i].color) << i;
    EXPECT_EQ(a.output.cones[i].colour_from_camera, b.output.cones[i].colour_from_camera) << i;
  }
  ASSERT_EQ(a.output.free_range.size(), b.output.free_range.size());
  for (std::size_t i = 0; i < a.output.free_range.size(); ++i)
    EXPECT_TRUE(same_bits(a.output.free_range[i], b.output.free_range[i])) << i;
  EXPECT_EQ(a.lidar.ok, b.lidar.ok);
  EXPECT_EQ(a.lidar.corrected, b.lidar.corrected);
  EXPECT_EQ(a.lidar.cones.size(), b.lidar.cones.size());
  EXPECT_EQ(a.camera_used, b.camera_used);
  EXPECT_EQ(a.camera_note, b.camera_note);
  EXPECT_EQ(a.camera_stamp, b.camera_stamp);
  EXPECT_EQ(a.detections.boxes.size(), b.detections.boxes.size());
  EXPECT_EQ(a.fusion.cones.size(), b.fusion.cones.size());
}

// the reference: a plain Perception fed as the stack fed it before the
// stage, each scan processed when it comes; its frames in order
std::vector<perception::PerceptionFrame> reference(const std::vector<Event>& events) {
  perception::Perception p(stage_params(0.0, 1));
  std::vector<perception::PerceptionFrame> frames;
  for (const Event& e : events) {
    if (const auto* m = std::get_if<hal::Imu>(&e.what)) p.add(*m);
    if (const auto* m = std::get_if<hal::WheelSpeeds>(&e.what)) p.add(*m);
    if (const auto* m = std::get_if<hal::CameraDetections>(&e.what)) p.add(*m);
    if (const auto* m = std::get_if<bool>(&e.what)) p.set_camera_distrusted(*m);
    if (const auto* m = std::get_if<hal::LidarScan>(&e.what)) {
      p.process(*m);
      frames.push_back(p.last());
    }
  }
  return frames;
}

struct Delivered {
  TimeNs at;
  perception::PerceptionFrame frame;
};

// the stage fed the same, delivering at each event's instant (and every
// 10 ms: the stack's control cycles) until `until`
std::vector<Delivered> staged(const std::vector<Event>& events, double latency, int threads, TimeNs until) {
  PerceptionStage stage(stage_params(latency, threads), nullptr);
  std::vector<Delivered> out;
  const auto deliver = [&](TimeNs now) {
    while (const perception::PerceptionFrame* f = stage.deliver(now)) {
      out.push_back({now, *f});
      EXPECT_EQ(&stage.last(), f);
    }
  };
  TimeNs tick = 0;
  for (const Event& e : events) {
    for (; tick < e.at; tick += 10'000'000) deliver(tick);
    if (const auto* m = std::get_if<hal::Imu>(&e.what)) stage.add(*m);
    if (const auto* m = std::get_if<hal::WheelSpeeds>(&e.what)) stage.add(*m);
    if (const auto* m = std::get_if<hal::CameraDetections>(&e.what)) stage.add(*m);
    if (const auto* m = std::get_if<bool>(&e.what)) stage.set_camera_distrusted(*m);
    if (const auto* m = std::get_if<hal::LidarScan>(&e.what)) {
      const hal::LidarScan& posted = stage.post(*m, e.at);
      EXPECT_EQ(posted.end, m->end);
      EXPECT_EQ(posted.points.size(), m->points.size());
      deliver(e.at);
    }
  }
  for (; tick <= until; tick += 10'000'000) deliver(tick);
  EXPECT_EQ(stage.stats().scans, static_cast<long>(out.size() + stage.in_flight()));
  return out;
}

TEST(PerceptionStage, GivesAPlainPerceptionsFramesBitForBitOnOneThreadOrTwo) {
  const std::vector<Event> events = drive(6);
  const std::vector<perception::PerceptionFrame> ref = reference(events);
  ASSERT_EQ(ref.size(), 6u);
  // the scene is seen: cones, the camera fused but over the distrusted rotation
  int fused = 0;
  for (const perception::PerceptionFrame& f : ref) {
    EXPECT_GE(f.output.cones.size(), 10u);
    fused += f.camera_used ? 1 : 0;
  }
  EXPECT_EQ(fused, 5);
  for (const int threads : {1, 2}) {
    for (const double latency : {0.0, 0.1, 0.25}) {
      const std::vector<Delivered> got = staged(events, latency, threads, from_seconds(2.0));
      ASSERT_EQ(got.size(), ref.size()) << threads << " threads, latency " << latency;
      for (std::size_t k = 0; k < got.size(); ++k)
        expect_same(got[k].frame, ref[k],
                    std::to_string(threads) + " threads, latency " + std::to_string(latency) + ", frame " + std::to_string(k));
    }
  }
}

TEST(PerceptionStage, DeliversEachFrameItsLatencyAfterItsScanCame) {
  const std::vector<Event> events = drive(4);
  std::vector<TimeNs> came, end;
  for (const Event& e : events) {
    if (const auto* m = std::get_if<hal::LidarScan>(&e.what)) {
      came.push_back(e.at);
      end.push_back(m->end);
    }
  }
  for (const double latency : {0.0, 0.1, 0.25}) {
    const std::vector<Delivered> got = staged(events, latency, 2, from_seconds(2.0));
    ASSERT_EQ(got.size(), came.size());
    for (std::size_t k = 0; k < got.size(); ++k) {
      // (the first instant the caller asks at, on or after the due time: the
      // scans come at multiples of 10 ms here, as the asking does)
      EXPECT_EQ(got[k].at, came[k] + from_seconds(latency)) << latency << " " << k;
      EXPECT_EQ(got[k].frame.output.stamp, end[k]) << k;
    }
  }
  // nothing before it is due, and the scans still in flight stay there
  PerceptionStage stage(stage_params(0.1, 2), nullptr);
  for (const Event& e : events) {
    if (const auto* m = std::get_if<hal::LidarScan>(&e.what)) {
      stage.post(*m, e.at);
      EXPECT_EQ(stage.deliver(e.at + from_seconds(0.1) - 1), nullptr);
      EXPECT_EQ(stage.in_flight(), 1u);
      const perception::PerceptionFrame* f = stage.deliver(e.at + from_seconds(0.1));
      ASSERT_NE(f, nullptr);
      EXPECT_EQ(f->output.stamp, m->end);
      EXPECT_EQ(stage.in_flight(), 0u);
    } else if (const auto* imu = std::get_if<hal::Imu>(&e.what)) {
      stage.add(*imu);
    } else if (const auto* w = std::get_if<hal::WheelSpeeds>(&e.what)) {
      stage.add(*w);
    }
  }
}

TEST(PerceptionStage, InputsWithNoScanToTakeThemAreAppliedInTheirOrder) {
  // the camera distrusted, then 12 s of odometry before the first scan (the
  // LiDAR silent): more than the stage holds for a scan, so it applies them
  // itself; the frames stay the reference's, the camera distrusted on
  std::vector<Event> events = drive(3, from_seconds(12.0));
  events.insert(events.begin(), Event{0, true});
  const std::vector<perception::PerceptionFrame> ref = reference(events);
  for (const perception::PerceptionFrame& f : ref) EXPECT_FALSE(f.camera_used);
  for (const int threads : {1, 2}) {
    const std::vector<Delivered> got = staged(events, 0.1, threads, from_seconds(14.0));
    ASSERT_EQ(got.size(), ref.size());
    for (std::size_t k = 0; k < got.size(); ++k) expect_same(got[k].frame, ref[k], "frame " + std::to_string(k));
    EXPECT_TRUE(got.back().frame.lidar.corrected);
  }
}

TEST(PerceptionStage, AStepOnAFrameRunsBesideTheCallerBeforeTheFrameIsDelivered) {
  // two threads, a latency of two rotations (two frames in flight): each
  // scan's step is attached some control cycles after its post (as the
  // stack's SLAM step waits for the odometry), sees its own frame (the
  // reference's cones), and has run, in the posts' order, when deliver()
  // gives the frame; a step attached to a job not in flight is refused, and
  // what a step throws comes out of its frame's delivery
  const std::vector<Event> events = drive(6);
  const std::vector<perception::PerceptionFrame> ref = reference(events);
  PerceptionStage stage(stage_params(0.2, 2), nullptr);
  ASSERT_TRUE(stage.threaded());
  std::vector<std::size_t> stepped;  // the frames' cone counts, in the steps' order (the stage's thread's)
  std::vector<std::uint64_t> unstepped;  // posted, no step yet (oldest first)
  std::size_t delivered = 0, checked = 0;
  const auto deliver = [&](TimeNs now) {
    while (const perception::PerceptionFrame* f = stage.deliver(now)) {
      ASSERT_LT(delivered, ref.size());
      // its step ran before (the deliveries read the list only now, on this thread)
      ASSERT_GT(stepped.size(), delivered);
      EXPECT_EQ(stepped[delivered], ref[delivered].output.cones.size());
      EXPECT_EQ(f->output.cones.size(), ref[delivered].output.cones.size());
      ++delivered;
      ++checked;
    }
  };
  TimeNs tick = 0;
  for (const Event& e : events) {
    for (; tick < e.at; tick += 10'000'000) {
      // a cycle after the post: the step of the oldest frame without one
      if (!unstepped.empty()) {
        stage.then(unstepped.front(), [&stepped](const perception::PerceptionFrame& f) { stepped.push_back(f.output.cones.size()); });
        EXPECT_THROW(stage.then(unstepped.front(), [](const perception::PerceptionFrame&) {}), std::logic_error);
        unstepped.erase(unstepped.begin());
      }
      deliver(tick);
    }
    if (const auto* m = std::get_if<hal::Imu>(&e.what)) stage.add(*m);
    if (const auto* m = std::get_if<hal::WheelSpeeds>(&e.what)) stage.add(*m);
    if (const auto* m = std::get_if<hal::CameraDetections>(&e.what)) stage.add(*m);
    if (const auto* m = std::get_if<hal::LidarScan>(&e.what)) {
      stage.post(*m, e.at);
      unstepped.push_back(stage.last_posted());
    }
  }
  for (; tick <= from_seconds(2.0); tick += 10'000'000) {
    if (!unstepped.empty()) {
      stage.then(unstepped.front(), [&stepped](const perception::PerceptionFrame& f) { stepped.push_back(f.output.cones.size()); });
      unstepped.erase(unstepped.begin());
    }
    deliver(tick);
  }
  EXPECT_EQ(checked, ref.size());
  EXPECT_EQ(stage.in_flight(), 0u);
  // delivered: no step any more
  EXPECT_THROW(stage.then(stage.last_posted(), [](const perception::PerceptionFrame&) {}), std::logic_error);
  // a step that throws: its frame's delivery says so
  const hal::LidarScan* scan = nullptr;
  for (const Event& e : events)
    if (const auto* m = std::get_if<hal::LidarScan>(&e.what)) scan = m;
  ASSERT_NE(scan, nullptr);
  stage.post(*scan, from_seconds(3.0));
  stage.then(stage.last_posted(), [](const perception::PerceptionFrame&) { throw std::runtime_error("step failed"); });
  EXPECT_THROW(stage.deliver(from_seconds(3.5)), std::runtime_error);
}

}  // namespace
}  // namespace paddock::stack
