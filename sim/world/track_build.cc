// the pieces every kind of track uses: nearest distances to a boundary, the
// median spacing, and gates from timekeeping posts and big orange cones.
#include "sim/world/track_build.h"

#include <algorithm>
#include <limits>
#include <utility>
#include <vector>

#include "autonomy/common/polyline.h"

namespace paddock::world::detail {

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

// distance from q to a polyline (brute force over its segments)
// a pair of posts as a gate whose left post is on the left of `heading`
Segment gate_from_posts(Vec2 p, Vec2 q, Vec2 heading) {
  const Vec2 mid = (p + q) * 0.5;
  return cross(heading, p - mid) > 0.0 ? Segment{p, q} : Segment{q, p};
}

std::vector<Post> group_posts(std::vector<std::pair<double, Vec2>> cones) {
  std::sort(cones.begin(), cones.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<Post> posts;
  std::size_t i = 0;
  while (i < cones.size()) {
    std::size_t k = i + 1;
    while (k < cones.size() && cones[k].first - cones[k - 1].first < kPostGroupDistance) ++k;
    Post p;
    for (std::size_t m = i; m < k; ++m) {
      p.along += cones[m].first;
      p.position += cones[m].second;
    }
    p.along /= static_cast<double>(k - i);
    p.position = p.position / static_cast<double>(k - i);
    posts.push_back(p);
    i = k;
  }
  return posts;
}

}  // namespace paddock::world::detail
