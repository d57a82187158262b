#pragma once
// `paddock report vehicle CAR.ini`: what a vehicle-dynamics engineer looks at
// first for a car, measured by driving the simulated car itself. Every figure
// is a closed-loop experiment through vehicle::step at 1 ms, starting from
// vehicle::initial_state or vehicle::rolling_state and reading only the
// state's pose, velocities and accelerations: nothing is taken from the
// model's insides, so the report holds for any model behind that API.
#include <string>
#include <vector>

#include "autonomy/planning/velocity_profile.h"
#include "render/figures.h"
#include "sim/vehicle/vehicle.h"

namespace paddock::runner {

struct PlotOptions;  // plots.h

// the FS acceleration event's length, m
inline constexpr double kAccelerationLength = 75.0;
// the speed braked from, m/s (100 km/h)
inline constexpr double kBrakingSpeed = 100.0 / 3.6;
// the FS skidpad's centreline radius, m: inner diameter 15.25 m, plus half the 3 m lane
inline constexpr double kSkidpadRadius = 15.25 / 2.0 + 1.5;

// full throttle from rest, steering 0: the 75 m time and the top speed
struct AccelerationRun {
  bool reached_75m = false;     // the CG travelled 75 m within the run (120 s at most)
  double time_75m = 0.0;        // s
  double speed_75m = 0.0;       // m/s
  double top_speed = 0.0;       // m/s: when it changed by < 0.01 m/s over 1 s (or at 120 s)
  double top_speed_time = 0.0;  // s, when it was judged
  bool top_speed_settled = false;  // false: still changing at 120 s
};

// a straight stop from a speed at one constant brake pedal
struct BrakingRun {
  double pedal = 1.0;
  bool stopped = false;            // false: still rolling after 60 s
  double distance = 0.0;           // m, travelled by the CG until at rest (< 0.05 m/s)
  double time = 0.0;               // s
  double mean_deceleration = 0.0;  // m/s^2, v0^2 / (2 distance): the constant deceleration that stops as short
};

// the fastest steady lap of the skidpad circle
struct SkidpadRun {
  bool held = false;             // the circle is held at the slowest speed tried
  double speed = 0.0;            // m/s, the highest speed it is held at (within 0.25 m for 10 s)
  double lap_time = 0.0;         // s, 2 pi R / speed
  double lateral = 0.0;          // m/s^2, speed^2 / R
  double radius_error_max = 0.0; // m, the largest |distance to the centre - R| in the 10 s at that speed
};

// one speed of the g-g-v envelope (accelerations as magnitudes)
struct GgvRow {
  double speed = 0.0;            // m/s
  double lateral = 0.0;          // m/s^2, the largest steady acceleration normal to the path
  std::string lateral_limit;     // what bounds it: "grip", "spin", "steering lock" or "power"
  double acceleration = 0.0;     // m/s^2, full throttle: mean ax over 0.1-0.3 s
  double braking = 0.0;          // m/s^2, the best constant pedal: mean -ax over 0.1-0.3 s
  double braking_pedal = 1.0;    // that pedal
};

struct VehicleReport {
  std::string source;            // the vehicle file
  AccelerationRun acceleration;
  BrakingRun full_brake, best_brake;  // from kBrakingSpeed
  SkidpadRun skidpad;
  std::vector<GgvRow> ggv;       // 5 m/s to the top speed (100 m/s at most) in 5 m/s steps
  double simulated_time = 0.0;   // s, every experiment together
};

// runs every experiment on the car; throws UserError when the model's state
// stops being finite (a car the 1 ms step cannot integrate)
VehicleReport vehicle_report(const vehicle::VehicleParams& p, const std::string& source);

// the g-g-v alone (what `paddock report limit` needs): the top speed, then
// the rows as vehicle_report measures them
struct GgvMeasurement {
  double top_speed = 0.0;        // m/s
  std::vector<GgvRow> rows;
  double simulated_time = 0.0;   // s
};
GgvMeasurement measure_ggv(const vehicle::VehicleParams& p);

// the measured g-g-v as the velocity profile's envelope (limits = ggv,
// margins 1, turn_accel_scale 1, v_max the top speed): a node at rest (the
// first row's acceleration and braking), one per row, and one at the top
// speed with no acceleration left. Rows whose lateral limit is the steering
// lock take the grip line a + b v^2 fitted to the grip-limited rows (the
// lock bounds the path's curvature, not the speed on it).
planning::VelocityProfileParams ggv_envelope(const std::vector<GgvRow>& rows, double top_speed);
// the envelope as the lines of a scenario's [planning.reference.profile]
std::string ggv_ini(const planning::VelocityProfileParams& envelope);

// the readable table `paddock report vehicle` prints
std::string vehicle_report_text(const VehicleReport& r);
// vehicle_report.json: one object, SI units plus the same in g and km/h; a
// figure not measured (75 m not reached, the circle not held, no stop) is null
std::string vehicle_report_json(const VehicleReport& r);
// the g-g-v envelope: max lateral, acceleration and braking (g) against speed
render::LineChartData ggv_chart(const VehicleReport& r);

// writes DIR/vehicle_report.json and DIR/ggv.png (chart_width x chart_height,
// atomically); returns their paths
std::vector<std::string> write_vehicle_report(const VehicleReport& r, const std::string& dir, const PlotOptions& o);

}  // namespace paddock::runner
