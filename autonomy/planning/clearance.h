#pragma once
// keeping a planned path clear of the cones: smoothing and splines cut
// corners, and a car 1.4 m wide whose rear axle runs inside its front axle
// in a hairpin needs the path's points well away from every cone.
#include <vector>

#include "autonomy/common/cone.h"
#include "autonomy/common/geometry.h"
#include "autonomy/common/params.h"
#include "autonomy/common/trajectory.h"

namespace paddock::planning {

struct ClearanceParams {
  // half the car's width (0.7 m) + a cone's base radius (0.114 m) + the rear
  // axle's off-tracking in a 4 m hairpin (L^2 / 2R = 0.29 m)
  double clearance = 1.1;
  // a point pushed off one cone may come near another
  int iterations = 3;

  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(clearance), {"m", params::in(0.0, 5.0), "planned path points stay this far from cone centres (0: off)"});
    v(PADDOCK_PARAM(iterations), {"", params::at_least(0), "passes over the path"});
  }
};

// moves each point of `path` that lies closer than the clearance to a cone
// straight away from that cone to the clearance distance; returns how many
// moves it made. Points between two cones closer than twice the clearance
// settle where the pushes balance.
int enforce_clearance(std::vector<Vec2>& path, const std::vector<Cone>& cones, const ClearanceParams& params);

// the spline through the points can swing back towards a cone between them:
// for each sample of `traj` closer than the clearance to a cone, the points
// within `reach` metres of that sample move away from the cone by the
// shortfall (each point once, by its largest shortfall); returns how many
// moved (0: the trajectory is clear to within `tolerance`)
int clear_trajectory(std::vector<Vec2>& points, const Trajectory& traj, const std::vector<Cone>& cones,
                     const ClearanceParams& params, double reach = 2.0, double tolerance = 0.02);

}  // namespace paddock::planning
