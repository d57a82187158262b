// the pose graph's optimise() on lap-sized graphs: a 300 m lap (a circle)
// with a node every metre, 250 cones (two rings 2.4 m apart along the lap),
// ~15 observations per node, 1 and 5 laps. The initial values are what a
// front end like FastSLAM hands over (the truth with 10 cm and 0.01 rad of
// independent error per node); the odometry has a 1 % scale error, a 2e-4
// rad/m gyro bias and noise; observations 2 cm + 1 %, 0.2 deg (the graph's
// defaults).
#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <random>
#include <vector>

#include "autonomy/slam/pose_graph.h"

namespace {

using namespace paddock;
using namespace paddock::slam;

constexpr double kLap = 300.0;
constexpr double kRadius = kLap / (2.0 * kPi);
constexpr int kPerRing = 125;
constexpr double kRange = 18.0;  // ahead, 180 deg: ~15 cones in view

Pose2 at(double s) {
  const double a = s / kRadius;
  return {kRadius * std::cos(a), kRadius * std::sin(a), wrap_angle(a + kPi / 2.0)};
}

PoseGraph lap_graph(int laps) {
  std::vector<Vec2> cones;
  for (int i = 0; i < kPerRing; ++i) {
    const double a = 2.0 * kPi * i / kPerRing;
    cones.push_back((kRadius - 1.75) * unit_from_angle(a));
    cones.push_back((kRadius + 1.75) * unit_from_angle(a));
  }
  std::mt19937_64 rng(1);
  std::normal_distribution<double> g(0.0, 1.0);
  PoseGraph graph;
  Pose2 odom = at(0.0), prev = at(0.0);
  const int n = laps * static_cast<int>(kLap);
  for (int i = 0; i <= n; ++i) {
    const Pose2 truth = at(i * 1.0);
    if (i > 0) {
      const Vec2 d = prev.inverse_transform(truth.position());
      const double dyaw = wrap_angle(truth.yaw - prev.yaw);
      const Vec2 p = odom.transform({1.01 * d.x + 0.005 * g(rng), 1.01 * d.y + 0.005 * g(rng)});
      odom = {p.x, p.y, wrap_angle(odom.yaw + dyaw + 2e-4 + 1e-4 * g(rng))};
    }
    prev = truth;
    const Pose2 estimate = i == 0 ? truth : Pose2{truth.x + 0.1 * g(rng), truth.y + 0.1 * g(rng), truth.yaw + 0.01 * g(rng)};
    const int node = graph.add_pose(estimate, odom);
    for (std::size_t k = 0; k < cones.size(); ++k) {
      const Vec2 b = truth.inverse_transform(cones[k]);
      const double r = norm(b);
      if (r > kRange || b.x < 0.0) continue;
      const double rn = r + (0.02 + 0.01 * r) * g(rng);
      const Vec2 z = rn * unit_from_angle(angle_of(b) + 0.0035 * g(rng));
      const std::int64_t id = static_cast<std::int64_t>(k);
      if (!graph.landmark(id)) graph.add_landmark(id, estimate.transform(z));
      graph.add_observation(node, id, z);
    }
  }
  return graph;
}

// the argument: laps; manual time, so copying the graph is not counted
void BM_PoseGraphOptimise(benchmark::State& st) {
  const PoseGraph built = lap_graph(static_cast<int>(st.range(0)));
  PoseGraph::Result r;
  for (auto _ : st) {
    PoseGraph graph = built;
    const auto t0 = std::chrono::steady_clock::now();
    r = graph.optimise();
    st.SetIterationTime(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    benchmark::DoNotOptimize(r);
  }
  st.counters["nodes"] = built.nodes();
  st.counters["landmarks"] = built.landmarks();
  st.counters["observations"] = built.observations();
  st.counters["iterations"] = r.iterations;
  st.counters["ok"] = r.ok ? 1.0 : 0.0;
}
BENCHMARK(BM_PoseGraphOptimise)->Arg(1)->Arg(5)->UseManualTime()->Unit(benchmark::kMillisecond);

}  // namespace
