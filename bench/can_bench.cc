// one control cycle's CAN traffic through CarCan with the shipped DBC: the
// IMU's two frames, the wheel speeds, the steering angle and the command,
// encoded, and decoded back into HAL messages. The car's bus carries ~720
// frames a second, so this should cost well under a microsecond a cycle.
#include <benchmark/benchmark.h>

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "autonomy/hal/car_can.h"

namespace {

using namespace paddock::hal;

CarCan shipped_car() {
  std::ifstream f(std::string(PADDOCK_SOURCE_DIR) + "/scenarios/sensors/paddock.dbc");
  std::stringstream ss;
  ss << f.rdbuf();
  return CarCan(parse_dbc(ss.str(), "paddock.dbc"), "paddock.dbc");
}

// a cornering car's messages at time t (ns)
struct Cycle {
  Imu imu;
  WheelSpeeds wheels;
  SteeringAngle steering;
  ActuatorCommand command;
};
Cycle cycle(paddock::TimeNs t) {
  return {Imu{t, 1.2, 14.7, 1.1, 9.9, 0.02, -0.01}, WheelSpeeds{t, {{62.1, 66.3, 61.8, 67.0}}}, SteeringAngle{t, 0.12},
          ActuatorCommand{t, 0.118, 0.45, 0.0, 150.0, AsState::Driving}};
}

void BM_CanEncodeCycle(benchmark::State& state) {
  CarCan can = shipped_car();
  const Cycle c = cycle(1'000'000);
  for (auto _ : state) {
    const std::vector<CanFrame> imu = can.encode(c.imu);
    const CanFrame wheels = can.encode(c.wheels), steering = can.encode(c.steering), command = can.encode(c.command);
    benchmark::DoNotOptimize(imu.data());
    benchmark::DoNotOptimize(wheels);
    benchmark::DoNotOptimize(steering);
    benchmark::DoNotOptimize(command);
  }
}
BENCHMARK(BM_CanEncodeCycle);

void BM_CanDecodeCycle(benchmark::State& state) {
  CarCan can = shipped_car();
  const Cycle c = cycle(0);
  std::vector<CanFrame> frames = can.encode(c.imu);
  frames.push_back(can.encode(c.wheels));
  frames.push_back(can.encode(c.steering));
  frames.push_back(can.encode(c.command));
  paddock::TimeNs t = 0;
  for (auto _ : state) {
    // the cycle's frames received 10 ms after the last's
    t += 10'000'000;
    for (CanFrame f : frames) {
      f.stamp = t;
      can.push(f);
    }
    while (auto m = can.pop_sensor()) benchmark::DoNotOptimize(*m);
    while (auto m = can.pop_command()) benchmark::DoNotOptimize(*m);
  }
  if (can.counters().imu != static_cast<std::uint64_t>(state.iterations()))
    state.SkipWithError("IMU halves did not pair");
}
BENCHMARK(BM_CanDecodeCycle);

}  // namespace
