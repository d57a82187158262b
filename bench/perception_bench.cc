// the cost of the LiDAR perception pipeline (LidarPipeline::process: motion
// correction, ground removal, clustering, cone reconstruction and filters,
// intensity colour) on one 32 x 1024 rotation; it runs at 10 Hz, target
// p99 < 10 ms on one core.
//
// Scene: the FSG 2023 track's cones (tracks/fsg_2023.csv), flat ground, the
// default LiDAR (noise on); the car at a quarter of the lap along the
// centreline, looking along it, driving at 10 m/s while turning at 0.3 rad/s
// (motion distortion in the scan, the odometry fed exact messages, so the
// correction runs). Eight different scans (consecutive rotations' noise)
// are processed in turn; each call is timed on its own and the counters give
// the mean, the p99 and the max over all calls.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <vector>

#include "autonomy/perception/lidar_pipeline.h"
#include "bench/bench_scenes.h"
#include "sim/sensors/lidar.h"
#include "sim/world/track.h"

namespace {

using namespace paddock;

void BM_LidarPipeline(benchmark::State& state) {
  const world::TrackModel track = bench::real_track("fsg_2023");
  const std::size_t i = track.centreline.size() / 4;
  const Vec2 p0 = track.centreline[i];
  const double yaw0 = angle_of(track.centreline[i + 1] - p0);
  const double v = 10.0, w = 0.3;
  // a constant turn from (p0, yaw0) at t = 0
  auto pose_at = [p0, yaw0, v, w](TimeNs t) {
    const double s = to_seconds(t), th = w * s;
    const Vec2 local{v / w * std::sin(th), v / w * (1.0 - std::cos(th))};
    const Vec2 p = p0 + rotate(local, yaw0);
    return Pose2{p.x, p.y, yaw0 + th};
  };

  sensors::LidarParams lp;
  sensors::LidarWorld lworld(track.cones);
  sensors::Lidar lidar(lp, 1);
  std::vector<hal::LidarScan> scans;
  for (int k = 0; k < 8; ++k) {
    const TimeNs start = from_seconds(0.5);  // the same pose, fresh noise
    hal::LidarScan scan;
    scan.stamp = start;
    scan.end = lidar.column_time(start, lp.columns - 1);
    for (const sensors::LidarPoint& q : lidar.scan(lworld, pose_at, start)) {
      scan.points.push_back({q.x, q.y, q.z, q.intensity, q.ring, q.t});
    }
    scans.push_back(std::move(scan));
  }
  perception::Odometry odo;
  const double r = odo.params().wheel_radius;
  for (TimeNs t = 0; t <= from_seconds(0.7); t += 5'000'000) {
    odo.add(hal::Imu{t, 0.0, v * w, w});
    odo.add(hal::WheelSpeeds{t, {v / r, v / r, (v - 0.6 * w) / r, (v + 0.6 * w) / r}});
  }

  perception::LidarPipelineParams pp;
  pp.calibration.mount_x = lp.mount_x;
  pp.calibration.mount_y = lp.mount_y;
  pp.calibration.mount_z = lp.mount_z;
  perception::LidarPipeline pipeline(pp);

  std::vector<double> ms;
  std::size_t cones = 0, k = 0;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    const perception::LidarResult res = pipeline.process(scans[k++ % scans.size()], &odo);
    const auto t1 = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(res.cones.data());
    ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    cones = res.cones.size();
  }
  std::sort(ms.begin(), ms.end());
  double mean = 0.0;
  for (double m : ms) mean += m;
  mean /= static_cast<double>(ms.size());
  const std::size_t p99 = std::min(ms.size() - 1, static_cast<std::size_t>(0.99 * static_cast<double>(ms.size())));
  state.counters["mean_ms"] = mean;
  state.counters["p99_ms"] = ms[p99];
  state.counters["max_ms"] = ms.back();
  state.counters["points"] = static_cast<double>(scans[0].points.size());
  state.counters["cones"] = static_cast<double>(cones);
}
BENCHMARK(BM_LidarPipeline)->Unit(benchmark::kMillisecond)->MinTime(2.0);

}  // namespace
