#include "autonomy/perception/lidar_pipeline.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace paddock::perception {

std::string LidarPipelineParams::check() const {
  if (const std::string why = params::validate(calibration); !why.empty()) return "calibration." + why;
  if (colour.big_cone_height != cone.big_cone_height)
    return "colour.big_cone_height must equal cone.big_cone_height (got " + params::number(colour.big_cone_height) +
           " and " + params::number(cone.big_cone_height) + ")";
  return "";
}

LidarPipeline::LidarPipeline(const LidarPipelineParams& params)
    : params_(params::require_valid(params, "LidarPipelineParams")),
      corrector_(params_.calibration),
      ground_(params_.ground, params_.calibration),
      clusterer_(params_.clustering, params_.calibration),
      cone_filter_(params_.cone, params_.calibration),
      colour_(params_.colour) {}

LidarResult LidarPipeline::process(const hal::LidarScan& scan, const Odometry* odometry) {
  LidarResult out;
  out.stamp = scan.end;
  LidarCounts& counts = out.counts;
  counts.points_in = scan.points.size();
  if (scan.points.empty()) {
    out.status = "empty scan: no points";
    return out;
  }

  // motion correction into the base frame at scan.end
  corrector_.correct(scan, odometry, cloud_);
  counts.invalid_dropped = cloud_.invalid;
  out.corrected = cloud_.corrected;
  if (cloud_.points.empty()) {
    out.status = "no usable points: all " + std::to_string(cloud_.invalid) +
                 " returns have a non-finite value or a ring beyond the calibration's channels";
    return out;
  }
  std::string notes;
  const auto note = [&notes](const std::string& s) { notes += (notes.empty() ? "" : "; ") + s; };
  if (odometry == nullptr) {
    note("no odometry: uncorrected");
  } else if (!cloud_.corrected) {
    note("odometry does not cover the scan: uncorrected");
  }
  if (cloud_.invalid > 0) note(std::to_string(cloud_.invalid) + " unusable returns dropped");
  if (scan.end < scan.stamp) note("scan end precedes its stamp");

  // ground removal
  const GroundStats gs = ground_.segment(cloud_);
  counts.ground = gs.ground;
  counts.non_ground = gs.non_ground;
  counts.vertical = gs.vertical;

  // clustering
  const ClusteringStats cs = clusterer_.cluster(cloud_, clusters_);
  counts.clustered = cs.points;
  counts.clusters = cs.clusters;

  // reconstruction and filters
  const ConeFilterStats fs = cone_filter_.filter(cloud_, ground_, clusters_, cone_clusters_, cone_members_);
  counts.reconstructed = fs.reconstructed;
  counts.rejected_count = fs.rejected_count;
  counts.rejected_size = fs.rejected_size;
  counts.rejected_height = fs.rejected_height;
  counts.rejected_shape = fs.rejected_shape;
  counts.rejected_density = fs.rejected_density;
  counts.cones = fs.accepted;

  // the free-space boundary: the nearest return per bearing that stands
  // higher than any cone above its ground
  const auto bins = static_cast<std::size_t>(params_.free_range_bins);
  out.free_range.assign(bins, std::numeric_limits<float>::infinity());
  for (const CloudPoint& p : cloud_.points) {
    if (p.label == PointLabel::Ground || !(p.height > params_.occluder_min_height)) continue;
    const double x = p.x, y = p.y;
    float& f = out.free_range[hal::free_range_bin(std::atan2(y, x), bins)];
    f = std::min(f, static_cast<float>(std::hypot(x, y)));
  }

  // colour from the intensity profile
  out.cones.reserve(cone_clusters_.size());
  for (const ConeCluster& c : cone_clusters_) {
    ConeCandidate cand;
    cand.centre = c.centre;
    cand.points = c.points;
    cand.color = colour_.classify(cloud_, cone_members_.data() + c.begin, c.end - c.begin, c.top);
    if (cand.color == ConeColor::Unknown) ++counts.colour_unknown;
    out.cones.push_back(cand);
  }

  if (params_.keep_points) {
    out.points.reserve(cloud_.points.size());
    for (const CloudPoint& p : cloud_.points) out.points.push_back({p.x, p.y, p.z, p.intensity, p.label});
  }
  out.ok = true;
  out.status = notes;
  return out;
}

}  // namespace paddock::perception
