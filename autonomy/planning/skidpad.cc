#include "autonomy/planning/skidpad.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace paddock::planning {

namespace {

// a length for a message: "0.3 m"
std::string metres(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g m", v);
  return buf;
}

// n equal steps as close to `spacing` as fit into `length` (at least one)
int steps(double length, double spacing) {
  return std::max(1, static_cast<int>(std::lround(length / spacing)));
}

}  // namespace

std::string SkidpadGeometry::check() const {
  if (!(inner_cone_radius() > 0.0)) return "inner_diameter must be > 2 cone_offset";
  if (!(inner_diameter < outer_diameter)) return "outer_diameter must be > inner_diameter";
  if (!(lane_half_width() > 0.0 && outer_cone_radius() > centreline_radius()))
    return "centre_distance must put the centreline circle (radius centre_distance / 2) between the inner and "
           "the outer cones";
  return "";
}

std::vector<Cone> skidpad_template_cones(const SkidpadGeometry& g) {
  if (!params::validate(g).empty()) return {};
  std::vector<Cone> cones;
  const double rc = g.centreline_radius();
  const double r_in = g.inner_cone_radius();
  const double r_out = g.outer_cone_radius();
  const double h = g.lane_half_width();
  const double pitch = 2.0 * kPi / g.cones_per_ring;
  // side -1: the right circle (centre (0, -rc), clockwise, yellow inside);
  // side +1: the left circle (centre (0, rc), counter-clockwise, blue inside)
  for (const double side : {-1.0, 1.0}) {
    const Vec2 centre{0.0, side * rc};
    const ConeColor inner = side < 0.0 ? ConeColor::Yellow : ConeColor::Blue;
    const ConeColor outer = side < 0.0 ? ConeColor::Blue : ConeColor::Yellow;
    // the inner ring, whole, from its cone on the axis x = 0 next to the crossing
    for (int k = 0; k < g.cones_per_ring; ++k) {
      const double a = -side * kPi / 2.0 + pitch * k;
      cones.push_back({centre + r_in * unit_from_angle(a), inner});
    }
    // the outer ring at the same angles, where it is beyond the lane's
    // boundary line |y| = h ...
    for (int k = 0; k < g.cones_per_ring; ++k) {
      const Vec2 p = centre + r_out * unit_from_angle(-side * kPi / 2.0 + pitch * k);
      if (side * p.y > h) cones.push_back({p, outer});
    }
    // ... and closed by one cone where it meets that line on each side
    const double x_end = std::sqrt(r_out * r_out - r_in * r_in);
    cones.push_back({{-x_end, side * h}, outer});
    cones.push_back({{x_end, side * h}, outer});
  }
  // the lanes' small orange cones, the exit closed on the axis
  for (const double side : {-1.0, 1.0}) {
    for (double x : g.entry_lane_x) cones.push_back({{x, side * h}, ConeColor::SmallOrange});
    for (double x : g.exit_lane_x) cones.push_back({{x, side * h}, ConeColor::SmallOrange});
  }
  cones.push_back({{g.exit_end_x, 0.0}, ConeColor::SmallOrange});
  // the timekeeping line's big orange cones
  for (const double sx : {-1.0, 1.0})
    for (const double sy : {-1.0, 1.0})
      cones.push_back({{sx * g.timekeeping_x, sy * g.timekeeping_y}, ConeColor::BigOrange});
  return cones;
}

std::string SkidpadPathParams::check() const {
  if (!(spacing <= 0.25 * geometry.centreline_radius())) return "spacing must be <= the centreline radius / 4";
  if (!(exit_stop_distance < geometry.exit_end_x)) return "exit_stop_distance must be < geometry.exit_end_x";
  return "";
}

SkidpadPath skidpad_path(const SkidpadPathParams& params) {
  SkidpadPath path;
  if (const std::string bad = params::validate(params); !bad.empty()) {
    path.reason = "skidpad path: " + bad;
    return path;
  }
  const double rc = params.geometry.centreline_radius();
  std::vector<Vec2>& pts = path.points;
  const Vec2 crossing{0.0, 0.0};

  // the entry straight along +x, ending at the crossing
  if (params.entry_length > 0.0) {
    const int n = steps(params.entry_length, params.spacing);
    for (int i = 0; i < n; ++i)
      pts.push_back({-params.entry_length * (1.0 - static_cast<double>(i) / n), 0.0});
  }
  pts.push_back(crossing);

  // four laps from the crossing back to it: right, right (side -1: centre
  // (0, -rc), angle decreasing from +pi/2), left, left (side +1: centre
  // (0, rc), angle increasing from -pi/2)
  const int n_lap = steps(2.0 * kPi * rc, params.spacing);
  for (int lap = 0; lap < 4; ++lap) {
    path.lap_start[lap] = pts.size() - 1;
    const double side = lap < 2 ? -1.0 : 1.0;
    const Vec2 centre{0.0, side * rc};
    for (int i = 1; i < n_lap; ++i) {
      const double a = -side * kPi / 2.0 + side * 2.0 * kPi * static_cast<double>(i) / n_lap;
      pts.push_back(centre + rc * unit_from_angle(a));
    }
    pts.push_back(crossing);
  }
  path.exit_start = pts.size() - 1;

  // the exit straight along +x, stopping short of the lane's end
  const double exit_length = params.geometry.exit_end_x - params.exit_stop_distance;
  const int n_exit = steps(exit_length, params.spacing);
  for (int i = 1; i <= n_exit; ++i)
    pts.push_back({exit_length * static_cast<double>(i) / n_exit, 0.0});
  return path;
}

SkidpadPlan plan_skidpad(const std::vector<Cone>& observed_cones, const Pose2& initial_guess,
                         const SkidpadParams& params) {
  SkidpadPlan out;
  out.T_map_template = initial_guess;
  // inputs
  if (const std::string bad = params::validate(params); !bad.empty()) {
    out.reason = "skidpad: " + bad;
    return out;
  }
  if (observed_cones.empty()) {
    out.reason = "skidpad: no cones observed";
    return out;
  }
  for (const Cone& c : observed_cones)
    if (!finite(c.position)) {
      out.reason = "skidpad: an observed cone is not finite";
      return out;
    }

  // the template cones onto the observed ones
  const std::vector<Cone> tmpl = skidpad_template_cones(params.path.geometry);
  std::vector<Vec2> source(tmpl.size()), target(observed_cones.size());
  for (std::size_t i = 0; i < tmpl.size(); ++i) source[i] = tmpl[i].position;
  for (std::size_t i = 0; i < observed_cones.size(); ++i) target[i] = observed_cones[i].position;
  out.alignment = align(source, target, initial_guess, params.gicp);
  const GicpResult& a = out.alignment;
  if (!a.converged) {
    out.reason = "skidpad: alignment failed: " + a.reason;
    return out;
  }
  if (a.inliers < params.min_inliers) {
    out.reason = "skidpad: alignment matched " + std::to_string(a.inliers) +
                 " template cones, fewer than min_inliers = " + std::to_string(params.min_inliers);
    return out;
  }
  if (a.rmse > params.max_rmse) {
    out.reason = "skidpad: alignment RMS distance " + metres(a.rmse) +
                 " is above max_rmse = " + metres(params.max_rmse);
    return out;
  }
  out.T_map_template = a.transform;

  // the path into the map frame, then the reference along it, ending at rest
  out.path = skidpad_path(params.path);
  if (!out.path.ok()) {
    out.reason = "skidpad: " + out.path.reason;
    return out;
  }
  for (Vec2& p : out.path.points) p = out.T_map_template.transform(p);
  ReferenceResult ref =
      build_reference(out.path.points, false, params.reference, std::nullopt, 0.0);
  if (!ref.ok()) {
    out.reason = "skidpad: " + ref.reason;
    return out;
  }
  out.trajectory = std::move(ref.trajectory);
  return out;
}

}  // namespace paddock::planning
