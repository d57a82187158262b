#include "autonomy/common/polyline.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <limits>

namespace paddock {

std::vector<double> cumulative_length(const std::vector<Vec2>& pts, bool closed) {
  std::vector<double> s;
  if (pts.empty()) return s;
  s.reserve(pts.size() + 1);
  s.push_back(0.0);
  for (std::size_t i = 1; i < pts.size(); ++i) s.push_back(s.back() + distance(pts[i - 1], pts[i]));
  if (closed) s.push_back(s.back() + distance(pts.back(), pts.front()));
  return s;
}

double polyline_length(const std::vector<Vec2>& pts, bool closed) {
  const auto s = cumulative_length(pts, closed);
  return s.empty() ? 0.0 : s.back();
}

std::vector<Vec2> resample(const std::vector<Vec2>& pts, bool closed, double spacing) {
  assert(spacing > 0.0);
  if (pts.size() < 2) return pts;
  std::vector<Vec2> v = pts;
  if (closed) v.push_back(pts.front());
  const auto s = cumulative_length(v, false);
  const double total = s.back();
  if (total <= 0.0) return {pts.front()};
  // n intervals of equal length, the count chosen nearest to the asked spacing
  const auto n = static_cast<std::size_t>(std::max(1.0, std::round(total / spacing)));
  std::vector<Vec2> out;
  out.reserve(n + 1);
  std::size_t seg = 0;
  const std::size_t count = closed ? n : n + 1;
  for (std::size_t k = 0; k < count; ++k) {
    const double sk = total * static_cast<double>(k) / static_cast<double>(n);
    while (seg + 2 < s.size() && s[seg + 1] < sk) ++seg;
    const double len = s[seg + 1] - s[seg];
    const double t = len > 0.0 ? std::clamp((sk - s[seg]) / len, 0.0, 1.0) : 0.0;
    out.push_back(v[seg] + (v[seg + 1] - v[seg]) * t);
  }
  return out;
}

Projection project(const std::vector<Vec2>& pts, bool closed, Vec2 q) {
  assert(pts.size() >= 2);
  Projection best;
  best.distance = INFINITY;
  const std::size_t nseg = closed ? pts.size() : pts.size() - 1;
  double s0 = 0.0;
  for (std::size_t i = 0; i < nseg; ++i) {
    const Vec2 a = pts[i];
    const Vec2 b = pts[(i + 1) % pts.size()];
    const Vec2 ab = b - a;
    const double len2 = squared_norm(ab);
    const double t = len2 > 0.0 ? std::clamp(dot(q - a, ab) / len2, 0.0, 1.0) : 0.0;
    const Vec2 p = a + ab * t;
    const double d = distance(q, p);
    const double len = std::sqrt(len2);
    if (d < best.distance) {
      best.point = p;
      best.segment = i;
      best.t = t;
      best.s = s0 + t * len;
      best.distance = d;
      best.signed_offset = cross(ab, q - a) >= 0.0 ? d : -d;
    }
    s0 += len;
  }
  return best;
}

bool polygon_contains(const std::vector<Vec2>& polygon, Vec2 q) {
  bool inside = false;
  const std::size_t n = polygon.size();
  for (std::size_t i = 0, j = n - 1; i < n; j = i++) {
    const Vec2 a = polygon[i], b = polygon[j];
    if ((a.y > q.y) != (b.y > q.y)) {
      const double x = a.x + (q.y - a.y) * (b.x - a.x) / (b.y - a.y);
      if (q.x < x) inside = !inside;
    }
  }
  return inside;
}

double polygon_area(const std::vector<Vec2>& polygon) {
  double a = 0.0;
  const std::size_t n = polygon.size();
  for (std::size_t i = 0; i < n; ++i) a += cross(polygon[i], polygon[(i + 1) % n]);
  return 0.5 * a;
}

std::optional<double> crossing_right_to_left(Vec2 p0, Vec2 p1, const Segment& g) {
  const Vec2 d = g.b - g.a;
  // side of each motion end: < 0 right of the gate's direction, > 0 left
  const double side0 = cross(d, p0 - g.a);
  const double side1 = cross(d, p1 - g.a);
  if (!(side0 < 0.0 && side1 >= 0.0)) return std::nullopt;
  const double f = side0 / (side0 - side1);
  const Vec2 hit = p0 + (p1 - p0) * f;
  const double len2 = squared_norm(d);
  const double u = dot(hit - g.a, d) / len2;
  if (u < 0.0 || u > 1.0) return std::nullopt;
  return f;
}

double polyline_distance(const std::vector<Vec2>& pts, bool closed, Vec2 q) {
  const std::size_t n = pts.size();
  if (n < 2) return std::numeric_limits<double>::infinity();
  // the nearest segment by squared distance (no hypot per segment), then its
  // distance as point_segment_distance gives it
  double best2 = std::numeric_limits<double>::infinity();
  std::size_t nearest = 0;
  for (std::size_t i = 0; i < (closed ? n : n - 1); ++i) {
    const Vec2 a = pts[i], b = pts[(i + 1) % n];
    // skip segments whose bounding box is clearly farther than the best so
    // far (the margin: never one the rounding of d2 could still make nearer)
    const double dx = std::max({std::min(a.x, b.x) - q.x, q.x - std::max(a.x, b.x), 0.0});
    const double dy = std::max({std::min(a.y, b.y) - q.y, q.y - std::max(a.y, b.y), 0.0});
    if (dx * dx + dy * dy > best2 * (1.0 + 1e-9)) continue;
    const double d2 = project_on_segment(q, a, b).distance2;
    if (d2 < best2) {
      best2 = d2;
      nearest = i;
    }
  }
  if (best2 == std::numeric_limits<double>::infinity()) return best2;  // none compared (e.g. q not finite)
  return point_segment_distance(q, pts[nearest], pts[(nearest + 1) % n]);
}

namespace {
constexpr std::size_t kMaxCellsPerSegment = 16;  // more: a long segment
}

PolylineIndex::PolylineIndex(std::vector<Vec2> pts, bool closed) : pts_(std::move(pts)), closed_(closed) {
  const std::size_t n = pts_.size();
  if (n < 2) return;
  segments_ = closed_ ? n : n - 1;
  Vec2 lo = pts_[0], hi = pts_[0];
  double length = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(pts_[i].x) || !std::isfinite(pts_[i].y)) return;  // no grid: brute force
    lo = {std::min(lo.x, pts_[i].x), std::min(lo.y, pts_[i].y)};
    hi = {std::max(hi.x, pts_[i].x), std::max(hi.y, pts_[i].y)};
  }
  for (std::size_t i = 0; i < segments_; ++i) length += paddock::distance(pts_[i], pts_[(i + 1) % n]);
  if (segments_ < 8 || !(length > 0.0) || !std::isfinite(length)) return;
  // cells of about a segment's mean length, at most ~4 per segment
  const double w = hi.x - lo.x, h = hi.y - lo.y;
  double cell = std::max(length / static_cast<double>(segments_), std::sqrt(w * h / (4.0 * static_cast<double>(segments_))));
  cell = std::max(cell, std::max(w, h) / 4096.0);
  if (!(cell > 0.0) || !std::isfinite(cell)) return;
  cell_ = cell;
  origin_ = lo;
  nx_ = static_cast<long>(w / cell) + 1;
  ny_ = static_cast<long>(h / cell) + 1;
  auto cell_of = [&](double v, double o, long count) {
    return std::clamp(static_cast<long>(std::floor((v - o) / cell_)), 0L, count - 1);
  };
  // two passes (count, then fill) into one array of cells' segment lists
  std::vector<std::array<long, 4>> box(segments_);
  first_.assign(static_cast<std::size_t>(nx_ * ny_) + 1, 0);
  for (std::size_t i = 0; i < segments_; ++i) {
    const Vec2 a = pts_[i], b = pts_[(i + 1) % n];
    box[i] = {cell_of(std::min(a.x, b.x), lo.x, nx_), cell_of(std::max(a.x, b.x), lo.x, nx_),
              cell_of(std::min(a.y, b.y), lo.y, ny_), cell_of(std::max(a.y, b.y), lo.y, ny_)};
    const auto cells = static_cast<std::size_t>((box[i][1] - box[i][0] + 1) * (box[i][3] - box[i][2] + 1));
    if (cells > kMaxCellsPerSegment) {
      long_.push_back(i);
      box[i][0] = -1;
      continue;
    }
    for (long y = box[i][2]; y <= box[i][3]; ++y)
      for (long x = box[i][0]; x <= box[i][1]; ++x) ++first_[static_cast<std::size_t>(y * nx_ + x) + 1];
  }
  for (std::size_t c = 1; c < first_.size(); ++c) first_[c] += first_[c - 1];
  in_cell_.resize(first_.back());
  std::vector<std::size_t> fill(first_.begin(), first_.end() - 1);
  for (std::size_t i = 0; i < segments_; ++i) {
    if (box[i][0] < 0) continue;
    for (long y = box[i][2]; y <= box[i][3]; ++y)
      for (long x = box[i][0]; x <= box[i][1]; ++x) in_cell_[fill[static_cast<std::size_t>(y * nx_ + x)]++] = i;
  }
}

double PolylineIndex::distance(Vec2 q) const {
  if (segments_ == 0) return std::numeric_limits<double>::infinity();
  const std::size_t n = pts_.size();
  const double fx = std::floor((q.x - origin_.x) / cell_), fy = std::floor((q.y - origin_.y) / cell_);
  // no grid, or a query too far from it for cell numbers: every segment
  if (cell_ == 0.0 || !(std::abs(fx) < 1e9) || !(std::abs(fy) < 1e9)) return polyline_distance(pts_, closed_, q);
  double best2 = std::numeric_limits<double>::infinity();
  std::size_t nearest = 0;
  auto consider = [&](std::size_t i) {
    const double d2 = project_on_segment(q, pts_[i], pts_[(i + 1) % n]).distance2;
    if (d2 < best2 || (d2 == best2 && i < nearest)) {
      best2 = d2;
      nearest = i;
    }
  };
  for (std::size_t i : long_) consider(i);
  const auto cx = static_cast<long>(fx), cy = static_cast<long>(fy);
  // rings of cells at Chebyshev distance r from q's: from the first that
  // meets the grid to the last, while a cell of the ring can be nearer than
  // the best (its points are at least (r - 1) cells away)
  const long r_first = std::max({0L, -cx, cx - (nx_ - 1), -cy, cy - (ny_ - 1)});
  const long r_last = std::max({std::abs(cx), std::abs(cx - (nx_ - 1)), std::abs(cy), std::abs(cy - (ny_ - 1))});
  // a query far from the polyline for its cells' size (a track whose width
  // is a hundred cone spacings) would visit more cells than there are
  // segments: past that, every segment is checked instead
  std::size_t visited = 0;
  auto visit = [&](long x, long y) {
    if (x < 0 || x >= nx_ || y < 0 || y >= ny_) return;
    ++visited;
    const auto c = static_cast<std::size_t>(y * nx_ + x);
    for (std::size_t k = first_[c]; k < first_[c + 1]; ++k) consider(in_cell_[k]);
  };
  for (long r = r_first; r <= r_last; ++r) {
    if (visited > segments_) {
      for (std::size_t i = 0; i < segments_; ++i) consider(i);
      break;
    }
    if (best2 != std::numeric_limits<double>::infinity()) {
      const double gap = static_cast<double>(r - 1) * cell_;
      if (gap > 0.0 && gap * gap > best2 * (1.0 + 1e-9)) break;
    }
    if (r == 0) {
      visit(cx, cy);
      continue;
    }
    const long x0 = std::max(cx - r, 0L), x1 = std::min(cx + r, nx_ - 1);
    for (long x = x0; x <= x1; ++x) {
      visit(x, cy - r);
      visit(x, cy + r);
    }
    const long y0 = std::max(cy - r + 1, 0L), y1 = std::min(cy + r - 1, ny_ - 1);
    for (long y = y0; y <= y1; ++y) {
      visit(cx - r, y);
      visit(cx + r, y);
    }
  }
  if (best2 == std::numeric_limits<double>::infinity()) return best2;
  return point_segment_distance(q, pts_[nearest], pts_[(nearest + 1) % n]);
}

double point_segment_distance(Vec2 q, Vec2 a, Vec2 b) { return distance(q, a + (b - a) * project_on_segment(q, a, b).t); }

}  // namespace paddock
