#include "autonomy/planning/reference.h"

#include <algorithm>
#include <cmath>
#include <limits>


namespace paddock::planning {

namespace {

// points closer than this count as the same point (m)
constexpr double kDuplicateTolerance = 1e-6;

}  // namespace

ReferenceResult reference_from_spline(const CubicSpline2D& spline, const ReferenceParams& params,
                                      std::optional<double> v_start, std::optional<double> v_end) {
  ReferenceResult out;
  if (const std::string bad = params::validate(params); !bad.empty()) {
    out.reason = "reference: " + bad;
    return out;
  }
  if (spline.empty()) {
    out.reason = "reference: the spline is empty";
    return out;
  }
  // samples at equal steps of true arc length, with heading and curvature
  double length = 0.0;
  const std::vector<SplineSample> samples = sample_by_arc_length(spline, params.ds, &length);
  if (samples.size() < 2 || !(length > 0.0)) {
    out.reason = "reference: the curve has no length";
    return out;
  }
  const std::size_t n = samples.size();
  const bool closed = spline.closed();
  const std::size_t nseg = closed ? n : n - 1;
  const double step = length / static_cast<double>(nseg);

  // the velocity profile along the samples
  std::vector<double> curvature(n);
  for (std::size_t i = 0; i < n; ++i) curvature[i] = samples[i].curvature;
  const std::vector<double> seg(nseg, step);
  VelocityProfile profile = solve_velocity_profile(curvature, seg, closed, params.profile, v_start, v_end);
  if (!profile.ok()) {
    out.reason = "reference: " + profile.reason;
    return out;
  }

  Trajectory& traj = out.trajectory;
  traj.closed = closed;
  traj.length = length;
  traj.points.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    TrajectoryPoint& p = traj.points[i];
    p.s = samples[i].s;
    p.x = samples[i].position.x;
    p.y = samples[i].position.y;
    p.heading = wrap_angle(samples[i].heading);
    p.curvature = samples[i].curvature;
    p.speed = profile.speed[i];
  }
  return out;
}

ReferenceResult build_reference(const std::vector<Vec2>& centreline, bool closed,
                                const ReferenceParams& params, std::optional<double> v_start,
                                std::optional<double> v_end) {
  ReferenceResult out;
  if (const std::string bad = params::validate(params); !bad.empty()) {
    out.reason = "reference: " + bad;
    return out;
  }
  // the centreline: finite, long enough, no point repeated
  for (const Vec2& p : centreline) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) {
      out.reason = "reference: the centreline has a NaN or infinite coordinate";
      return out;
    }
  }
  std::vector<Vec2> pts = centreline;
  // a closed centreline may close itself explicitly: drop the repeat
  if (closed && pts.size() >= 2 && distance(pts.front(), pts.back()) <= kDuplicateTolerance) pts.pop_back();
  const std::size_t min_points = closed ? 3 : 2;
  if (pts.size() < min_points) {
    out.reason = std::string("reference: a ") + (closed ? "closed" : "open") + " centreline needs at least " +
                 std::to_string(min_points) + " distinct points, got " + std::to_string(pts.size());
    return out;
  }
  for (std::size_t i = 0; i + 1 < pts.size(); ++i) {
    if (distance(pts[i], pts[i + 1]) <= kDuplicateTolerance) {
      out.reason = "reference: centreline points " + std::to_string(i) + " and " + std::to_string(i + 1) +
                   " coincide";
      return out;
    }
  }

  // knots at equal arc-length spacing along a first spline through every
  // centreline point. Spacing them along the spline rather than along the
  // polyline keeps them on the curve the points describe: on a polygon
  // approximating a circle, knots on the straight edges would sit up to a
  // sagitta inside it and ripple the curvature by 15 % (36-gon, R = 10 m,
  // 3 m knots); on the curve they stay within 1 %.
  const SplineFit dense = fit_spline(pts, closed);
  if (!dense.ok()) {
    out.reason = "reference: " + dense.reason;
    return out;
  }
  const double total = dense.spline.length();
  const double count = std::max(closed ? 3.0 : 1.0, std::round(total / params.knot_spacing));
  const auto n_knots = static_cast<std::size_t>(count) + (closed ? 0 : 1);
  std::vector<Vec2> knot_pts;
  knot_pts.reserve(n_knots);
  for (std::size_t k = 0; k < n_knots; ++k) {
    const double s = total * static_cast<double>(k) / count;
    const double u = (!closed && k + 1 == n_knots) ? dense.spline.param_end()
                                                    : dense.spline.param_at_arc_length(s).value_or(0.0);
    knot_pts.push_back(dense.spline.position(u));
  }

  const SplineFit fit = fit_spline(knot_pts, closed);
  if (!fit.ok()) {
    out.reason = "reference: " + fit.reason;
    return out;
  }
  return reference_from_spline(fit.spline, params, v_start, v_end);
}

double lap_time(const Trajectory& trajectory) {
  if (trajectory.empty()) return 0.0;
  const auto& pts = trajectory.points;
  const std::size_t n = pts.size();
  std::vector<double> speed(n), seg;
  seg.reserve(n);
  for (std::size_t i = 0; i < n; ++i) speed[i] = pts[i].speed;
  for (std::size_t i = 0; i + 1 < n; ++i) seg.push_back(pts[i + 1].s - pts[i].s);
  if (trajectory.closed) seg.push_back(trajectory.length - pts[n - 1].s);
  return profile_time(speed, seg, trajectory.closed);
}

}  // namespace paddock::planning
