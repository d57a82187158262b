#include "autonomy/common/polyline.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>

namespace paddock {

std::vector<double> cumulative_length(const std::vector<Vec2>& pts, bool closed) {
  std::vector<double> s;
  if (pts.empty()) return s;
  s.reserve(pts.size() + 1);
  s.push_back(0.0);
  for (std::size_t i = 1; i < pts.size(); ++i) s.push_back(s.back() + distance(pts[i - 1], pts[i]));
  if (closed) s.push_back(s.back() + distance(pts.back(), pts.front()));
  return s;
}

double polyline_length(const std::vector<Vec2>& pts, bool closed) {
  const auto s = cumulative_length(pts, closed);
  return s.empty() ? 0.0 : s.back();
}

std::vector<Vec2> resample(const std::vector<Vec2>& pts, bool closed, double spacing) {
  assert(spacing > 0.0);
  if (pts.size() < 2) return pts;
  std::vector<Vec2> v = pts;
  if (closed) v.push_back(pts.front());
  const auto s = cumulative_length(v, false);
  const double total = s.back();
  if (total <= 0.0) return {pts.front()};
  // n intervals of equal length, the count chosen nearest to the asked spacing
  const auto n = static_cast<std::size_t>(std::max(1.0, std::round(total / spacing)));
  std::vector<Vec2> out;
  out.reserve(n + 1);
  std::size_t seg = 0;
  const std::size_t count = closed ? n : n + 1;
  for (std::size_t k = 0; k < count; ++k) {
    const double sk = total * static_cast<double>(k) / static_cast<double>(n);
    while (seg + 2 < s.size() && s[seg + 1] < sk) ++seg;
    const double len = s[seg + 1] - s[seg];
    const double t = len > 0.0 ? std::clamp((sk - s[seg]) / len, 0.0, 1.0) : 0.0;
    out.push_back(v[seg] + (v[seg + 1] - v[seg]) * t);
  }
  return out;
}

Projection project(const std::vector<Vec2>& pts, bool closed, Vec2 q) {
  assert(pts.size() >= 2);
  Projection best;
  best.distance = INFINITY;
  const std::size_t nseg = closed ? pts.size() : pts.size() - 1;
  double s0 = 0.0;
  for (std::size_t i = 0; i < nseg; ++i) {
    const Vec2 a = pts[i];
    const Vec2 b = pts[(i + 1) % pts.size()];
    const Vec2 ab = b - a;
    const double len2 = squared_norm(ab);
    const double t = len2 > 0.0 ? std::clamp(dot(q - a, ab) / len2, 0.0, 1.0) : 0.0;
    const Vec2 p = a + ab * t;
    const double d = distance(q, p);
    const double len = std::sqrt(len2);
    if (d < best.distance) {
      best.point = p;
      best.segment = i;
      best.t = t;
      best.s = s0 + t * len;
      best.distance = d;
      best.signed_offset = cross(ab, q - a) >= 0.0 ? d : -d;
    }
    s0 += len;
  }
  return best;
}

bool polygon_contains(const std::vector<Vec2>& polygon, Vec2 q) {
  bool inside = false;
  const std::size_t n = polygon.size();
  for (std::size_t i = 0, j = n - 1; i < n; j = i++) {
    const Vec2 a = polygon[i], b = polygon[j];
    if ((a.y > q.y) != (b.y > q.y)) {
      const double x = a.x + (q.y - a.y) * (b.x - a.x) / (b.y - a.y);
      if (q.x < x) inside = !inside;
    }
  }
  return inside;
}

double polygon_area(const std::vector<Vec2>& polygon) {
  double a = 0.0;
  const std::size_t n = polygon.size();
  for (std::size_t i = 0; i < n; ++i) a += cross(polygon[i], polygon[(i + 1) % n]);
  return 0.5 * a;
}

std::optional<double> crossing_right_to_left(Vec2 p0, Vec2 p1, const Segment& g) {
  const Vec2 d = g.b - g.a;
  // side of each motion end: < 0 right of the gate's direction, > 0 left
  const double side0 = cross(d, p0 - g.a);
  const double side1 = cross(d, p1 - g.a);
  if (!(side0 < 0.0 && side1 >= 0.0)) return std::nullopt;
  const double f = side0 / (side0 - side1);
  const Vec2 hit = p0 + (p1 - p0) * f;
  const double len2 = squared_norm(d);
  const double u = dot(hit - g.a, d) / len2;
  if (u < 0.0 || u > 1.0) return std::nullopt;
  return f;
}

double polyline_distance(const std::vector<Vec2>& pts, bool closed, Vec2 q) {
  const std::size_t n = pts.size();
  if (n < 2) return std::numeric_limits<double>::infinity();
  // the nearest segment by squared distance (no hypot per segment), then its
  // distance as point_segment_distance gives it
  double best = std::numeric_limits<double>::infinity(), best2 = best;
  std::size_t nearest = 0;
  for (std::size_t i = 0; i < (closed ? n : n - 1); ++i) {
    const Vec2 a = pts[i], b = pts[(i + 1) % n];
    // skip segments whose bounding box is farther than the best so far
    const double dx = std::max({std::min(a.x, b.x) - q.x, q.x - std::max(a.x, b.x), 0.0});
    const double dy = std::max({std::min(a.y, b.y) - q.y, q.y - std::max(a.y, b.y), 0.0});
    if (dx >= best || dy >= best) continue;
    const double d2 = project_on_segment(q, a, b).distance2;
    if (d2 < best2) {
      best2 = d2;
      best = std::sqrt(d2);
      nearest = i;
    }
  }
  if (best2 == std::numeric_limits<double>::infinity()) return best2;  // none compared (e.g. q not finite)
  return point_segment_distance(q, pts[nearest], pts[(nearest + 1) % n]);
}

double point_segment_distance(Vec2 q, Vec2 a, Vec2 b) { return distance(q, a + (b - a) * project_on_segment(q, a, b).t); }

}  // namespace paddock
