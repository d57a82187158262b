#include "autonomy/planning/path_planner.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>

#include "autonomy/common/line_fit.h"
#include "autonomy/common/polyline.h"

namespace paddock::planning {

namespace {

// points closer than this are one point when the vehicle's position is put
// in front of the centreline (m)
constexpr double kSamePoint = 1e-3;

// the steps every planner shares: parameters, input, triangulation, search.
// False (with out's status and reason set) when there is no centreline.
bool triangulate_and_search(const std::vector<Cone>& cone_map, const Pose2& vehicle, double speed,
                            const PathPlannerParams& params, PlanResult& out) {
  if (const std::string bad = params::validate(params); !bad.empty()) {
    out.status = PlanStatus::BadParams;
    out.reason = "planner: " + bad;
    return false;
  }
  if (!finite(vehicle) || std::isnan(speed)) {
    out.status = PlanStatus::BadInput;
    out.reason = "planner: the vehicle's pose or speed is not finite";
    return false;
  }
  // the triangulation, then the search on it
  out.triangulation = triangulate(cone_map);
  if (!out.triangulation.ok()) {
    out.status = PlanStatus::NoTriangulation;
    out.reason = "planner: " + out.triangulation.reason;
    return false;
  }
  out.search = search_centreline(out.triangulation, cone_map, vehicle, params.search);
  if (!out.search.ok()) {
    out.status = PlanStatus::NoCentreline;
    out.reason = "planner: " + out.search.reason;
    return false;
  }
  return true;
}

// the boundaries of a path (a closed lap, or an open path ahead): every
// mapped cone within kBoundaryReach of its centreline, on the side of it
// where it lies, in the order of its projection along the path (the cones
// the path passes: the nearest part of the path claims a cone, so a
// neighbouring leg's cones are not this one's); and both cones of every
// edge of the triangulation the path crosses, however far from it they
// stand. A path that cuts the fan of rungs round a tight apex (a long step
// of the search across them, then smoothed) passes the fan's outer cones
// more than kBoundaryReach away, yet it crosses the track they bound: left
// out, the racing line had no outer boundary there and was held to the
// chord (FSG 2019 autocross, the 90-degree left at (-5, -20): a kink of
// 0.5 1/m in the first lap, on every seed)
constexpr double kBoundaryReach = 3.5;  // m: half the widest FS track and a cone's offset

// a and b strictly on opposite sides of the line through c-d, and c and d of a-b's
bool segments_cross(Vec2 a, Vec2 b, Vec2 c, Vec2 d) {
  const double d1 = cross(b - a, c - a), d2 = cross(b - a, d - a);
  const double d3 = cross(d - c, a - c), d4 = cross(d - c, b - c);
  return ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0)) && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0));
}

void path_boundaries(const std::vector<Vec2>& path, bool closed, const std::vector<Cone>& cones,
                     const Triangulation& tri, std::vector<Vec2>& left, std::vector<Vec2>& right) {
  if (path.size() < 2) return;  // no path, nothing it passes
  std::vector<Projection> on(cones.size());
  std::vector<char> taken(cones.size(), 0);
  for (std::size_t i = 0; i < cones.size(); ++i) {
    // a doubled cone once (the triangulation merged it), a non-finite one never
    if (i >= tri.representative.size() || tri.representative[i] != i) continue;
    on[i] = project(path, closed, cones[i].position);
    taken[i] = on[i].distance <= kBoundaryReach;
  }
  // an edge with a cone beyond the reach, its cones either side of the path:
  // a candidate, crossed if one of the path's segments crosses it
  const std::size_t n = path.size(), segments = closed ? n : n - 1;
  for (const TriEdge& e : tri.edges) {
    if (e.a >= cones.size() || e.b >= cones.size() || e.a >= tri.representative.size() ||
        e.b >= tri.representative.size() || (taken[e.a] && taken[e.b]))
      continue;
    if (tri.representative[e.a] != e.a || tri.representative[e.b] != e.b) continue;
    if ((on[e.a].signed_offset > 0.0) == (on[e.b].signed_offset > 0.0)) continue;
    const Vec2 a = cones[e.a].position, b = cones[e.b].position;
    for (std::size_t k = 0; k < segments; ++k) {
      if (segments_cross(path[k], path[(k + 1) % n], a, b)) {
        taken[e.a] = taken[e.b] = 1;
        break;
      }
    }
  }
  std::vector<std::pair<double, Vec2>> l, r;
  for (std::size_t i = 0; i < cones.size(); ++i) {
    if (!taken[i]) continue;
    (on[i].signed_offset > 0.0 ? l : r).push_back({on[i].s, cones[i].position});
  }
  const auto by_s = [](const auto& a, const auto& b) { return a.first < b.first; };
  std::stable_sort(l.begin(), l.end(), by_s);
  std::stable_sort(r.begin(), r.end(), by_s);
  for (const auto& [s, q] : l) left.push_back(q);
  for (const auto& [s, q] : r) right.push_back(q);
}

// the minimum-curvature line along out.smoothed (closed as out is) inside
// the boundaries of the cones along it, as a trajectory with `reference`'s
// profile: its points in out.racing_line and its boundaries in out, or
// nothing, with out.racing_fallback saying why. An open line is held at the
// car (leaving along start_heading) and at the end of the seen track
std::optional<Trajectory> racing_trajectory(PlanResult& out, const std::vector<Cone>& cones,
                                            const PathPlannerParams& params, const ReferenceParams& reference,
                                            std::optional<double> v_start = std::nullopt,
                                            std::optional<double> v_end = std::nullopt,
                                            std::optional<double> start_heading = std::nullopt) {
  path_boundaries(out.smoothed, out.closed, cones, out.triangulation, out.left_boundary, out.right_boundary);
  const RacingLine line = min_curvature_line(out.smoothed, out.left_boundary, out.right_boundary, out.closed,
                                             params.racing, !out.closed, start_heading);
  if (!line.ok()) {
    out.racing_fallback = line.reason;
    return std::nullopt;
  }
  const SplineFit fit = fit_spline(line.points, out.closed);
  if (!fit.ok()) {
    out.racing_fallback = "racing line: " + fit.reason;
    return std::nullopt;
  }
  ReferenceResult racing = reference_from_spline(fit.spline, reference, v_start, v_end);
  if (!racing.ok()) {
    out.racing_fallback = "racing line: " + racing.reason;
    return std::nullopt;
  }
  out.racing_line = line.points;
  return std::move(racing.trajectory);
}

}  // namespace

bool plan_racing_line(PlanResult& out, const std::vector<Cone>& cones, const PathPlannerParams& params) {
  out.racing_line.clear();
  out.left_boundary.clear();
  out.right_boundary.clear();
  out.racing_fallback.clear();
  if (!out.ok() || !out.closed) {
    out.racing_fallback = "racing line: not a planned lap";
    return false;
  }
  std::optional<Trajectory> racing = racing_trajectory(out, cones, params, params.reference);
  if (!racing) return false;
  out.trajectory = std::move(*racing);
  return true;
}

bool plan_locked_lap(PlanResult& lap, const std::vector<Cone>& cones, const PathPlannerParams& params) {
  if (params.line == PathPlannerParams::MinCurvature && plan_racing_line(lap, cones, params)) return true;
  if (!lap.ok() || !lap.closed) return false;
  ReferenceResult ref = build_reference(lap.smoothed, true, params.reference);
  if (ref.ok()) lap.trajectory = std::move(ref.trajectory);
  return params.line == PathPlannerParams::Centreline && ref.ok();
}

namespace {

// the end every planner shares: the reference's trajectory and Ok, or
// NoReference with the reference's reason
PlanResult with_reference(PlanResult out, ReferenceResult ref) {
  if (!ref.ok()) {
    out.status = PlanStatus::NoReference;
    out.reason = "planner: " + ref.reason;
    return out;
  }
  out.trajectory = std::move(ref.trajectory);
  out.status = PlanStatus::Ok;
  return out;
}

}  // namespace

const char* to_string(PlanStatus s) {
  switch (s) {
    case PlanStatus::Ok: return "ok";
    case PlanStatus::BadParams: return "bad parameters";
    case PlanStatus::BadInput: return "bad input";
    case PlanStatus::NoTriangulation: return "no triangulation";
    case PlanStatus::NoCentreline: return "no centreline";
    case PlanStatus::NoReference: return "no reference";
  }
  return "?";
}

PlanResult plan_path(const std::vector<Cone>& cone_map, const Pose2& vehicle, double speed,
                     const PathPlannerParams& params, bool lap) {
  PlanResult out;
  if (!triangulate_and_search(cone_map, vehicle, speed, params, out)) return out;

  // the raw centreline: a lap as found, an open path from the vehicle on
  out.closed = out.search.closed && lap;
  const Vec2 car = vehicle.position();
  if (out.search.closed && !out.closed) {
    // a lap not wanted as one: the open path along it from the vehicle, once
    // around, ending before it comes back to the vehicle (its last points,
    // within a search radius of the car, would overlap its beginning)
    const std::vector<Vec2>& ring = out.search.points;
    const std::size_t n = ring.size();
    const std::size_t first = (project(ring, true, car).segment + 1) % n;
    std::vector<Vec2> ahead;
    for (std::size_t k = 0; k < n; ++k) ahead.push_back(ring[(first + k) % n]);
    while (ahead.size() > 2 && distance(ahead.back(), car) < params.search.search_radius) ahead.pop_back();
    if (distance(car, ahead.front()) > kSamePoint) out.centreline.push_back(car);
    out.centreline.insert(out.centreline.end(), ahead.begin(), ahead.end());
  } else {
    if (!out.closed && distance(car, out.search.points.front()) > kSamePoint) out.centreline.push_back(car);
    out.centreline.insert(out.centreline.end(), out.search.points.begin(), out.search.points.end());
  }
  // a lap closes where it began: points at its end that overlap its first
  // step (past the first point, or on it) would fold the closed spline into
  // a cusp at the join
  if (out.closed) {
    std::vector<Vec2>& c = out.centreline;
    while (c.size() > 4 &&
           (distance(c.back(), c.front()) < 1.0 || dot(c.back() - c.front(), c[1] - c[0]) > 0.0)) {
      c.pop_back();
    }
  }

  // smoothing, then the spline and the velocity profile: an open path ends
  // at rest, where the seen track ends
  out.smoothed = smooth_centreline(out.centreline, out.closed, params.smoothing);
  enforce_clearance(out.smoothed, cone_map, params.clearance);
  const std::optional<double> v_start =
      out.closed ? std::nullopt : std::optional<double>(std::max(0.0, speed));
  const std::optional<double> v_end = out.closed ? std::nullopt : std::optional<double>(0.0);
  // every path planned here explores: with the envelope, at its own margins
  ReferenceParams reference = params.reference;
  if (reference.profile.limits == VelocityProfileParams::Ggv) {
    reference.profile.margin_lateral = params.explore_margin_lateral;
    reference.profile.margin_longitudinal = params.explore_margin_longitudinal;
  }
  // an open path with line = min_curvature: the racing line as far as the
  // map is known, from the car (its offset held at 0, leaving along the
  // car's heading) to where the seen track ends (back on the centreline
  // there); the centreline when it fails
  if (!out.closed && params.line == PathPlannerParams::MinCurvature) {
    std::optional<Trajectory> racing = racing_trajectory(out, cone_map, params, reference, v_start, v_end, vehicle.yaw);
    if (racing) return with_reference(std::move(out), ReferenceResult{std::move(*racing), ""});
  }
  ReferenceResult ref = build_reference(out.smoothed, out.closed, reference, v_start, v_end);
  // the spline can swing back towards a cone between the points: push the
  // points near such samples further and fit again (a few rounds)
  for (int round = 0; round < 3 && ref.ok(); ++round) {
    if (clear_trajectory(out.smoothed, ref.trajectory, cone_map, params.clearance) == 0) break;
    ref = build_reference(out.smoothed, out.closed, reference, v_start, v_end);
  }
  return with_reference(std::move(out), std::move(ref));
}

PlanResult plan_acceleration(const std::vector<Cone>& cone_map, const Pose2& vehicle,
                             double speed, const PathPlannerParams& params,
                             std::optional<double> length) {
  PlanResult out;
  if (length && !(std::isfinite(*length) && *length > 0.0)) {
    out.status = PlanStatus::BadInput;
    out.reason = "planner: the acceleration length must be a positive length (m)";
    return out;
  }
  if (!triangulate_and_search(cone_map, vehicle, speed, params, out)) return out;
  out.closed = false;
  out.centreline = out.search.points;

  // the line through the centreline points, pointing the way the car heads
  const LineFit line = fit_line(out.search.points);
  if (!line.ok()) {
    out.status = PlanStatus::NoCentreline;
    out.reason = "planner: " + line.reason;
    return out;
  }
  Vec2 dir = line.direction;
  if (dot(dir, vehicle.heading()) < 0.0) dir = -dir;
  // from the car's projection onto the line, to the farthest point or `length`
  const Vec2 start = line.point + dir * dot(vehicle.position() - line.point, dir);
  double far = 0.0;
  for (const Vec2& p : out.search.points) far = std::max(far, dot(p - start, dir));
  const double run = length.value_or(far);
  if (!(run > params.reference.ds)) {
    out.status = PlanStatus::NoCentreline;
    out.reason = "planner: the centreline ends behind the vehicle";
    return out;
  }
  out.smoothed = {start, start + dir * run};
  ReferenceResult ref =
      build_reference(out.smoothed, false, params.reference, std::max(0.0, speed), 0.0);
  return with_reference(std::move(out), std::move(ref));
}

}  // namespace paddock::planning
