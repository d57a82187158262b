#include "sim/runner/reports.h"

#include <cmath>
#include <limits>
#include <array>
#include <sstream>

#include "autonomy/common/format.h"
#include "autonomy/common/polyline.h"
#include "autonomy/planning/path_planner.h"
#include "sim/runner/files.h"
#include "sim/runner/scenario.h"
#include "sim/runner/simulation.h"
#include "sim/world/track.h"

namespace paddock::runner {
namespace {

struct Stats {
  double max = 0.0, mean = 0.0, std = 0.0;
};

Stats stats_of(const std::vector<double>& v) {
  Stats s;
  if (v.empty()) return s;
  double sum = 0.0, sum2 = 0.0;
  for (double x : v) {
    s.max = std::max(s.max, x);
    sum += x;
    sum2 += x * x;
  }
  const double n = static_cast<double>(v.size());
  s.mean = sum / n;
  s.std = std::sqrt(std::max(0.0, sum2 / n - s.mean * s.mean));
  return s;
}

}  // namespace

std::string report_controllers(const std::string& scenario_path, const std::vector<std::string>& overrides) {
  struct Row {
    const char* name;
    const char* key;
    double paper_itae, paper_rms, paper_max, paper_lap;
  };
  // the paper's Table I (FSG 2023, simulation)
  const Row rows[] = {{"Combined", "combined", 143.0, 0.201, 0.645, 40.772},
                      {"Stanley", "stanley", 50.0, 0.075, 0.244, 41.730},
                      {"Pure pursuit", "pure_pursuit", 273.0, 0.374, 1.047, 41.248}};
  std::ostringstream o;
  std::string name;
  o << "| controller | ITAE | RMS [m] | max lateral error [m] | lap time [s] | finished, DOO, OC | paper: ITAE / RMS / max / lap |\n";
  o << "|---|---|---|---|---|---|---|\n";
  for (const Row& row : rows) {
    std::vector<std::string> with_controller = overrides;
    with_controller.push_back(std::string("control.lateral=") + row.key);
    const Scenario scenario = load_scenario(scenario_path, with_controller);
    name = scenario.name;
    const world::TrackModel track = world::build_track(load_track_file(scenario.track_path));
    const RunResult r = run(scenario, track);
    // the mean lap, leaving out a standing-start first lap when there are more
    const auto& laps = r.event.laps;
    double lap = 0.0;
    std::size_t first = laps.size() > 1 ? 1 : 0, n = 0;
    for (std::size_t i = first; i < laps.size(); ++i, ++n) lap += laps[i].time;
    lap = n > 0 ? lap / static_cast<double>(n) : 0.0;
    o << "| " << row.name << " | " << fixed(r.tracking.itae, 1) << " | " << fixed(r.tracking.rms, 3) << " | "
      << fixed(r.tracking.max, 3) << " | " << fixed(lap, 3) << " | " << (r.event.finished ? "yes" : "no") << ", "
      << r.event.doo << ", " << r.event.oc << " | " << fixed(row.paper_itae, 1) << " / " << fixed(row.paper_rms, 3)
      << " / " << fixed(row.paper_max, 3) << " / " << fixed(row.paper_lap, 3) << " |\n";
  }
  return "Table I, lateral controllers: " + name + " (ITAE and errors per lap, averaged over the laps)\n\n" + o.str();
}

std::string report_smoothing(const std::string& track_path) {
  const world::TrackModel track = world::build_track(load_track_file(track_path));
  if (!track.closed) throw UserError(track_path + ": the smoothing report needs a circuit (a closed track)");
  planning::PathPlannerParams params;
  params.clearance.clearance = 0.0;  // the smoothing alone, as the paper compares it
  // the paper's planned limits: constant, 0.8 g, 20 m/s at most (the
  // stack's default plans with the car's envelope instead)
  params.reference.profile.limits = planning::VelocityProfileParams::Constant;
  params.reference.profile.v_max = 20.0;
  // the full lap's raw centreline: the search on the ground-truth cones from the start pose
  const planning::PlanResult lap = planning::plan_path(track.cones, track.start, 0.0, params);
  if (!lap.ok() || !lap.closed) {
    throw UserError(track_path + ": the centreline search did not close the lap: " +
                    (lap.reason.empty() ? "it stopped early" : lap.reason));
  }
  struct Method {
    const char* name;
    planning::SmoothingParams::Method method;
    double paper[8];  // lap, ay max/mean/std, CVR max/mean/std, min distance
  };
  const Method methods[] = {
      {"Raw", planning::SmoothingParams::Raw, {58.579, 40.138, 2.980, 3.839, 4.185, 0.398, 0.496, 1.547}},
      {"Moving avg.", planning::SmoothingParams::MovingAverage, {39.014, 12.325, 1.660, 1.556, 1.263, 0.036, 0.086, 1.227}},
      {"Opheim", planning::SmoothingParams::Opheim, {41.161, 11.115, 1.674, 1.590, 1.309, 0.113, 0.136, 1.349}},
      {"Combined", planning::SmoothingParams::Combined, {38.438, 13.502, 1.562, 1.419, 0.079, 0.002, 0.003, 1.261}},
  };
  std::vector<std::array<double, 8>> ours;
  for (const Method& m : methods) {
    planning::SmoothingParams sp = params.smoothing;
    sp.method = m.method;
    const std::vector<Vec2> smooth = planning::smooth_centreline(lap.search.points, true, sp);
    const planning::ReferenceResult ref = planning::build_reference(smooth, true, params.reference);
    if (!ref.ok()) throw UserError(track_path + ": " + m.name + ": " + ref.reason);
    const Trajectory& t = ref.trajectory;
    // lateral acceleration at a constant 5 m/s: v^2 |kappa|; CVR: |dkappa/ds| between samples
    std::vector<double> ay, cvr;
    double min_boundary = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < t.points.size(); ++i) {
      const TrajectoryPoint& a = t.points[i];
      const TrajectoryPoint& b = t.points[(i + 1) % t.points.size()];
      ay.push_back(25.0 * std::abs(a.curvature));
      const double ds = t.length / static_cast<double>(t.points.size());
      cvr.push_back(std::abs(b.curvature - a.curvature) / ds);
      min_boundary = std::min({min_boundary, polyline_distance(track.left, true, a.position()),
                               polyline_distance(track.right, true, a.position())});
    }
    const Stats lateral = stats_of(ay), curvature_rate = stats_of(cvr);
    ours.push_back({planning::lap_time(t), lateral.max, lateral.mean, lateral.std, curvature_rate.max, curvature_rate.mean,
                    curvature_rate.std, min_boundary});
  }
  const char* rows[] = {"Lap time [s]",         "Max lat. acc [m/s^2]", "Mean lat. acc [m/s^2]",
                        "Std lat. acc [m/s^2]", "Max CVR [1/m^2]",      "Mean CVR [1/m^2]",
                        "Std CVR [1/m^2]",      "Min dist. to bound [m]"};
  const int decimals[] = {3, 3, 3, 3, 3, 3, 3, 3};
  std::ostringstream o;
  o << "Table II, smoothing: " << track.name << " (ours / paper)\n\n| | Raw | Moving Avg. | Opheim | Combined |\n|---|---|---|---|---|\n";
  for (int r = 0; r < 8; ++r) {
    o << "| " << rows[r];
    for (std::size_t m = 0; m < 4; ++m) {
      o << " | " << fixed(ours[m][static_cast<std::size_t>(r)], decimals[r]) << " / " << fixed(methods[m].paper[r], decimals[r]);
    }
    o << " |\n";
  }
  return o.str();
}

}  // namespace paddock::runner
