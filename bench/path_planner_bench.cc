// one planning cycle (triangulation, centreline search, smoothing, the
// clearance pass, spline and velocity profile) on the FSG 2023 cone map from
// its start pose: the full map (a closed lap, ~200 cones), the same without
// the clearance pass, and the cones within 20 m of the car (an open path, as
// in the first seconds of autocross). Each call is timed alone; the counters
// give the mean and the 99th percentile (target: p99 under 5 ms on one core).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "autonomy/common/cone.h"
#include "autonomy/common/geometry.h"
#include "autonomy/planning/path_planner.h"

namespace {

using paddock::Cone;
using paddock::ConeColor;
using paddock::Pose2;
namespace planning = paddock::planning;

struct Track {
  std::vector<Cone> cones;
  Pose2 start;
};

// tracks/<name>.csv: "# start X Y YAW", a tag,x,y header, rows tag,x,y
Track read_track(const std::string& name) {
  Track t;
  std::ifstream in(std::string(PADDOCK_SOURCE_DIR) + "/tracks/" + name + ".csv");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("# start", 0) == 0) {
      std::istringstream s(line.substr(7));
      s >> t.start.x >> t.start.y >> t.start.yaw;
      continue;
    }
    if (line.empty() || line[0] == '#' || line.rfind("tag,", 0) == 0) continue;
    std::istringstream s(line);
    std::string tag, x, y;
    std::getline(s, tag, ',');
    std::getline(s, x, ',');
    std::getline(s, y, ',');
    ConeColor c = ConeColor::Unknown;
    if (tag == "blue") c = ConeColor::Blue;
    else if (tag == "yellow") c = ConeColor::Yellow;
    else if (tag == "orange") c = ConeColor::SmallOrange;
    else if (tag == "big_orange") c = ConeColor::BigOrange;
    t.cones.push_back({{std::stod(x), std::stod(y)}, c});
  }
  return t;
}

// times every call and reports mean and p99 (ms) besides the usual figures
void run_cycles(benchmark::State& state, const std::vector<Cone>& cones, const Pose2& start,
                const planning::PathPlannerParams& params = {}) {
  std::vector<double> ms;
  std::size_t points = 0;
  bool closed = false;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    planning::PlanResult plan = planning::plan_path(cones, start, 0.0, params);
    const auto t1 = std::chrono::steady_clock::now();
    ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    points = plan.search.points.size();
    closed = plan.closed;
    benchmark::DoNotOptimize(plan);
  }
  std::sort(ms.begin(), ms.end());
  double sum = 0.0;
  for (double v : ms) sum += v;
  const std::size_t i99 = std::min(ms.size() - 1, static_cast<std::size_t>(0.99 * static_cast<double>(ms.size())));
  state.counters["mean_ms"] = sum / static_cast<double>(ms.size());
  state.counters["p99_ms"] = ms[i99];
  state.counters["cones"] = static_cast<double>(cones.size());
  state.counters["points"] = static_cast<double>(points);
  state.counters["closed"] = closed ? 1.0 : 0.0;
}

void BM_PlanPath_FSG2023_FullMap(benchmark::State& state) {
  const Track t = read_track("fsg_2023");
  run_cycles(state, t.cones, t.start);
}
BENCHMARK(BM_PlanPath_FSG2023_FullMap)->Unit(benchmark::kMillisecond)->MinTime(2.0);

// the same without the clearance pass after the smoothing (clearance.h):
// the triangulation, the search, the smoothing and the reference alone
void BM_PlanPath_FSG2023_FullMap_NoClearance(benchmark::State& state) {
  const Track t = read_track("fsg_2023");
  planning::PathPlannerParams params;
  params.clearance.clearance = 0.0;
  run_cycles(state, t.cones, t.start, params);
}
BENCHMARK(BM_PlanPath_FSG2023_FullMap_NoClearance)->Unit(benchmark::kMillisecond)->MinTime(2.0);

void BM_PlanPath_FSG2023_Within20m(benchmark::State& state) {
  const Track t = read_track("fsg_2023");
  std::vector<Cone> near;
  for (const Cone& c : t.cones)
    if (paddock::distance(c.position, t.start.position()) <= 20.0) near.push_back(c);
  run_cycles(state, near, t.start);
}
BENCHMARK(BM_PlanPath_FSG2023_Within20m)->Unit(benchmark::kMillisecond)->MinTime(1.0);

// an open path as an autocross explores it with line = min_curvature (the
// racing line: IPOPT on the path within the mapped boundaries, every plan):
// the cones within 40 m of the start
void BM_PlanPath_FSG2023_Within40m_RacingLine(benchmark::State& state) {
  const Track t = read_track("fsg_2023");
  std::vector<Cone> near;
  for (const Cone& c : t.cones)
    if (paddock::distance(c.position, t.start.position()) <= 40.0) near.push_back(c);
  planning::PathPlannerParams params;
  params.line = planning::PathPlannerParams::MinCurvature;
  run_cycles(state, near, t.start, params);
}
BENCHMARK(BM_PlanPath_FSG2023_Within40m_RacingLine)->Unit(benchmark::kMillisecond)->MinTime(1.0);

}  // namespace
