#pragma once
// what stands around a real venue's track besides the cones: rows of barrier
// blocks (concrete or water-filled, as the paddock and run-off areas of FSG,
// FS East or FS Spain have them) outside the track's boundaries. A LiDAR
// odometry needs them: cones and a flat ground leave the car's x, y and yaw
// nearly unobserved on a straight (issue 11's degeneracy), as on a bare
// airfield.
//
// The sensors see them (LiDAR and camera, as solids of their own material);
// the car's physics does not: they stand `barrier_offset` outside the cones,
// where a car has left the track long before it could touch them.
//
// Where they go (venue_blocks): each boundary line of the track, walked at
// `block_length` steps, offset outwards (left of the left line, right of the
// right one) by `barrier_offset`; an offset point is kept only if it stays at
// least 0.9 `barrier_offset` from every cone and off the track (so no block
// stands in a hairpin's fold, in a narrow infield or across another part of
// the track), and two consecutive kept points carry one block between them,
// its whole axis checked the same way (every cone at least 0.9
// `barrier_offset` from it, a point every 0.25 m off the track). A block whose
// footprint overlaps one already placed (the offset lines of two boundaries
// meeting in an infield) is left out, unless it overlaps only its row's
// previous block (at a bend): then it starts later, by up to half its length.
// Deterministic: the same track and parameters give the same blocks.
#include <string>
#include <vector>

#include "autonomy/common/geometry.h"
#include "autonomy/common/params.h"
#include "sim/world/track.h"

namespace paddock::world {

struct VenueParams {
  double barrier_offset = 0.0;     // m, from the boundary cones outwards (0: no barriers)
  double barrier_height = 1.0;     // m, concrete and water-filled barriers are 0.8-1.1 m
  double barrier_width = 0.6;      // m, their base
  double block_length = 2.0;       // m, one block (water-filled blocks are 1-2 m)
  double block_gap = 0.05;         // m, between two blocks of a row

  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(barrier_offset), {"m", params::in(0.0, 100.0), "barrier rows this far outside the boundary cones (0: none)"});
    v(PADDOCK_PARAM(barrier_height), {"m", params::in(0.1, 10.0), "height of a barrier block"});
    v(PADDOCK_PARAM(barrier_width), {"m", params::in(0.05, 5.0), "width of a barrier block"});
    v(PADDOCK_PARAM(block_length), {"m", params::in(0.5, 20.0), "length of a barrier block"});
    v(PADDOCK_PARAM(block_gap), {"m", params::in(0.0, 10.0), "gap between two blocks of a row"});
  }
  std::string check() const {
    if (barrier_offset > 0.0 && barrier_offset < 0.5 * barrier_width + 0.5) {
      return "barrier_offset must be 0 (no barriers) or at least half the barrier's width plus 0.5 m";
    }
    return "";
  }
};

// a box standing on the ground: its footprint's centre and heading (along
// its length), its size
struct Block {
  Vec2 centre;
  double yaw = 0.0;     // rad
  double length = 0.0;  // m, along yaw
  double width = 0.0;   // m
  double height = 0.0;  // m
};

// the barrier blocks around `track` (none when barrier_offset is 0), clear of
// `cones` (the cones standing at the event: the track's and any the event
// adds, such as timekeeping posts); see the top of this file
std::vector<Block> venue_blocks(const TrackModel& track, const std::vector<Cone>& cones, const VenueParams& p);

// the corners of a block's footprint, counter-clockwise
std::vector<Vec2> block_corners(const Block& b);

}  // namespace paddock::world
