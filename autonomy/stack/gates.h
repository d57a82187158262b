#pragma once
// timekeeping gates from the cone map: the big orange cones of a start,
// finish or timing line, grouped into posts and paired across the track.
#include <string>
#include <vector>

#include "autonomy/common/cone.h"
#include "autonomy/common/geometry.h"
#include "autonomy/common/params.h"

namespace paddock::stack {

struct GateParams {
  // the rules put them in pairs before and after the line, ~1.2 m apart
  // (FSG 2024)
  double post_radius = 1.5;
  // the track is >= 3 m wide
  double min_width = 2.5;
  // FS timing posts stand metres off the track (FSE 2023: 15.4 m apart)
  double max_width = 20.0;

  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(post_radius), {"m", params::above(0.0), "big orange cones closer than this form one post"});
    v(PADDOCK_PARAM(min_width), {"m", params::at_least(0.0), "posts of one gate are at least this far apart ..."});
    v(PADDOCK_PARAM(max_width), {"m", params::above(0.0), "... and at most this far (>= min_width)"});
  }
  std::string check() const { return max_width >= min_width ? "" : "max_width must be >= min_width"; }
};

// the posts the big orange cones of `cones` form: each the mean of the big
// orange cones within post_radius of its first one, in the order of those
// first cones
std::vector<Vec2> find_posts(const std::vector<Cone>& cones, const GateParams& params = {});

// the gates the big orange cones of `cones` form, each as a segment between
// its two posts (unoriented: orient with orient_gate); a post pairs with its
// nearest other post when that one's nearest is it too and their distance is
// in [min_width, max_width]
std::vector<Segment> find_gates(const std::vector<Cone>& cones, const GateParams& params = {});

// the gate with its left post first as seen driving along `direction`, so that
// driving that way crosses it from its right side to its left (crossing_right_to_left)
Segment orient_gate(const Segment& gate, Vec2 direction);

}  // namespace paddock::stack
