// skidpad micro-benchmarks: the 2D GICP alignment of the 73-cone template
// onto an observed skidpad, and the whole skidpad plan (alignment, path,
// reference trajectory). Both run once per skidpad run: under 10 ms is fine.
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "autonomy/common/cone.h"
#include "autonomy/common/geometry.h"
#include "autonomy/planning/gicp.h"
#include "autonomy/planning/skidpad.h"

namespace {

using paddock::Cone;
using paddock::Pose2;
using paddock::Vec2;
namespace planning = paddock::planning;

// the rules' skidpad somewhere in a map: moved, 2 cm of noise, 10 % missed
std::vector<Cone> observed_skidpad(const Pose2& T_map_template) {
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.02);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::vector<Cone> out;
  for (const Cone& c : planning::skidpad_template_cones()) {
    const Vec2 n{noise(rng), noise(rng)};
    if (uniform(rng) < 0.1) continue;
    out.push_back({T_map_template.transform(c.position) + n, c.color});
  }
  return out;
}

const Pose2 kTruth{42.0, -17.0, 2.0};
// a start-pose guess: 1.2 m and 0.15 rad off
const Pose2 kGuess{41.0, -16.3, 2.15};

void BM_GicpAlign_Skidpad(benchmark::State& state) {
  std::vector<Vec2> source, target;
  for (const Cone& c : planning::skidpad_template_cones()) source.push_back(c.position);
  for (const Cone& c : observed_skidpad(kTruth)) target.push_back(c.position);
  const planning::GicpParams params;
  int iterations = 0;
  for (auto _ : state) {
    const planning::GicpResult r = planning::align(source, target, kGuess, params);
    iterations = r.iterations;
    benchmark::DoNotOptimize(r);
  }
  state.counters["iterations"] = iterations;
  state.counters["cones"] = static_cast<double>(target.size());
}
BENCHMARK(BM_GicpAlign_Skidpad)->Unit(benchmark::kMicrosecond);

void BM_PlanSkidpad(benchmark::State& state) {
  const std::vector<Cone> cones = observed_skidpad(kTruth);
  const planning::SkidpadParams params;
  std::size_t samples = 0;
  for (auto _ : state) {
    const planning::SkidpadPlan plan = planning::plan_skidpad(cones, kGuess, params);
    samples = plan.trajectory.points.size();
    benchmark::DoNotOptimize(plan);
  }
  state.counters["samples"] = static_cast<double>(samples);
}
BENCHMARK(BM_PlanSkidpad)->Unit(benchmark::kMicrosecond);

}  // namespace
