#include "sim/sensors/cone_sensor.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <sstream>

namespace paddock::sensors {

std::string ConeSensorParams::check() const {
  // the radii are not visited (the runner sets them): their bounds are here
  if (!params::above(0.0).contains(small_cone_radius))
    return "small_cone_radius must be > 0 m (got " + params::number(small_cone_radius) + ")";
  if (!params::above(0.0).contains(big_cone_radius))
    return "big_cone_radius must be > 0 m (got " + params::number(big_cone_radius) + ")";
  std::ostringstream s;
  if (!(range_max > range_min)) {
    s << "range_max must be > range_min (got " << range_max << " <= " << range_min << ")";
  } else if (miss_probability + miss_probability_growth > 1.0) {
    s << "miss_probability_growth must keep miss_probability + miss_probability_growth <= 1 (got "
      << miss_probability + miss_probability_growth << ")";
  } else if (unknown_color_probability + unknown_color_growth > 1.0) {
    s << "unknown_color_growth must keep unknown_color_probability + unknown_color_growth <= 1 (got "
      << unknown_color_probability + unknown_color_growth << ")";
  } else if (color_flip_probability + color_flip_growth > 1.0) {
    s << "color_flip_growth must keep color_flip_probability + color_flip_growth <= 1 (got "
      << color_flip_probability + color_flip_growth << ")";
  }
  return s.str();
}

ConeSensor::ConeSensor(const ConeSensorParams& params, std::uint64_t seed) : params_(params), rng_(seed) {
  params::require_valid(params_, "ConeSensorParams");
}

double ConeSensor::uniform() {
  // 53 random bits -> [0, 1), the same on every platform
  return static_cast<double>(rng_() >> 11) * 0x1.0p-53;
}

double ConeSensor::gaussian() { return normal_(rng_); }

// the length of [lo, hi] covered by the union of covered_ (disjoint, sorted)
double ConeSensor::covered_length(double lo, double hi) const {
  double len = 0.0;
  for (const Interval& iv : covered_) {
    if (iv.lo >= hi) break;
    len += std::max(0.0, std::min(hi, iv.hi) - std::max(lo, iv.lo));
  }
  return len;
}

// add [lo, hi] to covered_, merging every interval it touches
void ConeSensor::cover(double lo, double hi) {
  // the first interval that ends at or after lo
  auto first = std::lower_bound(covered_.begin(), covered_.end(), lo,
                                [](const Interval& iv, double v) { return iv.hi < v; });
  auto last = first;
  while (last != covered_.end() && last->lo <= hi) {
    lo = std::min(lo, last->lo);
    hi = std::max(hi, last->hi);
    ++last;
  }
  if (first == last) {
    covered_.insert(first, Interval{lo, hi});
  } else {
    *first = Interval{lo, hi};
    covered_.erase(first + 1, last);
  }
}

hal::ConeDetections ConeSensor::measure(const std::vector<Cone>& cones, const std::vector<bool>& knocked,
                                        const Pose2& base_pose, TimeNs stamp) {
  hal::ConeDetections out;
  out.stamp = stamp;
  stats_ = {};
  // a broken pose measures nothing
  if (!std::isfinite(base_pose.x) || !std::isfinite(base_pose.y) || !std::isfinite(base_pose.yaw)) return out;
  // programmer error: knocked must be empty or parallel to cones (a release
  // build reads a missing entry as standing)
  assert(knocked.empty() || knocked.size() == cones.size());
  const ConeSensorParams& p = params_;

  // the sensor origin in the map; the sensor's axes are the base frame's
  const Vec2 mount{p.mount_x, p.mount_y};
  const Vec2 origin = base_pose.transform(mount);
  const double c = std::cos(base_pose.yaw), s = std::sin(base_pose.yaw);
  const double range_max2 = p.range_max * p.range_max;

  // cull by squared range; a NaN position fails the comparison. Every
  // standing cone within range_max is a candidate, also those nearer than
  // range_min or outside the field of view: they still hide cones behind them.
  candidates_.clear();
  visible_.assign(cones.size(), false);
  for (std::size_t i = 0; i < cones.size(); ++i) {
    const Vec2 d = cones[i].position - origin;
    const double d2 = squared_norm(d);
    if (!(d2 <= range_max2)) continue;
    if (i < knocked.size() && knocked[i]) {
      // lying down: not a cone to the pipeline, and low enough to see over
      ++stats_.knocked;
      continue;
    }
    // the cone in the sensor frame: R(-yaw) d
    const double lx = c * d.x + s * d.y, ly = -s * d.x + c * d.y;
    const double radius = cones[i].color == ConeColor::BigOrange ? p.big_cone_radius : p.small_cone_radius;
    candidates_.push_back({d2, std::atan2(ly, lx), radius, cones[i].color, i});
  }

  // nearest first, so every cone meets its occluders before itself (ties by
  // index keep the order, and so the random draws, independent of the sort)
  std::sort(candidates_.begin(), candidates_.end(), [](const Candidate& a, const Candidate& b) {
    return a.range2 < b.range2 || (a.range2 == b.range2 && a.index < b.index);
  });

  covered_.clear();
  out.cones.reserve(candidates_.size());  // at most one detection a candidate (then the false ones)
  const double half_fov = 0.5 * p.fov;
  for (const Candidate& k : candidates_) {
    const double r = std::sqrt(k.range2);
    const bool in_view = r >= p.range_min && std::abs(k.bearing) <= half_fov;

    // occlusion: the cone's bearing interval [b - a, b + a], a = asin(radius / r)
    // (the half-angle the base circle subtends), split where it crosses +-pi.
    // It is hidden when nearer cones cover at least occlusion_fraction of it;
    // hidden or not, it then covers the cones behind it.
    bool hidden = false;
    if (p.occlusion) {
      const double a = r > k.radius ? std::asin(k.radius / r) : 0.5 * kPi;
      double lo = k.bearing - a, hi = k.bearing + a;
      double lo2 = 1.0, hi2 = 0.0;  // a second piece, empty unless it wraps
      if (lo < -kPi) {
        lo2 = lo + 2.0 * kPi, hi2 = kPi;
        lo = -kPi;
      } else if (hi > kPi) {
        lo2 = -kPi, hi2 = hi - 2.0 * kPi;
        hi = kPi;
      }
      if (in_view) {
        double len = covered_length(lo, hi);
        if (hi2 > lo2) len += covered_length(lo2, hi2);
        // 1e-12 rad: an interval exactly inside a nearer one counts as covered
        hidden = len >= p.occlusion_fraction * 2.0 * a - 1e-12;
      }
      cover(lo, hi);
      if (hi2 > lo2) cover(lo2, hi2);
    }
    if (!in_view) continue;
    ++stats_.in_view;
    if (hidden) {
      ++stats_.occluded;
      continue;
    }
    visible_[k.index] = true;

    // five draws per cone in view, whatever the parameters, so that turning
    // one effect off does not reshuffle the others
    const double u_miss = uniform();
    const double g_range = gaussian(), g_bearing = gaussian();
    const double u_unknown = uniform(), u_flip = uniform();

    // misses grow with (r / range_max)^2, like the cluster's point count falls
    const double q = k.range2 / range_max2;
    if (u_miss < p.miss_probability + p.miss_probability_growth * q) {
      ++stats_.missed;
      continue;
    }

    // range and bearing noise in the sensor's polar frame, then into the base frame
    const double rm = std::max(0.0, r + (p.range_noise + p.range_noise_per_m * r) * g_range);
    const double bm = k.bearing + p.bearing_noise * g_bearing;
    hal::DetectedCone det;
    det.position = mount + Vec2{rm * std::cos(bm), rm * std::sin(bm)};

    // colour: unknown first, else a flip to the look-alike. A big cone stays
    // big when its colour is lost: a LiDAR measures its height (505 mm against
    // 325 mm), so the timing lines' cones are known even without colour
    det.color = k.color;
    det.colour_from_camera = true;  // an object-level sensor stands for camera and LiDAR fused
    if (u_unknown < p.unknown_color_probability + p.unknown_color_growth * q) {
      det.color = k.color == ConeColor::BigOrange ? ConeColor::BigOrange : ConeColor::Unknown;
    } else if (u_flip < p.color_flip_probability + p.color_flip_growth * q) {
      det.color = look_alike(k.color);
    }
    out.cones.push_back(det);
  }

  // false positives: a Poisson count, uniform over the area of the annular
  // sector (r^2 uniform in [range_min^2, range_max^2], bearing uniform in the fov)
  if (p.false_positives_per_frame > 0.0) {
    std::poisson_distribution<int> poisson(p.false_positives_per_frame);
    const int n = poisson(rng_);
    const double rmin2 = p.range_min * p.range_min;
    for (int j = 0; j < n; ++j) {
      const double r = std::sqrt(rmin2 + uniform() * (range_max2 - rmin2));
      const double b = (2.0 * uniform() - 1.0) * half_fov;
      const double u_unknown = uniform(), u_color = uniform();
      hal::DetectedCone det;
      det.position = mount + Vec2{r * std::cos(b), r * std::sin(b)};
      static constexpr ConeColor kColors[] = {ConeColor::Blue, ConeColor::Yellow, ConeColor::SmallOrange,
                                              ConeColor::BigOrange};
      det.color = u_unknown < p.false_positive_unknown_probability
                      ? ConeColor::Unknown
                      : kColors[std::min(3, static_cast<int>(u_color * 4.0))];
      det.colour_from_camera = true;
      out.cones.push_back(det);
    }
    stats_.false_positives = n;
  }

  // nearest (measured) first; a real pipeline's order carries no meaning, and
  // this one does not betray which detections are false
  std::sort(out.cones.begin(), out.cones.end(), [&mount](const hal::DetectedCone& a, const hal::DetectedCone& b) {
    return squared_norm(a.position - mount) < squared_norm(b.position - mount);
  });
  return out;
}

}  // namespace paddock::sensors
