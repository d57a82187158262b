#include "autonomy/planning/velocity_profile.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>

namespace paddock::planning {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

bool all_finite(const std::vector<double>& v) {
  return std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); });
}

// linear interpolation in a table, the end values held beyond its ends
double interpolate(const std::vector<double>& xs, const std::vector<double>& ys, double x) {
  if (x <= xs.front()) return ys.front();
  if (x >= xs.back()) return ys.back();
  const std::size_t j = static_cast<std::size_t>(std::upper_bound(xs.begin(), xs.end(), x) - xs.begin());
  const double t = (x - xs[j - 1]) / (xs[j] - xs[j - 1]);
  return ys[j - 1] + t * (ys[j] - ys[j - 1]);
}

bool ggv(const VelocityProfileParams& p) { return p.limits == VelocityProfileParams::Ggv; }


// the longitudinal tyre limit left over by the lateral acceleration: the g-g
// shape (ax/ax_lim)^p + (ay/ay_lim)^p = 1 solved for ax, zero once the turn
// alone uses all the grip; with turn_accel_scale < 1 the limit shrinks with
// the lateral use (see the parameter's comment)
double tyre_longitudinal(double ax_lim, double v, double kappa, const VelocityProfileParams& p) {
  // the share of the lateral limit a speed uses on a curvature, in [0, inf)
  const double use = v * v * std::abs(kappa) / planned_lateral_limit(v, p);
  const double f = 1.0 - (1.0 - p.turn_accel_scale) * std::min(1.0, use);
  // the ellipse (p = 2) and the diamond (p = 1) without pow(), the common cases
  const bool ellipse = p.exponent == 2.0, diamond = p.exponent == 1.0;
  const double radicand = 1.0 - (ellipse ? use * use : diamond ? use : std::pow(use, p.exponent));
  if (!(radicand > 0.0)) return 0.0;
  const double root = ellipse ? std::sqrt(radicand) : diamond ? radicand : std::pow(radicand, 1.0 / p.exponent);
  return f * ax_lim * root;
}

// the g-g-v envelope's net values already carry the drag
double drag_decel(double v, const VelocityProfileParams& p) {
  return ggv(p) ? 0.0 : p.drag_coefficient * v * v / p.mass;
}

// the fastest speed at which a curvature uses no more than the lateral
// limit, v^2 |kappa| <= ay(v): the first crossing from rest, since a limit
// that grows with speed (downforce) could allow a second, faster band the car
// cannot reach through the slower speeds. Infinite on a straight, or when the
// limit outgrows v^2 |kappa| for good.
double corner_speed(double kappa, const VelocityProfileParams& p) {
  const double k = std::abs(kappa);
  if (!(k > 0.0)) return kInf;
  if (!ggv(p)) return std::sqrt(p.ay_max / k);
  const std::vector<double>& s = p.ggv_speed;
  const double m = p.margin_lateral;
  // below the first node the limit is constant
  const double v0 = std::sqrt(m * p.ggv_lateral.front() / k);
  if (v0 <= s.front()) return v0;
  // on a segment the limit is a0 + a1 v: the root of k v^2 - a1 v - a0 = 0
  for (std::size_t j = 0; j + 1 < s.size(); ++j) {
    const double l0 = m * p.ggv_lateral[j], l1 = m * p.ggv_lateral[j + 1];
    if (s[j + 1] * s[j + 1] * k <= l1) continue;  // still within the limit at the segment's end
    const double a1 = (l1 - l0) / (s[j + 1] - s[j]);
    const double a0 = l0 - a1 * s[j];
    const double v = (a1 + std::sqrt(a1 * a1 + 4.0 * k * a0)) / (2.0 * k);
    return std::clamp(v, s[j], s[j + 1]);
  }
  // above the last node the limit is constant again
  return std::max(s.back(), std::sqrt(m * p.ggv_lateral.back() / k));
}

// speed after one segment of length ds at constant acceleration a, from
// v^2 = v0^2 + 2 a ds; 0 when the car would stop within the segment
double next_speed(double v0, double a, double ds) {
  const double v2 = v0 * v0 + 2.0 * a * ds;
  return v2 > 0.0 ? std::sqrt(v2) : 0.0;
}

// forward step i -> i+1: accelerate as hard as tyres, machine and drag allow
// at point i; the limit only ever lowers the speed already there
bool forward_step(std::vector<double>& v, const std::vector<double>& kappa, std::size_t i,
                  std::size_t j, double ds, const VelocityProfileParams& p) {
  const double cand = next_speed(v[i], available_acceleration(v[i], kappa[i], p), ds);
  if (cand < v[j]) {
    v[j] = cand;
    return true;
  }
  return false;
}

// backward step j -> i (j follows i along the path): the fastest speed at i
// from which the car can still brake down to v[j]. The deceleration is
// evaluated at j, then once more at i with the speed that gives, keeping the
// smaller result, because the deceleration available at i (a different
// speed and curvature) is the one really used over the segment.
bool backward_step(std::vector<double>& v, const std::vector<double>& kappa, std::size_t j,
                   std::size_t i, double ds, const VelocityProfileParams& p) {
  double cand = next_speed(v[j], available_deceleration(v[j], kappa[j], p), ds);
  const double again = next_speed(v[j], available_deceleration(cand, kappa[i], p), ds);
  cand = std::min(cand, again);
  if (cand < v[i]) {
    v[i] = cand;
    return true;
  }
  return false;
}

}  // namespace

double available_acceleration(double v, double kappa, const VelocityProfileParams& p) {
  if (ggv(p)) return tyre_longitudinal(p.margin_longitudinal * interpolate(p.ggv_speed, p.ggv_accel, v), v, kappa, p);
  const double tyre = tyre_longitudinal(p.ax_max, v, kappa, p);
  return std::min(tyre, p.ax_machine) - drag_decel(v, p);
}

double available_deceleration(double v, double kappa, const VelocityProfileParams& p) {
  if (ggv(p)) return tyre_longitudinal(p.margin_longitudinal * interpolate(p.ggv_speed, p.ggv_brake, v), v, kappa, p);
  return tyre_longitudinal(p.ax_brake_max, v, kappa, p) + drag_decel(v, p);
}

double planned_lateral_limit(double v, const VelocityProfileParams& p) {
  return ggv(p) ? p.margin_lateral * interpolate(p.ggv_speed, p.ggv_lateral, v) : p.ay_max;
}

std::string VelocityProfileParams::check() const {
  if (!(std::isfinite(mass) && mass > 0.0)) return "mass must be > 0 kg (got " + params::number(mass) + ")";
  if (!(std::isfinite(drag_coefficient) && drag_coefficient >= 0.0))
    return "drag_coefficient must be >= 0 N s^2/m^2 (got " + params::number(drag_coefficient) + ")";
  const std::size_t n = ggv_speed.size();
  if (n == 0) return "ggv_speed needs at least one speed";
  if (ggv_lateral.size() != n || ggv_accel.size() != n || ggv_brake.size() != n)
    return "ggv_lateral, ggv_accel and ggv_brake need one value per ggv_speed (" + std::to_string(n) +
           "), got " + std::to_string(ggv_lateral.size()) + ", " + std::to_string(ggv_accel.size()) + " and " +
           std::to_string(ggv_brake.size());
  for (std::size_t i = 1; i < n; ++i)
    if (!(ggv_speed[i] > ggv_speed[i - 1]))
      return "ggv_speed must be strictly ascending (" + params::number(ggv_speed[i - 1]) + " then " +
             params::number(ggv_speed[i]) + ")";
  return "";
}

VelocityProfile solve_velocity_profile(const std::vector<double>& curvature,
                                       const std::vector<double>& segment_lengths, bool closed,
                                       const VelocityProfileParams& params,
                                       std::optional<double> v_start,
                                       std::optional<double> v_end) {
  VelocityProfile out;
  // check the inputs; nothing here throws
  const std::size_t n = curvature.size();
  if (n < 2) {
    out.reason = "velocity profile: needs at least 2 points, got " + std::to_string(n);
    return out;
  }
  const std::size_t nseg = closed ? n : n - 1;
  if (segment_lengths.size() != nseg) {
    out.reason = "velocity profile: " + std::to_string(n) + " points need " + std::to_string(nseg) +
                 " segment lengths (" + (closed ? "closed" : "open") + "), got " +
                 std::to_string(segment_lengths.size());
    return out;
  }
  if (!all_finite(curvature)) {
    out.reason = "velocity profile: curvature has a NaN or infinite value";
    return out;
  }
  if (!all_finite(segment_lengths)) {
    out.reason = "velocity profile: segment lengths have a NaN or infinite value";
    return out;
  }
  if (std::any_of(segment_lengths.begin(), segment_lengths.end(), [](double d) { return d <= 0.0; })) {
    out.reason = "velocity profile: segment lengths must be > 0 (duplicate points?)";
    return out;
  }
  if ((v_start && std::isnan(*v_start)) || (v_end && std::isnan(*v_end))) {
    out.reason = "velocity profile: v_start or v_end is NaN";
    return out;
  }
  if (const std::string bad = params::validate(params); !bad.empty()) {
    out.reason = "velocity profile: " + bad;
    return out;
  }

  // the corner speeds: all the lateral grip used, v^2 |kappa| = ay_max;
  // a straight's infinite corner speed never leaves the min with v_max
  std::vector<double> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = std::min(corner_speed(curvature[i], params), params.v_max);

  if (!closed) {
    // open: the start bound, a forward (acceleration) pass, the end bound,
    // then a backward (braking) pass
    if (v_start) v[0] = std::min(v[0], std::max(0.0, *v_start));
    for (std::size_t i = 0; i + 1 < n; ++i) forward_step(v, curvature, i, i + 1, segment_lengths[i], params);
    if (v_end) v[n - 1] = std::min(v[n - 1], std::max(0.0, *v_end));
    for (std::size_t j = n - 1; j > 0; --j) backward_step(v, curvature, j, j - 1, segment_lengths[j - 1], params);
    out.speed = std::move(v);
    return out;
  }

  // closed: the reference unrolls two laps and keeps the one with a run-in.
  // Here the passes go round the loop in place until a whole lap changes
  // nothing at the wrap, which is the same after one run-in lap on ordinary
  // tracks and also settles loops where drag makes a corner's speed decay
  // all the way round (a circle), where two laps are not enough.
  constexpr int kMaxLaps = 64;
  for (int lap = 0; lap < kMaxLaps; ++lap) {
    for (std::size_t i = 0; i + 1 < n; ++i) forward_step(v, curvature, i, i + 1, segment_lengths[i], params);
    if (!forward_step(v, curvature, n - 1, 0, segment_lengths[n - 1], params)) break;
  }
  for (int lap = 0; lap < kMaxLaps; ++lap) {
    for (std::size_t j = n - 1; j > 0; --j) backward_step(v, curvature, j, j - 1, segment_lengths[j - 1], params);
    if (!backward_step(v, curvature, 0, n - 1, segment_lengths[n - 1], params)) break;
  }
  out.speed = std::move(v);
  return out;
}

std::size_t catch_up_profile(std::vector<double>& speed, const std::vector<double>& curvature,
                             const std::vector<double>& segment_lengths, bool closed, std::size_t from,
                             double v0, const VelocityProfileParams& params) {
  const std::size_t n = speed.size();
  if (n < 2 || curvature.size() != n || segment_lengths.size() != (closed ? n : n - 1) || from >= n ||
      !std::isfinite(v0))
    return 0;
  v0 = std::max(v0, 0.0);
  if (v0 >= speed[from]) return 0;
  speed[from] = v0;
  std::size_t lowered = 1;
  // forward steps from `from`: each lowers the next point or, once the car's
  // speed is back on the profile, ends the catch-up; a closed path goes at
  // most once round
  for (std::size_t k = 0; k + 1 < n; ++k) {
    const std::size_t i = (from + k) % n;
    const std::size_t j = i + 1;
    if (j == n && !closed) break;
    if (!forward_step(speed, curvature, i, j % n, segment_lengths[i], params)) break;
    ++lowered;
  }
  return lowered;
}

double profile_time(const std::vector<double>& speed, const std::vector<double>& segment_lengths,
                    bool closed) {
  const std::size_t n = speed.size();
  const std::size_t nseg = closed ? n : (n > 0 ? n - 1 : 0);
  if (n < 2 || segment_lengths.size() != nseg) return std::numeric_limits<double>::quiet_NaN();
  // constant acceleration along each segment: the mean speed is (v_i + v_i+1) / 2
  double t = 0.0;
  for (std::size_t i = 0; i < nseg; ++i) {
    const double ds = segment_lengths[i];
    const double vsum = speed[i] + speed[(i + 1) % n];
    if (ds == 0.0) continue;
    if (!(vsum > 0.0)) return kInf;
    t += 2.0 * ds / vsum;
  }
  return t;
}

}  // namespace paddock::planning
