#pragma once
// the total-least-squares line through 2D points (the acceleration planner's
// line and the track builder's test for a straight lane of cones).
#include <string>
#include <vector>

#include "autonomy/common/geometry.h"

namespace paddock {

// the least-squares line through points: orthogonal (total) least squares,
// the principal axis of the points' covariance
struct LineFit {
  Vec2 point;            // the points' centroid (m)
  Vec2 direction;        // unit direction of the line
  double rms = 0.0;      // root mean square distance of the points from it (m)
  std::string reason;    // empty when ok: at least 2 distinct finite points

  bool ok() const { return reason.empty(); }
};
LineFit fit_line(const std::vector<Vec2>& points);

}  // namespace paddock
