#include "autonomy/perception/ground_segmentation.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "autonomy/common/fast_math.h"

namespace paddock::perception {

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

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
}

void GroundSegmenter::inter_ring(Cloud& cloud, GroundStats& stats) const {
  const double h = calib_.mount_z, s = params_.max_slope;
  // the gap between two returns on the steepest accepted ground plane
  const auto expected_gap = [h, s](const CloudPoint& a, const CloudPoint& b) {
    if (!(a.range_xy > 1e-3f) || !(b.range_xy > 1e-3f)) return kInfinity;
    const double ta = -static_cast<double>(a.z_sensor) / a.range_xy + s;
    const double tb = -static_cast<double>(b.z_sensor) / b.range_xy + s;
    if (ta <= 0.0 || tb <= 0.0) return kInfinity;
    return h * std::abs(1.0 / tb - 1.0 / ta);
  };
  std::vector<CloudPoint>& pts = cloud.points;
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
      const double gap = std::abs(static_cast<double>(b.range_xy) - a.range_xy);
      if (gap < expected_gap(a, b) + params_.gap_noise) {
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

std::size_t GroundSegmenter::region_of(double x, double y) const {
  const double dx = x - calib_.mount_x, dy = y - calib_.mount_y;
  const double r = std::sqrt(dx * dx + dy * dy);
  const auto ring = static_cast<std::size_t>(
      std::upper_bound(params_.region_bounds.begin(), params_.region_bounds.end(), r) -
      params_.region_bounds.begin());
  // (coarse: the sectors are 0.2 rad wide, and this runs for every return of every scan)
  const double u = (coarse_atan2(dy, dx) + kPi) / (2.0 * kPi);  // [0, 1]
  const auto sectors = static_cast<std::size_t>(params_.sectors);
  const std::size_t sector =
      std::min(sectors - 1, static_cast<std::size_t>(std::max(0.0, u * static_cast<double>(sectors))));
  return sector * rings_ + ring;
}

GroundSegmenter::Plane GroundSegmenter::fit_region(const Cloud& cloud, std::size_t region,
                                                   const Plane& prior, double r_inner,
                                                   double azimuth, bool& fitted) const {
  fitted = false;
  // where the region meets the one inside it (the sensor for the innermost)
  const double jx = calib_.mount_x + r_inner * std::cos(azimuth);
  const double jy = calib_.mount_y + r_inner * std::sin(azimuth);
  const bool innermost = !(r_inner > 0.0);
  const double spread = innermost ? params_.first_slope_prior_spread : params_.slope_prior_spread;
  const double first_window = innermost ? params_.first_fit_window : params_.fit_window;
  const double lambda = spread * spread;
  const int iters = params_.fit_iterations;
  Plane plane = prior;
  for (int it = 0; it < iters; ++it) {
    // the window shrinks geometrically from fit_window to ground_threshold
    const double f = iters == 1 ? 1.0 : static_cast<double>(it) / (iters - 1);
    const double window = first_window * std::pow(params_.ground_threshold / first_window, f);
    // moments of the candidates near the current plane
    double n = 0.0, sx = 0.0, sy = 0.0, sz = 0.0, sxx = 0.0, sxy = 0.0, syy = 0.0, sxz = 0.0, syz = 0.0;
    for (std::uint32_t m = offsets_[region]; m < offsets_[region + 1]; ++m) {
      const CloudPoint& p = cloud.points[members_[m]];
      if (p.vertical) continue;
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
    if (!(std::hypot(cand.a, cand.b) <= params_.max_slope)) {
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

  // the points bucketed by region (a counting sort)
  const std::size_t n = cloud.points.size();
  region_id_.resize(n);
  offsets_.assign(regions + 1, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const CloudPoint& p = cloud.points[i];
    region_id_[i] = static_cast<std::uint32_t>(region_of(p.x, p.y));
    ++offsets_[region_id_[i] + 1];
  }
  for (std::size_t r = 0; r < regions; ++r) offsets_[r + 1] += offsets_[r];
  members_.resize(n);
  cursor_.assign(offsets_.begin(), offsets_.end() - 1);
  for (std::size_t i = 0; i < n; ++i) members_[cursor_[region_id_[i]]++] = static_cast<std::uint32_t>(i);

  // stage 2: per sector, the regions from the inside out
  for (std::size_t s = 0; s < sectors; ++s) {
    const double azimuth = -kPi + (static_cast<double>(s) + 0.5) * 2.0 * kPi / static_cast<double>(sectors);
    Plane prior;  // the ground under the car: z = 0
    for (std::size_t k = 0; k < rings_; ++k) {
      const double r_inner = k == 0 ? 0.0 : params_.region_bounds[k - 1];
      bool fitted = false;
      const Plane plane = fit_region(cloud, s * rings_ + k, prior, r_inner, azimuth, fitted);
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
