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
#include "autonomy/planning/racing_line.h"
#include "autonomy/planning/reference.h"
#include "autonomy/planning/smoothing.h"

namespace paddock::planning {

struct PathPlannerParams {
  // the line the car drives: the paper's smoothed centreline, or the
  // minimum-curvature line inside the mapped boundaries: a trackdrive's
  // locked lap's (plan_locked_lap, plan_racing_line), and every open path
  // plan_path gives while exploring (autocross, a trackdrive's first lap)
  // as far as the map shows the track
  enum Line { Centreline, MinCurvature };
  static constexpr params::Choice<Line> kLineNames[] = {{"centreline", Centreline}, {"min_curvature", MinCurvature}};
  Line line = Centreline;
  CentrelineParams search;
  SmoothingParams smoothing;
  ClearanceParams clearance;
  ReferenceParams reference;
  // the racing line of a lap (line = min_curvature). Its clearance is to the
  // boundary lines between the cones, the car's centre kept half its width
  // (0.7 m) and a margin for tracking errors and the rear axle's
  // off-tracking away; boundary segments longer than max_gap are not known
  // well enough (a cone missed by the map), and the line keeps to the
  // centreline across them
  // limits = ggv: the shares of the envelope every path plan_path gives
  // (exploring: the autocross, a trackdrive's first lap, a lap the search
  // closes before the car is back at its start) plans with in place of the
  // profile's margins, lower because the map ahead is still being found and
  // the path is replanned every cycle; the profile's own margins are for
  // the locked lap (plan_locked_lap)
  double explore_margin_lateral = 0.6;
  double explore_margin_longitudinal = 0.6;
  RacingLineParams racing = [] {
    RacingLineParams r;
    r.clearance = 1.2;
    r.max_gap = 8.0;
    return r;
  }();

  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(line), kLineNames, "the line driven: the centreline, or the minimum-curvature racing line");
    v.section(PADDOCK_PARAM(search), "the reward-based centreline search");
    v.section(PADDOCK_PARAM(smoothing), "the centreline's smoothing");
    v.section(PADDOCK_PARAM(clearance), "the smoothed points are pushed clear of the cones");
    v.section(PADDOCK_PARAM(reference), "the reference trajectory: spline and velocity profile");
    v(PADDOCK_PARAM(explore_margin_lateral), {"", params::above_up_to(0.0, 1.0), "limits = ggv: lateral share of the envelope on an open path"});
    v(PADDOCK_PARAM(explore_margin_longitudinal), {"", params::above_up_to(0.0, 1.0), "limits = ggv: longitudinal share of the envelope on an open path"});
    v.section(PADDOCK_PARAM(racing), "the minimum-curvature racing line of a full lap (line = min_curvature)");
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
  // with line = min_curvature: the racing line's optimised points (empty
  // when the path follows the centreline), its boundaries from the path's
  // cones, and why the centreline was kept (empty when the racing line is
  // driven)
  std::vector<Vec2> racing_line;
  std::vector<Vec2> left_boundary, right_boundary;
  std::string racing_fallback;
  PlanStatus status = PlanStatus::BadInput;
  std::string reason;             // empty when Ok

  bool ok() const { return status == PlanStatus::Ok; }
};

// one planning cycle on the cone map seen so far.
//   vehicle  the car's pose in the map frame
//   speed    its speed (m/s): an open trajectory starts at most this fast
//            (negative counts as 0)
// A full lap (the search closes the loop) gives a closed trajectory with a
// closed velocity profile (along the centreline: plan_racing_line turns it
// into the racing line). Otherwise the path is open: it starts at the
// vehicle and ends at the last centreline point found, at speed 0, since the
// car must be able to stop before the unknown. With `lap` false a lap is not
// wanted yet (a car that has not driven far enough for the search's lap to be
// trusted as the circuit, e.g. a long-range sensor that already shows the
// whole of it): a lap the search closes is planned as an open path along it
// from the vehicle, once around, ending short of the vehicle. With line =
// min_curvature an open path is the minimum-curvature line (params.racing)
// inside the boundaries of the cones along it, from the vehicle (leaving
// along its heading) to the centreline's end; the centreline where that
// fails (racing_fallback says why). Never throws.
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

// the racing line of a planned lap (plan_path's closed result): the
// minimum-curvature line (params.racing) inside the lap's boundaries, which
// are the mapped cones within 3.5 m of the lap's smoothed centreline, on the
// side where each lies, in the order of their projections along it; its
// trajectory replaces the lap's, with params.reference's profile. False,
// with the lap left as it was and racing_fallback saying why, when it fails
// or `lap` is not a planned closed lap. Meant for a lap that is final (the
// trackdrive's locked lap): it takes tens of milliseconds.
bool plan_racing_line(PlanResult& lap, const std::vector<Cone>& cones, const PathPlannerParams& params = {});

// the lap a trackdrive drives from its second lap on, from plan_path's
// closed result: the racing line (line = min_curvature), or the centreline
// (its spline again, with params.reference's profile: with limits = ggv the
// lap's margins rather than plan_path's exploring ones). False when the
// racing line failed (the centreline is then planned, and racing_fallback
// says why) or `lap` is not a planned closed lap.
bool plan_locked_lap(PlanResult& lap, const std::vector<Cone>& cones, const PathPlannerParams& params = {});

const char* to_string(PlanStatus s);

}  // namespace paddock::planning
