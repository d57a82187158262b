// the cost of FastSLAM's two expensive steps with the default particle count:
// one update with 20 observations on a map of ~150 landmarks (the car mid-lap
// on a ring of cones), and one resample (copying the particles' landmark
// block pointers; the blocks are cloned later, on write)
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>
#include <vector>

#include "autonomy/slam/fastslam.h"

namespace {

using namespace paddock;
using namespace paddock::slam;

// two rings of 75 cones 3.5 m apart about a 15 m circle (150 landmarks,
// ~1.2 m apart along a ring): ~20 in a 12 m, 180 deg view
constexpr double kRadius = 15.0;
constexpr int kPerRing = 75;

std::vector<Vec2> ring() {
  std::vector<Vec2> w;
  for (int i = 0; i < kPerRing; ++i) {
    const double a = 2.0 * kPi * i / kPerRing;
    w.push_back((kRadius - 1.75) * unit_from_angle(a));
    w.push_back((kRadius + 1.75) * unit_from_angle(a));
  }
  return w;
}

Pose2 at(double s) {
  const double a = s / kRadius;
  return {kRadius * std::cos(a), kRadius * std::sin(a), wrap_angle(a + kPi / 2.0)};
}

std::vector<Observation> observe(const std::vector<Vec2>& world, const Pose2& p, std::mt19937_64& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<Observation> out;
  for (const Vec2& c : world) {
    const Vec2 b = p.inverse_transform(c);
    const double r = norm(b);
    if (r > 12.0 || b.x < 0.0) continue;
    const double rn = r + (0.02 + 0.01 * r) * g(rng);
    out.push_back({rn * unit_from_angle(angle_of(b) + 0.0035 * g(rng)), ConeColor::Blue, false});
  }
  return out;
}

// a filter after one lap of the ring: every cone mapped
FastSlamParams with_particles(int n) {
  FastSlamParams p;
  if (n > 0) p.particles = n;
  return p;
}

struct Lapped {
  explicit Lapped(int particles = 0) : slam(with_particles(particles), 1) { lap(); }
  std::vector<Vec2> world = ring();
  FastSlam slam;
  std::mt19937_64 rng{2};
  double s = 0.0;

  void lap() {
    slam.reset(at(0.0));
    const double lap = 2.0 * kPi * kRadius;
    while (s < lap) {
      step();
      slam.update(observe(world, at(s), rng));
    }
  }
  void step() {
    const Pose2 a = at(s), b = at(s + 1.0);
    const Vec2 d = a.inverse_transform(b.position());
    slam.predict({d.x, d.y, wrap_angle(b.yaw - a.yaw)});
    s += 1.0;
  }
};

// the argument: the particle count (0: the default); manual time, so the
// 99th percentile of the updates can be reported beside the mean
void BM_FastSlamUpdate(benchmark::State& st) {
  Lapped l(static_cast<int>(st.range(0)));
  std::size_t obs = 0;
  std::vector<double> us;
  for (auto _ : st) {
    l.step();
    const auto z = observe(l.world, at(l.s), l.rng);
    obs += z.size();
    const auto t0 = std::chrono::steady_clock::now();
    l.slam.update(z);
    const double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    st.SetIterationTime(dt);
    us.push_back(1e6 * dt);
  }
  std::sort(us.begin(), us.end());
  st.counters["p99_us"] = us[std::min(us.size() - 1, us.size() * 99 / 100)];
  st.counters["observations"] = static_cast<double>(obs) / static_cast<double>(st.iterations());
  st.counters["landmarks"] = static_cast<double>(l.slam.all_landmarks().size());
  st.counters["particles"] = st.range(0) > 0 ? static_cast<double>(st.range(0)) : FastSlamParams{}.particles;
}
BENCHMARK(BM_FastSlamUpdate)->Arg(0)->Arg(200)->Arg(300)->UseManualTime()->Unit(benchmark::kMicrosecond);

void BM_FastSlamResample(benchmark::State& st) {
  Lapped l;
  for (auto _ : st) l.slam.resample();
  st.counters["landmarks"] = static_cast<double>(l.slam.all_landmarks().size());
}
BENCHMARK(BM_FastSlamResample)->Unit(benchmark::kMicrosecond);

}  // namespace
