#pragma once
// the reference trajectory: what planning hands to control.
#include <cstddef>
#include <vector>

#include "autonomy/common/geometry.h"

namespace paddock {

// one sample of a reference trajectory
struct TrajectoryPoint {
  double s = 0.0;          // arc length from the first point (m)
  double x = 0.0;          // position in the map frame (m)
  double y = 0.0;
  double heading = 0.0;    // tangent direction (rad, counter-clockwise from +x)
  double curvature = 0.0;  // signed, > 0 turning left (1/m)
  double speed = 0.0;      // reference speed (m/s)

  Vec2 position() const { return {x, y}; }
};

// the fields a controller follows (position, heading, curvature, speed) are
// finite; s, the point's arc-length coordinate, is not checked
inline bool finite(const TrajectoryPoint& p) {
  return finite(p.x) && finite(p.y) && finite(p.heading) && finite(p.curvature) && finite(p.speed);
}

// samples at a fixed arc-length spacing; a closed trajectory's last point
// connects back to the first, and `length` then includes that closing step
struct Trajectory {
  std::vector<TrajectoryPoint> points;
  bool closed = false;
  double length = 0.0;  // m

  bool empty() const { return points.size() < 2; }
  // s wrapped into [0, length) when closed, clamped into [0, length] when open
  double wrap(double s) const;
  // linear interpolation of every field at arc length s (heading on the circle)
  TrajectoryPoint at(double s) const;
};

// the closest point of a trajectory to a query position
struct TrajectoryProjection {
  double s = 0.0;        // arc length of the closest point (m)
  double offset = 0.0;   // signed distance of the query from the path, > 0 left of it (m)
  TrajectoryPoint ref;   // the interpolated reference at s
};

// the closest point, searched within +-window metres of arc length around
// s_hint (a window <= 0 searches everything); the trajectory must not be empty
TrajectoryProjection project(const Trajectory& traj, Vec2 q, double s_hint, double window);
// a tracked point's projection: within the window around s_hint, unless that
// one lies farther than `relocalize` from q and a search of everything finds
// a nearer one
TrajectoryProjection project_near(const Trajectory& traj, Vec2 q, double s_hint, double window, double relocalize);

}  // namespace paddock
