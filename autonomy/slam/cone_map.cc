#include "autonomy/slam/cone_map.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace paddock::slam {

ConeColor MappedCone::color() const { return most_voted(votes); }

ConeMap::ConeMap(const ConeMapParams& params) : params_(params) {}

void ConeMap::add(const std::vector<Cone>& detections) {
  const double gate = params_.association_distance;
  const double gate2 = gate * gate;
  // the mapped cones a detection can reach: those within the gate of the
  // frame's bounding box, in the map's order (a frame covers a small part of
  // the map; a cone this frame adds is taken at once, so never a candidate)
  Box frame;
  for (const Cone& d : detections) frame.add(d.position);
  candidates_.clear();
  for (std::size_t i = 0; i < cones_.size(); ++i)
    if (frame.near(cones_[i].position, gate)) candidates_.push_back(i);
  // each mapped cone takes at most one detection of a frame (a frame sees a cone once)
  taken_.assign(candidates_.size(), 0);
  for (const Cone& d : detections) {
    if (!std::isfinite(d.position.x) || !std::isfinite(d.position.y)) continue;
    // the nearest free mapped cone within the gate (the first of equals)
    std::size_t best = cones_.size(), best_k = 0;
    double best_d2 = gate2;
    for (std::size_t k = 0; k < candidates_.size(); ++k) {
      if (taken_[k]) continue;
      const double d2 = squared_norm(cones_[candidates_[k]].position - d.position);
      if (d2 < best_d2) {
        best_d2 = d2;
        best = candidates_[k];
        best_k = k;
      }
    }
    if (best == cones_.size()) {
      MappedCone m;
      m.position = d.position;
      cones_.push_back(m);
    } else {
      taken_[best_k] = 1;
      // running mean: p_n = p_{n-1} + (x - p_{n-1}) / n
      MappedCone& m = cones_[best];
      m.position += (d.position - m.position) / static_cast<double>(m.observations + 1);
    }
    MappedCone& m = cones_[best];
    ++m.observations;
    ++m.votes[static_cast<std::size_t>(d.color)];
  }
}

std::vector<Cone> ConeMap::cones(int at_least) const {
  std::vector<Cone> out;
  out.reserve(cones_.size());
  for (const MappedCone& m : cones_) {
    if (m.observations >= at_least) out.push_back({m.position, m.color()});
  }
  return out;
}

}  // namespace paddock::slam
