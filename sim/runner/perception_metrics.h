#pragma once
// how well perception saw the cones, against the simulator's ground truth, per
// range bin: precision, recall, colour accuracy, position error.
//
// One frame = one set of perceived cones (base frame at the frame's stamp) and
// the truth of that instant: the base pose, every cone's position and colour,
// and which cones the sensor could see at all (a LiDAR scan that hit the cone
// with at least one point; for the object-level cone sensor every cone).
//
// Matching: perceived and true cones pair greedily by increasing distance, at
// most match_radius apart, each at most once. Range: in the plane, from the
// sensor's origin (its mounting point) to the true cone (matched and missed
// cones) or to the perceived cone (unmatched detections).
//   precision        matched detections / detections in the bin
//   recall           matched visible cones / visible cones in the bin
//   colour accuracy  matched detections with the true colour / matched
//                    (a detection without colour counts as wrong)
//   position error   mean and largest distance of the matched pairs
#include <array>
#include <cstddef>
#include <tuple>
#include <vector>

#include "autonomy/common/cone.h"
#include "autonomy/common/geometry.h"
#include "autonomy/hal/messages.h"

namespace paddock::runner {

struct RangeBinStats {
  double range_min = 0.0, range_max = 0.0;  // m, [min, max)
  long detections = 0;          // perceived cones in the bin
  long detections_matched = 0;  // of which matched to a true cone
  long visible = 0;             // true cones the sensor saw in the bin
  long visible_matched = 0;     // of which perceived
  long colour_right = 0;        // matched detections with the true colour
  long colour_unknown = 0;      // matched detections without a colour
  double error_sum = 0.0;       // m, over matched pairs binned by the true range
  double error_max = 0.0;       // m
  long error_count = 0;

  double precision() const;        // NaN without detections
  double recall() const;           // NaN without visible cones
  double colour_accuracy() const;  // NaN without matches
  double error_mean() const;       // NaN without matches
};

class PerceptionMetrics {
 public:
  // bin edges (m): bins [e0, e1), [e1, e2), ..., and a last one [e_last, inf)
  explicit PerceptionMetrics(std::vector<double> edges = {0.0, 5.0, 10.0, 15.0, 20.0, 30.0},
                             double match_radius = 0.5);

  // one frame; `visible[i]` tells whether true cone i could be seen (empty:
  // all of them); sensor_in_base is the sensor's origin in the base frame
  void add(const hal::ConeDetections& perceived, const Pose2& base_pose, Vec2 sensor_in_base,
           const std::vector<Cone>& truth, const std::vector<bool>& visible);

  long frames() const { return frames_; }
  const std::vector<RangeBinStats>& bins() const { return bins_; }
  // every bin together
  RangeBinStats total() const;

 private:
  std::size_t bin_of(double range) const;

  std::vector<RangeBinStats> bins_;
  double match_radius_;
  long frames_ = 0;
  // add()'s scratch, kept between frames (no allocation a frame)
  std::vector<Vec2> seen_;
  std::vector<std::size_t> near_;
  std::vector<std::tuple<double, std::size_t, std::size_t>> pairs_;
  std::vector<long> match_of_seen_;
  std::vector<char> truth_taken_;
};

}  // namespace paddock::runner
