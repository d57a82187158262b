// the cost of one ray-cast LiDAR rotation (Lidar::scan, 32 channels x 1024
// columns = 32768 rays, two rtcIntersect16 packets per column) on a whole
// track's cones; it runs at 10 Hz next to the 1 kHz physics, target < 3 ms on
// one core.
//
// Scene: a wavy ellipse of about 305 m (semi-axes 60 m and 35 m, a 4 m ripple
// six times round), 100 blue cones 1.5 m to its left and 100 yellow ones 1.5 m
// to its right (200 cones), a flat ground. The car sits at the start of the
// centreline looking along it, driving at 10 m/s (motion distortion on).
// Default parameters (noise on). BM_LidarWorldBuild: building the Embree scene.
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "bench/bench_scenes.h"
#include "sim/sensors/lidar.h"

namespace {

using namespace paddock;

void BM_LidarScan(benchmark::State& state) {
  const std::vector<Cone> cones = bench::oval_cones(static_cast<int>(state.range(0)) / 2);
  sensors::LidarWorld world(cones);
  sensors::Lidar lidar(sensors::LidarParams{}, 1);
  const Vec2 p0 = bench::oval_centreline(0.0);
  const double yaw = angle_of(bench::oval_tangent(0.0));
  auto pose_at = [p0, yaw](TimeNs t) {
    const double s = to_seconds(t);
    const Vec2 p = p0 + 10.0 * s * unit_from_angle(yaw);
    return Pose2{p.x, p.y, yaw};
  };
  std::size_t points = 0;
  for (auto _ : state) {
    const auto pts = lidar.scan(world, pose_at, 0);
    points = pts.size();
    benchmark::DoNotOptimize(pts.data());
  }
  state.counters["points"] = static_cast<double>(points);
  state.counters["rays/s"] = benchmark::Counter(
      32.0 * 1024.0 * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_LidarScan)->Arg(200)->Unit(benchmark::kMillisecond);

void BM_LidarWorldBuild(benchmark::State& state) {
  const std::vector<Cone> cones = bench::oval_cones(static_cast<int>(state.range(0)) / 2);
  for (auto _ : state) {
    sensors::LidarWorld world(cones);
    benchmark::DoNotOptimize(world.scene());
  }
}
BENCHMARK(BM_LidarWorldBuild)->Arg(200)->Unit(benchmark::kMillisecond);

}  // namespace
