#include "autonomy/stack/gates.h"

#include <limits>

namespace paddock::stack {

std::vector<Vec2> find_posts(const std::vector<Cone>& cones, const GateParams& p) {
  std::vector<Vec2> posts;
  std::vector<int> members;
  for (const Cone& c : cones) {
    if (c.color != ConeColor::BigOrange) continue;
    std::size_t k = 0;
    while (k < posts.size() && distance(posts[k], c.position) > p.post_radius) ++k;
    if (k == posts.size()) {
      posts.push_back(c.position);
      members.push_back(1);
    } else {
      ++members[k];
      posts[k] += (c.position - posts[k]) / static_cast<double>(members[k]);
    }
  }
  return posts;
}

std::vector<Segment> find_gates(const std::vector<Cone>& cones, const GateParams& p) {
  const std::vector<Vec2> posts = find_posts(cones, p);
  // each post's nearest partner in the width band; mutual pairs are gates
  const std::size_t n = posts.size();
  std::vector<std::size_t> nearest(n, n);
  for (std::size_t i = 0; i < n; ++i) {
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t j = 0; j < n; ++j) {
      const double d = distance(posts[i], posts[j]);
      if (j != i && d >= p.min_width && d <= p.max_width && d < best) {
        best = d;
        nearest[i] = j;
      }
    }
  }
  std::vector<Segment> gates;
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t j = nearest[i];
    if (j < n && j > i && nearest[j] == i) gates.push_back({posts[i], posts[j]});
  }
  return gates;
}

Segment orient_gate(const Segment& gate, Vec2 direction) {
  // a is on the left of the direction when it lies counter-clockwise of it from b
  return cross(direction, gate.a - gate.b) >= 0.0 ? gate : Segment{gate.b, gate.a};
}

}  // namespace paddock::stack
