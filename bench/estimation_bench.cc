// the cost of the velocity EKF's two halves: an IMU predict (200 Hz) and a
// four-wheel update (100 Hz), on a car cornering at 10 m/s
#include <benchmark/benchmark.h>

#include "autonomy/estimation/velocity_ekf.h"

namespace {

using namespace paddock;
using namespace paddock::estimation;

constexpr TimeNs kImuPeriod = 5'000'000;  // ns

void BM_EkfImuPredict(benchmark::State& st) {
  VelocityEkf ekf({}, CarGeometry{});
  ekf.reset(Pose2{}, 0);
  TimeNs t = 0;
  for (auto _ : st) {
    t += kImuPeriod;
    benchmark::DoNotOptimize(ekf.on_imu(hal::Imu{t, 0.2, 1.0, 0.1}));
  }
}
BENCHMARK(BM_EkfImuPredict);

void BM_EkfWheelUpdate(benchmark::State& st) {
  VelocityEkf ekf({}, CarGeometry{});
  ekf.reset(Pose2{}, 0);
  const double w = 10.0 / CarGeometry{}.wheel_radius;
  TimeNs t = 0;
  for (auto _ : st) {
    st.PauseTiming();
    t += kImuPeriod;
    ekf.on_imu(hal::Imu{t, 0.2, 1.0, 0.1});
    st.ResumeTiming();
    benchmark::DoNotOptimize(ekf.on_wheel_speeds(hal::WheelSpeeds{t, {w + 0.3, w - 0.3, w + 0.3, w - 0.3}}));
  }
}
BENCHMARK(BM_EkfWheelUpdate);

}  // namespace
