#pragma once
// the velocity profile: the forward-backward solver with a friction ellipse
// (paper section "Planning", after TUM trajectory_planning_helpers'
// calc_vel_profile v0.80, written anew here).
#include <optional>
#include <string>
#include <vector>

#include "autonomy/common/params.h"

namespace paddock::planning {

// the car's g-g limits and longitudinal model for the profile. The defaults
// are the AMZ "gotthard" car (m = 190 kg, tyre mu ~1.6, aero drag
// F = 0.7 v^2 N, motors 5000 N at the wheels), planned a little inside its
// limits so that the controller keeps a margin.
struct VelocityProfileParams {
  // the limits the stack plans with, not the tyres' own: the gotthard car's
  // tyres carry mu g = 1.6 * 9.81 = 15.7 m/s^2 (more with downforce), and a
  // driverless stack keeps about half of that in reserve for tracking,
  // localisation and perception errors, as the paper's car did (41 s laps on
  // FSG 2023). With these limits the car laps FSG 2023 in about 35 s.
  // 0.8 g
  double ax_max = 8.0;
  // 0.8 g, about half the tyres' grip
  double ay_max = 8.0;
  // 0.8 g
  double ax_brake_max = 8.0;
  // the g-g shape (ax/ax_max)^p + (ay/ay_max)^p <= 1: 2 is the friction
  // ellipse, 1 a diamond (conservative); any p >= 1 is a convex shape (the
  // reference recommends [1, 2]).
  double exponent = 2.0;
  // constant in speed: 5000 N / 190 kg = 26.3 m/s^2 is more than the tyres
  // can transmit, so it is capped at the traction limit mu g = 1.6 * 9.81 =
  // 15.7 m/s^2; with ax_max = 8 the planned limit is what shapes the launch.
  double ax_machine = 15.7;
  // vehicle mass (kg), used only to turn drag force into deceleration. Not
  // visited: the runner fills it from the vehicle ([vehicle] mass); check()
  // checks it
  double mass = 190.0;
  // aerodynamic drag F = c_d v^2 (N s^2/m^2): it slows the car when
  // accelerating and helps it when braking. Not visited: the runner fills it
  // from the vehicle ([vehicle] c_drag); check() checks it
  double drag_coefficient = 0.7;
  // 72 km/h, about what FS trackdrive straights allow at the constant
  // limits; with limits = ggv set it above the car's top speed (34.3 m/s
  // for the default car), where the envelope has no acceleration left
  double v_max = 20.0;
  // the paper's "reduced acceleration limits in turns" (1 = off). The tyre
  // limits ax_max and ax_brake_max are scaled by
  //   f = 1 - (1 - turn_accel_scale) * min(1, ay / ay_max),   ay = v^2 |kappa|,
  // before the friction ellipse is applied: on a straight f = 1, and the more
  // of the lateral grip a turn uses, the less of the longitudinal limit is
  // assumed available (a more conservative g-g shape in combined slip, where
  // real tyres and a tracking controller fall short of the ideal ellipse).
  // Default 0.4: in a turn at the lateral limit, 40 % of the straight-line
  // acceleration and braking is planned (0.5 before the car's tyres shared
  // their grip between drive and cornering: with combined slip a hairpin
  // exit at half the straight-line acceleration slid wide enough to hit
  // cones).
  double turn_accel_scale = 0.4;

  // where the limits come from: `constant` = ax_max, ay_max, ax_brake_max,
  // ax_machine and the drag term above (the paper's and the reference's
  // model, ORACLES A-D3); `ggv` = the car's g-g-v envelope below, scaled by
  // the two margins, in their place.
  enum Limits { Constant, Ggv };
  static constexpr params::Choice<Limits> kLimitsNames[] = {{"constant", Constant}, {"ggv", Ggv}};
  Limits limits = Constant;
  // the car's g-g-v envelope (limits = ggv), what a team measures of its own
  // car on track: at speed ggv_speed[i] it corners at up to ggv_lateral[i]
  // and accelerates at ggv_accel[i] and brakes at ggv_brake[i] on a level
  // straight, net (drag, rolling resistance and the motors' power limit
  // included, so no drag term is added); linear in between, the end values
  // held beyond the ends. `paddock report vehicle` measures it on the
  // simulated car and prints these four lines. Each combines with the
  // others through the g-g shape (exponent) and turn_accel_scale as the
  // constant limits do. The defaults are the default car's
  // (scenarios/vehicles/default.ini) as `paddock report vehicle` prints them.
  std::vector<double> ggv_speed = {0.0, 5.0, 10.0, 15.0, 20.0, 25.0, 30.0, 34.26};
  std::vector<double> ggv_lateral = {16.61, 16.67, 16.84, 17.08, 17.52, 18.04, 18.58, 18.58};
  std::vector<double> ggv_accel = {14.60, 14.60, 14.57, 14.29, 11.18, 8.78, 6.45, 0.0};
  std::vector<double> ggv_brake = {14.40, 14.40, 14.73, 15.39, 16.29, 17.55, 19.01, 19.01};
  // the shares of the envelope planned with (limits = ggv): the rest is the
  // reserve for tracking, localisation and perception errors. 0.75 each is
  // safe with the combined law; scenarios/racing.ini plans with 0.95 and 0.75
  // and the Stanley law, as `paddock tune scenarios/tunes/racing.ini` chose
  // over three trackdrives (a car loses its line under braking and drive in
  // a turn sooner than in the turn alone)
  double margin_lateral = 0.75;
  double margin_longitudinal = 0.75;

  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(ax_max), {"m/s^2", params::in(0.1, 100.0), "tyre acceleration limit of the profile"});
    v(PADDOCK_PARAM(ay_max), {"m/s^2", params::in(0.1, 100.0), "tyre lateral limit of the profile"});
    v(PADDOCK_PARAM(ax_brake_max), {"m/s^2", params::in(0.1, 100.0), "tyre deceleration limit of the profile"});
    v(PADDOCK_PARAM(exponent), {"", params::in(1.0, 10.0), "g-g diagram exponent p"});
    v(PADDOCK_PARAM(ax_machine), {"m/s^2", params::in(0.1, 100.0), "motor acceleration limit"});
    v(PADDOCK_PARAM(v_max), {"m/s", params::in(0.1, 100.0), "top speed of the profile"});
    v(PADDOCK_PARAM(turn_accel_scale), {"", params::fraction(), "longitudinal limits kept in a full-grip turn"});
    v(PADDOCK_PARAM(limits), kLimitsNames, "constant: the limits above; ggv: the car's g-g-v envelope below");
    v(PADDOCK_PARAM(ggv_speed), {"m/s", params::at_least(0.0), "g-g-v envelope: speeds, ascending"});
    v(PADDOCK_PARAM(ggv_lateral), {"m/s^2", params::above(0.0), "g-g-v envelope: lateral limit at each speed"});
    v(PADDOCK_PARAM(ggv_accel), {"m/s^2", params::at_least(0.0), "g-g-v envelope: net straight-line acceleration"});
    v(PADDOCK_PARAM(ggv_brake), {"m/s^2", params::above(0.0), "g-g-v envelope: net straight-line braking"});
    v(PADDOCK_PARAM(margin_lateral), {"", params::above_up_to(0.0, 1.0), "share of the envelope's lateral limit planned with"});
    v(PADDOCK_PARAM(margin_longitudinal), {"", params::above_up_to(0.0, 1.0), "share of the envelope's acceleration and braking planned with"});
  }
  std::string check() const;
};

// speeds along a path; `reason` says why it failed (empty when ok)
struct VelocityProfile {
  std::vector<double> speed;  // m/s, one per input point (empty on failure)
  std::string reason;

  bool ok() const { return reason.empty(); }
};

// the fastest speeds along a path within the car's limits.
//
// The discretisation is the reference's: corner speeds sqrt(ay_max/|kappa|)
// capped at v_max; a forward pass v_i+1^2 = v_i^2 + 2 a ds with a taken at
// point i (tyre limit from the g-g shape at v_i, capped by the machine, minus
// drag c_d v_i^2 / m); a backward pass the same with the braking limit plus
// drag, evaluated at the later point and once more at the earlier one with
// the speed that gives, keeping the smaller. It reproduces the reference's
// figures (ORACLES A-D3) and its profiles wherever the reference is right;
// it differs on purpose where the reference is not:
//  - closed paths: the reference keeps the lap of its backward pass that had
//    no run-in, so a lap starting inside a braking zone loses that braking
//    zone; here both passes go round until the wrap is consistent, and the
//    profile does not depend on where the lap starts;
//  - closed paths with uneven steps: the reference's backward pass takes
//    the length of the step after each point instead of the one before;
//  - the reference only sweeps forward from points where its first guess
//    rises and stops a sweep once it passes v_max, so drag never slows a
//    stretch that starts level (a constant corner after a v_max straight, or
//    a closed straight); here every step is swept.
//
//   curvature        signed curvature at each point (1/m); 0 = straight
//   segment_lengths  distance from point i to point i+1 (m, > 0); a closed
//                    path has one per point (the last closes the loop to
//                    point 0), an open path one fewer than points
//   closed           the path is a lap: solved round the loop so that the
//                    speed at the end of the lap leads into its start
//   v_start, v_end   (open paths only; ignored when closed) upper bounds of
//                    the speed at the first and last point (m/s, negative is
//                    taken as 0); nothing = free
// Errors (empty input, sizes that do not match, NaN or infinite values,
// non-positive segment lengths, bad parameters) come back in `reason`.
VelocityProfile solve_velocity_profile(const std::vector<double>& curvature,
                                       const std::vector<double>& segment_lengths, bool closed,
                                       const VelocityProfileParams& params,
                                       std::optional<double> v_start = std::nullopt,
                                       std::optional<double> v_end = std::nullopt);

// a profile caught up from the car's state: the speeds lowered, from point
// `from` on, to what the car reaches from speed v0 there when it accelerates
// as the solver's forward pass does (within the limits at each point's speed
// and curvature), round the loop when closed, until the car's speed meets the
// profile. A faster lap taking over from a slower one starts this way, so
// that its speed error is closed within the tyres and not by the speed loop
// at full throttle in a turn. Returns how many points were lowered (0 when
// v0 is already at or above the profile at `from`); `speed` is unchanged
// when an input is bad (sizes as for solve_velocity_profile, `from` out of
// range, v0 not finite).
std::size_t catch_up_profile(std::vector<double>& speed, const std::vector<double>& curvature,
                             const std::vector<double>& segment_lengths, bool closed, std::size_t from,
                             double v0, const VelocityProfileParams& params);

// time to drive the profile (s), constant acceleration along each segment:
// t = sum 2 ds_i / (v_i + v_i+1), including the closing segment when closed
// (segment_lengths then has one entry per point). Infinite when the car
// stands still over a segment of non-zero length; NaN for inconsistent sizes.
double profile_time(const std::vector<double>& speed, const std::vector<double>& segment_lengths,
                    bool closed);

// the longitudinal acceleration available at speed v on curvature kappa
// (m/s^2), drag included, as the solver uses it: forward (accelerating,
// >= -drag) or backward (the deceleration magnitude available to brake).
// Exposed for tests that check the profile against the limits.
double available_acceleration(double v, double kappa, const VelocityProfileParams& p);
double available_deceleration(double v, double kappa, const VelocityProfileParams& p);
// the lateral acceleration the profile allows at speed v (m/s^2): ay_max, or
// the envelope's times margin_lateral
double planned_lateral_limit(double v, const VelocityProfileParams& p);

}  // namespace paddock::planning
