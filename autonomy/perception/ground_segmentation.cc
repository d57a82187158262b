#include "autonomy/perception/ground_segmentation.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "autonomy/common/fast_math.h"

namespace paddock::perception {

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
// in_sector's margin (rad): 600 times coarse_atan2's largest error (1.66e-6
// rad, measured over 1.5e8 directions; its header says 2e-6)
constexpr double kSectorMargin = 1e-3;

// std::hypot(a, b) <= bound. For a bound in [1e-100, 1e100] the squared norm
// decides it the same way, without the library call, when it lies more than
// 1 % off bound^2: its rounding (4e-16 relative, and at most 5e-324 for
// squares that underflow) and hypot's (one ulp) are far below that. Near the
// bound, and for NaN, hypot decides
bool hypot_at_most(double a, double b, double bound) {
  if (bound >= 1e-100 && bound <= 1e100) {
    const double s = a * a + b * b, b2 = bound * bound;
    if (s < 0.99 * b2) return true;
    if (s > 1.01 * b2) return false;
  }
  return std::hypot(a, b) <= bound;
}

}  // namespace

std::string GroundSegmentationParams::check() const {
  if (fit_window < ground_threshold) return "fit_window must be >= ground_threshold";
  if (first_fit_window < ground_threshold) return "first_fit_window must be >= ground_threshold";
  if (region_bounds.size() > 1000)
    return "region_bounds must hold at most 1000 ranges (got " + std::to_string(region_bounds.size()) + ")";
  for (std::size_t i = 1; i < region_bounds.size(); ++i) {
    if (!(region_bounds[i] > region_bounds[i - 1])) return "region_bounds must be ascending (item " + std::to_string(i) + ")";
  }
  return "";
}

GroundSegmenter::GroundSegmenter(const GroundSegmentationParams& params,
                                 const LidarCalibration& calibration)
    : params_(params), calib_(calibration), rings_(params.region_bounds.size() + 1) {
  params::require_valid(params_, "GroundSegmentationParams");
  params::require_valid(calib_, "LidarCalibration");
  const auto sectors = static_cast<std::size_t>(params_.sectors);
  for (std::size_t s = 0; s < sectors; ++s) {
    const double azimuth = -kPi + (static_cast<double>(s) + 0.5) * 2.0 * kPi / static_cast<double>(sectors);
    sector_cos_.push_back(std::cos(azimuth));
    sector_sin_.push_back(std::sin(azimuth));
  }
  // ring_of compares squared ranges: fl(sqrt(s)) never decreases as s grows
  // (the root is correctly rounded), so region_of's r = fl(sqrt(s)) lies
  // below a bound b exactly when s lies below the least double whose root
  // rounds to b or more, found here from b * b in steps of one ulp
  for (const double b : params_.region_bounds) {
    double t = b * b;
    while (std::sqrt(t) >= b) t = std::nextafter(t, 0.0);
    while (std::sqrt(t) < b) t = std::nextafter(t, kInfinity);
    squared_bounds_.push_back(t);
  }
  // the sectors' wedges narrowed by kSectorMargin on both sides. A direction
  // strictly inside sector k's narrowed wedge has a coarse_atan2 within
  // 2e-6 rad of its true angle, so still 1e-3 rad inside the sector, which
  // the rounding of sector_of's u (~1e-15) cannot undo: sector_of gives k.
  // in_sector tests it with two cross products against the narrowed edges,
  // whose rounding (~1e-16 of the range) is as far below the margin. (Each
  // wedge lies inside one half-plane of the cut at +-pi: the cross products
  // see no wrap.) Narrower sectors than four margins, or a single one, take
  // sector_of always
  const double width = 2.0 * kPi / static_cast<double>(sectors);
  if (sectors >= 2 && width > 4.0 * kSectorMargin) {
    for (std::size_t s = 0; s < sectors; ++s) {
      const double lo = -kPi + static_cast<double>(s) * width + kSectorMargin;
      const double hi = -kPi + static_cast<double>(s + 1) * width - kSectorMargin;
      wedges_.push_back({std::cos(lo), std::sin(lo), std::cos(hi), std::sin(hi)});
    }
  }
  // the window shrinks geometrically from fit_window (first_fit_window for
  // the innermost region) to ground_threshold
  const int iters = params_.fit_iterations;
  const auto window = [this](double first_window, double f) {
    return first_window * std::pow(params_.ground_threshold / first_window, f);
  };
  for (int it = 0; it < iters; ++it) {
    const double f = iters == 1 ? 1.0 : static_cast<double>(it) / (iters - 1);
    first_windows_.push_back(window(params_.first_fit_window, f));
    windows_.push_back(window(params_.fit_window, f));
  }
}

void GroundSegmenter::inter_ring(Cloud& cloud, GroundStats& stats) {
  const double h = calib_.mount_z, s = params_.max_slope;
  std::vector<CloudPoint>& pts = cloud.points;
  // the gap between two returns a, b on the steepest accepted ground plane is
  // h |1 / (tan d_b + s) - 1 / (tan d_a + s)| (see the top), infinite when a
  // beam cannot meet the plane. Each return is b of one pair and a of the
  // next: its 1 / (tan d + s) is taken once, here (the same expression, so
  // the same double), and -1 when its beam cannot meet the plane (a real one
  // is positive, or NaN when a coordinate is, which then meets the plane as
  // it did before)
  inv_reach_.resize(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const CloudPoint& p = pts[i];
    const double t = -static_cast<double>(p.z_sensor) / p.range_xy + s;
    inv_reach_[i] = p.range_xy > 1e-3f && !(t <= 0.0) ? 1.0 / t : -1.0;
  }
  const auto meets = [](double inv) { return !(inv < 0.0); };
  const auto close_run = [&](std::uint32_t begin, std::uint32_t end, float z_min, float z_max) {
    if (end - begin >= 2 && z_max - z_min > params_.vertical_threshold) {
      for (std::uint32_t k = begin; k < end; ++k) pts[k].vertical = true;
      stats.vertical += end - begin;
    }
  };
  for (const CloudColumn& col : cloud.columns) {
    if (col.begin == col.end) continue;
    std::uint32_t run = col.begin;
    float z_min = pts[run].z_sensor, z_max = z_min;
    for (std::uint32_t k = col.begin + 1; k < col.end; ++k) {
      const CloudPoint& a = pts[k - 1];
      const CloudPoint& b = pts[k];
      const double ia = inv_reach_[k - 1], ib = inv_reach_[k];
      const double expected_gap = meets(ia) && meets(ib) ? h * std::abs(ib - ia) : kInfinity;
      const double gap = std::abs(static_cast<double>(b.range_xy) - a.range_xy);
      if (gap < expected_gap + params_.gap_noise) {
        z_min = std::min(z_min, b.z_sensor);
        z_max = std::max(z_max, b.z_sensor);
      } else {
        close_run(run, k, z_min, z_max);
        run = k;
        z_min = z_max = b.z_sensor;
      }
    }
    close_run(run, col.end, z_min, z_max);
  }
}

std::size_t GroundSegmenter::ring_of(double dx, double dy) const {
  // the number of bounds at or below the range r = sqrt(dx^2 + dy^2) (as
  // std::upper_bound would find it), compared squared (see the
  // constructor); for the few bounds of a real layout counted without a
  // branch (one column's returns jump between the rings: a binary search's
  // branches mispredict)
  const double s = dx * dx + dy * dy;
  const std::vector<double>& bounds = squared_bounds_;
  if (bounds.size() > 16) {
    return static_cast<std::size_t>(std::upper_bound(bounds.begin(), bounds.end(), s) - bounds.begin());
  }
  std::size_t ring = 0;
  for (const double b : bounds) ring += !(s < b);
  return ring;
}

std::size_t GroundSegmenter::sector_of(double dx, double dy) const {
  // (coarse: the sectors are 0.2 rad wide, and this runs for every return of every scan)
  const double u = (coarse_atan2(dy, dx) + kPi) / (2.0 * kPi);  // [0, 1]
  const auto sectors = static_cast<std::size_t>(params_.sectors);
  return std::min(sectors - 1, static_cast<std::size_t>(std::max(0.0, u * static_cast<double>(sectors))));
}

bool GroundSegmenter::in_sector(std::size_t sector, double dx, double dy) const {
  if (sector >= wedges_.size()) return false;
  const Wedge& w = wedges_[sector];
  // counter-clockwise of the low edge and clockwise of the high one (NaN: no)
  return w.lo_c * dy - w.lo_s * dx > 0.0 && dx * w.hi_s - dy * w.hi_c > 0.0;
}

std::size_t GroundSegmenter::region_of(double x, double y) const {
  const double dx = x - calib_.mount_x, dy = y - calib_.mount_y;
  return sector_of(dx, dy) * rings_ + ring_of(dx, dy);
}

GroundSegmenter::Plane GroundSegmenter::fit_region(std::size_t region, std::size_t sector,
                                                   const Plane& prior, double r_inner,
                                                   bool& fitted) const {
  fitted = false;
  // fewer candidates than a fit needs: every pass below would find fewer
  // still and stop at once with the prior
  const std::uint32_t first = offsets_[region], last = offsets_[region + 1];
  if (last - first < static_cast<std::uint32_t>(params_.min_fit_points)) return prior;
  // where the region meets the one inside it (the sensor for the innermost)
  const double jx = calib_.mount_x + r_inner * sector_cos_[sector];
  const double jy = calib_.mount_y + r_inner * sector_sin_[sector];
  const bool innermost = !(r_inner > 0.0);
  const double spread = innermost ? params_.first_slope_prior_spread : params_.slope_prior_spread;
  const std::vector<double>& windows = innermost ? first_windows_ : windows_;
  const double lambda = spread * spread;
  const int iters = params_.fit_iterations;
  Plane plane = prior;
  for (int it = 0; it < iters; ++it) {
    const double window = windows[static_cast<std::size_t>(it)];
    // moments of the candidates near the current plane
    double n = 0.0, sx = 0.0, sy = 0.0, sz = 0.0, sxx = 0.0, sxy = 0.0, syy = 0.0, sxz = 0.0, syz = 0.0;
    for (std::uint32_t m = first; m < last; ++m) {
      const FitPoint& p = fit_points_[m];
      const double x = p.x, y = p.y, z = p.z;
      if (!(std::abs(z - plane.at(x, y)) < window)) continue;
      n += 1.0;
      sx += x; sy += y; sz += z;
      sxx += x * x; sxy += x * y; syy += y * y;
      sxz += x * z; syz += y * z;
    }
    if (n < params_.min_fit_points) break;
    // centred moments, then the ridge-regularised slope:
    // [Cxx + l, Cxy; Cxy, Cyy + l] (a, b) = (Cxz + l a0, Cyz + l b0)
    const double mx = sx / n, my = sy / n, mz = sz / n;
    const double cxx = sxx / n - mx * mx, cxy = sxy / n - mx * my, cyy = syy / n - my * my;
    const double cxz = sxz / n - mx * mz, cyz = syz / n - my * mz;
    const double m00 = cxx + lambda, m01 = cxy, m11 = cyy + lambda;
    const double r0 = cxz + lambda * prior.a, r1 = cyz + lambda * prior.b;
    const double det = m00 * m11 - m01 * m01;  // >= lambda^2 > 0
    Plane cand;
    cand.a = (r0 * m11 - r1 * m01) / det;
    cand.b = (m00 * r1 - m01 * r0) / det;
    if (!hypot_at_most(cand.a, cand.b, params_.max_slope)) {
      // too steep for ground: keep the prior's slope, fit the height only
      cand.a = prior.a;
      cand.b = prior.b;
    }
    cand.c = mz - cand.a * mx - cand.b * my;
    // continuity: where the regions meet and where the candidates lie (a
    // few cone returns alone must not lift a plane to their own height)
    // (the innermost region's prior, the level ground under the car, holds
    // at the sensor only: there the slope bound does the centroid's part)
    if (!(std::abs(cand.at(jx, jy) - prior.at(jx, jy)) <= params_.max_step) ||
        (!innermost && !(std::abs(cand.at(mx, my) - prior.at(mx, my)) <= params_.max_step))) {
      break;
    }
    plane = cand;
    fitted = true;
  }
  return plane;
}

GroundStats GroundSegmenter::segment(Cloud& cloud) {
  GroundStats stats;
  const auto sectors = static_cast<std::size_t>(params_.sectors);
  const std::size_t regions = sectors * rings_;
  stats.regions = regions;
  planes_.assign(regions, Plane{});

  // stage 1: the inter-ring distance test per column
  inter_ring(cloud, stats);

  // the ground candidates (the points stage 1 left) bucketed by region (a
  // counting sort)
  const std::size_t n = cloud.points.size();
  region_id_.resize(n);
  offsets_.assign(regions + 1, 0);
  // region_of, but a return mostly lies in the sector of its ring's return
  // in the column before: in_sector confirms that (exactly, see the
  // constructor) for all but the returns near a sector's edge, which take
  // coarse_atan2. (The column's other rings are no such guide: the motion
  // correction moves the returns of one beam direction by up to a metre,
  // which turns a near one by several sectors)
  ring_sector_.assign(static_cast<std::size_t>(calib_.channels), static_cast<std::uint32_t>(sectors));  // none yet
  for (std::size_t i = 0; i < n; ++i) {
    const CloudPoint& p = cloud.points[i];
    const double dx = p.x - calib_.mount_x, dy = p.y - calib_.mount_y;
    std::size_t sector = p.ring < ring_sector_.size() ? ring_sector_[p.ring] : sectors;
    if (!in_sector(sector, dx, dy)) {
      sector = sector_of(dx, dy);
      if (p.ring < ring_sector_.size()) ring_sector_[p.ring] = static_cast<std::uint32_t>(sector);
    }
    region_id_[i] = static_cast<std::uint32_t>(sector * rings_ + ring_of(dx, dy));
    if (!p.vertical) ++offsets_[region_id_[i] + 1];
  }
  for (std::size_t r = 0; r < regions; ++r) offsets_[r + 1] += offsets_[r];
  if (fit_points_.size() < offsets_[regions]) fit_points_.resize(offsets_[regions]);
  cursor_.assign(offsets_.begin(), offsets_.end() - 1);
  for (std::size_t i = 0; i < n; ++i) {
    const CloudPoint& p = cloud.points[i];
    if (p.vertical) continue;
    // (field by field: a whole struct built and stored at once stalls a load)
    FitPoint& q = fit_points_[cursor_[region_id_[i]]++];
    q.x = p.x;
    q.y = p.y;
    q.z = p.z;
  }

  // stage 2: per sector, the regions from the inside out
  for (std::size_t s = 0; s < sectors; ++s) {
    Plane prior;  // the ground under the car: z = 0
    for (std::size_t k = 0; k < rings_; ++k) {
      const double r_inner = k == 0 ? 0.0 : params_.region_bounds[k - 1];
      bool fitted = false;
      const Plane plane = fit_region(s * rings_ + k, s, prior, r_inner, fitted);
      planes_[s * rings_ + k] = plane;
      if (fitted) ++stats.fitted_regions;
      prior = plane;
    }
  }

  // heights and labels
  for (std::size_t i = 0; i < n; ++i) {
    CloudPoint& p = cloud.points[i];
    const double h = p.z - planes_[region_id_[i]].at(p.x, p.y);
    p.height = static_cast<float>(h);
    const bool ground = !p.vertical && h < params_.ground_threshold;
    p.label = ground ? PointLabel::Ground : PointLabel::NonGround;
    if (ground) {
      ++stats.ground;
    } else {
      ++stats.non_ground;
    }
  }
  return stats;
}

double GroundSegmenter::ground_height(double x, double y) const {
  if (planes_.empty()) return 0.0;
  return planes_[region_of(x, y)].at(x, y);
}

}  // namespace paddock::perception
