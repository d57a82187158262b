// skidpad: two rings of cones around each of two centres, found by the
// cones' votes for circle centres and fitted by least squares; the
// centreline is the entry lane, the right circle, the left circle and the
// exit lane.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "autonomy/common/format.h"
#include "sim/world/track_build.h"

namespace paddock::world::detail {

namespace {

// circle through three points, if they are not collinear
std::optional<std::pair<Vec2, double>> circumcircle(Vec2 a, Vec2 b, Vec2 c) {
  const double d = 2.0 * cross(b - a, c - a);
  if (std::abs(d) < 1e-9) return std::nullopt;
  const double b2 = squared_norm(b - a), c2 = squared_norm(c - a);
  const Vec2 rel{((c - a).y * b2 - (b - a).y * c2) / d, ((b - a).x * c2 - (c - a).x * b2) / d};
  return std::make_pair(a + rel, norm(rel));
}

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

}  // namespace

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

}  // namespace paddock::world::detail
