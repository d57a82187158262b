#pragma once
// one planning cycle (paper section "Planning"): the Delaunay triangulation
// of the cone map, the centreline search from the vehicle, smoothing, a
// clearance pass that keeps the points away from the cones (clearance.h),
// and the reference trajectory (C2 spline and velocity profile). Autocross and
// trackdrive use plan_path; acceleration fits a line to the centreline
// (plan_acceleration).
#include <optional>
#include <string>
#include <vector>

#include "autonomy/common/cone.h"
#include "autonomy/common/geometry.h"
#include "autonomy/common/params.h"
#include "autonomy/common/trajectory.h"
#include "autonomy/planning/centreline.h"
#include "autonomy/planning/clearance.h"
#include "autonomy/planning/delaunay.h"
#include "autonomy/planning/reference.h"
#include "autonomy/planning/smoothing.h"

namespace paddock::planning {

struct PathPlannerParams {
  CentrelineParams search;
  SmoothingParams smoothing;
  ClearanceParams clearance;
  ReferenceParams reference;

  template <class V>
  void visit(V& v) {
    v.section(PADDOCK_PARAM(search), "the reward-based centreline search");
    v.section(PADDOCK_PARAM(smoothing), "the centreline's smoothing");
    v.section(PADDOCK_PARAM(clearance), "the smoothed points are pushed clear of the cones");
    v.section(PADDOCK_PARAM(reference), "the reference trajectory: spline and velocity profile");
  }
};

enum class PlanStatus {
  Ok,
  BadParams,        // params::validate() failed
  BadInput,         // a non-finite vehicle pose or speed
  NoTriangulation,  // fewer than 3 distinct cones, or all on one line
  NoCentreline,     // the search found no path (see `search` for why)
  NoReference,      // the spline or the velocity profile failed
};

struct PlanResult {
  Trajectory trajectory;          // empty unless Ok
  std::vector<Vec2> centreline;   // raw: open, the vehicle's position and then the search's points;
                                  // closed, the search's lap (end points overlapping its start dropped)
  std::vector<Vec2> smoothed;     // smoothed and pushed clear of the cones: what the spline is fitted through
  bool closed = false;            // a full lap: closed spline and closed velocity profile
  Triangulation triangulation;    // for plots: the grey layer, the midpoints
  CentrelineResult search;        // the search's points, scores and stop reason
  PlanStatus status = PlanStatus::BadInput;
  std::string reason;             // empty when Ok

  bool ok() const { return status == PlanStatus::Ok; }
};

// one planning cycle on the cone map seen so far.
//   vehicle  the car's pose in the map frame
//   speed    its speed (m/s): an open trajectory starts at most this fast
//            (negative counts as 0)
// A full lap (the search closes the loop) gives a closed trajectory with a
// closed velocity profile. Otherwise the path is open: it starts at the
// vehicle and ends at the last centreline point found, at speed 0, since the
// car must be able to stop before the unknown. With `lap` false a lap is not
// wanted yet (a car that has not driven far enough for the search's lap to be
// trusted as the circuit, e.g. a long-range sensor that already shows the
// whole of it): a lap the search closes is planned as an open path along it
// from the vehicle, once around, ending short of the vehicle. Never throws.
PlanResult plan_path(const std::vector<Cone>& cone_map, const Pose2& vehicle, double speed,
                     const PathPlannerParams& params = {}, bool lap = true);

// acceleration (the paper's line fitting): the centreline search as in
// plan_path, a line fitted to its points (fit_line, autonomy/common/line_fit.h), and a straight open trajectory
// along it from the vehicle's projection onto the line, heading the way the
// vehicle heads, for `length` metres (default: to the farthest centreline
// point), ending at speed 0. The search's result is kept for plots.
PlanResult plan_acceleration(const std::vector<Cone>& cone_map, const Pose2& vehicle,
                             double speed, const PathPlannerParams& params = {},
                             std::optional<double> length = std::nullopt);

const char* to_string(PlanStatus s);

}  // namespace paddock::planning
