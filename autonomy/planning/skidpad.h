#pragma once
// the skidpad (paper section "Planning"): a precalculated figure-of-eight
// path from the rules' geometry, aligned with the observed cones by 2D
// Generalised ICP (gicp.h), then a velocity profile.
//
// The template frame is the rules' layout as in tracks/skidpad.csv: the
// circles' centres at (0, +-9.125), crossing at the origin, the car driving
// +x through the middle; the entry lane on x < 0, the exit lane on x > 0.
#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "autonomy/common/cone.h"
#include "autonomy/common/geometry.h"
#include "autonomy/common/params.h"
#include "autonomy/common/trajectory.h"
#include "autonomy/planning/gicp.h"
#include "autonomy/planning/reference.h"

namespace paddock::planning {

// the rules' skidpad, as laid out in PacSim's skidpad.yaml (tracks/skidpad.csv)
struct SkidpadGeometry {
  // the centreline radius is half of it, 9.125 m
  double centre_distance = 18.25;
  // a 3 m lane
  double inner_diameter = 15.25;
  double outer_diameter = 21.25;
  // cone centres on radii 7.475 and 10.775 m, lane cones 1.65 m off the axis
  double cone_offset = 0.15;
  // one every 22.5 degrees; the outer rings stop where they meet the lanes
  int cones_per_ring = 16;
  std::vector<double> entry_lane_x = {-15.0, -11.25};
  std::vector<double> exit_lane_x = {11.0, 16.0, 21.0};
  double exit_end_x = 21.0;
  double timekeeping_x = 1.3;
  double timekeeping_y = 2.0;

  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(centre_distance), {"m", params::above(0.0), "distance between the two circles' centres"});
    v(PADDOCK_PARAM(inner_diameter), {"m", params::above(0.0), "diameter of the inner boundary line"});
    v(PADDOCK_PARAM(outer_diameter), {"m", params::above(0.0), "diameter of the outer boundary line"});
    v(PADDOCK_PARAM(cone_offset), {"m", params::at_least(0.0), "cones stand this far outside the lane's boundary lines"});
    v(PADDOCK_PARAM(cones_per_ring), {"", params::at_least(4), "cones per full ring, the first of each ring on the axis x = 0"});
    v(PADDOCK_PARAM(entry_lane_x), {"m", params::any(), "the entry lane's small orange cones: their x, on both sides of the axis"});
    v(PADDOCK_PARAM(exit_lane_x), {"m", params::any(), "the exit lane's small orange cones: their x, on both sides of the axis"});
    v(PADDOCK_PARAM(exit_end_x), {"m", params::above(0.0), "the exit lane is closed by a small orange cone on the axis here"});
    v(PADDOCK_PARAM(timekeeping_x), {"m", params::any(), "big orange timekeeping cones at (+-x, +-y): x"});
    v(PADDOCK_PARAM(timekeeping_y), {"m", params::any(), "big orange timekeeping cones at (+-x, +-y): y"});
  }
  std::string check() const;

  double centreline_radius() const { return 0.5 * centre_distance; }
  double inner_cone_radius() const { return 0.5 * inner_diameter - cone_offset; }
  double outer_cone_radius() const { return 0.5 * outer_diameter + cone_offset; }
  // distance of the lane cones from the axis (m)
  double lane_half_width() const { return centre_distance / 2.0 - inner_cone_radius(); }
};

// the cones the rules place, in the template frame: the right circle
// (centre (0, -9.125), driven clockwise) has yellow inner and blue outer
// cones, the left one (centre (0, 9.125), counter-clockwise) blue inner and
// yellow outer cones; small orange lane cones, big orange timekeeping cones.
// Empty when the geometry is invalid.
std::vector<Cone> skidpad_template_cones(const SkidpadGeometry& geometry = {});

struct SkidpadPathParams {
  SkidpadGeometry geometry;
  // each piece (the straights and every lap) is split into equal steps as
  // close to this as fit
  double spacing = 0.5;
  // behind where the car starts (x = -16.68 in tracks/skidpad.csv, -16.5 in
  // the FSSIM layout)
  double entry_length = 18.0;
  // the rear axle stops 4 m before the closing cone, the nose ~1.5 m before it
  double exit_stop_distance = 4.0;

  template <class V>
  void visit(V& v) {
    v.section(PADDOCK_PARAM(geometry), "the rules' skidpad layout");
    v(PADDOCK_PARAM(spacing), {"m", params::above(0.0), "spacing of the path's points (<= the centreline radius / 4)"});
    v(PADDOCK_PARAM(entry_length), {"m", params::at_least(0.0), "the entry straight starts this far before the crossing"});
    v(PADDOCK_PARAM(exit_stop_distance), {"m", params::at_least(0.0),
                                          "the exit straight ends this far before the end of the exit lane (< geometry.exit_end_x)"});
  }
  std::string check() const;
};

// the figure-of-eight path
struct SkidpadPath {
  std::vector<Vec2> points;                // driving order (m)
  std::array<std::size_t, 4> lap_start{};  // index of the crossing where each lap begins:
                                           // right, right, left, left
  std::size_t exit_start = 0;              // index of the crossing where the exit begins
  std::string reason;                      // empty when ok

  bool ok() const { return reason.empty(); }
};

// in the template frame: the entry straight along +x to the crossing, the
// right circle twice clockwise around (0, -R), the left circle twice
// counter-clockwise around (0, R), R = the centreline radius, then the exit
// straight along +x to exit_end_x - exit_stop_distance. Consecutive points
// differ; the crossing is a point of the path each of its 5 passes.
SkidpadPath skidpad_path(const SkidpadPathParams& params = {});

struct SkidpadParams {
  SkidpadPathParams path;
  GicpParams gicp;
  // not visited: the runner sets it to the planner's ([planning]), so the
  // skidpad plans with the same limits; check() checks it
  ReferenceParams reference;
  int min_inliers = 8;
  double max_rmse = 0.3;

  template <class V>
  void visit(V& v) {
    v.section(PADDOCK_PARAM(path), "the figure-of-eight path in the template frame");
    v.section(PADDOCK_PARAM(gicp), "the alignment of the template cones to the observed cones");
    v(PADDOCK_PARAM(min_inliers), {"", params::at_least(3), "the alignment is accepted with at least this many template cones matched ..."});
    v(PADDOCK_PARAM(max_rmse), {"m", params::above(0.0), "... at an RMS distance of at most this"});
  }
  std::string check() const {
    const std::string why = params::validate(reference);
    return why.empty() ? "" : "reference." + why;
  }
};

struct SkidpadPlan {
  Trajectory trajectory;  // map frame; empty on failure
  SkidpadPath path;       // the path's points in the map frame
  Pose2 T_map_template;   // the aligned template's pose
  GicpResult alignment;   // template cones (source) onto observed cones (target)
  std::string reason;     // empty when ok

  bool ok() const { return reason.empty(); }
};

// the skidpad's reference trajectory in the map frame.
//   observed_cones  the cone map (map frame); colours are not used
//   initial_guess   T_map_template, e.g. from the car's start pose
// GICP aligns the template cones to the observed cones, all colours
// together: correspondences by nearest neighbour whatever the colour, and
// covariances from neighbours of any colour, so a flipped or unknown colour
// (a LiDAR-only map) costs nothing. (Covariances from same-colour
// neighbours only, which trace a single ring, converged no better: 233 vs
// 291 of 300 partial views with 5 % colour flips.) The path is moved by the
// result and given a velocity profile ending at rest. No cones, non-finite
// values, a failed or poor alignment (min_inliers, max_rmse) or bad
// parameters give an empty trajectory and a reason.
SkidpadPlan plan_skidpad(const std::vector<Cone>& observed_cones, const Pose2& initial_guess,
                         const SkidpadParams& params = {});

}  // namespace paddock::planning
