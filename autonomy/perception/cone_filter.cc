#include "autonomy/perception/cone_filter.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace paddock::perception {

namespace {

// the cones (ORACLES.md): base width and height; the flat top's radius
constexpr double kSmallBaseRadius = 0.5 * 0.228, kSmallHeight = 0.325;  // m
constexpr double kBigBaseRadius = 0.5 * 0.285, kBigHeight = 0.505;      // m
constexpr double kTopRadius = 0.03;                                     // m
// E(d)'s cone face (ORACLES.md, AMZ)
constexpr double kExpectHeight = 0.31, kExpectWidth = 0.30;  // m

// the radius of a cone at height h above its base
double cone_radius(bool big, double h) {
  const double r0 = big ? kBigBaseRadius : kSmallBaseRadius;
  const double height = big ? kBigHeight : kSmallHeight;
  const double f = std::clamp(h / height, 0.0, 1.0);
  return r0 + (kTopRadius - r0) * f;
}

}  // namespace

ConeFilter::ConeFilter(const ConeFilterParams& params, const LidarCalibration& calibration)
    : params_(params), calib_(calibration) {
  params::require_valid(params_, "ConeFilterParams");
  params::require_valid(calib_, "LidarCalibration");
  // one channel: no vertical spacing; take a narrow 1 deg beam
  res_v_ = calib_.channels > 1 ? (calib_.elevation_max - calib_.elevation_min) / (calib_.channels - 1)
                               : kPi / 180.0;
  res_h_ = 2.0 * kPi / calib_.columns;
}

double ConeFilter::expected_points(double d) const {
  d = std::max(d, 1e-3);
  return 0.5 * kExpectHeight / (2.0 * d * std::tan(0.5 * res_v_)) * kExpectWidth /
         (2.0 * d * std::tan(0.5 * res_h_));
}

ConeFilterStats ConeFilter::filter(Cloud& cloud, const GroundSegmenter& ground,
                                   const Clusters& clusters, std::vector<ConeCluster>& cones,
                                   std::vector<std::uint32_t>& members) {
  ConeFilterStats stats;
  cones.clear();
  members.clear();
  std::vector<CloudPoint>& pts = cloud.points;
  const ConeFilterParams& p = params_;
  const double sx = calib_.mount_x, sy = calib_.mount_y;

  // the clusters' axes: the mean x, y of their returns
  axes_.resize(clusters.size());
  for (std::size_t k = 0; k < clusters.size(); ++k) {
    double mx = 0.0, my = 0.0;
    for (std::uint32_t m = clusters.offsets[k]; m < clusters.offsets[k + 1]; ++m) {
      mx += pts[clusters.members[m]].x;
      my += pts[clusters.members[m]].y;
    }
    const double cn = static_cast<double>(clusters.offsets[k + 1] - clusters.offsets[k]);
    axes_[k] = {mx / cn, my / cn};
  }

  // the local ground around a cone's axis looks up the ground returns in a
  // square grid of cells local_ground_outer wide around the sensor, so the
  // ring around a cone lies in the 3 x 3 cells around its own (the cells
  // around_cell visits)
  const double cell = p.local_ground_outer;
  const double half = kGroundGridRange + cell;
  const int side = static_cast<int>(std::ceil(2.0 * half / cell));
  // (a cell of a power of two metres, 1 m by default: the division by it is
  // a multiplication by its reciprocal, which is exact then, and cheaper)
  int cell_exponent = 0;
  const bool cell_pow2 = std::frexp(cell, &cell_exponent) == 0.5;
  const double inv_cell = 1.0 / cell;
  const auto in_cells = [&](double d) { return cell_pow2 ? d * inv_cell : d / cell; };
  const auto cell_of = [&](double x, double y) -> long {
    const double u = in_cells(x - sx + half), v = in_cells(y - sy + half);
    if (!(u >= 0.0 && v >= 0.0 && u < side && v < side)) return -1;
    return static_cast<long>(u) * side + static_cast<long>(v);
  };
  const auto around_cell = [side](long c0, const auto& visit) {
    const long cu = c0 / side, cv = c0 % side;
    for (long u = std::max(0L, cu - 1); u <= std::min<long>(side - 1, cu + 1); ++u) {
      for (long v = std::max(0L, cv - 1); v <= std::min<long>(side - 1, cv + 1); ++v) {
        visit(static_cast<std::size_t>(u * side + v));
      }
    }
  };
  // only those cells are ever looked up: only their ground returns are
  // binned (the lookups find the same returns in the same order)
  const auto cells = static_cast<std::size_t>(side) * static_cast<std::size_t>(side);
  cell_used_.assign(cells, 0);
  for (const Vec2& axis : axes_) {
    const long c0 = cell_of(axis.x, axis.y);
    if (c0 >= 0) around_cell(c0, [this](std::size_t c) { cell_used_[c] = 1; });
  }

  // one pass over the cloud: the ground returns a cylinder may give back,
  // and those in the used cells, with their cell. (Coordinates copied field
  // by field: a whole struct built on the stack and stored at once costs a
  // stalled load. The buffers keep their size between scans, the first n
  // are used: no value-initialisation of them each scan)
  const auto copy = [&pts](std::size_t i, GroundReturn& q) {
    q.x = pts[i].x;
    q.y = pts[i].y;
    q.z = pts[i].z;
    q.index = static_cast<std::uint32_t>(i);
  };
  if (candidates_.size() < pts.size()) candidates_.resize(pts.size());
  if (ground_.size() < pts.size()) ground_.resize(pts.size());
  ground_cell_.resize(pts.size());
  ground_cell_start_.assign(cells + 1, 0);
  std::size_t n_candidates = 0, n_ground = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    if (pts[i].label != PointLabel::Ground) continue;
    if (pts[i].height > p.reconstruction_margin) copy(i, candidates_[n_candidates++]);
    const long c = cell_of(pts[i].x, pts[i].y);
    if (c < 0 || !cell_used_[static_cast<std::size_t>(c)]) continue;
    ++ground_cell_start_[static_cast<std::size_t>(c) + 1];
    ground_cell_[n_ground] = static_cast<std::uint32_t>(c);
    copy(i, ground_[n_ground++]);
  }
  // the candidates sorted by x (then index)
  const auto candidates_end = candidates_.begin() + static_cast<std::ptrdiff_t>(n_candidates);
  std::sort(candidates_.begin(), candidates_end, [](const GroundReturn& a, const GroundReturn& b) {
    return a.x < b.x || (a.x == b.x && a.index < b.index);
  });
  const auto by_x = [](const GroundReturn& q, double x) { return q.x < x; };
  // the ground returns by cell (a counting sort; by index within a cell)
  for (std::size_t c = 1; c <= cells; ++c) ground_cell_start_[c] += ground_cell_start_[c - 1];
  if (ground_by_cell_.size() < n_ground) ground_by_cell_.resize(n_ground);
  ground_fill_.assign(ground_cell_start_.begin(), ground_cell_start_.end() - 1);
  for (std::size_t k = 0; k < n_ground; ++k) ground_by_cell_[ground_fill_[ground_cell_[k]]++] = ground_[k];

  const double rr2 = p.reconstruction_radius * p.reconstruction_radius;
  for (std::size_t k = 0; k < clusters.size(); ++k) {
    const auto begin = static_cast<std::uint32_t>(members.size());
    for (std::uint32_t m = clusters.offsets[k]; m < clusters.offsets[k + 1]; ++m) members.push_back(clusters.members[m]);
    const double mx = axes_[k].x, my = axes_[k].y;
    double g = ground.ground_height(mx, my);
    {
      // the local ground: the median of the ground returns around the axis
      local_z_.clear();
      const double r0 = p.local_ground_inner * p.local_ground_inner, r1 = p.local_ground_outer * p.local_ground_outer;
      const long c0 = cell_of(mx, my);
      if (c0 >= 0) {
        around_cell(c0, [&](std::size_t c) {
          for (std::uint32_t g_i = ground_cell_start_[c]; g_i < ground_cell_start_[c + 1]; ++g_i) {
            const GroundReturn& q = ground_by_cell_[g_i];
            const double dx = q.x - mx, dy = q.y - my, d2 = dx * dx + dy * dy;
            if (d2 >= r0 && d2 <= r1) local_z_.push_back(q.z);
          }
        });
      }
      if (static_cast<int>(local_z_.size()) >= p.local_ground_min_points) {
        auto mid = local_z_.begin() + static_cast<std::ptrdiff_t>(local_z_.size() / 2);
        std::nth_element(local_z_.begin(), mid, local_z_.end());
        g = *mid;
      }
    }

    // reconstruction: ground returns in the cylinder, above the margin
    auto it = std::lower_bound(candidates_.begin(), candidates_end, mx - p.reconstruction_radius, by_x);
    std::size_t readded = 0;
    for (; it != candidates_end && it->x <= mx + p.reconstruction_radius; ++it) {
      const GroundReturn& q = *it;
      const double dx = q.x - mx, dy = q.y - my, h = q.z - g;
      if (dx * dx + dy * dy <= rr2 && h > p.reconstruction_margin && h < p.max_height) {
        members.push_back(q.index);
        ++readded;
      }
    }
    const auto end = static_cast<std::uint32_t>(members.size());
    const int n = static_cast<int>(end - begin);

    // statistics over all its returns: heights above the ground at the axis
    double ax = 0.0, ay = 0.0, az = 0.0, top = -std::numeric_limits<double>::infinity();
    double lo_h = std::numeric_limits<double>::infinity();
    double x0 = lo_h, x1 = -lo_h, y0 = lo_h, y1 = -lo_h;
    for (std::uint32_t m = begin; m < end; ++m) {
      CloudPoint& q = pts[members[m]];
      q.height = static_cast<float>(q.z - g);
      ax += q.x;
      ay += q.y;
      az += q.z;
      top = std::max(top, static_cast<double>(q.height));
      lo_h = std::min(lo_h, static_cast<double>(q.height));
      x0 = std::min(x0, static_cast<double>(q.x));
      x1 = std::max(x1, static_cast<double>(q.x));
      y0 = std::min(y0, static_cast<double>(q.y));
      y1 = std::max(y1, static_cast<double>(q.y));
    }
    ax /= n;
    ay /= n;
    az /= n;
    const Vec2 ray{ax - sx, ay - sy};
    const double d = std::max(norm(ray), 1e-6);
    const Vec2 u = ray / d, t = left_normal(u);

    const auto reject = [&](std::size_t& counter) {
      ++counter;
      members.resize(begin);
    };
    if (n < p.min_points) {
      reject(stats.rejected_count);
      continue;
    }
    if (std::hypot(x1 - x0, y1 - y0) > p.max_extent) {
      reject(stats.rejected_size);
      continue;
    }
    if (top < p.min_height || top > p.max_height) {
      reject(stats.rejected_height);
      continue;
    }
    // shape: lateral symmetry, and the upper half no wider than the lower
    bool bad_shape = false;
    if (n >= 4) {
      const double mid_h = 0.5 * (lo_h + top);
      double t0 = std::numeric_limits<double>::infinity(), t1 = -t0;
      double lo0 = t0, lo1 = -t0, up0 = t0, up1 = -t0;
      int n_lo = 0, n_up = 0;
      for (std::uint32_t m = begin; m < end; ++m) {
        const CloudPoint& q = pts[members[m]];
        const double tq = dot(Vec2{q.x - ax, q.y - ay}, t);
        t0 = std::min(t0, tq);
        t1 = std::max(t1, tq);
        if (q.height < mid_h) {
          lo0 = std::min(lo0, tq);
          lo1 = std::max(lo1, tq);
          ++n_lo;
        } else {
          up0 = std::min(up0, tq);
          up1 = std::max(up1, tq);
          ++n_up;
        }
      }
      // the mean's lateral offset is 0 by construction: compare the middle
      bad_shape = std::abs(0.5 * (t0 + t1)) > p.max_asymmetry;
      if (n_lo >= 2 && n_up >= 2 && (up1 - up0) > (lo1 - lo0) + p.max_width_growth) bad_shape = true;
    }
    if (bad_shape) {
      reject(stats.rejected_shape);
      continue;
    }
    const double expected = expected_points(d);
    if (n < p.min_count_ratio * expected || n > p.max_count_ratio * expected + p.min_points) {
      reject(stats.rejected_density);
      continue;
    }

    // accepted: the axis behind the visible face (see the header)
    const bool big = top >= p.big_cone_height;
    double mean_h = 0.0;
    for (std::uint32_t m = begin; m < end; ++m) mean_h += pts[members[m]].height;
    mean_h /= n;
    const double behind = 0.25 * kPi * cone_radius(big, mean_h);
    ConeCluster c;
    c.begin = begin;
    c.end = end;
    c.centre = Eigen::Vector3d(ax + behind * u.x, ay + behind * u.y, az);
    c.range = d + behind;
    c.top = top;
    c.points = n;
    cones.push_back(c);
    for (std::uint32_t m = begin; m < end; ++m) pts[members[m]].label = PointLabel::Cone;
    stats.reconstructed += readded;
    ++stats.accepted;
  }
  return stats;
}

}  // namespace paddock::perception
