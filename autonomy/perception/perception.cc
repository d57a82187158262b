#include "autonomy/perception/perception.h"

#include <cmath>
#include <string>
#include <utility>

namespace paddock::perception {

std::string PerceptionParams::check() const {
  if (use_camera) {
    const CameraCalibration& c = camera;
    if (c.width <= 0 || c.height <= 0) return "camera.width and camera.height must be > 0 px";
    if (!(c.fx > 0.0) || !(c.fy > 0.0)) return "camera.fx and camera.fy must be > 0 px";
    if (!std::isfinite(c.cx) || !std::isfinite(c.cy) || !c.T_camera_base.matrix().allFinite())
      return "camera.cx, camera.cy and camera.T_camera_base must be finite";
  }
  return "";
}

Perception::Perception(const PerceptionParams& params, std::unique_ptr<ConeDetector> detector)
    : params_(params::require_valid(params, "PerceptionParams")),
      odometry_(params.odometry),
      pipeline_(params.lidar),
      detector_(std::move(detector)) {}

void Perception::add(hal::CameraDetections detections) { camera_ = CameraInput{std::move(detections), ""}; }

void Perception::add(const hal::CameraFrame& frame) {
  // no network of its own (or no camera in this mode): the boxes come as detections messages
  if (!detector_ || !params_.use_camera) return;
  DetectorResult r = detector_->detect(frame);
  CameraInput in{{frame.stamp, frame.width, frame.height, std::move(r.boxes)}, ""};
  if (!r.ok) {
    in.detections.boxes.clear();
    in.failure = r.reason.empty() ? "no reason given" : r.reason;
  }
  camera_ = std::move(in);
}

const hal::ConeDetections& Perception::process(const hal::LidarScan& scan) {
  ++stats_.scans;
  std::optional<LidarResult> ahead = ahead_ ? ahead_->take(scan, odometry_) : std::nullopt;
  last_.lidar = ahead ? std::move(*ahead) : pipeline_.process(scan, &odometry_);
  last_.camera_used = false;
  last_.camera_note.clear();
  last_.camera_stamp = 0;
  last_.detections = {};
  last_.fusion = {};
  hal::ConeDetections& out = last_.output;
  out.stamp = last_.lidar.stamp;
  out.cones.clear();
  out.free_range = last_.lidar.free_range;
  if (!last_.lidar.ok) {
    ++stats_.scans_failed;
    return out;
  }
  if (!last_.lidar.corrected) ++stats_.scans_uncorrected;
  const std::vector<ConeCandidate>& cands = last_.lidar.cones;

  // the detections of the camera frame exposed during this rotation, if the mode has a camera
  const TimeNs tol = from_seconds(params_.camera_sync_tolerance);
  const CameraInput* cam = nullptr;
  if (params_.use_camera) {
    const CameraCalibration& calib = params_.camera;
    if (camera_distrusted_) {
      last_.camera_note = "camera distrusted (lost or frozen)";
    } else if (!camera_) {
      last_.camera_note = "no camera detections";
    } else if (camera_->detections.stamp < scan.stamp - tol || camera_->detections.stamp > scan.end + tol) {
      last_.camera_note = "no camera detections of this rotation";
    } else if (!camera_->failure.empty()) {
      last_.camera_note = "detector: " + camera_->failure;
    } else if (camera_->detections.width != calib.width || camera_->detections.height != calib.height) {
      last_.camera_note = "camera detections on a " + std::to_string(camera_->detections.width) + " x " +
                          std::to_string(camera_->detections.height) + " image, the calibration's is " +
                          std::to_string(calib.width) + " x " + std::to_string(calib.height);
    } else {
      cam = &*camera_;
    }
  }
  if (cam == nullptr) {
    if (params_.use_camera) ++stats_.scans_without_camera;
    for (const ConeCandidate& c : cands) out.cones.push_back({{c.centre.x(), c.centre.y()}, c.color});
    return out;
  }

  // the candidates at the camera's exposure: the base pose at the scan's
  // reference time seen from the base at the exposure (planar motion)
  last_.camera_used = true;
  last_.camera_stamp = cam->detections.stamp;
  last_.detections = cam->detections;
  std::vector<ConeCandidate> at_camera = cands;
  if (const std::optional<Pose2> rel = odometry_.relative(cam->detections.stamp, out.stamp)) {
    for (ConeCandidate& c : at_camera) {
      const Vec2 p = rel->transform({c.centre.x(), c.centre.y()});
      c.centre.x() = p.x;
      c.centre.y() = p.y;
    }
  } else {
    last_.camera_note = "no odometry between the exposure and the scan: fused unmoved";
  }
  last_.fusion = fuse(at_camera, last_.detections.boxes, params_.camera, params_.fusion);
  for (std::size_t i = 0; i < cands.size(); ++i) {
    const FusedCone& f = last_.fusion.cones[i];
    if (!f.kept) {
      ++stats_.dropped_by_fusion;
      continue;
    }
    out.cones.push_back({{cands[i].centre.x(), cands[i].centre.y()}, f.color, f.source == FusionSource::Camera});
  }
  return out;
}

}  // namespace paddock::perception
