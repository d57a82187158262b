#include "autonomy/planning/clearance.h"

#include <algorithm>
#include <cmath>

namespace paddock::planning {

int enforce_clearance(std::vector<Vec2>& path, const std::vector<Cone>& cones, const ClearanceParams& params) {
  if (!(params.clearance > 0.0)) return 0;
  const double c2 = params.clearance * params.clearance;
  int moves = 0;
  for (int pass = 0; pass < params.iterations; ++pass) {
    int moved = 0;
    for (Vec2& p : path) {
      for (const Cone& cone : cones) {
        const Vec2 d = p - cone.position;
        const double d2 = squared_norm(d);
        // a point on the cone itself has no direction to be pushed in
        if (d2 >= c2 || d2 < 1e-12 || !std::isfinite(d2)) continue;
        p = cone.position + d * (params.clearance / std::sqrt(d2));
        ++moved;
      }
    }
    moves += moved;
    if (moved == 0) break;
  }
  return moves;
}

int clear_trajectory(std::vector<Vec2>& points, const Trajectory& traj, const std::vector<Cone>& cones,
                     const ClearanceParams& params, double reach, double tolerance) {
  if (!(params.clearance > 0.0) || cones.empty()) return 0;
  // each point's push: the largest shortfall of a sample near it, away from that sample's cone
  std::vector<double> shortfall(points.size(), 0.0);
  std::vector<Vec2> away(points.size());
  // the samples in runs of kRun along the path: a run's candidate cones are
  // those within the clearance of its bounding box, in the cones' order (a
  // hair wider: never one too few), so each sample finds the nearest cone as
  // a pass over every cone would, the first of equals
  constexpr std::size_t kRun = 32;
  const double gate = params.clearance - tolerance;
  std::vector<const Cone*> near;
  for (std::size_t first = 0; first < traj.points.size(); first += kRun) {
    const std::size_t last = std::min(traj.points.size(), first + kRun);
    Box run;
    for (std::size_t k = first; k < last; ++k) run.add(traj.points[k].position());
    near.clear();
    for (const Cone& c : cones)
      if (run.near(c.position, std::abs(gate))) near.push_back(&c);
    for (std::size_t k = first; k < last; ++k) {
      const Vec2 p = traj.points[k].position();
      const Cone* nearest = nullptr;
      double best2 = gate * gate;
      for (const Cone* c : near) {
        const double d2 = squared_norm(p - c->position);
        if (d2 < best2) {
          best2 = d2;
          nearest = c;
        }
      }
      if (!nearest) continue;
      const double missing = params.clearance - std::sqrt(best2);
      for (std::size_t i = 0; i < points.size(); ++i) {
        if (squared_norm(points[i] - p) > reach * reach || missing <= shortfall[i]) continue;
        const Vec2 d = points[i] - nearest->position;
        const double n = norm(d);
        if (n < 1e-9) continue;
        shortfall[i] = missing;
        away[i] = d / n;
      }
    }
  }
  int moved = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (shortfall[i] <= 0.0) continue;
    points[i] += away[i] * shortfall[i];
    ++moved;
  }
  return moved;
}

}  // namespace paddock::planning
