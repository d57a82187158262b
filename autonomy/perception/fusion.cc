#include "autonomy/perception/fusion.h"

#include <cmath>
#include <limits>

#include "autonomy/perception/camera_model.h"

namespace paddock::perception {

const char* to_string(FusionSource s) {
  switch (s) {
    case FusionSource::Camera: return "camera";
    case FusionSource::Lidar: return "lidar";
    case FusionSource::Dropped: return "dropped";
  }
  return "?";
}

FusionResult fuse(const std::vector<ConeCandidate>& candidates, const std::vector<BoundingBox>& boxes,
                  const CameraCalibration& calib, const FusionParams& params) {
  FusionResult r;
  r.cones.reserve(candidates.size());
  for (const ConeCandidate& c : candidates) {
    FusedCone f;
    f.centre = c.centre;
    f.color = c.color;
    const Eigen::Vector3d p = c.centre + Eigen::Vector3d(0.0, 0.0, params.height_offset);
    if (!p.allFinite()) {
      f.source = FusionSource::Dropped;
      ++r.dropped;
      r.cones.push_back(f);
      continue;
    }
    const std::optional<Eigen::Vector2d> uv = project(calib, p);
    if (uv) {
      f.projected = true;
      f.pixel = *uv;
    }
    const bool in_view = uv && in_image(calib, *uv) && to_camera(calib, p).norm() <= params.camera_range;
    if (!in_view) {
      f.kept = true;
      f.source = FusionSource::Lidar;
      ++r.from_lidar;
      r.cones.push_back(f);
      continue;
    }
    // the box holding the point whose centre column is nearest
    const double m = params.box_margin;
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < boxes.size(); ++k) {
      const BoundingBox& b = boxes[k];
      if (uv->x() < b.x_min - m || uv->x() > b.x_max + m || uv->y() < b.y_min - m || uv->y() > b.y_max + m) continue;
      const double d = std::abs(0.5 * (b.x_min + b.x_max) - uv->x());
      if (d < best) {
        best = d;
        f.box = static_cast<int>(k);
      }
    }
    if (f.box >= 0) {
      f.kept = true;
      f.color = boxes[static_cast<std::size_t>(f.box)].color;
      f.source = FusionSource::Camera;
      ++r.from_camera;
    } else {
      f.source = FusionSource::Dropped;
      ++r.dropped;
    }
    r.cones.push_back(f);
  }
  return r;
}

}  // namespace paddock::perception
