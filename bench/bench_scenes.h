#pragma once
// the scenes the benchmarks share: a real track read as the program reads it,
// and a synthetic wavy ellipse of about 305 m (semi-axes 60 m and 35 m, a 4 m
// ripple six times round) with blue cones 1.5 m to its left and yellow ones
// 1.5 m to its right.
#include <cmath>
#include <string>
#include <vector>

#include "autonomy/common/cone.h"
#include "autonomy/common/geometry.h"
#include "sim/runner/scenario.h"
#include "sim/world/track.h"

namespace paddock::bench {

// tracks/<name>.csv, parsed and built
inline world::TrackModel real_track(const std::string& name) {
  return world::build_track(runner::load_track_file(std::string(PADDOCK_SOURCE_DIR) + "/tracks/" + name + ".csv"));
}

// the ellipse's centreline at parameter t (rad)
inline Vec2 oval_centreline(double t) {
  const double ripple = 4.0 * std::sin(6.0 * t);
  return {(60.0 + ripple) * std::cos(t), (35.0 + ripple) * std::sin(t)};
}

// its unit tangent at t (central difference)
inline Vec2 oval_tangent(double t) {
  const Vec2 d = oval_centreline(t + 1e-5) - oval_centreline(t - 1e-5);
  return d / norm(d);
}

// per_side cones on each side, evenly in t
inline std::vector<Cone> oval_cones(int per_side) {
  std::vector<Cone> cones;
  for (int i = 0; i < per_side; ++i) {
    const double t = 2.0 * kPi * i / per_side;
    const Vec2 n = left_normal(oval_tangent(t));
    cones.push_back({oval_centreline(t) + 1.5 * n, ConeColor::Blue});
    cones.push_back({oval_centreline(t) - 1.5 * n, ConeColor::Yellow});
  }
  return cones;
}

}  // namespace paddock::bench
