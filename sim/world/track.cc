// track geometry: boundaries, centreline, widths, gates, start pose and the
// on-track region, derived from the cones of a TrackFile.
//
// the kind comes from the layout, not the file name: a skidpad when most
// blue/yellow cones vote (circle through each cone and its two nearest
// same-coloured neighbours) for two centres 10-30 m apart, each with an inner
// and an outer ring; an acceleration when the blue and the yellow cones each
// lie on a straight line; else a circuit, whose blue and yellow cones are
// chained into two nested loops and oriented so that blue is on the left.
// Unknown cones never take part; exact doubles are merged first.
#include "sim/world/track.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>
#include <utility>
#include <vector>

#include "autonomy/common/format.h"
#include "autonomy/common/line_fit.h"
#include "autonomy/common/polyline.h"

namespace paddock::world {

namespace {

// tuning of the geometry, in one place
constexpr double kMaxBoundaryGap = 10.0;      // m, longest allowed segment between boundary cones
constexpr double kLongGapFactor = 2.5;        // a segment this many times the median spacing gets a note
constexpr double kCentrelineSpacing = 0.5;    // m
constexpr double kDenseSpacing = 0.25;        // m, boundary sampling for the first centreline guess
constexpr double kStartToGate = 6.0;          // m, start pose before the first gate when the file has none
constexpr double kStartMargin = 3.0;          // m of track kept behind the start pose (FSSIM's start is the front wing)
constexpr double kEndMargin = 3.0;            // m of track kept past the last cone of an open layout, to stop in
constexpr double kGatePostMargin = 1.0;       // m beyond the boundaries for gates made from geometry
constexpr double kPostGroupDistance = 3.0;    // m along the track: big orange cones closer than this form one post
constexpr double kLineTolerance = 0.5;        // m, largest deviation of an acceleration line of cones from a straight line
constexpr double kRingTolerance = 0.5;        // m, largest radial residual of a skidpad ring cone

Vec2 unit(Vec2 v) {
  const double n = norm(v);
  return n > 0.0 ? v / n : Vec2{1.0, 0.0};
}

// proper or touching intersection of segments a-b and c-d
bool segments_intersect(Vec2 a, Vec2 b, Vec2 c, Vec2 d) {
  const double d1 = cross(b - a, c - a), d2 = cross(b - a, d - a);
  const double d3 = cross(d - c, a - c), d4 = cross(d - c, b - c);
  if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0))) return true;
  auto on = [](Vec2 p, Vec2 q, Vec2 r, double cr) {
    return cr == 0.0 && std::min(p.x, q.x) <= r.x && r.x <= std::max(p.x, q.x) && std::min(p.y, q.y) <= r.y &&
           r.y <= std::max(p.y, q.y);
  };
  return on(a, b, c, d1) || on(a, b, d, d2) || on(c, d, a, d3) || on(c, d, b, d4);
}

std::size_t segment_count(const std::vector<Vec2>& p, bool closed) {
  if (p.size() < 2) return 0;
  return closed ? p.size() : p.size() - 1;
}

// the first pair of non-adjacent segments of a polyline that intersect, if any
std::optional<std::pair<std::size_t, std::size_t>> self_intersection(const std::vector<Vec2>& p, bool closed) {
  const std::size_t n = p.size(), m = segment_count(p, closed);
  for (std::size_t i = 0; i < m; ++i) {
    for (std::size_t j = i + 2; j < m; ++j) {
      if (closed && i == 0 && j == m - 1) continue;  // adjacent through the closing vertex
      if (segments_intersect(p[i], p[(i + 1) % n], p[j], p[(j + 1) % n])) return std::make_pair(i, j);
    }
  }
  return std::nullopt;
}

bool polylines_intersect(const std::vector<Vec2>& p, bool pc, const std::vector<Vec2>& q, bool qc) {
  for (std::size_t i = 0; i < segment_count(p, pc); ++i) {
    for (std::size_t j = 0; j < segment_count(q, qc); ++j) {
      if (segments_intersect(p[i], p[(i + 1) % p.size()], q[j], q[(j + 1) % q.size()])) return true;
    }
  }
  return false;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

std::vector<double> segment_lengths(const std::vector<Vec2>& p, bool closed) {
  std::vector<double> out;
  for (std::size_t i = 0; i < segment_count(p, closed); ++i) out.push_back(distance(p[i], p[(i + 1) % p.size()]));
  return out;
}

// unit tangent of polyline point i from its neighbours
Vec2 tangent_at(const std::vector<Vec2>& p, bool closed, std::size_t i) {
  const std::size_t n = p.size();
  const Vec2 prev = (i > 0) ? p[i - 1] : (closed ? p[n - 1] : p[i]);
  const Vec2 next = (i + 1 < n) ? p[i + 1] : (closed ? p[0] : p[i]);
  return unit(next - prev);
}

// ---------------------------------------------------------------------------
// cones by colour, doubles merged

struct ConeSets {
  std::vector<Cone> all;  // every cone but the doubles
  std::vector<Vec2> blue, yellow, orange, big_orange;
};

ConeSets sort_cones(const TrackFile& f) {
  std::vector<bool> drop(f.cones.size(), false);
  for (const auto& d : f.doubles) drop[d.cone] = true;
  ConeSets s;
  for (std::size_t i = 0; i < f.cones.size(); ++i) {
    if (drop[i]) continue;
    const Cone& c = f.cones[i];
    s.all.push_back(c);
    switch (c.color) {
      case ConeColor::Blue: s.blue.push_back(c.position); break;
      case ConeColor::Yellow: s.yellow.push_back(c.position); break;
      case ConeColor::SmallOrange: s.orange.push_back(c.position); break;
      case ConeColor::BigOrange: s.big_orange.push_back(c.position); break;
      case ConeColor::Unknown: break;
    }
  }
  return s;
}

// ---------------------------------------------------------------------------
// boundary ordering: greedy nearest-neighbour chaining that prefers going
// straight on, leftovers inserted where they lengthen the loop least, and
// crossings removed by 2-opt moves (reversing the stretch between two
// crossing segments always removes that crossing and shortens the loop)

// big orange cones can stand in a boundary at the timekeeping line: a gap
// longer than kMaxBoundaryGap is allowed (up to twice that) where one of them
// stands within kBridgeDistance of it, and fill_gaps() puts them in
constexpr double kBridgeDistance = 1.0;  // m

bool bridged(Vec2 a, Vec2 b, const std::vector<Vec2>& bridges) {
  if (distance(a, b) > 2.0 * kMaxBoundaryGap) return false;
  for (const Vec2& q : bridges) {
    if (point_segment_distance(q, a, b) < kBridgeDistance) return true;
  }
  return false;
}

void fill_gaps(std::vector<Vec2>& loop, const std::vector<Vec2>& bridges) {
  for (std::size_t i = 0; i < loop.size(); ++i) {
    const Vec2 a = loop[i], b = loop[(i + 1) % loop.size()];
    if (distance(a, b) <= kMaxBoundaryGap) continue;
    std::vector<std::pair<double, Vec2>> in;
    for (const Vec2& q : bridges) {
      if (point_segment_distance(q, a, b) < kBridgeDistance) in.push_back({dot(q - a, b - a), q});
    }
    std::sort(in.begin(), in.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
    for (std::size_t k = 0; k < in.size(); ++k) {
      loop.insert(loop.begin() + static_cast<std::ptrdiff_t>(i + 1 + k), in[k].second);
    }
    i += in.size();
  }
}

std::vector<std::size_t> greedy_chain(const std::vector<Vec2>& p, std::size_t first, Vec2 dir, double turn_weight,
                                      const std::vector<Vec2>& bridges) {
  const std::size_t n = p.size();
  std::vector<bool> used(n, false);
  std::vector<std::size_t> order{first};
  used[first] = true;
  Vec2 d = unit(dir);
  std::size_t cur = first;
  for (;;) {
    std::size_t best = n;
    double best_cost = std::numeric_limits<double>::infinity();
    for (std::size_t q = 0; q < n; ++q) {
      if (used[q]) continue;
      const Vec2 v = p[q] - p[cur];
      const double len = norm(v);
      if (len > kMaxBoundaryGap && !bridged(p[cur], p[q], bridges)) continue;
      const double c = len > 0.0 ? dot(v, d) / len : 1.0;
      // never turn back by more than ~115 degrees from one cone to the next
      if (c < -0.42) continue;
      const double cost = len * (1.0 + turn_weight * (1.0 - c));
      if (cost < best_cost) {
        best_cost = cost;
        best = q;
      }
    }
    if (best == n) break;
    const Vec2 v = p[best] - p[cur];
    if (norm(v) > 0.0) d = unit(v);
    used[best] = true;
    order.push_back(best);
    cur = best;
  }
  // leftovers: cheapest insertion into the closed loop
  for (std::size_t q = 0; q < n; ++q) {
    if (used[q]) continue;
    std::size_t best_i = 0;
    double best_add = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < order.size(); ++i) {
      const Vec2 a = p[order[i]], b = p[order[(i + 1) % order.size()]];
      const double add = distance(a, p[q]) + distance(p[q], b) - distance(a, b);
      if (add < best_add) {
        best_add = add;
        best_i = i;
      }
    }
    order.insert(order.begin() + static_cast<std::ptrdiff_t>(best_i + 1), q);
    used[q] = true;
  }
  return order;
}

void untangle(std::vector<Vec2>& loop) {
  for (int pass = 0; pass < 100; ++pass) {
    const auto x = self_intersection(loop, true);
    if (!x) return;
    std::reverse(loop.begin() + static_cast<std::ptrdiff_t>(x->first + 1),
                 loop.begin() + static_cast<std::ptrdiff_t>(x->second + 1));
  }
}

// why a loop is not a plausible boundary, or empty
std::string loop_problem(const std::vector<Vec2>& loop) {
  if (loop.size() < 3) return "fewer than 3 cones";
  const auto lens = segment_lengths(loop, true);
  for (std::size_t i = 0; i < lens.size(); ++i) {
    if (lens[i] > kMaxBoundaryGap) {
      const Vec2 a = loop[i];
      return "a gap of " + fixed(lens[i], 1) + " m after the cone at (" + fixed(a.x, 2) + ", " + fixed(a.y, 2) +
             "), expected at most " + fixed(kMaxBoundaryGap, 0) + " m";
    }
  }
  if (auto x = self_intersection(loop, true)) {
    const Vec2 a = loop[x->first];
    return "the loop crosses itself near (" + fixed(a.x, 2) + ", " + fixed(a.y, 2) + ")";
  }
  return {};
}

struct LoopPair {
  std::vector<Vec2> left, right;
};

// close the blue and the yellow cones into two nested loops
LoopPair order_circuit(const ConeSets& cs, const std::optional<Pose2>& start, const std::string& source) {
  if (cs.blue.size() < 3 || cs.yellow.size() < 3) {
    throw TrackError(source + ": a circuit needs at least 3 blue and 3 yellow cones, found " +
                     std::to_string(cs.blue.size()) + " blue and " + std::to_string(cs.yellow.size()) + " yellow");
  }
  auto first_of = [&](const std::vector<Vec2>& p, Vec2& dir) {
    std::size_t first = 0;
    if (start) {
      dir = start->heading();
      double best = std::numeric_limits<double>::infinity();
      for (std::size_t i = 0; i < p.size(); ++i) {
        const double d = distance(p[i], start->position());
        if (d < best) {
          best = d;
          first = i;
        }
      }
    } else {
      // no start: begin anywhere, towards the nearest neighbour
      double best = std::numeric_limits<double>::infinity();
      for (std::size_t i = 1; i < p.size(); ++i) {
        const double d = distance(p[i], p[0]);
        if (d < best) {
          best = d;
          dir = p[i] - p[0];
        }
      }
    }
    return first;
  };
  std::string why;
  for (double turn_weight : {2.0, 1.0, 4.0, 0.5, 8.0}) {
    std::array<std::vector<Vec2>, 2> loops;
    std::array<std::string, 2> problems;
    for (int side = 0; side < 2; ++side) {
      const auto& p = side == 0 ? cs.blue : cs.yellow;
      Vec2 dir{1.0, 0.0};
      const std::size_t first = first_of(p, dir);
      for (std::size_t i : greedy_chain(p, first, dir, turn_weight, cs.big_orange)) loops[side].push_back(p[i]);
      untangle(loops[side]);
      fill_gaps(loops[side], cs.big_orange);
      problems[side] = loop_problem(loops[side]);
    }
    if (!problems[0].empty() || !problems[1].empty()) {
      if (why.empty()) why = !problems[0].empty() ? "blue: " + problems[0] : "yellow: " + problems[1];
      continue;
    }
    if (polylines_intersect(loops[0], true, loops[1], true)) {
      if (why.empty()) why = "the blue and the yellow loops cross each other";
      continue;
    }
    return {loops[0], loops[1]};
  }
  throw TrackError(source + ": cannot order the boundary cones into two loops (" + why + ")");
}

// ---------------------------------------------------------------------------
// centreline between two boundaries: a first guess from midpoints, then
// points moved along their normals until equidistant from both boundaries
// (the medial line, smooth except where a boundary has a sharp corner),
// lightly smoothed and resampled

struct Centre {
  std::vector<Vec2> line;
  std::vector<double> width;
};

// distance from q to a polyline (brute force over its segments)
double distance_to(const std::vector<Vec2>& p, bool closed, Vec2 q) {
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < segment_count(p, closed); ++i) {
    const Vec2 a = p[i], b = p[(i + 1) % p.size()];
    // skip segments whose bounding box is farther than the best so far
    const double dx = std::max({std::min(a.x, b.x) - q.x, q.x - std::max(a.x, b.x), 0.0});
    const double dy = std::max({std::min(a.y, b.y) - q.y, q.y - std::max(a.y, b.y), 0.0});
    if (dx >= best || dy >= best) continue;
    best = std::min(best, point_segment_distance(q, a, b));
  }
  return best;
}

// distance along the ray o + t d (d a unit vector) to its first hit of a polyline, or infinity
double ray_hit(const std::vector<Vec2>& p, bool closed, Vec2 o, Vec2 d) {
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < segment_count(p, closed); ++i) {
    const Vec2 a = p[i], b = p[(i + 1) % p.size()];
    const Vec2 e = b - a;
    const double den = cross(d, e);
    if (std::abs(den) < 1e-12) continue;
    // o + t d = a + u e  =>  t = cross(a - o, e) / cross(d, e), u = cross(a - o, d) / cross(d, e)
    const double t = cross(a - o, e) / den, u = cross(a - o, d) / den;
    if (t >= 0.0 && u >= 0.0 && u <= 1.0) best = std::min(best, t);
  }
  return best;
}

// Laplacian smoothing, end points of an open line kept
void smooth(std::vector<Vec2>& p, bool closed, double lambda, int iterations) {
  const std::size_t n = p.size();
  if (n < 3) return;
  std::vector<Vec2> q(n);
  for (int it = 0; it < iterations; ++it) {
    for (std::size_t i = 0; i < n; ++i) {
      if (!closed && (i == 0 || i + 1 == n)) {
        q[i] = p[i];
        continue;
      }
      const Vec2 a = p[(i + n - 1) % n], b = p[(i + 1) % n];
      q[i] = p[i] + ((a + b) * 0.5 - p[i]) * lambda;
    }
    p.swap(q);
  }
}

Centre centre_between(const std::vector<Vec2>& left, const std::vector<Vec2>& right, bool closed) {
  // first guess: each dense left sample paired with the nearest right point,
  // searched in a window that moves forward with the samples
  const auto dense = resample(left, closed, kDenseSpacing);
  const std::size_t nr = segment_count(right, closed);
  auto seg_point = [&](std::size_t j, Vec2 q) {
    const Vec2 a = right[j], b = right[(j + 1) % right.size()];
    const Vec2 ab = b - a;
    const double l2 = squared_norm(ab);
    const double t = l2 > 0.0 ? std::clamp(dot(q - a, ab) / l2, 0.0, 1.0) : 0.0;
    return a + ab * t;
  };
  std::size_t j = project(right, closed, dense.front()).segment;
  std::vector<Vec2> guess;
  guess.reserve(dense.size());
  for (const Vec2& q : dense) {
    const std::ptrdiff_t back = 2, ahead = 12;
    double best = std::numeric_limits<double>::infinity();
    std::size_t best_j = j;
    Vec2 best_p;
    for (std::ptrdiff_t k = -back; k <= ahead; ++k) {
      std::ptrdiff_t jj = static_cast<std::ptrdiff_t>(j) + k;
      if (closed) {
        jj = (jj % static_cast<std::ptrdiff_t>(nr) + static_cast<std::ptrdiff_t>(nr)) % static_cast<std::ptrdiff_t>(nr);
      } else if (jj < 0 || jj >= static_cast<std::ptrdiff_t>(nr)) {
        continue;
      }
      const Vec2 p = seg_point(static_cast<std::size_t>(jj), q);
      const double d = distance(p, q);
      if (d < best) {
        best = d;
        best_j = static_cast<std::size_t>(jj);
        best_p = p;
      }
    }
    j = best_j;
    guess.push_back((q + best_p) * 0.5);
  }
  smooth(guess, closed, 0.5, 10);
  std::vector<Vec2> c = resample(guess, closed, kCentrelineSpacing);

  // move each point along its normal to where both boundaries are equally far
  for (int round = 0; round < 6; ++round) {
    for (int it = 0; it < 3; ++it) {
      std::vector<Vec2> moved = c;
      for (std::size_t i = 0; i < c.size(); ++i) {
        if (!closed && (i == 0 || i + 1 == c.size())) continue;
        const Vec2 n = left_normal(tangent_at(c, closed, i));
        const double dl = distance_to(left, closed, c[i]);
        const double dr = distance_to(right, closed, c[i]);
        moved[i] = c[i] + n * (0.5 * (dl - dr));
      }
      c.swap(moved);
    }
    smooth(c, closed, 0.5, 2);
    c = resample(c, closed, kCentrelineSpacing);
  }
  // a last smoothing takes the corners of the medial line off (it moves the
  // line by a few centimetres, only in the tightest corners)
  for (int it = 0; it < 8; ++it) {
    smooth(c, closed, 0.5, 1);
    smooth(c, closed, -0.53, 1);
  }
  c = resample(c, closed, kCentrelineSpacing);
  // width across the track: the chord along the normal from boundary to
  // boundary (at least the sum of the nearest distances, which it falls
  // back to where the normal runs off at a grazing angle)
  Centre out;
  out.line = c;
  for (std::size_t i = 0; i < c.size(); ++i) {
    const Vec2 n = left_normal(tangent_at(c, closed, i));
    const double dl = distance_to(left, closed, c[i]), dr = distance_to(right, closed, c[i]);
    double wl = ray_hit(left, closed, c[i], n), wr = ray_hit(right, closed, c[i], -n);
    if (wl > 2.0 * dl + 0.5) wl = dl;
    if (wr > 2.0 * dr + 0.5) wr = dr;
    out.width.push_back(wl + wr);
  }
  return out;
}

// ---------------------------------------------------------------------------
// gates

// a pair of posts as a gate whose left post is on the left of `heading`
Segment gate_from_posts(Vec2 p, Vec2 q, Vec2 heading) {
  const Vec2 mid = (p + q) * 0.5;
  return cross(heading, p - mid) > 0.0 ? Segment{p, q} : Segment{q, p};
}

// big orange cones grouped into posts per side (by position `along` the
// track) and paired across: gates as (along of the gate, left post, right post)
struct Post {
  double along = 0.0;
  Vec2 position;
};

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

// the along-track coordinate and signed side (> 0 left) of a point
struct Station {
  double along = 0.0;
  double side = 0.0;
};

template <class StationOf>
std::vector<Segment> gates_from_big_orange(const std::vector<Vec2>& big, StationOf station_of) {
  std::vector<std::pair<double, Vec2>> left, right;
  for (const Vec2& p : big) {
    const Station s = station_of(p);
    (s.side > 0.0 ? left : right).push_back({s.along, p});
  }
  const auto lp = group_posts(left), rp = group_posts(right);
  std::vector<std::pair<double, Segment>> gates;
  for (const Post& l : lp) {
    const Post* best = nullptr;
    for (const Post& r : rp) {
      if (std::abs(r.along - l.along) < kPostGroupDistance &&
          (!best || std::abs(r.along - l.along) < std::abs(best->along - l.along))) {
        best = &r;
      }
    }
    if (best) gates.push_back({0.5 * (l.along + best->along), Segment{l.position, best->position}});
  }
  std::sort(gates.begin(), gates.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<Segment> out;
  for (const auto& g : gates) out.push_back(g.second);
  return out;
}

// ---------------------------------------------------------------------------
// circuits

// arc length of every centreline vertex, and where q projects
struct Arc {
  const std::vector<Vec2>* line;
  bool closed;
  double length;
  Station station(Vec2 q) const {
    const Projection pr = project(*line, closed, q);
    return {pr.s, pr.signed_offset};
  }
  Vec2 tangent(double s) const {
    const Projection pr = project(*line, closed, point(s));
    const Vec2 a = (*line)[pr.segment], b = (*line)[(pr.segment + 1) % line->size()];
    return unit(b - a);
  }
  Vec2 point(double s) const {
    if (closed) s = std::fmod(std::fmod(s, length) + length, length);
    const std::vector<Vec2>& p = *line;
    double acc = 0.0;
    for (std::size_t i = 0; i < segment_count(p, closed); ++i) {
      const Vec2 a = p[i], b = p[(i + 1) % p.size()];
      const double l = distance(a, b);
      if (acc + l >= s && l > 0.0) return a + (b - a) * ((s - acc) / l);
      acc += l;
    }
    return closed ? p.front() : p.back();
  }
};

void build_circuit(TrackModel& m, const TrackFile& f, const ConeSets& cs) {
  LoopPair loops = order_circuit(cs, f.start, f.source);
  // driving direction: blue on the left, so the loops run counter-clockwise
  // when blue is the inner loop and clockwise when it is the outer one
  const double area_b = polygon_area(loops.left), area_y = polygon_area(loops.right);
  const bool blue_inside = std::abs(area_b) < std::abs(area_y);
  const std::vector<Vec2>& inner = blue_inside ? loops.left : loops.right;
  const std::vector<Vec2>& outer = blue_inside ? loops.right : loops.left;
  for (const Vec2& p : inner) {
    if (!polygon_contains(outer, p)) {
      throw TrackError(f.source + ": the blue and yellow loops are not nested (the cone at (" + fixed(p.x, 2) + ", " +
                       fixed(p.y, 2) + ") lies outside the other loop), expected one loop inside the other");
    }
  }
  const bool ccw = blue_inside;
  if ((area_b > 0.0) != ccw) std::reverse(loops.left.begin(), loops.left.end());
  if ((area_y > 0.0) != ccw) std::reverse(loops.right.begin(), loops.right.end());
  m.left = loops.left;
  m.right = loops.right;
  m.closed = true;

  for (const auto* side : {&m.left, &m.right}) {
    const auto lens = segment_lengths(*side, true);
    const double typical = median(lens);
    for (std::size_t i = 0; i < lens.size(); ++i) {
      if (lens[i] > kLongGapFactor * typical) {
        const Vec2 a = (*side)[i];
        m.notes.push_back(f.source + ": " + (side == &m.left ? "left" : "right") + " boundary gap of " +
                          fixed(lens[i], 1) + " m after the cone at (" + fixed(a.x, 2) + ", " + fixed(a.y, 2) +
                          "), " + fixed(lens[i] / typical, 1) + "x the median spacing " + fixed(typical, 2) + " m");
      }
    }
  }

  Centre c = centre_between(m.left, m.right, true);
  Arc arc{&c.line, true, polyline_length(c.line, true)};

  // gates: timekeeping posts, else big orange cones, else a line across the track
  std::vector<Segment> gates;
  if (!f.timekeeping.empty()) {
    m.gates_from = "timekeeping";
    for (std::size_t i = 0; i + 1 < f.timekeeping.size(); i += 2) {
      const Vec2 mid = (f.timekeeping[i] + f.timekeeping[i + 1]) * 0.5;
      gates.push_back(gate_from_posts(f.timekeeping[i], f.timekeeping[i + 1], arc.tangent(arc.station(mid).along)));
    }
  } else if (!cs.big_orange.empty()) {
    m.gates_from = "big_orange";
    // stations relative to the centreline point farthest from the big orange
    // cones, so that a gate never straddles the centreline's seam
    Vec2 centroid;
    for (const Vec2& p : cs.big_orange) centroid += p;
    centroid = centroid / static_cast<double>(cs.big_orange.size());
    const double s_ref = arc.station(centroid).along + 0.5 * arc.length;
    gates = gates_from_big_orange(cs.big_orange, [&](Vec2 p) {
      Station s = arc.station(p);
      s.along = std::fmod(s.along - s_ref + 2.0 * arc.length, arc.length);
      return s;
    });
  }
  if (gates.empty()) {
    m.gates_from = "geometry";
    const double s0 = f.start ? arc.station(f.start->position()).along : 0.0;
    const double s = s0 + kStartToGate;
    const Vec2 p = arc.point(s), n = left_normal(arc.tangent(s));
    const double dl = distance_to(m.left, true, p), dr = distance_to(m.right, true, p);
    gates.push_back({p + n * (dl + kGatePostMargin), p - n * (dr + kGatePostMargin)});
  }

  // start: from the file, else on the centreline before the first gate
  const auto gate_station = [&](const Segment& g) { return arc.station((g.a + g.b) * 0.5).along; };
  if (f.start) {
    m.start = *f.start;
    m.start_from = "file";
  } else {
    const double s = gate_station(gates.front()) - kStartToGate;
    const Vec2 t = arc.tangent(s);
    const Vec2 p = arc.point(s);
    m.start = Pose2{p.x, p.y, angle_of(t)};
    m.start_from = "geometry";
  }

  // gates in driving order from the start
  const double s_start = arc.station(m.start.position()).along;
  std::sort(gates.begin(), gates.end(), [&](const Segment& a, const Segment& b) {
    const double sa = std::fmod(gate_station(a) - s_start + 2.0 * arc.length, arc.length);
    const double sb = std::fmod(gate_station(b) - s_start + 2.0 * arc.length, arc.length);
    return sa < sb;
  });
  m.gates = gates;

  // the centreline starts at its point nearest the start pose
  const Projection pr = project(c.line, true, m.start.position());
  const std::size_t k = (pr.t < 0.5) ? pr.segment : (pr.segment + 1) % c.line.size();
  std::rotate(c.line.begin(), c.line.begin() + static_cast<std::ptrdiff_t>(k), c.line.end());
  std::rotate(c.width.begin(), c.width.begin() + static_cast<std::ptrdiff_t>(k), c.width.end());
  m.centreline = c.line;
  m.width = c.width;

  const double heading_error = std::abs(wrap_angle(m.start.yaw - angle_of(tangent_at(m.centreline, true, 0))));
  if (heading_error > kPi / 2.0) {
    m.notes.push_back(f.source + ": the start pose faces against the driving direction given by the cone colours "
                                 "(blue on the left), " +
                      fixed(heading_error * 180.0 / kPi, 0) + " degrees off");
  }

  m.region.add_xor_polygon(m.left);
  m.region.add_xor_polygon(m.right);
}

// ---------------------------------------------------------------------------
// acceleration: two straight parallel lines of blue and yellow cones

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
  for (const Vec2& q : m.centreline) m.width.push_back(distance_to(lside, false, q) + distance_to(rside, false, q));

  std::vector<Vec2> polygon = lside;
  polygon.insert(polygon.end(), rside.rbegin(), rside.rend());
  m.region.add_xor_polygon(polygon);
}

// ---------------------------------------------------------------------------
// skidpad: two rings of cones around each of two centres

// circle through three points, if they are not collinear
std::optional<std::pair<Vec2, double>> circumcircle(Vec2 a, Vec2 b, Vec2 c) {
  const double d = 2.0 * cross(b - a, c - a);
  if (std::abs(d) < 1e-9) return std::nullopt;
  const double b2 = squared_norm(b - a), c2 = squared_norm(c - a);
  const Vec2 rel{((c - a).y * b2 - (b - a).y * c2) / d, ((b - a).x * c2 - (c - a).x * b2) / d};
  return std::make_pair(a + rel, norm(rel));
}

struct Ring {
  std::vector<Vec2> cones;
  std::vector<ConeColor> colors;
};

struct SkidCircle {
  Vec2 centre;
  double r_in = 0.0, r_out = 0.0;
  Ring inner, outer;
};

// least squares of two concentric circles: minimise sum (|p - c| - r_k)^2 over
// (cx, cy, r_in, r_out) by Gauss-Newton; the residual of p on ring k is
// |p - c| - r_k with gradient (-(p - c)/|p - c|, -1 on r_k)
void fit_concentric(SkidCircle& c) {
  for (int it = 0; it < 10; ++it) {
    double a[4][5] = {};
    auto add = [&](Vec2 p, int k, double r) {
      const Vec2 d = p - c.centre;
      const double rho = norm(d);
      if (rho <= 0.0) return;
      const double g[4] = {-d.x / rho, -d.y / rho, k == 0 ? -1.0 : 0.0, k == 1 ? -1.0 : 0.0};
      const double res = rho - r;
      for (int i = 0; i < 4; ++i) {
        for (int j = 0; j < 4; ++j) a[i][j] += g[i] * g[j];
        a[i][4] -= g[i] * res;
      }
    };
    for (const Vec2& p : c.inner.cones) add(p, 0, c.r_in);
    for (const Vec2& p : c.outer.cones) add(p, 1, c.r_out);
    // Gaussian elimination with partial pivoting on the 4x4 normal equations
    for (int col = 0; col < 4; ++col) {
      int piv = col;
      for (int r = col + 1; r < 4; ++r) {
        if (std::abs(a[r][col]) > std::abs(a[piv][col])) piv = r;
      }
      if (std::abs(a[piv][col]) < 1e-12) return;
      for (int k = 0; k < 5; ++k) std::swap(a[col][k], a[piv][k]);
      for (int r = 0; r < 4; ++r) {
        if (r == col) continue;
        const double fct = a[r][col] / a[col][col];
        for (int k = 0; k < 5; ++k) a[r][k] -= fct * a[col][k];
      }
    }
    const double dx[4] = {a[0][4] / a[0][0], a[1][4] / a[1][1], a[2][4] / a[2][2], a[3][4] / a[3][3]};
    c.centre += Vec2{dx[0], dx[1]};
    c.r_in += dx[2];
    c.r_out += dx[3];
    if (std::abs(dx[0]) + std::abs(dx[1]) + std::abs(dx[2]) + std::abs(dx[3]) < 1e-10) return;
  }
}

// two centres with two rings each, or nothing
std::optional<std::array<SkidCircle, 2>> find_skidpad(const ConeSets& cs, std::vector<std::string>& unassigned) {
  // every ring cone votes for the circle through it and its two nearest
  // neighbours of the same colour
  std::vector<Vec2> pts;
  std::vector<ConeColor> cols;
  for (const Vec2& p : cs.blue) {
    pts.push_back(p);
    cols.push_back(ConeColor::Blue);
  }
  for (const Vec2& p : cs.yellow) {
    pts.push_back(p);
    cols.push_back(ConeColor::Yellow);
  }
  if (pts.size() < 16) return std::nullopt;
  struct Vote {
    Vec2 centre;
    double radius;
  };
  std::vector<Vote> votes;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    std::size_t n1 = i, n2 = i;
    double d1 = std::numeric_limits<double>::infinity(), d2 = d1;
    for (std::size_t k = 0; k < pts.size(); ++k) {
      if (k == i || cols[k] != cols[i]) continue;
      const double d = distance(pts[i], pts[k]);
      if (d < d1) {
        d2 = d1;
        n2 = n1;
        d1 = d;
        n1 = k;
      } else if (d < d2) {
        d2 = d;
        n2 = k;
      }
    }
    if (n1 == i || n2 == i) continue;
    if (auto c = circumcircle(pts[i], pts[n1], pts[n2]); c && c->second > 4.0 && c->second < 15.0) {
      votes.push_back({c->first, c->second});
    }
  }
  // the two densest clusters of voted centres
  auto densest = [&](const std::vector<Vote>& v, std::size_t& count) {
    Vec2 best;
    count = 0;
    for (const Vote& a : v) {
      std::size_t n = 0;
      Vec2 sum;
      for (const Vote& b : v) {
        if (distance(a.centre, b.centre) < 1.0) {
          ++n;
          sum += b.centre;
        }
      }
      if (n > count) {
        count = n;
        best = sum / static_cast<double>(n);
      }
    }
    return best;
  };
  std::size_t n1 = 0, n2 = 0;
  const Vec2 c1 = densest(votes, n1);
  std::vector<Vote> rest;
  for (const Vote& v : votes) {
    if (distance(v.centre, c1) > 5.0) rest.push_back(v);
  }
  const Vec2 c2 = densest(rest, n2);
  if (n1 + n2 < pts.size() * 6 / 10 || n2 < pts.size() / 5) return std::nullopt;
  const double sep = distance(c1, c2);
  if (sep < 10.0 || sep > 30.0) return std::nullopt;

  // rings: radii of the cones around each centre split in two groups
  std::array<SkidCircle, 2> circles;
  circles[0].centre = c1;
  circles[1].centre = c2;
  for (auto& c : circles) {
    std::vector<double> r;
    for (const Vec2& p : pts) {
      const double rho = distance(p, c.centre);
      if (rho > 3.0 && rho < 15.0 && distance(p, c.centre) <= distance(p, (&c == &circles[0]) ? c2 : c1)) {
        r.push_back(rho);
      }
    }
    if (r.size() < 10) return std::nullopt;
    std::sort(r.begin(), r.end());
    // the widest gap between consecutive radii separates inner from outer
    std::size_t split = 0;
    for (std::size_t i = 1; i + 1 < r.size(); ++i) {
      if (r[i + 1] - r[i] > r[split + 1] - r[split]) split = i;
    }
    c.r_in = std::accumulate(r.begin(), r.begin() + static_cast<std::ptrdiff_t>(split + 1), 0.0) /
             static_cast<double>(split + 1);
    c.r_out = std::accumulate(r.begin() + static_cast<std::ptrdiff_t>(split + 1), r.end(), 0.0) /
              static_cast<double>(r.size() - split - 1);
    if (c.r_out - c.r_in < 1.5) return std::nullopt;
  }
  // assign each ring cone to the ring it fits best, fit, repeat once
  for (int pass = 0; pass < 2; ++pass) {
    for (auto& c : circles) c.inner = c.outer = Ring{};
    unassigned.clear();
    for (std::size_t i = 0; i < pts.size(); ++i) {
      double best = std::numeric_limits<double>::infinity();
      Ring* ring = nullptr;
      for (auto& c : circles) {
        const double rho = distance(pts[i], c.centre);
        for (auto [r, rg] : {std::make_pair(c.r_in, &c.inner), std::make_pair(c.r_out, &c.outer)}) {
          if (std::abs(rho - r) < best) {
            best = std::abs(rho - r);
            ring = rg;
          }
        }
      }
      if (ring && best < kRingTolerance) {
        ring->cones.push_back(pts[i]);
        ring->colors.push_back(cols[i]);
      } else {
        unassigned.push_back("(" + fixed(pts[i].x, 2) + ", " + fixed(pts[i].y, 2) + ")");
      }
    }
    for (auto& c : circles) {
      if (c.inner.cones.size() < 5 || c.outer.cones.size() < 5) return std::nullopt;
      fit_concentric(c);
    }
  }
  return circles;
}

void build_skidpad(TrackModel& m, const TrackFile& f, const ConeSets& cs, std::array<SkidCircle, 2> circles,
                   const std::vector<std::string>& unassigned) {
  SkidpadGeometry g;
  g.crossing = (circles[0].centre + circles[1].centre) * 0.5;
  const Vec2 across = unit(circles[1].centre - circles[0].centre);
  // heading at the crossing: perpendicular to the centres' line, along the start yaw,
  // else chosen so that the circle with the blue outer ring is on the right
  Vec2 h = left_normal(across);  // circles[1] is then on the right of h
  auto blue_outer = [](const SkidCircle& c) {
    long n = 0;
    for (ConeColor col : c.outer.colors) n += col == ConeColor::Blue ? 1 : -1;
    return n;
  };
  if (f.start) {
    Vec2 want = f.start->heading();
    if (std::abs(dot(want, h)) < 0.3) want = g.crossing - f.start->position();
    if (dot(want, h) < 0.0) h = -h;
  } else if (blue_outer(circles[0]) > blue_outer(circles[1])) {
    h = -h;
  }
  const int ri = cross(h, circles[0].centre - g.crossing) < 0.0 ? 0 : 1;  // index of the right circle
  const SkidCircle& cr = circles[static_cast<std::size_t>(ri)];
  const SkidCircle& cl = circles[static_cast<std::size_t>(1 - ri)];
  g.centre_right = cr.centre;
  g.centre_left = cl.centre;
  g.inner_radius = 0.5 * (cr.r_in + cl.r_in);
  g.outer_radius = 0.5 * (cr.r_out + cl.r_out);
  g.radius = 0.5 * (g.inner_radius + g.outer_radius);
  g.heading = angle_of(h);

  // lanes: small orange cones before (entry) and after (exit) the crossing
  auto along = [&](Vec2 p) { return dot(p - g.crossing, h); };
  auto side = [&](Vec2 p) { return cross(h, p - g.crossing); };
  double a_entry = 0.0, a_exit = 0.0;
  std::vector<double> lane_sides;
  for (const Vec2& p : cs.orange) {
    const double a = along(p);
    a_entry = std::min(a_entry, a);
    a_exit = std::max(a_exit, a);
    if (std::abs(side(p)) > 0.5) lane_sides.push_back(std::abs(side(p)));
  }
  if (a_entry == 0.0) a_entry = -(g.outer_radius + 5.0);
  if (a_exit == 0.0) a_exit = g.outer_radius + 5.0;
  g.lane_half_width = lane_sides.empty() ? 1.5 : median(lane_sides);

  // start: from the file, else at the beginning of the entry lane
  if (f.start) {
    m.start = *f.start;
    m.start_from = "file";
  } else {
    const Vec2 p = g.crossing + h * a_entry;
    m.start = Pose2{p.x, p.y, g.heading};
    m.start_from = "geometry";
  }
  a_entry = std::min(a_entry, along(m.start.position()));
  g.entry_start = g.crossing + h * a_entry;
  g.exit_end = g.crossing + h * a_exit;

  // colours: blue should be on the driver's left, i.e. the right circle's outer ring
  long blue_left = 0;
  for (ConeColor col : cr.outer.colors) blue_left += col == ConeColor::Blue ? 1 : -1;
  for (ConeColor col : cl.inner.colors) blue_left += col == ConeColor::Blue ? 1 : -1;
  if (blue_left < 0) {
    m.notes.push_back(f.source + ": the blue cones are on the driver's right (colours swapped relative to the rules: " +
                      "blue should be the right circle's outer ring and the left circle's inner ring)");
  }
  if (!unassigned.empty()) {
    std::string list;
    for (const auto& s : unassigned) list += (list.empty() ? "" : ", ") + s;
    m.notes.push_back(f.source + ": " + std::to_string(unassigned.size()) +
                      " blue/yellow cones fit neither ring and are ignored: " + list);
  }

  // boundaries in driving order: right circle clockwise, then left circle counter-clockwise
  auto ring_order = [&](const Ring& r, Vec2 c, bool clockwise) {
    // angles from a little before the crossing, so that a cone right at it comes first
    const double a0 = angle_of(g.crossing - c) + (clockwise ? 0.01 : -0.01);
    std::vector<std::pair<double, Vec2>> v;
    for (const Vec2& p : r.cones) {
      double t = angle_of(p - c) - a0;
      if (clockwise) t = -t;
      t = std::fmod(std::fmod(t, 2.0 * kPi) + 2.0 * kPi, 2.0 * kPi);
      v.push_back({t, p});
    }
    std::sort(v.begin(), v.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
    std::vector<Vec2> out;
    for (const auto& e : v) out.push_back(e.second);
    return out;
  };
  m.left = ring_order(cr.outer, cr.centre, true);
  for (const Vec2& p : ring_order(cl.inner, cl.centre, false)) m.left.push_back(p);
  m.right = ring_order(cr.inner, cr.centre, true);
  for (const Vec2& p : ring_order(cl.outer, cl.centre, false)) m.right.push_back(p);
  m.closed = false;

  // centreline: entry lane, right circle, left circle, exit lane
  auto add_line = [&](Vec2 a, Vec2 b, double w) {
    const auto n = static_cast<std::size_t>(std::max(1.0, std::round(distance(a, b) / kCentrelineSpacing)));
    for (std::size_t i = m.centreline.empty() ? 0 : 1; i <= n; ++i) {
      m.centreline.push_back(a + (b - a) * (static_cast<double>(i) / static_cast<double>(n)));
      m.width.push_back(w);
    }
  };
  auto add_circle = [&](const SkidCircle& c, bool clockwise) {
    const double a0 = angle_of(g.crossing - c.centre);
    const double r = 0.5 * (c.r_in + c.r_out);
    const auto n = static_cast<std::size_t>(std::round(2.0 * kPi * r / kCentrelineSpacing));
    for (std::size_t i = 1; i <= n; ++i) {
      const double a = a0 + (clockwise ? -1.0 : 1.0) * 2.0 * kPi * static_cast<double>(i) / static_cast<double>(n);
      m.centreline.push_back(c.centre + unit_from_angle(a) * r);
      m.width.push_back(c.r_out - c.r_in);
    }
  };
  add_line(g.entry_start, g.crossing, 2.0 * g.lane_half_width);
  add_circle(cr, true);
  add_circle(cl, false);
  add_line(g.crossing, g.exit_end, 2.0 * g.lane_half_width);

  // gates: timekeeping posts, else big orange cones, else a line at the crossing
  std::vector<std::pair<double, Segment>> gates;
  if (!f.timekeeping.empty()) {
    m.gates_from = "timekeeping";
    for (std::size_t i = 0; i + 1 < f.timekeeping.size(); i += 2) {
      const Segment gt = gate_from_posts(f.timekeeping[i], f.timekeeping[i + 1], h);
      gates.push_back({std::abs(along((gt.a + gt.b) * 0.5)), gt});
    }
  } else if (!cs.big_orange.empty()) {
    m.gates_from = "big_orange";
    for (const Segment& gt : gates_from_big_orange(cs.big_orange, [&](Vec2 p) { return Station{along(p), side(p)}; })) {
      gates.push_back({std::abs(along((gt.a + gt.b) * 0.5)), gt});
    }
  }
  if (gates.empty()) {
    m.gates_from = "geometry";
    const Vec2 n = left_normal(h) * (g.lane_half_width + kGatePostMargin);
    gates.push_back({0.0, Segment{g.crossing + n, g.crossing - n}});
  }
  std::stable_sort(gates.begin(), gates.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  for (const auto& gt : gates) m.gates.push_back(gt.second);

  // region: both annuli and the lane through the crossing
  for (const SkidCircle* c : {&cr, &cl}) m.region.add_annulus(c->centre, c->r_in, c->r_out);
  // (with room behind the start for the car's body)
  const Vec2 n = left_normal(h) * g.lane_half_width;
  const Vec2 back = g.entry_start - h * kStartMargin, front = g.exit_end + h * kEndMargin;
  m.region.add_xor_polygon({back - n, front - n, front + n, back + n});
  m.skidpad = g;
}

std::string file_stem(const std::string& source) {
  const auto slash = source.find_last_of("/\\");
  std::string base = slash == std::string::npos ? source : source.substr(slash + 1);
  const auto dot_pos = base.find_last_of('.');
  if (dot_pos != std::string::npos && dot_pos > 0) base.erase(dot_pos);
  return base;
}

}  // namespace

std::string_view track_kind_name(TrackKind kind) {
  switch (kind) {
    case TrackKind::Circuit: return "circuit";
    case TrackKind::Acceleration: return "acceleration";
    case TrackKind::Skidpad: return "skidpad";
  }
  return "circuit";
}

// ---------------------------------------------------------------------------
// region

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

// ---------------------------------------------------------------------------

TrackModel build_track(const TrackFile& f) {
  TrackModel m;
  m.name = file_stem(f.source);
  const ConeSets cs = sort_cones(f);
  m.cones = cs.all;
  if (cs.blue.empty() && cs.yellow.empty()) {
    throw TrackError(f.source + ": no blue or yellow cones, expected the boundaries of a circuit, an acceleration or "
                                "a skidpad layout");
  }
  std::vector<std::string> unassigned;
  if (auto circles = find_skidpad(cs, unassigned)) {
    m.kind = TrackKind::Skidpad;
    build_skidpad(m, f, cs, *circles, unassigned);
  } else if (looks_like_acceleration(cs)) {
    m.kind = TrackKind::Acceleration;
    build_acceleration(m, f, cs);
  } else {
    m.kind = TrackKind::Circuit;
    build_circuit(m, f, cs);
  }
  m.centreline_length = polyline_length(m.centreline, m.closed);
  if (!m.width.empty()) {
    m.width_min = *std::min_element(m.width.begin(), m.width.end());
    m.width_max = *std::max_element(m.width.begin(), m.width.end());
    m.width_mean = std::accumulate(m.width.begin(), m.width.end(), 0.0) / static_cast<double>(m.width.size());
  }
  // the rules' limits for a trackdrive circuit (ORACLES.md: width >= 3 m, lap 200..500 m)
  if (m.kind == TrackKind::Circuit) {
    if (m.width_min < 2.95) {
      const auto i = static_cast<std::size_t>(std::min_element(m.width.begin(), m.width.end()) - m.width.begin());
      m.notes.push_back(f.source + ": narrowest width " + fixed(m.width_min, 2) + " m at (" +
                        fixed(m.centreline[i].x, 2) + ", " + fixed(m.centreline[i].y, 2) +
                        "), below the rules' 3 m minimum");
    }
    if (m.centreline_length < 200.0 || m.centreline_length > 500.0) {
      m.notes.push_back(f.source + ": lap of " + fixed(m.centreline_length, 1) +
                        " m, outside the rules' 200 to 500 m");
    }
  }
  return m;
}

}  // namespace paddock::world
