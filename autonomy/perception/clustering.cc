#include "autonomy/perception/clustering.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <utility>

#include <nanoflann.hpp>

namespace paddock::perception {

namespace {

// nanoflann's view of the points being clustered (x, y)
struct XyAdaptor {
  const std::vector<std::array<float, 2>>* pts = nullptr;
  std::size_t kdtree_get_point_count() const { return pts->size(); }
  float kdtree_get_pt(std::size_t i, std::size_t dim) const { return (*pts)[i][dim]; }
  template <class Bbox>
  bool kdtree_get_bbox(Bbox&) const {
    return false;
  }
};
using XyTree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, XyAdaptor, float>,
                                                   XyAdaptor, 2, std::uint32_t>;

}  // namespace

// the points, the adaptor that views them and the tree over them, built
// once and rebuilt over new points each call
struct Clusterer::Index {
  std::vector<std::array<float, 2>> xy;
  XyAdaptor adaptor{&xy};
  XyTree tree{2, adaptor,
              nanoflann::KDTreeSingleIndexAdaptorParams(
                  10, nanoflann::KDTreeSingleIndexAdaptorFlags::SkipInitialBuildIndex)};
  std::vector<std::pair<std::uint32_t, float>> matches;
};

Clusterer::Clusterer(const ClusteringParams& params, const LidarCalibration& calibration)
    : params_(params), calib_(calibration), index_(std::make_unique<Index>()) {
  params::require_valid(params_, "ClusteringParams");
  params::require_valid(calib_, "LidarCalibration");
}

Clusterer::~Clusterer() = default;
Clusterer::Clusterer(Clusterer&&) noexcept = default;
Clusterer& Clusterer::operator=(Clusterer&&) noexcept = default;

namespace {
std::uint32_t find_root(std::vector<std::uint32_t>& parent, std::uint32_t a) {
  while (parent[a] != a) {
    parent[a] = parent[parent[a]];
    a = parent[a];
  }
  return a;
}
}  // namespace

void Clusterer::sort_by_cell() {
  // points_ is sorted by (ix, iy, source). When the cells' spans fit 16 bits
  // each (always, but for a tolerance thousands of times finer than a cone),
  // that order is the order of one 64-bit key per point, (ix - min, iy -
  // min, position in points_), the position standing in for the source
  // (points_ is in source order); plain integers sort far faster than the
  // structs with their three-way comparison
  const auto [x_lo, x_hi] = std::minmax_element(points_.begin(), points_.end(),
                                                [](const GridPoint& a, const GridPoint& b) { return a.ix < b.ix; });
  const auto [y_lo, y_hi] = std::minmax_element(points_.begin(), points_.end(),
                                                [](const GridPoint& a, const GridPoint& b) { return a.iy < b.iy; });
  const std::int64_t ix0 = x_lo->ix, iy0 = y_lo->iy;
  if (x_hi->ix - ix0 >= 65536 || y_hi->iy - iy0 >= 65536 || points_.size() >= (std::size_t{1} << 32)) {
    std::sort(points_.begin(), points_.end(), [](const GridPoint& a, const GridPoint& b) {
      return a.ix != b.ix ? a.ix < b.ix : a.iy != b.iy ? a.iy < b.iy : a.source < b.source;
    });
    return;
  }
  keys_.resize(points_.size());
  for (std::size_t i = 0; i < points_.size(); ++i) {
    keys_[i] = static_cast<std::uint64_t>(points_[i].ix - ix0) << 48 |
               static_cast<std::uint64_t>(points_[i].iy - iy0) << 32 | static_cast<std::uint64_t>(i);
  }
  std::sort(keys_.begin(), keys_.end());
  sorted_.resize(points_.size());
  for (std::size_t i = 0; i < keys_.size(); ++i) sorted_[i] = points_[keys_[i] & 0xffffffffu];
  points_.swap(sorted_);
}

ClusteringStats Clusterer::cluster(const Cloud& cloud, Clusters& out) {
  ClusteringStats stats;
  out.clear();
  Index& idx = *index_;
  // the non-ground points in range, with their grid cell
  const double tol = params_.tolerance;
  const double cell = tol / std::sqrt(2.0);
  points_.clear();
  const double r2 = params_.max_range * params_.max_range;
  for (std::size_t i = 0; i < cloud.points.size(); ++i) {
    const CloudPoint& p = cloud.points[i];
    if (p.label != PointLabel::NonGround) continue;
    const double dx = p.x - calib_.mount_x, dy = p.y - calib_.mount_y;
    if (!(dx * dx + dy * dy <= r2)) continue;
    const auto ix = static_cast<std::int32_t>(std::floor(p.x / cell));
    const auto iy = static_cast<std::int32_t>(std::floor(p.y / cell));
    points_.push_back({ix, iy, p.x, p.y, static_cast<std::uint32_t>(i)});
  }
  stats.points = points_.size();
  if (points_.empty()) return stats;

  // the occupied cells: runs of points sorted by cell (then by index: deterministic)
  sort_by_cell();
  cell_start_.clear();
  idx.xy.clear();
  for (std::size_t i = 0; i < points_.size(); ++i) {
    if (i == 0 || points_[i].ix != points_[i - 1].ix || points_[i].iy != points_[i - 1].iy) {
      cell_start_.push_back(static_cast<std::uint32_t>(i));
      idx.xy.push_back({static_cast<float>((points_[i].ix + 0.5) * cell), static_cast<float>((points_[i].iy + 0.5) * cell)});
    }
  }
  cell_start_.push_back(static_cast<std::uint32_t>(points_.size()));
  const std::size_t cells = idx.xy.size();
  idx.tree.buildIndex();

  // union-find over the cells; the points of one cell lie within `tol` of each
  // other (its diagonal), so a cell is connected; two cells join when some
  // pair of their points lies within tol, which needs their centres within
  // tol + the cell's diagonal
  parent_.resize(cells);
  for (std::size_t c = 0; c < cells; ++c) parent_[c] = static_cast<std::uint32_t>(c);
  const double reach = tol + cell * std::sqrt(2.0);
  const auto reach2 = static_cast<float>(reach * reach);
  const double tol2 = tol * tol;
  const nanoflann::SearchParams search(32, 0.0f, false);
  for (std::size_t a = 0; a < cells; ++a) {
    idx.tree.radiusSearch(idx.xy[a].data(), reach2, idx.matches, search);
    for (const auto& m : idx.matches) {
      const std::uint32_t b = m.first;
      if (b <= a) continue;
      const std::uint32_t ra = find_root(parent_, static_cast<std::uint32_t>(a)), rb = find_root(parent_, b);
      if (ra == rb) continue;
      bool linked = false;
      for (std::uint32_t i = cell_start_[a]; i < cell_start_[a + 1] && !linked; ++i) {
        for (std::uint32_t j = cell_start_[b]; j < cell_start_[b + 1]; ++j) {
          const double dx = points_[i].x - points_[j].x, dy = points_[i].y - points_[j].y;
          if (dx * dx + dy * dy <= tol2) {
            linked = true;
            break;
          }
        }
      }
      if (linked) parent_[std::max(ra, rb)] = std::min(ra, rb);
    }
  }

  // the clusters, in the order of their lowest cloud index, members ascending
  groups_.clear();
  for (std::size_t c = 0; c < cells; ++c) {
    const std::uint32_t r = find_root(parent_, static_cast<std::uint32_t>(c));
    for (std::uint32_t i = cell_start_[c]; i < cell_start_[c + 1]; ++i) groups_.push_back({r, points_[i].source});
  }
  std::sort(groups_.begin(), groups_.end());
  // (root, source) sorted: each root's run is one cluster, sources ascending
  order_.clear();
  for (std::size_t i = 0; i < groups_.size(); ++i)
    if (i == 0 || groups_[i].first != groups_[i - 1].first) order_.push_back({groups_[i].second, i});
  std::sort(order_.begin(), order_.end());
  for (const auto& [first_source, begin] : order_) {
    std::size_t end = begin;
    while (end < groups_.size() && groups_[end].first == groups_[begin].first) ++end;
    const std::size_t size = end - begin;
    if (size < static_cast<std::size_t>(params_.min_points)) {
      ++stats.too_small;
      continue;
    }
    if (size > static_cast<std::size_t>(params_.max_points)) {
      ++stats.too_large;
      continue;
    }
    for (std::size_t i = begin; i < end; ++i) out.members.push_back(groups_[i].second);
    out.offsets.push_back(static_cast<std::uint32_t>(out.members.size()));
  }
  stats.clusters = out.size();
  return stats;
}

}  // namespace paddock::perception
