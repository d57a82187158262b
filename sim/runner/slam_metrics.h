#pragma once
// how good the stack's final map is: its cones against the true cones,
// matched one to one within a radius, nearest pairs first
//   precision: matched map cones / map cones
//   recall: matched true cones / true cones within the driven corridor (the
//     cones the car passed within `corridor` of; the others it may never
//     have seen)
//   rmse: of the matched pairs' distances
//   colour accuracy: matched pairs whose colour is the true one (unknown is wrong)
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include "autonomy/common/cone.h"
#include "autonomy/common/geometry.h"

namespace paddock::runner {

struct MapMetrics {
  int map_cones = 0;
  int true_cones = 0;  // within the corridor
  int matched = 0;
  double rmse = 0.0;              // m
  double precision = 0.0;         // 0 with an empty map
  double recall = 0.0;            // 1 with no true cone in the corridor
  double colour_accuracy = 0.0;   // 0 with no match
};

// path: the true positions the car drove through (any spacing below corridor)
MapMetrics map_metrics(const std::vector<Cone>& map, const std::vector<Cone>& truth, const std::vector<Vec2>& path,
                       double match_radius = 1.0, double corridor = 5.0);

// the estimate's drift over a given distance (KITTI's relative error): for
// every window of `length` metres of true travel, one starting every `step`
// metres, the estimate's motion over the window against the truth's, both
// in the frame of the window's start: E = (T_i^-1 T_j)^-1 (S_i^-1 S_j) (T
// the true poses, S the estimates). The translation and rotation of E, as
// means over the windows; a window closes at the first sample at least
// `length` along. No window (a drive shorter than `length`): zeros.
struct Drift {
  double translation = 0.0;  // m over `length`
  double rotation = 0.0;     // rad over `length`
  int windows = 0;
};
Drift relative_drift(const std::vector<Pose2>& truth, const std::vector<Pose2>& estimate, double length = 100.0,
                     double step = 10.0);

// the same over n samples read in place: truth(i) and estimate(i) give the
// i-th sample's poses (a run's series, without copying its poses out)
template <class Truth, class Estimate>
Drift relative_drift(std::size_t n, const Truth& truth, const Estimate& estimate, double length, double step) {
  Drift d;
  if (n < 2) return d;
  // the true travelled distance at each sample
  std::vector<double> s(n, 0.0);
  for (std::size_t i = 1; i < n; ++i) s[i] = s[i - 1] + distance(truth(i - 1).position(), truth(i).position());
  double next = 0.0;
  std::size_t j = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (s[i] < next) continue;
    next = s[i] + step;
    j = std::max(j, i);
    while (j < n && s[j] < s[i] + length) ++j;
    if (j == n) break;
    const Pose2 e = between(between(truth(i), truth(j)), between(estimate(i), estimate(j)));
    d.translation += norm(e.position());
    d.rotation += std::abs(e.yaw);
    ++d.windows;
  }
  if (d.windows > 0) {
    d.translation /= d.windows;
    d.rotation /= d.windows;
  }
  return d;
}

}  // namespace paddock::runner
