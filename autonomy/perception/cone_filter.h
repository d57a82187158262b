#pragma once
// cone reconstruction and the rule-based cone filters (paper section "Lidar
// Perception").
//
// Reconstruction: the ground removal takes the returns of a cone's lowest
// few centimetres with the ground. A vertical cylinder of
// reconstruction_radius around the cluster's axis (the mean x, y of its
// returns) gives back the ground-labelled returns inside it that stand more
// than reconstruction_margin above the local ground plane (and below
// max_height).
//
// Filters, in this order, each counted when it rejects:
//  - count: fewer than min_points returns;
//  - size: the x, y bounding box's diagonal beyond max_extent (a big cone's
//    base is 0.285 m wide);
//  - height: the top return's height above the ground outside
//    [min_height, max_height] (small cone 0.325 m, big 0.505 m; the ring at
//    the sensor's own height, mount_z, hits every cone in range);
//  - shape: across the line of sight the cone is symmetric (the mean of
//    its returns' lateral offsets lies within max_asymmetry of the middle of
//    their extent) and narrows upward (the upper half of its height is at
//    most max_width_growth wider than the lower half);
//  - density: the count n against the expected count of ORACLES.md (AMZ)
//      E(d) = 1/2 * h_c / (2 d tan(r_v / 2)) * w_c / (2 d tan(r_h / 2)),
//    h_c = 0.31 m, w_c = 0.30 m, r_v, r_h the calibration's vertical and
//    horizontal resolutions, d the horizontal range from the sensor:
//    accepted within [min_count_ratio E(d), max_count_ratio E(d)] (the
//    floor min_points keeps far cones, where E(d) < 1).
//
// The centre: a LiDAR sees the near face of a cone, whose returns lie on
// average pi/4 R in front of its axis (points spread evenly across the chord
// of a circle of radius R: the mean depth of sqrt(R^2 - y^2) over y in
// [-R, R] is pi R / 4), R the cone's radius at the returns' mean height (the
// small or, when its top reaches big_cone_height, the big cone's profile).
// The axis is the returns' mean x, y moved that far away from the sensor;
// centre z is the returns' mean z (the centroid's height, what a camera
// projection of the cluster centre wants). All in the base frame at the
// reference time.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "autonomy/common/params.h"
#include "autonomy/perception/clustering.h"
#include "autonomy/perception/ground_segmentation.h"
#include "autonomy/perception/motion_correction.h"

namespace paddock::perception {

struct ConeFilterParams {
  // reconstruction: a big cone's base radius (0.1425 m) plus range noise
  double reconstruction_radius = 0.2;
  double reconstruction_margin = 0.02;
  // the ground under a cone: the median height of the ground returns in the
  // ring [local_ground_inner, local_ground_outer] around its axis, when there
  // are at least local_ground_min_points of them (else the region's plane,
  // which on a bumpy ground can be off by the bumps: a small cone's 0.325 m
  // would then pass for a big cone's 0.42 m)
  double local_ground_inner = 0.25;
  double local_ground_outer = 1.0;
  int local_ground_min_points = 4;
  // count floor: two returns (a small cone gets ~5 on three rings at 15 m,
  // ~2 on two at 20 m with the default 0.5 deg sensor)
  int min_points = 2;
  // size
  double max_extent = 0.45;
  double min_height = 0.08;
  double max_height = 0.6;
  // shape
  double max_asymmetry = 0.08;
  double max_width_growth = 0.06;
  // density, relative to E(d); a big cone has ~2x a small one's area
  double min_count_ratio = 0.2;
  double max_count_ratio = 4.0;
  // between the small cone's 0.325 m and the big one's 0.505 m
  double big_cone_height = 0.42;

  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(reconstruction_radius), {"m", params::above(0.0), "ground returns within this of a cone's axis are given back to it"});
    v(PADDOCK_PARAM(reconstruction_margin), {"m", params::at_least(0.0),
                                             "... when they stand more than this above the local ground"});
    v(PADDOCK_PARAM(local_ground_inner), {"m", params::at_least(0.0), "the ring of ground returns under a cone starts this far from its axis"});
    v(PADDOCK_PARAM(local_ground_outer), {"m", params::above(0.0), "... and ends this far (> local_ground_inner)"});
    v(PADDOCK_PARAM(local_ground_min_points), {"", params::at_least(1), "fewer ground returns in the ring: the region's plane is the ground"});
    v(PADDOCK_PARAM(min_points), {"", params::at_least(1), "a cone has at least this many returns"});
    v(PADDOCK_PARAM(max_extent), {"m", params::above(0.0), "largest diagonal of a cone's x, y bounding box"});
    v(PADDOCK_PARAM(min_height), {"m", params::any(), "lowest top return above the ground"});
    v(PADDOCK_PARAM(max_height), {"m", params::any(), "highest top return above the ground (> min_height)"});
    v(PADDOCK_PARAM(max_asymmetry), {"m", params::above(0.0), "largest offset of the returns' mean from the middle of their extent, across the line of sight"});
    v(PADDOCK_PARAM(max_width_growth), {"m", params::at_least(0.0), "the upper half of a cone is at most this much wider than the lower half"});
    v(PADDOCK_PARAM(min_count_ratio), {"", params::at_least(0.0), "fewest returns, relative to the expected count E(d)"});
    v(PADDOCK_PARAM(max_count_ratio), {"", params::above(0.0), "most returns, relative to E(d) (> min_count_ratio)"});
    v(PADDOCK_PARAM(big_cone_height), {"m", params::above(0.0), "a cluster whose top return reaches this is a big cone"});
  }
  std::string check() const {
    if (!(local_ground_outer > local_ground_inner)) return "local_ground_outer must be > local_ground_inner";
    if (!(max_height > min_height)) return "max_height must be > min_height";
    if (!(max_count_ratio > min_count_ratio)) return "max_count_ratio must be > min_count_ratio";
    return "";
  }
};

// an accepted cone: its returns are members[begin, end) of the filter's
// member list (cluster returns and the reconstructed ones)
struct ConeCluster {
  std::uint32_t begin = 0, end = 0;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // m, base frame (see the top)
  double range = 0.0;   // m, horizontal, from the sensor to the centre
  double top = 0.0;     // m, the highest return above the local ground
  int points = 0;
};

struct ConeFilterStats {
  std::size_t reconstructed = 0;  // ground returns given back to accepted cones
  std::size_t rejected_count = 0;
  std::size_t rejected_size = 0;
  std::size_t rejected_height = 0;
  std::size_t rejected_shape = 0;
  std::size_t rejected_density = 0;
  std::size_t accepted = 0;
};

class ConeFilter {
 public:
  // throws std::invalid_argument when params::validate(params) or
  // params::validate(calibration) fails
  ConeFilter(const ConeFilterParams& params, const LidarCalibration& calibration);

  // reconstructs and filters every cluster; the accepted ones go to `cones`
  // (cleared first) and their returns are labelled PointLabel::Cone
  ConeFilterStats filter(Cloud& cloud, const GroundSegmenter& ground, const Clusters& clusters,
                         std::vector<ConeCluster>& cones, std::vector<std::uint32_t>& members);

  // E(d) of ORACLES.md for this calibration
  double expected_points(double d) const;

  const ConeFilterParams& params() const { return params_; }

 private:
  ConeFilterParams params_;
  LidarCalibration calib_;
  double res_v_ = 0.0, res_h_ = 0.0;  // rad
  // a ground return as the reconstruction and the local ground read it: a
  // copy of its coordinates (contiguous in the order they are scanned) and
  // its index in the cloud
  struct GroundReturn {
    float x, y, z;
    std::uint32_t index;
  };
  std::vector<GroundReturn> candidates_;  // scratch: ground returns that may be re-added, by x
  // scratch: the ground returns within kGroundGridRange of the sensor, by grid cell
  static constexpr double kGroundGridRange = 40.0;  // m, beyond the clustering's reach
  std::vector<std::uint32_t> ground_cell_start_, ground_fill_;
  std::vector<GroundReturn> ground_by_cell_;
  std::vector<GroundReturn> ground_;        // scratch: the binned ground returns in cloud order ...
  std::vector<std::uint32_t> ground_cell_;  // ... and their cells
  std::vector<std::uint8_t> cell_used_;     // scratch: per cell, whether a cone's local ground looks into it
  std::vector<Vec2> axes_;                  // scratch: per cluster, its axis (the mean x, y of its returns)
  std::vector<float> local_z_;              // scratch: the ground heights around one cone
};

}  // namespace paddock::perception
