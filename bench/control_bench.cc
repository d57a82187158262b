// one control cycle (Controller::update) on a 300 m closed trajectory sampled
// every 0.5 m; the loop runs it at 100 Hz, so it should cost microseconds.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "autonomy/common/geometry.h"
#include "autonomy/common/trajectory.h"
#include "autonomy/control/controller.h"

namespace {

using paddock::kPi;
using paddock::Trajectory;
using paddock::TrajectoryPoint;

// a closed loop of 300 m: a radius-20 m circle whose radius wobbles by 30 %
// (three lobes), resampled to 600 points of equal arc length, with a
// curvature-limited speed profile
Trajectory wobbly_loop() {
  // dense polyline first
  const int dense = 6000;
  std::vector<paddock::Vec2> pts;
  for (int i = 0; i < dense; ++i) {
    const double a = 2.0 * kPi * i / dense;
    const double r = 20.0 * (1.0 + 0.3 * std::sin(3.0 * a));
    pts.push_back({r * std::cos(a), r * std::sin(a)});
  }
  std::vector<double> cum(pts.size() + 1, 0.0);
  for (std::size_t i = 0; i < pts.size(); ++i) {
    cum[i + 1] = cum[i] + paddock::distance(pts[i], pts[(i + 1) % pts.size()]);
  }
  // scale to 300 m, then resample at ds = 0.5 m
  const double scale = 300.0 / cum.back();
  for (auto& p : pts) p = p * scale;
  for (auto& c : cum) c *= scale;
  Trajectory t;
  t.closed = true;
  t.length = 300.0;
  const int n = 600;
  std::size_t j = 0;
  for (int i = 0; i < n; ++i) {
    const double s = 0.5 * i;
    while (cum[j + 1] < s) ++j;
    const double u = (s - cum[j]) / (cum[j + 1] - cum[j]);
    const paddock::Vec2 a = pts[j], b = pts[(j + 1) % pts.size()];
    TrajectoryPoint p;
    p.s = s;
    p.x = a.x + u * (b.x - a.x);
    p.y = a.y + u * (b.y - a.y);
    t.points.push_back(p);
  }
  // heading and curvature by central differences, speed from sqrt(a_y / kappa)
  for (int i = 0; i < n; ++i) {
    const auto& prev = t.points[static_cast<std::size_t>((i + n - 1) % n)];
    const auto& next = t.points[static_cast<std::size_t>((i + 1) % n)];
    auto& p = t.points[static_cast<std::size_t>(i)];
    p.heading = std::atan2(next.y - prev.y, next.x - prev.x);
  }
  for (int i = 0; i < n; ++i) {
    const auto& prev = t.points[static_cast<std::size_t>((i + n - 1) % n)];
    const auto& next = t.points[static_cast<std::size_t>((i + 1) % n)];
    auto& p = t.points[static_cast<std::size_t>(i)];
    p.curvature = paddock::wrap_angle(next.heading - prev.heading) / (2.0 * 0.5);
    p.speed = std::min(20.0, std::sqrt(12.0 / std::max(std::abs(p.curvature), 1e-3)));
  }
  return t;
}

// the car drives along the loop 0.3 m right of it; each iteration is one
// 10 ms cycle, so the projection hint moves as it does in the loop
void BM_ControllerUpdate(benchmark::State& state) {
  const Trajectory traj = wobbly_loop();
  paddock::control::ControlParams params;
  params.lateral = static_cast<paddock::control::LateralMode>(state.range(0));
  paddock::control::Controller controller(params);
  double s = 0.0;
  const double v = 12.0, dt = 0.01;
  for (auto _ : state) {
    const TrajectoryPoint ref = traj.at(s);
    paddock::control::ControlInput in;
    in.dt = dt;
    in.base_pose = {ref.x + 0.3 * std::sin(ref.heading), ref.y - 0.3 * std::cos(ref.heading),
                    ref.heading + 0.02};
    in.vx = v;
    in.yaw_rate = v * ref.curvature;
    in.trajectory = &traj;
    const paddock::control::ControlOutput out = controller.update(in);
    if (out.status != paddock::control::Status::Ok) {
      state.SkipWithError(out.reason);
      break;
    }
    benchmark::DoNotOptimize(out);
    s = traj.wrap(s + v * dt);
  }
}
BENCHMARK(BM_ControllerUpdate)
    ->ArgName("mode")
    ->Arg(static_cast<int>(paddock::control::LateralMode::Combined))
    ->Arg(static_cast<int>(paddock::control::LateralMode::Stanley))
    ->Arg(static_cast<int>(paddock::control::LateralMode::PurePursuit));

// the first call of a controller: a full search of all 600 segments
void BM_ControllerFirstUpdate(benchmark::State& state) {
  const Trajectory traj = wobbly_loop();
  const TrajectoryPoint ref = traj.at(123.4);
  paddock::control::ControlInput in;
  in.dt = 0.0;
  in.base_pose = {ref.x, ref.y, ref.heading};
  in.vx = 12.0;
  in.trajectory = &traj;
  paddock::control::Controller controller;
  for (auto _ : state) {
    controller.reset();
    benchmark::DoNotOptimize(controller.update(in));
  }
}
BENCHMARK(BM_ControllerFirstUpdate);

}  // namespace
