// the Delaunay triangulation of a cone map: against brute force on random
// point sets, Euler's counts, and the degenerate maps.
#include "autonomy/planning/delaunay.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include "autonomy/common/cone.h"
#include "autonomy/common/geometry.h"

namespace paddock::planning {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::vector<Cone> random_cones(std::mt19937& rng, std::size_t n, double size) {
  std::uniform_real_distribution<double> u(0.0, size);
  std::vector<Cone> cones;
  for (std::size_t i = 0; i < n; ++i) cones.push_back({{u(rng), u(rng)}, ConeColor::Unknown});
  return cones;
}

// the circumcircle of a, b, c: centre and squared radius
std::pair<Vec2, double> circumcircle(Vec2 a, Vec2 b, Vec2 c) {
  const Vec2 ab = b - a, ac = c - a;
  const double d = 2.0 * cross(ab, ac);
  const Vec2 off{(ac.y * squared_norm(ab) - ab.y * squared_norm(ac)) / d,
                 (ab.x * squared_norm(ac) - ac.x * squared_norm(ab)) / d};
  return {a + off, squared_norm(off)};
}

// true when some point other than the triangle's lies inside its
// circumcircle by more than a relative tolerance
bool circle_has_point_inside(const std::vector<Cone>& cones, std::size_t i, std::size_t j,
                             std::size_t k) {
  const auto [centre, r2] = circumcircle(cones[i].position, cones[j].position, cones[k].position);
  for (std::size_t m = 0; m < cones.size(); ++m) {
    if (m == i || m == j || m == k) continue;
    if (squared_norm(cones[m].position - centre) < r2 * (1.0 - 1e-9)) return true;
  }
  return false;
}

// the number of points on the convex hull (Andrew's monotone chain, points
// on a hull edge counted: a triangulation has a vertex there)
std::size_t hull_points(const std::vector<Cone>& cones) {
  std::vector<Vec2> p;
  for (const Cone& c : cones) p.push_back(c.position);
  std::sort(p.begin(), p.end(), [](Vec2 a, Vec2 b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
  std::vector<Vec2> h(2 * p.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    while (k >= 2 && cross(h[k - 1] - h[k - 2], p[i] - h[k - 2]) < 0.0) --k;
    h[k++] = p[i];
  }
  for (std::size_t i = p.size() - 1, t = k + 1; i-- > 0;) {
    while (k >= t && cross(h[k - 1] - h[k - 2], p[i] - h[k - 2]) < 0.0) --k;
    h[k++] = p[i];
  }
  return k - 1;
}

// every triangle's edges are edges, every edge is unique, and midpoints
// and lengths are what they say
void expect_consistent(const Triangulation& t, const std::vector<Cone>& cones) {
  std::set<std::pair<std::size_t, std::size_t>> edges;
  for (const TriEdge& e : t.edges) {
    EXPECT_LT(e.a, e.b);
    EXPECT_TRUE(edges.insert({e.a, e.b}).second) << "edge " << e.a << "-" << e.b << " twice";
    const Vec2 pa = cones[e.a].position, pb = cones[e.b].position;
    EXPECT_NEAR(e.midpoint.x, 0.5 * (pa.x + pb.x), 1e-12);
    EXPECT_NEAR(e.midpoint.y, 0.5 * (pa.y + pb.y), 1e-12);
    EXPECT_NEAR(e.length, distance(pa, pb), 1e-12);
  }
  for (const TriFace& f : t.triangles) {
    EXPECT_LT(f[0], f[1]);
    EXPECT_LT(f[0], f[2]);
    // counter-clockwise
    EXPECT_GT(cross(cones[f[1]].position - cones[f[0]].position,
                    cones[f[2]].position - cones[f[0]].position), 0.0);
    for (int k = 0; k < 3; ++k) {
      const std::size_t a = f[static_cast<std::size_t>(k)], b = f[static_cast<std::size_t>((k + 1) % 3)];
      EXPECT_TRUE(edges.count({std::min(a, b), std::max(a, b)})) << a << "-" << b;
    }
  }
}

TEST(Delaunay, RandomPointsAreDelaunayAndSatisfyEuler) {
  std::mt19937 rng(20240611);
  for (std::size_t n : {3u, 4u, 10u, 50u, 200u, 500u}) {
    for (int rep = 0; rep < 5; ++rep) {
      const auto cones = random_cones(rng, n, 100.0);
      const Triangulation t = triangulate(cones);
      ASSERT_TRUE(t.ok()) << t.reason;
      EXPECT_EQ(t.vertices, n);
      EXPECT_EQ(t.merged, 0u);
      expect_consistent(t, cones);
      // the Delaunay property: no point inside any triangle's circumcircle
      for (const TriFace& f : t.triangles)
        EXPECT_FALSE(circle_has_point_inside(cones, f[0], f[1], f[2]))
            << "n " << n << " triangle " << f[0] << " " << f[1] << " " << f[2];
      // Euler: E = 3n - 3 - h, T = 2n - 2 - h with h points on the hull
      const std::size_t h = hull_points(cones);
      EXPECT_EQ(t.edges.size(), 3 * n - 3 - h) << "n " << n;
      EXPECT_EQ(t.triangles.size(), 2 * n - 2 - h) << "n " << n;
    }
  }
}

// in general position the Delaunay triangulation is unique: exactly the
// triples with an empty circumcircle, found by trying all of them
TEST(Delaunay, MatchesBruteForceTriangles) {
  std::mt19937 rng(7);
  for (int rep = 0; rep < 5; ++rep) {
    const auto cones = random_cones(rng, 30, 50.0);
    std::set<TriFace> brute;
    for (std::size_t i = 0; i < cones.size(); ++i)
      for (std::size_t j = i + 1; j < cones.size(); ++j)
        for (std::size_t k = j + 1; k < cones.size(); ++k) {
          if (circle_has_point_inside(cones, i, j, k)) continue;
          // counter-clockwise with the smallest index first, as triangulate gives them
          const bool ccw = cross(cones[j].position - cones[i].position,
                                 cones[k].position - cones[i].position) > 0.0;
          brute.insert(ccw ? TriFace{i, j, k} : TriFace{i, k, j});
        }
    const Triangulation t = triangulate(cones);
    ASSERT_TRUE(t.ok());
    const std::set<TriFace> got(t.triangles.begin(), t.triangles.end());
    EXPECT_EQ(got, brute);
  }
}

// cones on a regular grid (an acceleration lane): many co-circular
// quadruples; any choice of diagonal is Delaunay, the counts still hold
TEST(Delaunay, CoCircularGrid) {
  std::vector<Cone> cones;
  for (int i = 0; i < 20; ++i) {
    cones.push_back({{5.0 * i, 1.5}, ConeColor::Blue});
    cones.push_back({{5.0 * i, -1.5}, ConeColor::Yellow});
  }
  const Triangulation t = triangulate(cones);
  ASSERT_TRUE(t.ok()) << t.reason;
  expect_consistent(t, cones);
  const std::size_t n = cones.size();
  EXPECT_EQ(t.triangles.size(), 2 * n - 2 - n);  // every point on the hull
  EXPECT_EQ(t.edges.size(), 3 * n - 3 - n);
  for (const TriFace& f : t.triangles) EXPECT_FALSE(circle_has_point_inside(cones, f[0], f[1], f[2]));
}

TEST(Delaunay, EmptyAndTooFewCones) {
  const Triangulation none = triangulate({});
  EXPECT_EQ(none.status, TriangulationStatus::NoCones);
  EXPECT_FALSE(none.reason.empty());
  EXPECT_TRUE(none.edges.empty());

  const Triangulation one = triangulate({{{1.0, 2.0}, ConeColor::Blue}});
  EXPECT_EQ(one.status, TriangulationStatus::TooFewCones);
  EXPECT_FALSE(one.reason.empty());
  EXPECT_TRUE(one.edges.empty());
  EXPECT_TRUE(one.triangles.empty());

  const Triangulation two = triangulate({{{0.0, 0.0}, ConeColor::Blue}, {{3.0, 4.0}, ConeColor::Yellow}});
  EXPECT_EQ(two.status, TriangulationStatus::TooFewCones);
  ASSERT_EQ(two.edges.size(), 1u);
  EXPECT_EQ(two.edges[0].a, 0u);
  EXPECT_EQ(two.edges[0].b, 1u);
  EXPECT_DOUBLE_EQ(two.edges[0].length, 5.0);
  EXPECT_DOUBLE_EQ(two.edges[0].midpoint.x, 1.5);
  EXPECT_DOUBLE_EQ(two.edges[0].midpoint.y, 2.0);
}

TEST(Delaunay, CollinearConesGiveTheChain) {
  // on a slanted line, out of order
  std::vector<Cone> cones;
  for (int i : {3, 0, 4, 1, 2}) cones.push_back({{1.0 + 2.0 * i, -1.0 + 1.0 * i}, ConeColor::Blue});
  const Triangulation t = triangulate(cones);
  EXPECT_EQ(t.status, TriangulationStatus::Collinear);
  EXPECT_FALSE(t.reason.empty());
  EXPECT_TRUE(t.triangles.empty());
  // the chain joins neighbours along the line: indices 1-3, 3-4, 4-0, 0-2
  ASSERT_EQ(t.edges.size(), 4u);
  const std::set<std::pair<std::size_t, std::size_t>> want{{1, 3}, {3, 4}, {0, 4}, {0, 2}};
  std::set<std::pair<std::size_t, std::size_t>> got;
  for (const TriEdge& e : t.edges) got.insert({e.a, e.b});
  EXPECT_EQ(got, want);
  for (const TriEdge& e : t.edges) EXPECT_NEAR(e.length, std::sqrt(5.0), 1e-12);
}

TEST(Delaunay, DoubledConesAreMerged) {
  std::mt19937 rng(3);
  const auto base = random_cones(rng, 40, 60.0);
  // every cone twice: exactly, and 5 mm off; one more 2 cm off stays apart
  std::vector<Cone> cones = base;
  for (std::size_t i = 0; i < base.size(); ++i) {
    Cone c = base[i];
    if (i % 2 == 1) c.position += Vec2{0.003, -0.004};
    cones.push_back(c);
  }
  cones.push_back({base[0].position + Vec2{0.02, 0.0}, ConeColor::Unknown});
  const Triangulation t = triangulate(cones);
  ASSERT_TRUE(t.ok()) << t.reason;
  EXPECT_EQ(t.vertices, base.size() + 1);
  EXPECT_EQ(t.merged, base.size());
  ASSERT_EQ(t.representative.size(), cones.size());
  for (std::size_t i = 0; i < base.size(); ++i) {
    EXPECT_EQ(t.representative[i], i);
    EXPECT_EQ(t.representative[base.size() + i], i);
  }
  EXPECT_EQ(t.representative.back(), cones.size() - 1);
  // only representatives appear in the edges
  for (const TriEdge& e : t.edges) {
    EXPECT_EQ(t.representative[e.a], e.a);
    EXPECT_EQ(t.representative[e.b], e.b);
  }
  expect_consistent(t, cones);

  // a whole map doubled triangulates as the map itself
  std::vector<Cone> doubled = base;
  doubled.insert(doubled.end(), base.begin(), base.end());
  const Triangulation a = triangulate(base), b = triangulate(doubled);
  ASSERT_EQ(a.edges.size(), b.edges.size());
  for (std::size_t i = 0; i < a.edges.size(); ++i) {
    EXPECT_EQ(a.edges[i].a, b.edges[i].a);
    EXPECT_EQ(a.edges[i].b, b.edges[i].b);
  }
  EXPECT_EQ(a.triangles, b.triangles);

  // three cones that are one: too few
  const Triangulation same =
      triangulate({{{1.0, 1.0}, ConeColor::Blue}, {{1.0, 1.0}, ConeColor::Blue}, {{1.005, 1.0}, ConeColor::Blue}});
  EXPECT_EQ(same.status, TriangulationStatus::TooFewCones);
  EXPECT_EQ(same.vertices, 1u);
  EXPECT_TRUE(same.edges.empty());
}

TEST(Delaunay, NonFiniteConesAreSkipped) {
  std::vector<Cone> cones{{{0.0, 0.0}, ConeColor::Blue},
                          {{kNaN, 1.0}, ConeColor::Blue},
                          {{4.0, 0.0}, ConeColor::Yellow},
                          {{0.0, std::numeric_limits<double>::infinity()}, ConeColor::Yellow},
                          {{0.0, 3.0}, ConeColor::Yellow}};
  const Triangulation t = triangulate(cones);
  ASSERT_TRUE(t.ok()) << t.reason;
  EXPECT_EQ(t.skipped, 2u);
  EXPECT_EQ(t.vertices, 3u);
  EXPECT_EQ(t.representative[1], kNoCone);
  EXPECT_EQ(t.representative[3], kNoCone);
  ASSERT_EQ(t.triangles.size(), 1u);
  EXPECT_EQ(t.triangles[0], (TriFace{0, 2, 4}));
  EXPECT_EQ(t.edges.size(), 3u);

  std::vector<Cone> all_nan(4, Cone{{kNaN, kNaN}, ConeColor::Blue});
  const Triangulation n = triangulate(all_nan);
  EXPECT_EQ(n.status, TriangulationStatus::NoCones);
  EXPECT_EQ(n.skipped, 4u);
}

TEST(Delaunay, DeterministicAndOrderedOutput) {
  std::mt19937 rng(11);
  const auto cones = random_cones(rng, 150, 80.0);
  const Triangulation a = triangulate(cones), b = triangulate(cones);
  ASSERT_EQ(a.edges.size(), b.edges.size());
  for (std::size_t i = 0; i < a.edges.size(); ++i) {
    EXPECT_EQ(a.edges[i].a, b.edges[i].a);
    EXPECT_EQ(a.edges[i].b, b.edges[i].b);
    if (i > 0) {
      EXPECT_TRUE(a.edges[i - 1].a < a.edges[i].a ||
                  (a.edges[i - 1].a == a.edges[i].a && a.edges[i - 1].b < a.edges[i].b));
    }
  }
  EXPECT_TRUE(std::is_sorted(a.triangles.begin(), a.triangles.end()));
  EXPECT_EQ(a.triangles, b.triangles);
}

}  // namespace
}  // namespace paddock::planning
