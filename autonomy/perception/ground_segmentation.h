#pragma once
// ground removal: the slope-robust cascaded ground segmentation of Narksri et
// al. 2018 ("A Slope-robust Cascaded Ground Segmentation in 3D Point Cloud
// for Autonomous Vehicles"), the paper's section "Lidar Perception".
//
// Stage 1, inter-ring distance, per column (one azimuth, rings ascending).
// A beam with depression angle d (tan d = -z / r from the optical centre, h =
// mount_z above the ground) meets a ground plane that rises away from the
// sensor with slope s at the horizontal range r = h / (tan d + s). Two
// consecutive returns a (lower beam) and b of one column on such a plane lie
//   g(a, b) = h (1 / (tan d_b + s) - 1 / (tan d_a + s))
// apart (infinite when beam b cannot meet the plane). With s = max_slope,
// the steepest ground we accept, g is the smallest gap ground can produce: a
// measured gap |r_b - r_a| below g + gap_noise (the range noise's share)
// means the returns stack up on something steeper than ground. A run of such returns (each one close to the previous)
// that rises by more than vertical_threshold is a vertical object; its points
// are non-ground for good. Using each return's own measured direction instead
// of the nominal ring elevations keeps the test right under a pitched mount.
//
// Stage 2, multi-region plane fitting. Around the sensor the plane is cut into
// `sectors` equal azimuth sectors and concentric rings at region_bounds. Per
// sector, from the inside out, each region fits z = a x + b y + c (least
// squares) to its stage-1 ground candidates near the plane of the region
// inside it (the prior; for the innermost region the ground under the car, z =
// 0 of the base frame). The fit is iterated fit_iterations times with a window
// shrinking geometrically from fit_window (first_fit_window for the innermost
// region) to ground_threshold, which drops
// cone returns and other outliers. A region seen by a single ring is an arc:
// its radial slope is unobservable, so the slope is pulled toward the
// prior's (a ridge term: the slope error along a direction is weighted by the
// points' variance there, the prior's by slope_prior_spread^2, or
// first_slope_prior_spread^2 for the innermost region). A fit steeper than
// max_slope keeps the prior's slope; a fit off the prior by more than
// max_step where the regions meet or at its candidates' centroid (the
// innermost region: at the sensor only) is discarded for the prior; a region with fewer than min_fit_points
// candidates takes the prior. A point is ground when it is not vertical and
// lies less than ground_threshold above its region's plane (below it counts
// as ground).
//
// Every point's height above its region's plane is stored in it; the planes
// stay queryable (ground_height) for the later stages.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "autonomy/common/params.h"
#include "autonomy/perception/motion_correction.h"
#include "autonomy/perception/types.h"

namespace paddock::perception {

struct GroundSegmentationParams {
  // FS tracks are nearly flat; 0.25 (14 deg) covers a 10 % slope with 0.1 m
  // bumps on a 10 m wavelength (up to ~0.19)
  double max_slope = 0.25;
  // two returns' horizontal ranges differ by noise too (range noise sigma
  // 2 cm: 2.8 cm on a difference). It matters for this low sensor, whose
  // 0.5 deg rings expect only 1 - 2 cm on the steepest ground beyond 2 m, no
  // more than a cone's own slope and noise put between two rings
  double gap_noise = 0.06;
  // a small cone at 10 m still takes three 0.5 deg rings, 0.17 m from the
  // lowest to the highest; the ground's range noise moves near returns by
  // millimetres in height
  double vertical_threshold = 0.05;
  // the ground's rings of a 0.15 m high sensor (-8 .. -0.5 deg, 0.5 deg apart) lie at 1.07
  // .. 1.91 m (eight rings), 2.1, 2.5, 2.9, 3.4, 4.3, 5.7, 8.6 and 17.2 m;
  // beyond that only uphill ground returns
  std::vector<double> region_bounds{2.0, 4.0, 6.0, 9.0, 13.0, 20.0};
  // 32 make a region about 1.7 m wide at 8.6 m, narrow enough for 0.1 m
  // bumps of a 10 m wavelength
  int sectors = 32;
  // bumps leave ~2-3 cm of residual, a cone's lowest returns below this are
  // added back by the cone reconstruction
  double ground_threshold = 0.05;
  // below the 0.15 m at which the ring level with the sensor hits every cone
  double fit_window = 0.1;
  // the innermost region's prior, the level ground under the car, holds at
  // the sensor only, and the lowest ring meets the ground ~1.1 m away, where
  // a 10 % slope with bumps (up to ~0.16) already lifts it 0.17 m
  double first_fit_window = 0.25;
  int fit_iterations = 3;
  // a ground ring crosses a 32-sector region in 32 columns; a cone gives a
  // region 2-10 returns off the vertical runs, so a few cones alone cannot
  // make one
  int min_fit_points = 20;
  // the ridge pulling an unobservable slope toward the prior's (see the
  // top). The innermost region's prior is the level ground under the car,
  // and its returns spread over metres: a weak pull finds a 10 % slope. An
  // outer region's prior is its inner neighbour's fitted plane, and the
  // region often holds one ring's arc plus a few cone-base returns whose
  // leverage would tilt a free fit: a stronger pull. 0.6 m: the -1 deg
  // ring's region (6 - 9 m) is extrapolated to the -0.5 deg ring at 17 m,
  // where a 0.01 slope error is already 0.09 m of height (0.3 m let cone
  // returns at 7 m tilt it that much, 0.8 m no longer follows 0.1 m bumps)
  double first_slope_prior_spread = 0.1;
  double slope_prior_spread = 0.6;
  double max_step = 0.08;

  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(max_slope), {"", params::above(0.0), "the steepest ground (dz / dr)"});
    v(PADDOCK_PARAM(gap_noise), {"m", params::at_least(0.0), "added to the expected gap between two returns of a column"});
    v(PADDOCK_PARAM(vertical_threshold), {"m", params::above(0.0), "a run of close returns rising by more than this is a vertical object"});
    v(PADDOCK_PARAM(region_bounds), {"m", params::above(0.0), "the regions' ring edges: ranges from the sensor, ascending, at most 1000"});
    v(PADDOCK_PARAM(sectors), {"", params::in(1, 4096), "azimuth sectors of the regions"});
    v(PADDOCK_PARAM(ground_threshold), {"m", params::above(0.0), "a point less than this above its region's plane is ground"});
    v(PADDOCK_PARAM(fit_window), {"m", params::above(0.0),
                                  "the first fit takes candidates within this of the prior plane (>= ground_threshold)"});
    v(PADDOCK_PARAM(first_fit_window), {"m", params::above(0.0), "the innermost region's first window (>= ground_threshold)"});
    v(PADDOCK_PARAM(fit_iterations), {"", params::in(1, 100), "fits per region, the window shrinking to ground_threshold"});
    v(PADDOCK_PARAM(min_fit_points), {"", params::at_least(3), "a region with fewer candidates takes the prior plane"});
    v(PADDOCK_PARAM(first_slope_prior_spread), {"m", params::above(0.0), "the innermost region's pull of the slope toward the prior's"});
    v(PADDOCK_PARAM(slope_prior_spread), {"m", params::above(0.0), "an outer region's pull of the slope toward the prior's"});
    v(PADDOCK_PARAM(max_step), {"m", params::above(0.0),
                                "a fit off the prior by more than this where it meets the inner region or at its candidates' centroid is discarded"});
  }
  std::string check() const;
};

struct GroundStats {
  std::size_t ground = 0;
  std::size_t non_ground = 0;
  std::size_t vertical = 0;        // stage 1's vertical points (all non-ground)
  std::size_t fitted_regions = 0;  // regions with their own plane
  std::size_t regions = 0;
};

class GroundSegmenter {
 public:
  // throws std::invalid_argument when params::validate(params) or
  // params::validate(calibration) fails
  GroundSegmenter(const GroundSegmentationParams& params, const LidarCalibration& calibration);

  // labels every point Ground or NonGround, sets its height and vertical
  // flag, and keeps the region planes for ground_height
  GroundStats segment(Cloud& cloud);

  // the ground's height (base frame z) at (x, y) of the base frame at the
  // reference time, from the last segment() call's region planes
  double ground_height(double x, double y) const;

  const GroundSegmentationParams& params() const { return params_; }

 private:
  struct Plane {
    double a = 0.0, b = 0.0, c = 0.0;  // z = a x + b y + c
    double at(double x, double y) const { return a * x + b * y + c; }
  };

  // a stage-1 ground candidate (not vertical) as the fit reads it
  struct FitPoint {
    float x, y, z;
  };

  // a sector's wedge narrowed by kSectorMargin on both sides: its edges'
  // unit directions (cosine, sine)
  struct Wedge {
    double lo_c, lo_s, hi_c, hi_s;
  };

  void inter_ring(Cloud& cloud, GroundStats& stats);
  // the region of (x, y), base frame: sector * rings_ + ring
  std::size_t region_of(double x, double y) const;
  // its parts, from (dx, dy) = (x, y) - the sensor's mount
  std::size_t ring_of(double dx, double dy) const;
  std::size_t sector_of(double dx, double dy) const;
  // whether (dx, dy) lies strictly inside sector's narrowed wedge, where
  // sector_of certainly gives `sector` (see the constructor); false for a
  // sector >= wedges_.size()
  bool in_sector(std::size_t sector, double dx, double dy) const;
  // fits region `region` (its candidates in fit_points_) from the prior plane
  Plane fit_region(std::size_t region, std::size_t sector, const Plane& prior, double r_inner,
                   bool& fitted) const;

  GroundSegmentationParams params_;
  LidarCalibration calib_;
  std::size_t rings_ = 0;  // concentric regions: region_bounds.size() + 1
  // fixed by the parameters, so computed once in the constructor (each by
  // one expression, the same doubles as computed per region): per sector,
  // the cosine and sine of its middle azimuth; per fit iteration, the
  // window of the innermost region and of the others
  std::vector<double> sector_cos_, sector_sin_;
  std::vector<double> first_windows_, windows_;
  // ring_of's squared bounds and in_sector's wedges (see the constructor)
  std::vector<double> squared_bounds_;
  std::vector<Wedge> wedges_;
  std::vector<Plane> planes_;  // sector * rings_ + ring
  // scratch: every point's region, and the ground candidates bucketed by
  // region (a counting sort; within a region in cloud order), copied out so
  // that the fit's passes over a region read contiguous memory
  std::vector<std::uint32_t> region_id_, offsets_, cursor_;
  std::vector<std::uint32_t> ring_sector_;  // per ring, the sector of its latest return
  std::vector<double> inv_reach_;           // per point, stage 1's 1 / (tan d + s)
  std::vector<FitPoint> fit_points_;
};

}  // namespace paddock::perception
