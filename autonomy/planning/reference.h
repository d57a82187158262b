#pragma once
// the reference trajectory (paper section "Planning"): a centreline through
// C2 cubic-spline knots, sampled at a fixed arc-length spacing with heading
// and curvature, and the velocity profile along it.
#include <optional>
#include <string>
#include <vector>

#include "autonomy/common/geometry.h"
#include "autonomy/common/trajectory.h"
#include "autonomy/planning/spline.h"
#include "autonomy/planning/velocity_profile.h"

namespace paddock::planning {

struct ReferenceParams {
  // knot spacing: the centreline's points are joined by a first spline,
  // knots are taken on it this far apart, and the final spline goes through
  // the knots only: this sets how much of the centreline's point noise the
  // curve follows (an interpolating cubic through knots d apart turns a
  // lateral error e at one knot into a curvature error of order 6 e / d^2).
  // Measured on the FSG 2023 track (centreline: each blue cone's midpoint
  // with the yellow boundary, resampled every 0.5 m), the mean |dkappa/ds|
  // of the result is 0.16 1/m^2 at 1 m knots (the curve rings with the cone
  // noise; lap 39.0 s with the default car), 0.053 at 2 m (30.8 s), 0.025 at
  // 3 m (27.9 s) and 0.020 at 4 m, where the curve starts to cut the
  // tightest hairpin (centreline radius ~2.5 m) by 0.3-0.5 m instead of
  // 0.2-0.3 m, and stays >= 1.38 m from the boundary lines. 3 m is the
  // smallest spacing on that plateau.
  double knot_spacing = 3.0;
  // the step used is the nearest that divides the curve into equal whole
  // steps
  double ds = 0.5;
  VelocityProfileParams profile;

  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(knot_spacing), {"m", params::in(0.1, 50.0), "spline knot spacing along the centreline"});
    v(PADDOCK_PARAM(ds), {"m", params::in(0.01, 10.0), "trajectory sample spacing"});
    v.section(PADDOCK_PARAM(profile), "the velocity profile: the car's planned limits");
  }
};

// a reference trajectory, or the reason why there is none
struct ReferenceResult {
  Trajectory trajectory;  // empty on failure
  std::string reason;     // empty when ok

  bool ok() const { return reason.empty(); }
};

// the reference trajectory along a centreline.
//   centreline   points in driving order (m); closed: a lap, the first point
//                not repeated at the end (a repeated one is dropped)
//   v_start, v_end  open paths only: upper bounds of the speed at the first
//                and last sample (m/s); nothing = free
// Steps: place knots `knot_spacing` apart along a first spline through the
// centreline's points, fit the C2 spline through the knots (periodic when closed, natural ends when open), sample it every
// `ds` metres of true arc length with heading and curvature, then solve the
// velocity profile (closed when the centreline is). Fewer than 2 points
// (3 closed), duplicate consecutive points, NaN or bad parameters give an
// empty trajectory and a reason; nothing throws.
ReferenceResult build_reference(const std::vector<Vec2>& centreline, bool closed,
                                const ReferenceParams& params,
                                std::optional<double> v_start = std::nullopt,
                                std::optional<double> v_end = std::nullopt);

// the same from an already fitted spline (knot_spacing unused): for
// planners that fit their own path, e.g. a skidpad template
ReferenceResult reference_from_spline(const CubicSpline2D& spline, const ReferenceParams& params,
                                      std::optional<double> v_start = std::nullopt,
                                      std::optional<double> v_end = std::nullopt);

// time to drive the trajectory at its reference speeds (s), constant
// acceleration between samples, including the closing step of a closed
// trajectory; infinite if it stands still somewhere, 0 when empty
double lap_time(const Trajectory& trajectory);

}  // namespace paddock::planning
