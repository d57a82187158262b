#pragma once
// the Delaunay triangulation of a cone map (paper section "Planning"): the
// centreline runs through the midpoints of the triangle edges. CGAL does the
// work behind this header (delaunay.cc is the only file that includes it);
// the rest of the project sees plain value types.
#include <array>
#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include "autonomy/common/cone.h"
#include "autonomy/common/geometry.h"

namespace paddock::planning {

inline constexpr std::size_t kNoCone = std::numeric_limits<std::size_t>::max();

// one edge of the triangulation, between two cones of the input map
struct TriEdge {
  std::size_t a = 0;  // index of one cone in the input (a < b)
  std::size_t b = 0;  // index of the other cone
  Vec2 midpoint;      // halfway between the two cones (m)
  double length = 0.0;  // distance between the two cones (m)
};

// one triangle: three cone indices, counter-clockwise
using TriFace = std::array<std::size_t, 3>;

enum class TriangulationStatus {
  Ok,           // a 2D triangulation: edges and triangles
  NoCones,      // no finite cone at all: nothing
  TooFewCones,  // one or two distinct cones: at most one edge, no triangle
  Collinear,    // every cone on one line: a chain of edges, no triangle
};

struct Triangulation {
  // unique edges, sorted by (a, b); every edge of every triangle, and in the
  // degenerate cases the chain of edges along the line of cones
  std::vector<TriEdge> edges;
  // finite triangles (none unless status is Ok), sorted
  std::vector<TriFace> triangles;
  // for each input cone, the cone that stands for it in the triangulation:
  // itself, the lowest-index cone it was merged with (cones closer than
  // kConeMergeDistance), or kNoCone when its position is not finite
  std::vector<std::size_t> representative;
  std::size_t vertices = 0;  // distinct cones triangulated
  std::size_t merged = 0;    // cones merged into another one
  std::size_t skipped = 0;   // cones skipped for a non-finite position
  TriangulationStatus status = TriangulationStatus::NoCones;
  std::string reason;        // empty when Ok; otherwise what is degenerate

  bool ok() const { return status == TriangulationStatus::Ok; }
};

// cones closer than this are one cone (m): a doubled cone in a map
inline constexpr double kConeMergeDistance = 0.01;

// the Delaunay triangulation of the cones' positions. Cones closer than
// kConeMergeDistance are merged into the lowest-index one (see
// `representative`); cones with a non-finite position are skipped. Never
// throws: degenerate maps come back with their status and reason, and with
// whatever edges exist (two cones: one edge; collinear cones: the chain).
// Edges and triangles are sorted, so the result depends only on the input.
Triangulation triangulate(const std::vector<Cone>& cones);

// a readable name of a status, for reasons and logs
const char* to_string(TriangulationStatus s);

}  // namespace paddock::planning
