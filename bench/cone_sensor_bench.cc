// the cost of one object-level cone sensor frame (ConeSensor::measure) on a
// whole track's cones: it runs at 10 Hz, so it has to stay far below a
// millisecond to be noise next to the 1 kHz physics.
//
// Scene: a wavy ellipse of about 305 m (semi-axes 60 m and 35 m, a 4 m ripple
// six times round), 200 blue cones 1.5 m to its left and 200 yellow ones 1.5 m
// to its right (400 cones; the FSG 2024 track file has 412 rows). The car sits
// on the centreline looking along it, at 32 places round the lap, one frame
// per place in turn. Default parameters: every effect on (occlusion, noise,
// misses, colour errors, false positives).
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "bench/bench_scenes.h"
#include "sim/sensors/cone_sensor.h"

namespace {

using namespace paddock;

void BM_ConeSensorMeasure(benchmark::State& state) {
  const std::vector<Cone> cones = bench::oval_cones(static_cast<int>(state.range(0)) / 2);
  const std::vector<bool> knocked(cones.size(), false);
  constexpr int kPlaces = 32;
  std::vector<Pose2> poses;
  for (int k = 0; k < kPlaces; ++k) {
    const double t = 2.0 * kPi * (k + 0.5) / kPlaces;
    const Vec2 c = bench::oval_centreline(t);
    poses.push_back({c.x, c.y, angle_of(bench::oval_tangent(t))});
  }
  sensors::ConeSensor sensor(sensors::ConeSensorParams{}, 2024);
  std::size_t k = 0;
  double detections = 0.0, in_view = 0.0, frames = 0.0;
  for (auto _ : state) {
    const hal::ConeDetections frame =
        sensor.measure(cones, knocked, poses[k % kPlaces], static_cast<TimeNs>(k) * 100'000'000);
    benchmark::DoNotOptimize(frame.cones.data());
    detections += static_cast<double>(frame.cones.size());
    in_view += sensor.last_stats().in_view;
    frames += 1.0;
    ++k;
  }
  state.counters["cones"] = static_cast<double>(cones.size());
  state.counters["detections"] = frames > 0.0 ? detections / frames : 0.0;
  state.counters["in_view"] = frames > 0.0 ? in_view / frames : 0.0;
}

}  // namespace

BENCHMARK(BM_ConeSensorMeasure)->Arg(400)->Unit(benchmark::kMicrosecond);
