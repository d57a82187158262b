#pragma once
// the LiDAR perception pipeline of the paper's section "Lidar Perception":
//   raw rotation -> motion correction (odometry) -> ground removal (slope-
//   robust cascaded segmentation) -> Euclidean clustering -> cone
//   reconstruction -> rule-based filters -> colour from the intensity profile
// giving cone candidates in the base frame at the scan's reference time (the
// rotation's end). Each stage is its own unit with its own Params (see their
// headers); this class strings them together and keeps their scratch
// buffers between calls, so a steady stream of scans allocates nothing new.
//
// Bad data never throws: unusable returns (NaN, a ring beyond the
// calibration's channels) are dropped and counted; a scan with no usable
// return gives ok = false and a reason; missing odometry gives an
// uncorrected result with a note in `status`.
//
// No I/O, no clock, no global state.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "autonomy/common/params.h"
#include "autonomy/common/time.h"
#include "autonomy/hal/messages.h"
#include "autonomy/perception/clustering.h"
#include "autonomy/perception/cone_filter.h"
#include "autonomy/perception/ground_segmentation.h"
#include "autonomy/perception/intensity_colour.h"
#include "autonomy/perception/motion_correction.h"
#include "autonomy/perception/odometry.h"
#include "autonomy/perception/types.h"

namespace paddock::perception {

struct LidarPipelineParams {
  // not visited: the runner fills it from the LiDAR's own layout and
  // mounting ([lidar]); check() checks it
  LidarCalibration calibration;
  GroundSegmentationParams ground;
  ClusteringParams clustering;
  ConeFilterParams cone;
  IntensityColourParams colour;
  // keep the corrected points with their labels in the result (for plots):
  // not visited, a run-time switch (Perception::set_keep_points)
  bool keep_points = false;
  // the free-space boundary (LidarResult::free_range): a non-ground return
  // this high above its local ground is no cone (a big cone is 0.505 m) but
  // something that hides what lies behind it (a barrier, a wall, a tent)
  double occluder_min_height = 0.6;
  int free_range_bins = 360;

  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(occluder_min_height), {"m", params::above(0.0), "a non-ground return this high above its ground is an obstacle that hides cones"});
    v(PADDOCK_PARAM(free_range_bins), {"", params::in(1, 36000), "bearing bins of the free-space boundary"});
    v.section(PADDOCK_PARAM(ground), "the ground removal (slope-robust cascaded segmentation)");
    v.section(PADDOCK_PARAM(clustering), "the Euclidean clustering of the non-ground points");
    v.section(PADDOCK_PARAM(cone), "the cone reconstruction and the rule-based cone filters");
    v.section(PADDOCK_PARAM(colour), "the cone colour from the LiDAR intensity profile");
  }
  // the calibration, then colour.big_cone_height == cone.big_cone_height
  std::string check() const;
};

// what each stage did with one scan
struct LidarCounts {
  std::size_t points_in = 0;
  std::size_t invalid_dropped = 0;  // NaN / infinite / ring out of range
  std::size_t ground = 0;
  std::size_t non_ground = 0;
  std::size_t vertical = 0;        // stage 1 of the ground removal
  std::size_t clustered = 0;       // non-ground points in clustering range
  std::size_t clusters = 0;        // after the clusterer's own size bounds
  std::size_t reconstructed = 0;   // ground points given back to cones
  std::size_t rejected_count = 0;  // per cone filter (cone_filter.h)
  std::size_t rejected_size = 0;
  std::size_t rejected_height = 0;
  std::size_t rejected_shape = 0;
  std::size_t rejected_density = 0;
  std::size_t cones = 0;
  std::size_t colour_unknown = 0;  // cones the intensity profile left undecided
};

// one corrected return and what the pipeline made of it (keep_points only)
struct LabelledPoint {
  float x = 0.0f, y = 0.0f, z = 0.0f;  // m, base frame at the reference time
  float intensity = 0.0f;
  PointLabel label = PointLabel::NonGround;
};

struct LidarResult {
  bool ok = false;
  // empty when all went well; else the reason (not ok) or notes (ok), e.g.
  // "no odometry: uncorrected"
  std::string status;
  TimeNs stamp = 0;        // the reference time: scan.end
  bool corrected = false;  // motion-corrected with the odometry
  std::vector<ConeCandidate> cones;
  // per bearing bin (hal::free_range_bin, free_range_bins of them) of the
  // base frame at `stamp`: the horizontal range of the nearest return higher
  // than occluder_min_height above its local ground, +infinity if none
  std::vector<float> free_range;
  LidarCounts counts;
  std::vector<LabelledPoint> points;  // keep_points only
};

class LidarPipeline {
 public:
  // throws std::invalid_argument when params::validate(params) fails
  explicit LidarPipeline(const LidarPipelineParams& params = {});

  // one rotation; odometry may be null (no motion correction)
  LidarResult process(const hal::LidarScan& scan, const Odometry* odometry);

  const LidarPipelineParams& params() const { return params_; }

 private:
  LidarPipelineParams params_;
  MotionCorrector corrector_;
  GroundSegmenter ground_;
  Clusterer clusterer_;
  ConeFilter cone_filter_;
  IntensityColourClassifier colour_;
  // scratch, reused between calls
  Cloud cloud_;
  Clusters clusters_;
  std::vector<ConeCluster> cone_clusters_;
  std::vector<std::uint32_t> cone_members_;
};

}  // namespace paddock::perception
