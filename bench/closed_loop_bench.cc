// the whole closed loop: the default scenario (FSG 2023 trackdrive, 10 laps,
// ground-truth state; planned from perceived cones, and with the oracle planner) end to end. The real-time factor is
// simulated seconds per wall-clock second; the target is >= 500x on one core.
#include <benchmark/benchmark.h>

#include <string>
#include <vector>

#include "sim/runner/scenario.h"
#include "sim/runner/simulation.h"
#include "sim/world/track.h"

namespace {

using namespace paddock;

// state.range(0): 0 the default scenario as shipped (planner = delaunay), 1 with planner = oracle
void BM_DefaultScenario(benchmark::State& state) {
  std::vector<std::string> overrides;
  if (state.range(0) == 1) overrides.push_back("autonomy.planner=oracle");
  const runner::Scenario sc =
      runner::load_scenario(std::string(PADDOCK_SOURCE_DIR) + "/scenarios/fsg_2023_trackdrive.ini", overrides);
  const world::TrackModel track = world::build_track(runner::load_track_file(sc.track_path));
  double sim_seconds = 0.0;
  bool finished = true;
  for (auto _ : state) {
    const runner::RunResult r = runner::run(sc, track);
    sim_seconds += r.sim_time;
    finished = finished && r.event.finished;
    benchmark::DoNotOptimize(r.event.total_time);
  }
  // a rate counter divides by the wall time of the timed loop: sim s per wall s
  state.counters["realtime_factor"] = benchmark::Counter(sim_seconds, benchmark::Counter::kIsRate);
  state.counters["finished"] = finished ? 1.0 : 0.0;
}
BENCHMARK(BM_DefaultScenario)->ArgName("oracle")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->Iterations(3)->UseRealTime();

}  // namespace
