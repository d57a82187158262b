#pragma once
// `paddock report limit SCENARIO.ini`: the fastest flying lap the scenario's
// car can drive on its track, a reference every run is held against. The
// car's g-g-v envelope is measured on the vehicle model itself
// (measure_ggv, the vehicle report's experiments), then a quasi-steady-state
// (QSS) forward-backward profile (planning::solve_velocity_profile with
// limits = ggv, no margin) is solved on two lines: the track's centreline,
// and the minimum-curvature line that keeps the car's centre `clearance`
// from the boundary lines (planning::min_curvature_line). Only circuits
// (trackdrive, autocross) have a lap.
#include <string>
#include <vector>

#include "autonomy/common/trajectory.h"
#include "autonomy/planning/racing_line.h"
#include "autonomy/planning/velocity_profile.h"
#include "sim/runner/vehicle_report.h"
#include "sim/world/track.h"

namespace paddock::runner {

struct PlotOptions;  // plots.h

// the clearance of the report's reference line (m): the racing line's own default
inline constexpr double kLimitClearance = planning::RacingLineParams{}.clearance;

// one line and its QSS profile
struct LimitLine {
  std::string name;                 // "centreline" or "min_curvature"
  Trajectory trajectory;            // samples every 0.5 m with curvature and the QSS speed
  double lap_time = 0.0;            // s, flying lap
  double v_min = 0.0, v_max = 0.0;  // m/s
  double clearance_min = 0.0;       // m, least distance from a sample to the boundary lines
  double curvature_max = 0.0;       // 1/m, largest |kappa|
};

// the two lines on one track with one envelope
struct LimitLines {
  double clearance = kLimitClearance;
  LimitLine centreline, min_curvature;
  double cost_centreline = 0.0, cost_min_curvature = 0.0;  // sum kappa^2 ds of the optimised points' reference and result
  int iterations = 0;
};

// the lines of a circuit; throws UserError when the track is not a circuit or
// a line cannot be built (naming the track and why)
LimitLines limit_lines(const world::TrackModel& track, const planning::VelocityProfileParams& envelope,
                       double clearance = kLimitClearance);

// the car's envelope as the QSS uses it: measure_ggv, then ggv_envelope
planning::VelocityProfileParams car_envelope(const vehicle::VehicleParams& car, GgvMeasurement* measured = nullptr);
// the same, kept on disk between runs (cache_dir(), files.h): read when this
// program measured this car before (the same build ID and every parameter
// the same), else measured and kept. The same numbers either way
planning::VelocityProfileParams kept_car_envelope(const vehicle::VehicleParams& car);
// the same, once per process and car (params::fingerprint of its
// parameters): the points of a sweep in one process share their car's
// (~1 s of CPU each on the default car when not kept on disk). Thread-safe;
// a second caller for a car being measured waits for that measurement; an
// exception is rethrown to every caller
planning::VelocityProfileParams shared_car_envelope(const vehicle::VehicleParams& car);

struct LimitReport {
  std::string scenario;                    // the scenario file
  std::string track;                       // the track's name
  double track_length = 0.0;               // m, centreline
  GgvMeasurement ggv;
  planning::VelocityProfileParams envelope;
  double steering_curvature = 0.0;         // 1/m: tan(steering_max) / wheelbase, the tightest the car can turn
  LimitLines lines;
};

// the report for a loaded scenario's car and track
LimitReport limit_report(const vehicle::VehicleParams& car, const world::TrackModel& track,
                         const std::string& scenario, double clearance = kLimitClearance);

std::string limit_report_text(const LimitReport& r);
std::string limit_report_json(const LimitReport& r);
// the samples of both lines: line,s,x,y,heading,curvature,speed (SI units,
// closed lines: the step from the last sample back to the first closes the lap)
std::string limit_lines_csv(const LimitLines& lines);
// writes DIR/limit_report.json, DIR/limit_lines.csv and DIR/limit.png (the
// racing line coloured by its QSS speed over the track, the centreline in
// grey); returns their paths
std::vector<std::string> write_limit_report(const LimitReport& r, const world::TrackModel& track, const std::string& dir,
                                            const PlotOptions& o);

}  // namespace paddock::runner
