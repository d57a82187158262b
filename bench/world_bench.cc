// the cost of one cone-world step (dt = 1 ms). The whole simulator must run at
// >= 500x real time, so the world may spend about 1 us per step on average: a
// step far from every cone has to be nearly free.
//
// Scene: a lane of cones 3 m apart, one every 5 m for 100 m (42 cones), the
// car driving 120 m down it at 15 m/s; optionally 360 more cones off to the
// side (a whole track's worth of bodies in the Box2D world). One benchmark
// iteration is one drive (8000 steps); the counter per_step is the figure.
//   centre:   down the middle, 0.69 m from the cone edges (Box2D never steps)
//   graze:    the car's side 1 cm from the cone edges (inside wake_margin:
//             Box2D steps along every cone, nothing is touched)
//   swerve:   swerves into the blue cones at 25-45 m and knocks some flying
//   no_skip:  down the middle with skip_idle_steps = false (Box2D every step)
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "sim/world/cone_world.h"

namespace {

using namespace paddock;
using namespace paddock::world;

constexpr double kDt = 1e-3;        // s
constexpr double kSpeed = 15.0;     // m/s
constexpr int kSteps = 8000;        // 120 m at 15 m/s
const Footprint kCar{0.5, 2.4, 0.7};

std::vector<Cone> lane_cones(int extra) {
  std::vector<Cone> cones;
  for (int k = 0; k <= 20; ++k) {
    cones.push_back({{5.0 * k, 1.5}, ConeColor::Blue});
    cones.push_back({{5.0 * k, -1.5}, ConeColor::Yellow});
  }
  // the rest of a track: 10 rows of 36 cones 40-130 m to the side
  for (int k = 0; k < extra; ++k) {
    cones.push_back({{2.5 * (k % 36), 40.0 + 10.0 * (k / 36)}, ConeColor::Blue});
  }
  return cones;
}

enum Path { kCentre, kGraze, kSwerve };

Pose2 car_at(Path path, double t) {
  const double x = -10.0 + kSpeed * t;
  switch (path) {
    case kCentre:
      return {x, 0.0, 0.0};
    case kGraze:
      return {x, 1.5 - 0.114 - 0.01 - kCar.half_width, 0.0};
    case kSwerve: {
      if (x < 25.0 || x > 45.0) return {x, 0.0, 0.0};
      const double k = kPi / 10.0, a = 0.6;
      return {x, a * (1.0 - std::cos(k * (x - 25.0))), std::atan(a * k * std::sin(k * (x - 25.0)))};
    }
  }
  return {};
}

void run(benchmark::State& state, Path path, bool skip) {
  const std::vector<Cone> cones = lane_cones(static_cast<int>(state.range(0)));
  ConeWorldParams params;
  params.skip_idle_steps = skip;
  // the car's poses, computed once
  std::vector<Pose2> poses(kSteps + 1);
  for (int k = 0; k <= kSteps; ++k) poses[k] = car_at(path, k * kDt);
  std::int64_t box2d_steps = 0, steps = 0;
  for (auto _ : state) {
    state.PauseTiming();
    ConeWorld world(cones, params, kCar);
    state.ResumeTiming();
    for (int k = 1; k <= kSteps; ++k) {
      const Pose2& p = poses[k];
      const Pose2& q = poses[k - 1];
      world.step(p, (p.x - q.x) / kDt, (p.y - q.y) / kDt, (p.yaw - q.yaw) / kDt, kDt);
    }
    benchmark::DoNotOptimize(world.doo_count());
    box2d_steps += world.stats().box2d_steps;
    steps += world.stats().steps;
  }
  // seconds per step
  state.counters["per_step"] =
      benchmark::Counter(static_cast<double>(kSteps), benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.counters["box2d_share"] = steps > 0 ? static_cast<double>(box2d_steps) / static_cast<double>(steps) : 0.0;
  state.counters["cones"] = static_cast<double>(cones.size());
}

void BM_ConeWorldLaneCentre(benchmark::State& state) { run(state, kCentre, true); }
void BM_ConeWorldLaneGraze(benchmark::State& state) { run(state, kGraze, true); }
void BM_ConeWorldLaneSwerve(benchmark::State& state) { run(state, kSwerve, true); }
void BM_ConeWorldLaneCentreNoSkip(benchmark::State& state) { run(state, kCentre, false); }

}  // namespace

BENCHMARK(BM_ConeWorldLaneCentre)->Arg(0)->Arg(360)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_ConeWorldLaneGraze)->Arg(0)->Arg(360)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_ConeWorldLaneSwerve)->Arg(0)->Arg(360)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_ConeWorldLaneCentreNoSkip)->Arg(0)->Arg(360)->Unit(benchmark::kMicrosecond);
