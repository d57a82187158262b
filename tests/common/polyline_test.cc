// polyline_distance against the distance to every segment, and the grid
// index against polyline_distance bit for bit
#include "autonomy/common/polyline.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

namespace paddock {
namespace {

// the oracle: the least distance to any segment, each by its own hypot
double every_segment(const std::vector<Vec2>& pts, bool closed, Vec2 q) {
  double best = std::numeric_limits<double>::infinity();
  const std::size_t n = pts.size();
  for (std::size_t i = 0; i + (closed ? 0 : 1) < n; ++i) best = std::min(best, point_segment_distance(q, pts[i], pts[(i + 1) % n]));
  return best;
}

// a track's boundary: a wobbly loop of radius ~60 m, a cone every ~4 m
std::vector<Vec2> loop(std::mt19937& rng, double radius) {
  std::uniform_real_distribution<double> wobble(-0.4, 0.4);
  std::vector<Vec2> pts;
  const int n = static_cast<int>(2.0 * M_PI * radius / 4.0);
  for (int i = 0; i < n; ++i) {
    const double a = 2.0 * M_PI * i / n;
    const double r = radius * (1.0 + 0.3 * std::sin(3.0 * a)) + wobble(rng);
    pts.push_back({r * std::cos(a) + 500.0, r * std::sin(a) - 200.0});
  }
  return pts;
}

// polylines of every shape the index must not get wrong
std::vector<std::vector<Vec2>> shapes() {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-100.0, 100.0);
  std::vector<std::vector<Vec2>> out;
  out.push_back(loop(rng, 60.0));
  out.push_back(loop(rng, 20.0));
  std::vector<Vec2> scatter;  // random points: long segments crossing the box
  for (int i = 0; i < 200; ++i) scatter.push_back({u(rng), u(rng)});
  out.push_back(scatter);
  std::vector<Vec2> line;  // collinear: a box of zero height
  for (int i = 0; i < 50; ++i) line.push_back({i * 3.0, 7.0});
  out.push_back(line);
  std::vector<Vec2> repeats = loop(rng, 30.0);  // repeated points: zero-length segments
  for (std::size_t i = 0; i < repeats.size(); i += 5) repeats.insert(repeats.begin() + static_cast<std::ptrdiff_t>(i), repeats[i]);
  out.push_back(repeats);
  std::vector<Vec2> mixed = loop(rng, 40.0);  // short segments and one across the whole track
  mixed.push_back({mixed.front().x + 300.0, mixed.front().y + 250.0});
  out.push_back(mixed);
  out.push_back({{0.0, 0.0}, {10.0, 0.0}});  // too few for a grid
  return out;
}

TEST(Polyline, DistanceIsTheNearestSegments) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-300.0, 700.0);
  for (const auto& pts : shapes()) {
    for (bool closed : {false, true}) {
      for (int k = 0; k < 300; ++k) {
        const Vec2 q{u(rng), u(rng) - 300.0};
        const double want = every_segment(pts, closed, q);
        EXPECT_NEAR(polyline_distance(pts, closed, q), want, 1e-9 * (1.0 + want));
      }
    }
  }
  EXPECT_EQ(polyline_distance({{1.0, 1.0}}, false, {0.0, 0.0}), std::numeric_limits<double>::infinity());
}

TEST(Polyline, IndexGivesPolylineDistanceBitForBit) {
  std::mt19937 rng(5);
  std::normal_distribution<double> near(0.0, 3.0);
  std::uniform_real_distribution<double> anywhere(-2000.0, 2000.0), pick(0.0, 1.0);
  for (const auto& pts : shapes()) {
    for (bool closed : {false, true}) {
      const PolylineIndex index(pts, closed);
      for (int k = 0; k < 2000; ++k) {
        Vec2 q;
        if (k % 4 == 0) {
          q = {anywhere(rng), anywhere(rng)};  // far, outside the grid too
        } else {  // near the polyline, as the centreline's queries are
          const Vec2 p = pts[static_cast<std::size_t>(pick(rng) * static_cast<double>(pts.size() - 1))];
          q = {p.x + near(rng), p.y + near(rng)};
        }
        const double want = polyline_distance(pts, closed, q);
        ASSERT_EQ(index.distance(q), want) << "query " << q.x << ", " << q.y << " of a polyline of " << pts.size();
      }
      // on the vertices themselves, and a query too far away for cell numbers
      for (const Vec2& p : pts) ASSERT_EQ(index.distance(p), polyline_distance(pts, closed, p));
      ASSERT_EQ(index.distance({1e15, -1e15}), polyline_distance(pts, closed, {1e15, -1e15}));
    }
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const PolylineIndex index(shapes()[0], true);
  EXPECT_EQ(index.distance({nan, 0.0}), std::numeric_limits<double>::infinity());
  EXPECT_EQ(PolylineIndex({}, true).distance({0.0, 0.0}), std::numeric_limits<double>::infinity());
}

}  // namespace
}  // namespace paddock
