// the cost of one vehicle step (dt = 1 ms) in a corner at speed: chassis, four
// wheels with their tyres, the powertrain. Issue 17's target: <= 2 us a step on
// one core of a 2.4 GHz machine.
#include <benchmark/benchmark.h>

#include <cmath>
#include <string>

#include "sim/runner/scenario.h"
#include "sim/vehicle/vehicle.h"

namespace {

using namespace paddock;
using namespace paddock::vehicle;

// the default car, read by the scenario loader
VehicleParams bench_params() {
  return runner::load_vehicle_file(std::string(PADDOCK_SOURCE_DIR) + "/scenarios/vehicles/default.ini");
}

void BM_VehicleStepCornering(benchmark::State& st) {
  const VehicleParams p = bench_params();
  const Car car(p);
  constexpr double dt = 1e-3;
  VehicleState s = rolling_state(p, Pose2{}, 12.0);
  // a steady left-hand corner at 12 m/s (steering 0.11 rad: radius ~14 m, ~1 g), the
  // speed held by a proportional throttle, reached before timing
  auto input = [&]() {
    return DriverInput{0.11, std::fmin(std::fmax(0.1 + 0.5 * (12.0 - s.vx), 0.0), 1.0), 0.0};
  };
  for (int k = 0; k < 3000; ++k) step(car, s, input(), dt);
  for (auto _ : st) {
    step(car, s, input(), dt);
    benchmark::DoNotOptimize(s);
    benchmark::ClobberMemory();
  }
  st.counters["speed_mps"] = speed(s);
  st.counters["ay_g"] = body_acceleration(s).y / kGravity;
}
BENCHMARK(BM_VehicleStepCornering);

}  // namespace
