// the on-track region: polygons combined by the even-odd rule (each with its
// edges bucketed in horizontal slabs) and annuli.
#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "sim/world/track.h"

namespace paddock::world {

void TrackRegion::add_xor_polygon(const std::vector<Vec2>& polygon) {
  IndexedPolygon ip;
  ip.pts = polygon;
  const std::size_t n = polygon.size();
  if (n < 3) return;
  ip.min_x = ip.max_x = polygon[0].x;
  ip.min_y = ip.max_y = polygon[0].y;
  for (const Vec2& p : polygon) {
    ip.min_x = std::min(ip.min_x, p.x);
    ip.max_x = std::max(ip.max_x, p.x);
    ip.min_y = std::min(ip.min_y, p.y);
    ip.max_y = std::max(ip.max_y, p.y);
  }
  // about one slab per two edges, each slab listing the edges whose y range meets it
  const double span = std::max(ip.max_y - ip.min_y, 1e-6);
  const std::size_t slabs = std::max<std::size_t>(1, n / 2);
  ip.slab_height = span / static_cast<double>(slabs);
  std::vector<std::vector<std::size_t>> buckets(slabs);
  auto slab_of = [&](double y) {
    const double k = std::floor((y - ip.min_y) / ip.slab_height);
    return static_cast<std::size_t>(std::clamp(k, 0.0, static_cast<double>(slabs - 1)));
  };
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2 a = polygon[i], b = polygon[(i + 1) % n];
    for (std::size_t k = slab_of(std::min(a.y, b.y)); k <= slab_of(std::max(a.y, b.y)); ++k) buckets[k].push_back(i);
  }
  ip.slab_begin.push_back(0);
  for (const auto& bk : buckets) {
    ip.edges.insert(ip.edges.end(), bk.begin(), bk.end());
    ip.slab_begin.push_back(ip.edges.size());
  }
  polygons_.push_back(std::move(ip));
}

void TrackRegion::add_annulus(Vec2 centre, double inner_radius, double outer_radius) {
  annuli_.push_back({centre, inner_radius * inner_radius, outer_radius * outer_radius});
}

bool TrackRegion::IndexedPolygon::contains(Vec2 q) const {
  if (q.x < min_x || q.x > max_x || q.y < min_y || q.y > max_y) return false;
  const double k = std::floor((q.y - min_y) / slab_height);
  const auto last = static_cast<double>(slab_begin.size() - 2);
  const auto slab = static_cast<std::size_t>(std::clamp(k, 0.0, last));
  // even-odd rule over the slab's edges (the same test as polygon_contains)
  bool inside = false;
  const std::size_t n = pts.size();
  for (std::size_t e = slab_begin[slab]; e < slab_begin[slab + 1]; ++e) {
    const Vec2 a = pts[edges[e]], b = pts[(edges[e] + 1) % n];
    if ((a.y > q.y) != (b.y > q.y)) {
      const double x = a.x + (q.y - a.y) * (b.x - a.x) / (b.y - a.y);
      if (q.x < x) inside = !inside;
    }
  }
  return inside;
}

bool TrackRegion::contains(Vec2 p) const {
  for (const Annulus& a : annuli_) {
    const double r2 = squared_norm(p - a.centre);
    if (r2 >= a.r2_min && r2 <= a.r2_max) return true;
  }
  bool inside = false;
  for (const IndexedPolygon& poly : polygons_) {
    if (poly.contains(p)) inside = !inside;
  }
  return inside;
}

}  // namespace paddock::world
