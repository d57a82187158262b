// acceleration: two straight parallel lines of blue and yellow cones; the
// lane's axis is the centreline, the gates and the start pose lie across it.
#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "autonomy/common/line_fit.h"
#include "autonomy/common/polyline.h"
#include "sim/world/track_build.h"

namespace paddock::world::detail {

namespace {

// a straight line of cones: the total-least-squares line through them, the
// cones' largest distance from it and their extent along it
struct ConeLine {
  LineFit fit;
  double max_residual = 0.0;  // m
  double extent = 0.0;        // m
};

ConeLine cone_line(const std::vector<Vec2>& p) {
  ConeLine l;
  l.fit = fit_line(p);
  if (!l.fit.ok()) return l;
  double lo = 0.0, hi = 0.0;
  for (const Vec2& q : p) {
    const Vec2 d = q - l.fit.point;
    l.max_residual = std::max(l.max_residual, std::abs(cross(l.fit.direction, d)));
    lo = std::min(lo, dot(d, l.fit.direction));
    hi = std::max(hi, dot(d, l.fit.direction));
  }
  l.extent = hi - lo;
  return l;
}

}  // namespace

bool looks_like_acceleration(const ConeSets& cs) {
  if (cs.blue.size() < 3 || cs.yellow.size() < 3) return false;
  const ConeLine b = cone_line(cs.blue), y = cone_line(cs.yellow);
  if (!b.fit.ok() || !y.fit.ok()) return false;
  return b.max_residual < kLineTolerance && y.max_residual < kLineTolerance && b.extent > 30.0 &&
         y.extent > 30.0 && std::abs(cross(b.fit.direction, y.fit.direction)) < std::sin(5.0 * kPi / 180.0);
}

void build_acceleration(TrackModel& m, const TrackFile& f, const ConeSets& cs) {
  const LineFit b = fit_line(cs.blue), y = fit_line(cs.yellow);
  Vec2 u = unit(b.direction + (dot(b.direction, y.direction) >= 0.0 ? y.direction : -y.direction));
  // driving direction: the start yaw, else blue on the left
  const bool blue_left_of_u = cross(u, b.point - y.point) > 0.0;
  if (f.start) {
    if (dot(u, f.start->heading()) < 0.0) u = -u;
    if (cross(u, b.point - y.point) < 0.0) {
      m.notes.push_back(f.source + ": the blue cones are on the driver's right (colours swapped relative to the rules)");
    }
  } else if (!blue_left_of_u) {
    u = -u;
  }
  const Vec2 o = (b.point + y.point) * 0.5;
  auto along = [&](Vec2 p) { return dot(p - o, u); };
  auto side = [&](Vec2 p) { return cross(u, p - o); };
  auto by_along = [&](std::vector<Vec2> p) {
    std::sort(p.begin(), p.end(), [&](Vec2 a, Vec2 c) { return along(a) < along(c); });
    return p;
  };
  const bool blue_left = cross(u, b.point - y.point) > 0.0;
  m.left = by_along(blue_left ? cs.blue : cs.yellow);
  m.right = by_along(blue_left ? cs.yellow : cs.blue);
  m.closed = false;

  // gates: timekeeping posts, else big orange cones, else the first boundary cone and 75 m on
  std::vector<std::pair<double, Segment>> gates;
  if (!f.timekeeping.empty()) {
    m.gates_from = "timekeeping";
    for (std::size_t i = 0; i + 1 < f.timekeeping.size(); i += 2) {
      const Segment g = gate_from_posts(f.timekeeping[i], f.timekeeping[i + 1], u);
      gates.push_back({along((g.a + g.b) * 0.5), g});
    }
  } else if (!cs.big_orange.empty()) {
    m.gates_from = "big_orange";
    for (const Segment& g : gates_from_big_orange(cs.big_orange, [&](Vec2 p) { return Station{along(p), side(p)}; })) {
      gates.push_back({along((g.a + g.b) * 0.5), g});
    }
  }
  const double half = 0.5 * std::abs(side(b.point) - side(y.point));
  if (gates.empty()) {
    m.gates_from = "geometry";
    const double a0 = std::min(along(m.left.front()), along(m.right.front()));
    for (double a : {a0, a0 + 75.0}) {
      const Vec2 c = o + u * a, n = left_normal(u);
      gates.push_back({a, Segment{c + n * (half + kGatePostMargin), c - n * (half + kGatePostMargin)}});
    }
  }
  std::sort(gates.begin(), gates.end(), [](const auto& g1, const auto& g2) { return g1.first < g2.first; });
  for (const auto& g : gates) m.gates.push_back(g.second);

  // start: from the file, else before the start gate
  if (f.start) {
    m.start = *f.start;
    m.start_from = "file";
  } else {
    const Vec2 p = o + u * (gates.front().first - kStartToGate);
    m.start = Pose2{p.x, p.y, angle_of(u)};
    m.start_from = "geometry";
  }

  // the layout: every coloured cone, from the start to the last cone; the
  // region keeps some room behind the start for the car's body
  double a_first = std::numeric_limits<double>::infinity(), a_max = -a_first;
  for (const Cone& c : cs.all) {
    if (c.color == ConeColor::Unknown) continue;
    a_first = std::min(a_first, along(c.position));
    a_max = std::max(a_max, along(c.position));
  }
  const double a_start = std::min(a_first, along(m.start.position()));
  const double a_min = std::min(a_first, a_start - kStartMargin);

  // the sides of the lane: all coloured cones off the axis, extended to both ends
  std::vector<Vec2> lside, rside;
  for (const Cone& c : cs.all) {
    if (c.color == ConeColor::Unknown) continue;
    const double s = side(c.position);
    if (s > 0.5) lside.push_back(c.position);
    if (s < -0.5) rside.push_back(c.position);
  }
  lside = by_along(lside);
  rside = by_along(rside);
  const double a_end = a_max + kEndMargin;
  auto extend = [&](std::vector<Vec2>& p) {
    const Vec2 n = left_normal(u);
    const Vec2 first = o + u * a_min + n * side(p.front());
    const Vec2 last = o + u * a_end + n * side(p.back());
    if (along(p.front()) > a_min) p.insert(p.begin(), first);
    if (along(p.back()) < a_end) p.push_back(last);
  };
  extend(lside);
  extend(rside);

  // centreline: the axis from the start to the end of the layout
  const std::vector<Vec2> axis{o + u * a_start, o + u * a_max};
  m.centreline = resample(axis, false, kCentrelineSpacing);
  const PolylineIndex left_index(lside, false), right_index(rside, false);
  for (const Vec2& q : m.centreline) m.width.push_back(left_index.distance(q) + right_index.distance(q));

  std::vector<Vec2> polygon = lside;
  polygon.insert(polygon.end(), rside.rbegin(), rside.rend());
  m.region.add_xor_polygon(polygon);
}

}  // namespace paddock::world::detail
