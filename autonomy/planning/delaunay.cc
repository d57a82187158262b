// the only file of the project that includes CGAL (it compiles slowly).
#include "autonomy/planning/delaunay.h"

#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <algorithm>
#include <cmath>
#include <utility>

namespace paddock::planning {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using VertexBase = CGAL::Triangulation_vertex_base_with_info_2<std::size_t, Kernel>;
using Tds = CGAL::Triangulation_data_structure_2<VertexBase>;
using Delaunay = CGAL::Delaunay_triangulation_2<Kernel, Tds>;
using Point = Kernel::Point_2;

TriEdge make_edge(const std::vector<Cone>& cones, std::size_t i, std::size_t j) {
  TriEdge e;
  e.a = std::min(i, j);
  e.b = std::max(i, j);
  const Vec2 pa = cones[e.a].position, pb = cones[e.b].position;
  e.midpoint = 0.5 * (pa + pb);
  e.length = distance(pa, pb);
  return e;
}

// representative[i]: the lowest-index cone within kConeMergeDistance of cone
// i that is itself a representative (i when none), kNoCone when not finite.
// A sweep over the cones sorted by x finds the close pairs in O(n log n).
std::vector<std::size_t> merge_close_cones(const std::vector<Cone>& cones) {
  const std::size_t n = cones.size();
  std::vector<std::size_t> rep(n, kNoCone);
  std::vector<std::size_t> order;
  order.reserve(n);
  for (std::size_t i = 0; i < n; ++i)
    if (finite(cones[i].position)) order.push_back(i);
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return cones[a].position.x < cones[b].position.x ||
           (cones[a].position.x == cones[b].position.x && a < b);
  });
  // close pairs (lower index first)
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  const double tol2 = kConeMergeDistance * kConeMergeDistance;
  for (std::size_t k = 0; k < order.size(); ++k) {
    const Vec2 p = cones[order[k]].position;
    for (std::size_t m = k + 1; m < order.size(); ++m) {
      const Vec2 q = cones[order[m]].position;
      if (q.x - p.x >= kConeMergeDistance) break;
      if (squared_norm(q - p) < tol2)
        pairs.emplace_back(std::min(order[k], order[m]), std::max(order[k], order[m]));
    }
  }
  // in index order: a cone joins the lowest-index representative close to it
  std::sort(pairs.begin(), pairs.end(), [](const auto& x, const auto& y) {
    return x.second < y.second || (x.second == y.second && x.first < y.first);
  });
  for (std::size_t i : order) rep[i] = i;
  for (const auto& [lo, hi] : pairs)
    if (rep[hi] == hi && rep[lo] == lo) rep[hi] = lo;
  return rep;
}

}  // namespace

const char* to_string(TriangulationStatus s) {
  switch (s) {
    case TriangulationStatus::Ok: return "ok";
    case TriangulationStatus::NoCones: return "no cones";
    case TriangulationStatus::TooFewCones: return "too few cones";
    case TriangulationStatus::Collinear: return "collinear cones";
  }
  return "?";
}

Triangulation triangulate(const std::vector<Cone>& cones) {
  Triangulation out;
  out.representative = merge_close_cones(cones);

  // the distinct, finite cones
  std::vector<std::pair<Point, std::size_t>> points;
  for (std::size_t i = 0; i < cones.size(); ++i) {
    const std::size_t r = out.representative[i];
    if (r == kNoCone) {
      ++out.skipped;
    } else if (r != i) {
      ++out.merged;
    } else {
      points.emplace_back(Point(cones[i].position.x, cones[i].position.y), i);
    }
  }
  out.vertices = points.size();
  const std::string counts = std::to_string(out.vertices) + " distinct cone(s) of " +
                             std::to_string(cones.size()) + " (" + std::to_string(out.merged) +
                             " merged, " + std::to_string(out.skipped) + " not finite)";

  // fewer than three cones: no triangle, at most one edge
  if (points.empty()) {
    out.status = TriangulationStatus::NoCones;
    out.reason = "triangulation: no cones: " + counts;
    return out;
  }
  if (points.size() < 3) {
    out.status = TriangulationStatus::TooFewCones;
    out.reason = "triangulation: fewer than 3 cones: " + counts;
    if (points.size() == 2) out.edges.push_back(make_edge(cones, points[0].second, points[1].second));
    return out;
  }

  // CGAL: a spatial sort, then incremental insertion; info carries the index
  const Delaunay dt(points.begin(), points.end());

  for (auto e = dt.finite_edges_begin(); e != dt.finite_edges_end(); ++e) {
    const std::size_t i = e->first->vertex(Delaunay::ccw(e->second))->info();
    const std::size_t j = e->first->vertex(Delaunay::cw(e->second))->info();
    out.edges.push_back(make_edge(cones, i, j));
  }
  std::sort(out.edges.begin(), out.edges.end(), [](const TriEdge& x, const TriEdge& y) {
    return x.a < y.a || (x.a == y.a && x.b < y.b);
  });

  if (dt.dimension() < 2) {
    out.status = TriangulationStatus::Collinear;
    out.reason = "triangulation: all cones on one line, no triangle: " + counts;
    return out;
  }
  for (auto f = dt.finite_faces_begin(); f != dt.finite_faces_end(); ++f) {
    TriFace t{f->vertex(0)->info(), f->vertex(1)->info(), f->vertex(2)->info()};
    // rotate the smallest index first, keeping the counter-clockwise order
    std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
    out.triangles.push_back(t);
  }
  std::sort(out.triangles.begin(), out.triangles.end());
  out.status = TriangulationStatus::Ok;
  return out;
}

}  // namespace paddock::planning
