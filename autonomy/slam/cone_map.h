#pragma once
// the stack's map of cones, built from detections at known poses: each
// detection is associated with the nearest mapped cone within a gate, whose
// position is the running mean of its observations and whose colour is the
// majority of the coloured votes. With `slam = ground_truth` the poses are the
// true ones; with the SLAM modes the back end's map replaces it (assign).
#include <array>
#include <cstddef>
#include <utility>
#include <vector>

#include "autonomy/common/cone.h"
#include "autonomy/common/geometry.h"
#include "autonomy/common/params.h"

namespace paddock::slam {

struct ConeMapParams {
  // half the smallest cone spacing of a real track (~2 m in a hairpin) keeps
  // neighbours apart while absorbing centimetres of noise
  double association_distance = 1.0;
  // a real cone is seen in most frames while the car approaches it (~20
  // frames from 20 m at 10 m/s), a false positive of a good pipeline rarely
  // repeats at one place; over a 10-lap run at 0.2 ghosts per frame, 2
  // sightings let dozens of ghosts in
  int min_observations = 5;

  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(association_distance), {"m", params::in(0.01, 10.0),
                                            "a detection farther from every mapped cone starts a new one"});
    v(PADDOCK_PARAM(min_observations), {"", params::in(1, 1000), "sightings before a mapped cone counts"});
  }
};

// the most voted colour of per-ConeColor votes (in enum order); unknown
// only when no coloured vote was ever cast
template <class T>
ConeColor most_voted(const std::array<T, 5>& votes) {
  int best = -1;
  T best_votes = 0;
  for (int c = 0; c < 5; ++c) {
    if (static_cast<ConeColor>(c) == ConeColor::Unknown) continue;
    if (votes[static_cast<std::size_t>(c)] > best_votes) {
      best = c;
      best_votes = votes[static_cast<std::size_t>(c)];
    }
  }
  return best < 0 ? ConeColor::Unknown : static_cast<ConeColor>(best);
}

struct MappedCone {
  Vec2 position;                     // mean of the associated observations (m, map frame)
  int observations = 0;
  std::array<double, 5> votes{};     // per ConeColor, in enum order (weights: a vote is 1 here)
  ConeColor color() const;           // the most voted colour, ignoring unknown unless it is all there is
};

class ConeMap {
 public:
  explicit ConeMap(const ConeMapParams& params = {});

  // one frame of detections in the map frame; non-finite positions are skipped
  void add(const std::vector<Cone>& detections);
  // the cones seen at least min_observations times (or `at_least` times)
  std::vector<Cone> cones() const { return cones(params_.min_observations); }
  std::vector<Cone> cones(int at_least) const;
  const std::vector<MappedCone>& all() const { return cones_; }
  std::size_t size() const { return cones_.size(); }
  void clear() { cones_.clear(); }
  // the map as a SLAM back end estimated it (its landmarks, their sightings
  // and votes), replacing what was there
  void assign(std::vector<MappedCone> cones) { cones_ = std::move(cones); }

 private:
  ConeMapParams params_;
  std::vector<MappedCone> cones_;
  // add()'s scratch: the mapped cones near a frame, and which of them it took
  std::vector<std::size_t> candidates_;
  std::vector<char> taken_;
};

}  // namespace paddock::slam
