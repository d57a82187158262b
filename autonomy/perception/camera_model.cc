#include "autonomy/perception/camera_model.h"

#include <cmath>

namespace paddock::perception {

Eigen::Vector3d to_camera(const CameraCalibration& calib, const Eigen::Vector3d& p_base) {
  return calib.T_camera_base * p_base;
}

std::optional<Eigen::Vector2d> project(const CameraCalibration& calib, const Eigen::Vector3d& p_base) {
  // [R|T] [X Y Z 1]^T, then K, then the division by w = z_camera
  const Eigen::Vector3d pc = to_camera(calib, p_base);
  if (!pc.allFinite() || !(pc.z() > kMinProjectionDepth)) return std::nullopt;
  Eigen::Matrix3d K;
  K << calib.fx, 0.0, calib.cx, 0.0, calib.fy, calib.cy, 0.0, 0.0, 1.0;
  const Eigen::Vector3d xyw = K * pc;
  const Eigen::Vector2d uv(xyw.x() / xyw.z(), xyw.y() / xyw.z());
  if (!uv.allFinite()) return std::nullopt;
  return uv;
}

bool in_image(const CameraCalibration& calib, const Eigen::Vector2d& uv) {
  return uv.x() >= 0.0 && uv.x() < calib.width && uv.y() >= 0.0 && uv.y() < calib.height;
}

}  // namespace paddock::perception
