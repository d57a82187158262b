#include "autonomy/slam/cone_map.h"

#include <cmath>
#include <limits>

namespace paddock::slam {

ConeColor MappedCone::color() const { return most_voted(votes); }

ConeMap::ConeMap(const ConeMapParams& params) : params_(params) {}

void ConeMap::add(const std::vector<Cone>& detections) {
  const double gate2 = params_.association_distance * params_.association_distance;
  // each mapped cone takes at most one detection of a frame (a frame sees a cone once)
  std::vector<char> taken(cones_.size(), 0);
  for (const Cone& d : detections) {
    if (!std::isfinite(d.position.x) || !std::isfinite(d.position.y)) continue;
    // nearest free mapped cone within the gate (brute force: a few hundred cones)
    std::size_t best = cones_.size();
    double best_d2 = gate2;
    for (std::size_t i = 0; i < taken.size(); ++i) {
      if (taken[i]) continue;
      const double d2 = squared_norm(cones_[i].position - d.position);
      if (d2 < best_d2) {
        best_d2 = d2;
        best = i;
      }
    }
    if (best == cones_.size()) {
      MappedCone m;
      m.position = d.position;
      cones_.push_back(m);
      taken.push_back(1);
      best = cones_.size() - 1;
    } else {
      taken[best] = 1;
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
