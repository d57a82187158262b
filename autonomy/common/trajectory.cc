#include "autonomy/common/trajectory.h"

#include <algorithm>
#include <cassert>
#include <cmath>

#include "autonomy/common/polyline.h"

namespace paddock {

double Trajectory::wrap(double s) const {
  if (closed) {
    if (s >= 0.0 && s < length) return s;  // what fmod would return, exactly
    s = std::fmod(s, length);
    return s < 0.0 ? s + length : s;
  }
  return std::clamp(s, 0.0, length);
}

TrajectoryPoint Trajectory::at(double s_query) const {
  assert(!empty());
  const double s = wrap(s_query);
  // points are equally spaced, so the segment index is a division away
  const std::size_t n = points.size();
  const std::size_t nseg = closed ? n : n - 1;
  const double step = length / static_cast<double>(nseg);
  auto i = static_cast<std::size_t>(s / step);
  if (i >= nseg) i = nseg - 1;
  const TrajectoryPoint& a = points[i];
  const TrajectoryPoint& b = points[(i + 1) % n];
  const double t = std::clamp((s - static_cast<double>(i) * step) / step, 0.0, 1.0);
  TrajectoryPoint p;
  p.s = s;
  p.x = a.x + t * (b.x - a.x);
  p.y = a.y + t * (b.y - a.y);
  p.heading = wrap_angle(a.heading + t * wrap_angle(b.heading - a.heading));
  p.curvature = a.curvature + t * (b.curvature - a.curvature);
  p.speed = a.speed + t * (b.speed - a.speed);
  return p;
}

TrajectoryProjection project(const Trajectory& traj, Vec2 q, double s_hint, double window) {
  assert(!traj.empty());
  const std::size_t n = traj.points.size();
  const std::size_t nseg = traj.closed ? n : n - 1;
  const double step = traj.length / static_cast<double>(nseg);
  // the segments to search: all of them, or those within the window around the hint
  long first = 0;
  long last = static_cast<long>(nseg) - 1;
  if (window > 0.0 && 2.0 * window < traj.length) {
    const long centre = static_cast<long>(std::floor(traj.wrap(s_hint) / step));
    const long half = static_cast<long>(std::ceil(window / step));
    first = centre - half;
    last = centre + half;
    if (!traj.closed) {
      first = std::max(first, 0L);
      last = std::min(last, static_cast<long>(nseg) - 1);
    }
  }
  double best_d2 = INFINITY;
  double best_s = 0.0;
  double best_side = 0.0;
  // segment k is segment k mod nseg (a closed window wraps past the start)
  const long m = static_cast<long>(nseg);
  auto i = static_cast<std::size_t>(((first % m) + m) % m);
  for (long k = first; k <= last; ++k, i = i + 1 == nseg ? 0 : i + 1) {
    const Vec2 a = traj.points[i].position();
    const Vec2 b = traj.points[i + 1 == n ? 0 : i + 1].position();
    const auto [t, d2] = project_on_segment(q, a, b);
    if (d2 < best_d2) {
      best_d2 = d2;
      best_s = (static_cast<double>(i) + t) * step;
      best_side = cross(b - a, q - a);
    }
  }
  TrajectoryProjection out;
  out.s = traj.wrap(best_s);
  out.ref = traj.at(out.s);
  const double d = std::sqrt(best_d2);
  out.offset = best_side >= 0.0 ? d : -d;
  return out;
}

TrajectoryProjection project_near(const Trajectory& traj, Vec2 q, double s_hint, double window, double relocalize) {
  TrajectoryProjection near = project(traj, q, s_hint, window);
  if (std::abs(near.offset) > relocalize) {
    const TrajectoryProjection all = project(traj, q, 0.0, 0.0);
    if (std::abs(all.offset) < std::abs(near.offset)) near = all;
  }
  return near;
}

}  // namespace paddock
