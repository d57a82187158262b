#pragma once
// the minimum-curvature racing line: the path between two boundaries that
// bends least, sum of kappa^2 ds, keeping a clearance to both. It is the
// classic approximation of the minimum-lap-time line (Braghin et al. 2008;
// TUM's global_racetrajectory_optimization solves it as a QP on spline
// coefficients): the less a line bends, the faster its corners, and on FS
// tracks, which are mostly corners, it is within a few per cent of the true
// minimum-time line.
//
// Formulation: reference points r_i every `step` metres along a reference
// line (a centreline), each free to move along its normal n_i by an offset
// a_i (> 0 to the left), p_i = r_i + a_i n_i, a_i within [lo_i, hi_i] where
// lo_i and hi_i keep p_i `clearance` from the right and left boundary along
// the normal. The cost is the sum over i of kappa_i^2 ds_i with kappa_i the
// curvature of the circle through p_i-1, p_i, p_i+1 (Menger curvature), a
// smooth non-linear least-squares problem with bounds, solved by a
// primal-dual interior-point method (IPOPT's algorithm specialised to
// bounds, interior_point.h; Gauss-Newton Hessian, gradients by Ceres'
// automatic differentiation) from the reference (a_i = 0). An
// interior-point method because a line pressed against a boundary of
// cones is pressed against many facets at once: Ceres' bounded
// Levenberg-Marquardt, which projects each step onto the box, stalls there
// with the line following the facets.
// The bounds are distances along the normals; where the Euclidean
// distance of a solved point to a boundary falls short of the clearance
// (the boundary bends towards it), that bound is tightened and the problem
// solved again (up to 4 rounds).
#include <optional>
#include <string>
#include <vector>

#include "autonomy/common/geometry.h"
#include "autonomy/common/params.h"

namespace paddock::planning {

struct RacingLineParams {
  // the car's centre keeps this far from each boundary line (the lines
  // joining consecutive cones of one colour): half the car's width (0.7 m)
  // and a margin for tracking errors
  double clearance = 1.0;
  // spacing of the reference points: about the wheelbase, so that the line
  // cannot bend at a scale the car cannot follow, and fine enough for the
  // tightest FS hairpins (centreline radius ~2.5 m)
  double step = 1.0;
  // boundaries further than this along a normal count as absent (m): the
  // point may not leave the reference on that side
  double reach = 15.0;
  int max_iterations = 300;
  // a boundary segment longer than this (m) is not a boundary: two cones
  // that far apart leave a gap the line must not be drawn into
  double max_gap = 1e9;

  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(clearance), {"m", params::at_least(0.0), "the line keeps this far from each boundary"});
    v(PADDOCK_PARAM(step), {"m", params::in(0.1, 10.0), "spacing of the optimised points"});
    v(PADDOCK_PARAM(reach), {"m", params::above(0.0), "a boundary further than this along a normal is not used"});
    v(PADDOCK_PARAM(max_iterations), {"", params::in(1, 10000), "solver iterations at most"});
    v(PADDOCK_PARAM(max_gap), {"m", params::above(0.0), "boundary segments longer than this are gaps, not boundaries"});
  }
};

struct RacingLine {
  std::vector<Vec2> points;     // the optimised line, one point per reference point, driving order
  std::vector<Vec2> reference;  // the reference points it started from
  std::vector<double> offset;   // a_i (m, > 0 left of the reference)
  std::vector<double> lower;    // the offset's bounds (m)
  std::vector<double> upper;
  double cost_reference = 0.0;  // sum kappa^2 ds of the reference points (1/m)
  double cost = 0.0;            // and of the optimised line
  int iterations = 0;
  std::string reason;           // empty when ok

  bool ok() const { return reason.empty(); }
};

// the minimum-curvature line along `reference` (driving order; closed: a lap,
// first point not repeated) between `left` and `right` (the boundary
// polylines, closed like the reference). Where the boundaries are closer
// together than twice the clearance, the point stays midway between them.
// Fewer than 3 (closed) or 4 (open) resampled points, NaN or bad parameters
// give a reason; nothing throws. Open lines have no curvature term at the
// ends; their end points' offsets are free, or held at 0 with pin_ends (a
// path that starts at the car and ends where the known track ends), and
// with start_heading (rad) as well the second point is held where the line
// leaves its first along that heading (the car's: a line that starts at an
// angle to the car asks a step of steering), as far as its bounds allow.
RacingLine min_curvature_line(const std::vector<Vec2>& reference, const std::vector<Vec2>& left,
                              const std::vector<Vec2>& right, bool closed, const RacingLineParams& params = {},
                              bool pin_ends = false, std::optional<double> start_heading = std::nullopt);

// sum kappa_i^2 ds_i of a polyline with Menger curvature (the cost above):
// closed, every point; open, the inner points
double curvature_cost(const std::vector<Vec2>& points, bool closed);

}  // namespace paddock::planning
