#pragma once
// Euclidean clustering of the non-ground points (paper section "Lidar
// Perception"): two points belong to one cluster when a chain of points, each
// within `tolerance` of the next, joins them (single linkage), found by a
// union-find over a grid (exact, and far cheaper than a radius query per
// point inside the dense near cones): the points are binned into square
// cells of side tolerance / sqrt 2, so the points of one cell are all linked;
// a nanoflann KD-tree over the occupied cells' centres finds the cells that
// can hold a linked pair (centres within tolerance + the cell's diagonal),
// and such a pair of cells joins when a pair of their points is within the
// tolerance.
//
// Distances are taken in the ground plane (x, y of the base frame): a cone is
// upright, so its returns at different heights share its footprint, while
// the rings that hit a distant cone lie far apart in height (0.17 m between
// two 0.5 deg rings at 20 m, 0.35 m for 1 deg), which a 3D distance would
// split. The tolerance
// sits between the largest gap inside one cone's returns (two columns at
// 20 m: 20 m x 6.1 mrad = 0.12 m) and the smallest gap between two cones
// (centres >= 1.5 m apart on a track, minus two base radii: ~1.2 m).
//
// No I/O, no clock, no global state; the clusterer keeps its tree and
// scratch buffers between calls.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "autonomy/common/params.h"

#include "autonomy/perception/motion_correction.h"

namespace paddock::perception {

struct ClusteringParams {
  double tolerance = 0.4;
  // a small cone gets a single return beyond ~20 m
  double max_range = 25.0;
  // the cone filter applies the real, range-dependent count test
  int min_points = 1;
  // with the default 0.5 deg sensor a small cone at 1 m gets ~800 points, a
  // big one ~1150, and nearer than that a cone stands under the nose
  int max_points = 2000;

  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(tolerance), {"m", params::above(0.0), "points closer than this (in the ground plane) join one cluster"});
    v(PADDOCK_PARAM(max_range), {"m", params::above(0.0), "only points this close to the sensor (horizontally) are clustered"});
    v(PADDOCK_PARAM(min_points), {"", params::at_least(1), "clusters with fewer points are dropped"});
    v(PADDOCK_PARAM(max_points), {"", params::at_least(1), "clusters with more points are no cones (dropped before the costlier stages)"});
  }
  std::string check() const { return max_points < min_points ? "max_points must be >= min_points" : ""; }
};

// clusters as index lists into Cloud::points: cluster k is
// members[offsets[k] .. offsets[k + 1])
struct Clusters {
  std::vector<std::uint32_t> members;
  std::vector<std::uint32_t> offsets{0};
  std::size_t size() const { return offsets.size() - 1; }
  void clear() {
    members.clear();
    offsets.assign(1, 0);
  }
};

struct ClusteringStats {
  std::size_t points = 0;     // non-ground points in range, clustered
  std::size_t clusters = 0;   // kept
  std::size_t too_small = 0;  // clusters dropped for fewer than min_points
  std::size_t too_large = 0;  // clusters dropped for more than max_points
};

class Clusterer {
 public:
  // throws std::invalid_argument when params::validate fails for params or calibration
  Clusterer(const ClusteringParams& params, const LidarCalibration& calibration);
  ~Clusterer();
  Clusterer(Clusterer&&) noexcept;
  Clusterer& operator=(Clusterer&&) noexcept;

  // clusters the cloud's NonGround points within max_range of the sensor
  ClusteringStats cluster(const Cloud& cloud, Clusters& out);

  const ClusteringParams& params() const { return params_; }

 private:
  struct Index;  // nanoflann, kept out of the header
  ClusteringParams params_;
  LidarCalibration calib_;
  std::unique_ptr<Index> index_;
  // scratch, kept between calls
  struct GridPoint {
    std::int32_t ix, iy;  // cell
    double x, y;          // m
    std::uint32_t source; // index in the cloud
  };
  // sorts points_ by (ix, iy, source)
  void sort_by_cell();

  std::vector<GridPoint> points_;                                  // sorted by cell
  std::vector<std::uint64_t> keys_;                                // sort_by_cell's sort keys
  std::vector<GridPoint> sorted_;                                  // sort_by_cell's sorted copy
  std::vector<std::uint32_t> cell_start_;                          // cell c: points_[start[c] .. start[c + 1])
  std::vector<std::uint32_t> parent_;                              // union-find over the cells
  std::vector<std::pair<std::uint32_t, std::uint32_t>> groups_;    // (root cell, cloud index)
  std::vector<std::pair<std::uint32_t, std::size_t>> order_;       // (lowest cloud index, first row in groups_)
};

}  // namespace paddock::perception
