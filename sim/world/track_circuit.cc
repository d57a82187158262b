// circuits: the blue and the yellow cones chained into two nested loops,
// oriented so that blue is on the left, the centreline equidistant from
// both, and the gates and start pose on it.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "autonomy/common/format.h"
#include "autonomy/common/polyline.h"
#include "sim/world/track_build.h"

namespace paddock::world::detail {

namespace {

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

// source names the file in the error of a centreline that does not settle
Centre centre_between(const std::vector<Vec2>& left, const std::vector<Vec2>& right, bool closed, const std::string& source) {
  // a centreline runs between its boundaries: longer than both together, it
  // is swinging from side to side (a layout with no track between its two
  // boundaries), and would only grow with every round
  const double longest = polyline_length(left, closed) + polyline_length(right, closed);
  auto settled = [&](const std::vector<Vec2>& line, int round) {
    const double length = polyline_length(line, closed);
    if (length > longest + 100.0)
      throw TrackError(source + ": the centreline does not settle between the boundaries (" + fixed(length, 0) +
                       " m after round " + std::to_string(round) + ", the boundaries " + fixed(longest, 0) +
                       " m together): the cones do not make a track");
  };
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
  const PolylineIndex left_index(left, closed), right_index(right, closed);
  for (int round = 0; round < 6; ++round) {
    for (int it = 0; it < 3; ++it) {
      std::vector<Vec2> moved = c;
      for (std::size_t i = 0; i < c.size(); ++i) {
        if (!closed && (i == 0 || i + 1 == c.size())) continue;
        const Vec2 n = left_normal(tangent_at(c, closed, i));
        const double dl = left_index.distance(c[i]);
        const double dr = right_index.distance(c[i]);
        moved[i] = c[i] + n * (0.5 * (dl - dr));
      }
      c.swap(moved);
    }
    smooth(c, closed, 0.5, 2);
    settled(c, round + 1);
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
    const double dl = left_index.distance(c[i]), dr = right_index.distance(c[i]);
    double wl = ray_hit(left, closed, c[i], n), wr = ray_hit(right, closed, c[i], -n);
    if (wl > 2.0 * dl + 0.5) wl = dl;
    if (wr > 2.0 * dr + 0.5) wr = dr;
    out.width.push_back(wl + wr);
  }
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

}  // namespace

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

  Centre c = centre_between(m.left, m.right, true, f.source);
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
    const double dl = polyline_distance(m.left, true, p), dr = polyline_distance(m.right, true, p);
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

}  // namespace paddock::world::detail
