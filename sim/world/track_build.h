#pragma once
// what the track builders share (track.cc, track_build.cc, track_circuit.cc,
// track_acceleration.cc, track_skidpad.cc): the geometry's tuning, the cones
// by colour, polyline helpers, gates from posts, and the builder of each
// kind. Internal to sim/world; the public interface is track.h.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "autonomy/common/geometry.h"
#include "sim/world/track.h"

namespace paddock::world::detail {

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

// v scaled to length 1, or (1, 0) for the zero vector
inline Vec2 unit(Vec2 v) {
  const double n = norm(v);
  return n > 0.0 ? v / n : Vec2{1.0, 0.0};
}

// the number of segments of a polyline (closed: with the one back to the start)
inline std::size_t segment_count(const std::vector<Vec2>& p, bool closed) {
  if (p.size() < 2) return 0;
  return closed ? p.size() : p.size() - 1;
}

// the median of v (the upper one of an even count); 0 when empty
double median(std::vector<double> v);


// ---------------------------------------------------------------------------
// cones by colour, doubles merged

struct ConeSets {
  std::vector<Cone> all;  // every cone but the doubles
  std::vector<Vec2> blue, yellow, orange, big_orange;
};

// ---------------------------------------------------------------------------
// gates

// a pair of posts as a gate whose left post is on the left of `heading`
Segment gate_from_posts(Vec2 p, Vec2 q, Vec2 heading);

// big orange cones grouped into posts per side (by position `along` the
// track) and paired across: gates as (along of the gate, left post, right post)
struct Post {
  double along = 0.0;
  Vec2 position;
};

// cones (along, position) sorted by `along` and merged into posts where closer than kPostGroupDistance
std::vector<Post> group_posts(std::vector<std::pair<double, Vec2>> cones);

// the along-track coordinate and signed side (> 0 left) of a point
struct Station {
  double along = 0.0;
  double side = 0.0;
};

// big orange cones paired across the track into gates, in the order of their
// `along` (station_of(p) gives a point's along-track coordinate and side)
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
// the builders of each kind: they fill m from the file and its cones

// circuits (track_circuit.cc)
void build_circuit(TrackModel& m, const TrackFile& f, const ConeSets& cs);

// acceleration (track_acceleration.cc): two straight parallel lines of blue and yellow cones
// true when the blue and the yellow cones each lie on a straight line over
// 30 m, within kLineTolerance, and the two lines are parallel within 5 degrees
bool looks_like_acceleration(const ConeSets& cs);
void build_acceleration(TrackModel& m, const TrackFile& f, const ConeSets& cs);

// skidpad (track_skidpad.cc): two rings of cones around each of two centres
// the cones of one ring, with their colours
struct Ring {
  std::vector<Vec2> cones;
  std::vector<ConeColor> colors;
};

// one circle of the figure of eight: its centre, the radii of its rings and their cones
struct SkidCircle {
  Vec2 centre;
  double r_in = 0.0, r_out = 0.0;
  Ring inner, outer;
};

// two centres with two rings each, or nothing
std::optional<std::array<SkidCircle, 2>> find_skidpad(const ConeSets& cs, std::vector<std::string>& unassigned);
// the skidpad from its two circles; `unassigned` lists the ring cones that fit
// no ring (for a note)
void build_skidpad(TrackModel& m, const TrackFile& f, const ConeSets& cs, std::array<SkidCircle, 2> circles,
                   const std::vector<std::string>& unassigned);

}  // namespace paddock::world::detail
