// the cost of one ray-cast LiDAR rotation (Lidar::scan, 32 channels x 1024
// columns = 32768 rays) on a whole track's cones; it runs at 10 Hz next to
// the 1 kHz physics. Target (issue 15): <= 0.5 ms on flat ground on the
// reference machine (2.4 GHz), read as a ratio against the path before
// (LidarCast::Packets) from one run of this file.
//
// Scene: a wavy ellipse of about 305 m (semi-axes 60 m and 35 m, a 4 m ripple
// six times round), 100 blue cones 1.5 m to its left and 100 yellow ones 1.5 m
// to its right (200 cones). The car sits at the start of the centreline
// looking along it, driving at 10 m/s (motion distortion on). Default
// parameters (noise on).
//
// BM_LidarScan/<cast>/<ground>: the whole scan, points and noise included,
//   cast 0 LidarCast::Exploit (the default), 1 Packets (every beam through
//   the whole scene in rtcIntersect16 packets: the path before), 2 Single
//   (every beam through the whole scene with rtcIntersect1); ground 0 flat,
//   1 the CI's sloped and bumpy ground (4 % and 2 % grades, 8 cm bumps every
//   12 m). Counters: rays/s (32768 beams a scan), the points, and the beams
//   Exploit cast through Embree for the cones' windows.
// BM_LidarRays1/<ground>: the plain loop, no points: the same scan's 32768
//   rays (the same origins and directions, made beforehand) through the whole
//   scene with rtcIntersect1, one at a time.
// BM_LidarWorldBuild/<ground>: building the scenes.
#include <benchmark/benchmark.h>

#include <cmath>
#include <functional>
#include <vector>

#include <embree3/rtcore.h>

#include "bench/bench_scenes.h"
#include "sim/sensors/embree_ray.h"
#include "sim/sensors/lidar.h"

namespace {

using namespace paddock;

constexpr int kCones = 200;

sensors::GroundParams ground_of(int64_t g) {
  sensors::GroundParams p;
  if (g == 1) {
    p.slope_x = 0.04;
    p.slope_y = 0.02;
    p.bump_height = 0.08;
    p.bump_wavelength = 12.0;
  }
  return p;
}

// driving along the centreline's tangent at 10 m/s
std::function<Pose2(TimeNs)> drive() {
  const Vec2 p0 = bench::oval_centreline(0.0);
  const double yaw = angle_of(bench::oval_tangent(0.0));
  return [p0, yaw](TimeNs t) {
    const Vec2 p = p0 + 10.0 * to_seconds(t) * unit_from_angle(yaw);
    return Pose2{p.x, p.y, yaw};
  };
}

void BM_LidarScan(benchmark::State& state) {
  const auto cast = static_cast<sensors::LidarCast>(state.range(0));
  sensors::LidarWorld world(bench::oval_cones(kCones / 2), {}, ground_of(state.range(1)));
  sensors::Lidar lidar(sensors::LidarParams{}, 1);
  const auto pose_at = drive();
  std::size_t points = 0;
  for (auto _ : state) {
    const auto pts = lidar.scan(world, pose_at, 0, cast);
    points = pts.size();
    benchmark::DoNotOptimize(pts.data());
  }
  const sensors::LidarParams& p = lidar.params();
  state.counters["points"] = static_cast<double>(points);
  state.counters["window"] = static_cast<double>(lidar.window_beams());
  state.counters["rays/s"] = benchmark::Counter(
      static_cast<double>(p.channels) * p.columns * static_cast<double>(state.iterations()),
      benchmark::Counter::kIsRate);
}
BENCHMARK(BM_LidarScan)
    ->ArgNames({"cast", "ground"})
    ->ArgsProduct({{0, 1, 2}, {0, 1}})
    ->Unit(benchmark::kMillisecond);

void BM_LidarRays1(benchmark::State& state) {
  sensors::LidarWorld world(bench::oval_cones(kCones / 2), {}, ground_of(state.range(0)));
  const sensors::Lidar lidar(sensors::LidarParams{}, 1);
  const sensors::LidarParams& p = lidar.params();
  const auto pose_at = drive();
  // the scan's rays, as Lidar::scan makes them (no pitch)
  std::vector<float> rays;  // org xyz, dir xyz
  for (int c = 0; c < p.columns; ++c) {
    const Pose2 pose = pose_at(lidar.column_time(0, c));
    const Vec2 o = pose.transform({p.mount_x, p.mount_y});
    const double oz = world.ground_z(o.x, o.y) + p.mount_z;
    const double az = -kPi + c * lidar.horizontal_resolution();
    for (int i = 0; i < p.channels; ++i) {
      const double el = p.elevation_min + i * lidar.vertical_resolution();
      const double dx = std::cos(el) * std::cos(az), dy = std::cos(el) * std::sin(az);
      const double cy = std::cos(pose.yaw), sy = std::sin(pose.yaw);
      const double v[6] = {o.x, o.y, oz, cy * dx - sy * dy, sy * dx + cy * dy, std::sin(el)};
      for (double x : v) rays.push_back(static_cast<float>(x));
    }
  }
  const float tfar = static_cast<float>(p.range_max + 6.0 * p.range_noise + 0.01);
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  std::size_t hits = 0;
  for (auto _ : state) {
    hits = 0;
    for (std::size_t k = 0; k < rays.size(); k += 6) {
      RTCRayHit rh;
      const double org[3] = {rays[k], rays[k + 1], rays[k + 2]};
      const double dir[3] = {rays[k + 3], rays[k + 4], rays[k + 5]};
      sensors::set_ray(rh, org, dir, 0.0f, tfar);
      rtcIntersect1(world.scene(), &context, &rh);
      hits += rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
    }
    benchmark::DoNotOptimize(hits);
  }
  state.counters["hits"] = static_cast<double>(hits);
  const double per_scan = static_cast<double>(rays.size() / 6);
  state.counters["rays/s"] = benchmark::Counter(
      per_scan * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_LidarRays1)->ArgNames({"ground"})->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

void BM_LidarWorldBuild(benchmark::State& state) {
  const std::vector<Cone> cones = bench::oval_cones(kCones / 2);
  const sensors::GroundParams g = ground_of(state.range(0));
  for (auto _ : state) {
    sensors::LidarWorld world(cones, {}, g);
    benchmark::DoNotOptimize(world.scene());
  }
}
BENCHMARK(BM_LidarWorldBuild)->ArgNames({"ground"})->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace
