// fast_atan2 against std::atan2 (glibc) over the same 4096 random arguments
// per iteration: the ratio of their times is the figure (fast_math.h)
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <vector>

#include "autonomy/common/fast_math.h"

namespace {

struct Args {
  std::vector<double> y, x;
  Args() {
    std::mt19937_64 rng(1);
    std::uniform_real_distribution<double> u(-20.0, 20.0);
    for (int i = 0; i < 4096; ++i) {
      y.push_back(u(rng));
      x.push_back(u(rng));
    }
  }
};

template <double (*F)(double, double)>
void atan2_loop(benchmark::State& state) {
  static const Args a;
  for (auto _ : state) {
    double sum = 0.0;
    for (std::size_t i = 0; i < a.x.size(); ++i) sum += F(a.y[i], a.x[i]);
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(a.x.size()));
}

double library_atan2(double y, double x) { return std::atan2(y, x); }

void BM_Atan2Library(benchmark::State& state) { atan2_loop<library_atan2>(state); }
BENCHMARK(BM_Atan2Library);
void BM_Atan2Fast(benchmark::State& state) { atan2_loop<paddock::fast_atan2>(state); }
BENCHMARK(BM_Atan2Fast);

}  // namespace
