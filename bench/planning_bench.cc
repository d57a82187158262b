// planning micro-benchmarks: the reference trajectory and its parts on a
// ~300 m closed loop (the size of an FS trackdrive lap) at ds = 0.5 m.
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "autonomy/common/geometry.h"
#include "autonomy/planning/reference.h"
#include "autonomy/planning/spline.h"
#include "autonomy/planning/velocity_profile.h"

namespace {

using paddock::kPi;
using paddock::Vec2;
namespace planning = paddock::planning;

// a wavy ellipse (semi-axes 60 m and 35 m, a 4 m ripple six times round):
// about 305 m, centreline points every ~1 m as a planner would hand them over
std::vector<Vec2> wavy_loop() {
  std::vector<Vec2> pts;
  const int n = 300;
  for (int i = 0; i < n; ++i) {
    const double t = 2.0 * kPi * i / n;
    const double ripple = 4.0 * std::sin(6.0 * t);
    pts.push_back({(60.0 + ripple) * std::cos(t), (35.0 + ripple) * std::sin(t)});
  }
  return pts;
}

void BM_BuildReference_Loop300m(benchmark::State& state) {
  const auto pts = wavy_loop();
  const planning::ReferenceParams params;  // knots 3 m, ds 0.5 m, the car's limits
  std::size_t samples = 0;
  for (auto _ : state) {
    auto res = planning::build_reference(pts, true, params);
    samples = res.trajectory.points.size();
    benchmark::DoNotOptimize(res);
  }
  state.counters["samples"] = static_cast<double>(samples);
}
BENCHMARK(BM_BuildReference_Loop300m)->Unit(benchmark::kMicrosecond);

void BM_FitSpline_Loop300m(benchmark::State& state) {
  const auto pts = wavy_loop();
  for (auto _ : state) benchmark::DoNotOptimize(planning::fit_spline(pts, true));
}
BENCHMARK(BM_FitSpline_Loop300m)->Unit(benchmark::kMicrosecond);

void BM_SampleByArcLength_Loop300m(benchmark::State& state) {
  const auto fit = planning::fit_spline(wavy_loop(), true);
  for (auto _ : state) benchmark::DoNotOptimize(planning::sample_by_arc_length(fit.spline, 0.5));
}
BENCHMARK(BM_SampleByArcLength_Loop300m)->Unit(benchmark::kMicrosecond);

void BM_VelocityProfile_Closed610(benchmark::State& state) {
  const auto fit = planning::fit_spline(wavy_loop(), true);
  const auto samples = planning::sample_by_arc_length(fit.spline, 0.5);
  std::vector<double> kappa;
  for (const auto& s : samples) kappa.push_back(s.curvature);
  const std::vector<double> ds(kappa.size(), fit.spline.length() / static_cast<double>(kappa.size()));
  const planning::VelocityProfileParams params;
  for (auto _ : state) {
    benchmark::DoNotOptimize(planning::solve_velocity_profile(kappa, ds, true, params));
  }
}
BENCHMARK(BM_VelocityProfile_Closed610)->Unit(benchmark::kMicrosecond);

}  // namespace
