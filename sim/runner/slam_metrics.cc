#include "sim/runner/slam_metrics.h"

#include <algorithm>
#include <cmath>
#include <tuple>

namespace paddock::runner {

namespace {
bool in_corridor(Vec2 c, const std::vector<Vec2>& path, double corridor) {
  for (std::size_t i = 0; i < path.size(); ++i) {
    // the distance to the segment from this path point to the next
    const Vec2 a = path[i];
    const Vec2 b = i + 1 < path.size() ? path[i + 1] : path[i];
    const Vec2 ab = b - a;
    const double len2 = dot(ab, ab);
    const double f = len2 > 0.0 ? std::clamp(dot(c - a, ab) / len2, 0.0, 1.0) : 0.0;
    if (distance(c, a + ab * f) <= corridor) return true;
  }
  return false;
}
}  // namespace

MapMetrics map_metrics(const std::vector<Cone>& map, const std::vector<Cone>& truth, const std::vector<Vec2>& path,
                       double match_radius, double corridor) {
  MapMetrics m;
  m.map_cones = static_cast<int>(map.size());
  std::vector<bool> counted(truth.size());
  for (std::size_t j = 0; j < truth.size(); ++j) {
    counted[j] = in_corridor(truth[j].position, path, corridor);
    m.true_cones += counted[j] ? 1 : 0;
  }
  // every pair within the radius, nearest first; each cone matched once
  std::vector<std::tuple<double, std::size_t, std::size_t>> pairs;
  for (std::size_t i = 0; i < map.size(); ++i)
    for (std::size_t j = 0; j < truth.size(); ++j) {
      const double d = distance(map[i].position, truth[j].position);
      if (d <= match_radius) pairs.emplace_back(d, i, j);
    }
  std::sort(pairs.begin(), pairs.end());
  std::vector<bool> map_taken(map.size()), truth_taken(truth.size());
  double sum2 = 0.0;
  int colour_right = 0, matched_counted = 0;
  for (const auto& [d, i, j] : pairs) {
    if (map_taken[i] || truth_taken[j]) continue;
    map_taken[i] = truth_taken[j] = true;
    ++m.matched;
    matched_counted += counted[j] ? 1 : 0;
    sum2 += d * d;
    colour_right += map[i].color == truth[j].color ? 1 : 0;
  }
  if (m.matched > 0) {
    m.rmse = std::sqrt(sum2 / m.matched);
    m.colour_accuracy = static_cast<double>(colour_right) / m.matched;
  }
  m.precision = m.map_cones > 0 ? static_cast<double>(m.matched) / m.map_cones : 0.0;
  m.recall = m.true_cones > 0 ? static_cast<double>(matched_counted) / m.true_cones : 1.0;
  return m;
}

Drift relative_drift(const std::vector<Pose2>& truth, const std::vector<Pose2>& estimate, double length,
                     double step) {
  return relative_drift(
      std::min(truth.size(), estimate.size()), [&truth](std::size_t i) -> const Pose2& { return truth[i]; },
      [&estimate](std::size_t i) -> const Pose2& { return estimate[i]; }, length, step);
}

}  // namespace paddock::runner
