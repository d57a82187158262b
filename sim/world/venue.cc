// the venue's barrier rows around a track: see venue.h.
#include "sim/world/venue.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace paddock::world {

namespace {

// a polyline walked by arc length (closed: the last point joins the first)
class Walk {
 public:
  Walk(const std::vector<Vec2>& pts, bool closed) : pts_(pts), closed_(closed) {
    s_.push_back(0.0);
    const std::size_t n = pts_.size();
    const std::size_t segs = closed_ ? n : n - 1;
    for (std::size_t i = 0; i < segs; ++i) s_.push_back(s_.back() + distance(pts_[i], pts_[(i + 1) % n]));
  }
  double length() const { return s_.back(); }
  Vec2 at(double s) const {
    const double L = length();
    if (closed_) {
      s = std::fmod(s, L);
      if (s < 0.0) s += L;
    } else {
      s = std::clamp(s, 0.0, L);
    }
    const auto it = std::upper_bound(s_.begin(), s_.end(), s);
    const std::size_t i = it == s_.begin() ? 0 : std::min<std::size_t>(static_cast<std::size_t>(it - s_.begin()) - 1, s_.size() - 2);
    const double ds = s_[i + 1] - s_[i];
    const double f = ds > 0.0 ? (s - s_[i]) / ds : 0.0;
    const Vec2 a = pts_[i], b = pts_[(i + 1) % pts_.size()];
    return a + (b - a) * f;
  }

 private:
  const std::vector<Vec2>& pts_;
  bool closed_;
  std::vector<double> s_;  // arc length at each point (and at the closing point)
};

double point_segment_distance(Vec2 p, Vec2 a, Vec2 b) {
  const Vec2 ab = b - a;
  const double l2 = squared_norm(ab);
  const double f = l2 > 0.0 ? std::clamp(dot(p - a, ab) / l2, 0.0, 1.0) : 0.0;
  return distance(p, a + ab * f);
}

// whether two footprints overlap (separating axes: the rectangles' edge normals)
bool overlap(const Block& a, const Block& b) {
  const std::vector<Vec2> ca = block_corners(a), cb = block_corners(b);
  for (const Block* r : {&a, &b}) {
    for (const Vec2 axis : {unit_from_angle(r->yaw), left_normal(unit_from_angle(r->yaw))}) {
      double lo_a = dot(ca[0], axis), hi_a = lo_a, lo_b = dot(cb[0], axis), hi_b = lo_b;
      for (std::size_t k = 1; k < 4; ++k) {
        lo_a = std::min(lo_a, dot(ca[k], axis));
        hi_a = std::max(hi_a, dot(ca[k], axis));
        lo_b = std::min(lo_b, dot(cb[k], axis));
        hi_b = std::max(hi_b, dot(cb[k], axis));
      }
      if (hi_a <= lo_b || hi_b <= lo_a) return false;
    }
  }
  return true;
}

}  // namespace

std::vector<Vec2> block_corners(const Block& b) {
  const Vec2 u = unit_from_angle(b.yaw), n = left_normal(u);
  const Vec2 hl = u * (0.5 * b.length), hw = n * (0.5 * b.width);
  return {b.centre - hl - hw, b.centre + hl - hw, b.centre + hl + hw, b.centre - hl + hw};
}

std::vector<Block> venue_blocks(const TrackModel& track, const std::vector<Cone>& cones, const VenueParams& p) {
  std::vector<Block> blocks;
  if (p.barrier_offset <= 0.0) return blocks;
  const double keep = 0.9 * p.barrier_offset;
  // a point where a barrier may stand: far enough from every cone, off the track
  const auto free = [&](Vec2 q) {
    for (const Cone& c : cones) {
      if (finite(c.position) && distance(q, c.position) < keep) return false;
    }
    return !track.on_track(q);
  };
  // side: +1 offsets to the left of the line's direction, -1 to the right
  const auto row = [&](const std::vector<Vec2>& line, double side) {
    if (line.size() < 2) return;
    const Walk walk(line, track.closed);
    const double L = walk.length();
    if (!(L > p.block_length)) return;
    // the steps: a whole number of them on a closed line (no seam)
    const auto n = static_cast<std::size_t>(std::floor(L / p.block_length));
    const double step = track.closed ? L / static_cast<double>(n) : p.block_length;
    const std::size_t count = track.closed ? n : n + 1;
    const double h = 1.0;  // m, the tangent from the line 1 m either side
    std::vector<Vec2> at(count);
    std::vector<char> ok(count);
    for (std::size_t k = 0; k < count; ++k) {
      const double s = step * static_cast<double>(k);
      const Vec2 t = walk.at(s + h) - walk.at(s - h);
      const double tn = norm(t);
      if (!(tn > 0.0)) continue;
      at[k] = walk.at(s) + left_normal(t / tn) * (side * p.barrier_offset);
      ok[k] = free(at[k]);
    }
    const std::size_t pairs = track.closed ? count : count - 1;
    std::size_t last_of_row = 0;  // blocks.size() just after this row's last block
    for (std::size_t k = 0; k < pairs; ++k) {
      const std::size_t k1 = (k + 1) % count;
      if (!ok[k] || !ok[k1]) continue;
      const Vec2 a = at[k], b = at[k1];
      const double len = distance(a, b);
      // a fold of the offset line (an inner corner) gives a short or long chord
      if (len < 0.5 * p.block_length || len > 2.0 * p.block_length) continue;
      // the whole axis: no cone nearer than keep, no point of it on the track
      bool axis_free = true;
      for (const Cone& c : cones) {
        if (finite(c.position) && point_segment_distance(c.position, a, b) < keep) {
          axis_free = false;
          break;
        }
      }
      const int samples = static_cast<int>(std::ceil(len / 0.25));
      for (int q = 1; q < samples && axis_free; ++q) axis_free = !track.on_track(a + (b - a) * (q / double(samples)));
      if (!axis_free) continue;
      // no overlap with a block already placed; at a bend, the block gives
      // way to its row's previous one by starting later (by up to half its
      // length, in 5 % steps)
      Block blk;
      bool clear = false;
      for (int f = 0; f <= 10 && !clear; ++f) {
        const Vec2 a1 = a + (b - a) * (0.05 * f);
        blk = {0.5 * (a1 + b), angle_of(b - a), distance(a1, b) - p.block_gap, p.barrier_width, p.barrier_height};
        if (!(blk.length > 0.0)) break;
        clear = true;
        for (std::size_t o = 0; o < blocks.size() && clear; ++o) clear = !overlap(blocks[o], blk);
        if (!clear && !(last_of_row == blocks.size() && !blocks.empty() && overlap(blocks.back(), blk))) break;
      }
      if (!clear) continue;
      blocks.push_back(blk);
      last_of_row = blocks.size();
    }
  };
  row(track.left, +1.0);
  row(track.right, -1.0);
  return blocks;
}

}  // namespace paddock::world
