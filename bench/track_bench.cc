// building a track model from its file and the on-track test the event asks
// at every sample (they were timing assertions in tests/world; timing lives here)
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "bench/bench_scenes.h"
#include "sim/runner/scenario.h"
#include "sim/world/track.h"

namespace {

using namespace paddock;

// the biggest shipped track (FSG 2024): ordering, centreline, gates, region
void BM_BuildTrack(benchmark::State& state) {
  const world::TrackFile f = runner::load_track_file(std::string(PADDOCK_SOURCE_DIR) + "/tracks/fsg_2024.csv");
  for (auto _ : state) {
    const world::TrackModel m = world::build_track(f);
    benchmark::DoNotOptimize(m.centreline.data());
  }
}
BENCHMARK(BM_BuildTrack)->Unit(benchmark::kMillisecond);

// one on_track query at a random point around FSG 2024
void BM_OnTrack(benchmark::State& state) {
  const world::TrackModel m = bench::real_track("fsg_2024");
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> ux(-60, 60), uy(-100, 20);
  std::vector<Vec2> q(4096);
  for (auto& p : q) p = {ux(rng), uy(rng)};
  std::size_t i = 0, inside = 0;
  for (auto _ : state) inside += m.on_track(q[i++ & 4095]);
  benchmark::DoNotOptimize(inside);
}
BENCHMARK(BM_OnTrack)->Unit(benchmark::kNanosecond);

}  // namespace
