#pragma once
// polylines and polygons: arc length, resampling, projection, containment, crossings.
#include <algorithm>
#include <cstddef>
#include <optional>
#include <vector>

#include "autonomy/common/geometry.h"

namespace paddock {

// cumulative arc length at each vertex (s[0] = 0); a closed polyline gets one
// more entry, the length including the closing segment back to vertex 0
std::vector<double> cumulative_length(const std::vector<Vec2>& pts, bool closed);

// total length, including the closing segment when closed
double polyline_length(const std::vector<Vec2>& pts, bool closed);

// points at equal arc-length spacing (as close to `spacing` as divides the
// length evenly); an open polyline keeps both end points, a closed one
// starts at vertex 0 and does not repeat it
std::vector<Vec2> resample(const std::vector<Vec2>& pts, bool closed, double spacing);

// the closest point of a polyline to a query point
struct Projection {
  Vec2 point;               // closest point on the polyline
  std::size_t segment = 0;  // index i of the segment pts[i] -> pts[i+1] (wrapping when closed)
  double t = 0.0;           // position along that segment in [0, 1]
  double s = 0.0;           // arc length of the closest point
  double distance = 0.0;    // distance from the query to `point`
  double signed_offset = 0.0;  // > 0 when the query lies left of the polyline's direction
};

// brute force over all segments; pts must have at least two points
Projection project(const std::vector<Vec2>& pts, bool closed, Vec2 q);

// even-odd rule; the polygon is implicitly closed
bool polygon_contains(const std::vector<Vec2>& polygon, Vec2 q);

// signed area (> 0 counter-clockwise)
double polygon_area(const std::vector<Vec2>& polygon);

// where the directed motion p0 -> p1 crosses segment g from its right side to
// its left side (left of the direction g.a -> g.b): the motion fraction in
// [0, 1], or nothing; touching an end point counts
std::optional<double> crossing_right_to_left(Vec2 p0, Vec2 p1, const Segment& g);

// distance from q to the segment a-b
double point_segment_distance(Vec2 q, Vec2 a, Vec2 b);

// where q projects onto the segment a-b: the fraction t in [0, 1] along it
// (0 for a point segment) and the squared distance from q to that point
struct SegmentProjection {
  double t = 0.0;
  double distance2 = 0.0;
};
inline SegmentProjection project_on_segment(Vec2 q, Vec2 a, Vec2 b) {
  const Vec2 ab = b - a;
  const double len2 = squared_norm(ab);
  const double t = len2 > 0.0 ? std::clamp(dot(q - a, ab) / len2, 0.0, 1.0) : 0.0;
  return {t, squared_norm(q - (a + ab * t))};
}

// distance from q to the nearest segment of a polyline (closed: with the
// segment back to the first point); infinite for fewer than 2 points. The
// nearest segment is the one of least squared distance (project_on_segment),
// the lowest index of equals
double polyline_distance(const std::vector<Vec2>& pts, bool closed, Vec2 q);

// many polyline_distance queries to one polyline: its segments in a uniform
// grid, searched in rings of cells outward from the query's until no nearer
// segment can remain; distance(q) equals polyline_distance(pts, closed, q)
// bit for bit (the same nearest segment). A segment whose box spans many
// cells (a polyline of few long segments) is checked on every query instead.
class PolylineIndex {
 public:
  PolylineIndex(std::vector<Vec2> pts, bool closed);
  double distance(Vec2 q) const;

 private:
  std::vector<Vec2> pts_;
  bool closed_ = false;
  std::size_t segments_ = 0;
  Vec2 origin_;            // the grid's lower left corner
  double cell_ = 0.0;      // m, a cell's side (0: no grid, every query brute force)
  long nx_ = 0, ny_ = 0;   // cells across, up
  std::vector<std::size_t> first_;  // per cell: its segments are in_cell_[first_[c] .. first_[c + 1])
  std::vector<std::size_t> in_cell_;
  std::vector<std::size_t> long_;   // the segments checked on every query
};

}  // namespace paddock
